"""The paper's Fig. 5 (model C phase diagram, A x omega) at the paper's own parameters:
drawn where its points finish, its cost measured point by point.

    python -m harness.benchmarks.fig5_paper [--workers 2] [--cap 10] [--cycles 3] [--grid 8]
                                            [--formulations 0 1] [--rtol 1e-6] [--out out]
                                            [--contact-law linear]

Model C at the paper's parameters, which are the FMU's defaults (k_d = 5e-6, V_d = 2e-4,
A_x = 1e3, omega_x = 2e-2, P_l = 1; m = k_n = 1, k_t = 0.28, gamma_n = 0.07,
gamma_t = 2.5e-4, mu_s = 0.5), integrated by ``adaptive`` at its default tolerances
(rtol = 1e-8, atol = 1e-10; ``--rtol`` sets rtol and atol = rtol / 100) with the default
Coulomb bound and flight, in each formulation.  As in the claim studies, a point starts
on the steady in-contact orbit at a crest of the corrugation (x_start = pi / (2 omega_x))
at the time the drive spring is relaxed (t0 = x_start / V_d).

The grid: omega in [0.1, 1] and A in [0.3, 300], ``--grid`` points each, log-spaced (the
ranges of Fig. 1c's benchmark).  What one point needs: >= ``--cycles``
stick-slip cycles, or, where the block slides, >= ``--cycles`` corrugation wavelengths,
after a transient of half a unit, with one unit more in the window, as in
``fig1c_paper_parameters``: (cycles + 1.5) units per point.  The units:

* stick-slip (A below the detachment onset A_c(omega) at a crest, P_l for g): the
  unvibrated cycle, T = mu_s P_l / (k_d V_d) = 5e8 tau_0 (the stretch at which the drive's
  pull reaches mu_s P_l, at V_d; the slip that ends it is ~300 wavelengths).  Vibration
  below the onset lowers the bound, so a cycle may be shorter; on the paper's corrugation
  the block may also jam on a flank (docs/physics.md Sec. 8): T is the nominal unit.
* sliding (A at or above A_c): one wavelength lambda / V_d = 2 pi / (omega_x V_d) =
  1.57e6 tau_0.

Every grid point runs until it has its (cycles + 1.5) units or until ``--cap`` seconds of
wall time (in chunks of about a second).  A point that finishes has its phi =
<(dx/dt - V_d)^2> / V_d^2 over the window (the core's exact phi integral) and is drawn in
the colour of its phi (no threshold is drawn: the paper gives none for model C, and the
model-A threshold of Fig. 1c's benchmark does not carry over).  A point that does not is
drawn as unfinished and costed by extrapolation: its CPU time times the units it needed
over what it simulated (CPU time, so that other processes' load on a shared machine does
not count).  That extrapolation is rough: a capped run sees only the start of its point
(a stick-slip point's first stick, where the jumps are longest, or its first flights).
The diagram's cost is the sum over points divided by the workers; the verdict compares
it with 10 minutes.  Saves ``<out>/fig5_paper.png`` and ``.csv``; ``--replot`` redraws
the figure from the CSV.  With a cap long enough for every point to finish, the run's
wall time is the diagram's.

Its figures go to docs/benchmarks.md (section fig5_paper); nothing here is a timed test.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OMEGA_X = 2e-2
CREST = math.pi / (2 * OMEGA_X)  # sin(omega_x x) = +1, slope 0
WAVELENGTH = 2 * math.pi / OMEGA_X
DT = 1.0  # adaptive's storage grid: no effect on accuracy or cost
TARGET = 600.0  # seconds for the 8 x 8 diagram
CHUNK_SECONDS = 1.0  # wall time aimed at per advance call
# Longest advance call: a chunk grown while the block was held (periods jumped at ~1e8
# tau_0 per second) must not carry on into a slip or a flank resolved at ~1 step per tau_0,
# where it would meet the per-call step budget (16.7e6 steps) and fail with its work uncounted.
CHUNK_MAX = 1e7
FORMULATIONS = ("fixed_axes", "tangent_frame")


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


def unit_time(omega: float, amplitude: float, p: dict) -> float:
    """The unit a point needs (cycles + 1.5) of: the stick-slip cycle below the onset, a wavelength above."""
    return cycle_time(p) if amplitude < onset(omega, p) else wavelength_time(p)


def run_point(args):
    """One grid point for (cycles + 1.5) units or ``cap`` seconds of wall time, whichever comes first."""
    formulation, omega, amplitude, cap, rtol, cycles, contact_law = args
    from vibroblock import Block, ModelError

    p = paper_parameters()
    unit = unit_time(omega, amplitude, p)
    t0 = CREST / p["V_d"]
    window_start, end = t0 + 0.5 * unit, t0 + (cycles + 1.5) * unit
    block = Block("C", "adaptive", initial_state=2, A=amplitude, omega=omega, x_start=CREST, dt=DT,
                  formulation=formulation, rtol=rtol, atol=1e-2 * rtol, contact_law=contact_law)
    started, cpu_started = time.perf_counter(), time.process_time()
    block.start(t0)
    x0 = block.output("x")
    phi_start = x_start = math.nan
    t, chunk = t0, 16.0 * 2.0 * math.pi / omega
    error = ""
    while t < end and time.perf_counter() - started < cap:
        target = min(t + DT * max(1.0, math.floor(chunk / DT)), end)
        if t < window_start:
            target = min(target, window_start)
        before = time.perf_counter()
        try:
            block.advance_to(target)
        except ModelError as exc:
            error = str(exc).split(";")[0]
            break
        took = max(time.perf_counter() - before, 1e-4)
        t = target
        if t == window_start:
            phi_start, x_start = block.output("phi_integral"), block.output("x")
        remaining = cap - (time.perf_counter() - started)
        # Kept within CHUNK_MAX: a chunk grown unbounded while the jumps ran would stay at
        # CHUNK_MAX for many calls after the motion turned expensive.
        chunk = min(chunk * min(4.0, max(0.25, min(CHUNK_SECONDS, max(remaining, 0.05)) / took)), CHUNK_MAX)
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu_started
    finished = t >= end and not error
    window = end - window_start
    phi = drift = math.nan
    if finished:
        phi = (block.output("phi_integral") - phi_start) / (window * p["V_d"] ** 2)
        drift = (block.output("x") - x_start) / (window * p["V_d"])
    counters = block.counters
    simulated = t - t0
    needed = end - t0
    cost = cpu if finished else (cpu * needed / simulated if simulated > 0 and not error else math.inf)
    return dict(formulation=formulation, omega=omega, A=amplitude, below=amplitude < onset(omega, p),
                needed=needed, simulated=simulated, finished=finished, phi=phi, drift=drift,
                advance=block.output("x") - x0, wall=wall, cpu=cpu, cost=cost, steps=counters["accepted"],
                rejected=counters["rejected"], events=counters["events"], resets=counters["resets"],
                jumped=counters["periods_jumped"], error=error)


def human(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "inf"
    for unit, size in (("d", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


def plot(results: list, formulations, out: Path, p: dict, rtol: float, cycles: int) -> Path:
    """phi over the grid for each formulation (colour, finished points), the unfinished points marked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    fig, axes = plt.subplots(1, len(formulations), figsize=(5.8 * len(formulations), 5.2), squeeze=False)
    omegas = sorted({r["omega"] for r in results})
    w = np.geomspace(omegas[0] * 0.9, omegas[-1] * 1.1, 200)
    for ax, formulation in zip(axes[0], formulations):
        rows = [r for r in results if r["formulation"] == formulation]
        done = [r for r in rows if r["finished"] and r["phi"] > 0]
        if done:
            phis = [r["phi"] for r in done]
            norm = LogNorm(min(phis), max(max(phis), 1.01 * min(phis)))
            dots = ax.scatter([r["omega"] for r in done], [r["A"] for r in done], c=[r["phi"] for r in done],
                              norm=norm, cmap="viridis", s=60, marker="s", label=f"finished ({len(done)})")
            fig.colorbar(dots, ax=ax, label=r"$\phi = \langle(\dot x - V_d)^2\rangle / V_d^2$")
        rest = [(r["omega"], r["A"]) for r in rows if r not in done]
        if rest:
            ax.plot(*zip(*rest), "x", color="0.5", ls="none", label=f"not finished in the cap ({len(rest)})")
        ax.plot(w, onset(w, p), "k-", lw=1, label=r"onset $A_c(\omega)$ at a crest")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(r"$\omega$ [$1/\tau_0$]")
        ax.set_ylabel(r"$A$ [$\delta_0$]")
        cost = sum(r["cost"] for r in rows)
        ax.set_title(f"{FORMULATIONS[formulation]}: {human(cost)} CPU for the diagram", fontsize=9)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    fig.suptitle(f"Model C at the paper's parameters (Fig. 5), adaptive rtol {rtol:g},\n>= {cycles} stick-slip "
                 f"cycles or corrugation wavelengths per point", fontsize=9)
    fig.tight_layout()
    path = out / "fig5_paper.png"
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def read_csv(path: Path) -> list:
    """The rows ``main`` saved, typed back."""
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        for key, value in row.items():
            if key in ("formulation", "steps", "rejected", "events", "resets", "jumped"):
                row[key] = int(value)
            elif key in ("below", "finished"):
                row[key] = value == "True"
            elif key != "error":
                row[key] = float(value)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cap", type=float, default=10.0, help="wall seconds per point")
    parser.add_argument("--cycles", type=int, default=3, help="stick-slip cycles or wavelengths per point")
    parser.add_argument("--grid", type=int, default=8, help="points per axis")
    parser.add_argument("--formulations", type=int, nargs="+", default=[0, 1], choices=[0, 1])
    parser.add_argument("--rtol", type=float, help="adaptive's rtol (atol = rtol / 100); default the FMU's")
    parser.add_argument("--contact-law", default="linear", choices=["linear", "linear_along_normal"],
                        help="the contact law (fixed axes: the conservative default, or the force along the normal)")
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    parser.add_argument("--replot", action="store_true", help="redraw the figure from <out>/fig5_paper.csv only")
    args = parser.parse_args(argv)
    os.environ.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".cache" / "numba"))
    from vibroblock import Block

    p = paper_parameters()
    rtol = args.rtol or p["rtol"]
    if args.replot:
        results = read_csv(args.out / "fig5_paper.csv")
        formulations = sorted({r["formulation"] for r in results})
        print(f"saved {plot(results, formulations, args.out, p, rtol, args.cycles)}")
        return results
    # Compile or load the kernels here, so the workers' caps measure integration, not compilation.
    for formulation in args.formulations:
        warm = Block("C", "adaptive", initial_state=2, A=0.3, omega=0.5, x_start=CREST, dt=DT, formulation=formulation,
                     contact_law=args.contact_law)
        warm.start(CREST / p["V_d"])
        warm.advance_to(CREST / p["V_d"] + 10.0)
        warm.outputs()
    omegas, amplitudes = np.geomspace(0.1, 1.0, args.grid), np.geomspace(0.3, 300.0, args.grid)
    # Faster plates cost more per tau_0: start them first, so the workers end together.
    points = [(f, float(w), float(a), args.cap, rtol, args.cycles, args.contact_law) for f in args.formulations
              for w in omegas[::-1] for a in amplitudes]
    print(f"Fig. 5 at the paper's parameters (model C: k_d = {p['k_d']:g}, V_d = {p['V_d']:g}, A_x = {p['A_x']:g}, "
          f"omega_x = {p['omega_x']:g}, P_l = {p['P_l']:g}), adaptive (rtol = {rtol:g}, atol = {1e-2 * rtol:g}); "
          f"units: stick-slip cycle T = {cycle_time(p):.3g} tau_0, wavelength {wavelength_time(p):.3g} tau_0; "
          f"{len(points)} points, each to {args.cycles + 1.5:g} units or {args.cap:g} s, on {args.workers} workers",
          flush=True)
    started = time.perf_counter()
    results = []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for done in as_completed([pool.submit(run_point, point) for point in points]):
            r = done.result()
            results.append(r)
            state = f"phi = {r['phi']:.3g}" if r["finished"] else f"capped at {r['simulated']:.3g} tau_0"
            print(f"  [{len(results)}/{len(points)}, {time.perf_counter() - started:.0f} s] "
                  f"{FORMULATIONS[r['formulation']]} omega = {r['omega']:.3g}, A = {r['A']:.3g}: {r['cpu']:.1f} "
                  f"CPU-s, {state}", flush=True)
    wall = time.perf_counter() - started

    args.out.mkdir(parents=True, exist_ok=True)
    fields = ("formulation", "omega", "A", "below", "finished", "phi", "drift", "needed", "simulated", "cpu", "cost",
              "steps", "rejected", "events", "resets", "jumped", "error")
    with open(args.out / "fig5_paper.csv", "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(fields)
        for r in results:
            writer.writerow([f"{r[k]:.6g}" if isinstance(r[k], float) else r[k] for k in fields])
    verdicts = []
    for formulation in args.formulations:
        rows = sorted((r for r in results if r["formulation"] == formulation), key=lambda r: (r["omega"], r["A"]))
        print(f"\nformulation = {formulation} ({FORMULATIONS[formulation]}); costs in CPU seconds (one core)")
        print(f"{'omega':>6} {'A':>8} {'A/A_c':>7} {'side':>10} {'needed':>9} {'simulated':>9} {'steps':>9} "
              f"{'events':>8} {'jumped':>9} {'CPU s':>6} {'point':>9} {'phi':>9}")
        for r in rows:
            side = "stick-slip" if r["below"] else "sliding"
            phi = f"{r['phi']:9.3g}" if r["finished"] else "  (capped)"
            print(f"{r['omega']:6.3g} {r['A']:8.3g} {r['A'] / onset(r['omega'], p):7.3g} {side:>10} "
                  f"{r['needed']:9.3g} {r['simulated']:9.3g} {r['steps']:9d} {r['events']:8d} {r['jumped']:9d} "
                  f"{r['cpu']:6.1f} {human(r['cost']):>9} {phi}" + (f"  stopped: {r['error']}" if r['error'] else ""))
        total = sum(r["cost"] for r in rows)
        finished = sum(r["finished"] for r in rows)
        below, above = sum(r["below"] for r in rows), sum(not r["below"] for r in rows)
        cost_below = sum(r["cost"] for r in rows if r["below"])
        estimate = total / args.workers
        verdicts.append((FORMULATIONS[formulation], estimate))
        print(f"{len(rows)} points ({below} below the onset: {human(cost_below)} CPU; {above} at or above it: "
              f"{human(total - cost_below)} CPU), {finished} finished within the cap; the diagram on "
              f"{args.workers} cores: {human(estimate)} = {estimate / TARGET:.3g} x the 10-minute target: "
              f"{'within' if estimate <= TARGET else 'OUT OF REACH'}")
    path = plot(results, args.formulations, args.out, p, rtol, args.cycles)
    print(f"\nmeasured in {wall:.0f} s wall; saved {path}")
    for name, estimate in verdicts:
        print(f"{name}: {args.grid} x {args.grid} diagram with >= {args.cycles} cycles/wavelengths per point ~ "
              f"{human(estimate)} on {args.workers} cores ({'within' if estimate <= TARGET else 'not within'} "
              f"10 minutes)")
    return results


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("fig5_paper"):
        main()
