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


def test_c4_counts_the_w1_spread_in_steps_of_an_uneven_ramp():
    values = c4_values([0.2, 0.25, 0.3])
    values["omegas"] = [0.08, 0.11, 0.2, 0.25, 0.3, 0.35, 0.5]
    values["per_gamma"][2].update(omega_1=0.5, omega_star=0.45)  # one step up, though 0.15 > the finest step
    assert verdict_c4(values).verdict == AGREES
    values["per_gamma"][2]["omega_1"] = 0.25
    values["per_gamma"][2]["omega_star"] = 0.2
    assert "w1 spread 0.1 over gamma_n (2 ramp step(s))" in verdict_c4(values).reason


def test_c4_reports_the_bouncing_floor_beside_the_verdict():
    values = c4_values([0.2, 0.25, 0.3])
    for p, floor, inside in zip(values["per_gamma"], (0.21, 0.3, 0.5), (True, False, False)):
        p.update(restitution=0.9, floor_omega=floor, floor_bracketed=inside, down_to=0.2)
    row = verdict_c4(values)
    assert row.verdict == AGREES  # the floor is not part of the verdict
    assert "floor between w* and the next ramp value for 1/3 gamma_n" in row.reason
    assert "bouncing-ball floor 0.21 from e = 0.9, between w* and the next ramp value" in row.measured
