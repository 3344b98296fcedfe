"""Compiled kernels: every integrator's compiled once per build, each Block FMU ships its default's.

The kernels take the run's variant, readings and laws (``kind``) as a plain integer and
only the integrator (``method``) as a compile-time constant, so one compilation per
integrator serves every model, reading, law, scene flag, energy option and initial
state.  What is compiled when:

* ``make fmus`` compiles every integrator's kernels once (``KERNEL_JOBS``: the advance
  and observe entry points of each integrator record, with their C entries of
  ``vibroblock.native``), one job per integrator in child processes, one per core, each
  job with an empty numba cache of its own.  The caches are kept in
  ``build/work/kernels-<key>/<job>/`` with a key of everything they depend on (core
  sources, Python, numba, llvmlite, CPU), so rebuilding an FMU reuses them and builds
  stay byte-reproducible.  A test session seeds its cache from all of them
  (``tests/conftest.py``), so the tests do not compile them again.
* A Block FMU ships only the kernels its default configuration runs (``shipped_jobs``,
  derived from the core's settings: the default integrator, the kernels it hands a run
  over to, e.g. ``adaptive`` on model A to ``event_driven``'s exact flows, and the
  integrator's own kernels), and those too dear to compile at a first use
  (``SHIPPED_ALWAYS``), packed as ``resources/vibroblock_kernels/`` (entry points only,
  ``entry_files``).  At run time
  the core copies them into the host's numba cache where it has none yet
  (``vibroblock/jitcache.py``), and numba uses them if they match the host: the same
  numba and Python versions and the same CPU (name and features).
* Any other configuration (another integrator, or a scene reduction) compiles its
  integrator's kernels at first use into the host's cache, once per core version; every
  model, reading and law of that integrator then runs from it.
"""
from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
WORK_DIR = HERE / "work"
ARCHIVE_FOLDER = "resources/vibroblock_kernels"
# Children compiling kernels side by side (one per core, as numba compiles on one).
MAX_CHILDREN = 8
# Integrators whose kernels every Block FMU ships although no default runs them: compiling
# them at a first use would take longer than a first use may (30 s): adaptive's took 186 s
# of CPU on the 2-core machine, the others 18-36 s (build_cost, section 1).  And the
# paper's scheme, which the harness's sweeps run where adaptive's cost grows with the
# plate's frequency: without it every fresh worker of a sweep compiled it at its first
# point (~30 s each, the workers side by side).
SHIPPED_ALWAYS = ("adaptive", "symplectic_euler")
# The job of the chain's kernel (vibroblock/chain/kernel.py), which the BlockChain FMU ships.
CHAIN_JOB = "chain"
# Relative compile costs measured on one core (harness/benchmarks/build_cost.py), so the
# most expensive jobs start first and the children finish together.
COST = {"adaptive": 10, "event_driven": 4, "implicit_contact": 3}

