"""The work-precision benchmark's verdicts on synthetic rows (method, setting, seconds,
error, per-observable errors): which run a ratio at equal accuracy rests on."""
from __future__ import annotations

import math

from harness.benchmarks import work_precision as wp


def _row(method, setting, seconds, error):
    return (method, setting, seconds, error, {"x": error})


ADAPTIVE = [_row("adaptive", "rtol 1e-06", 0.01, 3e-6), _row("adaptive", "rtol 1e-08", 0.02, 2e-8)]


def test_time_at_accuracy_is_the_fastest_run_that_reaches_the_level():
    assert wp.time_at_accuracy(ADAPTIVE, "adaptive", 1e-6) == (0.02, False)


def test_time_at_accuracy_extrapolates_along_the_runs_or_says_not_reached():
    rows = [_row("rk4", "dt 0.01", 1.0, 1e-2), _row("rk4", "dt 0.001", 10.0, 1e-4)]
    seconds, extrapolated = wp.time_at_accuracy(rows, "rk4", 1e-6)
    assert extrapolated and math.isclose(seconds, 100.0, rel_tol=1e-9)  # one decade of time per two of error
    stuck = [_row("rk4", "dt 0.01", 1.0, 1e-2), _row("rk4", "dt 0.001", 10.0, 2e-2)]
    assert math.isinf(wp.time_at_accuracy(stuck, "rk4", 1e-6)[0])


def test_a_method_that_never_reaches_the_level_is_bounded_by_its_longest_run():
    # The most accurate run is not the longest: the bound must come from the longest one,
    # which still missed the level (so reaching it costs more).
    euler = [_row("symplectic_euler", "dt 3e-06", 1.8, 1.5e-4), _row("symplectic_euler", "dt 1e-06", 5.7, 1.6e-4)]
    peers = [_row("solve_ivp DOP853", "rtol 1e-08", 0.9, 5e-7), _row("solve_ivp RK45", "rtol 1e-06", 0.5, 1e-5)]
    (line,) = wp.adaptive_targets({"B test": (ADAPTIVE + euler + peers, 1e-9)})
    assert "symplectic_euler never reached it (its best error 1.5e-04)" in line
    assert "dt 1e-06, error 1.6e-04, 5.7 s) already takes 285x adaptive's time" in line
    assert "solve_ivp DOP853 measured 0.9 s: 45x (target >= 30x)" in line


def test_model_a_reports_adaptive_as_users_get_it_and_on_its_own_steps():
    event_driven = [_row("event_driven", "dt 0.001", 0.001, 1e-9)]
    exact = [_row("adaptive", "rtol 1e-06", 0.0011, 1e-9), _row("adaptive", "rtol 1e-08", 0.0012, 1e-9)]
    own = [_row(wp.OWN_STEPS, "rtol 1e-06", 0.05, 5e-7), _row(wp.OWN_STEPS, "rtol 1e-08", 0.08, 4e-9)]
    (line,) = wp.adaptive_targets({"A test": (event_driven + exact + own, 1e-10)})
    assert "1.1 ms vs event_driven 1 ms (error 1.0e-09): 1.1x its time (target <= 10x)" in line
    assert "On its own steps (exact_flows off): 50 ms, 50x; tightest (rtol 1e-08) error 4.0e-09, 80 ms" in line
