"""C3 -- model A's A-omega phase diagram (Fig. 1c): the onset of sliding.

The grid brackets each column's friction/sliding boundary; each bracket is then bisected
in A (:mod:`harness.runs.bisection`) to ``BOUNDARY_RESOLUTION``, all columns together.

Criteria: C3a: every column with omega <= ``LOW_OMEGA`` has its located boundary within
``FORMULA_TOLERANCE`` of A = g/omega^2 (within the grid bracket where nothing was
located), and no column changes regime more than once along A.  C3b: the same test for
A_c(omega) on every column."""
from __future__ import annotations

from typing import Sequence

from harness.paper.plots import regime_grid
from harness.runs.bisection import Transition, refine
from harness.runs.settings import PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import (OBSERVE_A, SCALED, friction_held, loss_amplitude, observe_json, onset_amplitude, regime_changes,
                      run_and_measure, transition_bracket)
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, FORMULA_TOLERANCE, NOT_REPRODUCED, Row, combine, fmt

LOW_OMEGA = 0.3
BOUNDARY_RESOLUTION = 0.03  # relative width in A of a located boundary

TEXT = {
    "C3a": "A: stick-slip -> sliding at A omega^2 = g (omega << omega_n), the only transition in A",
    "C3b": "A: refined onset A_c(omega) = (g/omega^2)|k_n - m omega^2 + i gamma_n omega|/k_n",
}
FIGURES = {
    "C3a": ["fig1c_phase_diagram_A.png", "fig1c_paper_parameters.png"],
    "C3b": ["fig1c_phase_diagram_A.png", "fig1c_paper_parameters.png"],
}


def _bracketed(column: dict, line: float, amplitudes: Sequence[float]) -> bool:
    """The line agrees with the column's boundary: within FORMULA_TOLERANCE of the located
    boundary, or (nothing located) between the grid amplitudes that bracket it."""
    if column.get("located_A") is not None:
        return abs(column["located_A"] / line - 1.0) <= FORMULA_TOLERANCE
    low, high = column["last_friction_A"], column["first_sliding_A"]
    if high is None:
        return line > max(amplitudes)
    return (low is None or low <= line) and line <= high


def study_c3(runner: Runner) -> Study:
    """Model A: A-omega phase diagram (Fig. 1c) against A = g/omega^2 and A_c(omega)."""
    res = runner.resolution
    base = PointSettings(run=runner.run("A", parameters=SCALED, horizon=res.horizon_a), observe=OBSERVE_A)
    ds = runner.sweep(Grid((Axis("A", res.c3_amplitudes), Axis("omega", res.c3_omegas))), base)
    columns = []
    for omega in ds.omega.values:
        regimes = ds.regime.sel(omega=omega).values.tolist()
        amplitudes = ds.A.values.tolist()
        last_held, first_slide = transition_bracket(amplitudes, regimes)
        columns.append({"omega": float(omega), "regimes": regimes, "last_friction_A": last_held,
                        "first_sliding_A": first_slide, "changes": regime_changes(regimes),
                        "paper_line": 1.0 / float(omega) ** 2, "onset_curve": float(onset_amplitude(omega))})
    _locate_boundaries(runner, base, columns)
    measured = {"columns": columns, "amplitudes": ds.A.values.tolist(), "resolution": BOUNDARY_RESOLUTION}
    settings = {"model": "A", "parameters": "scaled", "horizon": res.horizon_a, "initial": "steady orbit",
                **observe_json(OBSERVE_A)}
    data = {"omega": ds.omega.values.tolist(), "A": ds.A.values.tolist(),
            "regime": ds.regime.transpose("A", "omega").values.tolist(),
            "phi": ds.phi.transpose("A", "omega").values.tolist()}
    return Study("C3", measured, settings, data)


