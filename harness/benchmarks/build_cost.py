"""Benchmark: what a fresh build and a first doStep cost, and the step speed against a release.

    python -m harness.benchmarks.build_cost [--fmu-dir build/fmus] [--previous e856204] [--quick]

Prints, in one run:

1. the compile time of each integrator's kernels (``build/kernels.py``'s jobs: the advance
   and observe entry points and their C entries of ``vibroblock.native``), each in a fresh
   process with an empty numba cache, one after the other (wall and CPU seconds), and
   the size of the cache each leaves;
2. the size of each FMU, and which kernels each Block FMU ships;
3. the first doStep of each Block FMU's default configuration through fmpy in a fresh
   process: cold (empty numba cache: the FMU's shipped kernels are all it has) and warm
   (the cache the cold run left); the time from instantiate to the end of the first
   doStep, split into instantiate (the core's imports: numba, scipy, the core), initialize
   (the run's kernels loaded, or compiled) and the doStep itself; and numba's own floor
   (its import, and a trivial cached kernel's first call, which sets up its target context);
4. the cold first doStep of configurations that are not a default: each other integrator
   of BlockA (and adaptive's own steps on B), and a non-default reading and law on B,
   each in a fresh process with an empty cache (what it compiles is kept in that cache);
5. the step speed of each integrator against the previous release (``--previous``, a git
   worktree made in build/work/), both cores' kernels compiled and loaded before the
   timing, the two sides measured in turns on the same scenarios, best of the rounds,
   and the ratio (this build / previous; below 0.9 is a loss beyond the target).  The
   times are CPU seconds of the run (one thread): on a machine shared with other work a
   process's wall time measures the scheduler (10x on a load of 13 on 2 cores).

The targets (issue 33, item 5) are printed beside the figures.  ``--quick`` measures the
FMUs only (sections 2 and 3) and publishes nothing.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from harness.benchmarks import recorded

ROOT = Path(__file__).resolve().parents[2]
CORE = ROOT / "fmu_src" / "vibroblock"
PREVIOUS = "e856204"  # the release before the kernels took kind as a run constant
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}  # the core_and_fmu benchmark's stick-slip set
VIBRATING = {"A": 0.3, "omega": 0.8, **SCALED}
DT = 4e-4
# (model, integrator, simulated time): every integrator on the flat and on the corrugated plate.
SPEED_SCENARIOS = [("A", "symplectic_euler", 800.0), ("B", "symplectic_euler", 800.0), ("A", "rk4", 400.0),
                   ("B", "rk4", 400.0), ("A", "implicit_contact", 400.0), ("B", "implicit_contact", 400.0),
                   ("A", "event_driven", 1e7), ("A", "adaptive", 1e7), ("B", "adaptive", 4000.0),
                   ("C", "adaptive", 5e4)]

# Child: the kernels of one integrator record (or the chain's one kernel, both of its
# schemes) compiled in this process's (empty) cache.
COMPILE = r"""
import json, os, sys, time
wall, cpu = time.perf_counter(), time.process_time()
import numpy as np
from vibroblock import layout as L
from vibroblock.integrators import BY_ID
from vibroblock.native import entry_address
times = {"import": [time.perf_counter() - wall, time.process_time() - cpu]}
if sys.argv[1] == "chain":
    from vibroblock.chain import Chain
    def advance_chain():
        chain = Chain(2, A=0.3, omega=0.5)
        chain.start(0.0)
        chain.advance_to(1.0)
    steps = (("advance", advance_chain), ("observe", lambda: None), ("C advance", lambda: None),
             ("C observe", lambda: None))
else:
    record = next(r for r in BY_ID.values() if r.name == sys.argv[1])
    arrays = (0, 0, np.zeros(L.N_Y), np.zeros(L.N_CNT, np.int64), np.zeros(L.N_DRV), np.zeros(L.N_PRM))
    steps = (("advance", lambda: record.bind_advance(*arrays)), ("observe", lambda: record.bind_observe(*arrays)),
             ("C advance", lambda: entry_address(record.advance, record.id)),
             ("C observe", lambda: entry_address(record.observe, record.id)))
for name, compile_ in steps:
    wall, cpu = time.perf_counter(), time.process_time()
    compile_()
    times[name] = [time.perf_counter() - wall, time.process_time() - cpu]
