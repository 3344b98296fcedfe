"""Sharp transitions and crossovers: the criterion on known curves, and on the model."""
from __future__ import annotations

import math

import numpy as np
import pytest

from harness.paper.claims.measure import (CROSSOVER, FLOOR_FRACTION, SHARP, foot_bracket, locate_feet,
                                          transition_character)

THRESHOLD = 10.0


def side(phi, contact=1.0):
    return {"phi": phi, "contact_fraction": contact}


def smooth(a, a_n=0.83, scale=80.0, power=2.0):
    """A phi that falls continuously to 0 at a_n (a crossover by construction)."""
    return scale * max(1.0 - a / a_n, 0.0) ** power + 1e-3


def test_a_smooth_fall_through_the_threshold_is_a_crossover():
    # The 3 % bracket around the crossing of a smooth curve.
    a = np.geomspace(0.3, 0.83, 2001)
    crossing = a[np.argmax([smooth(v) < THRESHOLD for v in a])]
    lo, hi = crossing / 1.015, crossing * 1.015
    assert smooth(lo) > THRESHOLD >= smooth(hi)
    assert transition_character(side(smooth(lo)), side(smooth(hi)), THRESHOLD) == CROSSOVER


def test_a_jump_across_the_bracket_is_sharp():
    # The applied-load bound's recovery at the A_c root: phi 0.04 -> 187 over 2.5 %.
    assert transition_character(side(187.0), side(0.04), THRESHOLD) == SHARP
    # Just under a decade is still a crossover; just over is sharp.
    assert transition_character(side(11.0), side(1.2), THRESHOLD) == CROSSOVER
    assert transition_character(side(11.0), side(1.0), THRESHOLD) == SHARP


def test_a_change_that_loses_contact_or_is_not_a_threshold_crossing_is_sharp():
    assert transition_character(side(12.0), side(8.0, contact=0.4), THRESHOLD) == SHARP
    assert transition_character(side(12.0), side(None), THRESHOLD) == SHARP
    # Held below the threshold (stuck, jammed): the class did not change through phi.
    assert transition_character(side(0.5), side(0.2), THRESHOLD) == SHARP


def test_the_foot_is_bisected_to_where_phi_reaches_the_floor():
    # phi = smooth(a) reaches FLOOR_FRACTION * THRESHOLD at a known amplitude.
    floor = FLOOR_FRACTION * THRESHOLD
    expected = 0.83 * (1.0 - math.sqrt((floor - 1e-3) / 80.0))
    curve = {a: side(smooth(a)) for a in (0.5, 0.6, 0.7, 0.9)}
    bracket = foot_bracket(curve, 0.6, True, THRESHOLD)
    assert bracket == (0.7, 0.9)
    searches = [{"curve": curve, "bracket": bracket, "upward": True}]
    locate_feet(lambda pairs: [side(smooth(a)) for _, a in pairs], searches, THRESHOLD, 0.01)
    assert abs(searches[0]["foot"] / expected - 1.0) <= 0.01
    # Walking down from the sliding side of a recovery.
    assert foot_bracket({w: side(smooth(1.7 - w)) for w in (0.8, 1.0, 1.2)}, 1.2, False, THRESHOLD) == (0.8, 1.0)
    assert foot_bracket({0.5: side(50.0), 0.7: side(20.0)}, 0.5, True, THRESHOLD) is None


def test_the_foot_is_not_sought_past_a_run_that_leaves_the_plate():
    """Walking up a crossover, a run that loses contact ends the walk: phi's floor beyond
    it (a flying block) is not the crossover's foot, but the floor reached as the block
    starts to leave the plate is."""
    bouncing = {"phi": 30.0, "contact_fraction": 0.4}
    curve = {0.5: side(50.0), 0.7: side(20.0), 1.0: bouncing, 60.0: side(0.0)}
    assert foot_bracket(curve, 0.5, True, THRESHOLD) is None
    curve[0.8] = side(0.0, contact=0.9)
    assert foot_bracket(curve, 0.5, True, THRESHOLD) == (0.7, 0.8)


@pytest.mark.slow
def test_model_a_loses_friction_in_a_crossover_ending_at_the_closed_form_a_n(tmp_path, fmu_dir):
    """Model A at omega = 2.52 under the contact-force bound: phi falls continuously as A
    rises towards A_N (docs/physics.md), and the foot lies at A_N(omega) of the closed
    form (vibroblock.orbits), which shares no code with the runs."""
    from harness.paper.claims import RESOLUTIONS, Runner
    from harness.paper.claims.measure import OBSERVE_A, SCALED, run_and_measure
    from harness.runs.settings import PointSettings
    from vibroblock.orbits import friction_loss_amplitude

    omega = 2.52
    a_n = float(friction_loss_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07))
    runner = Runner(tmp_path / "store", RESOLUTIONS["tiny"], fmus={m: fmu_dir / f"Block{m}.fmu" for m in "ABC"})
    base = PointSettings(run=runner.run("A", parameters={**SCALED, "omega": omega}, horizon=20_000.0),
                         observe=OBSERVE_A)

    def measure(amplitudes):
        items = [{"point": PointSettings(run=base.run.with_parameters({"A": a}), observe=base.observe)}
                 for a in amplitudes]
        return [r["observables"] for r in runner.tasks(run_and_measure, items)]

    amplitudes = [a_n * f for f in (0.6, 0.7, 0.8, 1.1)]
    curve = dict(zip(amplitudes, measure(amplitudes)))
    phis = [curve[a]["phi"] for a in amplitudes[:3]]
    assert phis[0] > phis[1] > phis[2], phis  # continuous fall, no jump to the floor
    assert all(curve[a]["contact_fraction"] >= 0.99 for a in amplitudes[:3])
    bracket = foot_bracket(curve, amplitudes[0], True, OBSERVE_A.phi_threshold)
    assert bracket is not None
    searches = [{"curve": curve, "bracket": bracket, "upward": True}]
    locate_feet(lambda pairs: measure([a for _, a in pairs]), searches, OBSERVE_A.phi_threshold, 0.03)
    assert abs(searches[0]["foot"] / a_n - 1.0) <= 0.10
