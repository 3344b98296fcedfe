"""Work-precision benchmark: error against wall time for every integrator and scipy's solve_ivp.

    python -m harness.benchmarks.work_precision [--out out] [--quick]

Regenerates out/work_precision.png and out/work_precision.md, measured side by side in
one run (one process, so the numbers compare on the same machine load).

Scenarios (the scaled drive k_d = V_d = 1e-2, gamma_t = 5e-3 for A; the paper's B and C
near a valley of their corrugation):

* ``A stick-slip``: no vibration, two stick-slip cycles (t = 11000, 2 x 28 resets);
* ``A sub-threshold``: A = 0.3 at omega = 0.8 (A_c = 0.57), block embedded, two cycles:
  each reset comes where k_t F first touches the oscillating bound mu_s N;
* ``A bouncing (locked)``: A = 1.0 at omega = 0.8, above the onset, bouncing locked to
  the plate (not chaotic), t = 2000;
* ``A bouncing (chaotic)``: A = 5 A_c(0.8) = 2.85: a 1e-12 perturbation grows to O(1)
  by t ~ 350, so errors are taken on statistics over the window [200, 4000]: mean drift
  velocity, phi, contact fraction (sampled every 0.5) and the energy residual (relative
  to the energy dissipated; exactly 0);
* ``B`` and ``C``: the paper's corrugation (A_x = 1e3, omega_x = 0.02), sub-threshold
  vibration A = 0.2, omega = 0.8, from a slope of 0.1 near a valley (t = 600);
* ``B ...`` and ``C ...`` with the scaled drive (k_d = V_d = 1e-2, gamma_t = 5e-3) on the
  paper's corrugation from that slope: ``stick`` (no vibration, drive spring relaxed: no
  reset within t = 300), ``stick-slip`` (no vibration, drive spring stretched by 40:
  Coulomb resets from the start, t = 300), ``sub-threshold`` (A = 0.2, omega = 0.8, t = 200,
  resets) and ``bouncing`` (A = 1, omega = 0.8, above the onset, t = 30, short enough to
  stay non-chaotic).
* ``C held, vibrated (paper, fixed axes | tangent frame)``: model C at the paper's own
  parameters held at a crest (slope 0) of its corrugation by friction on a plate vibrated
  at omega = 0.316 with about a third of the detachment onset (A = 3), from the steady orbit,
  for t = 2e4 (~1000 plate periods, no switch): the regime of the paper's long vibrated
  sticks, where ``adaptive`` takes the periods many at a time (its stroboscopic jumps,
  ``periods_jumped``).

Integrators: the fixed-step ones over dt, ``event_driven`` (model A), ``adaptive`` over
rtol (atol = rtol / 100); on model A ``adaptive`` takes event_driven's exact flows, and
its own steps are measured beside it (``adaptive, own steps``: exact_flows off).  On B and
C (not with ``--quick``) ``symplectic_euler`` goes on to finer steps (EULER_FINE) until it
reaches the equal-accuracy level or one of its runs costs 100x ``adaptive``'s time there,
so that the target is met or missed by a measured run.

Non-chaotic scenarios are compared pointwise at the end: x and phi (errors relative to
their reference values) and z (in delta_0, the rest penetration), the error being the
largest of these.  The reference is ``harness.paper.reference`` (independent of the core:
DOP853 at rtol = atol = 1e-12, restarts at every switch, switches sought at 16 points of
each step's interpolant and steps capped to 1/16 of the plate period); its own error is
estimated by running it again at 1e-11 and reported as the floor.  Peers: scipy's RK45,
LSODA and Radau over a range of tolerances, with the same restarts and solve_ivp's own
event detection (sign at the step ends), i.e. what a user of solve_ivp gets.

The targets (printed and written in the table), at equal accuracy: on model A event_driven
against symplectic_euler and solve_ivp, and adaptive against event_driven (within 10x,
agreeing to 1e-8; its own steps reported beside); on B and C adaptive against
symplectic_euler (>= 100x) and against the fastest solve_ivp run reaching the accuracy
(>= 30x).
"""
from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
VALLEY_X = (-0.5 * math.pi + 0.005) / 0.02  # slope 0.1 of A_x sin(omega_x x) with the paper's A_x, omega_x
STEPS = (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4)
PEERS = {"RK45": (1e-4, 1e-6, 1e-8, 1e-10), "DOP853": (1e-4, 1e-6, 1e-8, 1e-10),
         "LSODA": (1e-4, 1e-6, 1e-8, 1e-10), "Radau": (1e-4, 1e-6, 1e-8)}
