"""The paper's Fig. 1b: x(t) of model A at A = 10 below and above the onset.

No verdict of its own: the figure goes with C1 and C2."""
from __future__ import annotations

import numpy as np

from harness.runs.settings import ObservableSettings, PointSettings

from .measure import SCALED, observe_json, onset_amplitude, run_and_measure
from .study import Claim, Runner, Study

TEXT: dict = {}
FIGURES: dict = {}
FIG1B_AMPLITUDE, FIG1B_OMEGAS = 10.0, {"stick-slip": 0.25, "sliding": 0.40}


def study_fig1b(runner: Runner) -> Study:
    """The paper's Fig. 1b: x(t) at A = 10 below and above the onset (settings of
    examples/fig1b_stick_slip_vs_sliding.py, run on a worker)."""
    observe_settings = ObservableSettings(transient=2000.0)
    items = [{"point": PointSettings(run=runner.run("A", parameters={**SCALED, "A": FIG1B_AMPLITUDE, "omega": w},
                                                    horizon=20_000.0, output_interval=5.0),
                                     observe=observe_settings), "extras": ["trace"]}
             for w in FIG1B_OMEGAS.values()]
    results = runner.tasks(run_and_measure, items)
    runs = [{"label": label, "omega": w, "phi": r["observables"]["phi"], "regime": r["observables"]["regime"],
             "onset": float(onset_amplitude(w)), **r["trace"]}
            for (label, w), r in zip(FIG1B_OMEGAS.items(), results)]
    measured = {"runs": [{k: v for k, v in run.items() if k not in ("time", "x")} for run in runs]}
    settings = {"model": "A", "parameters": "scaled", "A": FIG1B_AMPLITUDE, "horizon": 20_000.0,
                "initial": "steady orbit", **observe_json(observe_settings)}
    return Study("Fig1b", measured, settings, {"runs": runs, "V_d": SCALED["V_d"]})


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(6.5, 4.0))
    for run in d["runs"]:
        ax.plot(run["time"], run["x"], label=f"{run['label']}: $\\omega$ = {run['omega']:g}, "
                                             f"$\\phi$ = {run['phi']:.2g}")
    t = np.asarray(d["runs"][0]["time"])
    ax.plot(t, d["V_d"] * t, "k:", lw=1, label="drive $V_d t$")
    ax.set(xlabel=r"$t$ [$\tau_0$]", ylabel=r"$x$ [$\delta_0$]",
           title=f"Model A, A = {study.settings['A']:g} (scaled drive)")
    ax.legend(fontsize=8)
    save(fig, "fig1b.png")


CLAIM = Claim("Fig1b", study_fig1b, None, TEXT, FIGURES, draw)
