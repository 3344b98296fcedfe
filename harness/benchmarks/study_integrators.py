"""Benchmark: which integrator the claims' studies should run models B and C with, by omega.

    python -m harness.benchmarks.study_integrators [--full]

The studies' runs of models B and C (scaled drive k_d = V_d = 1e-2, gamma_t = 5e-3, on
the paper's plate A_x = 1e3, omega_x = 2e-2) each run once with the paper's
``symplectic_euler`` (dt = 4e-4) and once with ``adaptive`` (rtol 1e-6, atol 1e-8),
side by side in one process, through the FMU and the same measurement as the studies
(``harness.paper.claims.measure.run_and_measure``):

* model C, a row of the C6 diagram (horizon 1e4, from a crest with the drive spring
  relaxed) at A = 0.3 and 3 (``--full``: also A = 1 and 10, and ten omegas instead of six);
* model C, C8's fast drive: V_d = 10 at A = 0.5, omega = 0.3 (``--full``: also V_d = 1,
  and omega = 1);
* model B, the C5 runs (horizon 1e5, omega = 0.5, from a valley) at A = 0 and 5
  (``--full``: A = 0, 1, 2.5, 5, 10 and k_t = 0).

Printed per run: wall time of each integrator, their ratio, and each one's regime and
phi.  The studies' switch (``harness.paper.claims.study.CORRUGATED_INTEGRATION``) runs
``adaptive`` where it is the cheaper one; the last lines total what the switch costs
against either integrator alone.  Wall times on a shared machine are noisy at the 20 %
level; ratios measured side by side are the figures to read.
"""
from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from harness.paper.claims.measure import CREST, OBSERVE_B, OBSERVE_SHORT, SCALED, VALLEY, run_and_measure
from harness.paper.claims.study import CORRUGATED_INTEGRATION, CORRUGATED_TOLERANCES
from harness.runs.settings import InitialCondition, Integration, PointSettings, RunSettings, default_fmu

EULER = Integration("symplectic_euler")
ADAPTIVE = Integration("adaptive")


def model_c_point(amplitude: float, omega: float, v_d: float = SCALED["V_d"]) -> PointSettings:
    run = RunSettings(fmu=default_fmu("C"), horizon=10_000.0,
                      parameters={**SCALED, **CORRUGATED_TOLERANCES, "A": amplitude, "omega": omega, "V_d": v_d},
                      initial=InitialCondition("steady_orbit", x_start=CREST), start_time=CREST / v_d)
    return PointSettings(run=run, observe=OBSERVE_SHORT)


def model_b_point(amplitude: float, **more) -> PointSettings:
    run = RunSettings(fmu=default_fmu("B"), horizon=100_000.0,
                      parameters={**SCALED, **CORRUGATED_TOLERANCES, "A": amplitude, "omega": 0.5, **more},
                      initial=InitialCondition("steady_orbit", x_start=VALLEY), start_time=VALLEY / SCALED["V_d"])
    return PointSettings(run=run, observe=OBSERVE_B)


def timed(point: PointSettings, integration: Integration) -> tuple[float, dict]:
    point = dataclasses.replace(point, run=dataclasses.replace(point.run, integration=integration))
    start = time.perf_counter()
    observables = run_and_measure({"point": point}, None)["observables"]
    return time.perf_counter() - start, observables


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--full", action="store_true", help="every row and omega (about 8 minutes)")
    args = parser.parse_args(argv)
    omegas = np.round(np.geomspace(0.1, 50.0, 10), 4) if args.full else (0.1, 0.4, 1.5832, 3.1581, 12.5661, 50.0)
    cases = [(f"C  A = {a:<4g} omega = {w:<7g}", model_c_point(a, float(w)))
             for a in ((0.3, 1.0, 3.0, 10.0) if args.full else (0.3, 3.0)) for w in omegas]
    cases += [(f"C  A = 0.5  omega = {w:<7g} V_d = {v:g}", model_c_point(0.5, w, v))
              for v in ((1.0, 10.0) if args.full else (10.0,)) for w in ((0.3, 1.0) if args.full else (0.3,))]
    b_cases = [(a, {}) for a in ((0.0, 1.0, 2.5, 5.0, 10.0) if args.full else (0.0, 5.0))]
    b_cases += [(0.0, {"k_t": 0.0})] if args.full else []
    cases += [(f"B  A = {a:<4g} omega = 0.5 " + " ".join(f"{k} = {v:g}" for k, v in more.items()),
               model_b_point(a, **more)) for a, more in b_cases]
    print(f"{'run':44s} {'euler s':>8s} {'adaptive s':>10s} {'ratio':>6s}   euler regime, phi | adaptive regime, phi")
    totals = {"symplectic_euler": 0.0, "adaptive": 0.0, "switched": 0.0}
    disagreements = 0
    for label, point in cases:
        t_euler, euler = timed(point, EULER)
        t_adaptive, adaptive = timed(point, ADAPTIVE)
        totals["symplectic_euler"] += t_euler
        totals["adaptive"] += t_adaptive
        chosen = CORRUGATED_INTEGRATION.for_values(point.run.parameters)
        totals["switched"] += t_adaptive if chosen == "adaptive" else t_euler
        disagreements += euler["regime"] != adaptive["regime"]
        print(f"{label:44s} {t_euler:8.2f} {t_adaptive:10.2f} {t_euler / t_adaptive:6.2f}   "
              f"{euler['regime']}, {euler['phi']:.4g} | {adaptive['regime']}, {adaptive['phi']:.4g}"
              f"   (switch: {chosen})", flush=True)
    print(f"\ntotal: symplectic_euler {totals['symplectic_euler']:.1f} s, adaptive {totals['adaptive']:.1f} s, "
          f"the studies' switch ({CORRUGATED_INTEGRATION.describe()}) {totals['switched']:.1f} s")
    print(f"switch / euler = {totals['switched'] / totals['symplectic_euler']:.2f}, "
          f"switch / adaptive = {totals['switched'] / totals['adaptive']:.2f}; "
          f"regimes differ between the integrators at {disagreements}/{len(cases)} runs")


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("study_integrators"):
        main()
