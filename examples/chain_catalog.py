"""A chain of blocks on the plate (BlockChain.fmu): its event catalogue and the statistics
seismologists read from it.

    python examples/chain_catalog.py [--stop-time 2e5] [--spread 0.3] [--k-c 1.0] [--out out]
        [--record example|FILE [--record-scale 0.1] [--record-onset 1e5] [--time-scale 200]]

Runs build/fmus/BlockChain.fmu (16 blocks, the paper's friction and contact per block,
per-block mu_s drawn from mu_s (1 + spread u), u uniform in [-1, 1]) through fmpy, writes
its catalogue to out/chain_catalog.csv, and prints: the number of events and how many
blocks they involve, the magnitude-frequency distribution's maximum-likelihood b-value
with its completeness, the size exponent over the small events, and the recurrence of
system-wide events.  Saves out/chain_catalog.png (cumulative magnitude-frequency and the
event sizes in time).

With ``--record``, a real record shakes the plate: ``example`` (the strong part of obspy's
example event) or any file obspy reads, its vertical acceleration scaled to a peak of
``--record-scale`` g, stretched by ``--time-scale`` model time units per record second and
played from ``--record-onset`` on (``harness.chain.sweep.record_table``; the chain then
runs with communication steps of 2 tau_0).  The figure marks when it played, and the
events during it and in as long a time before are printed.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_experiment(fmu=ROOT / "build" / "fmus" / "BlockChain.fmu", *, stop_time=2e5, spread=0.3, k_c=1.0,
                   out=ROOT / "out", seed=1, record=None, record_scale=0.1, record_onset=1e5,
                   time_scale=200.0) -> dict:
    """Run the chain (shaken by ``record`` if given) and return its catalogue frame and
    statistics (also printed)."""
    import numpy as np
    from fmpy import read_model_description

    from harness.chain.run import simulate_chain
    from harness.chain.statistics import b_value, recurrence_intervals, size_exponent

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plate, window = None, None
    if record is not None:
        from harness.chain.sweep import record_table

        plate, end = record_table({"source": record, "peak": record_scale, "onset": record_onset,
                                   "time_scale": time_scale}, stop_time, 2.0)
        window = (record_onset, end)
    _, events = simulate_chain(fmu, stop_time=stop_time, step_size=100.0, catalog=out / "chain_catalog.csv",
                               start_values={"mu_s_spread": spread, "k_c": k_c, "seed": seed}, plate=plate)
    n_blocks = sum(v.name.startswith("x[") for v in read_model_description(str(fmu)).modelVariables)
    whole = events[events.n_blocks == n_blocks]
    print(f"{len(events)} events in {stop_time:g} tau_0 ({events.attrs['thresholds']})")
    print(f"  {len(whole)} involve all {n_blocks} blocks, {int((events.n_blocks == 1).sum())} a single block")
    result = {"events": events, "system_wide": len(whole)}
    finite = events.magnitude[np.isfinite(events.magnitude)]
    try:
        result["b"] = b_value(finite)
        print(f"  magnitude-frequency: {result['b']}")
    except ValueError as exc:
        print(f"  magnitude-frequency: {exc}")
    small = events.potency[(events.n_blocks < n_blocks) & (events.potency > 0)]
    if len(small) > 10:
        result["tau"] = size_exponent(small, float(np.quantile(small, 0.2)))
        print(f"  size exponent of the events smaller than the chain: {result['tau']}")
    intervals = recurrence_intervals(whole.t_start, whole.magnitude, -np.inf)
    if len(intervals):
        result["recurrence"] = (float(intervals.mean()), float(intervals.std()))
        print(f"  system-wide events recur every {intervals.mean():.4g} tau_0 (std {intervals.std():.3g})")
    if window is not None:
        t = events.t_start
        during = int(((t >= window[0]) & (t < window[1])).sum())
        before = int(((t >= 2 * window[0] - window[1]) & (t < window[0])).sum())
        result["record"] = {"window": window, "during": during, "before": before}
        print(f"  the record ({record_scale:g} g peak) played from {window[0]:g} to {window[1]:g} tau_0: "
              f"{during} events started then, {before} in as long a time before")
    _figure(events, out / "chain_catalog.png", window)
    return result


def _figure(events, path: Path, window=None) -> None:
    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6))
    left, right = fig.subplots(1, 2)
    m = np.sort(events.magnitude[np.isfinite(events.magnitude)].to_numpy())
    left.semilogy(m, np.arange(m.size, 0, -1), ".", ms=3)
    left.set(xlabel="magnitude (2/3) log10(potency)", ylabel="events with M >= m", title="magnitude-frequency")
    right.semilogy(events.t_start, events.potency, ".", ms=3)
    if window is not None:
        right.axvspan(*window, color="C1", alpha=0.25, label="record playing")
        right.legend(fontsize=8)
    right.set(xlabel="t_start [tau_0]", ylabel="potency [delta_0]", title="event sizes in time")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"saved {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop-time", type=float, default=2e5, help="tau_0 to run (default 2e5)")
    parser.add_argument("--spread", type=float, default=0.3, help="mu_s spread between blocks (default 0.3)")
    parser.add_argument("--k-c", type=float, default=1.0, help="coupling spring (default 1.0: l^2 = 100)")
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    parser.add_argument("--record", help="shake the plate with a record: 'example' (obspy's) or a file obspy reads")
    parser.add_argument("--record-scale", type=float, default=0.1, help="the record's peak acceleration, in g")
    parser.add_argument("--record-onset", type=float, default=1e5, help="when it starts to play, tau_0")
    parser.add_argument("--time-scale", type=float, default=200.0, help="model time units per record second")
    args = parser.parse_args(argv)
    run_experiment(stop_time=args.stop_time, spread=args.spread, k_c=args.k_c, out=args.out, record=args.record,
                   record_scale=args.record_scale, record_onset=args.record_onset, time_scale=args.time_scale)
    return 0


if __name__ == "__main__":
    sys.exit(main())
