"""Sweeps of the chain: its catalogue over a grid of plate drives and record scalings, on
dask.distributed as the single block's sweeps run.

    python -m harness.chain.sweep --grid A=0:0.6:4 --grid omega=0.2,0.8 [--blocks 64]
        [--stop-time 2e4] [--set mu_s_spread=0.3] [--record example|FILE --grid record_scale=0.05,0.2]
        [--scheduler ADDRESS|inline] [--workers N] [--out out/chain_sweep]

Each point is one run of ``BlockChain3.fmu`` (N set at run time) through fmpy
(:func:`harness.chain.run.simulate_chain`), its catalogue read back and summarised
(:func:`point_statistics`).  A grid axis names any parameter of the chain or its blocks
(``A``, ``omega``, ``k_c``, ``mu_s_spread``, ...), or ``record_scale``: the peak plate
acceleration (in g) to which a record (``--record``: ``example``, the strong part of obspy's
example event, or a file obspy reads) is scaled, played from ``--record-onset`` on,
stretched by ``--time-scale`` model time units per record second.

The points run on a Dask LocalCluster (one worker per core) or on the scheduler given
(``inline``: in this process).  Every finished point is stored under ``<out>/points`` as
it arrives, keyed by its settings and the FMU's sha256 (:func:`harness.runs.sweep.cached_map`):
a sweep that is killed and started again computes only the points that had not finished.
The result is an xarray Dataset with one dimension per axis (``<out>/chain_sweep.nc``).
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from harness.cosim.fmu import REPO_ROOT, fmu_sha256
from harness.runs.sweep import Execution, Grid, cached_map

CHAIN_FMU = REPO_ROOT / "build" / "fmus" / "BlockChain3.fmu"
RECORD_AXIS = "record_scale"
OBSERVABLES = ("events", "events_per_1e4", "system_wide", "largest_potency", "b_value", "b_sigma",
               "events_during_record", "events_before_record")


@dataclass(frozen=True)
class ChainSweep:
    """What every point shares: the FMU, the chain length, the run, the fixed parameters
    and, for a record axis, the record and how it is played."""

    fmu: str = str(CHAIN_FMU)
    n_blocks: int = 64
    stop_time: float = 2e4
    step: float = 50.0  # tau_0 between communication points (the catalogue keeps every event)
    parameters: tuple = ()  # (name, value) pairs set on every point
    record: str | None = None  # "example" or a file obspy reads
    record_onset: float = 1e4
    time_scale: float = 200.0


def point_item(sweep: ChainSweep, coordinates: dict) -> dict:
    values = {**dict(sweep.parameters), **{k: v for k, v in coordinates.items() if k != RECORD_AXIS}}
    item = {"fmu": sweep.fmu, "n_blocks": sweep.n_blocks, "stop_time": sweep.stop_time, "step": sweep.step,
            "start_values": values}
    if RECORD_AXIS in coordinates:
        if sweep.record is None:
            raise ValueError(f"a {RECORD_AXIS} axis needs a record (--record example or a file)")
        item["record"] = {"source": sweep.record, "peak": coordinates[RECORD_AXIS], "onset": sweep.record_onset,
                          "time_scale": sweep.time_scale}
    return item


def record_table(record: dict, stop_time: float, step: float):
    """The plate input of a record scaled to its peak acceleration: fmpy's input table on
    the communication grid, and the time the record stops playing."""
    from harness.ground.excitation import excitation_of, peak_scaled_parameters, plate_input, playback_of

    if record["source"] == "example":
        from harness.ground.triggering import triggering_motion
        motion = triggering_motion()
    else:
        from harness.ground.records.processing import load_ground_motion
        motion = load_ground_motion(record["source"])
    playback = playback_of(motion)
    parameters = peak_scaled_parameters(playback, record["peak"], record["time_scale"], record["onset"])
    table = plate_input(excitation_of(playback, **parameters), step_size=step, stop_time=stop_time)
    return table, record["onset"] + playback.duration * record["time_scale"]


def point_statistics(events, n_blocks: int, stop_time: float, window: tuple[float, float] | None) -> dict:
    """The numbers a point keeps: events, their rate per 1e4 tau_0, system-wide events, the
    largest potency, the b-value with its error (NaN with fewer than 2 events above M_c),
    and with a record the events that started while it played and in as long a time
    before it."""
    from harness.chain.statistics import b_value, magnitudes

    potency = events.potency.to_numpy(dtype=float)
    measured = {"events": int(len(events)), "events_per_1e4": len(events) / stop_time * 1e4,
                "system_wide": int((events.n_blocks == n_blocks).sum()),
                "largest_potency": float(potency.max()) if potency.size else math.nan,
                "b_value": math.nan, "b_sigma": math.nan,
                "events_during_record": -1, "events_before_record": -1}
    try:
        b = b_value(magnitudes(potency))
        measured["b_value"], measured["b_sigma"] = b.b, b.sigma
    except ValueError:
        pass
    if window is not None:
        start, end = window
        t = events.t_start.to_numpy(dtype=float)
        measured["events_during_record"] = int(((t >= start) & (t < end)).sum())
        measured["events_before_record"] = int(((t >= start - (end - start)) & (t < start)).sum())
    return measured


def chain_point(item: dict, pool=None) -> dict:
    """One point (on a worker): the chain's run and its catalogue's numbers."""
    from harness.chain.run import simulate_chain

    plate, window = None, None
    if "record" in item:
        plate, end = record_table(item["record"], item["stop_time"], item["step"])
        window = (item["record"]["onset"], end)
    with tempfile.TemporaryDirectory() as folder:
        _, events = simulate_chain(item["fmu"], stop_time=item["stop_time"], step_size=item["step"],
                                   catalog=Path(folder) / "catalog.csv", outputs=("event_count",), plate=plate,
                                   start_values={**item["start_values"], "N": item["n_blocks"]})
    return point_statistics(events, item["n_blocks"], item["stop_time"], window)


def chain_sweep(grid: Grid, sweep: ChainSweep = ChainSweep(), out: str | Path = REPO_ROOT / "out" / "chain_sweep",
                execution: Execution = Execution(), client=None):
    """Run every point of ``grid`` (stored under ``<out>/points``); the Dataset of the
    observables over the grid's axes, with ``attrs`` stating the fixed settings and how
    many points were computed and reused."""
    import xarray as xr

    if grid.derived:
        raise ValueError("a chain sweep takes axes only, no derived parameters")
    combinations = list(grid.combinations())
    items = [point_item(sweep, coordinates) for _, coordinates in combinations]
    outcome = cached_map(chain_point, items, Path(out) / "points", {"fmu_sha256": fmu_sha256(sweep.fmu)}, execution,
                         client)
    data = {name: np.full(grid.shape, np.nan) for name in OBSERVABLES}
    for (index, _), result in zip(combinations, outcome.results):
        for name in OBSERVABLES:
            data[name][index] = result[name]
    coords = {axis.name: list(axis.values) for axis in grid.axes}
    dataset = xr.Dataset({name: (grid.names, values) for name, values in data.items()}, coords=coords)
    dataset.attrs.update({"fmu": Path(sweep.fmu).name, "n_blocks": sweep.n_blocks, "stop_time": sweep.stop_time,
                          "parameters": repr(dict(sweep.parameters)), "record": sweep.record or "",
                          "points_computed": outcome.computed, "points_reused": outcome.reused,
                          "compute_time_s": outcome.compute_time})
    return dataset


def _value(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"{text!r} is not of the form name=value")
    return name.strip(), float(value)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m harness.chain.sweep", description=__doc__.splitlines()[0])
    parser.add_argument("--grid", action="append", required=True, help="an axis: name=start:stop:n[:log] or v1,v2")
    parser.add_argument("--set", action="append", type=_value, default=[], help="a fixed parameter: name=value")
    parser.add_argument("--blocks", type=int, default=ChainSweep.n_blocks)
    parser.add_argument("--stop-time", type=float, default=ChainSweep.stop_time)
    parser.add_argument("--step", type=float, default=ChainSweep.step)
    parser.add_argument("--record", help="'example' (obspy's example event) or a record file, for record_scale")
    parser.add_argument("--record-onset", type=float, default=ChainSweep.record_onset)
    parser.add_argument("--time-scale", type=float, default=ChainSweep.time_scale)
    parser.add_argument("--fmu", type=Path, default=CHAIN_FMU)
    parser.add_argument("--scheduler", help="address of an existing Dask scheduler, or 'inline' (no Dask)")
    parser.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "out" / "chain_sweep")
    parser.add_argument("--no-progress", action="store_true")
    args = parser.parse_args(argv)
    try:
        grid = Grid.parse(args.grid)
    except ValueError as exc:
        parser.error(str(exc))
    if not args.fmu.exists():
        parser.error(f"no chain FMU at {args.fmu}: build it with `make fmus`")
    sweep = ChainSweep(str(args.fmu), args.blocks, args.stop_time, args.step, tuple(args.set), args.record,
                       args.record_onset, args.time_scale)
    execution = Execution(scheduler=args.scheduler, workers=args.workers, progress=not args.no_progress)
    try:
        dataset = chain_sweep(grid, sweep, args.out, execution)
    except ValueError as exc:
        raise SystemExit(f"python -m harness.chain.sweep: {exc}") from None
    from harness.runs.dataset_files import save_dataset

    save_dataset(dataset, args.out / "chain_sweep.nc")
    frame = dataset[["events", "system_wide", "b_value", "events_during_record"]].to_dataframe()
    print(frame.to_string())
    print(f"{dataset.attrs['points_computed']} points computed, {dataset.attrs['points_reused']} from the store; "
          f"saved {args.out / 'chain_sweep.nc'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
