"""Catalogue statistics (``harness.chain.statistics``) against samples of known law."""
import math

import numpy as np
import pytest

from harness.chain.statistics import b_value, completeness, recurrence_intervals, size_exponent


def _gutenberg_richter(b, mc, n, seed):
    """Continuous magnitudes above mc with P(M > m) = 10^(-b (m - mc))."""
    return mc + np.random.default_rng(seed).exponential(1.0 / (b * math.log(10.0)), n)


@pytest.mark.parametrize("b", [0.8, 1.0, 1.5])
def test_the_b_value_of_a_gutenberg_richter_sample_is_found_within_its_error(b):
    estimate = b_value(_gutenberg_richter(b, 2.0, 4000, seed=int(10 * b)), completeness_magnitude=2.0)
    assert abs(estimate.b - b) < 3.0 * estimate.sigma
    assert estimate.sigma == pytest.approx(b / math.sqrt(4000), rel=0.1)  # Shi and Bolt ~ b / sqrt(n)
    assert estimate.n_events == 4000


def test_binned_magnitudes_need_utsus_correction():
    """Rounded to 0.1, the sample's b is recovered with the half-bin correction and
    biased low without it."""
    m = np.round(_gutenberg_richter(1.0, 1.95, 20000, seed=4), 1)
    corrected = b_value(m, completeness_magnitude=2.0, delta_m=0.1)
    uncorrected = b_value(m, completeness_magnitude=2.0, delta_m=0.0)
    assert abs(corrected.b - 1.0) < 3.0 * corrected.sigma
    assert uncorrected.b > 1.0 + 5.0 * corrected.sigma


def test_completeness_is_the_most_populated_bin_of_an_incomplete_sample():
    """Complete above 1.5, one in fifty events detected below: the frequency-magnitude
    curve peaks at the first complete bin (maximum curvature's premise)."""
    rng = np.random.default_rng(1)
    every = _gutenberg_richter(1.0, 0.5, 20000, seed=2)
    detected = every[(every >= 1.45) | (rng.uniform(size=every.size) < 0.02)]
    assert completeness(detected, 0.1) == pytest.approx(1.5)
    assert completeness(detected, 0.1, correction=0.2) == pytest.approx(1.7)


def test_the_size_exponent_of_a_pareto_sample_with_and_without_an_upper_cut():
    rng = np.random.default_rng(3)
    tau, s_min = 1.6, 2.0
    sizes = s_min * (1.0 - rng.uniform(size=20000)) ** (-1.0 / (tau - 1.0))
    free = size_exponent(sizes, s_min)
    assert abs(free.tau - tau) < 3.0 * free.sigma
    cut = size_exponent(sizes, s_min, 50.0)  # truncated: the sizes above 50 dropped, the law the same
    assert abs(cut.tau - tau) < 3.0 * cut.sigma
    naive = 1.0 + 1.0 / np.mean(np.log(sizes[sizes <= 50.0] / s_min))  # ignoring the cut is biased
    assert naive > tau + 3.0 * cut.sigma


def test_recurrence_intervals_keep_only_the_large_events():
    assert recurrence_intervals([5.0, 1.0, 3.0, 9.0], [2.0, 3.0, 1.0, 2.5], 2.0).tolist() == [4.0, 4.0]
