"""C4's hysteresis criteria on synthetic ramps."""
from __future__ import annotations

from harness.paper.claims.c4_hysteresis import verdict_c4
from harness.paper.claims.verdicts import AGREES, DISAGREES, NOT_REPRODUCED


def c4_values(stars):
    return {"amplitude": 10.0, "omega_step": 0.05, "fresh_gamma_n": 0.07, "omegas": [0.2, 0.25, 0.3, 0.35],
            "down_differs_from_fresh_orbit": [0.25], "up_differs_from_fresh_impact": [],
            "fresh_steady_orbit": [], "fresh_equilibrium": [],
            "per_gamma": [{"gamma_n": g, "omega_1": 0.35, "omega_star": s, "onset_omega": 0.3}
                          for g, s in zip((0.035, 0.07, 0.14), stars)]}


def test_c4_hysteresis_criteria():
    assert verdict_c4(c4_values([0.2, 0.25, 0.3])).verdict == AGREES
    no_loop = verdict_c4(c4_values([0.35, 0.35, 0.35]))
    assert no_loop.verdict == DISAGREES and "w* < w1 for 0/3" in no_loop.reason
    growing = verdict_c4(c4_values([0.3, 0.25, 0.2]))
    assert growing.verdict == DISAGREES
    assert verdict_c4(c4_values([None, 0.25, 0.3])).verdict == NOT_REPRODUCED
