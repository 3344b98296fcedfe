"""C5 -- model B (corrugated plate): x(t) for several A at omega = 0.5, stick positions, k_t = 0.

Criteria: C5a: at every A, mean slip interval and slip length within
``UNCHANGED_TOLERANCE`` of A = 0.  C5b: median distance of stuck samples from the nearest
stable root of Eq. (9) below ``ROOT_TOLERANCE`` wavelengths (k_t = 0 run).  C5c: the
k_t = 0 run is in stick-slip."""
from __future__ import annotations

import math

import numpy as np

from harness.runs.observables import PHI_STICK_SLIP

from vibroblock.models import parameters_for

from .measure import OBSERVE_B, OMEGA_X, SCALED, VALLEY, WAVELENGTH, b_point, observe_json, run_and_measure
from .study import Claim, Runner, Study
from .readings import READINGS
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, UNCHANGED_TOLERANCE, Row, fmt, relative

ROOT_TOLERANCE = 0.02

TEXT = {
    "C5a": "B: horizontal motion unaffected by the vibration",
    "C5b": "B: stick positions are the stable roots of cos(omega_x x*) = K(x* - V_d t)",
    "C5c": "B: stick-slip even with k_t = 0",
}
FIGURES = {
    "C5a": ["model_b_x_t.png"],
    "C5b": ["model_b_x_t.png", "fig4_eq9_roots.png"],
    "C5c": ["model_b_x_t.png"],
}


# The k_t = 0 run lasts past the fold of Eq. (9) by this factor: without friction the block
# rests where the drive spring balances the slope, and that rest ends only where the
# spring's pull exceeds the slope's largest restoring force, A_x omega_x m g.
FOLD_MARGIN = 1.25
MODEL_B_DEFAULTS = {p.name: p.default for p in parameters_for("B")}


def frictionless_horizon(horizon: float) -> float:
    """The k_t = 0 run's horizon: ``horizon``, or past Eq. (9)'s fold, the time the drive
    takes to stretch its spring by A_x omega_x m g / k_d (2e5 with the scaled drive)."""
    stretch = MODEL_B_DEFAULTS["A_x"] * OMEGA_X * MODEL_B_DEFAULTS["m"] * MODEL_B_DEFAULTS["g"] / SCALED["k_d"]
    return max(horizon, FOLD_MARGIN * stretch / SCALED["V_d"])


def study_c5(runner: Runner) -> Study:
    """Model B: x(t) for several A at omega = 0.5, stick positions, and k_t = 0."""
    res = runner.resolution
    omega = 0.5
    items = [{"point": b_point(runner, res.b_horizon, OBSERVE_B, A=a, omega=omega),
              "extras": ["trace", "stick_roots"]} for a in res.b_amplitudes]
    items.append({"point": b_point(runner, frictionless_horizon(res.b_horizon), OBSERVE_B, A=0.0, omega=omega,
                                   k_t=0.0),
                  "extras": ["trace", "stick_roots", "stick_sites"]})
    results = runner.tasks(run_and_measure, items)
    runs = []
    for amplitude, result in zip(res.b_amplitudes, results):
        obs = result["observables"]
        runs.append({"A": amplitude, "peak_acceleration_over_g": amplitude * omega**2, "regime": obs["regime"],
                     "slip_events": obs["slip_events"], "slip_interval": obs["slip_interval_mean"],
                     "slip_length": obs["slip_length_mean"], "drift_velocity": obs["drift_velocity"],
                     "contact_fraction": obs["contact_fraction"], "slope_angle_end": obs["slope_angle_end"],
                     "root_distance_median": result["root_distance_median"]})
    reference = np.interp(results[0]["trace"]["time"], results[0]["trace"]["time"], results[0]["trace"]["x"])
    for run, result in zip(runs, results):
        other = np.interp(results[0]["trace"]["time"], result["trace"]["time"], result["trace"]["x"])
        run["max_x_difference"] = float(np.max(np.abs(other - reference)))
    frictionless = results[-1]
    obs = frictionless["observables"]
    measured = {"omega": omega, "runs": runs, "wavelength": WAVELENGTH, "V_d": SCALED["V_d"], "omega_x": OMEGA_X,
                "eq9_slope": eq9_slope(),
                "frictionless": {"regime": obs["regime"], "slip_events": obs["slip_events"],
                                 "slip_length": obs["slip_length_mean"],
                                 "root_distance_median": frictionless["root_distance_median"],
                                 "root_distance_p90": frictionless["root_distance_p90"],
                                 "horizon": frictionless_horizon(res.b_horizon)}}
    settings = {"model": "B", "parameters": "paper plate (A_x = 1e3, omega_x = 2e-2), scaled drive "
                "k_d = V_d = 1e-2, gamma_t = 5e-3", "omega": omega, "horizon": res.b_horizon,
                "frictionless_horizon": frictionless_horizon(res.b_horizon),
                "initial": f"valley x = 3 pi/(2 omega_x) = {VALLEY:.1f}, steady orbit, spring relaxed at t0",
                **observe_json(OBSERVE_B)}
    data = {"traces": [{"A": a, **r["trace"]} for a, r in zip(res.b_amplitudes, results)],
            "frictionless_trace": frictionless["trace"], "frictionless_stick_sites": frictionless["stick_sites"]}
    return Study("C5", measured, settings, data)


