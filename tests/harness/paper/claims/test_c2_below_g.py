"""C2's verdict: unchanged slips agree, a shortened cycle disagrees."""
from __future__ import annotations

from harness.paper.claims.c2_below_g import verdict_c2
from harness.paper.claims.verdicts import AGREES, DISAGREES


def c2_values(interval_at_a: float) -> dict:
    return {"omega": 0.25, "amplitudes": [0.0, 8.0], "peak_acceleration_over_g": [0.0, 0.5],
            "slip_interval": [5000.0, interval_at_a], "stick_time": [4600.0, interval_at_a - 400.0],
            "slip_length": [49.0, 49.0 * interval_at_a / 5000.0], "slip_events": [3, 3],
            "regime": ["stick_slip", "stick_slip"]}


def test_c2_agrees_when_unchanged_and_disagrees_when_shortened():
    assert verdict_c2(c2_values(4900.0)).verdict == AGREES
    row = verdict_c2(c2_values(3700.0))
    assert row.verdict == DISAGREES and "26%" in row.reason
    assert "3.7e+03" in row.measured
