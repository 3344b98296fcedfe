"""Durable results: resume after SIGKILL, no mixing of FMUs or settings."""
from __future__ import annotations

import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import psutil
import pytest
import xarray as xr

from harness.runs import cli
from harness.runs.settings import Integration, ObservableSettings, PointSettings, RunSettings
from harness.runs.store import PointStore, StoreMismatch
from harness.runs.sweep import INLINE, Execution, Grid, run_sweep

INLINE_QUIET = Execution(scheduler=INLINE, progress=False)
# Eight points of ~0.5 s each on one worker: the sweep is killed part-way.
RESUME_ARGS = ["--grid", "A=0,0.5,1,1.5", "--grid", "omega=0.5,0.7", "--horizon", "8000", "--transient", "1000",
               "--no-progress"]


def cli_point(args: list[str], fmu: Path) -> PointSettings:
    """The PointSettings the command line builds from these arguments."""
    parsed = cli.build_parser().parse_args(["sweep", "--fmu", str(fmu), *args])
    return cli._point(parsed)


def snapshot(store: Path) -> dict[str, tuple[int, bytes]]:
    return {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in (store / "points").glob("*.json")}


def kill_group(process: subprocess.Popen) -> None:
    family = [process.pid] + [c.pid for c in psutil.Process(process.pid).children(recursive=True)]
    os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=30)
    psutil.wait_procs([psutil.Process(p) for p in family if psutil.pid_exists(p)], timeout=30)


def test_a_sweep_killed_with_sigkill_resumes_with_only_the_missing_points(fmu_a, tmp_path, subprocess_env):
    store = tmp_path / "store"
    command = [sys.executable, "-m", "harness", "sweep", "--fmu", str(fmu_a), *RESUME_ARGS, "--store", str(store)]
    process = subprocess.Popen(command + ["--workers", "1"], env=subprocess_env, start_new_session=True,
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        deadline = time.monotonic() + 120
        while len(list((store / "points").glob("*.json"))) < 3:
            assert process.poll() is None, "the sweep ended before it could be killed"
            assert time.monotonic() < deadline, "no points were stored in time"
            time.sleep(0.05)
    finally:
        kill_group(process)
    before = snapshot(store)
    assert 3 <= len(before) < 8, f"{len(before)} points stored when killed"
    for name, (_, content) in before.items():  # every stored point is whole
        assert json.loads(content)["key"] == Path(name).stem

    resumed = subprocess.run(command + ["--workers", "2"], env=subprocess_env, capture_output=True, text=True,
                             timeout=180)
    assert resumed.returncode == 0, resumed.stderr[-2000:]
    summary = json.loads(resumed.stdout.strip().splitlines()[-1])
    assert summary["computed"] == 8 - len(before) and summary["reused"] == len(before)
    after = snapshot(store)
    assert len(after) == 8
    assert {name: after[name] for name in before} == before  # stored points were not rewritten

    base = cli_point(RESUME_ARGS, fmu_a)
    grid = Grid.parse(["A=0,0.5,1,1.5", "omega=0.5,0.7"])
    from_store = run_sweep(grid, base, store, INLINE_QUIET)
    assert from_store.computed == 0
    uninterrupted = run_sweep(grid, base, tmp_path / "uninterrupted", INLINE_QUIET)
    assert uninterrupted.computed == 8
    xr.testing.assert_identical(from_store.dataset, uninterrupted.dataset)


def rewrite_with_extra_member(fmu: Path) -> None:
    """Same model, other bytes: what a rebuild produces."""
    with zipfile.ZipFile(fmu, "a") as archive:
        archive.writestr("documentation/rebuild.txt", "rebuilt\n")


def test_a_changed_fmu_or_setting_is_never_mixed_with_stored_points(fmu_a, tmp_path):
    fmu = tmp_path / "fmu" / "BlockA.fmu"
    fmu.parent.mkdir()
    shutil.copy(fmu_a, fmu)
    grid = Grid.parse(["A=0,0.5"])
    base = PointSettings(RunSettings.for_model("A", fmu=str(fmu), horizon=300.0), ObservableSettings(transient=50.0))
    store = tmp_path / "store"

    first = run_sweep(grid, base, store, INLINE_QUIET)
    assert (first.computed, first.reused) == (2, 0)
    assert (run_sweep(grid, base, store, INLINE_QUIET).computed) == 0

    rewrite_with_extra_member(fmu)  # same path, new sha256
    second = run_sweep(grid, base, store, INLINE_QUIET)
    assert (second.computed, second.reused) == (2, 0)
    assert second.dataset.attrs["fmu_sha256"] != first.dataset.attrs["fmu_sha256"]
    assert len(PointStore(store).keys()) == 4
    shas = {json.loads(p.read_text())["inputs"]["fmu_sha256"] for p in (store / "points").glob("*.json")}
    assert shas == {first.dataset.attrs["fmu_sha256"], second.dataset.attrs["fmu_sha256"]}

    finer = dataclasses.replace(base.run, integration=Integration(dt=2e-4))
    third = run_sweep(grid, PointSettings(finer, base.observe), store, INLINE_QUIET)
    assert third.computed == 2
    other_window = run_sweep(grid, PointSettings(base.run, ObservableSettings(transient=100.0)), store, INLINE_QUIET)
    assert other_window.computed == 2
    assert len(list((store / "sweeps").glob("*.json"))) == 4  # each sweep's inputs are kept


def test_a_point_file_for_other_inputs_is_refused(fmu_a, tmp_path):
    grid = Grid.parse(["A=0"])
    base = PointSettings(RunSettings.for_model("A", fmu=str(fmu_a), horizon=100.0), ObservableSettings(transient=10.0))
    store = tmp_path / "store"
    run_sweep(grid, base, store, INLINE_QUIET)
    (path,) = (store / "points").glob("*.json")
    record = json.loads(path.read_text())
    record["inputs"]["fmu_sha256"] = "0" * 64
    path.write_text(json.dumps(record))
    with pytest.raises(StoreMismatch, match="other inputs"):
        run_sweep(grid, base, store, INLINE_QUIET)


def test_a_folder_that_is_not_a_store_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(StoreMismatch, match="not a point store"):
        PointStore(tmp_path)


def test_studies_side_by_side_open_one_new_store_at_once(tmp_path):
    """Threads that open the same new store together (the main job's studies) all get it:
    none mistakes the folders another is creating for a foreign folder."""
    from concurrent.futures import ThreadPoolExecutor

    for attempt in range(40):
        root = tmp_path / f"store{attempt}"
        with ThreadPoolExecutor(8) as pool:
            stores = list(pool.map(lambda _: PointStore(root), range(8)))
        assert all(s.points.is_dir() for s in stores)
        assert json.loads((root / "store.json").read_text())["format"] == "vibroblock-point-store"


def test_a_damaged_point_file_is_moved_aside_and_recomputed(tmp_path):
    from harness.runs.store import PointStore, point_key

    store = PointStore(tmp_path / "store")
    inputs = {"A": 1.0, "omega": 0.5}
    key = point_key(inputs)
    store.save(key, inputs, {"phi": 0.25}, 0.1)
    assert store.load(key, inputs) == {"phi": 0.25}
    store.path(key).write_text('{"key": "' + key + '", "inputs": {"A": 1.0')  # truncated mid-write
    with pytest.warns(RuntimeWarning, match="damaged"):
        assert store.load(key, inputs) is None
    assert not store.path(key).exists()
    assert len(list((store.points / "damaged").iterdir())) == 1
    store.save(key, inputs, {"phi": 0.5}, 0.1)  # computed again
    assert store.load(key, inputs) == {"phi": 0.5}
