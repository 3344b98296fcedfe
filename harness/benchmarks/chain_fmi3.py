"""Benchmark: BlockChain.fmu (FMI 2.0, scalars x[i]) beside BlockChain3.fmu (FMI 3.0,
arrays x, vx sized by N) through fmpy's low-level interfaces, side by side in one run.

    python -m harness.benchmarks.chain_fmi3 [--quick]

For N = 16 and 256 blocks and communication steps of 10 and 1 tau_0 (1000 and 100
internal steps of dt = 1e-2), each FMU runs the same chain (mu_s spread 0.3) over the
same simulated time, and at every communication point the master reads all 2 N block
outputs (x and vx).  Printed, wall microseconds per communication point, best of
``--rounds``: the doStep, the read of the 2 N outputs, and the FMI 3.0 FMU's time over
the FMI 2.0 one's.  The last column says whether both ended on the same bits.

Each FMU runs in a process of its own. The FMI 2.0 FMU of N = 256 is built for the run
(build/build_fmus.py --chain-blocks); the FMI 3.0 FMU takes N = 256 as its structural
parameter.  Memory is not compared:
both FMUs hold the same ``Chain`` and the arrays of 2 N doubles the outputs need.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import ROOT, recorded

SETTINGS = {"mu_s_spread": 0.3, "seed": 1}


def _instantiated(slave_class, fmu: Path, folder: str, name: str):
    """(an instantiated fmpy slave of ``fmu`` extracted into ``folder``, its value references by name)."""
    from fmpy import extract, read_model_description

    md = read_model_description(str(fmu))
    slave = slave_class(guid=md.guid, unzipDirectory=extract(str(fmu), unzipdir=folder),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    slave.instantiate()
    return slave, {v.name: v.valueReference for v in md.modelVariables}


def _fmi2_run(fmu: Path, folder: str, n_blocks: int, step: float, points: int):
    from fmpy.fmi2 import FMU2Slave

    slave, vr = _instantiated(FMU2Slave, fmu, folder, "fmi2")
    slave.setReal([vr[name] for name in SETTINGS], list(SETTINGS.values()))
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    outputs = [vr[f"{name}[{i}]"] for name in ("x", "vx") for i in range(1, n_blocks + 1)]
    timing = _timed(lambda t: slave.doStep(t, step), lambda: slave.getReal(outputs), step, points)
    slave.terminate()
    slave.freeInstance()
    return timing


def _fmi3_run(fmu: Path, folder: str, n_blocks: int, step: float, points: int):
    from fmpy.fmi3 import FMU3Slave

    slave, vr = _instantiated(FMU3Slave, fmu, folder, "fmi3")
    slave.enterConfigurationMode()
    slave.setUInt64([vr["N"]], [n_blocks])
    slave.exitConfigurationMode()
    slave.setFloat64([vr[name] for name in SETTINGS], list(SETTINGS.values()))
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    outputs = [vr["x"], vr["vx"]]
    timing = _timed(lambda t: slave.doStep(t, step), lambda: slave.getFloat64(outputs, 2 * n_blocks), step, points)
    slave.terminate()
    slave.freeInstance()
    return timing


def _timed(do_step, read, step: float, points: int):
    """(seconds per doStep, seconds per read, the last read): a first point outside the timing."""
    do_step(0.0)
    read()
    stepping = reading = 0.0
    for k in range(1, points + 1):
        start = time.perf_counter()
        do_step(k * step)
        middle = time.perf_counter()
        values = read()
        reading += time.perf_counter() - middle
        stepping += middle - start
    return stepping / points, reading / points, values


RUNS = {"2": _fmi2_run, "3": _fmi3_run}


def _child(version: str, fmu: str, n_blocks: int, step: float, points: int, rounds: int) -> None:
    """One FMU's measurement, printed as JSON: best seconds per doStep and per read, the last read."""
    results = []
    for _ in range(rounds):
        with tempfile.TemporaryDirectory() as folder:
            results.append(RUNS[version](Path(fmu), folder, n_blocks, step, points))
    print(json.dumps([min(r[0] for r in results), min(r[1] for r in results), results[-1][2]]))


def _measured(version: str, fmu: Path, n_blocks: int, step: float, points: int, rounds: int):
    """``_child`` in a process of its own: two builds of one model identifier (BlockChain of 16
    and of 256 blocks) cannot share a process, pythonfmu loads one script per name."""
    done = subprocess.run([sys.executable, "-m", __spec__.name, "--child", version, str(fmu), str(n_blocks),
                           str(step), str(points), str(rounds)], check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(fmus: Path, t_end: float, rounds: int) -> None:
    print(f"BlockChain (FMI 2.0) and BlockChain3 (FMI 3.0) through fmpy, {t_end:g} tau_0, x and vx read at every "
          f"communication point; wall microseconds per point, best of {rounds}, each FMU in a process of its own")
    print(f"   {'N':>4} {'step':>5} {'doStep 2.0':>11} {'doStep 3.0':>11} {'ratio':>6} {'read 2.0':>9} "
          f"{'read 3.0':>9} {'ratio':>6}  same bits")
    with tempfile.TemporaryDirectory() as scratch:
        subprocess.run([sys.executable, str(ROOT / "build" / "build_fmus.py"), "BlockChain", "--chain-blocks", "256",
                        "--dest", str(Path(scratch) / "n256")], check=True, capture_output=True)
        fmi2_fmus = {16: fmus / "BlockChain.fmu", 256: Path(scratch) / "n256" / "BlockChain.fmu"}
        for n_blocks, fmi2 in fmi2_fmus.items():
            for step in (10.0, 1.0):
                points = int(round(t_end / step))
                two = _measured("2", fmi2, n_blocks, step, points, rounds)
                three = _measured("3", fmus / "BlockChain3.fmu", n_blocks, step, points, rounds)
                print(f"   {n_blocks:4d} {step:5g} {two[0] * 1e6:11.1f} {three[0] * 1e6:11.1f} "
                      f"{three[0] / two[0]:6.2f} {two[1] * 1e6:9.1f} {three[1] * 1e6:9.1f} {three[1] / two[1]:6.2f}"
                      f"  {'yes' if two[2] == three[2] else 'NO'}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmus", type=Path, default=ROOT / "build" / "fmus", help="folder of the built FMUs")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="short runs; publishes nothing")
    parser.add_argument("--child", nargs=6, metavar=("VERSION", "FMU", "N", "STEP", "POINTS", "ROUNDS"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        version, fmu, n_blocks, step, points, rounds = args.child
        _child(version, fmu, int(n_blocks), float(step), int(points), int(rounds))
        return 0
    if not (args.fmus / "BlockChain3.fmu").exists():
        print(f"no {args.fmus / 'BlockChain3.fmu'} (make fmus)")
        return 1
    with recorded("chain_fmi3", argv):
        measure(args.fmus, 20.0 if args.quick else 2000.0, 1 if args.quick else args.rounds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
