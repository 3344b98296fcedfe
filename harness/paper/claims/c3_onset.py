"""C3 -- model A's A-omega phase diagram (Fig. 1c): the onset of sliding.

The grid brackets each column's friction/sliding boundary; each bracket is then bisected
in A (:mod:`harness.runs.bisection`) to ``BOUNDARY_RESOLUTION``, all columns together.
Each located change is then called sharp or a crossover from the runs on its two sides
(:func:`.measure.transition_character`).  A sharp boundary is the located value.  A
crossover (phi falling continuously through the threshold, the block in contact) is
reported by its phi curve, and its boundary is its foot, where phi reaches the floor of
sliding with the drive (bisected to the same resolution on that floor): the physical
marker there is A_N(omega), where the contact force's minimum reaches 0.

Criteria: C3a: every column with omega <= ``LOW_OMEGA`` has its boundary within
``FORMULA_TOLERANCE`` of A = g/omega^2 (within the grid bracket where nothing was
located), and no column changes regime more than once along A.  C3b: the refined onset
on every column, A_c(omega) at a sharp boundary and the friction-loss marker A_N(omega)
at a crossover's foot (with the default contact-force bound friction goes where the
contact force first reaches zero, A_N <= A_c)."""
from __future__ import annotations

from typing import Sequence

from harness.paper.plots import regime_grid
from harness.runs.bisection import Transition, refine
from harness.runs.settings import PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import (CROSSOVER, OBSERVE_A, SCALED, foot_bracket, friction_held, locate_feet, loss_amplitude,
                      observe_json, onset_amplitude, phi_curve, regime_changes, run_and_measure,
                      transition_bracket, transition_character)
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
    "C3b": ["fig1c_phase_diagram_A.png", "c3_crossovers.png", "fig1c_paper_parameters.png"],
}


def boundary(column: dict) -> float | None:
    """The column's boundary: the located value of a sharp change, the foot of a crossover
    (None where a crossover's foot was not found or nothing was located)."""
    if column.get("character") == CROSSOVER:
        return column.get("foot_A")
    return column.get("located_A")


def _bracketed(column: dict, line: float, amplitudes: Sequence[float]) -> bool:
    """The line agrees with the column's boundary: within FORMULA_TOLERANCE of the located
    boundary, or (nothing located) between the grid amplitudes that bracket it."""
    if boundary(column) is not None:
        return abs(boundary(column) / line - 1.0) <= FORMULA_TOLERANCE
    low, high = column["last_friction_A"], column["first_sliding_A"]
    if high is None:
        return line > max(amplitudes)
    return (low is None or low <= line) and line <= high


def study_c3(runner: Runner) -> Study:
    """Model A: A-omega phase diagram (Fig. 1c) against A = g/omega^2 and A_c(omega)."""
    res = runner.resolution
    base = PointSettings(run=runner.run("A", parameters=SCALED, horizon=res.horizon_a), observe=OBSERVE_A)
    ds = runner.sweep(Grid((Axis("A", res.c3_amplitudes), Axis("omega", res.c3_omegas))), base)
    columns, curves = [], {}
    for omega in ds.omega.values:
        regimes = ds.regime.sel(omega=omega).values.tolist()
        amplitudes = ds.A.values.tolist()
        last_held, first_slide = transition_bracket(amplitudes, regimes)
        columns.append({"omega": float(omega), "regimes": regimes, "last_friction_A": last_held,
                        "first_sliding_A": first_slide, "changes": regime_changes(regimes),
                        "paper_line": 1.0 / float(omega) ** 2, "onset_curve": float(onset_amplitude(omega)),
                        "loss_curve": float(loss_amplitude(omega))})
        column_ds = ds.sel(omega=omega)
        curves[float(omega)] = {float(a): {"phi": float(p), "contact_fraction": float(c)} for a, p, c in
                                zip(amplitudes, column_ds.phi.values, column_ds.contact_fraction.values)}
    _locate_boundaries(runner, base, columns, curves)
    _characterise(runner, base, columns, curves)
    measured = {"columns": columns, "amplitudes": ds.A.values.tolist(), "resolution": BOUNDARY_RESOLUTION,
                "phi_threshold": OBSERVE_A.phi_threshold}
    settings = {"model": "A", "parameters": "scaled", "horizon": res.horizon_a, "initial": "steady orbit",
                **observe_json(OBSERVE_A)}
    data = {"omega": ds.omega.values.tolist(), "A": ds.A.values.tolist(),
            "regime": ds.regime.transpose("A", "omega").values.tolist(),
            "phi": ds.phi.transpose("A", "omega").values.tolist()}
    return Study("C3", measured, settings, data)


