"""C6r -- the recovery question (claim C6), tested directly, in models A and C.

The paper: in model C friction comes back above a second frequency omega_2 ~ k_n/gamma_n,
independent of A, weakly dependent on k_n at fixed k_n/gamma_n, without hysteresis, and
only because the surface is modulated.  The contact-oscillator reading (docs/physics.md)
predicts otherwise for A below delta_0 = load/k_n: friction is lost where the steady orbit's
normal force first reaches zero (A > A_N(omega)) or the block detaches (A > A_c(omega)),
which for A < delta_0 happens only in a band around the contact resonance; above the band
friction returns at the upper root of A_N(omega) = A (A_c with the applied-load bound),
which depends on A, and the flat plate of model A does the same.

The study asks the questions, it does not assume an answer:

* for model A (both Coulomb-bound readings) and model C (both formulations), at amplitudes
  A = a delta_0 below delta_0, an omega grid through and far above the resonance; every
  change between held by friction and sliding is located by bisection
  (:mod:`harness.runs.bisection`) to ``RECOVERY_RESOLUTION``;
* each located transition is set against the candidates: k_n/gamma_n and the roots of
  A_c(omega) = A and A_N(omega) = A (load m g in A, P_l in C);
* hysteresis: a continuation ramp in omega, up then down, across the located omega_2;
* omega_2 against k_n at fixed k_n/gamma_n with A scaled by delta_0 = P_l/k_n (C6d), so that
  changing k_n does not change what the amplitude means.

"Held by friction" is the regime rule of :mod:`harness.runs.observables` (stick_slip,
stuck or jammed; not sliding, not flying) over a window covering >= 3 stick-slip cycles of
the scaled drive (model A) or the second corrugation wavelength (model C).

Criteria: C6r-a: the paper says recovery needs the modulated surface, so it disagrees
when model A regains friction above the resonance.  C6r-b: omega_2 within ``WITHIN`` of
k_n/gamma_n in every row and spread over A <= 2 resolutions; the reason names the
contact-oscillator root (A_N or A_c) omega_2 lies at, within 2 resolutions.  C6r-c: the
up and down ramps regain friction less than 1.5 ramp steps apart.  C6r-d: omega_2 spreads
<= ``WITHIN`` over k_n at fixed k_n/gamma_n (A in units of delta_0 = P_l/k_n).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from harness.runs.bisection import LOSS, RECOVERY, locate_transitions
from harness.runs.continuation import Ramp
from harness.runs.settings import InitialCondition, Integration, ObservableSettings, PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import (CREST, CROSSOVER, SCALED, foot_bracket, friction_held, locate_feet, observe_json, phi_curve,
                      ramp_task, relaxed_start, run_and_measure, transition_character)
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, Row, combine, fmt

RECOVERY_RESOLUTION = 0.03  # relative width of a located transition in omega
K_N, GAMMA_N, LOAD = 1.0, 0.07, 1.0  # the paper's contact (delta_0 = load / k_n = 1)
# Stick time of the scaled drive ~ mu_s m g / (k_t V_S) ~ 5200: the window holds >= 3 cycles.
# Model C starts on a crest with the spring relaxed: the first wavelength (lambda / V_d =
# 3.1e4) is a transient (the descent into the valley and the climb of the next flank, where
# a held block self-locks), so its window is the last 2e4 of 6e4.


@dataclass(frozen=True)
class Configuration:
    """One model with one reading of its equations."""

    label: str
    model: str
    readings: tuple  # (name, value) pairs of FMU Integer parameters
    integrator: str | None = None  # None: the runner's choice (study.Runner.run)
    horizon: float = 20_000.0
    transient: float = 4_000.0

    @property
    def observe(self) -> ObservableSettings:
        return ObservableSettings(transient=self.transient)

    def parameters(self, **values) -> dict:
        return {**SCALED, **dict(self.readings), **values}


CONFIGURATIONS = (
    # event_driven is exact for model A and refuses the applied-load bound.
    Configuration("A, contact-force bound", "A", (("coulomb_normal", 0),), integrator="event_driven"),
    Configuration("A, applied-load bound", "A", (("coulomb_normal", 1),), integrator="symplectic_euler"),
    Configuration("C, fixed axes", "C", (("formulation", 0),), horizon=60_000.0, transient=40_000.0),
    Configuration("C, tangent frame", "C", (("formulation", 1),), horizon=60_000.0, transient=40_000.0),
)


@dataclass(frozen=True)
class Sizes:
    amplitudes: tuple        # A / delta_0, model A
    amplitudes_c: tuple      # A / delta_0, model C (each point costs ~100x a model A point)
    omegas: tuple            # the grid kept for the figure (model A)
    omegas_c: tuple          # the same for model C
    ramp_points: int         # steps of the hysteresis ramp (each way)
    stiffnesses: tuple       # k_n for C6d, at k_n / gamma_n fixed
    configurations: tuple    # labels run


SIZES = {
    # Grids denser around the contact resonance omega_n = sqrt(k_n/m) = 1, where the
    # amplitudes below delta_0 can lose friction (a band of width ~1.35 at A = 0.3 delta_0).
    "default": Sizes(amplitudes=(0.3, 0.6), amplitudes_c=(0.3,),
                     omegas=tuple(np.round(np.concatenate([np.geomspace(0.3, 3.0, 13), np.geomspace(3.0, 60.0, 7)[1:]]), 4)),
                     omegas_c=(0.3, 0.85, 1.0, 1.15, 1.4, 6.0, 40.0), ramp_points=5,
                     stiffnesses=(0.5, 1.0, 2.0), configurations=tuple(c.label for c in CONFIGURATIONS)),
    "quick": Sizes(amplitudes=(0.3,), amplitudes_c=(), omegas=(0.5, 0.8, 1.0, 1.25, 1.6, 3.0, 10.0, 30.0, 60.0),
                   omegas_c=(), ramp_points=4, stiffnesses=(0.5, 2.0), configurations=("A, contact-force bound",)),
    "tiny": Sizes(amplitudes=(0.3,), amplitudes_c=(), omegas=(0.5, 1.1, 2.5), omegas_c=(), ramp_points=3,
                  stiffnesses=(1.0,), configurations=("A, contact-force bound",)),
}


def crossings(curve, amplitude: float, low: float = 1e-2, high: float = 1e3, samples: int = 40001) -> list[float]:
    """Every omega where ``curve(omega)`` crosses ``amplitude`` (fine log grid, then linear
    interpolation in log omega): where friction is predicted to be lost or regained."""
    grid = np.geomspace(low, high, samples)
    above = curve(grid) > amplitude  # a sample exactly on the amplitude counts once
    out = []
    for i in np.flatnonzero(above[:-1] != above[1:]):
        f0, f1 = curve(grid[i]) - amplitude, curve(grid[i + 1]) - amplitude
        fraction = f0 / (f0 - f1)
        out.append(float(np.exp(np.log(grid[i]) + fraction * np.log(grid[i + 1] / grid[i]))))
    return out


def predictions(amplitude: float, k_n: float = K_N, gamma_n: float = GAMMA_N, load: float = LOAD) -> dict:
    """The candidate transition frequencies for one amplitude (m = 1)."""
    # Imported here: a harness process that never asks for a prediction keeps no core
    # import that an FMU loaded in the same process would have to match.
    from vibroblock.orbits import detachment_amplitude, friction_loss_amplitude

    def onset(w):
        return detachment_amplitude(w, m=1.0, g=load, k_n=k_n, gamma_n=gamma_n)

    def loss(w):
        return friction_loss_amplitude(w, m=1.0, g=load, k_n=k_n, gamma_n=gamma_n)

    return {"k_n_over_gamma_n": k_n / gamma_n if gamma_n > 0 else math.inf, "A_c_roots": crossings(onset, amplitude),
            "A_N_roots": crossings(loss, amplitude)}


def _run(runner: Runner, configuration: Configuration, amplitude: float, **values):
    parameters = configuration.parameters(A=amplitude, **values)
    chosen = {"integration": Integration(configuration.integrator)} if configuration.integrator else {}
    if configuration.model == "A":
        return runner.run("A", parameters=parameters, horizon=configuration.horizon, **chosen)
    return runner.run("C", parameters=parameters, horizon=configuration.horizon, **chosen,
                      initial=InitialCondition("steady_orbit", x_start=CREST),
                      start_time=relaxed_start(CREST, parameters["V_d"]))


def _observe_along_omega(runner: Runner, base: PointSettings, omegas) -> list[dict]:
    """Observables of the runs at ``omegas`` (each a cached task)."""
    items = [{"point": PointSettings(run=base.run.with_parameters({"omega": float(w)}), observe=base.observe)}
             for w in omegas]
    return [r["observables"] for r in runner.tasks(run_and_measure, items)]


def _transitions(runner: Runner, base: PointSettings, curve: dict, omegas, regimes) -> list[dict]:
    """Every class change along omega, bisected to RECOVERY_RESOLUTION and called sharp or
    a crossover (:func:`.measure.transition_character`); a crossover's foot, where phi
    reaches the floor of sliding with the drive on its sliding side, is bisected to the
    same resolution.  ``boundary``: the located value of a sharp change, the foot of a
    crossover (its located threshold crossing where no foot was found).  ``curve``
    ({omega: observables}) gains every run."""
    held = [friction_held(r) for r in regimes]

    def classify(points):
        observed = _observe_along_omega(runner, base, points)
        curve.update(zip((float(p) for p in points), observed))
        return [friction_held(o["regime"]) for o in observed]

    found = [t.as_dict() for t in locate_transitions(classify, omegas, held, resolution=RECOVERY_RESOLUTION)]
    threshold = base.observe.phi_threshold
    searches = []
    for t in found:
        held_side, other_side = (t["lo"], t["hi"]) if t["held_lo"] else (t["hi"], t["lo"])
        t["character"] = transition_character(curve[held_side], curve[other_side], threshold)
        t["foot"] = t["foot_bracket"] = None
        if t["character"] == CROSSOVER:
            # The sliding side lies above a loss and below a recovery.
            bracket = foot_bracket(curve, other_side, t["held_lo"], threshold)
            if bracket is not None:
                searches.append({"transition": t, "curve": curve, "bracket": bracket, "upward": t["held_lo"]})
    if searches:
        locate_feet(lambda pairs: _observe_along_omega(runner, base, [w for _, w in pairs]), searches, threshold,
                    RECOVERY_RESOLUTION)
    for search in searches:
        search["transition"].update(foot=search["foot"], foot_bracket=search["foot_bracket"])
    for t in found:
        t["boundary"] = t["foot"] if t["character"] == CROSSOVER and t["foot"] is not None else t["value"]
    return found


def _closest(value: float, candidates: list[float]) -> float | None:
    return min(candidates, key=lambda c: abs(math.log(c / value))) if candidates else None


def _row(runner: Runner, configuration: Configuration, amplitude: float, omegas, k_n: float = K_N) -> dict:
    gamma_n = k_n * GAMMA_N / K_N  # k_n / gamma_n kept at the paper's 14.3
    base = PointSettings(run=_run(runner, configuration, amplitude, k_n=k_n, gamma_n=gamma_n),
                         observe=configuration.observe)
    ds = runner.sweep(Grid((Axis("omega", omegas),)), base)
    regimes = ds.regime.values.tolist()
    curve = {float(w): {"phi": float(p), "contact_fraction": float(c)}
             for w, p, c in zip(omegas, ds.phi.values, ds.contact_fraction.values)}
    transitions = _transitions(runner, base, curve, list(omegas), regimes)
    candidates = predictions(amplitude, k_n=k_n, gamma_n=gamma_n, load=LOAD)
    losses = [t for t in transitions if t["kind"] == LOSS]
    omega_1 = losses[0]["boundary"] if losses else None
    # omega_2: friction regained above the first loss.
    recoveries = [t for t in transitions if t["kind"] == RECOVERY and omega_1 is not None and t["boundary"] > omega_1]
    omega_2 = recoveries[0]["boundary"] if recoveries else None
    return {"configuration": configuration.label, "A": amplitude, "k_n": k_n, "gamma_n": gamma_n,
            "omegas": list(omegas), "regimes": regimes,
            "contact_fraction": ds.contact_fraction.values.tolist(), "phi": ds.phi.values.tolist(),
            "slope_angle_end": ds.slope_angle_end.values.tolist(),
            "transitions": transitions, "omega_1": omega_1, "omega_2": omega_2,
            "omega_2_character": recoveries[0]["character"] if recoveries else None,
            "omega_1_character": losses[0]["character"] if losses else None,
            "omega_2_resolution": recoveries[0]["resolution"] if recoveries else None,
            "loss_above_omega_2": next((t["boundary"] for t in losses if omega_2 and t["boundary"] > omega_2), None),
            "phi_curve": phi_curve(curve),
            **candidates}


def _hysteresis(runner: Runner, configuration: Configuration, amplitude: float, omega_2: float, points: int) -> dict:
    """Ramp omega up then down across omega_2 on one live instance; where friction returns each way."""
    values = tuple(float(v) for v in np.geomspace(omega_2 / 1.6, omega_2 * 1.6, points))
    run = _run(runner, configuration, amplitude, omega=values[0])
    point = PointSettings(run=run, observe=configuration.observe)
    [loop] = runner.tasks(ramp_task, [{"point": point, "ramp": Ramp("omega", values)}])
    up = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "up"]
    down = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "down"]
    up_held = [v for v, r in up if friction_held(r)]
    down_held = [v for v, r in down if friction_held(r)]
    # Friction regained going up: lowest held value above the last sliding one; coming down,
    # the lowest value still held before the first sliding one.
    up_sliding = [v for v, r in up if not friction_held(r)]
    down_sliding = [v for v, r in down if not friction_held(r)]
    up_return = min((v for v in up_held if not up_sliding or v > max(up_sliding)), default=None)
    down_return = min((v for v in down_held if not down_sliding or v > max(down_sliding)), default=None)
    return {"configuration": configuration.label, "A": amplitude, "values": list(values),
            "ramp_ratio": float(values[1] / values[0]), "up_regimes": [r for _, r in up],
            "down_regimes": [r for _, r in down], "up_return": up_return, "down_return": down_return}


def study_recovery(runner: Runner) -> Study:
    sizes = SIZES[runner.resolution.name]
    configurations = [c for c in CONFIGURATIONS if c.label in sizes.configurations]
    rows = [_row(runner, c, a * LOAD / K_N, sizes.omegas if c.model == "A" else sizes.omegas_c)
            for c in configurations for a in (sizes.amplitudes if c.model == "A" else sizes.amplitudes_c)]
    loops = []
    for configuration in configurations:
        first = next((r for r in rows if r["configuration"] == configuration.label and r["omega_2"]), None)
        if first is not None:
            loops.append(_hysteresis(runner, configuration, first["A"], first["omega_2"], sizes.ramp_points))
    # C6d: k_n changes at fixed k_n / gamma_n; A = a delta_0 with delta_0 = P_l / k_n.  On
    # model A (exact and cheap): model C's normal motion in the tangent frame is model A's
    # oscillator with P_l in place of m g, and in model C every held block self-locks.
    stiff_configuration = CONFIGURATIONS[0]
    scaled_amplitude = sizes.amplitudes[0]
    stiffness_rows = [_row(runner, stiff_configuration, scaled_amplitude * LOAD / k_n, sizes.omegas, k_n=k_n)
                      for k_n in sizes.stiffnesses]
    for row in rows + stiffness_rows:
        if row["omega_2"] is not None:
            row["closest_A_N_root"] = _closest(row["omega_2"], row["A_N_roots"])
            row["closest_A_c_root"] = _closest(row["omega_2"], row["A_c_roots"])
    measured = {"rows": rows, "loops": loops, "stiffness_rows": stiffness_rows,
                "stiffness_configuration": stiff_configuration.label, "scaled_amplitude": scaled_amplitude,
                "resolution": RECOVERY_RESOLUTION}
    settings = {"models": ", ".join(c.label for c in configurations),
                "parameters": "scaled drive (k_d = V_d = 1e-2, gamma_t = 5e-3), k_n = 1, gamma_n = 0.07, P_l = m g = 1; "
                              "C on the paper's plate",
                "amplitudes": "A / delta_0 = " + ", ".join(f"{a:g}" for a in sizes.amplitudes) + " (model A), "
                              + (", ".join(f"{a:g}" for a in sizes.amplitudes_c) or "none") + " (model C)",
                "horizon": "A: 2e4 (transient 4e3); C: 6e4 (transient 4e4)",
                "integrators": "; ".join(f"{c.label}: {_run(runner, c, 0.1).integration.describe()}"
                                         for c in configurations),
                "initial": "A: steady orbit; C: crest, steady orbit, spring relaxed at t0",
                "bisection": f"to {RECOVERY_RESOLUTION:.0%} in omega", **observe_json(CONFIGURATIONS[0].observe)}
    return Study("C6r", measured, settings, {"rows": rows + stiffness_rows, "loops": loops})





# ---------------------------------------------------------------------- verdicts
WITHIN = 0.25  # "omega_2 ~ k_n/gamma_n": within 25 % (the report's RECOVERY_SLACK)


def _spread(values: list[float]) -> float:
    return max(values) / min(values) - 1.0


def verdict_rows(m: dict) -> list:
    """Report rows: the paper's recovery claims against the located transitions."""
    rows, resolution = [], m["resolution"]
    by_configuration: dict[str, list[dict]] = {}
    for row in m["rows"]:
        by_configuration.setdefault(row["configuration"], []).append(row)

    def jams(r):
        angles = [a for a, regime in zip(r.get("slope_angle_end", []), r["regimes"]) if regime == "jammed"]
        return (f"; jammed at {len(angles)}/{len(r['regimes'])} grid omegas, on slopes of {min(angles):.0f} to "
                f"{max(angles):.0f} deg") if angles else ""

    def character(r, part):
        kind = r.get(f"{part}_character")
        return f" ({kind}{', at its foot' if kind == CROSSOVER else ''})" if kind else ""

    def located(r):
        return (f"{r['configuration']}, A = {r['A']:g}: friction lost at {fmt(r['omega_1'])}{character(r, 'omega_1')}, "
                f"back at {fmt(r['omega_2'])}{character(r, 'omega_2')}, lost again at "
                f"{fmt(r['loss_above_omega_2'])} (A_N roots "
                + ", ".join(f"{w:.3g}" for w in r["A_N_roots"]) + "; A_c roots "
                + ", ".join(f"{w:.3g}" for w in r["A_c_roots"]) + ")" + jams(r))

    measured = "; ".join(located(r) for r in m["rows"])
    flat = [r for r in m["rows"] if r["configuration"].startswith("A,")]
    if not flat:
        rows.append(Row("C6r-a", measured, NOT_REPRODUCED, "model A not run at this resolution"))
    else:
        recovered = [r for r in flat if r["omega_2"] is not None]
        rows.append(Row("C6r-a", measured, DISAGREES if recovered else AGREES,
                        f"the flat plate (model A) regains friction above the resonance in {len(recovered)}/{len(flat)} "
                        "rows: recovery does not need a modulated surface" if recovered else
                        "the flat plate never regains friction in the scanned range"))

    parts, explained = [], []
    for label, group in by_configuration.items():
        found = [r for r in group if r["omega_2"] is not None]
        if not found:
            parts.append((NOT_REPRODUCED, f"{label}: no recovery"))
            continue
        near = [r for r in found if abs(math.log(r["omega_2"] / r["k_n_over_gamma_n"])) <= math.log(1 + WITHIN)]
        parts.append((AGREES if len(near) == len(found) else DISAGREES,
                      f"{label}: omega_2 within {WITHIN:.0%} of k_n/gamma_n in {len(near)}/{len(found)}"))
        if len(found) > 1:
            spread = _spread([r["omega_2"] for r in found])
            parts.append((AGREES if spread <= 2 * resolution else DISAGREES,
                          f"{label}: omega_2 spreads {spread:.0%} over A"))
        for r in found:
            for name in ("closest_A_N_root", "closest_A_c_root"):
                root = r.get(name)
                if root is not None and abs(math.log(r["omega_2"] / root)) <= 2 * resolution:
                    explained.append(f"{label}, A = {r['A']:g}: omega_2 = {r['omega_2']:.3g} at the "
                                     f"{'A_N' if 'N' in name else 'A_c'} root {root:.3g}")
                    break
    verdict, reason = combine(parts)
    if explained:
        reason += ". Explained by the contact oscillator: " + "; ".join(explained)
    rows.append(Row("C6r-b", measured, verdict, reason))

    loops = m["loops"]
    measured = "; ".join(f"{lp['configuration']}, A = {lp['A']:g}: friction back at {fmt(lp['up_return'])} going up, "
                         f"{fmt(lp['down_return'])} coming down (ramp step x{lp['ramp_ratio']:.3g})" for lp in loops)
    if not loops:
        rows.append(Row("C6r-c", "no recovery to ramp across", NOT_REPRODUCED, "no omega_2 located"))
    else:
        parts = []
        for lp in loops:
            if lp["up_return"] is None or lp["down_return"] is None:
                parts.append((NOT_REPRODUCED, f"{lp['configuration']}: a ramp never regains friction"))
                continue
            steps = abs(math.log(lp["up_return"] / lp["down_return"])) / math.log(lp["ramp_ratio"])
            parts.append((AGREES if steps < 1.5 else DISAGREES,
                          f"{lp['configuration']}: up and down differ by {steps:.0f} ramp step(s)"))
        rows.append(Row("C6r-c", measured, *combine(parts)))

    stiff = m["stiffness_rows"]
    measured = (f"{m['stiffness_configuration']}, A = {m['scaled_amplitude']:g} P_l/k_n: "
                + ", ".join(f"k_n = {r['k_n']:g}: omega_2 = {fmt(r['omega_2'])} (k_n/gamma_n = "
                            f"{r['k_n_over_gamma_n']:.3g}, A_N root {fmt(r.get('closest_A_N_root'))})" for r in stiff))
    found = [r for r in stiff if r["omega_2"] is not None]
    if len(found) < 2:
        rows.append(Row("C6r-d", measured, NOT_REPRODUCED, "fewer than two stiffnesses regain friction"))
    else:
        spread = _spread([r["omega_2"] for r in found])
        k_spread = _spread([r["k_n"] for r in found])
        rows.append(Row("C6r-d", measured, AGREES if spread <= WITHIN else DISAGREES,
                        f"omega_2 spreads {spread:.0%} while k_n spreads {k_spread:.0%} at fixed k_n/gamma_n"))
    return rows


