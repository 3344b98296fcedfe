"""Benchmark: speed of the physics core and the cost of going through an FMU.

    python -m harness.benchmarks.core_and_fmu [--fmu-dir build/fmus] [--substeps 2e7]

Prints, measured side by side in one run on one core:

1. internal steps per second of the core, per model and integrator (the scaled
   stick-slip set, once with the plate at rest and once vibrating); for the
   event-driven scheme these are grid steps covered per second, its cost being set by
   the number of events instead;
2. the shared fixed-step driver against a plain numba loop: model A's first-order
   scheme (``symplectic_euler``, vibrating) side by side with a hand-written numba
   kernel of the same scheme that calls sin/cos of the drive every step, and the ratio;
   the previous release's driver (``--previous``) on the same run beside them;
3. fmpy -> FMU cost: a fixed amount of work (internal steps) split into communication
   steps of 1, 10, 100 and 1000 internal steps, the overhead per doStep against the bare
   core doing the same work, and the FMU's slowdown relative to the core.
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from numba import njit

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from vibroblock import INTEGRATORS, Block, ModelError
from vibroblock.models import VARIANTS

from harness.benchmarks.build_cost import PREVIOUS, SpeedChild, previous_core

ROOT = Path(__file__).resolve().parents[2]
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
DT = 4e-4


def best_of(repeats, run):
    return min(run() for _ in range(repeats))


def core_seconds(model, integrator, steps, **parameters):
    def run():
        block = Block(model, integrator, initial_state=2, **SCALED, **parameters)
        block.start()
        block.advance_to(DT)  # compile/load kernels outside the timing
        start = time.perf_counter()
        block.advance_to(DT * (steps + 1))
        return time.perf_counter() - start
    return best_of(3, run)


@njit(cache=True)
def plain_euler(y, n_steps, dt, amp, omega, k_n, gamma_n, k_t, gamma_t, mu_s, k_d, v_d):
    """Model A's semi-implicit Euler step written out, the plate's sin/cos evaluated
    every step: the baseline a driver with a sin/cos recurrence is measured against."""
    x, z, vx, vz, shear = y[0], y[1], y[2], y[3], y[4]
    for n in range(n_steps):
        t = n * dt
        plate_z, plate_v = amp * math.sin(omega * t), amp * omega * math.cos(omega * t)
        pen = plate_z - z
        u_n, u_t = vz - plate_v, vx
        normal = k_n * pen - gamma_n * u_n if pen > 0.0 else 0.0
        tangential = -gamma_t * u_t - (k_t * shear if pen > 0.0 else 0.0)
        vx += dt * (-k_d * (x - v_d * t) + tangential)
        vz += dt * (normal - 1.0)
        x += dt * vx
        z += dt * vz
        t1 = t + dt
        pen1 = amp * math.sin(omega * t1) - z
        if pen > 0.0:
            shear += dt * vx
        normal1 = k_n * pen1 - gamma_n * (vz - amp * omega * math.cos(omega * t1)) if pen1 > 0.0 else 0.0
        if pen1 <= 0.0 or abs(k_t * shear) >= mu_s * normal1:
            shear = 0.0
    y[0], y[1], y[2], y[3], y[4] = x, z, vx, vz, shear
    return n_steps


def plain_seconds(steps, amp, omega):
    def run():
        y = np.array([0.0, -1.0, 0.0, 0.0, 0.0])
        plain_euler(y, 10, DT, amp, omega, 1.0, 0.07, 0.28, SCALED["gamma_t"], 0.5, SCALED["k_d"], SCALED["V_d"])
        start = time.perf_counter()
        plain_euler(y, steps, DT, amp, omega, 1.0, 0.07, 0.28, SCALED["gamma_t"], 0.5, SCALED["k_d"], SCALED["V_d"])
        return time.perf_counter() - start
    return best_of(3, run)


def previous_release_seconds(commit: str, steps: int, drive: dict) -> float:
    """The previous release's shared driver on the same run (model A, symplectic_euler), in
    its own process (``build_cost.SpeedChild``, the release as a git worktree), best of 3."""
    child = SpeedChild(previous_core(commit), ROOT / "build" / "work" / f"numba-release-{commit}")
    try:
        return min(child.seconds(["A", "symplectic_euler", DT * (steps + 1), dict(SCALED, dt=DT, **drive)])[0]
                   for _ in range(3))
    finally:
        child.close()


def fmu_seconds(unzipdir, md, steps, substeps_per_step):
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="bench")
    slave.instantiate()
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vr[k] for k in SCALED], list(SCALED.values()))
        # The bare core's run: symplectic_euler (not the FMU's default integrator) from initial_state 2.
        slave.setInteger([vr["integrator"], vr["initial_state"]], [INTEGRATORS["symplectic_euler"], 2])
        slave.exitInitializationMode()
        h = substeps_per_step * DT
        n_calls = steps // substeps_per_step
        slave.doStep(0.0, h)
        outputs = [vr["x"], vr["vx"]]
        start = time.perf_counter()
        for k in range(1, n_calls + 1):
            slave.doStep(k * h, h)
            slave.getReal(outputs)  # a master reads outputs after each step
        return time.perf_counter() - start, n_calls
    finally:
        slave.terminate()
        slave.freeInstance()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu-dir", type=Path, default=ROOT / "build" / "fmus")
    parser.add_argument("--substeps", type=float, default=2e7, help="internal steps per core measurement")
    parser.add_argument("--fmu-work", type=float, default=2e5, help="internal steps per FMU measurement")
    parser.add_argument("--previous", default=PREVIOUS,
                        help="the release whose driver section 2 also times ('' to skip)")
    args = parser.parse_args(argv)
    steps = int(args.substeps)

    print(f"1. core speed, dt = {DT}, {steps:.0e} internal steps, best of 3")
    print(f"   {'model':5} {'integrator':18} {'plate':9} {'Msteps/s':>9} {'ns/step':>8}")
    for model in VARIANTS:
        for integrator in INTEGRATORS:
            for label, drive in (("at rest", {}), ("vibrating", {"A": 0.3, "omega": 0.8})):
                try:
                    seconds = core_seconds(model, integrator, steps, **drive)
                except ModelError:  # e.g. event_driven exists for model A only
                    continue
                print(f"   {model:5} {integrator:18} {label:9} {steps / seconds / 1e6:9.1f} {seconds / steps * 1e9:8.2f}")

    drive = {"A": 0.3, "omega": 0.8}
    ours = core_seconds("A", "symplectic_euler", steps, **drive)
    plain = plain_seconds(steps, drive["A"], drive["omega"])
    print(f"\n2. model A, symplectic_euler, vibrating: shared driver {steps / ours / 1e6:.1f} Msteps/s, plain numba "
          f"loop with sin/cos per step {steps / plain / 1e6:.1f} Msteps/s: ratio {plain / ours:.2f}x (target >= 2)")
    if args.previous:
        before = previous_release_seconds(args.previous, steps, drive)
        print(f"   the release {args.previous}'s driver on the same run (its own process, CPU time): "
              f"{steps / before / 1e6:.1f} Msteps/s: ratio {plain / before:.2f}x; this driver / the release's "
              f"speed {before / ours:.2f}")

    work = int(args.fmu_work)
    md = read_model_description(str(args.fmu_dir / "BlockA.fmu"))
    unzipdir = extract(str(args.fmu_dir / "BlockA.fmu"))
    bare = core_seconds("A", "symplectic_euler", work)
    print(f"\n3. fmpy -> BlockA.fmu, {work:.0e} internal steps in all; bare core {bare * 1e3:.2f} ms")
    print(f"   {'steps/doStep':>12} {'doSteps':>8} {'FMU s':>8} {'overhead/doStep':>16} {'FMU/core':>9}")
    for per_step in (1, 10, 100, 1000):
        seconds, calls = fmu_seconds(unzipdir, md, work, per_step)
        overhead = (seconds - bare) / calls
        print(f"   {per_step:12d} {calls:8d} {seconds:8.3f} {overhead * 1e6:13.1f} us {seconds / bare:9.2f}")


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("core_and_fmu"):
        main()
