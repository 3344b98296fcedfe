"""Benchmark: what a chain of blocks costs per block and per step, beside the single block
and beside the chain's previous kernel.

    python -m harness.benchmarks.chain_speed [--quick] [--previous e630600]

Measured side by side in one run, compiled kernels warm, CPU seconds, best of ``--rounds``:

1. the single block (``Block("A", "symplectic_euler")``, the chain's scheme), and chains
   of 1, 16, 64, 256 and 1000 blocks (``Chain``), all at the chain's defaults (scaled
   stick-slip drive, dt = 1e-2, mu_s spread 0.3), over the same simulated time:
   nanoseconds per block-step, block-steps per second and their ratio to the target
   (1e8 per second per core at N = 1000) and to the ceiling (below), and the ratio of
   the time per block-step to the single block's; then the same with ``rk4`` (the
   chain's fourth-order scheme) beside the single block's ``rk4``;
2. the chain's kernel against the kernel of commit ``--previous`` (by default the one
   before a flat plate's contact and forces skipped their products by cos a = 1 and
   sin a = 0, ``models.flat_plate``), each core in its own process (``build_cost.SpeedChild``; the previous core a git worktree in
   build/work/), measured in turns on the same runs, best of the rounds: ns per
   block-step on each side, the speed-up, and the largest difference of the blocks'
   final x (0: the same bits);
3. BlockChain.fmu through fmpy (16 blocks) at communication steps of 100, 10 and 1 tau_0,
   reading every output at each: the time per simulated tau_0 against the core's;
4. jumping through sticks (``Chain(jump_sticks=True)``, ``chain.jump``) against stepping,
   chains of 16, 64, 256 and 1000 blocks at the chain's defaults over the same simulated
   time, 64 blocks whose ringing decays ten times faster (gamma_t = 0.05), and 256 blocks
   at Carlson-Langer's parameters with the cluster catalogue: CPU
   seconds of each, their ratio, the fraction of steps jumped, the events of each, and
   the largest difference of the final x relative to the largest |x|.  ``--jumps`` runs
   this section alone (printed, not published).

The ceiling.  A block-step of the default physics needs about 25-30 floating-point
operations (contact, forces, the update, the friction rule and the phi quadrature); the
ceiling here is a core's scalar peak, 2 double-precision operations per cycle (two
floating-point ports; the step's per-block branches, contact and reset, keep it
scalar), at the clock /proc/cpuinfo states, over 27.5 operations per block-step:
2 f / 27.5 block-steps per second (1.67e8 at 2.3 GHz).  Memory does not set it at these
N: the ~48 bytes a block-step must move would ask 8 GB/s at that rate, and a chain of
1000 blocks keeps all its per-block rows (0.55 MB) in a core's 2 MB cache here.

A catalogue of 1e4 large events of a 64-block chain (about 5e7 tau_0 at one event per
~5e3 tau_0) costs the block-step figure times 64 x 5e9.
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from harness.chain.run import CARLSON_LANGER as CARLSON_LANGER_PARAMETERS
from vibroblock import Block
from vibroblock.chain import Chain
from vibroblock.chain.runner import BLOCK_DEFAULTS
from vibroblock.layout import C_STEP

from . import ROOT, cpu_info, recorded
from .build_cost import CORE, SpeedChild, previous_core

SPREAD = {"mu_s_spread": 0.3, "seed": 1}
SIZES = (1, 16, 64, 256, 1000)
JUMP_SIZES = (16, 64, 256, 1000)
# Carlson-Langer's standard parameters in the chain's units (docs/chain.md), cluster catalogue.
CARLSON_LANGER = {**CARLSON_LANGER_PARAMETERS, "clusters": True}
TARGET = 1e8  # block-steps per second per core at N = 1000 (the explicit first-order kernel)
FLOPS_PER_BLOCK_STEP = 27.5  # the physics' own count, 25-30
FLOPS_PER_CYCLE = 2.0  # scalar double precision: two floating-point ports
# The kernel before the flat plate's contact and forces skipped the frame's products
# (``models.flat_plate``); 8b6b5d6 is the one before the single-pass step.
PREVIOUS = "e630600"
PREVIOUS_SIZES = (16, 256, 1000)

# Child: the chain's kernel of the core on its path, timed on the runs it is sent; answers
# with the CPU seconds and the blocks' final x.
CHAIN_SPEED = r"""
import json, sys, time
from vibroblock.chain import Chain
for line in sys.stdin:
    n_blocks, t_end, parameters = json.loads(line)
    chain = Chain(n_blocks, **parameters)
    chain.start()
    chain.advance_to(1.0)  # compiled or loaded outside the timing
    start = time.process_time()
    chain.advance_to(t_end)
    print(json.dumps([time.process_time() - start, chain.x.tolist()]), flush=True)