RTOLS = (1e-4, 1e-6, 1e-8, 1e-10)  # adaptive's settings
# symplectic_euler's further steps on B and C, taken while it has not reached ACCURACY and its
# last run cost less than EULER_BOUND times adaptive's time there (so the ratio is measured,
# not bounded by a run that is cheaper than the target), each run capped at EULER_CAP seconds.
EULER_FINE = (1e-4, 3e-5, 1e-5, 3e-6, 1e-6)
EULER_BOUND = 100.0
EULER_CAP = 90.0
ADAPTIVE_DT = 1e-2  # its storage grid (no effect on accuracy)
# adaptive on model A with exact_flows off: its own error-controlled steps, which on B and C
# are all it has (on A it otherwise takes event_driven's exact flows).
OWN_STEPS = "adaptive, own steps"
ACCURACY = 1e-6  # the equal-accuracy level of the targets
CREST_X = 0.5 * math.pi / 0.02  # slope 0 at a crest of the paper's corrugation
HELD_OMEGA = 0.316
HELD_AMPLITUDE = 3.0  # about A_c(0.316) / 3 = 3.006 with the paper's contact (vibroblock.detachment_amplitude)


@dataclass(frozen=True)
class Scenario:
    name: str
    model: str
    parameters: dict
    horizon: float
    initial: int = 2
    x_start: float = 0.0
    window: tuple | None = None  # statistics window (chaotic scenarios)
    formulation: int = 0


SCENARIOS = (
    Scenario("A stick-slip", "A", dict(SCALED), 11000.0, initial=0),
    Scenario("A sub-threshold", "A", dict(SCALED, A=0.3, omega=0.8), 11000.0),
    Scenario("A bouncing (locked)", "A", dict(SCALED, A=1.0, omega=0.8), 2000.0),
    Scenario("A bouncing (chaotic)", "A", dict(SCALED, A=2.8463, omega=0.8), 4000.0, window=(200.0, 4000.0)),
    Scenario("B", "B", dict(A=0.2, omega=0.8), 600.0, x_start=VALLEY_X),
    Scenario("C", "C", dict(A=0.2, omega=0.8), 600.0, x_start=VALLEY_X),
    *(Scenario(f"{model} {name}", model, dict(SCALED, **extra), horizon, initial, VALLEY_X + offset)
      for model in "BC"
      for name, extra, horizon, initial, offset in (
          ("stick", {}, 300.0, 0, 0.0),
          ("stick-slip", {}, 300.0, 0, -40.0),
          ("sub-threshold", dict(A=0.2, omega=0.8), 200.0, 2, 0.0),
          ("bouncing", dict(A=1.0, omega=0.8), 30.0, 2, 0.0))),
    *(Scenario(f"C held, vibrated (paper, {name})", "C", dict(A=HELD_AMPLITUDE, omega=HELD_OMEGA), 2e4,
               x_start=CREST_X, formulation=formulation)
      for formulation, name in ((0, "fixed axes"), (1, "tangent frame"))),
)


# ----------------------------------------------------------------------------- observables
def core_run(scenario: Scenario, integrator: str, dt: float, **tolerances):
    """Timed run of the physics core; returns (seconds, observables)."""
    from vibroblock import Block

    def make():
        readings = {"formulation": scenario.formulation} if scenario.model != "A" else {}
        block = Block(scenario.model, integrator, dt=dt, initial_state=scenario.initial, x_start=scenario.x_start,
                      energy_balance=True, **scenario.parameters, **readings, **tolerances)
        block.start()
        return block

    block = make()
    block.advance_to(min(1.0, scenario.horizon))  # load kernels outside the timing
    block = make()
    started = time.perf_counter()
    if scenario.window:
        block.advance_to(scenario.window[0])
        first = block.outputs()
    block.advance_to(scenario.horizon)
    seconds = time.perf_counter() - started
    last = block.outputs()
    obs = {"x": last["x"], "z": last["z"], "phi": last["phi_integral"]}
    if scenario.window:
        span = scenario.window[1] - scenario.window[0]
        obs["drift"] = (last["x"] - first["x"]) / span
        obs["phi_window"] = (last["phi_integral"] - first["phi_integral"]) / (span * scenario.parameters["V_d"] ** 2)
        obs["energy"] = last["energy_residual"] / last["energy_dissipated"]
        # contact fraction from a separate, untimed, sampled run
        sampled = make()
        sampled.advance_to(scenario.window[0])
        hits = []
        for t in np.arange(scenario.window[0] + 0.5, scenario.window[1] + 1e-9, 0.5):
            sampled.advance_to(t)
            hits.append(sampled.output("contact"))
        obs["contact"] = float(np.mean(hits))
    return seconds, obs


