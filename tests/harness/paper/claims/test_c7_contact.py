"""C7: where the block leaves contact and where it is embedded again, bisected in omega."""
from __future__ import annotations

from harness.paper.claims import c7_contact
from harness.paper.claims.c7_contact import BOUNDARY_RESOLUTION, EMBEDDED, verdict_c7
from harness.paper.claims.verdicts import AGREES, DISAGREES
from harness.runs.settings import PointSettings, RunSettings


class Contact:
    """Stands in for the runner: embedded outside (leave(A), back(A)), half in contact inside."""

    def __init__(self, leave, back):
        self.leave, self.back = leave, back

    def fraction(self, amplitude, omega):
        return 0.5 if self.leave(amplitude) < omega < self.back(amplitude) else 1.0

    def tasks(self, function, items):
        return [{"observables": {"contact_fraction": self.fraction(float(i["point"].run.parameters["A"]),
                                                                   float(i["point"].run.parameters["omega"]))}}
                for i in items]


def test_leaving_and_returning_are_bisected_per_model_and_amplitude():
    leave, back = (lambda a: 0.5 + a), (lambda a: 14.0 * (1 + a))
    runner = Contact(leave, back)
    omegas = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
    curves = {model: [{"A": a, "omega": omegas, "contact_fraction": [runner.fraction(a, w) for w in omegas]}
                      for a in (0.3, 3.0)] for model in "BC"}
    base = PointSettings(run=RunSettings(parameters={"A": 0.0, "omega": 1.0}))
    c7_contact._locate(runner, {"B": base, "C": base}, curves)
    for model_curves in curves.values():
        for curve in model_curves:
            lo, hi = curve["located_omega_1_bracket"]
            assert lo < leave(curve["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION
            lo, hi = curve["located_omega_2_bracket"]
            assert lo < back(curve["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION


def test_a_curve_that_never_returns_to_contact_disagrees():
    omegas = [0.1, 1.0, 14.0]
    back = {"A": 0.3, "omega": omegas, "contact_fraction": [1.0, 0.5, EMBEDDED]}
    never = {"A": 3.0, "omega": omegas, "contact_fraction": [1.0, 0.5, 0.6]}
    assert verdict_c7({"curves": {"B": [back], "C": [back]}}).verdict == AGREES
    row = verdict_c7({"curves": {"B": [back], "C": [never]}})
    assert row.verdict == DISAGREES and "C, A = 3: never re-embedded" in row.reason
