"""Triggered events in a chain of blocks: harmonic bursts, chirps and a real record
shaking the plate at phases of the loading cycle, and the clock advance of the next large
event against period and acceleration (harness/chain/triggering.py).

    python examples/chain_triggering.py [--phases 0.3,0.6,0.9] [--periods 1,10,100,1000]
        [--accelerations 0.05,0.2] [--no-signals]

Prints one row per burst: phase, period P, acceleration amplitude a (in g), T_0 (the time
left before the undisturbed event when the burst arrives), the clock advance, whether the
burst triggered the event; then, per phase and acceleration, whether the advance is the
same for every period below T_0 (the shape Perfettini, Schmittbuhl and Cochard 2003
describe) and how it changes above.  Then the same phases and accelerations with a
logarithmic chirp from P = 100 to P = 10 over 300 tau_0 (Hann-tapered, acceleration
amplitude a) and with obspy's example event (BW.RJOB, vertical, its strong part) stretched
by 200 (its ~10 Hz at P ~ 20 tau_0) and scaled to peak acceleration a.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_experiment(phases=(0.3, 0.6, 0.9), periods=(1.0, 10.0, 100.0, 1000.0), accelerations=(0.05, 0.2),
                   settings=None) -> list[dict]:
    from harness.chain.triggering import TriggerSettings, clock_advance, reference_cycle

    settings = settings or TriggerSettings()
    reference = reference_cycle(settings)
    print(f"reference cycle: the last large event ends at t_s = {reference.t_s:g}, the next starts at "
          f"t_ref = {reference.t_ref:g} (T = {reference.cycle:g} tau_0); {settings.n_blocks} blocks, "
          f"bursts of {settings.cycles} periods")
    print(f"{'phase':>6} {'P':>7} {'a [g]':>6} {'T_0':>8} {'advance':>9} triggered")
    rows = []
    for phase in phases:
        for acceleration in accelerations:
            for period in periods:
                row = clock_advance(reference, settings, phase, period, acceleration)
                rows.append(row)
                print(f"{phase:6.2f} {period:7g} {acceleration:6.3f} {row['T0']:8.1f} {row['advance']:9.2f} "
                      f"{'yes' if row['triggered'] else 'no'}")
    print(triggered_fractions(rows))
    return rows


def triggered_fractions(rows) -> str:
    """The fraction of bursts that triggered the event, in all and by acceleration, period and phase."""
    def share(group):
        return f"{sum(r['triggered'] for r in group)}/{len(group)}"

    parts = [f"triggered: {share(rows)} bursts"]
    for key, unit in (("acceleration", " g"), ("period", ""), ("phase", "")):
        values = sorted({r[key] for r in rows})
        parts.append(f"by {key}: " + ", ".join(f"{v:g}{unit} {share([r for r in rows if r[key] == v])}"
                                                for v in values))
    return "; ".join(parts)


CHIRP = {"period_start": 100.0, "period_end": 10.0, "duration": 300.0, "sweep": "log"}
RECORD_TIME_SCALE = 200.0


def run_signals(phases=(0.3, 0.6, 0.9), accelerations=(0.05, 0.2), settings=None) -> list[dict]:
    """The chirp and the record at each phase and acceleration (peak acceleration for the record)."""
    from harness.chain.triggering import Chirp, RecordSignal, TriggerSettings, reference_cycle, signal_advance

    settings = settings or TriggerSettings()
    reference = reference_cycle(settings)
    print(f"\nchirp {CHIRP}, record: obspy's example event stretched by {RECORD_TIME_SCALE:g}")
    print(f"{'signal':>7} {'phase':>6} {'a [g]':>6} {'T_0':>8} {'advance':>9} triggered")
    rows = []
    for phase in phases:
        for acceleration in accelerations:
            for name, signal in (("chirp", Chirp(acceleration, **CHIRP)),
                                 ("record", RecordSignal(acceleration, time_scale=RECORD_TIME_SCALE))):
                row = {"signal": name, "acceleration": acceleration,
                       **signal_advance(reference, settings, phase, signal)}
                rows.append(row)
                print(f"{name:>7} {phase:6.2f} {acceleration:6.3f} {row['T0']:8.1f} {row['advance']:9.2f} "
                      f"{'yes' if row['triggered'] else 'no'}")
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    floats = lambda text: tuple(float(v) for v in text.split(","))  # noqa: E731
    parser.add_argument("--phases", type=floats, default=(0.3, 0.6, 0.9))
    parser.add_argument("--periods", type=floats, default=(1.0, 10.0, 100.0, 1000.0))
    parser.add_argument("--accelerations", type=floats, default=(0.05, 0.2))
    parser.add_argument("--no-signals", action="store_true", help="bursts only: no chirp, no record")
    args = parser.parse_args(argv)
    run_experiment(args.phases, args.periods, args.accelerations)
    if not args.no_signals:
        run_signals(args.phases, args.accelerations)
    return 0


if __name__ == "__main__":
    sys.exit(main())
