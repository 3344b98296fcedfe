"""Benchmark: a catalogue of 1e4 events of a chain of 1000 blocks, what it costs on two
cores and how far its statistics are from those of finer steps.

    python -m harness.benchmarks.chain_catalog [--quick] [--blocks 1000] [--horizon 3.5e4]

The chain: Carlson and Langer's standard parameters (``harness.chain.run.CARLSON_LANGER``)
with the cluster catalogue, the chain's symplectic Euler at its default step dt = 1e-2
(the product's choice), run to ``--horizon``.  Beside it, in the same run, the same chain
with finer steps: symplectic Euler at dt = 5e-3 and 2.5e-3, and ``rk4`` at dt = 5e-3
(fourth order between resets; the resets keep it first order).  The runs go two at a
time, one per core, each in a process of its own (``concurrent.futures``).

Printed:

1. per run: events, CPU seconds, block-steps per second, and the CPU seconds to the
   1e4th event; the wall time of all runs on the two cores;
2. the catalogue's error against the finest run (symplectic Euler at 2.5e-3, and rk4 at
   5e-3 beside it): the chain is chaotic, so single events part after a while (the time
   up to which the catalogues agree event for event is printed), and what is compared is
   the statistics: event rate, system-wide events, b-value, size exponent, the mean
   potency of the system-wide events, and the two-sample Kolmogorov-Smirnov distance of
   the potency distributions (scipy) with its 5 % critical value, the distance two
   samples of the same law would stay below.  The differences between the two finest
   runs say how well the reference itself is known.
"""
from __future__ import annotations

import argparse
import math
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from . import recorded

TARGET_EVENTS = 10_000
BUDGET_S = 600.0  # the catalogue's budget on two cores
# (label, integrator, dt): the product's default first, the finest last.
RUNS = (("symplectic_euler, dt = 1e-2", "symplectic_euler", 1e-2),
        ("symplectic_euler, dt = 5e-3", "symplectic_euler", 5e-3),
        ("rk4, dt = 5e-3", "rk4", 5e-3),
        ("symplectic_euler, dt = 2.5e-3", "symplectic_euler", 2.5e-3))
CHUNK = 500.0  # tau_0 between looks at the catalogue (the CPU time at the 1e4th event)


def catalogue(n_blocks: int, horizon: float, integrator: str, dt: float) -> dict:
    """One run (in a worker process): its events and CPU seconds, and the CPU seconds at
    which the catalogue held TARGET_EVENTS events."""
    from harness.chain.run import CARLSON_LANGER
    from vibroblock.chain import Chain

    chain = Chain(n_blocks, clusters=True, integrator=integrator, dt=dt, **CARLSON_LANGER)
    chain.start()
    chain.advance_to(1.0)  # compiled or loaded outside the timing
    start, at_target, t = time.process_time(), math.nan, 1.0
    while t < horizon:
        t = min(t + CHUNK, horizon)
        chain.advance_to(t)
        if math.isnan(at_target) and len(chain.events) >= TARGET_EVENTS:
            at_target = time.process_time() - start
    return {"seconds": time.process_time() - start, "at_target": at_target, "steps": horizon / dt,
            "events": np.asarray(chain.events, dtype=float)}


def statistics(events: np.ndarray, n_blocks: int, horizon: float) -> dict:
    from harness.chain.statistics import catalogue_summary

    measured = catalogue_summary(n_blocks, events[:, 3].astype(int), events[:, 4], events[:, 0])
    whole = events[events[:, 3] == n_blocks, 4]
    return {"rate": len(events) / horizon * 1e4, "system_wide": measured["system_wide"],
            "b": measured["b_value"].get("b", math.nan), "b_sigma": measured["b_value"].get("sigma", math.nan),
            "tau": measured["size_exponent"].get("tau", math.nan),
            "tau_sigma": measured["size_exponent"].get("sigma", math.nan),
            "mean_system_wide": float(whole.mean()) if whole.size else math.nan}