def _observe(runner: Runner, base: PointSettings, points: list[tuple[float, float]]) -> list[dict]:
    """Observables of the runs at (omega, A) points (each a cached task)."""
    items = [{"point": PointSettings(run=base.run.with_parameters({"A": a, "omega": omega}), observe=base.observe)}
             for omega, a in points]
    return [r["observables"] for r in runner.tasks(run_and_measure, items)]


def _locate_boundaries(runner: Runner, base: PointSettings, columns: list[dict], curves: dict) -> None:
    """Bisect each column's grid bracket (last held A, first sliding A) in A, all columns
    per round in one batch; adds located_A and its bracket to the columns, and every run's
    observables to the column's curve."""
    found = [Transition(c["last_friction_A"], c["first_sliding_A"], True, where={"omega": c["omega"]})
             for c in columns if c["last_friction_A"] is not None and c["first_sliding_A"] is not None]

    def classify(pairs):
        observed = _observe(runner, base, [(t.where["omega"], a) for t, a in pairs])
        for (t, a), o in zip(pairs, observed):
            curves[t.where["omega"]][a] = o
        return [friction_held(o["regime"]) for o in observed]

    refine(classify, found, BOUNDARY_RESOLUTION)
    located = {t.where["omega"]: t for t in found}
    for column in columns:
        t = located.get(column["omega"])
        column.update({"located_A": t.value if t else None, "located_lo": t.lo if t else None,
                       "located_hi": t.hi if t else None})


def _characterise(runner: Runner, base: PointSettings, columns: list[dict], curves: dict) -> None:
    """Call each located change sharp or a crossover (:func:`.measure.transition_character`);
    locate each crossover's foot above it (phi down to the floor of sliding with the
    drive), all columns per round in one batch; adds character, foot_A, foot_bracket and
    the phi curve (grid and every bisection run) to the columns."""
    threshold = OBSERVE_A.phi_threshold
    searches = []
    for column in columns:
        curve = curves[column["omega"]]
        column["character"] = (transition_character(curve[column["located_lo"]], curve[column["located_hi"]], threshold)
                               if column.get("located_lo") is not None else None)
        column["foot_A"] = column["foot_bracket"] = None
        if column["character"] == CROSSOVER:
            bracket = foot_bracket(curve, column["located_hi"], True, threshold)
            if bracket is not None:
                searches.append({"column": column, "curve": curve, "bracket": bracket, "upward": True})
    if searches:
        locate_feet(lambda pairs: _observe(runner, base, [(s["column"]["omega"], a) for s, a in pairs]),
                    searches, threshold, BOUNDARY_RESOLUTION)
    for search in searches:
        search["column"].update(foot_A=search["foot"], foot_bracket=search["foot_bracket"])
    for column in columns:
        column["phi_curve"] = phi_curve(curves[column["omega"]])


def _column_text(c: dict) -> str:
    """One column's boundary: a sharp change's located value, or a crossover's phi curve and foot."""
    where = f"w = {c['omega']:.3g}: grid [{fmt(c['last_friction_A'])}, {fmt(c['first_sliding_A'])}], "
    lines = f"(g/w^2 = {c['paper_line']:.3g}, A_c = {c['onset_curve']:.3g}, A_N = {fmt(c.get('loss_curve'))})"
    if c.get("character") == CROSSOVER:
        curve = ", ".join(f"{fmt(a)}: {fmt(phi, 2)}" for a, phi, _ in c.get("phi_curve", [])
                          if c["last_friction_A"] <= a <= (c.get("foot_bracket") or [c["first_sliding_A"]])[-1])
        return (where + f"crossover (phi continuous, in contact; phi crosses the threshold near "
                f"{fmt(c.get('located_A'))}), foot (phi at the sliding floor) at {fmt(c.get('foot_A'))} {lines}; "
                f"phi(A) {curve}")
    return where + f"{c.get('character') or 'not'} located {fmt(c.get('located_A'))} {lines}"


def _marker(c: dict) -> float:
    """The refined onset a column's boundary is judged against: A_N at a crossover's foot
    (friction goes where the contact force first reaches 0), A_c at a sharp change."""
    return c["loss_curve"] if c.get("character") == CROSSOVER and c.get("loss_curve") else c["onset_curve"]


