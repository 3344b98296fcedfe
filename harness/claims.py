"""The studies behind the claims report: each claim C1-C8 of DESIGN.md -> measured values.

Every study is a function ``study_cN(runner) -> Study``: it runs sweeps (through
:func:`harness.sweep.run_sweep`, persisted in the runner's point store) and single runs
or continuation ramps (through :func:`harness.sweep.map_with_pool`, each result cached
as JSON under ``<store>/studies`` keyed by its inputs and the FMU's sha256), and returns
plain numbers.  Nothing here decides whether a claim holds: :mod:`harness.report` turns
the numbers into verdicts by explicit criteria.

Sizes (grid points, horizons, ramp steps) come from a :class:`Resolution`; ``default``
is the main job's, ``quick`` a one-minute version, ``tiny`` the tests'.

Conventions used by all studies
-------------------------------
* Model A uses the ``scaled`` preset (k_d = V_d = 1e-2, gamma_t = 5e-3): the paper's
  drive makes one stick-slip cycle ~5e7 tau_0.  Models B and C use the paper's plate
  (A_x = 1e3, omega_x = 2e-2, P_l = 1) with the same scaled drive.
* Vibrated runs start on the steady in-contact orbit (``steady_orbit``).  Models B and
  C start at a valley (B) or a crest (C) of the corrugation, at the time when the drive
  spring is relaxed (start_time = x_start / V_d), so that no spring force acts at t0.
* "Friction" = the block is held by friction in the window: regime stick_slip, stuck
  (no slip and no sliding within the window) or jammed (self-locked on a flank);
  "sliding" = it follows the drive; "flying" = no contact in the window (not friction).
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from .continuation import Ramp, continuation
from .fmu import fmu_sha256
from .observables import FLYING, SLIDING, STICK_SLIP, observe, window, window_slips
from .run import simulate
from .settings import (PRESETS, InitialCondition, ObservableSettings, PointSettings, RunSettings, canonical_json,
                       default_fmu, to_jsonable)
from .store import write_json_atomically
from .sweep import OBSERVABLES_VERSION, Axis, Execution, Grid, map_with_pool, run_sweep

SCALED = dict(PRESETS["scaled"])
OMEGA_X = 2e-2
VALLEY = 3 * math.pi / (2 * OMEGA_X)  # sin(omega_x x) = -1
CREST = math.pi / (2 * OMEGA_X)       # sin(omega_x x) = +1
WAVELENGTH = 2 * math.pi / OMEGA_X
TRACE_POINTS = 3000  # samples kept of a trajectory for figures

# Observation settings per use (all reported with the results).
OBSERVE_A = ObservableSettings(transient=4000.0)
# Vibration splits slips into short bursts separated by tangential ringing; bursts closer
# than merge_gap are one slip, and slips down to 5 % of mu_s m g / k_d count.
OBSERVE_A_BURSTS = ObservableSettings(transient=4000.0, slip_min_fraction=0.05, merge_gap=100.0)
OBSERVE_SHORT = ObservableSettings(transient=2000.0)
OBSERVE_B = ObservableSettings(transient=5000.0, merge_gap=100.0)


@dataclass(frozen=True)
class Resolution:
    """Sizes of the studies (see module doc)."""

    name: str
    horizon_a: float           # model A runs and sweep points
    c2_amplitudes: tuple
    c3_omegas: tuple
    c3_amplitudes: tuple
    c4_gammas: tuple
    c4_omegas: tuple
    c4_step: float             # duration of a ramp step
    b_horizon: float           # model B x(t) runs
    b_amplitudes: tuple
    c_horizon: float           # model C sweep points
    c6_amplitudes: tuple
    c6_omegas: tuple
    c6_ratios: tuple           # k_n / gamma_n
    c6_stiffnesses: tuple      # k_n
    c6_relative_omegas: tuple  # omega / (k_n / gamma_n)
    c6_ramp: tuple
    c6_ramp_step: float
    c7_omegas: tuple
    contact_horizon: float
    c8_velocities: tuple
    c8_omegas: tuple


RESOLUTIONS = {
    "default": Resolution(
        name="default", horizon_a=20_000.0, c2_amplitudes=(0.0, 4.0, 8.0, 12.0, 15.0),
        c3_omegas=tuple(np.round(np.geomspace(0.1, 4.0, 9), 4)),
        c3_amplitudes=tuple(np.round(np.geomspace(0.02, 300.0, 10), 4)),
        c4_gammas=(0.035, 0.07, 0.14, 0.28), c4_omegas=tuple(np.round(np.arange(0.15, 0.5001, 0.025), 4)),
        c4_step=12_000.0, b_horizon=100_000.0, b_amplitudes=(0.0, 1.0, 2.5, 5.0, 10.0), c_horizon=10_000.0,
        c6_amplitudes=(0.1, 0.3, 1.0, 3.0, 10.0, 30.0), c6_omegas=tuple(np.round(np.geomspace(0.1, 50.0, 10), 4)),
        c6_ratios=(7.0, 14.29, 28.57), c6_stiffnesses=(0.5, 1.0, 2.0),
        c6_relative_omegas=(0.25, 0.5, 1.0, 1.5, 2.0, 3.0), c6_ramp=(5.0, 8.0, 11.0, 14.0, 17.0, 22.0, 30.0, 40.0),
        c6_ramp_step=8_000.0, c7_omegas=tuple(np.round(np.geomspace(0.1, 50.0, 10), 4)), contact_horizon=5_000.0,
        c8_velocities=(1e-3, 1e-2, 0.1, 1.0, 10.0), c8_omegas=(0.1, 0.3, 1.0, 3.0, 10.0, 30.0)),
    "quick": Resolution(
        name="quick", horizon_a=14_000.0, c2_amplitudes=(0.0, 8.0, 15.0), c3_omegas=(0.1, 0.3, 1.0, 3.0),
        c3_amplitudes=(0.03, 0.3, 3.0, 30.0, 300.0), c4_gammas=(0.035, 0.07, 0.28),
        c4_omegas=(0.2, 0.3, 0.4, 0.5), c4_step=8_000.0, b_horizon=40_000.0, b_amplitudes=(0.0, 5.0),
        c_horizon=5_000.0, c6_amplitudes=(0.3, 3.0), c6_omegas=(0.1, 1.0, 5.0, 14.0, 40.0),
        c6_ratios=(7.0, 14.29), c6_stiffnesses=(1.0, 2.0), c6_relative_omegas=(0.5, 2.0),
        c6_ramp=(5.0, 14.0, 40.0), c6_ramp_step=4_000.0, c7_omegas=(0.1, 1.0, 14.0, 40.0),
        contact_horizon=3_000.0, c8_velocities=(1e-2, 10.0), c8_omegas=(0.3, 3.0)),
    "tiny": Resolution(
        name="tiny", horizon_a=6_000.0, c2_amplitudes=(0.0, 8.0), c3_omegas=(0.2, 2.0), c3_amplitudes=(0.1, 100.0),
        c4_gammas=(0.07, 0.28), c4_omegas=(0.25, 0.45), c4_step=3_000.0, b_horizon=8_000.0, b_amplitudes=(0.0, 5.0),
        c_horizon=3_000.0, c6_amplitudes=(3.0,), c6_omegas=(0.3, 14.0), c6_ratios=(14.29,), c6_stiffnesses=(1.0,),
        c6_relative_omegas=(0.5, 2.0), c6_ramp=(5.0, 30.0), c6_ramp_step=2_500.0, c7_omegas=(0.3, 14.0),
        contact_horizon=2_500.0, c8_velocities=(10.0,), c8_omegas=(0.3,)),
}


@dataclass
class Study:
    """What one claim's study measured.

    ``measured``: the numbers the verdict is computed from (JSON-able);
    ``settings``: parameter set, start, threshold, window, transient per part;
    ``data``: arrays for the figures (JSON-able lists)."""

    claim: str
    measured: dict
    settings: dict
    data: dict = field(default_factory=dict)


# ---------------------------------------------------------------------- execution
class Runner:
    """Runs sweeps and cached tasks for the studies on one Dask client (or inline)."""

    def __init__(self, store: str | os.PathLike, resolution: Resolution, execution: Execution = Execution(),
                 client=None, fmus: dict | None = None):
        self.store = Path(store)
        self.resolution = resolution
        self.execution = execution
        self.client = client
        self.fmus = {m: str((fmus or {}).get(m, default_fmu(m))) for m in "ABC"}
        self._sha = {m: fmu_sha256(path) for m, path in self.fmus.items()}
        self.points_computed = 0
        self.points_reused = 0

    def run(self, model: str, **fields) -> RunSettings:
        return RunSettings(fmu=self.fmus[model], **fields)

    def sweep(self, grid: Grid, base: PointSettings):
        outcome = run_sweep(grid, base, self.store / "points", self.execution, self.client)
        self.points_computed += outcome.computed
        self.points_reused += outcome.reused
        return outcome.dataset

    def tasks(self, function: Callable, items: Sequence[dict]) -> list[dict]:
        """``function(item, pool)`` for every item, cached by (function, item, FMU hashes)."""
        folder = self.store / "studies"
        keys = []
        for item in items:
            text = canonical_json({"function": f"{function.__module__}.{function.__qualname__}", "item": item,
                                   "fmu_sha256": self._sha, "observables_version": OBSERVABLES_VERSION})
            keys.append(hashlib.sha256(text.encode()).hexdigest())
        results: dict[int, dict] = {}
        for number, key in enumerate(keys):
            path = folder / f"{key}.json"
            if path.exists():
                results[number] = json.loads(path.read_text())["result"]
        missing = [n for n in range(len(items)) if n not in results]
        if missing:
            computed = map_with_pool(function, [items[n] for n in missing], self.execution, self.client)
            for number, result in zip(missing, computed):
                write_json_atomically(folder / f"{keys[number]}.json", {"item": to_jsonable(items[number]),
                                                                        "result": result})
                results[number] = result
        return [results[n] for n in range(len(items))]


def _jsonable_float(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _trace(ds, points: int = TRACE_POINTS) -> dict:
    stride = max(1, len(ds.time) // points)
    return {"time": ds.time.values[::stride].tolist(), "x": ds.x.values[::stride].tolist()}


# ---------------------------------------------------------------------- worker tasks
def run_and_measure(item: dict, pool) -> dict:
    """One run: observables plus the extras named in ``item["extras"]`` (worker task)."""
    point: PointSettings = item["point"]
    extras = item.get("extras", ())
    outputs = ("x", "vx", "phi_integral", "contact", "slip_count", "penetration")
    ds = simulate(point.run, pool, outputs=outputs)
    result = {"observables": observe(ds, point.observe).as_dict()}
    win = window(ds, point.observe.transient, point.observe.window)
    part = win.slice()
    t, x, vx = ds.time.values[part], ds.x.values[part], ds.vx.values[part]
    v_d = float(ds.attrs["V_d"])
    if "rest_penetration" in extras:
        result["rest_penetration"] = float(np.mean(ds.penetration.values[part]))
    if "creep" in extras:
        result["creep_velocity"] = _creep_velocity(ds, win, point.observe)
    if "offset" in extras:
        # Stationary sliding x = V_d t - x0: x0 is the mean lag behind the drive.
        result["offset"] = float(np.mean(v_d * t - x))
        result["offset_std"] = float(np.std(v_d * t - x))
    if "trace" in extras:
        result["trace"] = _trace(ds)
    if "stick_roots" in extras:
        result.update(_stick_root_distances(ds, t, x, vx, v_d))
    return result


def _creep_velocity(ds, win, settings: ObservableSettings) -> float | None:
    """Median slope of x over the middle half of each complete stick phase in the window."""
    slips = window_slips(ds, win, settings)
    t, x = ds.time.values, ds.x.values
    slopes = []
    for begin, end in zip(slips.end[:-1], slips.onset[1:]):
        lo, hi = begin + 0.25 * (end - begin), begin + 0.75 * (end - begin)
        chosen = (t >= lo) & (t <= hi)
        if chosen.sum() >= 3:
            slopes.append(np.polyfit(t[chosen], x[chosen], 1)[0])
    return _jsonable_float(np.median(slopes)) if slopes else None


def stable_roots_near(x: float, drive: float, k_ratio: float, omega_x: float = OMEGA_X) -> float:
    """The stable root x* of cos(omega_x x*) = K (x* - drive) nearest to x (sin(omega_x x*) < 0),
    searched within one wavelength either side; nan if none."""
    span = 2 * math.pi / omega_x
    grid = np.linspace(x - span, x + span, 4001)
    h = np.cos(omega_x * grid) - k_ratio * (grid - drive)
    change = np.flatnonzero(np.sign(h[:-1]) != np.sign(h[1:]))
    if not len(change):
        return math.nan
    roots = grid[change] - h[change] * (grid[change + 1] - grid[change]) / (h[change + 1] - h[change])
    roots = roots[np.sin(omega_x * roots) < 0]
    if not len(roots):
        return math.nan
    return float(roots[np.argmin(np.abs(roots - x))])


def _stick_root_distances(ds, t, x, vx, v_d) -> dict:
    """Distances of the stuck block from the nearest stable root of the paper's Eq. (9)."""
    a = ds.attrs
    k_ratio = -a["k_d"] / (a["A_x"] * a["omega_x"] * a["m"] * a["g"])
    stuck = np.flatnonzero(np.abs(vx) < 0.2 * abs(v_d))
    if not len(stuck):
        return {"stick_samples": 0, "root_distance_median": None, "root_distance_p90": None}
    chosen = stuck[np.linspace(0, len(stuck) - 1, min(400, len(stuck))).astype(int)]
    distances = np.array([abs(x[i] - stable_roots_near(x[i], v_d * t[i], k_ratio, a["omega_x"])) for i in chosen])
    distances = distances[np.isfinite(distances)]
    return {"stick_samples": int(len(stuck)), "stick_share": float(len(stuck) / len(x)),
            "root_distance_median": _jsonable_float(np.median(distances)) if len(distances) else None,
            "root_distance_p90": _jsonable_float(np.percentile(distances, 90)) if len(distances) else None}