def agree_until(a: np.ndarray, b: np.ndarray, tolerance: float = 0.5) -> float:
    """The start of the first event at which two catalogues part (first block, blocks, or
    start times more than ``tolerance`` tau_0 apart); inf if they never do."""
    for row_a, row_b in zip(a, b):
        if row_a[2] != row_b[2] or row_a[3] != row_b[3] or abs(row_a[0] - row_b[0]) > tolerance:
            return float(min(row_a[0], row_b[0]))
    return math.inf


def ks(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Two-sample KS distance of the potencies and its 5 % critical value."""
    from scipy.stats import ks_2samp

    n, m = len(a), len(b)
    return float(ks_2samp(a, b).statistic), 1.358 * math.sqrt((n + m) / (n * m))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=1000)
    parser.add_argument("--horizon", type=float, default=3.5e4, help="tau_0 each run covers")
    parser.add_argument("--quick", action="store_true", help="64 blocks over 2e3 tau_0; publishes nothing")
    args = parser.parse_args(argv)
    n_blocks, horizon = (64, 2e3) if args.quick else (args.blocks, args.horizon)
    with recorded("chain_catalog", argv):
        print(f"A chain of {n_blocks} blocks at Carlson and Langer's parameters, cluster catalogue, "
              f"{horizon:g} tau_0 per run; runs two at a time, one per core, each in its own process")
        started = time.perf_counter()
        with ProcessPoolExecutor(2) as pool:
            futures = [pool.submit(catalogue, n_blocks, horizon, integrator, dt) for _, integrator, dt in RUNS]
            runs = [future.result() for future in futures]
        wall = time.perf_counter() - started
        print(f"\n1. cost (CPU seconds of each run's process; all {len(RUNS)} runs took {wall:.0f} s wall on 2 cores)")
        print(f"   {'run':30} {'events':>7} {'CPU s':>8} {'block-steps/s':>14} {f'CPU s to {TARGET_EVENTS}':>14}")
        for (label, _, _), run in zip(RUNS, runs):
            rate = run["steps"] * n_blocks / run["seconds"]
            print(f"   {label:30} {len(run['events']):7d} {run['seconds']:8.1f} {rate:14.3g} {run['at_target']:14.1f}")
        default = runs[0]
        if not math.isnan(default["at_target"]):
            print(f"   the default reaches {TARGET_EVENTS} events in {default['at_target']:.0f} CPU-s of one core: "
                  f"{default['at_target'] / BUDGET_S:.2f} of the {BUDGET_S:.0f} s budget")
        print(f"\n2. statistics of each run, and against the finest ({RUNS[-1][0]})")
        stats = [statistics(run["events"], n_blocks, horizon) for run in runs]
        reference = runs[-1]["events"]
        print(f"   {'run':30} {'events/1e4':>10} {'system-wide':>11} {'b':>13} {'tau':>13} "
              f"{'<potency> sys':>13} {'KS (5 % crit)':>14} {'same events until':>18}")
        for (label, _, _), run, s in zip(RUNS, runs, stats):
            if run is runs[-1]:
                distance = "-"
                until = "-"
            else:
                d, critical = ks(run["events"][:, 4], reference[:, 4])
                distance = f"{d:.3f} ({critical:.3f})"
                until = f"{agree_until(run['events'], reference):.0f}"
            print(f"   {label:30} {s['rate']:10.0f} {s['system_wide']:11d} {s['b']:6.3f}+-{s['b_sigma']:.3f} "
                  f"{s['tau']:6.3f}+-{s['tau_sigma']:.3f} {s['mean_system_wide']:13.1f} {distance:>14} {until:>18}")
        finest = stats[-1]
        print(f"\n   differences from the finest: " + "; ".join(
            f"{label}: rate {s['rate'] / finest['rate'] - 1:+.1%}, b {s['b'] - finest['b']:+.3f}, "
            f"tau {s['tau'] - finest['tau']:+.3f}, <potency> of system-wide "
            f"{s['mean_system_wide'] / finest['mean_system_wide'] - 1:+.1%}"
            for (label, _, _), s in zip(RUNS[:-1], stats[:-1])))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