"""


def clock_hz() -> float:
    """The core's clock as /proc/cpuinfo states it (nan where it does not)."""
    try:
        return float(cpu_info("cpu MHz")) * 1e6
    except (TypeError, ValueError):
        return float("nan")


def ceiling() -> float:
    """Block-steps per second at the core's scalar floating-point peak (module doc)."""
    return FLOPS_PER_CYCLE * clock_hz() / FLOPS_PER_BLOCK_STEP


def _seconds(make, t_end: float, rounds: int) -> float:
    best = float("inf")
    for _ in range(rounds):
        runner = make()
        runner.start()
        runner.advance_to(1.0)  # compiled or loaded outside the timing
        start = time.process_time()
        runner.advance_to(t_end)
        best = min(best, time.process_time() - start)
    return best


def core(t_end: float, rounds: int) -> float:
    steps = t_end / BLOCK_DEFAULTS["dt"]
    top = ceiling()
    single = _seconds(lambda: Block("A", "symplectic_euler", 0, False, **BLOCK_DEFAULTS), t_end, rounds)
    print(f"1. core, {t_end:g} tau_0 at dt = {BLOCK_DEFAULTS['dt']:g} ({steps:.3g} steps), best of {rounds}; "
          f"target {TARGET:.0e} block-steps/s, ceiling {top:.3g} ({FLOPS_PER_CYCLE:g} flops/cycle at "
          f"{clock_hz() / 1e9:.2f} GHz over {FLOPS_PER_BLOCK_STEP:g} flops per block-step)")
    print(f"   {'runner':24} {'CPU s':>8} {'ns/block-step':>14} {'block-steps/s':>14} {'/ target':>9} "
          f"{'/ ceiling':>10} {'ratio to single':>16}")
    per_single = single / steps * 1e9

    def row(label, seconds, per):
        rate = 1e9 / per
        print(f"   {label:24} {seconds:8.3f} {per:14.2f} {rate:14.3g} {rate / TARGET:9.2f} {rate / top:10.2f} "
              f"{per / per_single:16.2f}")
    row("single Block", single, per_single)
    for n in SIZES:
        seconds = _seconds(lambda n=n: Chain(n, **SPREAD), t_end, rounds)
        row(f"Chain of {n}", seconds, seconds / (steps * n) * 1e9)
    single_rk4 = _seconds(lambda: Block("A", "rk4", 0, False, **BLOCK_DEFAULTS), t_end, rounds) / steps * 1e9
    print(f"   {'single Block, rk4':24} {single_rk4 * steps / 1e9:8.3f} {single_rk4:14.2f}")
    for n in (16, 64):
        seconds = _seconds(lambda n=n: Chain(n, integrator="rk4", **SPREAD), t_end, rounds)
        per = seconds / (steps * n) * 1e9
        print(f"   {f'Chain of {n}, rk4':24} {seconds:8.3f} {per:14.2f}  ({per / single_rk4:.2f} x the single rk4)")
    return _seconds(lambda: Chain(16, **SPREAD), t_end, rounds) / t_end


def against_previous(commit: str, t_end: float, rounds: int) -> None:
    """Section 2: this core's chain kernel and commit's, each in its own process, in turns."""
    steps = t_end / BLOCK_DEFAULTS["dt"]
    print(f"\n2. the chain's kernel against commit {commit}'s, {t_end:g} tau_0 ({steps:.3g} steps), each core in "
          f"its own process, in turns, CPU seconds, best of {rounds} (|dx|: largest difference of the final x)")
    print(f"   {'blocks':>6} {'previous ns':>12} {'this ns':>8} {'speed-up':>9} {'this block-steps/s':>19} "
          f"{'|dx|':>8}")
    work = ROOT / "build" / "work"
    ours = SpeedChild(CORE.parent, Path(os.environ.get("NUMBA_CACHE_DIR", work / "numba")), CHAIN_SPEED)
    theirs = SpeedChild(previous_core(commit), work / f"numba-release-{commit}", CHAIN_SPEED)
    try:
        for n in PREVIOUS_SIZES:
            run = [n, t_end, SPREAD]
            best_ours = best_theirs = float("inf")
            for _ in range(rounds):
                seconds_theirs, x_theirs = theirs.seconds(run)
                seconds_ours, x_ours = ours.seconds(run)
                best_ours, best_theirs = min(best_ours, seconds_ours), min(best_theirs, seconds_theirs)
            per_ours, per_theirs = best_ours / (steps * n) * 1e9, best_theirs / (steps * n) * 1e9
            dx = max(abs(a - b) for a, b in zip(x_ours, x_theirs))
            print(f"   {n:6d} {per_theirs:12.2f} {per_ours:8.2f} {per_theirs / per_ours:9.2f} "
                  f"{1e9 / per_ours:19.3g} {dx:8.1e}")
    finally:
        ours.close()
        theirs.close()


