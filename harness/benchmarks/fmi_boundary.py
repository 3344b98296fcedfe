"""Benchmark: first use of a freshly extracted FMU, and the cost of the FMI boundary.

    python -m harness.benchmarks.fmi_boundary [--fmu-dir build/fmus] [--without-shipped-kernels]

Prints side by side:

1. the first doStep of BlockA.fmu extracted to a fresh folder, with an empty numba
   cache ("cold") and again with the cache the first run left ("warm"), in a C master
   (tests/build/fmi_host.c: process start to the end of the first doStep, Python start
   included) and in fmpy (a child process: instantiate to the end of the first doStep).
   ``--without-shipped-kernels`` adds the cold case with the FMU's compiled kernels
   removed, i.e. numba compiling everything (about half a minute); and, in fmpy, the cold
   first doStep of BlockC.fmu in a reading other than the default (tangent frame,
   applied-load bound) with the ``adaptive`` integrator, whose kernels ship as well;
2. at 1000 internal steps per doStep: time per doStep through the C master and fmpy
   against the bare core doing the same work, and time per output read after each step
   (5 outputs read in one call), with the FMU's native front end running each doStep
   and each read without Python (as shipped: the compiled advance and observe kernels
   called through the Block's NativeStep record, vibroblock/native.py) and, for
   comparison, with every doStep and read a Python call through pythonfmu's library
   (``VIBROBLOCK_PYTHONFMU_DOSTEP=1``), and
   fmpy's own cost of an FMI call (timed on one that does not enter Python).  Each
   figure is given as the mean over all doSteps and
   as the mean of the quietest block of BLOCK doSteps: on a shared machine the load of
   other processes comes and goes, and the quietest blocks of the FMU and of the core
   compare the work itself.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
import zipfile
from pathlib import Path

from fmpy import read_model_description

ROOT = Path(__file__).resolve().parents[2]
HOST_SOURCE = ROOT / "tests" / "build" / "fmi_host.c"
DT = 4e-4
PER_STEP = 1000
OUTPUTS = ("x", "z", "vx", "vz", "friction_force")
BLOCK = 100  # doSteps per block (the C master's BENCH_BLOCK)
THROUGH_PYTHONFMU = "VIBROBLOCK_PYTHONFMU_DOSTEP"  # "1": the front end leaves doStep to pythonfmu

FMPY_FIRST_STEP = textwrap.dedent("""
    import json, sys, time
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave
    folder, model, integers = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
    md = read_model_description(folder)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    start = time.perf_counter()
    slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=model, instanceName="first")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.setInteger([vr[name] for name in integers], list(integers.values()))
    slave.exitInitializationMode()
    slave.doStep(0.0, 0.4)
    print(time.perf_counter() - start)
    slave.terminate()
    slave.freeInstance()