def scipy_run(scenario: Scenario, solver):
    from harness.paper import reference

    if scenario.window:
        times = np.arange(scenario.window[0], scenario.window[1] + 1e-9, 0.5)
    else:
        times = np.array([scenario.horizon])
    run = reference.simulate(scenario.model, scenario.parameters, scenario.horizon, times, solver=solver,
                             initial=scenario.initial, x_start=scenario.x_start, formulation=scenario.formulation)
    obs = {"x": run.final("x"), "z": run.final("z"), "phi": run.final("phi")}
    if scenario.window:
        span = scenario.window[1] - scenario.window[0]
        obs["drift"] = (run.final("x") - run["x"][0]) / span
        obs["phi_window"] = (run.final("phi") - run["phi"][0]) / (span * scenario.parameters["V_d"] ** 2)
        obs["energy"] = run.energy_residual()[-1] / run.final("dissipated")
        obs["contact"] = float(np.mean(run["contact"][1:]))
    return run.wall_time, obs


def errors(scenario: Scenario, obs: dict, ref: dict) -> dict:
    if scenario.window:
        return {"drift": abs(obs["drift"] - ref["drift"]) / abs(ref["drift"]),
                "phi": abs(obs["phi_window"] - ref["phi_window"]) / abs(ref["phi_window"]),
                "contact": abs(obs["contact"] - ref["contact"]),
                "energy": abs(obs["energy"])}
    return {"x": abs(obs["x"] - ref["x"]) / max(abs(ref["x"]), 1.0),
            "z": abs(obs["z"] - ref["z"]),  # lengths in delta_0, the rest penetration
            "phi": abs(obs["phi"] - ref["phi"]) / abs(ref["phi"])}


def accuracy(scenario: Scenario, err: dict) -> float:
    """The error plotted: the largest pointwise error; for a chaotic scenario the energy
    residual, the one statistic whose exact value is known (the others carry the noise of a
    finite window, which the table reports with the reference's own spread)."""
    return err["energy"] if scenario.window else max(err.values())


# ----------------------------------------------------------------------------- measuring
def measure(scenario: Scenario, quick: bool, log):
    from vibroblock import INTEGRATORS, ModelError

    from harness.paper.reference import Solver

    rows = []
    ref_seconds, ref = scipy_run(scenario, Solver.reference(1e-12))
    _, check = scipy_run(scenario, Solver.reference(1e-11))
    floors = errors(scenario, check, ref)
    floor = accuracy(scenario, floors)
    log(f"  reference DOP853 1e-12: {ref_seconds:.2f} s; its error estimate (vs 1e-11) {floor:.1e} "
        f"({', '.join(f'{k} {v:.1e}' for k, v in floors.items())})")
    rows.append(("reference DOP853", "rtol 1e-12", ref_seconds, floor, floors))
    steps = STEPS[1:4] if quick else STEPS
    methods = {name: (name, {}) for name in INTEGRATORS}
    if scenario.model == "A":  # adaptive as users get it (exact flows) and on its own steps
        methods[OWN_STEPS] = ("adaptive", {"exact_flows": False})
    for method, (integrator, options) in methods.items():
        if integrator == "event_driven" and scenario.model != "A":
            continue
        if integrator == "adaptive":
            runs = [(f"rtol {rtol:g}", ADAPTIVE_DT, {"rtol": rtol, "atol": rtol * 1e-2, **options})
                    for rtol in (RTOLS[1:3] if quick else RTOLS)]
        else:
            runs = [(f"dt {dt:g}", dt, {}) for dt in ((STEPS[2],) if integrator == "event_driven" else steps)]
        for setting, dt, keywords in runs:
            try:
                seconds, obs = core_run(scenario, integrator, dt, **keywords)
            except ModelError as exc:  # e.g. a reading the integrator does not run
                log(f"  {method:17s} {setting:13s} refused: {exc}")
                break
            err = errors(scenario, obs, ref)
            rows.append((method, setting, seconds, accuracy(scenario, err), err))
            log(f"  {method:17s} {setting:13s} {seconds:9.4f} s  error {accuracy(scenario, err):.2e}")
    if scenario.model != "A" and not quick:
        refine_euler(scenario, rows, ref, floor, log)
    for method, tolerances in PEERS.items():
        for rtol in (tolerances[:2] if quick else tolerances):
            seconds, obs = scipy_run(scenario, Solver(method, rtol, rtol * 1e-2))
            err = errors(scenario, obs, ref)
            rows.append((f"solve_ivp {method}", f"rtol {rtol:g}", seconds, accuracy(scenario, err), err))
            log(f"  solve_ivp {method:7s} rtol {rtol:<6g} {seconds:9.4f} s  error {accuracy(scenario, err):.2e}")
    return rows, floor