def ramp_task(item: dict, pool) -> dict:
    """A continuation ramp (worker task): per step direction, value, regime, phi, contact."""
    ds = continuation(item["point"], item["ramp"], pool)
    parameter = item["ramp"].parameter
    return {"direction": ds.direction.values.tolist(), "value": ds[parameter].values.tolist(),
            "regime": ds.regime.values.tolist(), "phi": ds.phi.values.tolist(),
            "contact_fraction": ds.contact_fraction.values.tolist()}


# ---------------------------------------------------------------------- helpers
def friction_held(regime: str) -> bool:
    """Held by friction in the window: stick-slip, stuck or jammed (not sliding, not flying)."""
    return regime not in (SLIDING, FLYING)


def first_sliding(values: Sequence[float], regimes: Sequence[str]) -> float | None:
    """First value (in the given order) whose regime is sliding."""
    for value, regime in zip(values, regimes):
        if regime == SLIDING:
            return float(value)
    return None


def regime_changes(regimes: Sequence[str]) -> int:
    held = [friction_held(r) for r in regimes]
    return int(sum(a != b for a, b in zip(held[:-1], held[1:])))


def transition_bracket(values: Sequence[float], regimes: Sequence[str]) -> tuple[float | None, float | None]:
    """(value just below the first sliding one, first sliding value) along ascending values;
    (largest value, None) when nothing slides."""
    first = first_sliding(values, regimes)
    if first is None:
        return float(values[-1]), None
    index = list(values).index(first)
    return (float(values[index - 1]) if index > 0 else None), first


