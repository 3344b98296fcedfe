"""Triggered slips: a record late in the stick brings the slip forward, a tiny one does not,
and the simulated resets follow the in-contact prediction of the normal force."""
from __future__ import annotations

import math

import numpy as np
import pytest

from harness.ground.triggering import TriggeringSettings, normal_force_response, reset_thresholds, run_triggering


@pytest.fixture(scope="module")
def result(fmu_path):
    settings = TriggeringSettings(block_fmu=fmu_path("A"), phases=(0.3, 0.7), peak_accelerations=(0.001, 0.3))
    return run_triggering(settings)


def branch(result, phase, peak):
    (found,) = [b for b in result.branches if b.phase == phase and b.peak_acceleration == peak]
    return found


def test_the_reference_cycle_is_the_regular_stick_slip(result):
    cycle = result.cycle
    # scaled set: stick ~mu_s m g / (k_d V_d) = 5e3, slip ~mu_s m g / k_d = 50 (quantised)
    assert 4500.0 < cycle.stick_time < 5500.0
    assert 45.0 < cycle.slip_length < 52.0
    assert len(cycle.states) > 50 and all(isinstance(s, bytes) for _, s in cycle.states)
    assert result.record_duration < 0.5 * cycle.stick_time  # the record is short against the stick


def test_a_record_late_in_the_stick_brings_the_slip_forward(result):
    late = branch(result, 0.7, 0.3)
    assert late.predicted_reset < 0.3 and late.resets > 0
    assert late.clock_advance > 0.2 * result.cycle.stick_time
    assert late.outcome == "early slip"
    assert 0.6 < late.stress_ratio < 0.8
    # the stress released is the stress stored: an early slip is shorter
    assert late.slip_length < 0.8 * result.cycle.slip_length


def test_a_tiny_record_or_an_early_phase_changes_nothing(result):
    for phase, peak in ((0.7, 0.001), (0.3, 0.001), (0.3, 0.3)):
        quiet = branch(result, phase, peak)
        assert quiet.resets == 0 and quiet.contact_fraction == 1.0
        assert abs(quiet.clock_advance) < 0.5, (phase, peak, quiet.clock_advance)
        assert quiet.outcome == "no effect"
    assert branch(result, 0.3, 0.3).predicted_reset > 0.3  # the prediction agrees


def test_normal_force_response_is_quasi_static_slowly_and_resonant_near_the_contact_frequency():
    t = np.linspace(0.0, 400.0, 40001)
    params = {"m": 1.0, "k_n": 1.0, "gamma_n": 0.07}
    for omega, gain in ((0.05, 1.0), (1.0, math.hypot(1.0, 0.07) / 0.07)):
        response = normal_force_response(np.sin(omega * t), t, params)
        late = response[t > 300.0]  # after the start transient (decay time 2 m / gamma_n ~ 29)
        assert np.max(np.abs(late)) == pytest.approx(gain, rel=0.02)
    # a slow downward pulse of 1 g at half the Coulomb bound: reset at 0.5 g, lift-off at 1 g
    slow = t[t <= 200.0]
    pulse = -np.sin(np.pi * slow / 200.0) ** 2
    reset, liftoff = reset_thresholds(pulse, slow, 0.25 * np.ones_like(slow), {"mu_s": 0.5})
    assert reset == pytest.approx(0.5, rel=0.01) and liftoff == pytest.approx(1.0, rel=0.01)
