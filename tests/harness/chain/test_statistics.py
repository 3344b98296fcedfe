"""Catalogue statistics (``harness.chain.statistics``) against samples of known law."""
import math

import numpy as np
import pytest

from harness.chain.statistics import b_value, catalogue_summary, completeness, recurrence_intervals, size_exponent


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


def test_the_statistics_recover_a_drawn_size_law_and_count_each_family():
    rng = np.random.default_rng(3)
    n_blocks, tau = 64, 1.7
    # Small forward events of potency ~ s^-tau above 0.5 (inverse transform), ten
    # system-wide events every 500 tau_0, and back-slips.
    small = 0.5 * rng.uniform(size=4000) ** (-1.0 / (tau - 1.0))
    sizes = np.concatenate([rng.integers(1, n_blocks // 2, size=small.size), np.full(10, n_blocks), [1, 2, 3]])
    potencies = np.concatenate([small, np.full(10, 1e4), [-0.5, -1.0, -0.2]])
    t_start = np.concatenate([rng.uniform(0, 5000, size=small.size), 250.0 + 500.0 * np.arange(10), [1.0, 2.0, 3.0]])
    measured = catalogue_summary(n_blocks, sizes, potencies, t_start)
    assert measured["events"] == small.size + 13 and measured["system_wide"] == 10
    assert measured["back_slips"] == 3 and measured["small_forward"] == small.size
    fit = measured["size_exponent"]
    assert fit["s_min"] == pytest.approx(np.quantile(small, 0.2))
    assert abs(fit["tau"] - tau) < 3 * fit["sigma"] + 0.02
    # Potency ~ s^-tau is magnitude M = (2/3) log10 s with b = (3/2)(tau - 1) above the
    # completeness (events below M_c missing are the fit's business).
    assert measured["b_value"]["b"] == pytest.approx(1.5 * (tau - 1.0), rel=0.15)
    assert measured["system_wide_recurrence"] == {"mean": pytest.approx(500.0), "std": pytest.approx(0.0, abs=1e-9)}


def test_too_few_events_give_a_stated_reason_not_a_number():
    measured = catalogue_summary(8, [8, 8], [100.0, 120.0], [10.0, 30.0])
    assert "too few" in measured["size_exponent"]["error"]
    assert measured["system_wide"] == 2 and measured["system_wide_recurrence"]["mean"] == 20.0
