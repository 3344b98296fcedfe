"""C7 -- models B and C: contact fraction against omega at fixed A.

Each (model, A) curve brackets on the omega grid where the block leaves contact
(omega_1: contact fraction first below ``EMBEDDED``) and where it is embedded again
(omega_2); both brackets are bisected in omega to ``BOUNDARY_RESOLUTION``, all curves per
round in one batch.  The slope angle of the corrugation where the block rests is recorded
with each grid point.

Criterion: every (model, A) curve that leaves contact returns to it at higher omega."""
from __future__ import annotations

import dataclasses
from typing import Sequence

from harness.runs.bisection import Transition, refine
from harness.runs.settings import ObservableSettings, PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import b_point, c_run, observe_json, run_and_measure
from .study import Claim, Runner, Study
from .readings import READINGS
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, Row, combine, fmt

EMBEDDED = 0.99  # contact fraction above which the block counts as embedded
BOUNDARY_RESOLUTION = 0.03  # relative width in omega to which both transitions are bisected

TEXT = {
    "C7": "B, C: block embedded for omega < omega_1 and omega > omega_2",
}
FIGURES = {
    "C7": ["contact_fraction.png"],
}


def embedded(fraction: float | None) -> bool:
    return fraction is not None and fraction >= EMBEDDED


def contact_transitions(omegas: Sequence[float], fractions: Sequence[float]) -> tuple[float | None, float | None]:
    """First omega leaving contact and the first omega above it back in contact."""
    omega_1 = omega_2 = None
    for omega, fraction in zip(omegas, fractions):
        if omega_1 is None and not embedded(fraction):
            omega_1 = omega
        elif omega_1 is not None and embedded(fraction):
            omega_2 = omega
            break
    return omega_1, omega_2


def _locate(runner: Runner, bases: dict, curves: dict) -> None:
    """Bisect every curve's leaving and return brackets in omega; adds located_omega_1/2 and
    their brackets to the curves."""
    found = []
    for model, model_curves in curves.items():
        for curve in model_curves:
            omegas, fractions = curve["omega"], curve["contact_fraction"]
            omega_1, omega_2 = contact_transitions(omegas, fractions)
            for value, was_embedded in ((omega_1, True), (omega_2, False)):
                index = omegas.index(value) if value is not None else 0
                if index > 0:
                    found.append(Transition(omegas[index - 1], value, was_embedded,
                                            where={"model": model, "A": curve["A"]}))

    def classify(pairs):
        items = [{"point": PointSettings(run=bases[t.where["model"]].run.with_parameters(
            {"A": t.where["A"], "omega": w}), observe=bases[t.where["model"]].observe)} for t, w in pairs]
        return [embedded(r["observables"]["contact_fraction"]) for r in runner.tasks(run_and_measure, items)]

    refine(classify, found, BOUNDARY_RESOLUTION)
    for model, model_curves in curves.items():
        for curve in model_curves:
            for name, was_embedded in (("omega_1", True), ("omega_2", False)):
                t = next((t for t in found if t.where == {"model": model, "A": curve["A"]}
                          and t.held_lo == was_embedded), None)
                curve[f"located_{name}"] = t.value if t else None
                curve[f"located_{name}_bracket"] = [t.lo, t.hi] if t else None


def study_c7(runner: Runner) -> Study:
    """Models B and C: contact fraction against omega at fixed A."""
    res = runner.resolution
    amplitudes = (0.3, 3.0)
    observe_contact = ObservableSettings(transient=1000.0)
    curves, bases = {}, {}
    for model in ("B", "C"):
        if model == "B":
            base = b_point(runner, res.contact_horizon, observe_contact)
            base = dataclasses.replace(base, run=dataclasses.replace(base.run, output_interval=0.5))
        else:
            base = PointSettings(run=dataclasses.replace(c_run(runner, res.contact_horizon), output_interval=0.5),
                                 observe=observe_contact)
        bases[model] = base
        ds = runner.sweep(Grid((Axis("A", amplitudes), Axis("omega", res.c7_omegas))), base)
        curves[model] = [{"A": float(a), "omega": ds.omega.values.tolist(),
                          "contact_fraction": ds.contact_fraction.sel(A=a).values.tolist(),
                          "regime": ds.regime.sel(A=a).values.tolist(),
                          "slope_angle_at_rest": ds.slope_angle_at_rest.sel(A=a).values.tolist()}
                         for a in ds.A.values]
    _locate(runner, bases, curves)
    measured = {"curves": curves, "k_n_over_gamma_n": 1.0 / 0.07, "embedded_threshold": EMBEDDED,
                "resolution": BOUNDARY_RESOLUTION}
    settings = {"models": "B, C", "parameters": "as C5 (B) and C6 (C)", "horizon": res.contact_horizon,
                "output_interval": 0.5, "initial": "B: valley; C: crest; steady orbit",
                **observe_json(observe_contact)}
    return Study("C7", measured, settings, {"curves": curves})


def verdict_c7(m: dict) -> Row:
    parts, texts = [], []
    for model, curves in m["curves"].items():
        for curve in curves:
            omega_1, omega_2 = contact_transitions(curve["omega"], curve["contact_fraction"])
            texts.append(f"{model}, A = {curve['A']:g}: contact " + ", ".join(
                f"{f:.2f}" for f in curve["contact_fraction"]) + f" -> leaves at w = {fmt(omega_1)} (located "
                f"{fmt(curve.get('located_omega_1'))}), back at {fmt(omega_2)} (located "
                f"{fmt(curve.get('located_omega_2'))})")
            if omega_1 is None:
                continue
            back = curve.get("located_omega_2") or omega_2
            parts.append((AGREES if omega_2 is not None else DISAGREES,
                          f"{model}, A = {curve['A']:g}: " + (f"re-embedded at w = {back:.3g}" if omega_2
                                                              else "never re-embedded")))
    measured = (f"w = {m['curves']['B'][0]['omega']}; " + "; ".join(texts) + f" (embedded: fraction >= {EMBEDDED}; "
                f"located to {m.get('resolution', BOUNDARY_RESOLUTION):.0%} in omega)")
    if not parts:
        return Row("C7", measured, NOT_REPRODUCED, "the block never leaves contact in the scanned range")
    verdict, reason = combine(parts)
    return Row("C7", measured, verdict, reason)


def draw(study: Study, save) -> None:
    """The figures of this claim, each handed to ``save(figure, file name)``."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for model, curves in study.data["curves"].items():
        for curve in curves:
            line, = ax.plot(curve["omega"], curve["contact_fraction"], "o-" if model == "B" else "s--",
                            label=f"model {model}, A = {curve['A']:g}")
            for key in ("located_omega_1", "located_omega_2"):
                if curve.get(key) is not None:  # the bisected transitions, on the embedded threshold
                    ax.plot(curve[key], EMBEDDED, "|", ms=14, mew=2, color=line.get_color())
    ax.axvline(study.measured["k_n_over_gamma_n"], color="k", ls=":", label=r"$k_n/\gamma_n$")
    ax.set(xscale="log", xlabel=r"$\omega$ [$\tau_0^{-1}$]", ylabel="contact fraction [1]")
    ax.legend(fontsize="small")
    save(fig, "contact_fraction.png")


CLAIM = Claim("C7", study_c7, verdict_c7, TEXT, FIGURES, draw, readings=READINGS)
