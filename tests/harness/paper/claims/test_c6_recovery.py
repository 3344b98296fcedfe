"""C6: both transitions of a diagram row bisected in omega, and the verdicts on located values."""
from __future__ import annotations

import dataclasses
import math

import pytest

from harness.paper.claims import c6_recovery
from harness.paper.claims.c6_recovery import BOUNDARY_RESOLUTION, RECOVERY_SLACK, verdict_c6
from harness.paper.claims.measure import recovery
from harness.paper.claims.verdicts import AGREES, DISAGREES, NOT_REPRODUCED
from harness.runs.settings import PointSettings, RunSettings


class Regimes:
    """Stands in for the runner: classifies a run by its (A, omega) from known boundaries."""

    def __init__(self, loss, back):
        self.loss, self.back, self.batches = loss, back, []

    def tasks(self, function, items):
        self.batches.append(len(items))
        return [{"observables": {"regime": self.regime(float(i["point"].run.parameters["A"]),
                                                         float(i["point"].run.parameters["omega"]))}}
                for i in items]

    def regime(self, amplitude, omega):
        return "sliding" if self.loss(amplitude) < omega < self.back(amplitude) else "stick_slip"


def test_each_rows_loss_and_recovery_are_bisected_to_the_resolution():
    loss, back = (lambda a: 1 / math.sqrt(a)), (lambda a: 14.0 + a)
    runner = Regimes(loss, back)
    omegas = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
    rows = []
    for amplitude in (0.3, 3.0):
        rows.append({"A": amplitude, **recovery(omegas, [runner.regime(amplitude, w) for w in omegas])})
    base = PointSettings(run=RunSettings(parameters={"A": 0.0, "omega": 1.0}))
    c6_recovery._locate_transitions(runner, base, rows)
    for row in rows:
        lo, hi = row["located_omega_1_bracket"]
        assert lo < loss(row["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION
        lo, hi = row["located_omega_2_bracket"]
        assert lo < back(row["A"]) <= hi and hi / lo - 1 <= BOUNDARY_RESOLUTION
    # All brackets of a round go out as one batch.
    assert runner.batches[0] == 4


def row(amplitude, omega_1, omega_2, located_1=None, located_2=None):
    return {"A": amplitude, "omega_1": omega_1, "last_friction_before_1": omega_1 / 3, "omega_2": omega_2,
            "last_sliding": omega_2 / 3 if omega_2 else None, "first_transition_paper": 1 / math.sqrt(amplitude),
            "first_transition_onset": None, "located_omega_1": located_1, "located_omega_2": located_2}


def measured(rows):
    return {"k_n_over_gamma_n": 1 / 0.07, "frictionless": {"regime": "sliding", "slip_events": 0, "phi": 0.0,
                                                           "drift_velocity": 0.01},
            "diagram_rows": rows, "omegas": [], "resolution": BOUNDARY_RESOLUTION, "stiffness_amplitude": 0.5,
            "recovery_vs_k": [], "ramp_amplitude": 0.5, "ramp_values": [], "ramp_up_omega_2": None,
            "ramp_down_omega_2": None, "ramp_up_regimes": [], "ramp_down_regimes": []}


@pytest.mark.parametrize("located, verdict", [(1.0 / math.sqrt(3.0) * 1.05, AGREES),
                                              (1.0 / math.sqrt(3.0) * 1.3, DISAGREES)])
def test_the_first_transition_is_judged_against_the_located_loss(located, verdict):
    rows = {r.claim: r for r in verdict_c6(measured([row(3.0, 1.0, 15.0, located_1=located)]))}
    assert rows["C6b"].verdict == verdict


def test_recovery_is_judged_on_located_values_near_k_n_over_gamma_n_and_alike_across_a():
    ratio = 1 / 0.07
    alike = [row(0.3, 3.0, 30.0, located_2=ratio * 1.05), row(3.0, 1.0, 30.0, located_2=ratio * 1.08)]
    assert {r.claim: r for r in verdict_c6(measured(alike))}["C6c"].verdict == AGREES
    far = [row(0.3, 3.0, 30.0, located_2=ratio * (1 + 2 * RECOVERY_SLACK)), row(3.0, 1.0, 30.0, located_2=ratio)]
    c6c = {r.claim: r for r in verdict_c6(measured(far))}["C6c"]
    assert c6c.verdict == DISAGREES and "within 25% of k_n/gamma_n in 1/2" in c6c.reason


def test_independence_of_a_is_not_claimed_from_one_row():
    """With omega_2 at one amplitude its spread over the rows is 0 whatever was measured:
    that check cannot fail, so it is not counted, and the reason says it was not tested."""
    ratio = 1 / 0.07
    one = {r.claim: r for r in verdict_c6(measured([row(0.3, 3.0, 30.0, located_2=ratio * 1.05)]))}["C6c"]
    assert "of its mean over the rows" not in one.reason
    assert "independence of A not tested (omega_2 found at one amplitude only)" in one.reason
    two = [row(0.3, 3.0, 30.0, located_2=ratio * 1.05), row(3.0, 1.0, 30.0, located_2=ratio * 1.5)]
    spread = {r.claim: r for r in verdict_c6(measured(two))}["C6c"]
    assert "of its mean over the rows" in spread.reason and spread.verdict == DISAGREES


# ------------------------------------------------------------ the start-phase ensemble
def test_the_start_phases_are_the_crest_both_flanks_and_the_valley():
    from harness.paper.claims.measure import OMEGA_X, START_PHASES
    height = {name: math.sin(OMEGA_X * x) for name, x in START_PHASES.items()}
    slope = {name: math.cos(OMEGA_X * x) for name, x in START_PHASES.items()}
    assert height["crest"] == pytest.approx(1) and height["valley"] == pytest.approx(-1)
    # Flanks at mid height, the surface going down then up along the drive (+x).
    assert height["descending flank"] == pytest.approx(0, abs=1e-12) and slope["descending flank"] == pytest.approx(-1)
    assert height["ascending flank"] == pytest.approx(0, abs=1e-12) and slope["ascending flank"] == pytest.approx(1)


class StartDependent(Regimes):
    """Regimes from known boundaries, except that ``slides_from`` (a start x) slides everywhere."""

    def __init__(self, loss, back, slides_from=None):
        super().__init__(loss, back)
        self.slides_from, self.runs = slides_from, []

    def run(self, model, **fields):
        return RunSettings(**fields)

    def tasks(self, function, items):
        self.runs += [i["point"] for i in items]
        out = []
        for i in items:
            run = i["point"].run
            regime = ("sliding" if run.initial.x_start == self.slides_from else
                      self.regime(float(run.parameters["A"]), float(run.parameters["omega"])))
            out.append({"observables": {"regime": regime, "phi": 1.0, "contact_fraction": 1.0, "drift_velocity": 0.0}})
        return out


def _located_rows(runner, omegas=(0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)):
    rows = [{"A": 0.3, **recovery(list(omegas), [runner.regime(0.3, w) for w in omegas])}]
    c6_recovery._locate_transitions(runner, PointSettings(run=RunSettings(parameters={"A": 0.0, "omega": 1.0})), rows)
    return rows


@pytest.mark.parametrize("slides_from", [None, "valley"])
def test_both_sides_of_each_located_transition_are_rerun_from_four_starts_over_long_windows(slides_from):
    from harness.paper.claims.measure import SCALED, START_PHASES, WAVELENGTH
    loss, back = (lambda a: 1 / math.sqrt(a)), (lambda a: 14.0 + a)
    runner = StartDependent(loss, back, START_PHASES.get(slides_from))
    rows = _located_rows(runner)
    runner.runs.clear()
    ensemble = c6_recovery._check_by_start_ensemble(runner, rows, wavelengths=3.0)
    travel = WAVELENGTH / SCALED["V_d"]
    # 2 transitions x 2 sides x 4 starts, each with a 3-wavelength window after its transient.
    assert len(runner.runs) == 16
    assert {p.run.initial.x_start for p in runner.runs} == set(START_PHASES.values())
    assert all(p.run.horizon - p.observe.transient >= 3.0 * travel for p in runner.runs)
    assert all(p.run.start_time * SCALED["V_d"] == pytest.approx(p.run.initial.x_start) for p in runner.runs)
    omegas = {(c["transition"], c["side"]): c["omega"] for c in ensemble["checks"]}
    assert omegas[("omega_1", "below")] < loss(0.3) <= omegas[("omega_1", "above")]
    assert omegas[("omega_2", "below")] < back(0.3) <= omegas[("omega_2", "above")]
    # From the valley everything slides: the sides where the diagram holds friction fail.
    failing = {(c["transition"], c["side"]) for c in ensemble["checks"] if not c["agrees"]}
    assert failing == (set() if slides_from is None else {("omega_1", "below"), ("omega_2", "above")})

    m = measured([{**rows[0], "first_transition_paper": loss(0.3), "first_transition_onset": None}])
    m["start_ensemble"] = ensemble
    verdicts = {r.claim: r for r in verdict_c6(m)}
    if slides_from is None:
        assert verdicts["C6b"].verdict == AGREES and "keep their class" in verdicts["C6b"].reason
    else:
        assert verdicts["C6b"].verdict == NOT_REPRODUCED and verdicts["C6c"].verdict == NOT_REPRODUCED
        assert "valley sliding" in verdicts["C6b"].reason


def test_the_start_ensemble_gets_a_figure_with_one_marker_per_start_and_side():
    import matplotlib
    matplotlib.use("Agg")
    from harness.paper.claims.measure import START_PHASES

    loss, back = (lambda a: 1 / math.sqrt(a)), (lambda a: 14.0 + a)
    runner = StartDependent(loss, back, START_PHASES.get("valley"))
    ensemble = c6_recovery._check_by_start_ensemble(runner, _located_rows(runner), wavelengths=3.0)
    fig = c6_recovery.draw_start_ensemble(ensemble)
    ax = fig.axes[0]
    assert sum(len(c.get_offsets()) for c in ax.collections) == 4 * len(START_PHASES)
    ticks = [t.get_text() for t in ax.get_xticklabels()]
    assert len(ticks) == 4 and any("NOT confirmed" in t for t in ticks) and all("tau_0^{-1}" in t for t in ticks)
    assert "phi" in ax.get_ylabel() and ax.get_yscale() == "log"
    assert "start_ensemble.png" in c6_recovery.FIGURES["C6b"] and "start_ensemble.png" in c6_recovery.FIGURES["C6c"]


def test_the_figures_for_the_papers_figs_5_and_6_say_they_run_the_scaled_drive_and_draw_both_onsets():
    import matplotlib

    matplotlib.use("Agg")
    from harness.paper.claims.study import Study

    omegas, amplitudes = [0.5, 5.0, 50.0], [0.3, 3.0]
    study = Study("C6", {"k_n_over_gamma_n": 14.3, "diagram_rows": [row(0.3, 5.0, 50.0, 5.2, 40.0)]}, {},
                  {"omega": omegas, "A": amplitudes, "regime": [["stick_slip", "sliding", "stick_slip"]] * 2,
                   "recovery_vs_k": [{"ratio": 14.3, "k_n": 1.0, "omega_2": 12.0},
                                     {"ratio": 14.3, "k_n": 2.0, "omega_2": None}]})
    titles, legends = {}, {}

    def save(figure, name):
        titles[name] = figure.axes[0].get_title()
        legends[name] = figure.axes[0].get_legend_handles_labels()[1]

    c6_recovery.draw(study, save)
    assert set(titles) == {"model_c_phase_diagram.png", "omega2_vs_k_n.png"}
    # Both onsets on the diagram: detachment A_c and friction loss A_N.
    diagram = legends["model_c_phase_diagram.png"]
    assert any("A_c" in label for label in diagram) and any("A_N" in label for label in diagram)
    assert "Fig. 5" in titles["model_c_phase_diagram.png"] and "Fig. 6" in titles["omega2_vs_k_n.png"]
    assert all("scaled drive" in title and "fig5_paper" in title for title in titles.values())


def test_the_rows_bracket_the_roots_linear_theory_predicts():
    """The predicted roots solve A_c(omega) = A and A_N(omega) = A of the closed forms
    (harness.paper.analytic, independent of vibroblock.orbits), and the extra omegas put
    each between two runs."""
    from harness.paper.analytic import detachment_amplitude, friction_loss_amplitude
    from harness.paper.claims.c6_recovery import BRACKET, theory_roots

    for amplitude in (0.3, 1.0, 3.0, 10.0):
        theory = theory_roots(amplitude)
        assert theory["paper_omega_1"] == pytest.approx((1.0 / amplitude) ** 0.5)
        for root in theory["A_c_roots"]:
            assert detachment_amplitude(root) == pytest.approx(amplitude, rel=1e-3)
        for root in theory["A_N_roots"]:
            assert friction_loss_amplitude(root) == pytest.approx(amplitude, rel=1e-3)
        for root in [theory["paper_omega_1"], *theory["A_c_roots"], *theory["A_N_roots"]]:
            assert any(w < root for w in theory["bracketed"]) and any(w > root for w in theory["bracketed"])
            assert min(abs(w / root - BRACKET) for w in theory["bracketed"]) < 1e-3
    # Below delta_0 friction is lost in a band only: two roots, the upper one its recovery.
    assert len(theory_roots(0.3)["A_c_roots"]) == 2 and len(theory_roots(3.0)["A_c_roots"]) == 1
    # The figures of the brief: sqrt(P_l/(m A)) against the A_c root, 107 % at A = 0.3 and 5 % at 10.
    for amplitude, gap in ((0.3, 1.07), (10.0, 0.05)):
        theory = theory_roots(amplitude)
        assert theory["paper_omega_1"] / theory["A_c_roots"][0] - 1 == pytest.approx(gap, abs=0.02)


def test_under_a_law_reading_c6_judges_fig_5_s_parts_only():
    """The law readings measure the diagram (C6a-C6c), not the k_n sweep or the ramp: their
    parts are left out, not judged 'not reproduced' on data that was never taken."""
    paper = measured([row(3.0, 1.0, 15.0, located_1=0.6, located_2=14.5)])
    law = dict(paper, fig5_only=True)
    assert {r.claim for r in verdict_c6(paper)} == {"C6a", "C6b", "C6c", "C6d", "C6e"}
    assert {r.claim for r in verdict_c6(law)} == {"C6a", "C6b", "C6c"}
    assert ([r.verdict for r in verdict_c6(law)] == [r.verdict for r in verdict_c6(paper)][:3])


class Diagram(Regimes):
    """``Regimes`` with the sweep of a grid: a runner for the whole study, recording what it was asked."""

    reading = None
    resolution = None
    asked: list

    def sweep(self, grid, base):
        import numpy as np
        import xarray as xr

        self.asked.append(("sweep", tuple(a.name for a in grid.axes)))
        names = [a.name for a in grid.axes]
        values = [np.asarray(a.values, dtype=float) for a in grid.axes]
        mesh = np.meshgrid(*values, indexing="ij")
        regimes = np.vectorize(lambda a, w: self.regime(a, w), otypes=[object])(mesh[0], mesh[1])
        return xr.Dataset({"regime": (names, regimes)}, coords=dict(zip(names, values)))

    def tasks(self, function, items):
        self.asked.append(("tasks", function.__name__, len(items)))
        return [{"observables": {"regime": self.regime(float(i["point"].run.parameters["A"]),
                                                       float(i["point"].run.parameters["omega"])),
                                 "slip_events": 0, "phi": 0.0, "drift_velocity": 0.01}} for i in items]


def test_a_law_reading_s_c6_runs_the_diagram_and_not_the_k_n_sweep_or_the_ramp(monkeypatch):
    """Run end to end on a stand-in runner: under a law reading the study asks for one sweep
    (the A-omega diagram) and no ramp, and its verdicts are C6a-C6c."""
    from harness.paper.claims.readings import LAW_READINGS
    from harness.paper.claims.study import RESOLUTIONS

    runner = Diagram(lambda a: 1 / math.sqrt(max(a, 1e-9)), lambda a: 14.0 + a)
    runner.asked, runner.reading = [], LAW_READINGS[0]
    runner.resolution = dataclasses.replace(RESOLUTIONS["tiny"], ensemble_wavelengths=0.0)
    monkeypatch.setattr(c6_recovery, "c_run", lambda r, horizon, **p: RunSettings(parameters={"A": 0.0, "omega": 1.0,
                                                                                              **p}))
    study = c6_recovery.study_c6(runner)
    assert [a for a in runner.asked if a[0] == "sweep"] == [("sweep", ("A", "omega"))]
    assert not [a for a in runner.asked if a[0] == "tasks" and a[1] == "ramp_task"]
    assert {r.claim for r in verdict_c6(study.measured)} == {"C6a", "C6b", "C6c"}
