"""Measured values -> verdicts, figures and ``out/report.md``.

Verdicts are computed here from the numbers a study measured (:mod:`harness.claims`),
never written by hand.  Each claim is split into parts that can be tested separately;
each part's function returns a :class:`Row` with the numbers it used, its verdict and
the reason.  Verdicts:

* ``agrees``: the criterion below holds;
* ``disagrees``: it was measured and does not hold;
* ``not reproduced``: the study could not measure what the criterion needs (e.g. no
  transition in the scanned range, no complete slip in the window).

Criteria (tolerances are the module constants):

* C1: each measured quantity within ``FORMULA_TOLERANCE`` (rest penetration:
  ``PENETRATION_TOLERANCE``) of its formula, relative.
* C2: at every A with A omega^2 < g, mean slip interval and slip length within
  ``UNCHANGED_TOLERANCE`` of their A = 0 values.
* C3a: every column with omega <= ``LOW_OMEGA`` has its friction/sliding boundary
  between the same two grid amplitudes as A = g/omega^2, and no column changes regime
  more than once along A.  C3b: the same bracket test for A_c(omega) on every column.
* C4: omega_1 (first sliding value going up) spreads over at most one ramp step across
  gamma_n; omega* (highest value held by friction on the way down; below the ramp if none) < omega_1 for every
  gamma_n; the gap omega_1 - omega* never grows with gamma_n and shrinks overall.
* C5a: at every A, mean slip interval and slip length within ``UNCHANGED_TOLERANCE`` of
  A = 0.  C5b: median distance of stuck samples from the nearest stable root of Eq. (9)
  below ``ROOT_TOLERANCE`` wavelengths (k_t = 0 run).  C5c: the k_t = 0 run is in stick-slip.
* C6a: k_t = 0 run not in stick-slip.  C6b: in every A row that loses friction, the grid
  omegas bracketing the loss contain sqrt(P_l/(m A)).  C6c: every row that loses
  friction regains it (omega_2) and k_n/gamma_n lies within ``RECOVERY_SLACK`` of the
  bracket [last sliding omega, omega_2]; omega_2 equal in all rows.  C6d: at each
  k_n/gamma_n, omega_2 (in units of k_n/gamma_n) spreads over at most one grid step
  across k_n.  C6e: up and down ramps regain friction at the same omega.
* C7: every (model, A) curve that leaves contact (contact fraction < ``EMBEDDED``)
  returns to it at higher omega.
* C8a: at the largest V_d every omega slides, in models A and C.  C8b: the measured x0
  within ``FORMULA_TOLERANCE`` of the paper's printed x0 = (gamma_t V_d - mu_s m g/2)/k_d.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from .claims import EMBEDDED, Study, friction_held

AGREES, DISAGREES, NOT_REPRODUCED = "agrees", "disagrees", "not reproduced"
FORMULA_TOLERANCE = 0.10
PENETRATION_TOLERANCE = 0.02
UNCHANGED_TOLERANCE = 0.10
LOW_OMEGA = 0.3
ROOT_TOLERANCE = 0.02
RECOVERY_SLACK = 0.25

CLAIM_TEXT = {
    "C1": "A, no vibration: rest penetration mg/k_n, creep V_S = V_d k_d/(k_t+k_d), stick time mu_s mg/(k_t V_S), "
          "slip mu_s mg/k_d",
    "C2": "A, max plate acceleration < g: stick-slip as at A = 0",
    "C3a": "A: stick-slip -> sliding at A omega^2 = g (omega << omega_n), the only transition in A",
    "C3b": "A: refined onset A_c(omega) = (g/omega^2)|k_n - m omega^2 + i gamma_n omega|/k_n",
    "C4": "A: hysteresis in omega: omega_1 independent of gamma_n, omega*(gamma_n) < omega_1, omega* -> omega_1 "
          "as gamma_n grows",
    "C5a": "B: horizontal motion unaffected by the vibration",
    "C5b": "B: stick positions are the stable roots of cos(omega_x x*) = K(x* - V_d t)",
    "C5c": "B: stick-slip even with k_t = 0",
    "C6a": "C: no stick-slip with k_t = 0",
    "C6b": "C: first transition at A = P_l/(m omega^2)",
    "C6c": "C: friction recovery at omega_2 ~ k_n/gamma_n, independent of A",
    "C6d": "C: omega_2 weakly dependent on k_n at fixed k_n/gamma_n",
    "C6e": "C: no hysteresis at omega_2",
    "C7": "B, C: block embedded for omega < omega_1 and omega > omega_2",
    "C8a": "A, C: large V_d gives sliding at any omega",
    "C8b": "A: stationary sliding x = V_d t - x0 with the paper's x0 = (gamma_t V_d - mu_s mg/2)/k_d",
}


@dataclass
class Row:
    claim: str
    measured: str
    verdict: str
    reason: str
    figures: list = field(default_factory=list)
    settings: str = ""


def _fmt(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return f"{float(value):.{digits}g}"


def _relative(measured, expected) -> float:
    if measured is None or expected in (None, 0) or not math.isfinite(float(measured)):
        return math.inf
    return abs(float(measured) / float(expected) - 1.0)


def _combine(parts: Sequence[tuple[str, str]]) -> tuple[str, str]:
    """Overall verdict of parts (verdict, text): any disagreement wins, then not reproduced."""
    verdicts = [v for v, _ in parts]
    overall = DISAGREES if DISAGREES in verdicts else NOT_REPRODUCED if NOT_REPRODUCED in verdicts else AGREES
    return overall, "; ".join(f"{text} ({v})" for v, text in parts)


# ---------------------------------------------------------------------- verdicts
def verdict_c1(m: dict) -> Row:
    checks = [("rest penetration", m["rest_penetration"], m["rest_penetration_formula"], PENETRATION_TOLERANCE),
              ("creep V_S", m["creep_velocity"], m["creep_velocity_formula"], FORMULA_TOLERANCE),
              ("stick time", m["stick_time"], m["stick_time_formula"], FORMULA_TOLERANCE),
              ("slip length", m["slip_length"], m["slip_length_formula"], FORMULA_TOLERANCE)]
    measured = ", ".join(f"{name} {_fmt(v)} vs {_fmt(f)} ({_fmt(100 * _relative(v, f), 2)} %)"
                         for name, v, f, _ in checks)
    parts = []
    for name, value, formula, tolerance in checks:
        if value is None or not math.isfinite(float(value)):
            parts.append((NOT_REPRODUCED, f"{name} not measured"))
        elif _relative(value, formula) <= tolerance:
            parts.append((AGREES, f"{name} within {tolerance:.0%}"))
        else:
            parts.append((DISAGREES, f"{name} off by {_relative(value, formula):.0%} > {tolerance:.0%}"))
    verdict, reason = _combine(parts)
    return Row("C1", measured, verdict, reason)


def verdict_c2(m: dict) -> Row:
    amplitudes, interval, length = m["amplitudes"], m["slip_interval"], m["slip_length"]
    measured = f"omega = {m['omega']:g}; " + ", ".join(
        f"A = {a:g} (A w^2/g = {acc:.2g}): slip every {_fmt(i)}, slip {_fmt(s)}"
        for a, acc, i, s in zip(amplitudes, m["peak_acceleration_over_g"], interval, length))
    if 0.0 not in amplitudes or interval[amplitudes.index(0.0)] is None:
        return Row("C2", measured, NOT_REPRODUCED, "no complete stick-slip cycle at A = 0")
    ref = amplitudes.index(0.0)
    # Amplitudes without two complete slips in the window cannot be compared; they are listed.
    compared = [i for i in range(len(amplitudes)) if interval[i] is not None and math.isfinite(interval[i])
                and length[i] is not None and math.isfinite(length[i])]
    unmeasured = [amplitudes[i] for i in range(len(amplitudes)) if i not in compared]
    worst_interval = max(_relative(interval[i], interval[ref]) for i in compared)
    worst_length = max(_relative(length[i], length[ref]) for i in compared)
    if unmeasured:
        measured += f"; no complete slip pair at A = {unmeasured}"
    if max(worst_interval, worst_length) <= UNCHANGED_TOLERANCE:
        return Row("C2", measured, AGREES, f"slip interval and length within {UNCHANGED_TOLERANCE:.0%} of A = 0")
    shortest = min((v for v in interval if v is not None), default=math.nan)
    return Row("C2", measured, DISAGREES,
               f"largest change from A = 0: slip interval {worst_interval:.0%}, slip length {worst_length:.0%} "
               f"(> {UNCHANGED_TOLERANCE:.0%}); the cycle shortens to {_fmt(shortest)} because the Coulomb bound "
               "mu_s N(t) oscillates with the plate")


def _bracketed(column: dict, line: float, amplitudes: Sequence[float]) -> bool:
    low, high = column["last_friction_A"], column["first_sliding_A"]
    if high is None:
        return line > max(amplitudes)
    return (low is None or low <= line) and line <= high


def verdict_c3(m: dict) -> tuple[Row, Row]:
    columns, amplitudes = m["columns"], m["amplitudes"]
    low = [c for c in columns if c["omega"] <= LOW_OMEGA]
    paper_ok = [c for c in low if _bracketed(c, c["paper_line"], amplitudes)]
    single = [c for c in columns if c["changes"] <= 1]
    paper_all = [c for c in columns if _bracketed(c, c["paper_line"], amplitudes)]
    onset_ok = [c for c in columns if _bracketed(c, c["onset_curve"], amplitudes)]
    boundaries = "; ".join(f"w = {c['omega']:.3g}: [{_fmt(c['last_friction_A'])}, {_fmt(c['first_sliding_A'])}] "
                           f"(g/w^2 = {c['paper_line']:.3g}, A_c = {c['onset_curve']:.3g})" for c in columns)
    measured_a = (f"friction/sliding boundary brackets g/w^2 in {len(paper_ok)}/{len(low)} columns with "
                  f"w <= {LOW_OMEGA:g} ({len(paper_all)}/{len(columns)} over all w); single transition in "
                  f"{len(single)}/{len(columns)} columns. Boundaries: {boundaries}")
    if not low:
        row_a = Row("C3a", measured_a, NOT_REPRODUCED, f"no column with omega <= {LOW_OMEGA:g}")
    else:
        parts = [(AGREES if len(paper_ok) == len(low) else DISAGREES,
                  f"g/w^2 bracketed in {len(paper_ok)}/{len(low)} low-w columns"),
                 (AGREES if len(single) == len(columns) else DISAGREES,
                  f"{len(columns) - len(single)} column(s) with more than one transition in A")]
        verdict, reason = _combine(parts)
        row_a = Row("C3a", measured_a, verdict, reason)
    measured_b = (f"A_c(w) bracketed in {len(onset_ok)}/{len(columns)} columns, g/w^2 in "
                  f"{len(paper_all)}/{len(columns)}")
    verdict = AGREES if len(onset_ok) == len(columns) else DISAGREES
    reason = (f"A_c(w) lies between the last friction and first sliding amplitude in "
              f"{len(onset_ok)}/{len(columns)} columns")
    return row_a, Row("C3b", measured_b, verdict, reason)


def verdict_c4(m: dict) -> Row:
    per = m["per_gamma"]
    step = m["omega_step"] or 0.0
    measured = "; ".join(f"gamma_n = {p['gamma_n']:g}: w1 = {_fmt(p['omega_1'])}, w* = {_fmt(p['omega_star'])} "
                         f"(A_c onset {_fmt(p['onset_omega'])})" for p in per)
    measured += (f"; A = {m['amplitude']:g}, ramp step {_fmt(step)}. Fresh starts (gamma_n = {m['fresh_gamma_n']:g}) "
                 f"differ from the down ramp at w = {m['down_differs_from_fresh_orbit'] or 'none'}; impact starts "
                 f"differ from the up ramp at w = {m['up_differs_from_fresh_impact'] or 'none'}")
    omega_1 = [p["omega_1"] for p in per]
    if any(v is None for v in omega_1):
        return Row("C4", measured, NOT_REPRODUCED, "no sliding reached on some up ramp")
    parts = [(AGREES if max(omega_1) - min(omega_1) <= step + 1e-9 else DISAGREES,
              f"w1 spread {max(omega_1) - min(omega_1):.3g} over gamma_n (one step = {step:.3g})")]
    gaps = [p["omega_1"] - p["omega_star"] if p["omega_star"] is not None else None for p in per]
    # No friction anywhere on the way down: w* lies below the ramp, still below w1.
    hysteretic = [g is None or g > 1e-9 for g in gaps]
    parts.append((AGREES if all(hysteretic) else DISAGREES,
                  f"w* < w1 for {sum(hysteretic)}/{len(per)} gamma_n"))
    if all(g is not None for g in gaps) and len(gaps) > 1:
        shrinking = all(b <= a + 1e-9 for a, b in zip(gaps[:-1], gaps[1:])) and gaps[-1] < gaps[0]
        parts.append((AGREES if shrinking else DISAGREES,
                      "gap w1 - w* vs gamma_n: " + ", ".join(_fmt(g) for g in gaps)))
    else:
        parts.append((NOT_REPRODUCED, "w* missing for some gamma_n (friction never back on the down ramp)"))
    verdict, reason = _combine(parts)
    return Row("C4", measured, verdict, reason)


def verdict_c5(m: dict) -> tuple[Row, Row, Row]:
    runs = m["runs"]
    measured_a = "; ".join(f"A = {r['A']:g} (A w^2/g = {r['peak_acceleration_over_g']:.2g}): {r['slip_events']} slips, "
                           f"every {_fmt(r['slip_interval'])}, length {_fmt(r['slip_length'])}, drift "
                           f"{_fmt(r['drift_velocity'])}, contact {_fmt(r['contact_fraction'])}, max |x - x_(A=0)| "
                           f"{_fmt(r['max_x_difference'])}" for r in runs)
    reference = runs[0]
    if reference["slip_interval"] is None or not math.isfinite(float(reference["slip_interval"])):
        row_a = Row("C5a", measured_a, NOT_REPRODUCED, "fewer than two complete slips at A = 0 in the window")
    else:
        worst = max(max(_relative(r["slip_interval"], reference["slip_interval"]),
                        _relative(r["slip_length"], reference["slip_length"])) for r in runs)
        row_a = Row("C5a", measured_a, AGREES if worst <= UNCHANGED_TOLERANCE else DISAGREES,
                    f"largest change of slip interval or length from A = 0: {_fmt(100 * worst, 2)} % "
                    f"(tolerance {UNCHANGED_TOLERANCE:.0%})")
    free = m["frictionless"]
    distance = free["root_distance_median"]
    measured_b = (f"k_t = 0: median distance of stuck samples from the nearest stable root {_fmt(distance)} "
                  f"(90th percentile {_fmt(free['root_distance_p90'])}), wavelength {m['wavelength']:.3g}; with "
                  f"friction (A = 0): {_fmt(reference['root_distance_median'])}")
    if distance is None:
        row_b = Row("C5b", measured_b, NOT_REPRODUCED, "no stuck samples")
    else:
        ok = distance <= ROOT_TOLERANCE * m["wavelength"]
        row_b = Row("C5b", measured_b, AGREES if ok else DISAGREES,
                    f"median distance {'<=' if ok else '>'} {ROOT_TOLERANCE:g} wavelengths")
    measured_c = f"k_t = 0: regime {free['regime']}, {free['slip_events']} slips of {_fmt(free['slip_length'])}"
    if free["regime"] == "stick_slip":
        row_c = Row("C5c", measured_c, AGREES, "stick-slip without tangential spring")
    elif free["regime"] == "stuck":
        row_c = Row("C5c", measured_c, NOT_REPRODUCED, "no slip in the window (stuck): window shorter than a stick")
    elif free["regime"] == "jammed":
        row_c = Row("C5c", measured_c, DISAGREES, "jammed (self-locked on a flank) without tangential spring")
    else:
        row_c = Row("C5c", measured_c, DISAGREES, "sliding without tangential spring")
    return row_a, row_b, row_c


def verdict_c6(m: dict) -> list[Row]:
    rows = []
    free = m["frictionless"]
    measured = (f"k_t = 0, A = 0: regime {free['regime']}, phi {_fmt(free['phi'])}, drift {_fmt(free['drift_velocity'])}, "
                f"{free['slip_events']} slips")
    rows.append(Row("C6a", measured, DISAGREES if free["regime"] == "stick_slip" else AGREES,
                    f"regime {free['regime']}"))

    diagram = m["diagram_rows"]
    losing = [r for r in diagram if r["omega_1"] is not None]
    measured = "; ".join(f"A = {r['A']:g}: friction lost at w in ({_fmt(r['last_friction_before_1'])}, "
                         f"{_fmt(r['omega_1'])}] (sqrt(P_l/mA) = {r['first_transition_paper']:.3g}, "
                         f"A_c onset {_fmt(r['first_transition_onset'])}), regained at {_fmt(r['omega_2'])}"
                         for r in diagram)
    if not losing:
        rows.append(Row("C6b", measured, NOT_REPRODUCED, "no row loses friction in the scanned omega range"))
    else:
        ok = [r for r in losing if (r["last_friction_before_1"] is None
                                    or r["last_friction_before_1"] <= r["first_transition_paper"])
              and r["first_transition_paper"] <= r["omega_1"]]
        rows.append(Row("C6b", measured, AGREES if len(ok) == len(losing) else DISAGREES,
                        f"sqrt(P_l/mA) bracketed in {len(ok)}/{len(losing)} rows that lose friction"))

    ratio = m["k_n_over_gamma_n"]
    recovered = [r for r in losing if r["omega_2"] is not None]
    measured = (f"k_n/gamma_n = {ratio:.3g}; omega_2 per A: "
                + ", ".join(f"A = {r['A']:g}: {_fmt(r['omega_2'])}" for r in losing))
    if not losing:
        rows.append(Row("C6c", measured, NOT_REPRODUCED, "no sliding region to recover from"))
    elif not recovered:
        rows.append(Row("C6c", measured, DISAGREES,
                        f"no row regains friction up to w = {max(m['omegas']):g}"))
    else:
        near = [r for r in recovered if r["last_sliding"] * (1 - RECOVERY_SLACK) <= ratio
                <= r["omega_2"] * (1 + RECOVERY_SLACK)]
        same = len({r["omega_2"] for r in recovered}) == 1
        parts = [(AGREES if len(recovered) == len(losing) else DISAGREES,
                  f"{len(recovered)}/{len(losing)} rows that lose friction regain it"),
                 (AGREES if len(near) == len(recovered) else DISAGREES,
                  f"k_n/gamma_n within the recovery bracket (+-{RECOVERY_SLACK:.0%}) in {len(near)}/{len(recovered)}"),
                 (AGREES if same else DISAGREES, "omega_2 the same grid value in all rows" if same
                  else "omega_2 differs between rows")]
        verdict, reason = _combine(parts)
        rows.append(Row("C6c", measured, verdict, reason))

    by_ratio: dict[float, list] = {}
    for entry in m["recovery_vs_k"]:
        by_ratio.setdefault(entry["ratio"], []).append(entry)
    measured = "; ".join(f"k_n/gamma_n = {r:g}: " + ", ".join(
        f"k_n = {e['k_n']:g}: w2/(k_n/gamma_n) = {_fmt(e['omega_2'] / r if e['omega_2'] else None)}"
        for e in entries) + f" (A = {m['stiffness_amplitude']:g})" for r, entries in by_ratio.items())
    parts = []
    for r, entries in by_ratio.items():
        found = [e["omega_2"] / r for e in entries if e["omega_2"] is not None]
        if len(found) < len(entries):
            parts.append((NOT_REPRODUCED, f"ratio {r:g}: no recovery for {len(entries) - len(found)} k_n"))
            continue
        grid = sorted(set(round(o / r, 9) for o in entries[0]["omegas"]))
        positions = [min(range(len(grid)), key=lambda i: abs(grid[i] - f)) for f in found]
        parts.append((AGREES if max(positions) - min(positions) <= 1 else DISAGREES,
                      f"ratio {r:g}: w2 spans {max(positions) - min(positions)} grid steps over k_n"))
    verdict, reason = _combine(parts) if parts else (NOT_REPRODUCED, "no data")
    rows.append(Row("C6d", measured, verdict, reason))

    up, down = m["ramp_up_omega_2"], m["ramp_down_omega_2"]
    measured = (f"ramp at A = {m['ramp_amplitude']:g}, w = {m['ramp_values']}: up {m['ramp_up_regimes']}, down "
                f"{m['ramp_down_regimes']}; friction back at w = {_fmt(up)} (up), held down to {_fmt(down)} (down)")
    if up is None or "sliding" not in m["ramp_up_regimes"]:
        rows.append(Row("C6e", measured, NOT_REPRODUCED, "the up ramp shows no sliding -> friction recovery"))
    else:
        rows.append(Row("C6e", measured, AGREES if up == down else DISAGREES,
                        "same recovery value up and down" if up == down else "recovery differs up and down"))
    return rows


def contact_transitions(omegas: Sequence[float], fractions: Sequence[float]) -> tuple[float | None, float | None]:
    """First omega leaving contact and the first omega above it back in contact."""
    omega_1 = omega_2 = None
    for omega, fraction in zip(omegas, fractions):
        embedded = fraction is not None and fraction >= EMBEDDED
        if omega_1 is None and not embedded:
            omega_1 = omega
        elif omega_1 is not None and embedded:
            omega_2 = omega
            break
    return omega_1, omega_2


def verdict_c7(m: dict) -> Row:
    parts, texts = [], []
    for model, curves in m["curves"].items():
        for curve in curves:
            omega_1, omega_2 = contact_transitions(curve["omega"], curve["contact_fraction"])
            texts.append(f"{model}, A = {curve['A']:g}: contact " + ", ".join(
                f"{f:.2f}" for f in curve["contact_fraction"]) + f" -> leaves at w = {_fmt(omega_1)}, back at "
                f"{_fmt(omega_2)}")
            if omega_1 is None:
                continue
            parts.append((AGREES if omega_2 is not None else DISAGREES,
                          f"{model}, A = {curve['A']:g}: " + (f"re-embedded at w = {omega_2:g}" if omega_2
                                                              else "never re-embedded")))
    measured = f"w = {m['curves']['B'][0]['omega']}; " + "; ".join(texts) + f" (embedded: fraction >= {EMBEDDED})"
    if not parts:
        return Row("C7", measured, NOT_REPRODUCED, "the block never leaves contact in the scanned range")
    verdict, reason = _combine(parts)
    return Row("C7", measured, verdict, reason)


def verdict_c8(m: dict) -> tuple[Row, Row]:
    parts, texts = [], []
    for model in ("model_a", "model_c"):
        rows = m[model]
        top = max(rows, key=lambda r: r["V_d"])
        texts.append(f"{model[-1].upper()}: " + "; ".join(
            f"V_d = {r['V_d']:g}: {sum(not friction_held(x) for x in r['regimes'])}/{len(r['regimes'])} sliding"
            for r in rows))
        sliding = all(not friction_held(x) for x in top["regimes"])
        parts.append((AGREES if sliding else DISAGREES,
                      f"{model[-1].upper()} at V_d = {top['V_d']:g}: " + ("all omegas slide" if sliding else
                      f"friction at w = {[w for w, x in zip(m['omegas'], top['regimes']) if friction_held(x)]}")))
    verdict, reason = _combine(parts)
    row_a = Row("C8a", " | ".join(texts) + f" (A: A = {m['model_a_amplitude']:g}; C: A = {m['model_c_amplitude']:g})",
                verdict, reason)
    offsets = m["offsets"]
    measured = "; ".join(f"V_d = {o['V_d']:g}: x0 = {_fmt(o['x0'], 4)} +- {_fmt(o['x0_std'], 2)}, force balance "
                         f"{_fmt(o['force_balance'], 4)}, paper {_fmt(o['paper'], 4)}" for o in offsets)
    against_paper = max(_relative(o["x0"], o["paper"]) for o in offsets)
    against_balance = max(_relative(o["x0"], o["force_balance"]) for o in offsets)
    verdict = AGREES if against_paper <= FORMULA_TOLERANCE else DISAGREES
    reason = (f"largest deviation from the paper's x0 {against_paper:.0%}, from (gamma_t V_d + mu_s mg/2)/k_d "
              f"{against_balance:.1%}: the sign of mu_s mg/(2 k_d) is +, not -")
    return row_a, Row("C8b", measured, verdict, reason)


# ---------------------------------------------------------------------- table
FIGURES = {
    "C1": ["fig1b.png"], "C2": ["fig1b.png"], "C3a": ["fig1c_phase_diagram_A.png"],
    "C3b": ["fig1c_phase_diagram_A.png"], "C4": ["hysteresis_gamma_n.png"], "C5a": ["model_b_x_t.png"],
    "C5b": ["model_b_x_t.png"], "C5c": ["model_b_x_t.png"], "C6a": [], "C6b": ["model_c_phase_diagram.png"],
    "C6c": ["model_c_phase_diagram.png"], "C6d": ["omega2_vs_k_n.png"], "C6e": ["model_c_phase_diagram.png"],
    "C7": ["contact_fraction.png"], "C8a": ["model_c_Vd_omega.png", "model_a_Vd_omega.png"], "C8b": [],
}


def claim_rows(studies: dict[str, Study]) -> list[Row]:
    """Every row of the claims table, from the studies' measured values."""
    rows: list[Row] = []
    makers = {"C1": verdict_c1, "C2": verdict_c2, "C3": verdict_c3, "C4": verdict_c4, "C5": verdict_c5,
              "C6": verdict_c6, "C7": verdict_c7, "C8": verdict_c8}
    for name, maker in makers.items():
        if name not in studies:
            continue
        made = maker(studies[name].measured)
        made = [made] if isinstance(made, Row) else list(made)
        for row in made:
            row.figures = FIGURES.get(row.claim, [])
            row.settings = _settings_text(studies[name].settings)
        rows.extend(made)
    return rows


