"""Conventions, worker tasks and regime arithmetic the claim studies share.

Conventions used by all studies
-------------------------------
* Model A uses the ``scaled`` preset (k_d = V_d = 1e-2, gamma_t = 5e-3): the paper's
  drive makes one stick-slip cycle ~5e7 tau_0.  Models B and C use the paper's plate
  (A_x = 1e3, omega_x = 2e-2, P_l = 1) with the same scaled drive.
* Vibrated runs start on the steady in-contact orbit (``steady_orbit``).  Models B and
  C start at a valley (B) or a crest (C) of the corrugation, at the time when the drive
  spring is relaxed (start_time = x_start / V_d), so that no spring force acts at t0.
* "Friction" = the block is held by friction in the window: regime stick_slip, micro_slip, stuck
  (no slip and no sliding within the window) or jammed (self-locked on a flank);
  "sliding" = it follows the drive; "hopping" = it neither rests nor stays in contact;
  "flying" = no contact in the window (none of the three is friction).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from harness.runs.continuation import continuation
from harness.runs.observables import FLYING, HOPPING, SLIDING, observe, window, window_slips
from harness.runs.run import simulate
from harness.runs.settings import PRESETS, InitialCondition, ObservableSettings, PointSettings, RunSettings

from .study import Runner

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


def jsonable_float(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def trace(ds, points: int = TRACE_POINTS) -> dict:
    stride = max(1, len(ds.time) // points)
    return {"time": ds.time.values[::stride].tolist(), "x": ds.x.values[::stride].tolist()}


# ---------------------------------------------------------------------- worker tasks
def run_and_measure(item: dict, pool) -> dict:
    """One run: observables plus the extras named in ``item["extras"]`` (worker task)."""
    point: PointSettings = item["point"]
    extras = item.get("extras", ())
    outputs = ("x", "vx", "phi_integral", "contact", "coulomb_resets", "penetration")
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
        result["trace"] = trace(ds)
    if "stick_roots" in extras:
        result.update(_stick_root_distances(ds, t, x, vx, v_d))
    if "stick_sites" in extras:
        result["stick_sites"] = stick_sites(t, x, vx, v_d)
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
    return jsonable_float(np.median(slopes)) if slopes else None


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


def stick_sites(t, x, vx, v_d, most: int = 50, min_run: int = 5) -> list[list[float]]:
    """(t, x) of up to ``most`` stuck samples spread evenly over those of the window: samples
    with |vx| < 0.2 |V_d| (the criterion of the Eq. (9) distances) in runs of at least
    ``min_run`` consecutive ones, so that the turning points of an oscillation, where vx
    passes zero, do not count.  Taken from every output sample, not from a thinned trace,
    whose sampling can alias an oscillation into a seeming stick."""
    slow = np.abs(np.asarray(vx)) < 0.2 * abs(v_d)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], slow.astype(np.int8), [0]])))
    stuck = np.concatenate([np.arange(a, b) for a, b in zip(edges[::2], edges[1::2]) if b - a >= min_run]
                           or [np.empty(0, dtype=int)])
    chosen = stuck[np.unique(np.linspace(0, len(stuck) - 1, min(most, len(stuck))).astype(int))] if len(stuck) else []
    return [[float(t[i]), float(x[i])] for i in chosen]


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
            "root_distance_median": jsonable_float(np.median(distances)) if len(distances) else None,
            "root_distance_p90": jsonable_float(np.percentile(distances, 90)) if len(distances) else None}


def ramp_task(item: dict, pool) -> dict:
    """A continuation ramp (worker task): per step direction, value, regime, phi, contact."""
    ds = continuation(item["point"], item["ramp"], pool)
    parameter = item["ramp"].parameter
    return {"direction": ds.direction.values.tolist(), "value": ds[parameter].values.tolist(),
            "regime": ds.regime.values.tolist(), "phi": ds.phi.values.tolist(),
            "contact_fraction": ds.contact_fraction.values.tolist()}


# ---------------------------------------------------------------------- helpers
def friction_held(regime: str) -> bool:
    """Held by friction in the window: stick-slip, micro-slip, stuck or jammed (not sliding, hopping or flying)."""
    return regime not in (SLIDING, HOPPING, FLYING)


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


def loss_amplitude(omega, load: float = 1.0, m: float = 1.0, k_n: float = 1.0, gamma_n: float = 0.07):
    """A_N(omega), the friction-loss onset of the same orbit: its contact force first reaches
    0 (``vibroblock.orbits.friction_loss_amplitude`` with g = load / m)."""
    from vibroblock.orbits import friction_loss_amplitude
    return friction_loss_amplitude(omega, m=m, g=load / m, k_n=k_n, gamma_n=gamma_n)


def observe_json(observe_settings: ObservableSettings) -> dict:
    return {"phi_threshold": observe_settings.phi_threshold, "transient": observe_settings.transient,
            "window": "rest of run" if observe_settings.window is None else observe_settings.window,
            "slip_min_fraction": observe_settings.slip_min_fraction, "merge_gap": observe_settings.merge_gap}


def relaxed_start(x_start: float, v_d: float) -> float:
    return x_start / v_d



def onset_omega(amplitude: float, gamma_n: float, load: float = 1.0, k_n: float = 1.0) -> float | None:
    """Lowest omega at which A_c(omega) falls to ``amplitude`` (bisection on a fine grid)."""
    grid = np.geomspace(1e-3, 100.0, 20001)
    below = np.flatnonzero(onset_amplitude(grid, load, 1.0, k_n, gamma_n) <= amplitude)
    return float(grid[below[0]]) if len(below) else None


def b_point(runner: Runner, horizon: float, observe_settings: ObservableSettings, **parameters) -> PointSettings:
    values = {**SCALED, **parameters}
    run = runner.run("B", parameters=values, horizon=horizon, output_interval=2.0,
                     initial=InitialCondition("steady_orbit", x_start=VALLEY),
                     start_time=relaxed_start(VALLEY, values["V_d"]))
    return PointSettings(run=run, observe=observe_settings)


def c_run(runner: Runner, horizon: float, x_start: float = CREST, **parameters) -> RunSettings:
    """A model C run on the paper's plate with the scaled drive, starting at ``x_start`` on the
    steady orbit with the drive spring relaxed."""
    values = {**SCALED, **parameters}
    return runner.run("C", parameters=values, horizon=horizon, initial=InitialCondition("steady_orbit", x_start=x_start),
                      start_time=relaxed_start(x_start, values["V_d"]))


# Start phases on the corrugation Z = A_x sin(omega_x x), named along the drive's
# direction (+x): the crest, the flank going down, the valley, the flank going up.
START_PHASES = {"crest": CREST, "descending flank": math.pi / OMEGA_X, "valley": VALLEY,
                "ascending flank": WAVELENGTH}


def start_ensemble(runner: Runner, points: Sequence[dict], wavelengths: float) -> dict:
    """Each point (model C parameters) run from every start phase of ``START_PHASES`` over a
    window of ``wavelengths`` corrugation wavelengths of drive travel, after a transient
    of half a wavelength: what a short run from one start classified, checked against
    the horizon and the start.  Returns the settings and, per point, each start's regime,
    phi, contact fraction and drift velocity, whether friction holds, and the spread."""
    travel = WAVELENGTH / SCALED["V_d"]  # time for the drive to move one wavelength
    observe_settings = ObservableSettings(transient=0.5 * travel)
    horizon = float(math.ceil((0.5 + wavelengths) * travel))  # whole output intervals
    items = [{"point": PointSettings(run=c_run(runner, horizon, x_start=x_start, **point), observe=observe_settings)}
             for point in points for x_start in START_PHASES.values()]
    results = iter(runner.tasks(run_and_measure, items))
    out = []
    for point in points:
        starts = {}
        for name in START_PHASES:
            o = next(results)["observables"]
            starts[name] = {"regime": o["regime"], "held": friction_held(o["regime"]), "phi": o["phi"],
                            "contact_fraction": o["contact_fraction"], "drift_velocity": o["drift_velocity"]}
        phis = [s["phi"] for s in starts.values() if s["phi"] is not None and math.isfinite(s["phi"])]
        out.append({"parameters": dict(point), "starts": starts,
                    "held": sorted({s["held"] for s in starts.values()}),
                    "phi_range": [min(phis), max(phis)] if phis else None})
    return {"wavelengths": wavelengths, "horizon": horizon, "transient": observe_settings.transient,
            "starts": dict(START_PHASES), "points": out}


def ensemble_agrees(entry: dict, held: bool) -> bool:
    """Every start of an ensemble point classified as ``held`` (friction) or not."""
    return entry["held"] == [held]


C_START = f"crest x = pi/(2 omega_x) = {CREST:.1f}, steady orbit, spring relaxed at t0"
C_PARAMETERS = "paper plate (A_x = 1e3, omega_x = 2e-2, P_l = 1), scaled drive k_d = V_d = 1e-2, gamma_t = 5e-3"
# What the figures standing for the paper's Figs. 5-7 say about their parameters: the
# paper's own drive (k_d = 5e-6, V_d = 2e-4) is drawn by harness.benchmarks.fig5_paper
# on its 8 x 8 grid in the tangent frame only; these studies' designs (omega up to 50,
# both formulations, k_n and V_d sweeps) are out of reach at that drive.
SCALED_FIGURE_NOTE = ("scaled drive $k_d = V_d = 10^{-2}$, $\\gamma_t = 5\\cdot10^{-3}$ on the paper's plate\n"
                      "(the paper's drive: harness.benchmarks.fig5_paper, tangent frame; out of reach here)")


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


# ---------------------------------------------------------------------- sharp or crossover
# A class change located by bisection is either a sharp transition, where phi jumps across
# the last bracket (the applied-load bound's recovery at the A_c root: phi 0.04 -> 187
# over 2.5 % in omega), or a crossover, where phi falls continuously through the regime
# threshold with the block in contact on both sides (A -> A_N under the contact-force
# bound: phi 61, 47, 20, 12, 7.2, 3.5, 1.0, 0.005 over A = 0.5 ... 0.82 at omega = 2.52).
# Where phi crosses a level in a crossover is a property of the level, not of the model,
# so a crossover is reported by its phi curve and by its foot, where phi reaches the floor
# of sliding with the drive, set against the physical marker (N_min -> 0 at A_N).
SHARP, CROSSOVER = "sharp", "crossover"
# phi changes by at least this many decades across a sharp transition's last bracket (3 %
# wide).  A smooth curve crossing the threshold changes by (1.03)^s over it, s = dln phi /
# dln A: 1.24 (0.09 decades) at the crossover above, where s ~ 7; one decade needs s ~ 78.
SHARP_DECADES = 1.0
# phi of a block sliding with the drive, as a share of the regime threshold: the crossover
# above ends at 0.005 (5e-4 of the threshold 10) from 1.0 (0.1 of it) one step before.
FLOOR_FRACTION = 0.01
IN_CONTACT = 0.99  # contact fraction of a block "in contact throughout"


def _finite_phi(value) -> float | None:
    return float(value) if value is not None and math.isfinite(float(value)) else None


def transition_character(held_side: dict, other_side: dict, threshold: float) -> str:
    """``SHARP`` or ``CROSSOVER`` for a located class change, from the runs on its two sides
    (each {"phi", "contact_fraction"}: observables): a crossover when the block is in
    contact on both sides, phi lies above ``threshold`` on the held side and below it on
    the other (the class changed because phi crossed the threshold) and changes by less
    than ``SHARP_DECADES`` across the bracket; sharp otherwise."""
    phi_held, phi_other = _finite_phi(held_side.get("phi")), _finite_phi(other_side.get("phi"))
    contacts = [held_side.get("contact_fraction"), other_side.get("contact_fraction")]
    if phi_held is None or phi_other is None or any(c is None or not c >= IN_CONTACT for c in contacts):
        return SHARP
    if not phi_held > threshold >= phi_other:
        return SHARP
    decades = math.log10(phi_held / max(phi_other, threshold * 1e-9))
    return CROSSOVER if decades < SHARP_DECADES else SHARP


def above_floor(observables: dict, threshold: float) -> bool:
    """phi above the floor of sliding with the drive (``FLOOR_FRACTION`` of the threshold);
    a run without a finite phi (no contact) is not."""
    phi = _finite_phi(observables.get("phi"))
    return phi is not None and phi > FLOOR_FRACTION * threshold


def foot_bracket(curve: dict, start: float, upward: bool, threshold: float) -> tuple[float, float] | None:
    """The crossover's foot on the measured curve {value: observables}: walking from
    ``start`` (the sliding side of the located threshold crossing) away from the held side
    (towards higher values if ``upward``), the first pair of neighbours whose phi falls
    from above the floor to the floor (ascending (lo, hi)); None if the curve does not
    reach the floor there before the block leaves the plate.  A crossover is a change in
    contact: the walk ends after the first run that loses contact (where phi may reach the
    floor with the contact force reaching 0, at A_N), or the foot would be located where
    the block flies, far from the crossover."""
    values = sorted(v for v in curve if (v >= start if upward else v <= start))
    if not upward:
        values = values[::-1]
    for near, far in zip(values[:-1], values[1:]):
        if not _in_contact(curve[near]):
            return None
        if above_floor(curve[near], threshold) and not above_floor(curve[far], threshold):
            return (near, far) if upward else (far, near)
    return None


def _in_contact(observables: dict) -> bool:
    contact = _finite_phi(observables.get("contact_fraction"))
    return contact is not None and contact >= IN_CONTACT


def locate_feet(measure, searches: list[dict], threshold: float, resolution: float) -> None:
    """Bisect each crossover's foot bracket to ``resolution``, all searches per round in one
    batch.  ``searches``: dicts with "curve" ({value: observables}, extended in place),
    "bracket" (lo, hi) from :func:`foot_bracket` and "upward"; ``measure(pairs)``
    runs (search, value) pairs and returns their observables.  Adds "foot" (the located
    value) and "foot_bracket" to each search."""
    from harness.runs.bisection import Transition, refine

    found = [Transition(s["bracket"][0], s["bracket"][1], s["upward"], where={"search": n})
             for n, s in enumerate(searches)]

    def classify(pairs):
        observed = measure([(searches[t.where["search"]], value) for t, value in pairs])
        for (t, value), o in zip(pairs, observed):
            searches[t.where["search"]]["curve"][value] = o
        return [above_floor(o, threshold) for o in observed]

    refine(classify, found, resolution)
    for search, t in zip(searches, found):
        search["foot"], search["foot_bracket"] = t.value, [t.lo, t.hi]


def phi_curve(curve: dict) -> list[list[float | None]]:
    """The curve {value: observables} as ascending [value, phi, contact fraction] rows (JSON)."""
    return [[float(v), _finite_phi(curve[v].get("phi")), _finite_phi(curve[v].get("contact_fraction"))]
            for v in sorted(curve)]