""")


def compile_host(work: Path) -> Path:
    exe = work / "fmi_host"
    subprocess.run(["cc", "-O2", "-o", str(exe), str(HOST_SOURCE), "-ldl", "-lm"], check=True)
    return exe


def extract(fmu: Path, folder: Path, keep_kernels: bool = True) -> Path:
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    if not keep_kernels:
        shutil.rmtree(folder / "resources" / "vibroblock_kernels", ignore_errors=True)
    return folder


def child_env(cache: Path, through_pythonfmu: bool = False) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("PYTHON") and k not in ("VIBROBLOCK_PYTHON", THROUGH_PYTHONFMU)}
    env["NUMBA_CACHE_DIR"] = str(cache)
    if through_pythonfmu:
        env[THROUGH_PYTHONFMU] = "1"
    return env


def host_first_step(host, folder, md, cache) -> float:
    done = subprocess.run([str(host), "bench", str(folder), "BlockA", md.guid, repr(PER_STEP * DT), "1", "0"],
                          capture_output=True, text=True, env=child_env(cache), check=True)
    return float(done.stdout.split("first_step_s")[1].split()[0])


def fmpy_first_step(folder, cache, model: str = "BlockA", integers: dict | None = None) -> float:
    done = subprocess.run([sys.executable, "-c", FMPY_FIRST_STEP, str(folder), model, json.dumps(integers or {})],
                          capture_output=True, text=True, env=child_env(cache), check=True)
    return float(done.stdout.split()[-1])


def bare_core_per_call(calls: int) -> tuple[tuple[float, float], float]:
    """The core doing the same work, per 1000 steps: one advance_to per BLOCK doSteps'
    worth of steps (mean, quietest block), and one advance_to and five output reads per
    1000 steps (mean); best of three runs each."""
    from vibroblock import Block

    def started():
        block = Block("A")
        block.start()
        block.advance_to(PER_STEP * DT)
        return block

    def whole():
        block, blocks = started(), []
        for k in range(1, calls // BLOCK + 1):
            start = time.perf_counter()
            block.advance_to((k * BLOCK + 1) * PER_STEP * DT)
            blocks.append((time.perf_counter() - start) / BLOCK)
        return sum(blocks) / len(blocks), min(blocks)

    def chunked():
        block = started()
        start = time.perf_counter()
        for k in range(2, calls + 2):
            block.advance_to(k * PER_STEP * DT)
            [block.output(name) for name in OUTPUTS]
        return (time.perf_counter() - start) / calls

    runs = [whole() for _ in range(3)]
    return (min(mean for mean, _ in runs), min(best for _, best in runs)), min(chunked() for _ in range(3))


def host_per_call(host, folder, md, vr, calls: int, env: dict) -> tuple[tuple[float, float], tuple[float, float]]:
    done = subprocess.run([str(host), "bench", str(folder), "BlockA", md.guid, repr(PER_STEP * DT), str(calls),
                           *[str(vr[name]) for name in OUTPUTS]], capture_output=True, text=True, env=env, check=True)
    figures = {key: float(value) for key, value in (line.split() for line in done.stdout.splitlines())}
    return ((figures["do_step_us"] * 1e-6, figures["do_step_us_quietest"] * 1e-6),
            (figures["read_us_per_output"] * 1e-6, figures["read_us_per_output_quietest"] * 1e-6))


def fmpy_per_call(folder, md, calls: int, through_pythonfmu: bool = False) -> tuple[float, float]:
    # The front end reads the switch when the instance is made (getenv sees os.environ).
    previous = os.environ.pop(THROUGH_PYTHONFMU, None)
    if through_pythonfmu:
        os.environ[THROUGH_PYTHONFMU] = "1"
    try:
        return _fmpy_per_call(folder, md, calls)
    finally:
        os.environ.pop(THROUGH_PYTHONFMU, None)
        if previous is not None:
            os.environ[THROUGH_PYTHONFMU] = previous


def _fmpy_per_call(folder, md, calls: int) -> tuple[float, float]:
    from fmpy.fmi2 import FMU2Slave

    vr = {v.name: v.valueReference for v in md.modelVariables}
    outputs = [vr[name] for name in OUTPUTS]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier="BlockA", instanceName="bench")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    h = PER_STEP * DT
    slave.doStep(0.0, h)
    steps, reads = [], []
    for k in range(1, calls + 1):
        t0 = time.perf_counter()
        slave.doStep(k * h, h)
        t1 = time.perf_counter()
        slave.getReal(outputs)
        reads.append(time.perf_counter() - t1)
        steps.append(t1 - t0)
    slave.terminate()
    slave.freeInstance()
    return mean_and_quietest(steps), mean_and_quietest(reads, len(outputs))


def fmpy_call_layer(folder, md, calls: int) -> tuple[float, float]:
    """fmpy's own cost of an FMI call (ctypes, its status check), from an FMI call that
    does not enter Python: fmi2SetDebugLogging (the front end and pythonfmu's C++ only)."""
    from fmpy.fmi2 import FMU2Slave, fmi2False

    slave = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier="BlockA", instanceName="layer")
    slave.instantiate()
    times = []
    for _ in range(calls):
        t0 = time.perf_counter()
        slave.fmi2SetDebugLogging(slave.component, fmi2False, 0, None)
        times.append(time.perf_counter() - t0)
    slave.freeInstance()
    return mean_and_quietest(times)