def eq9_slope(k_d: float = SCALED["k_d"], amplitude_x: float = 1e3, omega_x: float = OMEGA_X, m: float = 1.0,
              g: float = 1.0) -> float:
    """K of the paper's Eq. (9), cos(omega_x x*) = K (x* - V_d t): K = -k_d/(A_x omega_x m g)."""
    return -k_d / (amplitude_x * omega_x * m * g)


def eq9_roots(drive: float, k_ratio: float, omega_x: float, low: float, high: float) -> tuple[list, list]:
    """Stable (sin(omega_x x*) < 0) and unstable roots of Eq. (9) in [low, high]."""
    grid = np.linspace(low, high, 20001)
    h = np.cos(omega_x * grid) - k_ratio * (grid - drive)
    change = np.flatnonzero(np.sign(h[:-1]) != np.sign(h[1:]))
    roots = grid[change] - h[change] * (grid[change + 1] - grid[change]) / (h[change + 1] - h[change])
    stable = np.sin(omega_x * roots) < 0
    return roots[stable].tolist(), roots[~stable].tolist()


def spread(sites: list, count: int = 3) -> list[tuple[float, float]]:
    """``count`` of the (t, x) stick sites, spread over the run (first, last, between)."""
    if not sites:
        return []
    chosen = dict.fromkeys(int(i) for i in np.linspace(0, len(sites) - 1, min(count, len(sites))))
    return [(float(sites[i][0]), float(sites[i][1])) for i in chosen]


def verdict_c5(m: dict) -> tuple[Row, Row, Row]:
    runs = m["runs"]
    measured_a = "; ".join(f"A = {r['A']:g} (A w^2/g = {r['peak_acceleration_over_g']:.2g}): {r['regime']}, "
                           f"{r['slip_events']} slips, "
                           f"every {fmt(r['slip_interval'])}, length {fmt(r['slip_length'])}, drift "
                           f"{fmt(r['drift_velocity'])}, contact {fmt(r['contact_fraction'])}, max |x - x_(A=0)| "
                           f"{fmt(r['max_x_difference'])}" for r in runs)
    reference = runs[0]
    if reference.get("regime") == "jammed":
        # On the paper's corrugation (slopes up to arctan(A_x omega_x) = 87 deg) the drive
        # pushes the unvibrated block up a flank steeper than arctan(1/mu_s), where mu_s
        # times the pull's share normal to the surface exceeds its share along it: there is
        # no stick-slip cycle at A = 0 to compare with, however long the window.
        row_a = Row("C5a", measured_a, NOT_REPRODUCED,
                    f"no stick-slip cycle at A = 0: the block jams (self-locked on a flank at alpha = "
                    f"{fmt(reference.get('slope_angle_end'))} deg, steeper than arctan(1/mu_s)), so there is no "
                    f"cycle for the vibration to leave unchanged")
    elif reference["slip_interval"] is None or not math.isfinite(float(reference["slip_interval"])):
        row_a = Row("C5a", measured_a, NOT_REPRODUCED,
                    f"fewer than two complete slips at A = 0 in the window (regime {reference.get('regime')}, "
                    f"ending on a slope of alpha = {fmt(reference.get('slope_angle_end'))} deg)")
    else:
        worst = max(max(relative(r["slip_interval"], reference["slip_interval"]),
                        relative(r["slip_length"], reference["slip_length"])) for r in runs)
        row_a = Row("C5a", measured_a, AGREES if worst <= UNCHANGED_TOLERANCE else DISAGREES,
                    f"largest change of slip interval or length from A = 0: {fmt(100 * worst, 2)} % "
                    f"(tolerance {UNCHANGED_TOLERANCE:.0%})")
    free = m["frictionless"]
    distance = free["root_distance_median"]
    measured_b = (f"k_t = 0: median distance of stuck samples from the nearest stable root {fmt(distance)} "
                  f"(90th percentile {fmt(free['root_distance_p90'])}), wavelength {m['wavelength']:.3g}; with "
                  f"friction (A = 0): {fmt(reference['root_distance_median'])}")
    if distance is None:
        row_b = Row("C5b", measured_b, NOT_REPRODUCED, "no stuck samples")
    else:
        ok = distance <= ROOT_TOLERANCE * m["wavelength"]
        row_b = Row("C5b", measured_b, AGREES if ok else DISAGREES,
                    f"median distance {'<=' if ok else '>'} {ROOT_TOLERANCE:g} wavelengths")
    measured_c = f"k_t = 0: regime {free['regime']}, {free['slip_events']} slips of {fmt(free['slip_length'])}"
    if free["regime"] in PHI_STICK_SLIP:
        row_c = Row("C5c", measured_c, AGREES, "stick-slip without tangential spring")
    elif free["regime"] == "stuck":  # (k_t = 0 cannot self-lock: never "jammed")
        row_c = Row("C5c", measured_c, NOT_REPRODUCED,
                    f"no slip in the window (stuck): the block rests where the drive spring balances the slope "
                    f"(Eq. 9), and the run ({fmt(free.get('horizon'))} tau_0) does not reach a slip")
    else:
        row_c = Row("C5c", measured_c, DISAGREES, "sliding without tangential spring")
    return row_a, row_b, row_c


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for trace in d["traces"]:
        ax.plot(trace["time"], trace["x"], label=f"A = {trace['A']:g}")
    ax.plot(d["frictionless_trace"]["time"], d["frictionless_trace"]["x"], "k--", lw=0.8, label="A = 0, $k_t$ = 0")
    t = np.asarray(d["traces"][0]["time"])
    ax.plot(t, study.measured["V_d"] * t, "k:", lw=0.8, label="$V_d t$")
    ax.set(xlabel=r"$t$", ylabel="x", title=f"Model B, $\\omega$ = {study.measured['omega']:g}")
    ax.legend(fontsize="small")
    save(fig, "model_b_x_t.png")
    draw_fig4(study, save)