def verdict_c3(m: dict) -> tuple[Row, Row]:
    columns, amplitudes = m["columns"], m["amplitudes"]
    low = [c for c in columns if c["omega"] <= LOW_OMEGA]
    paper_ok = [c for c in low if _bracketed(c, c["paper_line"], amplitudes)]
    single = [c for c in columns if c["changes"] <= 1]
    paper_all = [c for c in columns if _bracketed(c, c["paper_line"], amplitudes)]
    onset_ok = [c for c in columns if _bracketed(c, _marker(c), amplitudes)]
    crossovers = [c for c in columns if c.get("character") == CROSSOVER]
    boundaries = "; ".join(_column_text(c) for c in columns)
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
    measured_b = (f"refined onset at the boundary in {len(onset_ok)}/{len(columns)} columns ({len(crossovers)} "
                  f"crossover(s), judged at their foot against A_N), g/w^2 in {len(paper_all)}/{len(columns)}. "
                  f"Boundaries: {boundaries}")
    missing_feet = [c for c in crossovers if c.get("foot_A") is None]
    verdict = AGREES if len(onset_ok) == len(columns) else DISAGREES
    reason = (f"A_c(w) within {FORMULA_TOLERANCE:.0%} of the sharp boundaries located to "
              f"{m.get('resolution', 0):.0%} in A (or inside the grid bracket), A_N(w) within it of the crossovers' "
              f"feet: {len(onset_ok)}/{len(columns)} columns")
    if missing_feet and verdict != AGREES:
        verdict = NOT_REPRODUCED
        reason += (f"; {len(missing_feet)} crossover(s) never reach the sliding floor in the scanned range, so "
                   "their boundary is not measured")
    return row_a, Row("C3b", measured_b, verdict, reason)


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(8.5, 4.5))
    regime_grid(ax, d["omega"], d["A"], d["regime"], onset_amplitude, r"$A = g/\omega^2$", r"$A_c(\omega)$",
                loss=loss_amplitude)
    columns = study.measured["columns"]
    sharp = [(c["omega"], c["located_A"]) for c in columns
             if c.get("located_A") is not None and c.get("character") != CROSSOVER]
    if sharp:
        ax.plot(*zip(*sharp), "D", color="k", mfc="none", label="sharp boundary (bisected)")
    feet = [(c["omega"], c["foot_A"]) for c in columns if c.get("character") == CROSSOVER and c.get("foot_A")]
    if feet:
        ax.plot(*zip(*feet), "s", color="tab:purple", mfc="none", label="crossover's foot (phi at the floor)")
    ax.set(xscale="log", yscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel=r"$A$ [$\delta_0$]", title="Model A (scaled drive)")
    ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
    ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.01, 0.5))  # beside the grid, not over it
    save(fig, "fig1c_phase_diagram_A.png")
    crossovers = [c for c in columns if c.get("character") == CROSSOVER]
    if crossovers:
        save(draw_crossovers(crossovers, study.measured.get("phi_threshold", 10.0)), "c3_crossovers.png")


def draw_crossovers(columns: list[dict], threshold: float):
    """phi against A / A_N(omega) for every crossover column (grid and bisection runs): where
    phi crosses the threshold is a property of the threshold; the foot, where phi reaches
    the floor of sliding with the drive, is set against A_N (1 on this axis)."""
    import matplotlib.pyplot as plt

    from .measure import FLOOR_FRACTION

    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    for number, c in enumerate(columns):
        rows = [(a / c["loss_curve"], phi) for a, phi, _ in c["phi_curve"] if phi is not None]
        ax.plot(*zip(*rows), "o-", color=f"C{number}", ms=3, label=f"$\\omega$ = {c['omega']:.3g}")
        if c.get("foot_A"):
            ax.axvline(c["foot_A"] / c["loss_curve"], color=f"C{number}", ls=":", lw=1)
    ax.axvline(1.0, color="k", lw=1, label="$A_N(\\omega)$: $N_{min} = 0$")
    ax.axhline(threshold, color="grey", ls="--", lw=1, label="regime threshold")
    ax.axhline(FLOOR_FRACTION * threshold, color="grey", ls=":", lw=1, label="sliding floor")
    ax.set(xscale="log", yscale="log", xlim=(0.3, 1.5), xlabel="$A / A_N(\\omega)$ [1]",
           ylabel="$\\phi$ [1]", title="Model A: crossovers (dotted: each foot, bisected on the floor)")
    ax.legend(fontsize="small", loc="lower left")
    return fig


CLAIM = Claim("C3", study_c3, verdict_c3, TEXT, FIGURES, draw)
