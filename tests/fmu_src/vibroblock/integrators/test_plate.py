"""The drive's phase on the grid (``vibroblock.integrators.plate``) against exact rationals."""
import math
from fractions import Fraction

import numpy as np
import pytest

from vibroblock import layout as L
from vibroblock.integrators.plate import drive_phase, reduced_phase

TURN = 2 * Fraction("3.14159265358979323846264338327950288419716939937510582097494459")


def exact(phase, rate, steps):
    value = Fraction(phase) + Fraction(rate) * steps
    return value - TURN * math.floor(value / TURN)


@pytest.mark.parametrize("omega, dt", [(0.316, 4e-4), (1.3, 1e-2), (1e3, 1e-5), (2e-2, 0.5)])
def test_drive_phase_is_the_exact_multiple_reduced_at_any_step(omega, dt):
    drv, cnt = np.zeros(L.N_DRV), np.zeros(L.N_CNT, dtype=np.int64)
    drv[L.D_OMEGA], drv[L.D_DT], drv[L.D_PHASE] = omega, dt, 5.1
    cnt[L.C_PHASE_STEP] = 1234
    rate = omega * dt  # the kernels' phase per grid step
    worst = 0.0
    for n in [1234, 1235, 10**6, 2**40 + 7, 3 * 10**13, 2**52 - 1]:
        phase = drive_phase(drv, cnt, n)
        assert 0.0 <= phase < 2 * math.pi
        distance = abs(Fraction(phase) - exact(5.1, rate, n - 1234))
        worst = max(worst, float(min(distance, TURN - distance)))
    # A double sum would be off by ~1e-2 rad at the largest steps (phase ~6e13 rad).
    assert worst < 4e-15


def test_reduced_phase_is_exact_for_large_products():
    cases = [(0.0, 0.316, 2e9), (3.0, 1e3, 1e12), (6.2, 2e-2, 0.0), (0.0, 0.0, 1e15), (1.0, 2e-4, 3 * 10**13)]
    for phase, rate, elapsed in cases:
        expected = float(exact(phase, rate, Fraction(elapsed)))
        # As Block passes them: numpy scalars (whose int64 would overflow inside Fraction).
        as_numpy = (np.float64(phase), np.float64(rate),
                    np.int64(elapsed) if isinstance(elapsed, int) else np.float64(elapsed))
        for arguments in ((phase, rate, elapsed), as_numpy):
            value = reduced_phase(*arguments)
            assert 0.0 <= value < 2 * math.pi
            assert abs(value - expected) < 1e-15


def test_a_whole_number_of_turns_is_phase_zero_not_two_pi():
    # omega dt = 2 pi / k rounded: at whole periods the product falls a rounding short of
    # (or just past) k' 2 pi; the reduced phase must still lie in [0, 2 pi).
    drv, cnt = np.zeros(L.N_DRV), np.zeros(L.N_CNT, dtype=np.int64)
    drv[L.D_DT] = 1e-3
    short_of_a_turn = 0
    for k in range(1, 60):
        drv[L.D_OMEGA] = 2 * math.pi / (k * drv[L.D_DT])
        rate = drv[L.D_OMEGA] * drv[L.D_DT]
        for n in range(k, 40 * k, k):
            phase = drive_phase(drv, cnt, n)
            assert 0.0 <= phase < 2 * math.pi
            distance = abs(Fraction(phase) - exact(0.0, rate, n))
            assert float(min(distance, TURN - distance)) < 1e-15
            short_of_a_turn += exact(0.0, rate, n) > TURN / 2
    assert short_of_a_turn > 0  # the case the reduction has to fold back to 0 did occur
    # The same in Python, where the drive's phase is set.
    assert reduced_phase(-1e-300, 1.0, 0.0) == 0.0
