"""C7 -- models B and C: contact fraction against omega at fixed A.

Criterion: every (model, A) curve that leaves contact (contact fraction < ``EMBEDDED``)
returns to it at higher omega."""
from __future__ import annotations

import dataclasses
from typing import Sequence

from harness.runs.settings import ObservableSettings, PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import b_point, c_run, observe_json
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, Row, combine, fmt

EMBEDDED = 0.99  # contact fraction above which the block counts as embedded

TEXT = {
    "C7": "B, C: block embedded for omega < omega_1 and omega > omega_2",
}
FIGURES = {
    "C7": ["contact_fraction.png"],
}


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


def study_c7(runner: Runner) -> Study:
    """Models B and C: contact fraction against omega at fixed A."""
    res = runner.resolution
    amplitudes = (0.3, 3.0)
    observe_contact = ObservableSettings(transient=1000.0)
    curves = {}
    for model in ("B", "C"):
        if model == "B":
            base = b_point(runner, res.contact_horizon, observe_contact)
            base = dataclasses.replace(base, run=dataclasses.replace(base.run, output_interval=0.5))
        else:
            base = PointSettings(run=dataclasses.replace(c_run(runner, res.contact_horizon), output_interval=0.5),
                                 observe=observe_contact)
        ds = runner.sweep(Grid((Axis("A", amplitudes), Axis("omega", res.c7_omegas))), base)
        curves[model] = [{"A": float(a), "omega": ds.omega.values.tolist(),
                          "contact_fraction": ds.contact_fraction.sel(A=a).values.tolist(),
                          "regime": ds.regime.sel(A=a).values.tolist()} for a in ds.A.values]
    measured = {"curves": curves, "k_n_over_gamma_n": 1.0 / 0.07, "embedded_threshold": EMBEDDED}
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
                f"{f:.2f}" for f in curve["contact_fraction"]) + f" -> leaves at w = {fmt(omega_1)}, back at "
                f"{fmt(omega_2)}")
            if omega_1 is None:
                continue
            parts.append((AGREES if omega_2 is not None else DISAGREES,
                          f"{model}, A = {curve['A']:g}: " + (f"re-embedded at w = {omega_2:g}" if omega_2
                                                              else "never re-embedded")))
    measured = f"w = {m['curves']['B'][0]['omega']}; " + "; ".join(texts) + f" (embedded: fraction >= {EMBEDDED})"
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
            ax.plot(curve["omega"], curve["contact_fraction"], "o-" if model == "B" else "s--",
                    label=f"model {model}, A = {curve['A']:g}")
    ax.axvline(study.measured["k_n_over_gamma_n"], color="k", ls=":", label=r"$k_n/\gamma_n$")
    ax.set(xscale="log", xlabel=r"$\omega$", ylabel="contact fraction")
    ax.legend(fontsize="small")
    save(fig, "contact_fraction.png")


CLAIM = Claim("C7", study_c7, verdict_c7, TEXT, FIGURES, draw)