def fmu(fmu_path: Path, t_end: float, core_per_tau: float) -> None:
    from fmpy import read_model_description, simulate_fmu

    outputs = [v.name for v in read_model_description(str(fmu_path)).modelVariables if v.causality == "output"]
    print(f"\n3. BlockChain.fmu (16 blocks) through fmpy, {t_end:g} tau_0, all {len(outputs)} outputs read at "
          f"every communication point (wall seconds, one run each)")
    print(f"   {'communication step':>19} {'wall s':>8} {'per tau_0 / core':>17}")
    for step in (100.0, 10.0, 1.0):
        start = time.perf_counter()
        simulate_fmu(str(fmu_path), stop_time=t_end, output_interval=step, start_values=dict(SPREAD),
                     output=outputs)
        wall = time.perf_counter() - start
        print(f"   {step:19g} {wall:8.3f} {wall / t_end / core_per_tau:17.2f}")


def _run(n_blocks: int, t_end: float, jump: bool, parameters: dict):
    chain = Chain(n_blocks, jump_sticks=jump, **parameters)
    chain.start()
    chain.advance_to(1.0)  # compiled or loaded outside the timing
    start = time.process_time()
    chain.advance_to(t_end)
    return time.process_time() - start, chain


def jumps(t_end: float, carlson_langer_end: float) -> None:
    """Section 4: the same runs stepped and jumped, one run each."""
    print(f"\n4. jumping through sticks against stepping, CPU seconds, one run each; |dx|: the largest difference "
          f"of the final x over the largest |x|")
    print(f"   {'run':32} {'tau_0':>8} {'stepped s':>10} {'jumped s':>9} {'speed-up':>9} {'jumped':>7} "
          f"{'events':>13} {'|dx|':>8}")
    runs = [(f"{n} blocks, defaults", n, t_end, SPREAD) for n in JUMP_SIZES]
    runs.append(("64 blocks, gamma_t = 0.05", 64, t_end, {**SPREAD, "gamma_t": 0.05}))
    runs.append(("256 blocks, Carlson-Langer", 256, carlson_langer_end, CARLSON_LANGER))
    for label, n, end, parameters in runs:
        seconds_stepped, stepped = _run(n, end, False, parameters)
        seconds_jumped, jumped = _run(n, end, True, parameters)
        same = ([e[:4] for e in stepped.events] == [e[:4] for e in jumped.events])
        scale = max(abs(v) for v in stepped.x)
        dx = max(abs(a - b) for a, b in zip(stepped.x, jumped.x)) / scale
        fraction = jumped.jumped_steps / jumped.cnt[C_STEP]
        events = f"{len(stepped.events)}/{len(jumped.events)}{'' if same else ' (differ)'}"
        print(f"   {label:32} {end:8g} {seconds_stepped:10.3f} {seconds_jumped:9.3f} "
              f"{seconds_stepped / seconds_jumped:9.1f} {fraction:7.3f} {events:>13} {dx:8.1e}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockChain.fmu")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--previous", default=PREVIOUS,
                        help="the commit whose chain kernel section 2 times ('' to skip)")
    parser.add_argument("--quick", action="store_true", help="short runs, no section 2; publishes nothing")
    parser.add_argument("--jumps", action="store_true", help="section 4 alone (jumps against steps); publishes nothing")
    args = parser.parse_args(argv)
    t_end = 500.0 if args.quick else 2e4
    if args.jumps:
        jumps(t_end, t_end / 2)
        return 0
    with recorded("chain_speed", argv):
        per_tau = core(t_end, 1 if args.quick else args.rounds)
        if args.previous and not args.quick:
            against_previous(args.previous, t_end / 4, args.rounds)
        if args.fmu.exists():
            fmu(args.fmu, t_end, per_tau)
        else:
            print(f"\n3. skipped: no {args.fmu} (make fmus)")
        jumps(t_end, t_end / 2)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
