"""Bisection of the transitions a coarse grid brackets: located to the stated resolution."""
import math

import numpy as np
import pytest

from harness.runs.bisection import LOSS, RECOVERY, Transition, brackets, locate_transitions, refine

LOSS_AT, RECOVERY_AT = 1.37, 12.5  # a classifier held below 1.37 and above 12.5


def held(value: float) -> bool:
    return value < LOSS_AT or value > RECOVERY_AT


def test_every_transition_is_bracketed_to_the_resolution_with_one_batch_per_round():
    grid = np.geomspace(0.3, 60.0, 8)  # neighbours a factor 2.13 apart
    batches = []

    def classify(points):
        batches.append(list(points))
        return [held(p) for p in points]

    found = locate_transitions(classify, grid, [held(v) for v in grid], resolution=0.03)
    assert [t.kind for t in found] == [LOSS, RECOVERY]
    for transition, truth in zip(found, (LOSS_AT, RECOVERY_AT)):
        assert transition.lo < truth <= transition.hi
        assert transition.resolution <= 0.03
        assert abs(transition.value / truth - 1) <= 0.03
    # Both brackets are halved together: rounds = ceil(log2(ln 2.13 / ln 1.03)).
    assert len(batches) == math.ceil(math.log2(math.log(grid[1] / grid[0]) / math.log(1.03)))
    assert all(len(batch) == 2 for batch in batches)


def test_a_grid_without_a_change_needs_no_evaluation():
    def classify(points):
        raise AssertionError("nothing to bisect")

    assert locate_transitions(classify, [1.0, 2.0, 3.0], [True, True, True]) == []


def test_brackets_through_zero_halve_linearly():
    found = locate_transitions(lambda ps: [p < 0.25 for p in ps], [-1.0, 1.0], [True, False], resolution=1e-3)
    [transition] = found
    assert transition.lo < 0.25 <= transition.hi


@pytest.mark.parametrize("values, classes, message", [
    ([1.0, 2.0], [True], "2 values but 1 classes"),
    ([2.0, 1.0], [True, False], "strictly ascending"),
])
def test_bad_grids_are_refused(values, classes, message):
    with pytest.raises(ValueError, match=message):
        brackets(values, classes)


def test_brackets_of_several_columns_are_refined_together():
    # Two columns of a phase diagram, each with its own boundary in A: one batch per round.
    truth = {0.5: 4.0, 2.0: 0.25}
    found = [Transition(1.0, 10.0, True, where={"omega": 0.5}), Transition(0.1, 1.0, True, where={"omega": 2.0})]
    batches = []

    def classify(pairs):
        batches.append(len(pairs))
        return [point < truth[t.where["omega"]] for t, point in pairs]

    refine(classify, found, resolution=0.01)
    for transition in found:
        assert transition.lo < truth[transition.where["omega"]] <= transition.hi
        assert transition.resolution <= 0.01
    assert set(batches) == {2}