size = sum(p.stat().st_size for p in __import__("pathlib").Path(os.environ["NUMBA_CACHE_DIR"]).rglob("*.nb*"))
print(json.dumps({"times": times, "cache_bytes": size}))
"""

# Child: an FMU instantiated through fmpy, parameters set, initialized and stepped once.
FIRST_STEP = r"""
import json, os, sys, time
begin = time.perf_counter()
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
fmu, unzipdir, settings = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
md = read_model_description(fmu)
vr = {v.name: (v.valueReference, v.type) for v in md.modelVariables}
start = time.perf_counter()
slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="first")
slave.instantiate()
instantiated = time.perf_counter()
slave.setupExperiment(startTime=0.0)
for name, value in settings.items():
    ref, kind = vr[name]
    {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean}[kind]([ref], [value])
slave.enterInitializationMode()
slave.exitInitializationMode()
step = time.perf_counter()
slave.doStep(0.0, 0.5)
end = time.perf_counter()
x = slave.getReal([vr["x"][0]])[0]
print(json.dumps({"first_step": end - start, "instantiate": instantiated - start, "initialize": step - instantiated,
                  "do_step": end - step, "process": end - begin, "cpu": time.process_time(), "x": x}), flush=True)
os._exit(0)  # (the embedded interpreter's teardown is not what is measured)
"""

# Child: one core (this release's or the previous one) timing scenarios read from stdin.
SPEED = r"""
import json, sys, time
from vibroblock import Block
for line in sys.stdin:
    model, integrator, t_end, parameters = json.loads(line)
    block = Block(model, integrator, 2, False, **parameters)
    block.start()
    block.advance_to(%(dt)r)  # kernels compiled or loaded outside the timing
    start = time.process_time()
    block.advance_to(t_end)
    print(json.dumps([time.process_time() - start, block.outputs()["x"]]), flush=True)
""" % {"dt": DT}


def _child_env(cache: Path, core_parent: Path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(core_parent))
    env.pop("NUMBA_DISABLE_JIT", None)
    return env


def compile_costs(scratch: Path) -> None:
    sys.path.insert(0, str(ROOT / "build"))
    import kernels

    print("1. compile time of each integrator's kernels, fresh process, empty cache, one at a time "
          "(seconds wall / CPU)")
    print(f"   {'kernels':17} {'advance':>13} {'observe':>13} {'C advance':>13} {'C observe':>13} "
          f"{'total':>13} {'cache MB':>9}")
    total = [0.0, 0.0]
    for job in kernels.kernel_jobs():
        out = subprocess.run([sys.executable, "-c", COMPILE, job], env=_child_env(scratch / f"compile-{job}",
                             CORE.parent), capture_output=True, text=True, check=True)
        result = json.loads(out.stdout.strip().splitlines()[-1])
        times = result["times"]
        parts = [times[name] for name in ("advance", "observe", "C advance", "C observe")]
        job_total = [sum(p[0] for p in parts), sum(p[1] for p in parts)]
        total = [total[0] + job_total[0], total[1] + job_total[1]]
        cells = " ".join(f"{w:6.1f} /{c:5.1f}" for w, c in [*parts, job_total])
        print(f"   {job:17} {cells} {result['cache_bytes'] / 1e6:9.2f}")
    print(f"   all kernels: {total[0]:.0f} s wall, {total[1]:.0f} s CPU on one core (make fmus runs them "
          f"in {os.cpu_count()} children); the largest alone is a non-default's first use (target <= 30 s)")


def fmu_sizes(fmu_dir: Path) -> None:
    sys.path.insert(0, str(ROOT / "build"))
    import kernels

    print("\n2. FMU sizes (target: each Block FMU <= 5 MB)")
    for fmu in sorted(fmu_dir.glob("*.fmu")):
        shipped = ", ".join(kernels.shipped_jobs(fmu.stem[len("Block"):])) if fmu in block_fmus(fmu_dir) else (
            kernels.CHAIN_JOB if fmu.stem in ("BlockChain", "BlockChain3") else "-")
        print(f"   {fmu.name:16} {fmu.stat().st_size / 1e6:6.2f} MB   kernels shipped: {shipped}")


def block_fmus(fmu_dir: Path) -> list[Path]:
    """The single-block FMUs, one per model variant (not BlockChain)."""
    sys.path.insert(0, str(CORE.parent))
    from vibroblock.models import VARIANTS

    return [fmu_dir / f"Block{model}.fmu" for model in VARIANTS if (fmu_dir / f"Block{model}.fmu").is_file()]


def first_step(fmu: Path, cache: Path, settings: dict, scratch: Path) -> dict:
    unzipdir = Path(tempfile.mkdtemp(dir=scratch, prefix=f"{fmu.stem}-"))
    from fmpy import extract
    extract(str(fmu), unzipdir=str(unzipdir))
    began = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", FIRST_STEP, str(fmu), str(unzipdir), json.dumps(settings)],
                         env=_child_env(cache, ROOT), capture_output=True, text=True)
    lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
    if not lines:
        raise RuntimeError(f"first doStep of {fmu.name} {settings} failed:\n{out.stdout}\n{out.stderr[-3000:]}")
    result = json.loads(lines[-1])
    result["wall"] = time.perf_counter() - began
    return result


def _row(label: str, result: dict) -> str:
    return (f"   {label:44} {result['first_step']:6.2f} s = instantiate {result['instantiate']:5.2f} + initialize "
            f"{result['initialize']:5.2f} + doStep {result['do_step']:5.3f}  (process {result['wall']:.1f} s wall, "
            f"{result['cpu']:.1f} s CPU)")


# Child: numba's own floor for a first call, a trivial cached kernel (import, then the first
# call: numba's target context is set up by the first kernel a process loads or compiles).
FLOOR = r"""
import json, time
begin = time.perf_counter()
from numba import njit
imported = time.perf_counter()
@njit(cache=True)
def one(x):
    return x + 1
