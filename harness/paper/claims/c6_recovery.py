"""C6 -- model C (confining load): both transitions in the A-omega plane, friction recovery at omega_2.

Each A row of the diagram brackets its friction loss (omega_1) and recovery (omega_2)
on the omega grid; both brackets are then bisected in omega to ``BOUNDARY_RESOLUTION``
(all rows per round in one batch), and the verdicts judge the located values.

Criteria: C6a: k_t = 0 run not in stick-slip.  C6b: in every A row that loses friction,
sqrt(P_l/(m A)) lies within FORMULA_TOLERANCE of the located omega_1 (inside the grid
bracket where nothing was located).  C6c: every row that loses friction regains it, the
located omega_2 lies within ``RECOVERY_SLACK`` of k_n/gamma_n (the paper says "about"),
and the rows' omega_2 agree within UNCHANGED_TOLERANCE of their mean ("independent of
A").  C6d: at each k_n/gamma_n, omega_2 (in units of k_n/gamma_n) spreads over at most
one grid step across k_n.  C6e: up and down ramps regain friction at the same omega.

Start phases and horizon: the diagram's points start on a crest and their window sees a
quarter of a corrugation wavelength of drive travel.  In the default reading (in every
reading with ``Runner.ensembles_every_reading``, ``python -m harness.main
--ensembles-every-reading``), both sides
of the located omega_1 and omega_2 of the lowest A row are run again from four start
phases (crest, descending flank, valley, ascending flank) over
``Resolution.ensemble_wavelengths`` wavelengths (3 by default); where a side's class
(friction held or not) differs between starts or from the diagram's, the located
boundary is not a property of the model at this horizon and C6b/C6c say "not
reproduced" with the regimes found, whatever the formula comparison gave."""
from __future__ import annotations

import math

import numpy as np

from harness.paper.plots import regime_grid
from harness.runs.bisection import Transition, refine
from harness.runs.continuation import Ramp
from harness.runs.observables import PHI_STICK_SLIP
from harness.runs.settings import PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import (C_PARAMETERS, C_START, OBSERVE_SHORT, SCALED_FIGURE_NOTE, c_run, ensemble_agrees,
                      friction_held, loss_amplitude, observe_json, onset_amplitude, onset_omega, ramp_task, recovery,
                      run_and_measure, start_ensemble)
from .study import Claim, Runner, Study
from .readings import DEFAULT_READING, READINGS
from .verdicts import (AGREES, DISAGREES, FORMULA_TOLERANCE, NOT_REPRODUCED, UNCHANGED_TOLERANCE, Row, combine,
                       fmt, relative)

RECOVERY_SLACK = 0.25
BOUNDARY_RESOLUTION = 0.03  # relative width in omega to which both transitions are bisected

TEXT = {
    "C6a": "C: no stick-slip with k_t = 0",
    "C6b": "C: first transition at A = P_l/(m omega^2)",
    "C6c": "C: friction recovery at omega_2 ~ k_n/gamma_n, independent of A",
    "C6d": "C: omega_2 weakly dependent on k_n at fixed k_n/gamma_n",
    "C6e": "C: no hysteresis at omega_2",
}
FIGURES = {
    "C6a": [],
    "C6b": ["model_c_phase_diagram.png", "start_ensemble.png"],
    "C6c": ["model_c_phase_diagram.png", "start_ensemble.png"],
    "C6d": ["omega2_vs_k_n.png"],
    "C6e": ["model_c_phase_diagram.png"],
}


