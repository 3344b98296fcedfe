"""Onsets located numerically for any contact law: the plate amplitude A_c(omega) at which
the block's steady orbit on a vibrating flat plate (model A) first reaches zero
penetration.

For the linear laws the orbit is a damped linear oscillator and A_c has the closed form
``vibroblock.orbits.detachment_amplitude`` (the tests check the search against it); a
nonlinear contact (Hertz-Hunt-Crossley,
``contact_law = 3``) has none, so it is located here: the Block FMU's core is run on its
steady orbit (``initial_state = 2``, the start computed with the law's rest stiffness)
for ``periods`` plate periods, the lowest penetration over the last half is refined by
a parabola through the sampled minimum and its neighbours, and A_c is the root of that
minimum in A (brentq; it is continuous through A_c, negative once the block flies).
The horizontal motion plays no part: no drive, no friction spring.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from vibroblock import Block

# Only the vertical motion: no drive spring, no friction spring.
VERTICAL = {"k_d": 0.0, "V_d": 0.0, "k_t": 0.0}


def lowest_penetration(amplitude: float, omega: float, contact_law: int = 0, *, periods: int = 60,
                       samples: int = 256, dt: float = 1e-3, **parameters) -> float:
    """The lowest penetration of the block over the last half of ``periods`` plate periods
    (``samples`` per period, refined by a parabola through the lowest sample)."""
    block = Block("A", "rk4", 2, False, A=amplitude, omega=omega, dt=dt, contact_law=contact_law,
                  **{**VERTICAL, **parameters})
    block.start()
    step = 2.0 * math.pi / omega / samples
    block.advance_to(step * samples * (periods // 2))
    values = np.empty(samples * (periods - periods // 2))
    for k in range(values.size):
        block.advance_to(step * (samples * (periods // 2) + k + 1))
        values[k] = block.output("penetration")
    i = int(np.argmin(values[1:-1])) + 1
    left, centre, right = values[i - 1], values[i], values[i + 1]
    curvature = left - 2.0 * centre + right
    return float(centre - (right - left) ** 2 / (8.0 * curvature)) if curvature > 0.0 else float(centre)


def located_detachment_amplitude(omega: float, contact_law: int = 0, *, tolerance: float = 1e-4,
                                 **parameters) -> float:
    """A_c(omega) for ``contact_law``: the amplitude at which the steady orbit's lowest
    penetration reaches zero, bracketed outwards from the quasi-static g / omega^2 (the
    contact's resonance moves A_c from it by orders of magnitude near resonance)."""
    def lowest(amplitude):
        return lowest_penetration(amplitude, omega, contact_law, **parameters)

    low = high = parameters.get("g", 1.0) / omega**2
    for _ in range(12):
        if lowest(low) > 0.0:
            break
        low /= 3.0
    for _ in range(12):
        if lowest(high) < 0.0:
            break
        high *= 3.0
    return brentq(lowest, low, high, rtol=tolerance)
