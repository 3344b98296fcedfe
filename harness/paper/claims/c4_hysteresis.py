"""C4 -- model A: hysteresis in omega, continuation up then down at fixed A for several gamma_n.

Criterion: omega_1 (first sliding value going up) spreads over at most one ramp step
across gamma_n; omega* (highest value held by friction on the way down; below the ramp
if none) < omega_1 for every gamma_n; the gap omega_1 - omega* never grows with gamma_n
and shrinks overall.

The down ramp reaches below the bouncing-ball floor of each gamma_n
(:func:`harness.paper.analytic.bouncing_floor_omega`: Gamma* = A omega*^2/g =
pi (1 - e)/(1 + e), e the contact's restitution), where the bouncing branch must end; the
report gives, per gamma_n, the floor and whether it lies between omega* and the next
value of the down ramp (not part of the verdict: the floor is our prediction, not the
paper's claim)."""
from __future__ import annotations

import numpy as np

from harness.runs.continuation import Ramp
from harness.runs.settings import InitialCondition, ObservableSettings, PointSettings
from harness.runs.sweep import Axis, Grid

from harness.paper.analytic import bouncing_floor_omega, restitution

from .measure import SCALED, first_sliding, friction_held, observe_json, onset_omega, ramp_task
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, Row, combine, fmt

TEXT = {
    "C4": "A: hysteresis in omega: omega_1 independent of gamma_n, omega*(gamma_n) < omega_1, omega* "
          "-> omega_1 as gamma_n grows",
}
FIGURES = {
    "C4": ["hysteresis_gamma_n.png"],
}


def _ramp_branches(loop: dict) -> tuple[float | None, float | None]:
    """omega_1: first sliding value going up; omega*: the highest value of the down branch
    held by friction (where friction comes back on the way down)."""
    up = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "up"]
    down = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "down"]
    omega_1 = first_sliding([v for v, _ in up], [r for _, r in up])
    held_down = [v for v, r in down if friction_held(r)]
    omega_star = max(held_down) if held_down else None
    return omega_1, omega_star


def _above(values, value: float | None) -> float | None:
    """The ramp value next above ``value`` (None if there is none or value is None)."""
    higher = [v for v in values if value is not None and v > value]
    return min(higher) if higher else None


