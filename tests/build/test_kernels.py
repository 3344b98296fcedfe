"""build/kernels.py: every integrator compiled once; each Block FMU ships its default's kernels only."""
import io
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import build_fmus
import kernels
import pytest

MAX_FMU_BYTES = 5_000_000  # issue 33: each Block FMU <= 5 MB

# A fresh process: the FMU instantiated through fmpy in its default configuration, one doStep.
FIRST_STEP = r"""
import os, sys
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
fmu, unzipdir = sys.argv[1:3]
md = read_model_description(fmu)
slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="first")
slave.instantiate()
slave.setupExperiment(startTime=0.0)
slave.enterInitializationMode()
slave.exitInitializationMode()
slave.doStep(0.0, 0.5)
x = {v.name: v.valueReference for v in md.modelVariables}["x"]
print("x =", slave.getReal([x])[0], flush=True)
os._exit(0)
"""


def _models():
    sys.path.insert(0, str(build_fmus.SOURCES))
    from vibroblock.models import VARIANTS
    return list(VARIANTS)


def test_one_job_per_compiled_kernel_pair():
    from vibroblock.integrators import BY_ID

    jobs = kernels.kernel_jobs()
    assert len(jobs) == len(set(jobs))
    assert {record.name for record in BY_ID.values()} | {kernels.CHAIN_JOB} == set(jobs)
    assert jobs[0] == "adaptive"  # the dearest first, so that the children finish together


@pytest.mark.parametrize("model", _models())
def test_an_fmu_ships_the_kernels_its_default_runs(model):
    """What runs (adaptive on model A: event_driven's exact flows) and the chosen integrator's
    own kernels (what it runs where it cannot hand over), and not every integrator's."""
    from vibroblock import Block
    from vibroblock.integrators import BY_ID, integrator
    from vibroblock.parameters import DEFAULT_INTEGRATOR

    settings = Block(model, DEFAULT_INTEGRATOR).settings  # as the FMU's slave makes it
    shipped = kernels.shipped_jobs(model)
    assert BY_ID[settings.kernel().id].name in shipped
    assert BY_ID[integrator(settings.integrator).id].name in shipped
    for name in kernels.SHIPPED_ALWAYS:  # too dear to compile at a first use, and what it hands over to
        assert BY_ID[Block(model, name).settings.kernel().id].name in shipped
        assert name in shipped
    assert len(shipped) < len(kernels.kernel_jobs())


def _shipped(fmu: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(fmu) as archive:
        return {name[len(kernels.ARCHIVE_FOLDER) + 1:]: archive.read(name) for name in archive.namelist()
                if name.startswith(kernels.ARCHIVE_FOLDER + "/")}


@pytest.mark.parametrize("model", _models())
def test_a_block_fmu_is_small_and_ships_only_its_defaults(fmu_path, model):
    fmu = Path(fmu_path(model))
    assert fmu.stat().st_size <= MAX_FMU_BYTES
    shipped = _shipped(fmu)
    folder = kernels.kept_kernels(build_fmus.CORE)
    jobs = kernels.shipped_jobs(model)
    expected = {path.relative_to(folder / job).as_posix() for job in jobs
                for path in kernels.entry_files(folder / job) if path.suffix == ".nbi"}
    assert shipped and {name for name in shipped if name.endswith(".nbi")} == expected
    for index in expected:
        # Every shipped job's entries of this index are in the FMU's one index (the jobs'
        # C entries share a source file), each with its data file and nothing else.
        keys = set()
        for job in jobs:
            if (folder / job / index).is_file():
                keys |= set(_overloads((folder / job / index).read_bytes()))
        overloads = _overloads(shipped[index])
        assert set(overloads) == keys
        data = {name for name in shipped if name.startswith(index[:-len("nbi")]) and name.endswith(".nbc")}
        assert data == {f"{Path(index).parent.as_posix()}/{name}" for name in overloads.values()}
    assert all(name.endswith(".nbi") or name[:name.rindex(".", 0, -4)] + ".nbi" in expected for name in shipped)
    compiled = {path.relative_to(folder / job).as_posix() for job in kernels.kernel_jobs()
                for path in (folder / job).rglob("*.nbi")}
    assert compiled - expected, "every kernel shipped: the defaults are not told apart"


def _overloads(index: bytes) -> dict:
    """{key: data file} of a numba cache index (its version, then the source stamp and the overloads)."""
    import pickle

    stream = io.BytesIO(index)
    pickle.load(stream)
    return pickle.loads(stream.read())[1]


@pytest.mark.parametrize("model", _models())
@pytest.mark.parametrize("core_imported_first", [False, True], ids=["fresh process", "core imported first"])
def test_a_first_do_step_with_an_empty_cache_compiles_nothing(fmu_path, tmp_path, model, core_imported_first):
    """A fresh process with an empty numba cache runs the default configuration from the
    FMU's shipped kernels: afterwards the cache holds exactly those files, byte for byte
    (a kernel numba had to compile would have added or rewritten one).  The same holds in
    a process that imported the same core from elsewhere first, as the harness's workers
    do: the FMU seeds the cache from its own shipped kernels."""
    from fmpy import extract

    fmu = fmu_path(model)
    unzipdir = extract(fmu, unzipdir=str(tmp_path / "fmu"))
    cache = tmp_path / "numba"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    env.pop("NUMBA_DISABLE_JIT", None)
    script = ("import vibroblock\n" if core_imported_first else "") + FIRST_STEP
    run = subprocess.run([sys.executable, "-c", script, fmu, unzipdir], env=env, capture_output=True,
                         text=True, timeout=600)
    assert "x = " in run.stdout, run.stderr[-3000:]
    cached = {path.relative_to(cache).as_posix(): path.read_bytes() for path in cache.rglob("*.nb?")}
    assert cached == _shipped(Path(fmu))