one(1)
print(json.dumps([imported - begin, time.perf_counter() - imported]))
"""


def first_steps(fmu_dir: Path, scratch: Path) -> None:
    print("\n3. first doStep of each Block FMU's default configuration through fmpy, fresh process, from "
          "instantiate to the end of the first doStep (target cold <= 1 s)")
    floor_dir = scratch / "floor"
    floor_dir.mkdir()
    (floor_dir / "floor.py").write_text(FLOOR)  # (numba caches kernels of files only)
    for label in ("compiled", "cached"):
        out = subprocess.run([sys.executable, "floor.py"], env=_child_env(scratch / "cache-floor", floor_dir),
                             cwd=floor_dir, capture_output=True, text=True, check=True)
        imported, called = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"   numba's floor: import {imported:.2f} s, first call of a trivial kernel ({label}) {called:.2f} s")
    for fmu in block_fmus(fmu_dir):
        cache = scratch / f"cache-{fmu.stem}"
        print(_row(f"{fmu.stem} default, cold (empty cache)", first_step(fmu, cache, {}, scratch)))
        print(_row(f"{fmu.stem} default, warm (the cold run's cache)", first_step(fmu, cache, {}, scratch)))


def non_defaults(fmu_dir: Path, scratch: Path) -> None:
    sys.path.insert(0, str(CORE.parent))
    from vibroblock import INTEGRATORS
    from vibroblock.parameters import DEFAULT_INTEGRATOR

    print("\n4. cold first doStep of configurations that are not a default (fresh process, empty cache; "
          "target <= 30 s, then cached)")
    cases = [("A", {"integrator": INTEGRATORS[name]}) for name in INTEGRATORS if name != DEFAULT_INTEGRATOR]
    if DEFAULT_INTEGRATOR != "adaptive":
        cases.append(("B", {"integrator": INTEGRATORS["adaptive"]}))
    cases += [("B", {"formulation": 1}), ("B", {"contact_law": 1, "coulomb_normal": 1})]
    for model, settings in cases:
        fmu = fmu_dir / f"Block{model}.fmu"
        label = f"Block{model} " + ", ".join(f"{name} = {value}" for name, value in settings.items())
        cache = scratch / f"cache-{model}-{len(os.listdir(scratch))}"
        print(_row(label + ", cold", first_step(fmu, cache, settings, scratch)))
        print(_row(label + ", then", first_step(fmu, cache, settings, scratch)))


def previous_core(commit: str) -> Path:
    """The previous release's core, as a git worktree in build/work/ (made once)."""
    tree = ROOT / "build" / "work" / f"release-{commit}"
    if not (tree / "fmu_src" / "vibroblock").is_dir():
        subprocess.run(["git", "worktree", "prune"], cwd=ROOT, check=True)
        subprocess.run(["git", "worktree", "add", "--detach", str(tree), commit], cwd=ROOT, check=True,
                       capture_output=True)
    return tree / "fmu_src"