def _locate_boundaries(runner: Runner, base: PointSettings, columns: list[dict]) -> None:
    """Bisect each column's grid bracket (last held A, first sliding A) in A, all columns
    per round in one batch; adds located_A and its bracket to the columns."""
    found = [Transition(c["last_friction_A"], c["first_sliding_A"], True, where={"omega": c["omega"]})
             for c in columns if c["last_friction_A"] is not None and c["first_sliding_A"] is not None]

    def classify(pairs):
        items = [{"point": PointSettings(run=base.run.with_parameters({"A": a, "omega": t.where["omega"]}),
                                         observe=base.observe)} for t, a in pairs]
        return [friction_held(r["observables"]["regime"]) for r in runner.tasks(run_and_measure, items)]

    refine(classify, found, BOUNDARY_RESOLUTION)
    located = {t.where["omega"]: t for t in found}
    for column in columns:
        t = located.get(column["omega"])
        column.update({"located_A": t.value if t else None, "located_lo": t.lo if t else None,
                       "located_hi": t.hi if t else None})


def verdict_c3(m: dict) -> tuple[Row, Row]:
    columns, amplitudes = m["columns"], m["amplitudes"]
    low = [c for c in columns if c["omega"] <= LOW_OMEGA]
    paper_ok = [c for c in low if _bracketed(c, c["paper_line"], amplitudes)]
    single = [c for c in columns if c["changes"] <= 1]
    paper_all = [c for c in columns if _bracketed(c, c["paper_line"], amplitudes)]
    onset_ok = [c for c in columns if _bracketed(c, c["onset_curve"], amplitudes)]
    boundaries = "; ".join(f"w = {c['omega']:.3g}: grid [{fmt(c['last_friction_A'])}, {fmt(c['first_sliding_A'])}], "
                           f"located {fmt(c.get('located_A'))} (g/w^2 = {c['paper_line']:.3g}, "
                           f"A_c = {c['onset_curve']:.3g})" for c in columns)
    measured_a = (f"friction/sliding boundary at g/w^2 (within {FORMULA_TOLERANCE:.0%}) in {len(paper_ok)}/{len(low)} columns with "
                  f"w <= {LOW_OMEGA:g} ({len(paper_all)}/{len(columns)} over all w); single transition in "
                  f"{len(single)}/{len(columns)} columns. Boundaries: {boundaries}")
    if not low:
        row_a = Row("C3a", measured_a, NOT_REPRODUCED, f"no column with omega <= {LOW_OMEGA:g}")
    else:
        parts = [(AGREES if len(paper_ok) == len(low) else DISAGREES,
                  f"g/w^2 at the boundary in {len(paper_ok)}/{len(low)} low-w columns"),
                 (AGREES if len(single) == len(columns) else DISAGREES,
                  f"{len(columns) - len(single)} column(s) with more than one transition in A")]
        verdict, reason = combine(parts)
        row_a = Row("C3a", measured_a, verdict, reason)
    measured_b = (f"A_c(w) at the boundary in {len(onset_ok)}/{len(columns)} columns, g/w^2 in "
                  f"{len(paper_all)}/{len(columns)}. Boundaries: {boundaries}")
    verdict = AGREES if len(onset_ok) == len(columns) else DISAGREES
    reason = (f"A_c(w) within {FORMULA_TOLERANCE:.0%} of the boundary located to "
              f"{m.get('resolution', 0):.0%} in A (or inside the grid bracket) in {len(onset_ok)}/{len(columns)} columns")
    return row_a, Row("C3b", measured_b, verdict, reason)


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(8.5, 4.5))
    regime_grid(ax, d["omega"], d["A"], d["regime"], onset_amplitude, r"$A = g/\omega^2$", r"$A_c(\omega)$",
                loss=loss_amplitude)
    located = [(c["omega"], c["located_A"]) for c in study.measured["columns"] if c.get("located_A") is not None]
    if located:
        ax.plot(*zip(*located), "D", color="k", mfc="none", label="boundary (bisected)")
    ax.set(xscale="log", yscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel=r"$A$ [$\delta_0$]", title="Model A (scaled drive)")
    ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
    ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.01, 0.5))  # beside the grid, not over it
    save(fig, "fig1c_phase_diagram_A.png")


CLAIM = Claim("C3", study_c3, verdict_c3, TEXT, FIGURES, draw)