def mean_and_quietest(times: list, per: int = 1) -> tuple[float, float]:
    """Mean per call (divided by ``per``) over all calls and over the quietest block of BLOCK calls."""
    blocks = [sum(times[i:i + BLOCK]) / BLOCK for i in range(0, len(times) - BLOCK + 1, BLOCK)]
    return sum(times) / len(times) / per, min(blocks) / per


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, default=ROOT / "build" / "fmus")
    parser.add_argument("--calls", type=int, default=5000, help="doSteps per boundary measurement")
    parser.add_argument("--without-shipped-kernels", action="store_true",
                        help="also time a cold start with the FMU's compiled kernels removed (slow)")
    args = parser.parse_args(argv)
    fmu = args.fmu_dir / "BlockA.fmu"
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}

    with tempfile.TemporaryDirectory(prefix="vibroblock-bench-") as tmp:
        work = Path(tmp)
        host = compile_host(work)
        print("1. first doStep (1000 internal steps) of a freshly extracted BlockA.fmu, seconds")
        print(f"   {'':52} {'C master':>9} {'fmpy':>9}")
        rows = [("cold: empty numba cache", True, "cold"), ("warm: cache of the cold run", True, "cold")]
        if args.without_shipped_kernels:
            rows.append(("cold, shipped kernels removed", False, "bare"))
        for n, (label, keep, cache_name) in enumerate(rows):
            figures = []
            for kind in ("host", "fmpy"):
                cache = work / f"cache-{kind}-{cache_name}"
                if n == 0 or not keep:
                    shutil.rmtree(cache, ignore_errors=True)
                folder = extract(fmu, work / f"x-{kind}-{n}", keep)
                figures.append(host_first_step(host, folder, md, cache) if kind == "host"
                               else fmpy_first_step(folder, cache))
            print(f"   {label:52} {figures[0]:9.2f} {figures[1]:9.2f}")
        # A reading other than the default, with the stiff-stable integrator: its kernels
        # ship too, so it does not compile either (fmpy only: the C master runs BlockA).
        reading = {"formulation": 1, "coulomb_normal": 1, "integrator": 4}
        folder = extract(args.fmu_dir / "BlockC.fmu", work / "x-fmpy-reading")
        cache = work / "cache-fmpy-reading"
        first_step = fmpy_first_step(folder, cache, "BlockC", reading)
        print(f"   {'cold: BlockC, tangent frame, applied load, adaptive':52} {'-':>9} {first_step:9.2f}")

        folder = extract(fmu, work / "x-boundary")
        cache = work / "cache-host-cold"
        rows = [("C master -> FMU", host_per_call(host, folder, md, vr, args.calls, child_env(cache))),
                ("fmpy -> FMU", fmpy_per_call(folder, md, args.calls)),
                ("C master -> FMU, all via pythonfmu",
                 host_per_call(host, folder, md, vr, args.calls, child_env(cache, through_pythonfmu=True))),
                ("fmpy -> FMU, all via pythonfmu", fmpy_per_call(folder, md, args.calls, through_pythonfmu=True))]
        layer = fmpy_call_layer(folder, md, args.calls)
        bare, chunked = bare_core_per_call(args.calls)

    print(f"\n2. cost of the FMI boundary at {PER_STEP} internal steps per doStep ({args.calls} doSteps), BlockA;")
    print(f"   mean over all doSteps | mean of the quietest block of {BLOCK} doSteps")
    print(f"   {'':38} {'us/doStep':>10} {'vs core':>8} {'us/output read':>15} | {'us/doStep':>10} {'vs core':>8} "
          f"{'us/output read':>15}")
    print(f"   {'bare core, one call per block':38} {bare[0] * 1e6:10.2f} {1.0:8.2f} {'-':>15} | "
          f"{bare[1] * 1e6:10.2f} {1.0:8.2f} {'-':>15}")
    print(f"   {'bare core, a Python call per doStep':38} {chunked * 1e6:10.2f} {chunked / bare[0]:8.2f} {'-':>15} |")
    for label, (step, read) in rows:
        print(f"   {label:38} {step[0] * 1e6:10.2f} {step[0] / bare[0]:8.2f} {read[0] * 1e6:15.2f} | "
              f"{step[1] * 1e6:10.2f} {step[1] / bare[1]:8.2f} {read[1] * 1e6:15.2f}")
    print(f"   {'fmpy call layer alone (see below)':38} {layer[0] * 1e6:10.2f} {layer[0] / bare[0]:8.2f} {'-':>15} | "
          f"{layer[1] * 1e6:10.2f} {layer[1] / bare[1]:8.2f} {'-':>15}")
    print("   fmpy call layer: fmpy's own cost of one FMI call (ctypes, its status check), timed on "
          "fmi2SetDebugLogging,\n   which does not enter Python; every fmpy doStep pays it on top of the C master's.")


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("fmi_boundary"):
        main()
