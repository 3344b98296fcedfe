"""The claims report is computed from measured values (synthetic and from a tiny main job)."""
from __future__ import annotations

import json
import math

import pytest

from harness import report
from harness.claims import Study, load_studies, recovery, stable_roots_near, transition_bracket
from harness.report import AGREES, DISAGREES, NOT_REPRODUCED


def c1_values(stick_time: float) -> dict:
    return {"rest_penetration": 1.0, "rest_penetration_formula": 1.0, "creep_velocity": 3.45e-4,
            "creep_velocity_formula": 3.4483e-4, "stick_time": stick_time, "stick_time_formula": 5178.6,
            "slip_length": 49.0, "slip_length_formula": 50.0, "slip_events": 3, "regime": "stick_slip"}


def test_c1_verdict_follows_the_tolerance():
    assert report.verdict_c1(c1_values(5000.0)).verdict == AGREES
    row = report.verdict_c1(c1_values(3000.0))
    assert row.verdict == DISAGREES and "stick time off by 42%" in row.reason
    assert report.verdict_c1({**c1_values(5000.0), "creep_velocity": None}).verdict == NOT_REPRODUCED


def c2_values(interval_at_a: float) -> dict:
    return {"omega": 0.25, "amplitudes": [0.0, 8.0], "peak_acceleration_over_g": [0.0, 0.5],
            "slip_interval": [5000.0, interval_at_a], "stick_time": [4600.0, interval_at_a - 400.0],
            "slip_length": [49.0, 49.0 * interval_at_a / 5000.0], "slip_events": [3, 3],
            "regime": ["stick_slip", "stick_slip"]}


def test_c2_agrees_when_unchanged_and_disagrees_when_shortened():
    assert report.verdict_c2(c2_values(4900.0)).verdict == AGREES
    row = report.verdict_c2(c2_values(3700.0))
    assert row.verdict == DISAGREES and "26%" in row.reason
    assert "3.7e+03" in row.measured


def c3_column(omega, low, high, changes=1):
    from harness.claims import onset_amplitude

    return {"omega": omega, "regimes": [], "last_friction_A": low, "first_sliding_A": high, "changes": changes,
            "paper_line": 1 / omega**2, "onset_curve": float(onset_amplitude(omega))}


def test_c3_bracket_tests():
    amplitudes = [0.1, 1.0, 10.0, 100.0, 1000.0]
    good = {"amplitudes": amplitudes, "columns": [c3_column(0.1, 10.0, 100.0 * 1.01), c3_column(1.0, 0.01, 0.1)]}
    row_a, row_b = report.verdict_c3(good)
    assert row_a.verdict == AGREES
    assert row_b.verdict == AGREES  # A_c(1) = 0.07 lies in (0.01, 0.1]; g/w^2 = 1 does not
    bad = {"amplitudes": amplitudes, "columns": [c3_column(0.1, 1000.0, None), c3_column(1.0, 0.01, 0.1, 3)]}
    row_a, row_b = report.verdict_c3(bad)
    assert row_a.verdict == DISAGREES and "1 column(s) with more than one transition" in row_a.reason
    assert row_b.verdict == DISAGREES


def c4_values(stars):
    return {"amplitude": 10.0, "omega_step": 0.05, "fresh_gamma_n": 0.07, "omegas": [0.2, 0.25, 0.3, 0.35],
            "down_differs_from_fresh_orbit": [0.25], "up_differs_from_fresh_impact": [],
            "fresh_steady_orbit": [], "fresh_equilibrium": [],
            "per_gamma": [{"gamma_n": g, "omega_1": 0.35, "omega_star": s, "onset_omega": 0.3}
                          for g, s in zip((0.035, 0.07, 0.14), stars)]}