def onset_amplitude(omega, load: float = 1.0, m: float = 1.0, k_n: float = 1.0, gamma_n: float = 0.07):
    """A_c(omega) of the steady in-contact orbit, with the load m g (A, B) or P_l (C):
    ``vibroblock.orbits.detachment_amplitude`` with g = load / m."""
    from vibroblock.orbits import detachment_amplitude
    return detachment_amplitude(omega, m=m, g=load / m, k_n=k_n, gamma_n=gamma_n)


def _observe_json(observe_settings: ObservableSettings) -> dict:
    return {"phi_threshold": observe_settings.phi_threshold, "transient": observe_settings.transient,
            "window": "rest of run" if observe_settings.window is None else observe_settings.window,
            "slip_min_fraction": observe_settings.slip_min_fraction, "merge_gap": observe_settings.merge_gap}


def _relaxed_start(x_start: float, v_d: float) -> float:
    return x_start / v_d


# ---------------------------------------------------------------------- studies
def study_c1(runner: Runner) -> Study:
    """Model A at rest: penetration, creep, stick time and slip length against their formulas."""
    res = runner.resolution
    parameters = {**SCALED, "A": 0.0, "omega": 0.0}
    horizon = max(res.horizon_a, 20_000.0)
    point = PointSettings(run=runner.run("A", parameters=parameters, horizon=horizon,
                                         initial=InitialCondition("equilibrium")), observe=OBSERVE_A)
    [result] = runner.tasks(run_and_measure, [{"point": point, "extras": ["rest_penetration", "creep", "trace"]}])
    m = g = k_n = 1.0
    k_t, mu_s = 0.28, 0.5
    k_d, v_d = SCALED["k_d"], SCALED["V_d"]
    creep = v_d * k_d / (k_t + k_d)
    obs = result["observables"]
    measured = {
        "rest_penetration": result["rest_penetration"], "rest_penetration_formula": m * g / k_n,
        "creep_velocity": result["creep_velocity"], "creep_velocity_formula": creep,
        "stick_time": obs["stick_time_mean"], "stick_time_formula": mu_s * m * g / (k_t * creep),
        "slip_length": obs["slip_length_mean"], "slip_length_formula": mu_s * m * g / k_d,
        "slip_events": obs["slip_events"], "regime": obs["regime"],
    }
    settings = {"model": "A", "parameters": "scaled", **parameters, "horizon": horizon,
                "initial": "equilibrium (plate at rest)", **_observe_json(OBSERVE_A)}
    return Study("C1", measured, settings, {"trace": result["trace"]})