# Child process, run with the core's parent folder on sys.path and an empty NUMBA_CACHE_DIR
# of its own: the kernels of one integrator record (``vibroblock.integrators.BY_ID``),
# through the calls an FMU makes (start, inputs, advance, outputs, state, the C entries),
# in the first configuration the core accepts for it.  Prints the configuration as JSON.
WARM_UP = r"""
import itertools, json, sys
CHAIN_JOB = "chain"
from vibroblock import Block, INTEGRATORS, ModelError
from vibroblock.integrators import BY_ID
from vibroblock.models import VARIANTS
from vibroblock.native import NativeStep
from vibroblock.parameters import INTEGRATOR_OPTIONS, SCENE_OPTIONS

job = sys.argv[1]
if job == CHAIN_JOB:  # the chain's kernel, with and without the energy balance, and a jump's probe
    from vibroblock.chain import Chain
    for energy_balance in (False, True):
        chain = Chain(2, energy_balance=energy_balance, A=0.3, omega=0.5)
        chain.start(0.0)
        chain.advance_to(1.0)
        chain.outputs()
    chain = Chain(2, jump_sticks=True)
    chain.start(0.0)
    chain.advance_to(30.0)
    print(json.dumps({"job": job}))
    sys.exit(0)
options = [{}] + [{name: True} for name in SCENE_OPTIONS] + [
    {name: not default} for name, (_, default, _) in INTEGRATOR_OPTIONS.items()]
for model, integrator, option in itertools.product(VARIANTS, INTEGRATORS, options):
    try:
        block = Block(model, integrator, 0, True, A=0.3, omega=0.5, **option)
        if BY_ID[block.settings.kernel().id].name != job:
            continue
        block.drive_natively(NativeStep(), 1e-9)  # as the FMU's slave: its C entries too
        block.start(0.0)
    except ModelError:
        continue
    block.advance_to(1.0)
    block.set_plate_input(0.01, 0.0, 0.0)
    block.advance_to(2.0)
    block.outputs()
    block.set_state(block.get_state())
    print(json.dumps({"job": job, "model": model, "integrator": integrator, "options": option}))
    break
else:
    sys.exit(f"no configuration runs the kernels of {job}")
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


def kernel_jobs() -> list[str]:
    """One job per compiled kernel pair: the names of the integrator records by id
    (``adaptive`` handing model A over runs ``event_driven``'s, the same id)."""
    from vibroblock.integrators import BY_ID
    names = {record.name for record in BY_ID.values()} | {CHAIN_JOB}
    return sorted(names, key=lambda name: (-COST.get(name, 1), name))


def shipped_jobs(model: str) -> list[str]:
    """The jobs whose kernels the Block FMU of ``model`` ships: for its default integrator
    and each of ``SHIPPED_ALWAYS`` the model offers, the kernels it runs in the default
    configuration (where it hands the run over, e.g. adaptive on model A to
    event_driven's exact flows, those) and its own."""
    from vibroblock import Block
    from vibroblock.integrators import BY_ID, INTEGRATORS, integrator
    from vibroblock.parameters import DEFAULT_INTEGRATOR  # the FMU's where the master does not choose

    names = {DEFAULT_INTEGRATOR} | {
        name for name in SHIPPED_ALWAYS if name in INTEGRATORS and integrator(name).supports(model)}
    ids = set()
    for name in names:
        ids |= {Block(model, name).settings.kernel().id, integrator(name).id}
    return sorted(BY_ID[i].name for i in ids)


def entry_files(job_cache: Path) -> list[Path]:
    """The cache files of a job's entry points only: its advance and observe kernels and
    their C entries, each a self-contained library.  The helpers they call and inline were
    cached on their own as well, but loading an entry point does not read them."""
    from vibroblock.integrators import BY_ID

    if job_cache.name == CHAIN_JOB:
        return [path for path in sorted(job_cache.rglob("*.nb?"))
                if path.name.startswith(("kernel.advance-", "kernel.rest_probe-"))]
    record = next(record for record in BY_ID.values() if record.name == job_cache.name)
    # numba names a cache file "<source file's stem>.<qualname>-<line>..." ("__init__" for
    # a kernel defined in a package's __init__.py, e.g. event_driven's).
    prefixes = tuple(f"{Path(kernel.py_func.__code__.co_filename).stem}.{kernel.py_func.__qualname__}-"
                     for kernel in (record.advance, record.observe)) + ("native.",)
    return [path for path in sorted(job_cache.rglob("*.nb?")) if path.name.startswith(prefixes)]


def kept_kernels(core: Path) -> Path | None:
    """The folder of kernels compiled for the core at ``core`` by an earlier build, if any:
    one subfolder (a numba cache) per job."""
    folder = WORK_DIR / f"kernels-{_key(core)}"
    return folder if folder.is_dir() else None


def _compile_job(job: str, core: Path, scratch: Path) -> dict:
    cache = scratch / job
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(core.parent))
    env.pop("NUMBA_DISABLE_JIT", None)
    child = subprocess.run([sys.executable, "-c", WARM_UP, job], env=env, cwd=scratch, capture_output=True,
                           text=True, timeout=3600)
    if child.returncode != 0:
        raise RuntimeError(f"compiling the kernels of {job} failed:\n{child.stdout}\n{child.stderr[-4000:]}")
    return json.loads(child.stdout.strip().splitlines()[-1])


