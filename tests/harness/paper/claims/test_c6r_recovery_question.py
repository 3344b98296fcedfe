"""The recovery study (claim C6): predicted transition frequencies, located transitions
against them on model A (exact event-driven integrator), and the verdicts' criteria."""
from __future__ import annotations

import math

import pytest

from harness.paper.claims import RESOLUTIONS, Runner
from harness.paper.claims import c6r_recovery_question as recovery_study
from harness.paper.claims.verdicts import AGREES, DISAGREES
from harness.runs.sweep import Execution


@pytest.mark.parametrize("amplitude", [0.1, 0.3, 0.6])
def test_predicted_roots_match_the_undamped_closed_form(amplitude):
    # gamma_n = 0: A_c = A_N = (g/w^2)|k_n - m w^2| / k_n, so A_c(w) = A at
    # w^2 = g k_n / (A k_n + m g) below the resonance and g k_n / (m g - A k_n) above it.
    k_n, load = 2.0, 1.5
    found = recovery_study.predictions(amplitude, k_n=k_n, gamma_n=0.0, load=load)
    below = math.sqrt(load * k_n / (amplitude * k_n + load))
    above = math.sqrt(load * k_n / (load - amplitude * k_n))
    for roots in (found["A_c_roots"], found["A_N_roots"]):
        assert roots == pytest.approx([below, above], rel=1e-6)


def test_damping_adds_the_high_frequency_friction_loss():
    found = recovery_study.predictions(0.3)  # the paper's k_n = 1, gamma_n = 0.07
    assert len(found["A_c_roots"]) == 2 and len(found["A_N_roots"]) == 3
    assert found["A_N_roots"][2] > 10 * found["A_c_roots"][1]  # A_N falls as 1/omega: a third root


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory, fmu_dir):
    runner = Runner(tmp_path_factory.mktemp("recovery-store"), RESOLUTIONS["tiny"],
                    Execution(scheduler="inline", progress=False), fmus={m: fmu_dir / f"Block{m}.fmu" for m in "ABC"})
    return recovery_study.study_recovery(runner)


def test_model_a_loses_and_regains_friction_where_the_normal_force_first_reaches_zero(tiny_study):
    [row] = tiny_study.measured["rows"]
    assert row["configuration"] == "A, contact-force bound" and row["A"] == 0.3
    assert [t["kind"] for t in row["transitions"]] == ["loss", "recovery"]
    for transition, root in zip(row["transitions"], row["A_N_roots"][:2]):
        assert transition["resolution"] <= recovery_study.RECOVERY_RESOLUTION
        # The located bracket (widened by one resolution for the finite window) holds the root.
        assert transition["lo"] / 1.03 <= root <= transition["hi"] * 1.03
    # Friction comes back near omega = 1.19, a twelfth of k_n/gamma_n = 14.3.
    assert row["omega_2"] < 0.2 * row["k_n_over_gamma_n"]


def test_verdicts_follow_the_measurements(tiny_study):
    rows = {r.claim: r for r in recovery_study.verdict_rows(tiny_study.measured)}
    assert rows["C6r-a"].verdict == DISAGREES  # the flat plate recovers
    assert rows["C6r-b"].verdict == DISAGREES and "A_N root" in rows["C6r-b"].reason
    synthetic = {**tiny_study.measured, "rows": [
        {**tiny_study.measured["rows"][0], "A": a, "omega_2": 14.0, "closest_A_N_root": None,
         "closest_A_c_root": None} for a in (0.3, 0.6)]}
    rows = {r.claim: r for r in recovery_study.verdict_rows(synthetic)}
    assert rows["C6r-b"].verdict == AGREES  # at k_n/gamma_n and the same for both amplitudes


def test_the_figure_keeps_regime_colours_for_regimes_and_labels_off_the_markers():
    from types import SimpleNamespace

    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.colors import to_hex

    from harness.paper.claims import c6r_recovery_question as c6r
    from harness.paper.plots import REGIME_STYLE

    regained = next(kind for kind in ("regain", "recovery", "regained") if kind != c6r.LOSS)
    row = {"configuration": "model A", "k_n": c6r.K_N, "gamma_n": 0.07, "A": 0.3 * c6r.LOAD / c6r.K_N,
           "omegas": [0.5, 0.9, 1.5], "regimes": ["stick_slip", "sliding", "stick_slip"],
           "transitions": [{"kind": c6r.LOSS, "value": 0.87}, {"kind": regained, "value": 1.22}]}
    drawn = []
    c6r.draw(SimpleNamespace(measured={"rows": [row], "stiffness_rows": []}), lambda fig, name: drawn.append(fig))
    ax = drawn[0].axes[0]
    regime_colours = {to_hex(style["color"]) for style in REGIME_STYLE.values()}
    marks = [line for line in ax.lines if line.get_marker() in ("v", "^")]
    assert {to_hex(line.get_color()) for line in marks} == {to_hex("tab:brown"), to_hex("tab:cyan")}
    assert not {to_hex(line.get_color()) for line in marks} & regime_colours
    assert all(text.get_position() != text.xy and text.xyann == (0, 7) for text in ax.texts)
    assert "[$\\tau_0^{-1}$]" in ax.get_xlabel() and "[$\\delta_0$]" in ax.get_ylabel()
    labels = ax.get_legend_handles_labels()[1]
    assert "friction lost (located)" in labels and "friction regained (located)" in labels