def study_c6(runner: Runner) -> Study:
    """Model C: k_t = 0, both transitions in the A-omega plane, omega_2 vs k_n, ramp across omega_2."""
    res = runner.resolution
    observe_c = OBSERVE_SHORT
    # k_t = 0 and the ramp across omega_2 run as tasks, in parallel.
    k_t_zero = {"point": PointSettings(run=c_run(runner, max(res.c_horizon, 8000.0), A=0.0, k_t=0.0),
                                       observe=observe_c), "extras": ["trace"]}
    ramp_amplitude = 0.5
    # The ramp runs across the linear theory's recovery (the upper A_c root at this A) as
    # well as across k_n/gamma_n.
    ramp_theory = theory_roots(ramp_amplitude)
    ramp_values = tuple(sorted(set(res.c6_ramp) | {round(w * f, 4) for w in ramp_theory["A_c_roots"][1:]
                                                     for f in (1 / BRACKET, 1.0, BRACKET)}))
    ramp_item = {"point": PointSettings(run=c_run(runner, res.c6_ramp_step, A=ramp_amplitude), observe=observe_c),
                 "ramp": Ramp("omega", ramp_values)}
    # Under a law reading C6 measures Fig. 5's diagram (C6a-C6c), the part the report's
    # table "which readings and laws reproduce the paper" asks of every law; C6d's k_n sweep
    # and C6e's ramp, each as costly as the diagram, stay with the paper's readings.
    fig5_only = runner.reading not in READINGS
    [frictionless] = runner.tasks(run_and_measure, [k_t_zero])
    loop = None if fig5_only else runner.tasks(ramp_task, [ramp_item])[0]

    base = PointSettings(run=c_run(runner, res.c_horizon), observe=observe_c)
    diagram = runner.sweep(Grid((Axis("A", res.c6_amplitudes), Axis("omega", res.c6_omegas))), base)
    rows = []
    for amplitude in diagram.A.values:
        theory = theory_roots(float(amplitude))
        omegas, regimes = _bracketing(runner, base, {"A": float(amplitude)}, diagram.omega.values.tolist(),
                                      diagram.regime.sel(A=amplitude).values.tolist(), theory["bracketed"])
        found = recovery(omegas, regimes)
        rows.append({"A": float(amplitude), "omegas": omegas, "regimes": regimes, **found,
                     "first_transition_paper": math.sqrt(1.0 / float(amplitude)),
                     "first_transition_onset": onset_omega(float(amplitude), 0.07), "theory": theory})
    _locate_transitions(runner, base, rows)
    # A boundary that depends on the start is no property of the model in any reading; the
    # other readings' ensembles run on request (Runner.ensembles_every_reading).
    ensemble = (_check_by_start_ensemble(runner, rows, res.ensemble_wavelengths)
                if res.ensemble_wavelengths > 0
                and (runner.reading == DEFAULT_READING or runner.ensembles_every_reading) else None)

    stiffness_amplitude = 0.5
    base_k = PointSettings(run=c_run(runner, res.c_horizon, A=stiffness_amplitude), observe=observe_c)
    grid_k = Grid((Axis("ratio", res.c6_ratios), Axis("k_n", res.c6_stiffnesses),
                   Axis("relative_omega", res.c6_relative_omegas)),
                  derived={"gamma_n": "k_n / ratio", "omega": "relative_omega * ratio"})
    stiff = None if fig5_only else runner.sweep(grid_k, base_k)
    recovery_vs_k = []
    for ratio in ([] if fig5_only else stiff.ratio.values):
        for k_n in stiff.k_n.values:
            theory = theory_roots(stiffness_amplitude, k_n=float(k_n), gamma_n=float(k_n / ratio))
            omegas, regimes = _bracketing(runner, base_k, {"k_n": float(k_n), "gamma_n": float(k_n / ratio)},
                                          (stiff.relative_omega.values * ratio).tolist(),
                                          stiff.regime.sel(ratio=ratio, k_n=k_n).values.tolist(), theory["bracketed"])
            found = recovery(omegas, regimes)
            recovery_vs_k.append({"ratio": float(ratio), "k_n": float(k_n), "regimes": regimes, "omegas": omegas,
                                  **found, "theory": theory})

    loop = loop or {"direction": [], "value": [], "regime": []}
    up = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "up"]
    down = [(v, r) for d, v, r in zip(loop["direction"], loop["value"], loop["regime"]) if d == "down"]
    up_rec = recovery([v for v, _ in up], [r for _, r in up])
    # Coming down from high omega, friction is lost at the highest sliding value.
    down_sliding = [v for v, r in down if not friction_held(r)]
    down_friction_above = [v for v, r in down if friction_held(r) and (not down_sliding or v > max(down_sliding))]
    measured = {
        "k_n_over_gamma_n": 1.0 / 0.07,
        "frictionless": {"regime": frictionless["observables"]["regime"],
                         "slip_events": frictionless["observables"]["slip_events"],
                         "phi": frictionless["observables"]["phi"],
                         "drift_velocity": frictionless["observables"]["drift_velocity"]},
        "diagram_rows": rows, "omegas": diagram.omega.values.tolist(), "resolution": BOUNDARY_RESOLUTION,
        "stiffness_amplitude": stiffness_amplitude, "recovery_vs_k": recovery_vs_k,
        "ramp_amplitude": ramp_amplitude, "ramp_values": list(ramp_values), "ramp_theory": ramp_theory,
        "ramp_up_omega_2": up_rec["omega_2"],
        "ramp_down_omega_2": min(down_friction_above) if down_friction_above else None,
        "ramp_up_regimes": [r for _, r in up], "ramp_down_regimes": [r for _, r in down],
        "start_ensemble": ensemble, "fig5_only": fig5_only,
    }
    settings = {"model": "C", "parameters": C_PARAMETERS, "horizon": res.c_horizon, "initial": C_START,
                "ramp_step": res.c6_ramp_step, **observe_json(observe_c),
                "friction": "regime stick_slip, micro_slip, stuck or jammed (not sliding, hopping or flying)"}
    data = {"omega": diagram.omega.values.tolist(), "A": diagram.A.values.tolist(),
            "regime": diagram.regime.transpose("A", "omega").values.tolist(),
            "recovery_vs_k": recovery_vs_k, "loop": loop}
    return Study("C6", measured, settings, data)


