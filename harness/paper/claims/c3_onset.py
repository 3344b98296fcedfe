"""C3 -- model A's A-omega phase diagram (Fig. 1c): the onset of sliding.

Criteria: C3a: every column with omega <= ``LOW_OMEGA`` has its friction/sliding boundary
between the same two grid amplitudes as A = g/omega^2, and no column changes regime more
than once along A.  C3b: the same bracket test for A_c(omega) on every column."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from harness.paper.plots import regime_scatter
from harness.runs.settings import PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import OBSERVE_A, SCALED, observe_json, onset_amplitude, regime_changes, transition_bracket
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, Row, combine, fmt

LOW_OMEGA = 0.3

TEXT = {
    "C3a": "A: stick-slip -> sliding at A omega^2 = g (omega << omega_n), the only transition in A",
    "C3b": "A: refined onset A_c(omega) = (g/omega^2)|k_n - m omega^2 + i gamma_n omega|/k_n",
}
FIGURES = {
    "C3a": ["fig1c_phase_diagram_A.png"],
    "C3b": ["fig1c_phase_diagram_A.png"],
}


def _bracketed(column: dict, line: float, amplitudes: Sequence[float]) -> bool:
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
    measured = {"columns": columns, "amplitudes": ds.A.values.tolist()}
    settings = {"model": "A", "parameters": "scaled", "horizon": res.horizon_a, "initial": "steady orbit",
                **observe_json(OBSERVE_A)}
    data = {"omega": ds.omega.values.tolist(), "A": ds.A.values.tolist(),
            "regime": ds.regime.transpose("A", "omega").values.tolist(),
            "phi": ds.phi.transpose("A", "omega").values.tolist()}
    return Study("C3", measured, settings, data)


def verdict_c3(m: dict) -> tuple[Row, Row]:
    columns, amplitudes = m["columns"], m["amplitudes"]
    low = [c for c in columns if c["omega"] <= LOW_OMEGA]
    paper_ok = [c for c in low if _bracketed(c, c["paper_line"], amplitudes)]
    single = [c for c in columns if c["changes"] <= 1]
    paper_all = [c for c in columns if _bracketed(c, c["paper_line"], amplitudes)]
    onset_ok = [c for c in columns if _bracketed(c, c["onset_curve"], amplitudes)]
    boundaries = "; ".join(f"w = {c['omega']:.3g}: [{fmt(c['last_friction_A'])}, {fmt(c['first_sliding_A'])}] "
                           f"(g/w^2 = {c['paper_line']:.3g}, A_c = {c['onset_curve']:.3g})" for c in columns)
    measured_a = (f"friction/sliding boundary brackets g/w^2 in {len(paper_ok)}/{len(low)} columns with "
                  f"w <= {LOW_OMEGA:g} ({len(paper_all)}/{len(columns)} over all w); single transition in "
                  f"{len(single)}/{len(columns)} columns. Boundaries: {boundaries}")
    if not low:
        row_a = Row("C3a", measured_a, NOT_REPRODUCED, f"no column with omega <= {LOW_OMEGA:g}")
    else:
        parts = [(AGREES if len(paper_ok) == len(low) else DISAGREES,
                  f"g/w^2 bracketed in {len(paper_ok)}/{len(low)} low-w columns"),
                 (AGREES if len(single) == len(columns) else DISAGREES,
                  f"{len(columns) - len(single)} column(s) with more than one transition in A")]
        verdict, reason = combine(parts)
        row_a = Row("C3a", measured_a, verdict, reason)
    measured_b = (f"A_c(w) bracketed in {len(onset_ok)}/{len(columns)} columns, g/w^2 in "
                  f"{len(paper_all)}/{len(columns)}")
    verdict = AGREES if len(onset_ok) == len(columns) else DISAGREES
    reason = (f"A_c(w) lies between the last friction and first sliding amplitude in "
              f"{len(onset_ok)}/{len(columns)} columns")
    return row_a, Row("C3b", measured_b, verdict, reason)


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(6, 4.5))
    omega, amplitude = np.meshgrid(d["omega"], d["A"])
    regime_scatter(ax, omega.ravel(), amplitude.ravel(), np.asarray(d["regime"]).ravel())
    line = np.geomspace(min(d["omega"]), max(d["omega"]), 300)
    ax.plot(line, 1 / line**2, "k:", label=r"$A = g/\omega^2$")
    ax.plot(line, onset_amplitude(line), "k-", lw=1, label=r"$A_c(\omega)$")
    ax.set(xscale="log", yscale="log", xlabel=r"$\omega$", ylabel="A", title="Model A (scaled drive)")
    ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
    ax.legend(fontsize="small")
    save(fig, "fig1c_phase_diagram_A.png")


CLAIM = Claim("C3", study_c3, verdict_c3, TEXT, FIGURES, draw)
