"""Benchmark: sweep throughput on 1 and 2 Dask workers, and the harness's overhead per point.

    python -m harness.benchmarks.sweep_throughput [--points 16] [--horizon 10000] [--interval 1]

Prints, measured side by side in one run:

1. points per second of the same sweep (model A, scaled set, an A x omega grid, no
   store) on a LocalCluster of 1 and of 2 workers, and their ratio.  Cluster start-up
   and each worker's first FMU load are excluded (the workers are warmed first), so
   the figures are the steady throughput of a long sweep.
2. per point, in this process, on one reused instance: a bare FMU run through fmpy's
   FMU2Slave (reset, set the parameters, initialize, doStep to the horizon at the same
   communication step), once reading nothing and once reading the same outputs after
   every step as the harness does; the harness's :func:`run_point` (those doSteps and
   reads, plus the Dataset and the observables); the harness's own overhead is the
   difference to the bare run with reads.  And the Dask cost per point on top
   (1-worker sweep time per point minus the in-process harness time).

Other processes competing for the cores spoil the speed-up; the cores they kept busy
just before the measurement, and the cores the workers kept busy, are printed with
the figures.
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

from harness.cosim.fmu import InstancePool
from harness.runs.run import POINT_OUTPUTS, resolved_parameters, run_point
from harness.runs.settings import Integration, ObservableSettings, PointSettings, RunSettings
from harness.runs.sweep import (POOL_PLUGIN, Execution, FmuPoolPlugin, Grid, close_client, open_client, points_of,
                           run_sweep)


def _warm(fmu: str, dask_worker=None) -> int:
    """Load the FMU on a worker and run it briefly, so timing starts from a warm worker."""
    from harness.runs.run import simulate
    from harness.runs.settings import RunSettings as Settings

    pool = dask_worker.plugins[POOL_PLUGIN].pool
    simulate(Settings(fmu=fmu, horizon=10.0), pool)
    return pool.loads


def _cpu_seconds() -> float:
    return time.process_time()


def sweep_seconds(grid: Grid, base: PointSettings, workers: int) -> tuple[float, float]:
    """Wall time of the sweep and the cores its workers kept busy (worker CPU time / wall)."""
    execution = Execution(workers=workers, progress=False)
    client = open_client(execution)
    try:
        client.wait_for_workers(workers, timeout=120)
        client.register_plugin(FmuPoolPlugin(execution.cache, execution.numba_cache()), name=POOL_PLUGIN)
        client.run(_warm, base.run.fmu)
        cpu_before = client.run(_cpu_seconds)
        started = time.perf_counter()
        outcome = run_sweep(grid, base, None, execution, client=client)
        elapsed = time.perf_counter() - started
        cpu_after = client.run(_cpu_seconds)
        assert outcome.computed == len(grid)
        busy = sum(cpu_after[w] - cpu_before[w] for w in cpu_after) / elapsed
        return elapsed, busy
    finally:
        close_client(client)


def bare_fmu_seconds(instance, point: PointSettings, outputs: tuple[str, ...] = ()) -> float:
    """The point's FMU work through fmpy alone, reading ``outputs`` after every step."""
    run = point.run
    slave = instance._slave  # the raw fmpy slave: this measures the harness against fmpy itself
    values = resolved_parameters(instance, run)
    real = [(instance.interface.variables[n].reference, float(v)) for n, v in values.items()
            if instance.interface.variables[n].type == "Real"]
    integer = [(instance.interface.variables[n].reference, int(v)) for n, v in values.items()
               if instance.interface.variables[n].type == "Integer"]
    reads = []
    getters = {"Real": slave.getReal, "Integer": slave.getInteger, "Boolean": slave.getBoolean}
    for kind in ("Real", "Integer", "Boolean"):
        refs = [instance.interface.variables[n].reference for n in outputs
                if instance.interface.variables[n].type == kind]
        if refs:
            reads.append((getters[kind], refs))
    started = time.perf_counter()
    slave.reset()
    slave.setupExperiment(startTime=run.start_time)
    slave.enterInitializationMode()
    slave.setReal([r for r, _ in real], [v for _, v in real])
    slave.setInteger([r for r, _ in integer], [v for _, v in integer])
    slave.exitInitializationMode()
    h = run.output_interval
    for k in range(run.n_outputs):
        slave.doStep(run.start_time + k * h, h)
        for getter, refs in reads:
            getter(refs)
    elapsed = time.perf_counter() - started
    instance.state = "running"
    return elapsed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=16, help="grid points (a square-ish A x omega grid)")
    parser.add_argument("--horizon", type=float, default=10_000.0, help="run length per point")
    parser.add_argument("--interval", type=float, default=1.0, help="output interval = communication step")
    parser.add_argument("--repeats", type=int, default=3, help="repeats of the in-process timings")
    args = parser.parse_args(argv)

    os.environ.setdefault("NUMBA_CACHE_DIR", str(Execution().numba_cache()))
    columns = max(1, int(round(args.points ** 0.5)))
    rows = max(1, args.points // columns)
    # Amplitudes below and above the onset, so both regimes (and their costs) are in.
    grid = Grid.parse([f"A=0:4:{rows}", f"omega=0.4:0.9:{columns}"])
    # The paper's scheme, as measured before the FMUs' default became adaptive: its cost
    # per point does not depend on the regime, which keeps the points comparable.
    base = PointSettings(RunSettings.for_model("A", horizon=args.horizon, output_interval=args.interval,
                                               integration=Integration("symplectic_euler")),
                         ObservableSettings(transient=args.horizon / 5))
    n = len(grid)
    import psutil

    busy = psutil.cpu_percent(interval=2.0) / 100 * (os.cpu_count() or 1)
    print(f"cores busy with other work just before the measurement: {busy:.2f}"
          + (" (the machine is shared: the figures below are pessimistic)" if busy > 0.2 else ""))
    print(f"sweep: {n} points of model A (scaled set), horizon {args.horizon:g}, output interval "
          f"{args.interval:g}, dt {base.run.integration.dt:g}, {os.cpu_count()} cores")

    one, one_busy = sweep_seconds(grid, base, 1)
    two, two_busy = sweep_seconds(grid, base, 2)
    print(f"  1 worker : {one:7.2f} s  {n / one:6.2f} points/s  (workers kept {one_busy:.2f} cores busy)")
    print(f"  2 workers: {two:7.2f} s  {n / two:6.2f} points/s  (workers kept {two_busy:.2f} cores busy)")
    print(f"  speed-up 2 vs 1 workers: {one / two:.2f}x (target >= 1.8x)")

    points = points_of(grid, base)
    bare, bare_reading, harness = [], [], []
    with InstancePool() as pool:
        instance = pool.get(base.run.fmu)
        run_point(points[0].settings, pool)  # warm
        for point in points:
            bare.append(min(bare_fmu_seconds(instance, point.settings) for _ in range(args.repeats)))
            bare_reading.append(min(bare_fmu_seconds(instance, point.settings, POINT_OUTPUTS)
                                    for _ in range(args.repeats)))
            best = float("inf")
            for _ in range(args.repeats):
                started = time.perf_counter()
                run_point(point.settings, pool)
                best = min(best, time.perf_counter() - started)
            harness.append(best)
    bare_mean, reading_mean = statistics.mean(bare), statistics.mean(bare_reading)
    harness_mean = statistics.mean(harness)
    steps = base.run.n_outputs
    print(f"per point, in this process (mean over the {n} points, best of {args.repeats}):")
    print(f"  bare FMU run, no reads          : {bare_mean * 1e3:8.1f} ms")
    print(f"  bare FMU run, reading {len(POINT_OUTPUTS)} outputs : {reading_mean * 1e3:8.1f} ms")
    print(f"  harness run_point               : {harness_mean * 1e3:8.1f} ms")
    overhead = harness_mean - reading_mean
    print(f"  harness overhead                : {overhead * 1e3:8.1f} ms per point ({overhead / reading_mean:.1%} of "
          f"the bare run with reads; {overhead / steps * 1e6:.1f} us per communication step, {steps} steps)")
    print(f"  reading outputs every step      : {(reading_mean - bare_mean) * 1e3:8.1f} ms "
          f"({(reading_mean - bare_mean) / steps * 1e6:.1f} us per step, mostly inside the FMU)")
    print(f"  Dask cost per point             : {(one / n - harness_mean) * 1e3:8.1f} ms (1-worker sweep time "
          f"per point minus the in-process harness time)")
    return 0


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("sweep_throughput"):
        status = main()
    raise SystemExit(status)