BRACKET = 1.1  # extra omegas at each predicted root / and * this factor


def theory_roots(amplitude: float, k_n: float = 1.0, gamma_n: float = 0.07, load: float = 1.0) -> dict:
    """What linear theory predicts for a row at plate amplitude ``amplitude`` (m = 1): the
    paper's first transition sqrt(P_l/(m A)), the roots of A_c(omega) = A (detachment:
    friction lost between the lower and regained at the upper with the applied-load
    bound) and of A_N(omega) = A (the contact force's zero, the same with the
    contact-force bound), and k_n/gamma_n; ``bracketed``: the omegas the row must run
    so that each prediction lies between two of its runs."""
    from .c6r_recovery_question import crossings

    a_c = crossings(lambda w: onset_amplitude(w, load, 1.0, k_n, gamma_n), amplitude)
    a_n = crossings(lambda w: loss_amplitude(w, load, 1.0, k_n, gamma_n), amplitude)
    paper = math.sqrt(load / amplitude)
    predicted = [paper, *a_c, *a_n]
    return {"paper_omega_1": paper, "A_c_roots": a_c, "A_N_roots": a_n, "k_n_over_gamma_n": k_n / gamma_n,
            "bracketed": sorted({round(w * f, 4) for w in predicted for f in (1 / BRACKET, BRACKET)})}


def _bracketing(runner: Runner, base: PointSettings, where: dict, omegas: list, regimes: list, extra: list):
    """The row's omegas and regimes with the runs at ``extra`` omegas inside the grid's range
    (cached tasks) merged in, ascending."""
    extra = [w for w in extra if min(omegas) < w < max(omegas) and w not in omegas]
    items = [{"point": PointSettings(run=base.run.with_parameters({**where, "omega": w}), observe=base.observe)}
             for w in extra]
    found = {float(w): r for w, r in zip(omegas, regimes)}
    found.update({w: r["observables"]["regime"] for w, r in zip(extra, runner.tasks(run_and_measure, items))})
    ordered = sorted(found)
    return ordered, [found[w] for w in ordered]


def _locate_transitions(runner: Runner, base: PointSettings, rows: list[dict]) -> None:
    """Bisect each row's loss bracket (last friction, omega_1] and recovery bracket
    (last sliding, omega_2] in omega; adds located_omega_1/2 and their brackets to the rows."""
    found = []
    for row in rows:
        if row["omega_1"] is not None and row["last_friction_before_1"] is not None:
            found.append(Transition(row["last_friction_before_1"], row["omega_1"], True, where={"A": row["A"]}))
        if row["omega_2"] is not None:
            found.append(Transition(row["last_sliding"], row["omega_2"], False, where={"A": row["A"]}))

    def classify(pairs):
        items = [{"point": PointSettings(run=base.run.with_parameters({"A": t.where["A"], "omega": w}),
                                         observe=base.observe)} for t, w in pairs]
        return [friction_held(r["observables"]["regime"]) for r in runner.tasks(run_and_measure, items)]

    refine(classify, found, BOUNDARY_RESOLUTION)
    for row in rows:
        for transition_name, held_lo in (("omega_1", True), ("omega_2", False)):
            t = next((t for t in found if t.where["A"] == row["A"] and t.held_lo == held_lo), None)
            row.update({f"located_{transition_name}": t.value if t else None,
                        f"located_{transition_name}_bracket": [t.lo, t.hi] if t else None})