def refine_euler(scenario: Scenario, rows: list, ref: dict, floor: float, log) -> None:
    """symplectic_euler at EULER_FINE steps until it reaches the equal-accuracy level, or its
    run already costs EULER_BOUND x adaptive's time at that level (which bounds the ratio
    from below by a measured run), or the next run would exceed EULER_CAP."""
    level = max(ACCURACY, floor)
    t_adaptive, _ = time_at_accuracy(rows, "adaptive", level)
    for dt in EULER_FINE:
        euler = [r for r in rows if r[0] == "symplectic_euler"]
        if not euler or math.isinf(t_adaptive) or min(r[3] for r in euler) <= level:
            return
        last_seconds = max(r[2] for r in euler)
        last_dt = min(float(r[1].split()[1]) for r in euler)
        if last_seconds >= EULER_BOUND * t_adaptive or last_seconds * last_dt / dt > EULER_CAP:
            return
        seconds, obs = core_run(scenario, "symplectic_euler", dt)
        err = errors(scenario, obs, ref)
        rows.append(("symplectic_euler", f"dt {dt:g}", seconds, accuracy(scenario, err), err))
        log(f"  {'symplectic_euler':17s} {f'dt {dt:g}':13s} {seconds:9.4f} s  error {accuracy(scenario, err):.2e}")


def time_at_accuracy(rows, method, level):
    """Wall time a method needs to reach `level`: its fastest run at or below it; else the
    least-squares line of log time against log error through all its runs, extrapolated
    (marked so) if the error falls with cost; else inf (not reached)."""
    runs = [(err, sec) for name, _, sec, err, _ in rows if name == method and err > 0.0]
    good = [sec for err, sec in runs if err <= level]
    if good:
        return min(good), False
    if len(runs) < 2:
        return math.inf, True
    slope, intercept = np.polyfit(np.log([e for e, _ in runs]), np.log([t for _, t in runs]), 1)
    if slope >= 0.0:
        return math.inf, True
    return float(np.exp(intercept + slope * math.log(level))), True


def ratio(numerator: float, denominator: float) -> str:
    return "n/a" if math.isinf(numerator) or denominator <= 0.0 else f"{numerator / denominator:,.0f}x"


def share(numerator: float, denominator: float) -> str:
    """A ratio near 1, to two digits."""
    return "n/a" if math.isinf(numerator) or denominator <= 0.0 else f"{numerator / denominator:.2g}x"