TEXT = {
    "C6r-a": "C: friction recovery needs the modulated surface (the flat plate does not recover)",
    "C6r-b": "C: omega_2 ~ k_n/gamma_n, independent of A (A below delta_0 = P_l/k_n, bisected)",
    "C6r-c": "C: no hysteresis at omega_2 (continuation up and down across it)",
    "C6r-d": "C: omega_2 weakly dependent on k_n at fixed k_n/gamma_n, A scaled by delta_0",
}


# ---------------------------------------------------------------------- figure
FIGURE = "recovery_question.png"
FIGURES = {part: [FIGURE] for part in ("C6r-a", "C6r-b", "C6r-c", "C6r-d")}


# The located transitions (friction lost: True), in colours no regime uses.
TRANSITION_STYLE = {True: {"marker": "v", "color": "tab:brown", "label": "friction lost (located)"},
                    False: {"marker": "^", "color": "tab:cyan", "label": "friction regained (located)"}}


def draw(study: Study, save) -> None:
    """One panel per configuration: regimes on the omega grid at each A (in delta_0), the
    located transitions (bars: the bisection bracket), A_c(omega) and A_N(omega), k_n/gamma_n."""
    import matplotlib.pyplot as plt
    from vibroblock.orbits import detachment_amplitude, friction_loss_amplitude

    from harness.paper.plots import REGIME_STYLE

    rows = [r for r in study.measured["rows"]] + [
        {**r, "configuration": f"{r['configuration']}, k_n = {r['k_n']:g} (A in P_l/k_n)"}
        for r in study.measured["stiffness_rows"] if r["k_n"] != K_N]
    labels = list(dict.fromkeys(r["configuration"] for r in rows))
    fig, axes = plt.subplots(len(labels), 1, figsize=(7.0, 2.6 * len(labels)), squeeze=False)
    for ax, label in zip(axes[:, 0], labels):
        group = [r for r in rows if r["configuration"] == label]
        k_n, gamma_n = group[0]["k_n"], group[0]["gamma_n"]
        delta_0 = LOAD / k_n
        line = np.geomspace(min(group[0]["omegas"]) / 1.5, max(group[0]["omegas"]) * 1.5, 400)
        ax.plot(line, detachment_amplitude(line, 1.0, LOAD, k_n, gamma_n) / delta_0, "k-", lw=1, label="$A_c(\\omega)$")
        ax.plot(line, friction_loss_amplitude(line, 1.0, LOAD, k_n, gamma_n) / delta_0, "k--", lw=1,
                label="$A_N(\\omega)$")
        ax.axvline(k_n / gamma_n, color="tab:olive", lw=1, label="$k_n/\\gamma_n$")
        shown = set()
        for r in group:
            level = r["A"] / delta_0
            for omega, regime in zip(r["omegas"], r["regimes"]):
                style = REGIME_STYLE.get(regime, {"marker": "?", "color": "k", "label": regime})
                ax.scatter([omega], [level], marker=style["marker"], color=style["color"],
                           label=None if regime in shown else style["label"])
                shown.add(regime)
            for t in r["transitions"]:
                # Colours and markers of their own: the regimes' colours mean regimes only.
                lost = t["kind"] == LOSS
                style = TRANSITION_STYLE[lost]
                at = t.get("boundary", t["value"])  # a crossover's foot, a sharp change's located value
                ax.plot([at], [level * 1.5], marker=style["marker"], color=style["color"], ms=7,
                        label=None if style["label"] in shown else style["label"])
                shown.add(style["label"])
                # The value above its marker, offset in points so that it never covers one.
                ax.annotate(f"{at:.3g}", (at, level * 1.5), xytext=(0, 7), textcoords="offset points",
                            ha="center", va="bottom", fontsize=7, color=style["color"])
        ax.set(xscale="log", yscale="log", ylim=(0.05, 3.0), xlabel="$\\omega$ [$\\tau_0^{-1}$]",
               ylabel="$A$ [$\\delta_0$]", title=label)
        ax.legend(fontsize=6, ncol=3, loc="lower left")
    fig.suptitle("Friction lost (brown, down) and regained (cyan, up) where bisection located it; markers below: the "
                 "regime of each run; scaled drive", fontsize=9)
    save(fig, FIGURE)

CLAIM = Claim("C6r", study_recovery, verdict_rows, TEXT, FIGURES, draw)

__all__ = ["CLAIM", "CONFIGURATIONS", "FIGURE", "RECOVERY_RESOLUTION", "TEXT", "crossings", "draw", "predictions",
           "study_recovery", "verdict_rows"]