def test_c4_hysteresis_criteria():
    assert report.verdict_c4(c4_values([0.2, 0.25, 0.3])).verdict == AGREES
    no_loop = report.verdict_c4(c4_values([0.35, 0.35, 0.35]))
    assert no_loop.verdict == DISAGREES and "w* < w1 for 0/3" in no_loop.reason
    growing = report.verdict_c4(c4_values([0.3, 0.25, 0.2]))
    assert growing.verdict == DISAGREES
    assert report.verdict_c4(c4_values([None, 0.25, 0.3])).verdict == NOT_REPRODUCED


def test_c8_offset_sign():
    def values(x0):
        return {"omegas": [1.0], "model_a": [{"V_d": 10.0, "regimes": ["sliding"]}],
                "model_c": [{"V_d": 10.0, "regimes": ["sliding"]}], "model_a_amplitude": 2.0,
                "model_c_amplitude": 2e4,
                "offsets": [{"V_d": 10.0, "x0": x0, "x0_std": 0.1, "force_balance": 30.0, "paper": -20.0,
                             "regime": "sliding"}]}
    sliding, offset = report.verdict_c8(values(30.0))
    assert sliding.verdict == AGREES and offset.verdict == DISAGREES and "+, not -" in offset.reason
    assert report.verdict_c8(values(-20.5))[1].verdict == AGREES


def test_helpers_on_known_cases():
    assert transition_bracket([1, 2, 3], ["stick_slip", "stuck", "sliding"]) == (2.0, 3.0)
    assert transition_bracket([1, 2], ["stick_slip", "stick_slip"]) == (2.0, None)
    found = recovery([1, 2, 3, 4], ["stuck", "sliding", "sliding", "stick_slip"])
    assert (found["omega_1"], found["omega_2"], found["last_sliding"]) == (2.0, 4.0, 3.0)
    # K small: the stable root near the valley (sin < 0) at drive = x.
    root = stable_roots_near(3 * math.pi / (2 * 0.02), 3 * math.pi / (2 * 0.02), -5e-4)
    assert math.sin(0.02 * root) < 0 and abs(math.cos(0.02 * root)) < 1e-3


@pytest.fixture(scope="module")
def tiny_job(tmp_path_factory, fmu_dir):
    from harness.main import main

    out = tmp_path_factory.mktemp("main_job")
    path = main(["--resolution", "tiny", "--scheduler", "inline", "--out", str(out), "--fmu-dir", str(fmu_dir),
                 "--no-progress"])
    return out, path


def test_tiny_main_job_writes_a_report_from_its_measurements(tiny_job):
    out, path = tiny_job
    text = path.read_text()
    studies = load_studies(out / "claims.json")
    assert set(studies) == {"Fig1b"} | {f"C{n}" for n in range(1, 9)}
    rows = report.claim_rows(studies)
    for row in rows:
        assert f"| {row.claim} |" in text
        assert f"**{row.verdict}**" in text
        assert row.verdict in (AGREES, DISAGREES, NOT_REPRODUCED)
    c1 = studies["C1"].measured
    assert f"stick time {report._fmt(c1['stick_time'])} vs" in text
    assert c1["rest_penetration"] == pytest.approx(1.0, rel=0.02)
    # x0 of stationary sliding carries the force-balance sign, so the paper's printed form fails.
    assert next(r for r in rows if r.claim == "C8b").verdict == DISAGREES
    for name in ("fig1b.png", "fig1c_phase_diagram_A.png", "hysteresis_gamma_n.png", "model_b_x_t.png",
                 "model_c_phase_diagram.png", "omega2_vs_k_n.png", "model_c_Vd_omega.png"):
        assert (out / name).stat().st_size > 0 and f"]({name})" in text
    assert "phi_threshold: 10" in text and "transient: 4000" in text


def test_changed_measurement_changes_the_report(tiny_job):
    out, _ = tiny_job
    studies = load_studies(out / "claims.json")
    studies["C1"].measured["slip_length"] = 10.0
    text = report.markdown(studies)
    assert "slip length off by 80%" in text
    assert next(r for r in report.claim_rows(studies) if r.claim == "C1").verdict == DISAGREES
