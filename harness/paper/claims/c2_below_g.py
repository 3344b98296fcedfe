"""C2 -- model A with the plate's peak acceleration below g: stick-slip as at A = 0.

Criterion: at every A with A omega^2 < g, mean slip interval and slip length within
``UNCHANGED_TOLERANCE`` of their A = 0 values."""
from __future__ import annotations

import math

from harness.runs.settings import PointSettings
from harness.runs.sweep import Axis, Grid

from .measure import OBSERVE_A_BURSTS, SCALED, jsonable_float, observe_json
from .study import Claim, Runner, Study
from .readings import A_READINGS
from .verdicts import AGREES, DISAGREES, NOT_REPRODUCED, UNCHANGED_TOLERANCE, Row, fmt, relative

TEXT = {
    "C2": "A, max plate acceleration < g: stick-slip as at A = 0",
}
FIGURES = {
    "C2": ["fig1b.png"],
}


def study_c2(runner: Runner) -> Study:
    """Model A below g: slip statistics against A at fixed omega."""
    res = runner.resolution
    omega = 0.25
    base = PointSettings(run=runner.run("A", parameters={**SCALED, "omega": omega}, horizon=max(res.horizon_a, 16_000.0)),
                         observe=OBSERVE_A_BURSTS)
    ds = runner.sweep(Grid((Axis("A", res.c2_amplitudes),)), base)
    amplitudes = ds.A.values.tolist()
    measured = {"omega": omega, "amplitudes": amplitudes,
                "peak_acceleration_over_g": [a * omega**2 for a in amplitudes],
                "slip_interval": [jsonable_float(v) for v in ds.slip_interval_mean.values],
                "stick_time": [jsonable_float(v) for v in ds.stick_time_mean.values],
                "slip_length": [jsonable_float(v) for v in ds.slip_length_mean.values],
                "slip_events": ds.slip_events.values.tolist(), "regime": ds.regime.values.tolist()}
    settings = {"model": "A", "parameters": "scaled", "omega": omega, "horizon": base.run.horizon,
                "initial": "steady orbit", **observe_json(OBSERVE_A_BURSTS)}
    return Study("C2", measured, settings)


def verdict_c2(m: dict) -> Row:
    amplitudes, interval, length = m["amplitudes"], m["slip_interval"], m["slip_length"]
    measured = f"omega = {m['omega']:g}; " + ", ".join(
        f"A = {a:g} (A w^2/g = {acc:.2g}): slip every {fmt(i)}, slip {fmt(s)}"
        for a, acc, i, s in zip(amplitudes, m["peak_acceleration_over_g"], interval, length))
    if 0.0 not in amplitudes or interval[amplitudes.index(0.0)] is None:
        return Row("C2", measured, NOT_REPRODUCED, "no complete stick-slip cycle at A = 0")
    ref = amplitudes.index(0.0)
    # Amplitudes without two complete slips in the window cannot be compared; they are listed.
    compared = [i for i in range(len(amplitudes)) if interval[i] is not None and math.isfinite(interval[i])
                and length[i] is not None and math.isfinite(length[i])]
    unmeasured = [amplitudes[i] for i in range(len(amplitudes)) if i not in compared]
    worst_interval = max(relative(interval[i], interval[ref]) for i in compared)
    worst_length = max(relative(length[i], length[ref]) for i in compared)
    if unmeasured:
        measured += f"; no complete slip pair at A = {unmeasured}"
    if max(worst_interval, worst_length) <= UNCHANGED_TOLERANCE:
        return Row("C2", measured, AGREES, f"slip interval and length within {UNCHANGED_TOLERANCE:.0%} of A = 0")
    shortest = min((v for v in interval if v is not None), default=math.nan)
    return Row("C2", measured, DISAGREES,
               f"largest change from A = 0: slip interval {worst_interval:.0%}, slip length {worst_length:.0%} "
               f"(> {UNCHANGED_TOLERANCE:.0%}); the cycle shortens to {fmt(shortest)} because the Coulomb bound "
               "mu_s N(t) oscillates with the plate")


CLAIM = Claim("C2", study_c2, verdict_c2, TEXT, FIGURES, None, readings=A_READINGS)
