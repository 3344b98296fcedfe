"""Triggered events in the chain (``harness.chain.triggering``)."""
import math

import pytest

from harness.chain.triggering import TriggerSettings, burst, clock_advance, reference_cycle


@pytest.fixture(scope="module")
def reference():
    return reference_cycle(TriggerSettings())


def test_the_burst_is_consistent_and_starts_and_ends_at_rest():
    """Velocity and acceleration are the derivatives of the height (central differences),
    and the taper brings all three to zero at both ends."""
    amplitude, period, cycles, h = 0.3, 7.0, 3, 1e-5
    for tau in (0.4, 5.0, 13.3):
        z, v, a = burst(amplitude, period, cycles, tau)
        assert v == pytest.approx((burst(amplitude, period, cycles, tau + h)[0]
                                   - burst(amplitude, period, cycles, tau - h)[0]) / (2 * h), rel=1e-6)
        assert a == pytest.approx((burst(amplitude, period, cycles, tau + h)[1]
                                   - burst(amplitude, period, cycles, tau - h)[1]) / (2 * h), rel=1e-6)
    for tau in (0.0, cycles * period):
        assert all(abs(value) < 1e-12 for value in burst(amplitude, period, cycles, tau))


def test_a_burst_of_no_amplitude_changes_nothing(reference):
    """Restored from a snapshot and run on with a still plate: the reference event, to the
    last bit of its start time."""
    row = clock_advance(reference, TriggerSettings(), 0.5, 20.0, 0.0)
    assert row["advance"] == 0.0 and not row["triggered"]
    assert row["T0"] == pytest.approx(0.5 * reference.cycle)


def test_a_strong_short_burst_triggers_the_event_during_the_burst(reference):
    """A burst whose acceleration lowers the normal force by half a g each period: the
    Coulomb bound drops below the held load long before the event was due."""
    settings = TriggerSettings()
    row = clock_advance(reference, settings, 0.7, 10.0, 0.5)
    assert row["triggered"] and 0.0 < row["advance"] <= row["T0"]
    assert row["t_event"] <= reference.t_s + 0.7 * reference.cycle + settings.cycles * 10.0
    assert math.isfinite(row["t_event"])