def study_c2(runner: Runner) -> Study:
    """Model A below g: slip statistics against A at fixed omega."""
    res = runner.resolution
    omega = 0.25
    base = PointSettings(run=runner.run("A", parameters={**SCALED, "omega": omega}, horizon=max(res.horizon_a, 16_000.0)),
                         observe=OBSERVE_A_BURSTS)
    ds = runner.sweep(Grid((Axis("A", res.c2_amplitudes),)), base)
    amplitudes = ds.A.values.tolist()
    measured = {"omega": omega, "amplitudes": amplitudes,
                "peak_acceleration_over_g": [a * omega**2 for a in amplitudes],
                "slip_interval": [_jsonable_float(v) for v in ds.slip_interval_mean.values],
                "stick_time": [_jsonable_float(v) for v in ds.stick_time_mean.values],
                "slip_length": [_jsonable_float(v) for v in ds.slip_length_mean.values],
                "slip_events": ds.slip_events.values.tolist(), "regime": ds.regime.values.tolist()}
    settings = {"model": "A", "parameters": "scaled", "omega": omega, "horizon": base.run.horizon,
                "initial": "steady orbit", **_observe_json(OBSERVE_A_BURSTS)}
    return Study("C2", measured, settings)


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
                **_observe_json(OBSERVE_A)}
    data = {"omega": ds.omega.values.tolist(), "A": ds.A.values.tolist(),
            "regime": ds.regime.transpose("A", "omega").values.tolist(),
            "phi": ds.phi.transpose("A", "omega").values.tolist()}
    return Study("C3", measured, settings, data)


