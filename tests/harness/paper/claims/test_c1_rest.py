"""C1's verdict follows its tolerance."""
from __future__ import annotations

from harness.paper.claims.c1_rest import verdict_c1
from harness.paper.claims.verdicts import AGREES, DISAGREES, NOT_REPRODUCED


def c1_values(stick_time: float) -> dict:
    return {"rest_penetration": 1.0, "rest_penetration_formula": 1.0, "creep_velocity": 3.45e-4,
            "creep_velocity_formula": 3.4483e-4, "stick_time": stick_time, "stick_time_formula": 5178.6,
            "slip_length": 49.0, "slip_length_formula": 50.0, "slip_events": 3, "regime": "stick_slip"}


def test_c1_verdict_follows_the_tolerance():
    assert verdict_c1(c1_values(5000.0)).verdict == AGREES
    row = verdict_c1(c1_values(3000.0))
    assert row.verdict == DISAGREES and "stick time off by 42%" in row.reason
    assert verdict_c1({**c1_values(5000.0), "creep_velocity": None}).verdict == NOT_REPRODUCED