def _check_by_start_ensemble(runner: Runner, rows: list[dict], wavelengths: float) -> dict | None:
    """Both sides of the located omega_1 and omega_2 of the lowest A row that has both,
    run from the four start phases over ``wavelengths`` corrugation wavelengths: the
    diagram's runs start on a crest and see a quarter of a wavelength, so a located
    boundary stands only if each side keeps its class from every start over a long window."""
    row = next((r for r in rows if r.get("located_omega_1_bracket") and r.get("located_omega_2_bracket")), None)
    if row is None:
        return None
    sides = []
    for transition, held_below in (("omega_1", True), ("omega_2", False)):
        below, above = row[f"located_{transition}_bracket"]
        sides += [(transition, "below", below, held_below), (transition, "above", above, not held_below)]
    found = start_ensemble(runner, [{"A": row["A"], "omega": omega} for _, _, omega, _ in sides], wavelengths)
    checks = [{"transition": transition, "side": side, "omega": omega, "held_expected": held, **entry,
               "agrees": ensemble_agrees(entry, held)}
              for (transition, side, omega, held), entry in zip(sides, found.pop("points"))]
    return {"A": row["A"], **found, "checks": checks}


def _ensemble_part(m: dict, transition: str) -> tuple[str, str] | None:
    """(verdict, text) of the start-ensemble check of one located transition: not
    reproduced when a side's class changes with the start or the longer window."""
    ensemble = m.get("start_ensemble")
    if not ensemble:
        return None
    checks = [c for c in ensemble["checks"] if c["transition"] == transition]
    where = (f"both sides of the located {transition} at A = {ensemble['A']:g}, from {len(ensemble['starts'])} "
             f"starts over {ensemble['wavelengths']:g} wavelengths")
    failing = [c for c in checks if not c["agrees"]]
    if not failing:
        return AGREES, f"{where} keep their class"
    detail = "; ".join(f"{c['side']} (w = {fmt(c['omega'])}, {'friction' if c['held_expected'] else 'sliding'} "
                       "in the diagram): " + ", ".join(f"{name} {s['regime']}" for name, s in c["starts"].items())
                       for c in failing)
    return NOT_REPRODUCED, (f"{where}: the class changes with the start or the window, so the diagram cannot "
                            f"locate it ({detail})")


def _ensemble_measured(m: dict) -> str:
    ensemble = m.get("start_ensemble")
    if not ensemble:
        return ""
    return f"; start ensemble at A = {ensemble['A']:g} ({ensemble['wavelengths']:g} wavelengths): " + ", ".join(
        f"{c['transition']} {c['side']} w = {fmt(c['omega'])}: "
        + "/".join(s["regime"] for s in c["starts"].values())
        + (f" (phi {fmt(c['phi_range'][0])}-{fmt(c['phi_range'][1])})" if c["phi_range"] else "")
        for c in ensemble["checks"])


def _with_ensemble(verdict: str, reason: str, part: tuple[str, str] | None) -> tuple[str, str]:
    """The verdict stands only where the start ensemble confirms the located boundary."""
    if part is None:
        return verdict, reason
    if part[0] == NOT_REPRODUCED:
        return NOT_REPRODUCED, f"{reason}; but {part[1]}"
    return verdict, f"{reason}; {part[1]}"


def _upper(roots: list) -> float | None:
    """The upper root of a band (friction regained there), None without a band."""
    return roots[1] if len(roots) >= 2 else None


def _theory_text(row: dict, recovery_only: bool = False) -> str:
    """What linear theory predicts for the row, beside what was measured."""
    theory = row.get("theory")
    if not theory:
        return ""
    a_c, a_n = theory["A_c_roots"], theory["A_N_roots"]
    if recovery_only:
        return (f" (theory: upper A_c root {fmt(_upper(a_c))} with the applied-load bound, upper A_N root "
                f"{fmt(_upper(a_n))} with the contact-force bound, k_n/gamma_n {theory['k_n_over_gamma_n']:.3g}"
                + ("; no band below delta_0, no recovery predicted" if len(a_c) < 2 else "") + ")")
    return (" [theory: A_c(w) = A at " + (", ".join(f"{w:.3g}" for w in a_c) or "none")
            + "; A_N(w) = A at " + (", ".join(f"{w:.3g}" for w in a_n) or "none") + "]")