def _ramp_branches(loop: dict) -> tuple[float | None, float | None]:
    """omega_1: first sliding value going up; omega*: the highest value of the down branch
    held by friction (where friction comes back on the way down)."""
    up = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "up"]
    down = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "down"]
    omega_1 = first_sliding([v for v, _ in up], [r for _, r in up])
    held_down = [v for v, r in down if friction_held(r)]
    omega_star = max(held_down) if held_down else None
    return omega_1, omega_star


def study_c4(runner: Runner) -> Study:
    """Model A: continuation in omega up then down at fixed A for several gamma_n; fresh starts."""
    res = runner.resolution
    amplitude = 10.0
    step_observe = ObservableSettings(transient=2000.0)
    ramp = Ramp("omega", res.c4_omegas)
    items = []
    for gamma_n in res.c4_gammas:
        run = runner.run("A", parameters={**SCALED, "A": amplitude, "gamma_n": gamma_n}, horizon=res.c4_step)
        items.append({"point": PointSettings(run=run, observe=step_observe), "ramp": ramp})
    loops = runner.tasks(ramp_task, items)
    middle_gamma = res.c4_gammas[len(res.c4_gammas) // 2]
    fresh = {}
    for kind in ("steady_orbit", "equilibrium"):
        base = PointSettings(run=runner.run("A", parameters={**SCALED, "A": amplitude, "gamma_n": middle_gamma},
                                            horizon=res.c4_step, initial=InitialCondition(kind)),
                             observe=step_observe)
        ds = runner.sweep(Grid((Axis("omega", res.c4_omegas),)), base)
        fresh[kind] = ds.regime.values.tolist()
    per_gamma = []
    for gamma_n, loop in zip(res.c4_gammas, loops):
        omega_1, omega_star = _ramp_branches(loop)
        per_gamma.append({"gamma_n": gamma_n, "omega_1": omega_1, "omega_star": omega_star,
                          "onset_omega": _onset_omega(amplitude, gamma_n)})
    middle = loops[res.c4_gammas.index(middle_gamma)]
    down = {v: r for d, v, r in zip(middle["direction"], middle["value"], middle["regime"]) if d == "down"}
    up = {v: r for d, v, r in zip(middle["direction"], middle["value"], middle["regime"]) if d == "up"}
    differs = [float(v) for v, r in zip(res.c4_omegas, fresh["steady_orbit"])
               if v in down and friction_held(down[v]) != friction_held(r)]
    impact_differs = [float(v) for v, r in zip(res.c4_omegas, fresh["equilibrium"])
                      if friction_held(up[v]) != friction_held(r)]
    measured = {"amplitude": amplitude, "omega_step": float(np.min(np.diff(res.c4_omegas))) if len(res.c4_omegas) > 1
                else None, "per_gamma": per_gamma, "fresh_gamma_n": middle_gamma,
                "fresh_steady_orbit": fresh["steady_orbit"], "fresh_equilibrium": fresh["equilibrium"],
                "omegas": list(res.c4_omegas), "down_differs_from_fresh_orbit": differs,
                "up_differs_from_fresh_impact": impact_differs}
    settings = {"model": "A", "parameters": "scaled", "A": amplitude, "step_duration": res.c4_step,
                "initial": "steady orbit at the first ramp value; fresh starts: steady orbit and equilibrium (impact)",
                **_observe_json(step_observe)}
    data = {"loops": [{"gamma_n": g, **loop} for g, loop in zip(res.c4_gammas, loops)]}
    return Study("C4", measured, settings, data)


def _onset_omega(amplitude: float, gamma_n: float, load: float = 1.0, k_n: float = 1.0) -> float | None:
    """Lowest omega at which A_c(omega) falls to ``amplitude`` (bisection on a fine grid)."""
    grid = np.geomspace(1e-3, 100.0, 20001)
    below = np.flatnonzero(onset_amplitude(grid, load, 1.0, k_n, gamma_n) <= amplitude)
    return float(grid[below[0]]) if len(below) else None


def _b_point(runner: Runner, horizon: float, observe_settings: ObservableSettings, **parameters) -> PointSettings:
    values = {**SCALED, **parameters}
    run = runner.run("B", parameters=values, horizon=horizon, output_interval=2.0,
                     initial=InitialCondition("steady_orbit", x_start=VALLEY),
                     start_time=_relaxed_start(VALLEY, values["V_d"]))
    return PointSettings(run=run, observe=observe_settings)


def study_c5(runner: Runner) -> Study:
    """Model B: x(t) for several A at omega = 0.5, stick positions, and k_t = 0."""
    res = runner.resolution
    omega = 0.5
    items = [{"point": _b_point(runner, res.b_horizon, OBSERVE_B, A=a, omega=omega),
              "extras": ["trace", "stick_roots"]} for a in res.b_amplitudes]
    items.append({"point": _b_point(runner, res.b_horizon, OBSERVE_B, A=0.0, omega=omega, k_t=0.0),
                  "extras": ["trace", "stick_roots"]})
    results = runner.tasks(run_and_measure, items)
    runs = []
    for amplitude, result in zip(res.b_amplitudes, results):
        obs = result["observables"]
        runs.append({"A": amplitude, "peak_acceleration_over_g": amplitude * omega**2, "regime": obs["regime"],
                     "slip_events": obs["slip_events"], "slip_interval": obs["slip_interval_mean"],
                     "slip_length": obs["slip_length_mean"], "drift_velocity": obs["drift_velocity"],
                     "contact_fraction": obs["contact_fraction"],
                     "root_distance_median": result["root_distance_median"]})
    reference = np.interp(results[0]["trace"]["time"], results[0]["trace"]["time"], results[0]["trace"]["x"])
    for run, result in zip(runs, results):
        other = np.interp(results[0]["trace"]["time"], result["trace"]["time"], result["trace"]["x"])
        run["max_x_difference"] = float(np.max(np.abs(other - reference)))
    frictionless = results[-1]
    obs = frictionless["observables"]
    measured = {"omega": omega, "runs": runs, "wavelength": WAVELENGTH, "V_d": SCALED["V_d"],
                "frictionless": {"regime": obs["regime"], "slip_events": obs["slip_events"],
                                 "slip_length": obs["slip_length_mean"],
                                 "root_distance_median": frictionless["root_distance_median"],
                                 "root_distance_p90": frictionless["root_distance_p90"]}}
    settings = {"model": "B", "parameters": "paper plate (A_x = 1e3, omega_x = 2e-2), scaled drive "
                "k_d = V_d = 1e-2, gamma_t = 5e-3", "omega": omega, "horizon": res.b_horizon,
                "initial": f"valley x = 3 pi/(2 omega_x) = {VALLEY:.1f}, steady orbit, spring relaxed at t0",
                **_observe_json(OBSERVE_B)}
    data = {"traces": [{"A": a, **r["trace"]} for a, r in zip(res.b_amplitudes, results)],
            "frictionless_trace": frictionless["trace"]}
    return Study("C5", measured, settings, data)


def _c_run(runner: Runner, horizon: float, **parameters) -> RunSettings:
    values = {**SCALED, **parameters}
    return runner.run("C", parameters=values, horizon=horizon, initial=InitialCondition("steady_orbit", x_start=CREST),
                      start_time=_relaxed_start(CREST, values["V_d"]))


C_START = f"crest x = pi/(2 omega_x) = {CREST:.1f}, steady orbit, spring relaxed at t0"
C_PARAMETERS = "paper plate (A_x = 1e3, omega_x = 2e-2, P_l = 1), scaled drive k_d = V_d = 1e-2, gamma_t = 5e-3"


def _rows(ds, row: str, column: str) -> list[dict]:
    rows = []
    for value in ds[row].values:
        regimes = ds.regime.sel({row: value}).values.tolist()
        rows.append({row: float(value), "regimes": regimes,
                     "contact_fraction": ds.contact_fraction.sel({row: value}).values.tolist()})
    return rows


def recovery(values: Sequence[float], regimes: Sequence[str]) -> dict:
    """Along ascending omega: omega_1 (first sliding) and omega_2 (first value above omega_1
    held by friction again), with the values bracketing each."""
    omega_1 = first_sliding(values, regimes)
    out = {"omega_1": omega_1, "omega_2": None, "last_sliding": None, "last_friction_before_1": None}
    if omega_1 is None:
        return out
    index_1 = list(values).index(omega_1)
    out["last_friction_before_1"] = float(values[index_1 - 1]) if index_1 > 0 else None
    for i in range(index_1 + 1, len(values)):
        if friction_held(regimes[i]):
            out["omega_2"] = float(values[i])
            out["last_sliding"] = float(values[i - 1])
            break
    return out


def study_c6(runner: Runner) -> Study:
    """Model C: k_t = 0, both transitions in the A-omega plane, omega_2 vs k_n, ramp across omega_2."""
    res = runner.resolution
    observe_c = OBSERVE_SHORT
    # k_t = 0 and the ramp across omega_2 run as tasks, in parallel.
    k_t_zero = {"point": PointSettings(run=_c_run(runner, max(res.c_horizon, 8000.0), A=0.0, k_t=0.0),
                                       observe=observe_c), "extras": ["trace"]}
    ramp_amplitude = 0.5
    ramp_item = {"point": PointSettings(run=_c_run(runner, res.c6_ramp_step, A=ramp_amplitude), observe=observe_c),
                 "ramp": Ramp("omega", res.c6_ramp)}
    [frictionless] = runner.tasks(run_and_measure, [k_t_zero])
    [loop] = runner.tasks(ramp_task, [ramp_item])

    base = PointSettings(run=_c_run(runner, res.c_horizon), observe=observe_c)
    diagram = runner.sweep(Grid((Axis("A", res.c6_amplitudes), Axis("omega", res.c6_omegas))), base)
    rows = []
    for amplitude in diagram.A.values:
        regimes = diagram.regime.sel(A=amplitude).values.tolist()
        omegas = diagram.omega.values.tolist()
        found = recovery(omegas, regimes)
        rows.append({"A": float(amplitude), "regimes": regimes, **found,
                     "first_transition_paper": math.sqrt(1.0 / float(amplitude)),
                     "first_transition_onset": _onset_omega(float(amplitude), 0.07)})

    stiffness_amplitude = 0.5
    base_k = PointSettings(run=_c_run(runner, res.c_horizon, A=stiffness_amplitude), observe=observe_c)
    grid_k = Grid((Axis("ratio", res.c6_ratios), Axis("k_n", res.c6_stiffnesses),
                   Axis("relative_omega", res.c6_relative_omegas)),
                  derived={"gamma_n": "k_n / ratio", "omega": "relative_omega * ratio"})
    stiff = runner.sweep(grid_k, base_k)
    recovery_vs_k = []
    for ratio in stiff.ratio.values:
        for k_n in stiff.k_n.values:
            regimes = stiff.regime.sel(ratio=ratio, k_n=k_n).values.tolist()
            omegas = (stiff.relative_omega.values * ratio).tolist()
            found = recovery(omegas, regimes)
            recovery_vs_k.append({"ratio": float(ratio), "k_n": float(k_n), "regimes": regimes, "omegas": omegas,
                                  **found})

    up = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "up"]
    down = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "down"]
    up_rec = recovery([v for v, _ in up], [r for _, r in up])
    # Coming down from high omega, friction is lost at the highest sliding value.
    down_sliding = [v for v, r in down if not friction_held(r)]
    down_friction_above = [v for v, r in down if friction_held(r) and (not down_sliding or v > max(down_sliding))]
    measured = {
        "k_n_over_gamma_n": 1.0 / 0.07,
        "frictionless": {"regime": frictionless["observables"]["regime"],
                         "slip_events": frictionless["observables"]["slip_events"],
                         "phi": frictionless["observables"]["phi"],
                         "drift_velocity": frictionless["observables"]["drift_velocity"]},
        "diagram_rows": rows, "omegas": diagram.omega.values.tolist(),
        "stiffness_amplitude": stiffness_amplitude, "recovery_vs_k": recovery_vs_k,
        "ramp_amplitude": ramp_amplitude, "ramp_values": list(res.c6_ramp),
        "ramp_up_omega_2": up_rec["omega_2"],
        "ramp_down_omega_2": min(down_friction_above) if down_friction_above else None,
        "ramp_up_regimes": [r for _, r in up], "ramp_down_regimes": [r for _, r in down],
    }
    settings = {"model": "C", "parameters": C_PARAMETERS, "horizon": res.c_horizon, "initial": C_START,
                "ramp_step": res.c6_ramp_step, **_observe_json(observe_c),
                "friction": "regime stick_slip or stuck (not sliding)"}
    data = {"omega": diagram.omega.values.tolist(), "A": diagram.A.values.tolist(),
            "regime": diagram.regime.transpose("A", "omega").values.tolist(),
            "recovery_vs_k": recovery_vs_k, "loop": loop}
    return Study("C6", measured, settings, data)


