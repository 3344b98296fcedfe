"""The paper's Fig. 5 (model C phase diagram, A x omega) at the paper's own parameters: its cost, measured.

    python -m harness.benchmarks.fig5_paper [--workers 2] [--cap 20] [--cycles 3] [--formulations 0 1]
                                            [--rtol 1e-8]

Model C at the paper's parameters, which are the FMU's defaults (k_d = 5e-6, V_d = 2e-4,
A_x = 1e3, omega_x = 2e-2, P_l = 1; m = k_n = 1, k_t = 0.28, gamma_n = 0.07,
gamma_t = 2.5e-4, mu_s = 0.5), integrated by ``adaptive`` at its default tolerances
(rtol = 1e-8, atol = 1e-10; ``--rtol`` sets rtol and atol = rtol / 100) with the default
Coulomb bound and flight, in each formulation.  As in the claim studies, a point starts
on the steady in-contact orbit at a crest of the corrugation (x_start = pi / (2 omega_x))
at the time the drive spring is relaxed (t0 = x_start / V_d).

What one point of the diagram needs (issue 10, item 4): >= ``--cycles`` stick-slip cycles,
or, where the block slides, >= ``--cycles`` corrugation wavelengths, with a transient of
half a unit before the window and one unit more in it, as in
``fig1c_paper_parameters``: (cycles + 1.5) units per point.  The units:

* stick-slip: the unvibrated cycle, T = mu_s P_l / (k_d V_d) = 5e8 tau_0 (the stretch at
  which the drive's pull reaches mu_s P_l, at V_d; the slip that ends it is ~300
  wavelengths).  Vibration below the onset lowers the bound (the contact force
  oscillates), so a cycle may be shorter; on the paper's corrugation the block may also
  jam on a flank (docs/physics.md Sec. 8), so T is the nominal unit, not a prediction.
* sliding: one wavelength lambda / V_d = 2 pi / (omega_x V_d) = 1.57e6 tau_0.

The full cost cannot be run in minutes, so each point runs for ``--cap`` seconds of wall
time (in chunks that each take about a second) and the cost is extrapolated from what it
measured: simulated tau_0 per CPU second (CPU time, so that other processes' load on a
shared machine does not count), internal steps, events.  Within a cap the drive moves by
some tens of delta_0 (a tenth of a wavelength), so a run cannot tell its regime; a point
is costed as the paper's diagram has it: below the detachment onset A_c a stick-slip point (per cycle, T / rate),
at or above it a sliding one (per wavelength, lambda / (V_d rate)).  Both unit costs are
printed for every point, with the distance the block covered in its run.

The points: omega in {0.1, 0.316, 1} (the steps resolve the plate's period to rtol, so the
cost per tau_0 grows with omega) at A = A_c(omega) / 3 and 3 A_c(omega),
A_c the detachment onset of the steady orbit at a crest (P_l for g).  The 8 x 8 diagram
(omega in [0.1, 1], A in [0.3, 300], log-spaced, the ranges of Fig. 1c's benchmark) is
extrapolated point by point: a grid point below A_c takes the stick-slip cost, above it
the sliding cost, each interpolated log-log in omega between the measured points, and the sum
is divided by the workers.  The verdict compares that with 10 minutes.

No diagram is drawn and no flag offers one: measured on the 2-core development machine
(README, "Choosing speed or accuracy"), with adaptive's explicit pair and its stroboscopic
jumps across the held block's plate periods (quadratures to second order in the drift),
the 8 x 8 diagram extrapolates to 18 min on 2 cores at ``--rtol 1e-6`` and 3.3 h at the
default 1e-8 in the tangent frame, 5.0 h and 18 h in fixed axes (where the held orbit is
not periodic and the jumps are refused); the sliding points, resolved hop by hop, are
most of it.  At rtol 1e-8 the jumps shrink along a stick, so a cap that covers only the
start of a stick extrapolates low.  Measured figures only; nothing here is a timed test.
"""
from __future__ import annotations

