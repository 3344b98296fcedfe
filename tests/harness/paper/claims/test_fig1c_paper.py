"""Fig. 1c at the paper's parameters: its slip count from sparse samples and its summary."""
from __future__ import annotations

import pytest

from harness.paper.claims.fig1c_paper import SLIP_ADVANCE, cycle_time, describe, sampled_slips


def test_the_cycle_time_is_the_paper_parameters_stick_time():
    # mu_s m g / (k_t V_S), V_S = V_d k_d / (k_t + k_d) with k_t = 0.28, k_d = 5e-4, V_d = 2e-5.
    assert cycle_time() == pytest.approx(0.5 / (0.28 * 2e-5 * 5e-4 / 0.2805), rel=1e-12)


def test_slips_are_runs_of_sample_intervals_that_advance_more_than_the_creep():
    creep = 0.01 * SLIP_ADVANCE
    x = [0.0]
    for advance in (creep, creep, 500.0, 400.0, creep, creep, 900.0, creep, 2 * SLIP_ADVANCE):
        x.append(x[-1] + advance)
    assert sampled_slips(x) == 3  # 500 + 400 is one slip split over two samples
    assert sampled_slips([0.0, 800.0, 800.01]) == 1 and sampled_slips([0.0, creep]) == 0


def test_the_summary_brackets_each_column_and_names_the_lines_inside():
    points = [{"A": a, "omega": w, "regime": "stick_slip" if a * w * w < 1.0 else "sliding"}
              for a in (0.3, 3.0, 30.0, 300.0) for w in (0.1, 1.0)]
    text = describe({"points": points, "cycle_time": 5e7, "fewest_slips_at_stick_slip": 3})
    assert "at least 3 slips" in text
    assert "w = 0.1: held up to A = 30, not from 300 (g/w^2, A_c inside; 1 change(s) along A)" in text
    # At omega = 1 the onset A_c (0.07) lies below the bracket [0.3, 3]: only g/omega^2 is inside.
    assert "w = 1: held up to A = 0.3, not from 3 (g/w^2 inside; 1 change(s) along A)" in text
    assert describe({"points": [], "cycle_time": 5e7, "fewest_slips_at_stick_slip": None}) == \
        "not run at this resolution"