def study_c7(runner: Runner) -> Study:
    """Models B and C: contact fraction against omega at fixed A."""
    res = runner.resolution
    amplitudes = (0.3, 3.0)
    observe_contact = ObservableSettings(transient=1000.0)
    curves = {}
    for model in ("B", "C"):
        if model == "B":
            base = _b_point(runner, res.contact_horizon, observe_contact)
            base = dataclasses.replace(base, run=dataclasses.replace(base.run, output_interval=0.5))
        else:
            base = PointSettings(run=dataclasses.replace(_c_run(runner, res.contact_horizon), output_interval=0.5),
                                 observe=observe_contact)
        ds = runner.sweep(Grid((Axis("A", amplitudes), Axis("omega", res.c7_omegas))), base)
        curves[model] = [{"A": float(a), "omega": ds.omega.values.tolist(),
                          "contact_fraction": ds.contact_fraction.sel(A=a).values.tolist(),
                          "regime": ds.regime.sel(A=a).values.tolist()} for a in ds.A.values]
    measured = {"curves": curves, "k_n_over_gamma_n": 1.0 / 0.07, "embedded_threshold": EMBEDDED}
    settings = {"models": "B, C", "parameters": "as C5 (B) and C6 (C)", "horizon": res.contact_horizon,
                "output_interval": 0.5, "initial": "B: valley; C: crest; steady orbit",
                **_observe_json(observe_contact)}
    return Study("C7", measured, settings, {"curves": curves})


