"""Benchmark: ``adaptive``'s work and precision on models B and C against the previous release.

    python -m harness.benchmarks.adaptive_release [--previous e856204] [--rounds 3] [--only NAME]

The work-precision benchmark's B and C scenarios (``work_precision.SCENARIOS``), run by
``adaptive`` in this build and in the previous release side by side: each core in its own
process (the release as a git worktree in build/work/, ``build_cost.previous_core``), the
two taking turns on every run, CPU seconds, best of ``--rounds``.  Both sides run the same
physics: the release's fixed-axes contact is today's ``contact_law = 1``
(``linear_along_normal``; the default became the conservative contact since); in the
tangent frame, which has no curvature term, the two laws are one and the default runs.  The errors
are against the independent reference (scipy DOP853 at rtol = atol = 1e-12 with a restart
at every switch, ``harness.paper.reference``, with that contact law), measured as the
work-precision benchmark measures them (the largest of the relative errors of x and phi and
of z in delta_0).

Printed per scenario: for each rtol (atol = rtol / 100) the two sides' CPU time and error;
then the time each side needs to reach the equal-accuracy level 1e-6 (its cheapest run
that does) and their ratio, previous / this.  ``adaptive``'s ratios against solve_ivp at
that level (docs/benchmarks.md, work_precision) change by exactly this factor: the target
is that they stay within 10 %, i.e. a ratio >= 0.9.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

from harness.benchmarks.build_cost import PREVIOUS, SpeedChild, previous_core
from harness.benchmarks.work_precision import ACCURACY, ADAPTIVE_DT, RTOLS, SCENARIOS, accuracy, errors

ROOT = Path(__file__).resolve().parents[2]
CORE_PARENT = ROOT / "fmu_src"
TARGET = 0.9  # previous / this at equal accuracy

# Child: one core running adaptive on the scenarios it is sent (one JSON line each).
RUN = r"""
import json, sys, time
from vibroblock import Block
for line in sys.stdin:
    s = json.loads(line)
    def make():
        block = Block(s["model"], "adaptive", s["initial"], True, dt=s["dt"], x_start=s["x_start"],
                      **s["parameters"])
        block.start()
        return block
    make().advance_to(min(1.0, s["horizon"]))  # kernels compiled or loaded outside the timing
    block = make()
    start = time.process_time()
    block.advance_to(s["horizon"])
    seconds = time.process_time() - start
    out = block.outputs()
    print(json.dumps([seconds, {"x": out["x"], "z": out["z"], "phi": out["phi_integral"]}]), flush=True)
"""


def request(scenario, rtol: float, release_contact: bool) -> dict:
    """One run of ``scenario`` at ``rtol``; ``release_contact``: this build's name for the
    release's fixed-axes contact (the release has no such parameter)."""
    parameters = dict(scenario.parameters, rtol=rtol, atol=rtol * 1e-2, formulation=scenario.formulation)
    if release_contact and scenario.formulation == 0:  # (no curvature term in the tangent frame: law 0 is it)
        parameters["contact_law"] = 1
    return {"model": scenario.model, "initial": scenario.initial, "dt": ADAPTIVE_DT, "x_start": scenario.x_start,
            "horizon": scenario.horizon, "parameters": parameters}


def reference(scenario) -> dict:
    from harness.paper.reference import Solver, simulate

    run = simulate(scenario.model, scenario.parameters, scenario.horizon, solver=Solver.reference(1e-12),
                   initial=scenario.initial, x_start=scenario.x_start, formulation=scenario.formulation,
                   contact_law="linear_along_normal")
    return {"x": run.final("x"), "z": run.final("z"), "phi": run.final("phi")}


def time_to_reach(rows: list[tuple[float, float]], level: float) -> float:
    """The cheapest (seconds, error) run whose error is at most ``level`` (inf: none)."""
    return min((seconds for seconds, error in rows if error <= level), default=math.inf)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--previous", default=PREVIOUS, help="the release to compare with")
    parser.add_argument("--rounds", type=int, default=3, help="turns per run (best of)")
    parser.add_argument("--only", default="", help="only the scenarios whose name starts with this")
    args = parser.parse_args(argv)
    scenarios = [s for s in SCENARIOS if s.model != "A" and s.name.startswith(args.only)]
    work = ROOT / "build" / "work"
    this = SpeedChild(CORE_PARENT, Path(os.environ.get("NUMBA_CACHE_DIR", work / "numba")), RUN)
    previous = SpeedChild(previous_core(args.previous), work / f"numba-release-{args.previous}", RUN)
    print(f"adaptive on B and C, this build against the release {args.previous}: CPU seconds, best of "
          f"{args.rounds} in turns; error against scipy DOP853 at 1e-12 (largest of x, phi relative, z in "
          f"delta_0); ratio = previous / this (target at equal accuracy {ACCURACY:g}: >= {TARGET})")
    print(f"   {'scenario':38} {'rtol':>6} {'previous':>9} {'error':>8} {'this':>9} {'error':>8} {'ratio':>6}")
    summary = []
    try:
        for scenario in scenarios:
            ref = reference(scenario)
            rows = {"previous": [], "this": []}
            for rtol in RTOLS:
                best = {"previous": (math.inf, None), "this": (math.inf, None)}
                for _ in range(args.rounds):
                    for side, core, ask in (("previous", previous, request(scenario, rtol, False)),
                                            ("this", this, request(scenario, rtol, True))):
                        seconds, obs = core.seconds(ask)
                        if seconds < best[side][0]:
                            best[side] = (seconds, obs)
                cells = []
                for side in ("previous", "this"):
                    seconds, obs = best[side]
                    error = accuracy(scenario, errors(scenario, obs, ref))
                    rows[side].append((seconds, error))
                    cells.append(f"{seconds * 1e3:7.2f}ms {error:8.1e}")
                print(f"   {scenario.name:38} {rtol:6.0e} {cells[0]} {cells[1]} "
                      f"{best['previous'][0] / best['this'][0]:6.2f}", flush=True)
            reach = {side: time_to_reach(rows[side], ACCURACY) for side in rows}
            summary.append((scenario.name, reach["previous"], reach["this"]))
    finally:
        this.close()
        previous.close()
    print(f"\nwork at equal accuracy {ACCURACY:g} (the cheapest run reaching it), previous / this "
          f"(target >= {TARGET})")
    ratios = []
    for name, before, after in summary:
        if math.isinf(before) or math.isinf(after):
            print(f"   {name:38} previous {before * 1e3:8.2f} ms  this {after * 1e3:8.2f} ms  (not reached by both)")
            continue
        ratios.append(before / after)
        print(f"   {name:38} previous {before * 1e3:8.2f} ms  this {after * 1e3:8.2f} ms  ratio {before / after:5.2f}")
    if ratios:
        print(f"   lowest ratio {min(ratios):.2f}, median {sorted(ratios)[len(ratios) // 2]:.2f} over {len(ratios)} "
              f"scenarios: {'within' if min(ratios) >= TARGET else 'NOT within'} the 10 % target")
    return 0


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("adaptive_release"):
        status = main()
    sys.exit(status)
