"""A sweep through a real `dask scheduler` and `dask worker` started on loopback."""
from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import psutil
import xarray as xr

from harness.runs.settings import ObservableSettings, PointSettings, RunSettings
from harness.runs.sweep import INLINE, Execution, Grid, run_sweep, worker_pool_loads

DASK = str(Path(sys.executable).with_name("dask"))


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def stop(process: subprocess.Popen) -> None:
    """SIGTERM to the process group, SIGKILL if it lingers; every child is reaped."""
    if process.poll() is not None:
        return
    family = [process] + [psutil.Process(c.pid) for c in psutil.Process(process.pid).children(recursive=True)]
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGTERM)
    try:
        process.wait(timeout=15)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=15)
    psutil.wait_procs([p for p in family[1:] if p.is_running()], timeout=15)


@contextlib.contextmanager
def dask_cluster(tmp_path: Path, env: dict, workers: int = 2):
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    log = open(tmp_path / "cluster.log", "w")
    started = []
    try:
        started.append(subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                         "--no-dashboard"], env=env, stdout=log, stderr=log,
                                        start_new_session=True))
        started.append(subprocess.Popen([DASK, "worker", address, "--host", "127.0.0.1", "--nworkers", str(workers),
                                         "--nthreads", "1", "--no-dashboard", "--local-directory",
                                         str(tmp_path / "workers")], env=env, stdout=log, stderr=log,
                                        start_new_session=True))
        yield address
    finally:
        for process in reversed(started):
            stop(process)
        log.close()


def test_a_sweep_runs_through_an_external_scheduler(fmu_a, tmp_path, subprocess_env):
    from distributed import Client

    grid = Grid.parse(["A=0,4", "omega=0.6,0.8"])
    base = PointSettings(RunSettings.for_model("A", fmu=str(fmu_a), horizon=1500.0),
                         ObservableSettings(transient=300.0))
    with dask_cluster(tmp_path, subprocess_env) as address:
        client = Client(address, timeout=60, set_as_default=False)
        try:
            client.wait_for_workers(2, timeout=60)
            workers = set(client.scheduler_info()["workers"])
            outcome = run_sweep(grid, base, tmp_path / "store", Execution(scheduler=address, progress=False))
            loads = worker_pool_loads(client)
        finally:
            client.close()
    assert outcome.computed == 4
    assert set(loads) == workers and all(n <= 1 for n in loads.values()) and sum(loads.values()) >= 1
    direct = run_sweep(grid, base, tmp_path / "direct", Execution(scheduler=INLINE, progress=False))
    xr.testing.assert_identical(outcome.dataset, direct.dataset)