def _settings_text(settings: dict) -> str:
    keys = ("model", "models", "parameters", "initial", "horizon", "step_duration", "phi_threshold", "transient",
            "window")
    return "; ".join(f"{k}: {settings[k]}" for k in keys if k in settings)


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def markdown(studies: dict[str, Study], figures_present: Sequence[str] = (), header: dict | None = None) -> str:
    rows = claim_rows(studies)
    header = header or {}
    lines = ["# vibroblock: claims C1-C8 against our simulations", ""]
    if header:
        lines += [f"- {k}: {v}" for k, v in header.items()] + [""]
    lines += ["Verdicts are computed from the measured numbers by the criteria stated in `harness/report.py` "
              f"(relative tolerance {FORMULA_TOLERANCE:.0%} for formulas, {UNCHANGED_TOLERANCE:.0%} for 'unchanged', "
              "bracket tests on the sweep grids). 'Friction' means regime stick_slip or stuck (held in the window); "
              "'sliding' means following the drive (phi below the threshold, drift >= V_d/2).", "",
              "| claim | statement | measured | verdict | why | figures |", "|---|---|---|---|---|---|"]
    summary = {}
    for row in rows:
        figures = " ".join(f"[{f}]({f})" for f in row.figures if f in figures_present)
        lines.append(f"| {row.claim} | {_cell(CLAIM_TEXT[row.claim])} | {_cell(row.measured)} | **{row.verdict}** | "
                     f"{_cell(row.reason)} | {figures} |")
        summary[row.verdict] = summary.get(row.verdict, 0) + 1
    lines += ["", "Summary: " + ", ".join(f"{v}: {n}" for v, n in sorted(summary.items())), "",
              "## Parameter sets and classification per study", "",
              "| study | settings |", "|---|---|"]
    for name, study in studies.items():
        lines.append(f"| {name} | {_cell(_settings_text(study.settings))}; merge gap {study.settings.get('merge_gap', 'n/a')}, "
                     f"min slip fraction {study.settings.get('slip_min_fraction', 'n/a')} |")
    if figures_present:
        lines += ["", "## Figures", ""] + [f"![{f}]({f})" for f in figures_present]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------- figures
