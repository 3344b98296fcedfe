"""Periodic loading of a chain of blocks under rate-and-state friction: the clock advance
of the next large event against the loading period, at fixed acceleration amplitude
(harness/chain/triggering.py, ``periodic_advance`` and ``RATE_STATE_STUDY``).

    python examples/chain_rate_state_triggering.py [--phases 0.3,0.6,0.9]
        [--periods 10,20,50,100,200,500,1000,2000] [--accelerations 0.005,0.02]
        [--blocks 16] [--seed 1] [--load-spread 0.3] [--friction-law 3]

(--blocks 1 --load-spread 0 is the single block under the same law.)

The chain (16 blocks, aging law, velocity weakening, weights spread by 30 %) is loaded
through three large events; at phase p of the next, undisturbed cycle the plate starts to
accelerate by a sin(2 pi t / P) and keeps on until the next large event.  Prints one row
per run (phase, T_0 the time left before the undisturbed event when the loading starts,
acceleration, period, clock advance, smaller events before the large one), then a table
per phase and acceleration of the advance against P, periods below T_0 marked, with the
range of the advances below T_0 and above it (the comparison with Perfettini, Schmittbuhl
and Cochard 2003: no dependence on P below T_0, a strong one above).
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time


def run_experiment(phases=(0.3, 0.6, 0.9), periods=(10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0),
                   accelerations=(0.005, 0.02), settings=None) -> list[dict]:
    from harness.chain.triggering import RATE_STATE_STUDY, periodic_advance, reference_cycle

    settings = settings or RATE_STATE_STUDY
    started = time.perf_counter()
    reference = reference_cycle(settings)
    print(f"reference cycle: the last large event ends at t_s = {reference.t_s:g}, the next starts at "
          f"t_ref = {reference.t_ref:g} (T = {reference.cycle:g} tau_0); {settings.n_blocks} blocks, "
          f"{dict(settings.parameters)}, load_spread = {settings.load_spread:g}, seed = {settings.seed}")
    print(f"{'phase':>6} {'T_0':>7} {'a [g]':>6} {'P':>7} {'advance':>9} {'smaller events before':>22}")
    rows = []
    for phase in phases:
        for acceleration in accelerations:
            for period in periods:
                row = periodic_advance(reference, settings, phase, period, acceleration)
                rows.append(row)
                print(f"{phase:6.2f} {row['T0']:7.1f} {acceleration:6.3f} {period:7g} {row['advance']:9.1f} "
                      f"{row['smaller_events']:22d}")
    print("\nclock advance (tau_0) against P; * marks P < T_0; nan: no large event within a cycle after t_ref")
    print(f"{'phase':>6} {'T_0':>7} {'a [g]':>6} " + " ".join(f"{f'P={p:g}':>9}" for p in periods))
    for k in range(0, len(rows), len(periods)):
        group = rows[k:k + len(periods)]
        below = [r["advance"] for r in group if r["period"] < r["T0"]]
        above = [r["advance"] for r in group if r["period"] >= r["T0"]]
        cells = " ".join(f"{r['advance']:8.1f}{'*' if r['period'] < r['T0'] else ' '}" for r in group)
        print(f"{group[0]['phase']:6.2f} {group[0]['T0']:7.1f} {group[0]['acceleration']:6.3f} {cells}   "
              f"below T_0: {_spread(below)}; above: {_spread(above)}")
    print(f"({len(rows)} runs, {time.perf_counter() - started:.0f} s)")
    return rows


def _spread(values) -> str:
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return "-"
    return f"{min(finite):.1f} to {max(finite):.1f}" + (f" ({len(values) - len(finite)} nan)" if len(finite) < len(values) else "")


def study_settings(args):
    """The study's chain with the options given on the command line replaced."""
    from harness.chain.triggering import RATE_STATE_STUDY

    changes = {name: value for name, value in (("n_blocks", args.blocks), ("seed", args.seed),
                                               ("load_spread", args.load_spread)) if value is not None}
    if args.friction_law is not None:
        changes["parameters"] = tuple((name, args.friction_law if name == "friction_law" else value)
                                      for name, value in RATE_STATE_STUDY.parameters)
    return dataclasses.replace(RATE_STATE_STUDY, **changes)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    floats = lambda text: tuple(float(v) for v in text.split(","))  # noqa: E731
    parser.add_argument("--phases", type=floats, default=(0.3, 0.6, 0.9))
    parser.add_argument("--periods", type=floats, default=(10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0))
    parser.add_argument("--accelerations", type=floats, default=(0.005, 0.02))
    parser.add_argument("--blocks", type=int, help="chain length (default: the study's 16)")
    parser.add_argument("--seed", type=int, help="seed of the weights' draw (default: the study's 1)")
    parser.add_argument("--load-spread", type=float, help="spread of the weights (default: the study's 0.3)")
    parser.add_argument("--friction-law", type=int, choices=(3, 4), help="3 aging (default), 4 slip law")
    args = parser.parse_args(argv)
    run_experiment(args.phases, args.periods, args.accelerations, study_settings(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