class SpeedChild:
    """A process running one core's kernels on the scenarios it is sent, one at a time:
    ``script`` reads a JSON line per scenario and answers with one."""

    def __init__(self, core_parent: Path, cache: Path, script: str = SPEED):
        self.process = subprocess.Popen([sys.executable, "-c", script], env=_child_env(cache, core_parent),
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def seconds(self, scenario) -> tuple[float, float]:
        self.process.stdin.write(json.dumps(scenario) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"the speed child stopped on {scenario}")
        return tuple(json.loads(line))

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait()


def step_speed(commit: str, rounds: int) -> None:
    print(f"\n5. step speed against the previous release {commit}, same scenarios (scaled stick-slip, "
          f"vibrating A = 0.3, omega = 0.8, dt = {DT}; B and C with contact_law = 1, the release's contact), "
          f"CPU seconds, in turns, best of {rounds} (target: ratio >= 0.9; |dx|: x at t_end, the two apart)")
    print(f"   {'model':5} {'integrator':17} {'t_end':>7} {'previous':>9} {'this':>9} {'ratio':>6} "
          f"{'|dx|':>8}")
    work = ROOT / "build" / "work"
    ours = SpeedChild(CORE.parent, Path(os.environ.get("NUMBA_CACHE_DIR", work / "numba")))
    theirs = SpeedChild(previous_core(commit), work / f"numba-release-{commit}")
    try:
        for model, integrator, t_end in SPEED_SCENARIOS:
            scenario = [model, integrator, t_end, dict(VIBRATING, dt=DT)]
            # The release's contact on a corrugated plate is today's contact_law = 1 (the
            # default became the conservative one): the same physics on both sides.
            release_law = {"contact_law": 1} if model != "A" else {}
            same_law = [model, integrator, t_end, dict(VIBRATING, dt=DT, **release_law)]
            best_ours, best_theirs = float("inf"), float("inf")
            for _ in range(rounds):
                seconds_theirs, x_theirs = theirs.seconds(scenario)
                seconds_ours, x_ours = ours.seconds(same_law)
                best_ours, best_theirs = min(best_ours, seconds_ours), min(best_theirs, seconds_theirs)
            print(f"   {model:5} {integrator:17} {t_end:7g} {best_theirs:8.3f}s {best_ours:8.3f}s "
                  f"{best_theirs / best_ours:6.2f} {abs(x_ours - x_theirs):8.1e}")
    finally:
        ours.close()
        theirs.close()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, default=ROOT / "build" / "fmus")
    parser.add_argument("--previous", default=PREVIOUS, help="the release to compare step speed with")
    parser.add_argument("--rounds", type=int, default=5, help="turns per step-speed scenario")
    parser.add_argument("--quick", action="store_true", help="FMU sizes and first doSteps only; publishes nothing")
    parser.add_argument("--sections", default="1,2,3,4,5", help="the sections to measure, e.g. 5")
    args = parser.parse_args(argv)
    if not block_fmus(args.fmu_dir):
        parser.error(f"no Block FMUs in {args.fmu_dir}: run make fmus first")
    scratch = Path(tempfile.mkdtemp(prefix="build_cost-"))
    try:
        sections = {int(part) for part in args.sections.split(",")} - ({1, 4, 5} if args.quick else set())
        with recorded("build_cost", argv):
            for number, measure in ((1, lambda: compile_costs(scratch)), (2, lambda: fmu_sizes(args.fmu_dir)),
                                    (3, lambda: first_steps(args.fmu_dir, scratch)),
                                    (4, lambda: non_defaults(args.fmu_dir, scratch)),
                                    (5, lambda: step_speed(args.previous, args.rounds))):
                if number in sections:
                    measure()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