EMBEDDED = 0.99  # contact fraction above which the block counts as embedded


def study_c8(runner: Runner) -> Study:
    """Models A and C: V_d-omega diagrams; the stationary sliding offset x0 of model A."""
    res = runner.resolution
    base_a = PointSettings(run=runner.run("A", parameters={**SCALED, "A": 2.0}, horizon=res.horizon_a),
                           observe=OBSERVE_A)
    grid = Grid((Axis("V_d", res.c8_velocities), Axis("omega", res.c8_omegas)))
    diagram_a = runner.sweep(grid, base_a)
    c_amplitude = 2e4
    base_c = PointSettings(run=_c_run(runner, res.c_horizon, A=c_amplitude), observe=OBSERVE_SHORT)
    diagram_c = runner.sweep(grid, base_c)

    velocities = (1.0, 3.0, 10.0)
    items = [{"point": PointSettings(run=runner.run("A", parameters={**SCALED, "A": 0.0, "V_d": v},
                                                    horizon=4000.0, initial=InitialCondition("equilibrium")),
                                     observe=ObservableSettings(transient=2000.0)), "extras": ["offset"]}
             for v in velocities]
    offsets = runner.tasks(run_and_measure, items)
    k_d, gamma_t, mu_s = SCALED["k_d"], SCALED["gamma_t"], 0.5
    sliding_offsets = [{"V_d": v, "x0": r["offset"], "x0_std": r["offset_std"],
                        "force_balance": (gamma_t * v + mu_s / 2) / k_d, "paper": (gamma_t * v - mu_s / 2) / k_d,
                        "regime": r["observables"]["regime"]} for v, r in zip(velocities, offsets)]

    def rows(ds):
        return [{"V_d": float(v), "regimes": ds.regime.sel(V_d=v).values.tolist()} for v in ds.V_d.values]

    measured = {"omegas": list(res.c8_omegas), "model_a": rows(diagram_a), "model_c": rows(diagram_c),
                "model_a_amplitude": 2.0, "model_c_amplitude": c_amplitude, "offsets": sliding_offsets}
    settings = {"models": "A (scaled, A = 2), C (" + C_PARAMETERS + f", A = {c_amplitude:g} as printed)",
                "horizon": res.horizon_a, "initial": "steady orbit; C: " + C_START,
                "offset_runs": "model A, A = 0, horizon 4000, transient 2000", **_observe_json(OBSERVE_A)}
    data = {"omega": list(res.c8_omegas), "V_d": list(res.c8_velocities),
            "regime_a": diagram_a.regime.transpose("V_d", "omega").values.tolist(),
            "regime_c": diagram_c.regime.transpose("V_d", "omega").values.tolist()}
    return Study("C8", measured, settings, data)


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
                "initial": "steady orbit", **_observe_json(observe_settings)}
    return Study("Fig1b", measured, settings, {"runs": runs, "V_d": SCALED["V_d"]})


STUDIES = {"Fig1b": study_fig1b, "C1": study_c1, "C2": study_c2, "C3": study_c3, "C4": study_c4, "C5": study_c5, "C6": study_c6,
           "C7": study_c7, "C8": study_c8}


def run_studies(runner: Runner, names: Sequence[str] = tuple(STUDIES), progress: bool = True) -> dict[str, Study]:
    """Run the named studies in order; {claim: Study}."""
    results = {}
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(names), desc="claims", unit="claim", position=0)
    try:
        for name in names:
            if bar is not None:
                bar.set_postfix_str(name)
            results[name] = STUDIES[name](runner)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return results


def save_studies(studies: dict[str, Study], path: str | os.PathLike) -> None:
    write_json_atomically(Path(path), {name: dataclasses.asdict(s) for name, s in studies.items()})


def load_studies(path: str | os.PathLike) -> dict[str, Study]:
    data = json.loads(Path(path).read_text())
    return {name: Study(**fields) for name, fields in data.items()}


__all__ = ["RESOLUTIONS", "Resolution", "Runner", "STUDIES", "Study", "load_studies", "run_studies",
           "save_studies", "stable_roots_near", "recovery", "transition_bracket"]