def study_c4(runner: Runner) -> Study:
    """Model A: continuation in omega up then down at fixed A for several gamma_n; fresh starts."""
    res = runner.resolution
    amplitude = 10.0
    step_observe = ObservableSettings(transient=2000.0)
    ramp = Ramp("omega", res.c4_omegas)
    items = []
    for gamma_n in res.c4_gammas:
        run = runner.run("A", parameters={**SCALED, "A": amplitude, "gamma_n": gamma_n}, horizon=res.c4_step)
        items.append({"point": PointSettings(run=run, observe=step_observe), "ramp": ramp})
    loops = runner.tasks(ramp_task, items)
    middle_gamma = res.c4_gammas[len(res.c4_gammas) // 2]
    fresh = {}
    for kind in ("steady_orbit", "equilibrium"):
        base = PointSettings(run=runner.run("A", parameters={**SCALED, "A": amplitude, "gamma_n": middle_gamma},
                                            horizon=res.c4_step, initial=InitialCondition(kind)),
                             observe=step_observe)
        ds = runner.sweep(Grid((Axis("omega", res.c4_omegas),)), base)
        fresh[kind] = ds.regime.values.tolist()
    per_gamma = []
    for gamma_n, loop in zip(res.c4_gammas, loops):
        omega_1, omega_star = _ramp_branches(loop)
        floor = float(bouncing_floor_omega(amplitude, gamma_n=gamma_n))
        # The bouncing branch ends between w* (held) and the next value above it (still sliding).
        top = _above(res.c4_omegas, omega_star)
        per_gamma.append({"gamma_n": gamma_n, "omega_1": omega_1, "omega_star": omega_star,
                          "onset_omega": onset_omega(amplitude, gamma_n),
                          "restitution": float(restitution(gamma_n=gamma_n)), "floor_omega": floor,
                          "branch_end": [omega_star, top], "floor_bracketed": None if omega_star is None or top is None
                          else bool(omega_star < floor <= top), "down_to": float(min(res.c4_omegas))})
    middle = loops[res.c4_gammas.index(middle_gamma)]
    down = {v: r for d, v, r in zip(middle["direction"], middle["value"], middle["regime"]) if d == "down"}
    up = {v: r for d, v, r in zip(middle["direction"], middle["value"], middle["regime"]) if d == "up"}
    differs = [float(v) for v, r in zip(res.c4_omegas, fresh["steady_orbit"])
               if v in down and friction_held(down[v]) != friction_held(r)]
    impact_differs = [float(v) for v, r in zip(res.c4_omegas, fresh["equilibrium"])
                      if friction_held(up[v]) != friction_held(r)]
    measured = {"amplitude": amplitude, "omega_step": float(np.min(np.diff(res.c4_omegas))) if len(res.c4_omegas) > 1
                else None, "per_gamma": per_gamma, "fresh_gamma_n": middle_gamma,
                "fresh_steady_orbit": fresh["steady_orbit"], "fresh_equilibrium": fresh["equilibrium"],
                "omegas": list(res.c4_omegas), "down_differs_from_fresh_orbit": differs,
                "up_differs_from_fresh_impact": impact_differs}
    settings = {"model": "A", "parameters": "scaled", "A": amplitude, "step_duration": res.c4_step,
                "initial": "steady orbit at the first ramp value; fresh starts: steady orbit and equilibrium (impact)",
                **observe_json(step_observe)}
    data = {"loops": [{"gamma_n": g, **loop} for g, loop in zip(res.c4_gammas, loops)]}
    return Study("C4", measured, settings, data)


def verdict_c4(m: dict) -> Row:
    per = m["per_gamma"]
    measured = "; ".join(f"gamma_n = {p['gamma_n']:g}: w1 = {fmt(p['omega_1'])}, w* = {fmt(p['omega_star'])} "
                         f"(A_c onset {fmt(p['onset_omega'])}{_floor_text(p)})" for p in per)
    steps = np.diff(sorted(m["omegas"]))
    measured += (f"; A = {m['amplitude']:g}, ramp {fmt(min(m['omegas']))} to {fmt(max(m['omegas']))} in steps of "
                 f"{fmt(min(steps)) if len(steps) else 'n/a'}{'' if len(steps) == 0 or np.ptp(steps) < 1e-9 else ' to ' + fmt(max(steps))}. Fresh starts (gamma_n = {m['fresh_gamma_n']:g}) "
                 f"differ from the down ramp at w = {m['down_differs_from_fresh_orbit'] or 'none'}; impact starts "
                 f"differ from the up ramp at w = {m['up_differs_from_fresh_impact'] or 'none'}")
    omega_1 = [p["omega_1"] for p in per]
    if any(v is None for v in omega_1):
        return Row("C4", measured, NOT_REPRODUCED, "no sliding reached on some up ramp")
    # Spread in ramp steps, counted on the ramp's own (possibly uneven) grid.
    positions = [sorted(m["omegas"]).index(w) for w in omega_1]
    spread = max(positions) - min(positions)
    parts = [(AGREES if spread <= 1 else DISAGREES,
              f"w1 spread {max(omega_1) - min(omega_1):.3g} over gamma_n ({spread} ramp step(s))")]
    gaps = [p["omega_1"] - p["omega_star"] if p["omega_star"] is not None else None for p in per]
    # No friction anywhere on the way down: w* lies below the ramp, still below w1.
    hysteretic = [g is None or g > 1e-9 for g in gaps]
    parts.append((AGREES if all(hysteretic) else DISAGREES,
                  f"w* < w1 for {sum(hysteretic)}/{len(per)} gamma_n"))
    if all(g is not None for g in gaps) and len(gaps) > 1:
        shrinking = all(b <= a + 1e-9 for a, b in zip(gaps[:-1], gaps[1:])) and gaps[-1] < gaps[0]
        parts.append((AGREES if shrinking else DISAGREES,
                      "gap w1 - w* vs gamma_n: " + ", ".join(fmt(g) for g in gaps)))
    else:
        parts.append((NOT_REPRODUCED, "w* missing for some gamma_n (friction never back on the down ramp)"))
    verdict, reason = combine(parts)
    floors = [p for p in per if "floor_omega" in p]
    if floors:
        inside = sum(bool(p["floor_bracketed"]) for p in floors)
        reason += (f". Bouncing-ball floor between w* and the next ramp value for {inside}/{len(floors)} gamma_n "
                   "(our prediction, not part of the verdict)")
    return Row("C4", measured, verdict, reason)


def _floor_text(p: dict) -> str:
    if "floor_omega" not in p:
        return ""
    if p["floor_bracketed"]:
        where = "between w* and the next ramp value"
    elif p["omega_star"] is None:
        where = "no friction back on the down ramp"
    elif p["floor_bracketed"] is None:
        where = "not bracketed (held at the top of the down ramp)"
    elif p["floor_omega"] <= p["omega_star"]:
        where = "the branch ended above it"
    else:
        where = "the branch survived below it"
    return (f"; bouncing-ball floor {fmt(p['floor_omega'])} from e = {fmt(p['restitution'], 4)}, {where}; "
            f"ramp down to {fmt(p['down_to'])}")


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    loops = study.data["loops"]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for number, loop in enumerate(loops):
        color = f"C{number}"
        for direction, face, marker in (("up", color, "s"), ("down", "none", "o")):
            pairs = [(v, p) for d, v, p in zip(loop["direction"], loop["value"], loop["phi"]) if d == direction]
            if pairs:
                v, p = zip(*pairs)
                ax.plot(v, np.maximum(p, 1e-3), marker=marker, color=color, markerfacecolor=face,
                        label=f"$\\gamma_n$ = {loop['gamma_n']:g} ({direction})")
        ax.axvline(float(bouncing_floor_omega(study.measured["amplitude"], gamma_n=loop["gamma_n"])), color=color,
                   ls=":", lw=0.8)
    ax.set(yscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel=r"$\phi$ [1]",
           title=f"Model A, A = {study.measured['amplitude']:g}: ramp up then down (dotted: bouncing-ball floor)")
    ax.legend(fontsize="x-small", ncol=2)
    save(fig, "hysteresis_gamma_n.png")


CLAIM = Claim("C4", study_c4, verdict_c4, TEXT, FIGURES, draw)
