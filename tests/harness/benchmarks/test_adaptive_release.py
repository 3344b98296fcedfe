"""The release comparison's bookkeeping: what "work at equal accuracy" picks, and that both
sides are asked for the same physics."""
import math

from harness.benchmarks.adaptive_release import request, time_to_reach
from harness.benchmarks.work_precision import SCENARIOS


def test_work_at_equal_accuracy_is_the_cheapest_run_reaching_it_or_infinite():
    rows = [(1.0, 1e-4), (2.0, 1e-7), (3.0, 1e-9), (1.5, 5e-7)]
    assert time_to_reach(rows, 1e-6) == 1.5
    assert math.isinf(time_to_reach(rows, 1e-10))


def test_this_build_runs_the_release_s_fixed_axes_contact_and_both_the_same_tolerances():
    scenario = next(s for s in SCENARIOS if s.model == "C")
    ours, theirs = request(scenario, 1e-6, True), request(scenario, 1e-6, False)
    assert ours["parameters"].pop("contact_law") == 1 and "contact_law" not in theirs["parameters"]
    assert ours == theirs and ours["parameters"]["atol"] == 1e-8


def test_the_tangent_frame_runs_the_default_contact_which_is_the_release_s_there():
    scenario = next(s for s in SCENARIOS if s.formulation == 1)
    assert "contact_law" not in request(scenario, 1e-6, True)["parameters"]
