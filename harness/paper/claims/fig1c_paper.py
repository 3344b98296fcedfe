"""The paper's Fig. 1c at the paper's own parameters: model A's A x omega diagram.

No verdict of its own: the figure goes with C3, whose verdicts are measured with the
scaled drive.  At the paper's drive (k_d = 5e-4, V_d = 2e-5) one stick-slip cycle lasts
T = mu_s m g / (k_t V_S) ~ 4.5e7 tau_0 (claim C1), ~1e11 steps of the paper's scheme;
``event_driven`` crosses it in a few operations.  Each point runs the FMU from the steady
in-contact orbit: a transient of T/2, then a window of (cycles + 1) T, which holds
cycles + 1 slips of the unvibrated cycle, i.e. ``cycles`` complete cycles.  x is sampled
SAMPLES times over the run; phi comes from the FMU's exact integral and the regime from
the rules of :mod:`harness.runs.observables` (a stick-slip block is sampled mostly at
rest).  Slips are counted from the samples: a run of sample intervals in which x
advances more than SLIP_ADVANCE (a stick's creep advances ~0.01 in one)."""
from __future__ import annotations

import numpy as np

from harness.runs.observables import PHI_STICK_SLIP
from harness.runs.settings import ObservableSettings, PointSettings

from .measure import friction_held, loss_amplitude, observe_json, onset_amplitude, run_and_measure
from .study import Claim, Runner, Study
from .verdicts import fmt

TEXT: dict = {}
FIGURES: dict = {}
SAMPLES = 450
SLIP_ADVANCE = 1.0  # delta_0


def cycle_time() -> float:
    """The unvibrated stick time at the paper's parameters, mu_s m g / (k_t V_S)."""
    from vibroblock import defaults

    p = defaults("A")
    creep = p["V_d"] * p["k_d"] / (p["k_t"] + p["k_d"])
    return p["mu_s"] * p["m"] * p["g"] / (p["k_t"] * creep)


def sampled_slips(x) -> int:
    """Runs of sample intervals in which x advances more than SLIP_ADVANCE."""
    moving = np.diff(np.asarray(x)) > SLIP_ADVANCE
    return int(np.sum(moving[1:] & ~moving[:-1]) + (1 if len(moving) and moving[0] else 0))


def study_fig1c_paper(runner: Runner) -> Study:
    """Model A at the paper's parameters on an omega x A grid (the resolution's)."""
    res = runner.resolution
    period = cycle_time()
    transient = 0.5 * period
    horizon = transient + (res.fig1c_cycles + 1) * period
    observe_settings = ObservableSettings(transient=transient)
    points = [(float(a), float(w)) for a in res.fig1c_amplitudes for w in res.fig1c_omegas]
    items = [{"point": PointSettings(run=runner.run("A", parameters={"A": a, "omega": w}, horizon=horizon,
                                                    output_interval=horizon / SAMPLES),
                                     observe=observe_settings), "extras": ["trace"]}
             for a, w in points]
    results = runner.tasks(run_and_measure, items)
    rows = []
    for (a, w), r in zip(points, results):
        t, x = np.asarray(r["trace"]["time"]), np.asarray(r["trace"]["x"])
        o = r["observables"]
        rows.append({"A": a, "omega": w, "regime": o["regime"], "phi": o["phi"],
                     "contact_fraction": o["contact_fraction"], "rest_fraction": o["rest_fraction"],
                     "slips_in_window": sampled_slips(x[t >= transient])})
    stick_slip = [row for row in rows if row["regime"] in PHI_STICK_SLIP]
    measured = {"points": rows, "cycle_time": period,
                "fewest_slips_at_stick_slip": min((row["slips_in_window"] for row in stick_slip), default=None)}
    settings = {"model": "A", "parameters": "paper (FMU defaults)", "integrator": "event_driven",
                "initial": "steady orbit", "horizon": horizon, "cycles": res.fig1c_cycles, "samples": SAMPLES,
                **observe_json(observe_settings)}
    data = {"omega": list(map(float, res.fig1c_omegas)), "A": list(map(float, res.fig1c_amplitudes)),
            "regime": [[row["regime"] for row in rows[i * len(res.fig1c_omegas):(i + 1) * len(res.fig1c_omegas)]]
                       for i in range(len(res.fig1c_amplitudes))]}
    return Study("Fig1c", measured, settings, data)


def describe(m: dict) -> str:
    """Per column: the grid bracket of the friction/sliding boundary in A, and whether the
    paper's line g/omega^2 and the onset A_c(omega) fall inside it."""
    if not m["points"]:
        return "not run at this resolution"
    columns = []
    for omega in sorted({p["omega"] for p in m["points"]}):
        column = sorted((p for p in m["points"] if p["omega"] == omega), key=lambda p: p["A"])
        held = [friction_held(p["regime"]) for p in column]
        lost = next((i for i, h in enumerate(held) if not h), None)
        low = column[lost - 1]["A"] if lost else None
        high = column[lost]["A"] if lost is not None else None
        lines = {"g/w^2": 1.0 / omega**2, "A_c": float(onset_amplitude(omega))}
        inside = [name for name, value in lines.items()
                  if (low is None or low <= value) and (high is None or value <= high)]
        columns.append(f"w = {omega:.3g}: held up to A = {fmt(low)}, not from {fmt(high)} "
                       f"({', '.join(inside) or 'neither line'} inside; "
                       f"{sum(h1 != h2 for h1, h2 in zip(held, held[1:]))} change(s) along A)")
    fewest = m["fewest_slips_at_stick_slip"]
    return (f"{len(m['points'])} points, cycle time T = {m['cycle_time']:.3g}; stick-slip points show at least "
            f"{fewest if fewest is not None else '-'} slips in their window. " + "; ".join(columns))


def draw(study: Study, save) -> None:
    """The diagram, with the paper's line and the onset of detachment A_c(omega)."""
    import matplotlib.pyplot as plt

    from harness.paper.plots import regime_grid

    d = study.data
    if not d.get("omega"):
        return
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    regime_grid(ax, d["omega"], d["A"], d["regime"], onset_amplitude, r"$A = g/\omega^2$", r"$A_c(\omega)$",
                loss=loss_amplitude)
    ax.set(xscale="log", yscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel=r"$A$ [$\delta_0$]",
           title=f"Model A, the paper's parameters (>= {study.settings['cycles']} stick-slip cycles per point)")
    ax.title.set_fontsize(9)
    ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    save(fig, "fig1c_paper_parameters.png")


CLAIM = Claim("Fig1c", study_fig1c_paper, None, TEXT, FIGURES, draw, describe=describe)
