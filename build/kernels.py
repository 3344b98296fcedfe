"""Compiled kernels shipped inside the Block FMUs, so that a first doStep does not compile.

Without them, the first ``doStep`` of a freshly installed FMU compiles the numba
kernels of the physics core (about 25 s on a 2-core machine, ~45 s more for the
adaptive integrator in a non-default reading).  At build time child processes, one per
core, run every model, integrator, reading and scene option of the core once with an
empty numba cache; the cache they leave (index and data files, filed by the core's
content-addressed locator, ``vibroblock/jitcache.py``) is packed into the FMU as
``resources/vibroblock_kernels/``.  At run time the core copies these files into the
host's numba cache where it has none yet, and numba uses them if they match the
host: the same numba and Python versions and the same CPU (name and features).
Otherwise it compiles as before and keeps its own copy.  A test session seeds its
cache from the same folder (``tests/conftest.py``), so the tests, which run the same
core, do not compile them again.

The compiled set is kept in ``build/work/kernels-<key>`` with a key of everything it
depends on (core sources, Python, numba, llvmlite, CPU), so rebuilding an FMU reuses
it and builds stay byte-reproducible.
"""
from __future__ import annotations

import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
WORK_DIR = HERE / "work"
ARCHIVE_FOLDER = "resources/vibroblock_kernels"
# Children compiling kernels side by side (one per core, as numba compiles on one).
MAX_CHILDREN = 8

# Runs in child processes with the core's parent folder on sys.path and one shared,
# initially empty NUMBA_CACHE_DIR.  Every configuration a master can choose goes
# through the same calls an FMU makes (start, inputs, advance, outputs, state): every
# model, integrator and scene option in the default reading, every model and
# integrator in each other reading of the paper (vibroblock.readings: each is a
# kernel of its own), and each integrator option that changes what runs
# (parameters.INTEGRATOR_OPTIONS: exact_flows off runs adaptive's own steps on model A).
# A configuration the core refuses is skipped.  The work is cut
# into jobs that compile disjoint kernels (one model, reading and integrator each),
# dealt out to `shares` children by their expected cost; child `share` runs its part.
WARM_UP = r"""
import itertools, sys
import vibroblock
from vibroblock import Block, INTEGRATORS, ModelError
from vibroblock.native import NativeStep
from vibroblock.models import VARIANTS, offered_by
from vibroblock.parameters import INTEGRATOR_OPTIONS, SCENE_OPTIONS
from vibroblock.readings import choices
READINGS = choices()

share, shares = map(int, sys.argv[1:3])
# Relative compile costs (adaptive kernels, RODAS4 and DOP853, take ~45 s of CPU each, a
# fixed-step scheme a few seconds), so that the children finish together.
COST = {"adaptive": 10, "event_driven": 6, "implicit_contact": 3}

jobs = []
for model in VARIANTS:
    names = [name for name, (models, _) in READINGS.items() if model in offered_by(models)]
    for values in itertools.product((0, 1), repeat=len(names)):
        reading = dict(zip(names, values))
        for integrator in INTEGRATORS:
            if any(values):
                configs = [(reading, False, 0)]
            else:
                scenes = [{}] + [{name: True} for name, (models, _) in SCENE_OPTIONS.items()
                                 if model in offered_by(models)]
                configs = [(scene, energy, initial) for energy, scene, initial
                           in itertools.product((False, True), scenes, (0, 2))]
            cost = COST.get(integrator, 2) * (1 if any(values) else 3)
            jobs.append((cost, model, integrator, configs))
            # An option that changes what runs (adaptive's exact_flows on model A: its own
            # steps instead of event_driven's flows) has kernels of its own.
            for name, (models, default, _) in INTEGRATOR_OPTIONS.items():
                if model not in offered_by(models):
                    continue
                try:
                    as_default = Block(model, integrator, **reading).settings.kernel()
                    changed = Block(model, integrator, **reading, **{name: not default}).settings.kernel()
                except ModelError:
                    continue
                if changed is not as_default:  # (a scene reduction runs its own scheme either way)
                    jobs.append((cost, model, integrator,
                                 [({**options, name: not default}, energy, initial) for options, energy, initial
                                  in configs if not set(options) & set(SCENE_OPTIONS)]))

load = [0] * shares
mine = []
for cost, model, integrator, configs in sorted(jobs, key=lambda job: -job[0]):
    child = load.index(min(load))
    load[child] += cost
    if child == share:
        mine.append((model, integrator, configs))

done = refused = 0
for model, integrator, configs in mine:
    for options, energy, initial in configs:
        try:
            block = Block(model, integrator, initial, energy, A=0.3, omega=0.5, **options)
            block.drive_natively(NativeStep(), 1e-9)  # as the FMU's slave: its C entry too
            block.start(0.0)
            block.advance_to(1.0)
            block.set_plate_input(0.01, 0.0, 0.0)
            block.advance_to(2.0)
            block.outputs()
            block.set_state(block.get_state())
            done += 1
        except ModelError:
            refused += 1
print(f"share {share}/{shares}: warmed up {done} configurations ({refused} refused)")
if done == 0 and mine:
    sys.exit("no configuration could be run")
"""