import argparse
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OMEGA_X = 2e-2
CREST = math.pi / (2 * OMEGA_X)  # sin(omega_x x) = +1, slope 0
WAVELENGTH = 2 * math.pi / OMEGA_X
OMEGAS = (0.1, 10 ** -0.5, 1.0)
FACTORS = (1.0 / 3.0, 3.0)  # A / A_c(omega)
GRID_OMEGAS = np.geomspace(0.1, 1.0, 8)
GRID_AMPLITUDES = np.geomspace(0.3, 300.0, 8)
DT = 1.0  # adaptive's storage grid: no effect on accuracy or cost
TARGET = 600.0  # seconds for the 8 x 8 diagram
CHUNK_SECONDS = 1.0  # wall time aimed at per advance call
# Longest advance call: a chunk grown while the block was held (periods jumped at ~1e8
# tau_0 per second) must not carry on into a slip or a flank resolved at ~1 step per tau_0,
# where it would meet the per-call step budget (16.7e6 steps) and fail with its work uncounted.
CHUNK_MAX = 1e7


def paper_parameters() -> dict:
    from vibroblock import defaults
    return defaults("C")


def cycle_time(p: dict) -> float:
    """The unvibrated stick: the drive stretches to mu_s P_l / k_d at V_d."""
    return p["mu_s"] * p["P_l"] / (p["k_d"] * p["V_d"])


def wavelength_time(p: dict) -> float:
    return WAVELENGTH / p["V_d"]


def onset(omega, p: dict):
    """Detachment onset at a crest (slope 0): A_c(omega) with g -> P_l / m."""
    from vibroblock import detachment_amplitude
    return detachment_amplitude(omega, m=p["m"], g=p["P_l"] / p["m"], k_n=p["k_n"], gamma_n=p["gamma_n"])


def run_point(args):
    """One point for ``cap`` seconds of wall time: what it simulated and what that cost."""
    formulation, omega, amplitude, cap, rtol = args
    from vibroblock import Block, ModelError

    p = paper_parameters()
    t0 = CREST / p["V_d"]
    block = Block("C", "adaptive", initial_state=2, A=amplitude, omega=omega, x_start=CREST, dt=DT,
                  formulation=formulation, rtol=rtol, atol=1e-2 * rtol)
    started, cpu_started = time.perf_counter(), time.process_time()
    block.start(t0)
    x0 = x_prev = block.output("x")
    t, chunk = t0, 16.0 * 2.0 * math.pi / omega
    error = ""
    while True:
        elapsed = time.perf_counter() - started
        if elapsed >= cap:
            break
        chunk = DT * max(1.0, math.floor(min(chunk, CHUNK_MAX) / DT))
        before = time.perf_counter()
        try:
            block.advance_to(t + chunk)
        except ModelError as exc:
            error = str(exc).split(";")[0]
            break
        took = max(time.perf_counter() - before, 1e-4)
        t += chunk
        x_prev = block.output("x")
        remaining = cap - (time.perf_counter() - started)
        chunk *= min(4.0, max(0.25, min(CHUNK_SECONDS, max(remaining, 0.05)) / took))
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu_started
    counters = block.counters
    simulated = t - t0
    return dict(formulation=formulation, omega=omega, A=amplitude, simulated=simulated, advance=x_prev - x0,
                wall=wall, cpu=cpu, steps=counters["accepted"],
                rejected=counters["rejected"], events=counters["events"], resets=counters["resets"], error=error)


def costs(result: dict, p: dict, cycles: int) -> dict:
    """CPU seconds per cycle and per wavelength, and per point for the unit of its side of
    the onset (stick-slip below, sliding above), extrapolated from the capped run."""
    rate = result["simulated"] / result["cpu"] if result["cpu"] > 0 and result["simulated"] > 0 else 0.0
    per_cycle = cycle_time(p) / rate if rate > 0 else math.inf
    per_wavelength = wavelength_time(p) / rate if rate > 0 else math.inf
    below = result["A"] < onset(result["omega"], p)
    return dict(rate=rate, per_cycle=per_cycle, per_wavelength=per_wavelength, below=below,
                per_point=(cycles + 1.5) * (per_cycle if below else per_wavelength))


def grid_estimate(results: list, p: dict, cycles: int, workers: int) -> tuple[float, int, int]:
    """Seconds for the 8 x 8 diagram on ``workers`` cores: each grid point stick-slip below
    the onset, sliding above, its cost interpolated log-log in omega between the measured
    points on its side of the onset."""
    below = sorted((r["omega"], costs(r, p, cycles)["per_point"]) for r in results if costs(r, p, cycles)["below"])
    above = sorted((r["omega"], costs(r, p, cycles)["per_point"]) for r in results
                   if not costs(r, p, cycles)["below"])
    total, n_below = 0.0, 0
    for omega in GRID_OMEGAS:
        threshold = onset(omega, p)
        for amplitude in GRID_AMPLITUDES:
            table = below if amplitude < threshold else above
            n_below += amplitude < threshold
            w, c = np.log([r[0] for r in table]), np.log([r[1] for r in table])
            total += float(np.exp(np.interp(math.log(omega), w, c)))
    return total / workers, n_below, GRID_OMEGAS.size * GRID_AMPLITUDES.size - n_below


