"""C5: the paper's Eq. (9) solved graphically (Fig. 4), on synthetic traces."""
from __future__ import annotations

import math

import numpy as np
import pytest

from harness.paper.claims.c5_corrugated_plate import draw_fig4, eq9_roots, eq9_slope, spread
from harness.paper.claims.measure import stable_roots_near, stick_sites
from harness.paper.claims.study import Study


def test_eq9_roots_solve_the_equation_and_stable_ones_are_those_the_study_measures_against():
    k_ratio, omega_x, drive = eq9_slope(), 0.02, 123.0
    assert k_ratio == pytest.approx(-1e-2 / (1e3 * 0.02))
    stable, unstable = eq9_roots(drive, k_ratio, omega_x, -500.0, 500.0)
    assert len(stable) >= 2 and len(unstable) >= 2
    for root in stable + unstable:
        assert math.cos(omega_x * root) == pytest.approx(k_ratio * (root - drive), abs=1e-6)
    for root in stable:
        assert math.sin(omega_x * root) < 0
        assert stable_roots_near(root, drive, k_ratio, omega_x) == pytest.approx(root, abs=0.5)
    assert all(math.sin(omega_x * r) > 0 for r in unstable)


def test_stick_sites_come_from_stuck_samples_and_three_are_spread_over_the_run():
    t = np.arange(0.0, 1000.0)
    x = np.interp(t, [0, 200, 250, 500, 550, 800, 850, 999], [0, 0, 50, 50, 100, 100, 150, 150])
    # An oscillation sampled at its own period looks still in x, but its velocity is not small.
    vx = np.gradient(x, t) + np.where((t > 500) & (t < 800), np.cos(t), 0.0)
    sites = stick_sites(t, x, vx, v_d=0.01)
    assert sites and all(abs(np.interp(ts, t, vx)) < 0.002 for ts, _ in sites)
    assert not any(500 < ts < 800 for ts, _ in sites)
    chosen = spread(sites)
    assert [x for _, x in chosen] == [0.0, 50.0, 150.0] or len({x for _, x in chosen}) == 3
    assert chosen[0][0] == sites[0][0] and chosen[-1][0] == sites[-1][0]
    assert stick_sites(t, 0.1 * t, np.full_like(t, 0.1), v_d=0.01) == [] and spread([]) == []


def test_fig4_is_drawn_from_the_k_t_zero_trace(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    t = np.arange(0.0, 1000.0)
    x = np.interp(t, [0, 300, 350, 999], [230, 230, 540, 540])
    study = Study("C5", {"V_d": 1e-2, "wavelength": 2 * math.pi / 0.02, "omega_x": 0.02, "eq9_slope": eq9_slope()},
                  {}, {"frictionless_stick_sites": stick_sites(t, x, np.gradient(x, t), v_d=1e-2)})
    saved = []
    draw_fig4(study, lambda fig, name: (fig.savefig(tmp_path / name), saved.append(name)))
    assert saved == ["fig4_eq9_roots.png"] and (tmp_path / "fig4_eq9_roots.png").stat().st_size > 10_000


def c5_measured(reference: dict, vibrated: dict) -> dict:
    def run(a, **values):
        return {"A": a, "peak_acceleration_over_g": a * 0.25, "regime": "stick_slip", "slip_events": 3,
                "slip_interval": 1000.0, "slip_length": 50.0, "drift_velocity": 0.01, "contact_fraction": 1.0,
                "slope_angle_end": 10.0, "max_x_difference": 0.0, "root_distance_median": 1.0, **values}
    return {"runs": [run(0.0, **reference), run(5.0, **vibrated)], "wavelength": 314.0,
            "frictionless": {"regime": "stick_slip", "slip_events": 2, "slip_length": 70.0,
                             "root_distance_median": 1.0, "root_distance_p90": 2.0}}


def test_c5a_compares_the_cycle_with_a_0_and_says_why_when_a_0_has_none():
    from harness.paper.claims.c5_corrugated_plate import verdict_c5
    from harness.paper.claims.verdicts import AGREES, DISAGREES, NOT_REPRODUCED

    assert verdict_c5(c5_measured({}, {"slip_interval": 1050.0}))[0].verdict == AGREES
    assert verdict_c5(c5_measured({}, {"slip_length": 70.0}))[0].verdict == DISAGREES
    jammed = verdict_c5(c5_measured({"regime": "jammed", "slip_interval": None, "slope_angle_end": 82.7}, {}))[0]
    assert jammed.verdict == NOT_REPRODUCED and "jams" in jammed.reason and "82.7" in jammed.reason
    short = verdict_c5(c5_measured({"slip_interval": None, "slope_angle_end": 81.0}, {}))[0]
    assert short.verdict == NOT_REPRODUCED and "fewer than two" in short.reason and "81" in short.reason
    assert "A = 0 (A w^2/g = 0): jammed" in jammed.measured


def test_c5c_without_friction_runs_past_the_eq9_fold_and_a_rest_there_is_stuck_not_jammed():
    """k_t = 0 cannot self-lock: the run lasts past the fold of Eq. (9), the stretch
    A_x omega_x m g / k_d = 2000 at V_d = 1e-2 (t = 2e5), and a block still at rest is
    reported as stuck with the run's length."""
    from harness.paper.claims.c5_corrugated_plate import FOLD_MARGIN, frictionless_horizon, verdict_c5
    from harness.paper.claims.verdicts import NOT_REPRODUCED

    assert frictionless_horizon(1e5) == pytest.approx(FOLD_MARGIN * 2e5)
    assert frictionless_horizon(1e6) == 1e6
    measured = c5_measured({}, {})
    measured["frictionless"].update(regime="stuck", slip_events=0, horizon=2.5e5)
    row = verdict_c5(measured)[2]
    assert row.verdict == NOT_REPRODUCED and "Eq. 9" in row.reason and "2.5e+05" in row.reason