def _key(core: Path) -> str:
    import llvmlite
    import llvmlite.binding as llvm
    import numba

    digest = hashlib.sha256()
    for path in sorted(core.rglob("*.py")):
        digest.update(path.relative_to(core).as_posix().encode())
        digest.update(path.read_bytes())
    digest.update(WARM_UP.encode())
    host = llvm.get_host_cpu_features().flatten() if hasattr(llvm, "get_host_cpu_features") else ""
    for part in (sys.version, numba.__version__, llvmlite.__version__, platform.machine(),
                 llvm.get_host_cpu_name(), host):
        digest.update(str(part).encode())
    return digest.hexdigest()[:16]


def kept_kernels(core: Path) -> Path | None:
    """The folder of kernels compiled for the core at ``core`` by an earlier build, if any."""
    folder = WORK_DIR / f"kernels-{_key(core)}"
    return folder if folder.is_dir() else None


def compile_kernels(core: Path) -> Path:
    """The folder of compiled kernels for the core at ``core`` (compiled if not kept yet)."""
    target = WORK_DIR / f"kernels-{_key(core)}"
    if target.is_dir():
        return target
    WORK_DIR.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(dir=WORK_DIR, prefix=".kernels-"))
    try:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(scratch / "cache"), PYTHONPATH=str(core.parent))
        env.pop("NUMBA_DISABLE_JIT", None)
        shares = max(1, min(os.cpu_count() or 1, MAX_CHILDREN))
        children = [subprocess.Popen([sys.executable, "-c", WARM_UP, str(share), str(shares)], env=env,
                                     cwd=scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                    for share in range(shares)]
        failures = []
        for child in children:
            try:
                out, err = child.communicate(timeout=3600)
            except subprocess.TimeoutExpired:
                child.kill()
                out, err = child.communicate()
            if child.returncode != 0:
                failures.append(f"{out}\n{err[-4000:]}")
        if failures:
            raise RuntimeError("compiling the kernels failed:\n" + "\n".join(failures))
        os.replace(scratch / "cache", target)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    for stale in WORK_DIR.glob("kernels-*"):
        if stale != target:
            shutil.rmtree(stale, ignore_errors=True)
    return target


def archive_members(core: Path) -> dict[str, bytes]:
    """The FMU members ``resources/vibroblock_kernels/...`` for the core at ``core``."""
    folder = compile_kernels(core)
    return {f"{ARCHIVE_FOLDER}/{path.relative_to(folder).as_posix()}": path.read_bytes()
            for path in sorted(folder.rglob("*")) if path.is_file() and path.suffix in (".nbi", ".nbc")}