def adaptive_targets(results):
    """adaptive against event_driven on A; against symplectic_euler and solve_ivp on B, C."""
    lines = []
    for name, (rows, floor) in results.items():
        if "chaotic" in name:
            continue
        level = max(ACCURACY, floor)
        t_adaptive, ext_a = time_at_accuracy(rows, "adaptive", level)
        tight = sorted([r for r in rows if r[0] == "adaptive"], key=lambda r: r[3])[0]
        if name.startswith("A"):
            ed = [r for r in rows if r[0] == "event_driven"][0]
            t_own, ext_o = time_at_accuracy(rows, OWN_STEPS, level)
            own = sorted([r for r in rows if r[0] == OWN_STEPS], key=lambda r: r[3])[0]
            lines.append(f"- **{name}**: adaptive at {level:.0e}: {t_adaptive * 1e3:.3g} ms"
                         f"{' (extrapolated)' if ext_a else ''} vs event_driven {ed[2] * 1e3:.3g} ms (error "
                         f"{ed[3]:.1e}): {share(t_adaptive, ed[2])} its time (target <= 10x); adaptive's tightest "
                         f"run ({tight[1]}) error {tight[3]:.1e}. On its own steps (exact_flows off): "
                         f"{t_own * 1e3:.3g} ms{' (extrapolated)' if ext_o else ''}, {ratio(t_own, ed[2])}; "
                         f"tightest ({own[1]}) error {own[3]:.1e}, {own[2] * 1e3:.3g} ms.")
            continue
        parts = [f"- **{name}** at {level:.0e}: adaptive {t_adaptive * 1e3:.3g} ms"
                 f"{' (extrapolated)' if ext_a else ''}"]
        for label, methods, target in (("symplectic_euler", ["symplectic_euler"], 100),
                                       ("solve_ivp", [f"solve_ivp {m}" for m in PEERS], 30)):
            reached = [(sec, method) for method in methods for m, _, sec, err, _ in rows
                       if m == method and err <= level]
            if reached:
                sec, method = min(reached)
                parts.append(f"{method} measured {sec:.3g} s: {ratio(sec, t_adaptive)} (target >= {target}x)")
            else:
                # Reaching the level takes more than any of its runs: finer settings than all
                # of them.  So its longest run bounds the ratio from below.
                longest = max([r for r in rows if r[0] in methods], key=lambda r: r[2])
                best = min([r for r in rows if r[0] in methods], key=lambda r: r[3])
                parts.append(f"{label} never reached it (its best error {best[3]:.1e}); its longest run "
                             f"({longest[0]}, {longest[1]}, error {longest[3]:.1e}, {longest[2]:.3g} s) already "
                             f"takes {ratio(longest[2], t_adaptive)} adaptive's time (a lower bound; target >= "
                             f"{target}x)")
        lines.append("; ".join(parts) + ".")
    return lines


def targets(results):
    lines = []
    for name, (rows, floor) in results.items():
        if not name.startswith("A") or "chaotic" in name:
            continue
        ed = [r for r in rows if r[0] == "event_driven"][0]
        euler = sorted([r for r in rows if r[0] == "symplectic_euler"], key=lambda r: r[3])[0]
        best_peer = sorted([r for r in rows if r[0].startswith("solve_ivp")], key=lambda r: r[3])[0]
        level = max(ACCURACY, ed[3])
        t_euler, ext_e = time_at_accuracy(rows, "symplectic_euler", level)
        t_peer, ext_p, peer_name = min((*time_at_accuracy(rows, f"solve_ivp {m}", level), m) for m in PEERS)
        lines.append(f"**{name}**: event_driven {ed[2] * 1e3:.2f} ms, error {ed[3]:.1e} (reference floor "
                     f"{floor:.1e}).")
        lines.append(f"- vs symplectic_euler, measured: its most accurate run ({euler[1]}, error {euler[3]:.1e}, "
                     f"{euler[2]:.3g} s) is {euler[2] / ed[2]:,.0f}x slower and less accurate (target >= 1000x).")
        if math.isinf(t_euler):
            lines.append(f"- vs symplectic_euler at equal accuracy {level:.0e}: not reached by its runs.")
        else:
            lines.append(f"- vs symplectic_euler at equal accuracy {level:.0e}: {t_euler:.3g} s"
                         f"{' (extrapolated along the fit of its runs)' if ext_e else ''}: "
                         f"{t_euler / ed[2]:,.0f}x.")
        lines.append(f"- vs solve_ivp, measured: its most accurate run ({best_peer[0]}, {best_peer[1]}, error "
                     f"{best_peer[3]:.1e}, {best_peer[2]:.3g} s) is {best_peer[2] / ed[2]:,.0f}x slower "
                     f"(target >= 100x).")
        if math.isinf(t_peer):
            lines.append(f"- vs solve_ivp at equal accuracy {level:.0e}: no run reached it.")
        else:
            lines.append(f"- vs solve_ivp at equal accuracy {level:.0e}: fastest is {peer_name}, {t_peer:.3g} s"
                         f"{' (extrapolated)' if ext_p else ''}: {t_peer / ed[2]:,.0f}x.")
    return lines