def compile_kernels(core: Path) -> Path:
    """The folder of compiled kernels for the core at ``core`` (compiled if not kept yet)."""
    target = WORK_DIR / f"kernels-{_key(core)}"
    if target.is_dir():
        return target
    WORK_DIR.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(dir=WORK_DIR, prefix=".kernels-"))
    try:
        jobs = kernel_jobs()
        children = max(1, min(os.cpu_count() or 1, MAX_CHILDREN, len(jobs)))
        with ThreadPoolExecutor(children) as pool:  # each thread waits on one child process
            configurations = list(pool.map(lambda job: _compile_job(job, core, scratch), jobs))
        (scratch / "jobs.json").write_text(json.dumps(configurations, indent=1) + "\n")
        try:
            os.replace(scratch, target)
        except OSError:  # another build (e.g. a second test worker) kept the same kernels first
            if not target.is_dir():
                raise
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    for stale in WORK_DIR.glob("kernels-*"):
        if stale != target:
            shutil.rmtree(stale, ignore_errors=True)
    return target


def job_caches(core: Path) -> list[Path]:
    """The numba cache folders of every job, compiled if not kept yet."""
    folder = compile_kernels(core)
    return [folder / job for job in kernel_jobs()]


def archive_members(core: Path, model: str) -> dict[str, bytes]:
    """The FMU members ``resources/vibroblock_kernels/...`` of the Block FMU of ``model``:
    the kernels of ``shipped_jobs`` for the core at ``core``; ``model`` "Chain": the
    BlockChain FMU's, the chain's kernel."""
    folder = compile_kernels(core)
    caches = {}  # cache index (relative path) -> [(its job's folder, the index file)]
    for job in [CHAIN_JOB] if model == "Chain" else shipped_jobs(model):
        for path in entry_files(folder / job):
            if path.suffix == ".nbi":
                caches.setdefault(path.relative_to(folder / job).as_posix(), []).append((folder / job, path))
    members = {}
    for name, sources in caches.items():
        members.update({f"{ARCHIVE_FOLDER}/{member}": data for member, data in merged_cache(name, sources).items()})
    return members


def merged_cache(name: str, sources: list[tuple[Path, Path]]) -> dict[str, bytes]:
    """One numba cache index ``name`` and its data files, from the same index compiled in
    several jobs (``sources``: (job folder, index file)): the C entries of every
    integrator live in one source file, so two shipped jobs each have an index of that
    name with their own entry.  The entries are renumbered into one index as numba writes
    it (its version, then the source stamp and {key: data file}), so no job's entry is
    lost; a key found in two jobs is the same kernel, kept once."""
    import pickle

    from numba.core.serialize import dumps  # what numba writes an index with

    base = name[:-len(".nbi")]
    if len(sources) == 1:  # as numba wrote it
        job_folder, index = sources[0]
        return {path.relative_to(job_folder).as_posix(): path.read_bytes()
                for path in sorted(index.parent.glob(f"{index.name[:-len('.nbi')]}.*"))}
    version = stamp = None
    overloads, members = {}, {}
    for _, index in sources:
        with open(index, "rb") as stream:
            job_version = pickle.load(stream)
            job_stamp, job_overloads = pickle.loads(stream.read())
        if version is None:
            version, stamp = job_version, job_stamp
        elif (job_version, job_stamp) != (version, stamp):
            raise RuntimeError(f"{name}: the jobs' caches come from different sources or numba versions")
        for key, data_name in job_overloads.items():
            if key in overloads:
                continue
            overloads[key] = f"{Path(base).name}.{len(overloads) + 1}.nbc"
            members[f"{base}.{len(overloads)}.nbc"] = (index.parent / data_name).read_bytes()
    members[name] = pickle.dumps(version, protocol=-1) + dumps((stamp, overloads))
    return members
