"""Benchmark: what a chain of blocks costs per block and per step, beside the single block.

    python -m harness.benchmarks.chain_speed [--quick]

Measured side by side in one process, compiled kernels warm, CPU seconds, best of
``--rounds``:

1. the single block (``Block("A", "symplectic_euler")``, the chain's scheme), and chains
   of 1, 16, 64 and 256 blocks (``Chain``), all at the chain's defaults (scaled stick-slip
   drive, dt = 1e-2, mu_s spread 0.3), over the same simulated time: nanoseconds per
   block-step and the ratio to the single block; then the same with ``rk4`` (the chain's
   fourth-order scheme) beside the single block's ``rk4``;
2. BlockChain.fmu through fmpy (16 blocks) at communication steps of 100, 10 and 1 tau_0,
   reading every output at each: the time per simulated tau_0 against the core's.

A catalogue of 1e4 large events of a 64-block chain (about 5e7 tau_0 at one event per
~5e3 tau_0) costs the block-step figure times 64 x 5e9.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from vibroblock import Block
from vibroblock.chain import Chain
from vibroblock.chain.runner import BLOCK_DEFAULTS

from . import ROOT, recorded

SPREAD = {"mu_s_spread": 0.3, "seed": 1}


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
    single = _seconds(lambda: Block("A", "symplectic_euler", 0, False, **BLOCK_DEFAULTS), t_end, rounds)
    print(f"1. core, {t_end:g} tau_0 at dt = {BLOCK_DEFAULTS['dt']:g} ({steps:.3g} steps), best of {rounds}")
    print(f"   {'runner':24} {'CPU s':>8} {'ns/block-step':>14} {'ratio to single':>16}")
    per_single = single / steps * 1e9
    print(f"   {'single Block':24} {single:8.3f} {per_single:14.1f} {1.0:16.2f}")
    for n in (1, 16, 64, 256):
        seconds = _seconds(lambda n=n: Chain(n, **SPREAD), t_end, rounds)
        per = seconds / (steps * n) * 1e9
        print(f"   {f'Chain of {n}':24} {seconds:8.3f} {per:14.1f} {per / per_single:16.2f}")
    single_rk4 = _seconds(lambda: Block("A", "rk4", 0, False, **BLOCK_DEFAULTS), t_end, rounds) / steps * 1e9
    print(f"   {'single Block, rk4':24} {single_rk4 * steps / 1e9:8.3f} {single_rk4:14.1f} "
          f"{single_rk4 / per_single:16.2f}")
    for n in (16, 64):
        seconds = _seconds(lambda n=n: Chain(n, integrator="rk4", **SPREAD), t_end, rounds)
        per = seconds / (steps * n) * 1e9
        print(f"   {f'Chain of {n}, rk4':24} {seconds:8.3f} {per:14.1f} {per / per_single:16.2f}  "
              f"({per / single_rk4:.2f} x the single rk4)")
    return _seconds(lambda: Chain(16, **SPREAD), t_end, rounds) / t_end


def fmu(fmu_path: Path, t_end: float, core_per_tau: float) -> None:
    from fmpy import read_model_description, simulate_fmu

    outputs = [v.name for v in read_model_description(str(fmu_path)).modelVariables if v.causality == "output"]
    print(f"\n2. BlockChain.fmu (16 blocks) through fmpy, {t_end:g} tau_0, all {len(outputs)} outputs read at "
          f"every communication point (wall seconds, one run each)")
    print(f"   {'communication step':>19} {'wall s':>8} {'per tau_0 / core':>17}")
    for step in (100.0, 10.0, 1.0):
        start = time.perf_counter()
        simulate_fmu(str(fmu_path), stop_time=t_end, output_interval=step, start_values=dict(SPREAD),
                     output=outputs)
        wall = time.perf_counter() - start
        print(f"   {step:19g} {wall:8.3f} {wall / t_end / core_per_tau:17.2f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockChain.fmu")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="short runs; publishes nothing")
    args = parser.parse_args(argv)
    t_end = 500.0 if args.quick else 2e4
    with recorded("chain_speed", argv):
        per_tau = core(t_end, 1 if args.quick else args.rounds)
        if args.fmu.exists():
            fmu(args.fmu, t_end, per_tau)
        else:
            print(f"\n2. skipped: no {args.fmu} (make fmus)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
