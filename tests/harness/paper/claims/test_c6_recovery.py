"""C6: both transitions of a diagram row bisected in omega, and the verdicts on located values."""
from __future__ import annotations

import math

import pytest

from harness.paper.claims import c6_recovery
from harness.paper.claims.c6_recovery import BOUNDARY_RESOLUTION, RECOVERY_SLACK, verdict_c6
from harness.paper.claims.measure import recovery
from harness.paper.claims.verdicts import AGREES, DISAGREES
from harness.runs.settings import PointSettings, RunSettings


class Regimes:
    """Stands in for the runner: classifies a run by its (A, omega) from known boundaries."""

    def __init__(self, loss, back):
        self.loss, self.back, self.batches = loss, back, []

    def tasks(self, function, items):
        self.batches.append(len(items))
        return [{"observables": {"regime": self.regime(float(i["point"].run.parameters["A"]),
                                                         float(i["point"].run.parameters["omega"]))}}
                for i in items]

    def regime(self, amplitude, omega):
        return "sliding" if self.loss(amplitude) < omega < self.back(amplitude) else "stick_slip"


def test_each_rows_loss_and_recovery_are_bisected_to_the_resolution():
    loss, back = (lambda a: 1 / math.sqrt(a)), (lambda a: 14.0 + a)
    runner = Regimes(loss, back)
    omegas = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
    rows = []
    for amplitude in (0.3, 3.0):
        rows.append({"A": amplitude, **recovery(omegas, [runner.regime(amplitude, w) for w in omegas])})
    base = PointSettings(run=RunSettings(parameters={"A": 0.0, "omega": 1.0}))
    c6_recovery._locate_transitions(runner, base, rows)
    for row in rows:
        lo, hi = row["located_omega_1_bracket"]
        assert lo < loss(row["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION
        lo, hi = row["located_omega_2_bracket"]
        assert lo < back(row["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION
    # All brackets of a round go out as one batch.
    assert runner.batches[0] == 4


def row(amplitude, omega_1, omega_2, located_1=None, located_2=None):
    return {"A": amplitude, "omega_1": omega_1, "last_friction_before_1": omega_1 / 3, "omega_2": omega_2,
            "last_sliding": omega_2 / 3 if omega_2 else None, "first_transition_paper": 1 / math.sqrt(amplitude),
            "first_transition_onset": None, "located_omega_1": located_1, "located_omega_2": located_2}


def measured(rows):
    return {"k_n_over_gamma_n": 1 / 0.07, "frictionless": {"regime": "sliding", "slip_events": 0, "phi": 0.0,
                                                           "drift_velocity": 0.01},
            "diagram_rows": rows, "omegas": [], "resolution": BOUNDARY_RESOLUTION, "stiffness_amplitude": 0.5,
            "recovery_vs_k": [], "ramp_amplitude": 0.5, "ramp_values": [], "ramp_up_omega_2": None,
            "ramp_down_omega_2": None, "ramp_up_regimes": [], "ramp_down_regimes": []}


@pytest.mark.parametrize("located, verdict", [(1.0 / math.sqrt(3.0) * 1.05, AGREES),
                                              (1.0 / math.sqrt(3.0) * 1.3, DISAGREES)])
def test_the_first_transition_is_judged_against_the_located_loss(located, verdict):
    rows = {r.claim: r for r in verdict_c6(measured([row(3.0, 1.0, 15.0, located_1=located)]))}
    assert rows["C6b"].verdict == verdict


def test_recovery_is_judged_on_located_values_near_k_n_over_gamma_n_and_alike_across_a():
    ratio = 1 / 0.07
    alike = [row(0.3, 3.0, 30.0, located_2=ratio * 1.05), row(3.0, 1.0, 30.0, located_2=ratio * 1.08)]
    assert {r.claim: r for r in verdict_c6(measured(alike))}["C6c"].verdict == AGREES
    far = [row(0.3, 3.0, 30.0, located_2=ratio * (1 + 2 * RECOVERY_SLACK)), row(3.0, 1.0, 30.0, located_2=ratio)]
    c6c = {r.claim: r for r in verdict_c6(measured(far))}["C6c"]
    assert c6c.verdict == DISAGREES and "within 25% of k_n/gamma_n in 1/2" in c6c.reason