def _near(row: dict, line: float) -> bool:
    """``line`` agrees with the row's first transition: within FORMULA_TOLERANCE of the located
    omega_1, or (nothing located) inside the grid bracket."""
    if row.get("located_omega_1") is not None:
        return relative(row["located_omega_1"], line) <= FORMULA_TOLERANCE
    return ((row["last_friction_before_1"] is None or row["last_friction_before_1"] <= line)
            and line <= row["omega_1"])


def _omega_2(row: dict) -> float | None:
    """The row's recovery: the located omega_2, or the grid value where nothing was located."""
    return row.get("located_omega_2") or row["omega_2"]


def verdict_c6(m: dict) -> list[Row]:
    rows = []
    free = m["frictionless"]
    measured = (f"k_t = 0, A = 0: regime {free['regime']}, phi {fmt(free['phi'])}, drift {fmt(free['drift_velocity'])}, "
                f"{free['slip_events']} slips")
    rows.append(Row("C6a", measured, DISAGREES if free["regime"] in PHI_STICK_SLIP else AGREES,
                    f"regime {free['regime']}"))

    diagram = m["diagram_rows"]
    losing = [r for r in diagram if r["omega_1"] is not None]
    measured = "; ".join(f"A = {r['A']:g}: friction lost at w in ({fmt(r['last_friction_before_1'])}, "
                         f"{fmt(r['omega_1'])}], located {fmt(r.get('located_omega_1'))} (sqrt(P_l/mA) = "
                         f"{r['first_transition_paper']:.3g}, A_c onset {fmt(r['first_transition_onset'])}), regained "
                         f"at {fmt(r['omega_2'])}, located {fmt(r.get('located_omega_2'))}" + _theory_text(r)
                         for r in diagram)
    measured += f" (located to {m.get('resolution', BOUNDARY_RESOLUTION):.0%} in omega)" + _ensemble_measured(m)
    if not losing:
        rows.append(Row("C6b", measured, NOT_REPRODUCED, "no row loses friction in the scanned omega range"))
    else:
        ok = [r for r in losing if _near(r, r["first_transition_paper"])]
        verdict, reason = _with_ensemble(
            AGREES if len(ok) == len(losing) else DISAGREES,
            f"sqrt(P_l/mA) within {FORMULA_TOLERANCE:.0%} of the located loss (or inside its grid bracket) in "
            f"{len(ok)}/{len(losing)} rows that lose friction", _ensemble_part(m, "omega_1"))
        rows.append(Row("C6b", measured, verdict, reason))

    ratio = m["k_n_over_gamma_n"]
    recovered = [r for r in losing if r["omega_2"] is not None]
    measured = (f"k_n/gamma_n = {ratio:.3g}; omega_2 per A: "
                + ", ".join(f"A = {r['A']:g}: {fmt(_omega_2(r))}" + _theory_text(r, recovery_only=True)
                            for r in losing))
    if not losing:
        rows.append(Row("C6c", measured, NOT_REPRODUCED, "no sliding region to recover from"))
    elif not recovered:
        rows.append(Row("C6c", measured, DISAGREES,
                        f"no row regains friction up to w = {max(m['omegas']):g}"))
    else:
        found = [_omega_2(r) for r in recovered]
        near = [w for w in found if relative(w, ratio) <= RECOVERY_SLACK]
        mean = float(np.mean(found))
        spread = max(relative(w, mean) for w in found)
        same = spread <= UNCHANGED_TOLERANCE
        parts = [(AGREES if len(recovered) == len(losing) else DISAGREES,
                  f"{len(recovered)}/{len(losing)} rows that lose friction regain it"),
                 (AGREES if len(near) == len(recovered) else DISAGREES,
                  f"omega_2 within {RECOVERY_SLACK:.0%} of k_n/gamma_n in {len(near)}/{len(recovered)}")]
        # Independence of A needs omega_2 at two amplitudes at least; with one row the
        # spread is 0 whatever was measured, a check that cannot fail: not counted, said so.
        untested = ""
        if len(recovered) >= 2:
            parts.append((AGREES if same else DISAGREES, f"omega_2 within {spread:.0%} of its mean over the rows "
                          f"(<= {UNCHANGED_TOLERANCE:.0%} counts as independent of A)"))
        else:
            untested = "; independence of A not tested (omega_2 found at one amplitude only)"
        verdict, reason = combine(parts)
        verdict, reason = _with_ensemble(verdict, reason + untested, _ensemble_part(m, "omega_2"))
        rows.append(Row("C6c", measured, verdict, reason))

    if m.get("fig5_only"):
        return rows  # C6d and C6e are measured under the paper's readings only (study_c6)
    by_ratio: dict[float, list] = {}
    for entry in m["recovery_vs_k"]:
        by_ratio.setdefault(entry["ratio"], []).append(entry)
    measured = "; ".join(f"k_n/gamma_n = {r:g}: " + ", ".join(
        f"k_n = {e['k_n']:g}: w2/(k_n/gamma_n) = {fmt(e['omega_2'] / r if e['omega_2'] else None)}"
        + (f" (w2 = {fmt(e['omega_2'])}; theory: upper A_c root {fmt(_upper(e['theory']['A_c_roots']))}, upper A_N "
           f"root {fmt(_upper(e['theory']['A_N_roots']))})" if e.get("theory") else "")
        for e in entries) + f" (A = {m['stiffness_amplitude']:g})" for r, entries in by_ratio.items())
    parts = []
    for r, entries in by_ratio.items():
        found = [e["omega_2"] / r for e in entries if e["omega_2"] is not None]
        if len(found) < len(entries):
            parts.append((NOT_REPRODUCED, f"ratio {r:g}: no recovery for {len(entries) - len(found)} k_n"))
            continue
        # The steps of every k_n's omegas at this ratio (the grid and the runs bracketing
        # each k_n's predicted roots).
        grid = sorted({round(o / r, 9) for e in entries for o in e["omegas"]})
        positions = [min(range(len(grid)), key=lambda i: abs(grid[i] - f)) for f in found]
        parts.append((AGREES if max(positions) - min(positions) <= 1 else DISAGREES,
                      f"ratio {r:g}: w2 spans {max(positions) - min(positions)} grid steps over k_n"))
    verdict, reason = combine(parts) if parts else (NOT_REPRODUCED, "no data")
    rows.append(Row("C6d", measured, verdict, reason))

    up, down = m["ramp_up_omega_2"], m["ramp_down_omega_2"]
    measured = (f"ramp at A = {m['ramp_amplitude']:g}, w = {m['ramp_values']}: up {m['ramp_up_regimes']}, down "
                f"{m['ramp_down_regimes']}; friction back at w = {fmt(up)} (up), held down to {fmt(down)} (down)"
                + (f"; theory at this A: friction lost and regained at the A_c roots "
                   + ", ".join(f"{w:.3g}" for w in m["ramp_theory"]["A_c_roots"]) + " (applied-load bound), A_N roots "
                   + ", ".join(f"{w:.3g}" for w in m["ramp_theory"]["A_N_roots"]) + " (contact-force bound), "
                   f"k_n/gamma_n = {m['ramp_theory']['k_n_over_gamma_n']:.3g}" if m.get("ramp_theory") else ""))
    if up is None or "sliding" not in m["ramp_up_regimes"]:
        rows.append(Row("C6e", measured, NOT_REPRODUCED, "the up ramp shows no sliding -> friction recovery"))
    else:
        rows.append(Row("C6e", measured, AGREES if up == down else DISAGREES,
                        "same recovery value up and down" if up == down else "recovery differs up and down"))
    return rows


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    d = study.data
    fig, ax = plt.subplots(figsize=(8.5, 4.5))
    regime_grid(ax, d["omega"], d["A"], d["regime"], onset_amplitude, r"$A = P_l/(m\omega^2)$",
                r"$A_c(\omega)$ with $P_l$", loss=loss_amplitude, loss_label=r"$A_N(\omega)$ with $P_l$")
    ax.axvline(study.measured["k_n_over_gamma_n"], color="tab:green", ls="--", label=r"$k_n/\gamma_n$")
    for key, marker, label in (("located_omega_1", "D", r"friction lost (bisected)"),
                               ("located_omega_2", "^", r"friction back (bisected)")):
        points = [(r[key], r["A"]) for r in study.measured["diagram_rows"] if r.get(key) is not None]
        if points:
            ax.plot(*zip(*points), marker, color="k", mfc="none", ls="none", label=label)
    ax.set(xscale="log", yscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel=r"$A$ [$\delta_0$]",
           title=f"Model C (the paper's Fig. 5)\n{SCALED_FIGURE_NOTE}")
    ax.title.set_fontsize(8)
    ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
    ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.01, 0.5))  # beside the grid, not over it
    save(fig, "model_c_phase_diagram.png")

    fig, ax = plt.subplots(figsize=(6, 4.5))
    by_ratio: dict[float, list] = {}
    for entry in d["recovery_vs_k"]:
        by_ratio.setdefault(entry["ratio"], []).append(entry)
    for number, (ratio, entries) in enumerate(by_ratio.items()):
        ks = [e["k_n"] for e in entries if e["omega_2"] is not None]
        ws = [e["omega_2"] for e in entries if e["omega_2"] is not None]
        ax.plot(ks, ws, "o-", color=f"C{number}", label=f"$k_n/\\gamma_n$ = {ratio:g}")
        missing = [e["k_n"] for e in entries if e["omega_2"] is None]
        if missing:
            ax.plot(missing, [ratio * 0.1] * len(missing), "x", color=f"C{number}")
        ax.axhline(ratio, color=f"C{number}", ls=":", lw=0.8)
    ax.set(xscale="log", yscale="log", xlabel=r"$k_n$ [$m_0/\tau_0^2$]", ylabel=r"$\omega_2$ [$\tau_0^{-1}$]",
           title="Friction recovery, the paper's Fig. 6 (x: none found; dotted: $k_n/\\gamma_n$)\n"
           + SCALED_FIGURE_NOTE)
    ax.title.set_fontsize(8)
    ax.legend(fontsize="small")
    save(fig, "omega2_vs_k_n.png")

    ensemble = study.measured.get("start_ensemble")
    if ensemble:
        save(draw_start_ensemble(ensemble), "start_ensemble.png")