# ----------------------------------------------------------------------------- output
def write_outputs(results, out: Path, total: float):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(results)
    n_rows = (len(names) + 1 + 3) // 4
    fig, axes = plt.subplots(n_rows, 4, figsize=(18, 4.25 * n_rows))
    styles = {"symplectic_euler": ("o-", "tab:blue"), "rk4": ("s-", "tab:orange"), "event_driven": ("*", "tab:red"),
              "implicit_contact": ("d-", "tab:purple"), "adaptive": ("h-", "tab:cyan"),
              OWN_STEPS: ("h:", "tab:gray"),
              "solve_ivp RK45": ("^--", "tab:green"), "solve_ivp DOP853": ("<--", "tab:pink"),
              "solve_ivp LSODA": ("v--", "tab:olive"), "solve_ivp Radau": ("x--", "tab:brown"),
              "reference DOP853": ("P", "black")}
    for ax, name in zip(axes.flat, names):
        rows, floor = results[name]
        methods = dict.fromkeys(r[0] for r in rows)
        for method in methods:
            pts = sorted((r[2], max(r[3], 1e-16)) for r in rows if r[0] == method)
            style, color = styles.get(method, (".-", "gray"))
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, color=color, label=method,
                      ms=12 if method == "event_driven" else 5)
        ax.axhline(max(floor, 1e-16), color="gray", lw=0.8, ls=":")
        ax.set_title(name + (": energy residual" if "chaotic" in name else ": pointwise at the end"), fontsize=10)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("|residual| / dissipated" if "chaotic" in name else "error")
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat[:-1]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    axes.flat[-1].legend(handles, labels, loc="center", fontsize=10, title="dotted: reference floor")
    fig.suptitle("Work-precision: error against wall time (one process, measured side by side)")
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "work_precision.png", dpi=130)

    lines = ["# Work-precision benchmark", "",
             "Regenerate: `python -m harness.benchmarks.work_precision` (writes this file and "
             "`work_precision.png`). All runs in one process, side by side; wall times on this machine "
             f"(total {total:.0f} s). Errors against `harness.paper.reference` (DOP853, rtol = atol = 1e-12, restarts at "
             "each switch, switches sought at 16 points per step; the floor is its change from 1e-11). Peers: "
             "scipy's RK45, LSODA, Radau with solve_ivp's event detection (sign at the step ends). "
             "Non-chaotic scenarios: largest of the relative errors of x and phi and the error of z (delta_0) "
             "at the end; `A bouncing (chaotic)`: largest of the errors of the mean drift velocity and phi "
             "(relative) and of the contact fraction, and the energy residual relative to the energy "
             "dissipated, over [200, 4000].", ""]
    for name, (rows, floor) in results.items():
        lines += [f"## {name}", ""]
        if "chaotic" in name:
            lines += ["Plotted: the energy residual. The statistics agree only to the noise of a finite window: "
                      "the reference's own spread (1e-11 against 1e-12) is in its row.", ""]
        lines += ["| method | setting | wall time [s] | error | per observable |", "|---|---|---|---|---|"]
        for method, setting, seconds, err, parts in rows:
            detail = ", ".join(f"{k} {v:.1e}" for k, v in parts.items())
            lines.append(f"| {method} | {setting} | {seconds:.4g} | {err:.2e} | {detail} |")
        lines.append("")
    lines += ["## Targets (model A, equal accuracy)", ""] + targets(results) + [""]
    lines += ["## Targets of adaptive (equal accuracy)", ""] + adaptive_targets(results) + [""]
    (out / "work_precision.md").write_text("\n".join(lines))
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    parser.add_argument("--quick", action="store_true", help="fewer steps and tolerances (a smoke run)")
    parser.add_argument("--only", default="", help="run only the scenarios whose name starts with this")
    args = parser.parse_args(argv)
    os.environ.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".cache" / "numba"))
    started = time.perf_counter()
    results = {}
    for scenario in SCENARIOS:
        if not scenario.name.startswith(args.only):
            continue
        print(f"{scenario.name}: model {scenario.model}, t = {scenario.horizon:g}, {scenario.parameters}", flush=True)
        results[scenario.name] = measure(scenario, args.quick, lambda s: print(s, flush=True))
    total = time.perf_counter() - started
    lines = write_outputs(results, args.out, total)
    print("\n".join(lines[lines.index("## Targets (model A, equal accuracy)"):]))
    print(f"saved {args.out / 'work_precision.png'} and {args.out / 'work_precision.md'} ({total:.0f} s)")


if __name__ == "__main__":
    from harness.benchmarks import recorded

    with recorded("work_precision"):
        main()