def _regime_scatter(ax, xs, ys, regimes):
    from .plots import REGIME_STYLE

    xs, ys, regimes = np.asarray(xs), np.asarray(ys), np.asarray(regimes)
    for name, style in REGIME_STYLE.items():
        chosen = regimes == name
        if chosen.any():
            ax.scatter(xs[chosen], ys[chosen], marker=style["marker"], color=style["color"], label=style["label"])


def make_figures(studies: dict[str, Study], out: str | os.PathLike) -> list[str]:
    """Draw every figure the studies allow into ``out``; the file names written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .claims import onset_amplitude

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        written.append(name)

    if "Fig1b" in studies:
        d = studies["Fig1b"].data
        fig, ax = plt.subplots(figsize=(6.5, 4.0))
        for run in d["runs"]:
            ax.plot(run["time"], run["x"], label=f"{run['label']}: $\\omega$ = {run['omega']:g}, "
                                                 f"$\\phi$ = {run['phi']:.2g}")
        t = np.asarray(d["runs"][0]["time"])
        ax.plot(t, d["V_d"] * t, "k:", lw=1, label="drive $V_d t$")
        ax.set(xlabel=r"$t$ [$\tau_0$]", ylabel=r"$x$ [$\delta_0$]",
               title=f"Model A, A = {studies['Fig1b'].settings['A']:g} (scaled drive)")
        ax.legend(fontsize=8)
        save(fig, "fig1b.png")

    if "C3" in studies:
        d = studies["C3"].data
        fig, ax = plt.subplots(figsize=(6, 4.5))
        omega, amplitude = np.meshgrid(d["omega"], d["A"])
        _regime_scatter(ax, omega.ravel(), amplitude.ravel(), np.asarray(d["regime"]).ravel())
        line = np.geomspace(min(d["omega"]), max(d["omega"]), 300)
        ax.plot(line, 1 / line**2, "k:", label=r"$A = g/\omega^2$")
        ax.plot(line, onset_amplitude(line), "k-", lw=1, label=r"$A_c(\omega)$")
        ax.set(xscale="log", yscale="log", xlabel=r"$\omega$", ylabel="A", title="Model A (scaled drive)")
        ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
        ax.legend(fontsize="small")
        save(fig, "fig1c_phase_diagram_A.png")

    if "C4" in studies:
        loops = studies["C4"].data["loops"]
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        for number, loop in enumerate(loops):
            color = f"C{number}"
            for direction, face, marker in (("up", color, "s"), ("down", "none", "o")):
                pairs = [(v, p) for d, v, p in zip(loop["direction"], loop["value"], loop["phi"]) if d == direction]
                if pairs:
                    v, p = zip(*pairs)
                    ax.plot(v, np.maximum(p, 1e-3), marker=marker, color=color, markerfacecolor=face,
                            label=f"$\\gamma_n$ = {loop['gamma_n']:g} ({direction})")
        ax.set(yscale="log", xlabel=r"$\omega$", ylabel=r"$\phi$",
               title=f"Model A, A = {studies['C4'].measured['amplitude']:g}: ramp up then down")
        ax.legend(fontsize="x-small", ncol=2)
        save(fig, "hysteresis_gamma_n.png")

    if "C5" in studies:
        d = studies["C5"].data
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        for trace in d["traces"]:
            ax.plot(trace["time"], trace["x"], label=f"A = {trace['A']:g}")
        ax.plot(d["frictionless_trace"]["time"], d["frictionless_trace"]["x"], "k--", lw=0.8, label="A = 0, $k_t$ = 0")
        t = np.asarray(d["traces"][0]["time"])
        ax.plot(t, studies["C5"].measured["V_d"] * t, "k:", lw=0.8, label="$V_d t$")
        ax.set(xlabel=r"$t$", ylabel="x", title=f"Model B, $\\omega$ = {studies['C5'].measured['omega']:g}")
        ax.legend(fontsize="small")
        save(fig, "model_b_x_t.png")

    if "C6" in studies:
        d = studies["C6"].data
        fig, ax = plt.subplots(figsize=(6, 4.5))
        omega, amplitude = np.meshgrid(d["omega"], d["A"])
        _regime_scatter(ax, omega.ravel(), amplitude.ravel(), np.asarray(d["regime"]).ravel())
        line = np.geomspace(min(d["omega"]), max(d["omega"]), 300)
        ax.plot(line, 1 / line**2, "k:", label=r"$A = P_l/(m\omega^2)$")
        ax.plot(line, onset_amplitude(line), "k-", lw=1, label=r"$A_c(\omega)$ with $P_l$")
        ax.axvline(studies["C6"].measured["k_n_over_gamma_n"], color="tab:green", ls="--", label=r"$k_n/\gamma_n$")
        ax.set(xscale="log", yscale="log", xlabel=r"$\omega$", ylabel="A", title="Model C")
        ax.set_ylim(min(d["A"]) / 1.5, max(d["A"]) * 1.5)
        ax.legend(fontsize="small")
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
        ax.set(xscale="log", yscale="log", xlabel="$k_n$", ylabel=r"$\omega_2$",
               title="Friction recovery (x: none found; dotted: $k_n/\\gamma_n$)")
        ax.legend(fontsize="small")
        save(fig, "omega2_vs_k_n.png")

    if "C7" in studies:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for model, curves in studies["C7"].data["curves"].items():
            for curve in curves:
                ax.plot(curve["omega"], curve["contact_fraction"], "o-" if model == "B" else "s--",
                        label=f"model {model}, A = {curve['A']:g}")
        ax.axvline(studies["C7"].measured["k_n_over_gamma_n"], color="k", ls=":", label=r"$k_n/\gamma_n$")
        ax.set(xscale="log", xlabel=r"$\omega$", ylabel="contact fraction")
        ax.legend(fontsize="small")
        save(fig, "contact_fraction.png")

    if "C8" in studies:
        d = studies["C8"].data
        for key, name, title in (("regime_c", "model_c_Vd_omega.png", "Model C"),
                                 ("regime_a", "model_a_Vd_omega.png", "Model A")):
            fig, ax = plt.subplots(figsize=(6, 4.5))
            omega, velocity = np.meshgrid(d["omega"], d["V_d"])
            _regime_scatter(ax, omega.ravel(), velocity.ravel(), np.asarray(d[key]).ravel())
            amplitude = studies["C8"].measured["model_c_amplitude" if key == "regime_c" else "model_a_amplitude"]
            ax.set(xscale="log", yscale="log", xlabel=r"$\omega$", ylabel="$V_d$", title=f"{title}, A = {amplitude:g}")
            ax.legend(fontsize="small")
            save(fig, name)
    return written


def write_report(studies: dict[str, Study], out: str | os.PathLike, extra_figures: Sequence[str] = (),
                 header: dict | None = None) -> Path:
    """Figures and ``<out>/report.md`` from the studies; the report's path."""
    out = Path(out)
    figures = list(extra_figures) + make_figures(studies, out)
    path = out / "report.md"
    path.write_text(markdown(studies, figures, header))
    return path


__all__ = ["AGREES", "DISAGREES", "NOT_REPRODUCED", "Row", "claim_rows", "make_figures", "markdown",
           "verdict_c1", "verdict_c2", "verdict_c3", "verdict_c4", "verdict_c5", "verdict_c6", "verdict_c7",
           "verdict_c8", "write_report"]