def draw_start_ensemble(ensemble: dict):
    """The runs behind the default reading's C6b/C6c verdicts: each side of each located
    transition run from every start phase; phi per start, marked by regime, with whether
    the side was expected to be held by friction."""
    import matplotlib.pyplot as plt

    from harness.paper.plots import REGIME_STYLE

    checks = ensemble["checks"]
    starts = list(ensemble["starts"])
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    shown = set()
    for number, check in enumerate(checks):
        for offset, name in enumerate(starts):
            entry = check["starts"].get(name)
            if entry is None or entry["phi"] is None:
                continue
            style = REGIME_STYLE.get(entry["regime"], {"marker": "?", "color": "k", "label": entry["regime"]})
            x = number + (offset - (len(starts) - 1) / 2) * 0.15
            ax.scatter([x], [max(entry["phi"], 1e-3)], marker=style["marker"], color=style["color"],
                       label=None if entry["regime"] in shown else style["label"])
            shown.add(entry["regime"])
    ax.set_xticks(range(len(checks)), [f"{c['transition']} {c['side']}\n$\\omega$ = {c['omega']:.3g} "
                                       f"$\\tau_0^{{-1}}$\nexpected: {'held' if c['held_expected'] else 'not held'}"
                                       f"\n{'confirmed' if c['agrees'] else 'NOT confirmed'}" for c in checks],
                  fontsize=7)
    ax.set(yscale="log", ylabel=r"$\phi = \langle (v_x - V_d)^2 \rangle / V_d^2$ [1]",
           title=f"Model C, A = {ensemble['A']:g} $\\delta_0$: both sides of each located transition from "
                 f"{len(starts)} starts ({', '.join(starts)}; left to right)\nover {ensemble['wavelengths']:g} "
                 "corrugation wavelengths; the located boundary stands only where every start agrees")
    ax.title.set_fontsize(8)
    ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.01, 0.5))
    return fig


CLAIM = Claim("C6", study_c6, verdict_c6, TEXT, FIGURES, draw, readings=READINGS)