def draw_fig4(study: Study, save) -> None:
    """The paper's Fig. 4: the graphical solution of Eq. (9) of the k_t = 0 run at the first and
    the last stuck sample of its window and at its end, the stable (filled) and unstable
    (open) roots at each time, and where the simulated block is then."""
    import matplotlib.pyplot as plt

    m = study.measured
    k_ratio, omega_x, v_d = m.get("eq9_slope", eq9_slope()), m.get("omega_x", OMEGA_X), m["V_d"]
    snapshots = spread(study.data.get("frictionless_stick_sites", []), 2)
    if not snapshots:  # no stick in the window (or a study stored before sites were recorded)
        return
    trace = study.data.get("frictionless_trace", {"time": []})
    if trace["time"] and trace["time"][-1] > snapshots[-1][0]:  # and where the block is at the end
        snapshots.append((float(trace["time"][-1]), float(trace["x"][-1])))
    low = min(x for _, x in snapshots) - 0.75 * m["wavelength"]
    high = max(x for _, x in snapshots) + 0.75 * m["wavelength"]
    grid = np.linspace(low, high, 2000)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(grid, np.cos(omega_x * grid), "k-", lw=1, label=r"$\cos(\omega_x x)$")
    for number, (t, x) in enumerate(snapshots):
        color = f"C{number}"
        ax.plot(grid, k_ratio * (grid - v_d * t), "--", color=color, lw=1, label=f"$K(x - V_d t)$, t = {t:.3g}")
        stable, unstable = eq9_roots(v_d * t, k_ratio, omega_x, low, high)
        ax.plot(stable, np.cos(omega_x * np.asarray(stable)), "o", color=color, ms=6)
        ax.plot(unstable, np.cos(omega_x * np.asarray(unstable)), "o", color=color, mfc="none", ms=6)
        ax.axvline(x, color=color, lw=2, alpha=0.5)
    ax.set(xlabel=r"$x$ [$\delta_0$]", ylabel="", title="Eq. (9), model B, $k_t$ = 0 (scaled drive): roots filled = stable, "
           "open = unstable;\nvertical bars: the simulated block at the first and last stuck sample and at the end")
    ax.title.set_fontsize("small")
    ax.legend(fontsize="x-small", loc="lower left")
    save(fig, "fig4_eq9_roots.png")


CLAIM = Claim("C5", study_c5, verdict_c5, TEXT, FIGURES, draw, readings=READINGS)