def human(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "inf"
    for unit, size in (("d", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cap", type=float, default=20.0, help="wall seconds per point")
    parser.add_argument("--cycles", type=int, default=3, help="stick-slip cycles or wavelengths per point")
    parser.add_argument("--formulations", type=int, nargs="+", default=[0, 1], choices=[0, 1])
    parser.add_argument("--rtol", type=float, help="adaptive's rtol (atol = rtol / 100); default the FMU's")
    args = parser.parse_args(argv)
    os.environ.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".cache" / "numba"))
    from vibroblock import Block

    p = paper_parameters()
    rtol = args.rtol or p["rtol"]
    # Compile or load the kernels here, so the workers' caps measure integration, not compilation.
    for formulation in args.formulations:
        warm = Block("C", "adaptive", initial_state=2, A=0.3, omega=0.5, x_start=CREST, dt=DT, formulation=formulation)
        warm.start(CREST / p["V_d"])
        warm.advance_to(CREST / p["V_d"] + 10.0)
        warm.outputs()
    points = [(f, w, factor * float(onset(w, p)), args.cap, rtol) for f in args.formulations for w in OMEGAS
              for factor in FACTORS]
    print(f"Fig. 5 at the paper's parameters (model C: k_d = {p['k_d']:g}, V_d = {p['V_d']:g}, A_x = {p['A_x']:g}, "
          f"omega_x = {p['omega_x']:g}, P_l = {p['P_l']:g}), adaptive (rtol = {rtol:g}, atol = {1e-2 * rtol:g}); "
          f"units: stick-slip cycle T = {cycle_time(p):.3g} tau_0, wavelength {wavelength_time(p):.3g} tau_0; "
          f"{len(points)} points capped at {args.cap:g} s on {args.workers} workers", flush=True)
    started = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(run_point, points, chunksize=1))
    wall = time.perf_counter() - started

    verdicts = []
    for formulation in args.formulations:
        name = ("fixed_axes", "tangent_frame")[formulation]
        rows = [r for r in results if r["formulation"] == formulation]
        print(f"\nformulation = {formulation} ({name}); costs in CPU seconds (one core)")
        print(f"{'omega':>6} {'A':>8} {'A/A_c':>6} {'simulated':>10} {'dx/lambda':>9} {'steps':>9} {'events':>8} "
              f"{'CPU s':>6} {'tau0/CPUs':>9} {'steps/tau0':>10} {'per cycle':>10} {'per lambda':>10} "
              f"{f'point (>={args.cycles})':>22}")
        for r in rows:
            c = costs(r, p, args.cycles)
            point = human(c["per_point"]) + (" (stick-slip)" if c["below"] else " (sliding)")
            print(f"{r['omega']:6.3g} {r['A']:8.3g} {r['A'] / onset(r['omega'], p):6.2f} {r['simulated']:10.3g} "
                  f"{r['advance'] / WAVELENGTH:9.3g} {r['steps']:9d} {r['events']:8d} {r['cpu']:6.1f} "
                  f"{c['rate']:9.3g} {r['steps'] / max(r['simulated'], 1e-300):10.3g} {human(c['per_cycle']):>10} "
                  f"{human(c['per_wavelength']):>10} {point:>22}" + (f"  stopped: {r['error']}" if r['error'] else ""))
        estimate, n_below, n_above = grid_estimate(rows, p, args.cycles, args.workers)
        verdicts.append((name, estimate))
        print(f"8 x 8 diagram ({n_below} points below the onset at the cycle cost, {n_above} at or above it at "
              f"the wavelength cost), {args.workers} cores: {human(estimate)} = {estimate / TARGET:.3g} x the "
              f"10-minute target: {'within' if estimate <= TARGET else 'OUT OF REACH'}")
    print(f"\nmeasured in {wall:.0f} s wall")
    for name, estimate in verdicts:
        print(f"{name}: 8 x 8 diagram with >= {args.cycles} cycles/wavelengths per point ~ {human(estimate)} on "
              f"{args.workers} cores ({'within' if estimate <= TARGET else 'not within'} 10 minutes)")
    return results


if __name__ == "__main__":
    main()
