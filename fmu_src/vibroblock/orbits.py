"""Closed-form results of the embedded block: the steady in-contact orbit and the
amplitudes at which it loses friction and contact.

Pure Python and numpy: importing this module loads no compiler and changes nothing, so
the harness, the studies and the docs use these formulas instead of copies.

Seen from the plate, the embedded block is a damped oscillator driven by the plate's
acceleration: with y = z - Z_p (the negative penetration along a flat plate),

    m y'' + gamma_n y' + k_n y = -W + m A omega^2 sin(theta),

W the load pressing the block in (m g in model A).  Its steady orbit is
y = -W/k_n + Im(R e^{i theta}), R = m A omega^2 / (k_n - m omega^2 + i gamma_n omega).
"""
from __future__ import annotations

import cmath

import numpy as np


def orbit_response(m, k_n, gamma_n, amplitude, omega) -> complex:
    """Complex amplitude R of the steady orbit's oscillation about -W/k_n.  An undamped
    contact driven at its own resonance has none (its oscillation grows without bound):
    ValueError, saying so."""
    denominator = complex(k_n - m * omega**2, gamma_n * omega)
    if denominator == 0.0 and amplitude * omega != 0.0:
        raise ValueError(f"no steady in-contact orbit: the undamped contact (gamma_n = 0) is driven at its "
                         f"resonance omega = sqrt(k_n / m) = {omega:g}, where its oscillation grows without bound")
    return m * amplitude * omega**2 / denominator if denominator != 0.0 else 0.0j


def steady_orbit(m, k_n, gamma_n, weight, amplitude, omega, phase):
    """Offset and rate of the block relative to a plate moving as A sin(phase), on the
    steady in-contact orbit of m y'' + gamma_n y' + k_n y = -weight - m Z_p''."""
    rotating = orbit_response(m, k_n, gamma_n, amplitude, omega) * cmath.exp(1j * phase)
    return -weight / k_n + rotating.imag, (1j * omega * rotating).imag


def detachment_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07):
    """Smallest amplitude at which the steady in-contact orbit reaches zero penetration:
    A_c = (g / omega^2) |k_n - m omega^2 + i gamma_n omega| / k_n.

    It tends to the paper's A = g / omega^2 for omega << sqrt(k_n / m).  For another
    confining load W pass g = W / m (model C in the tangent frame: g -> P_l / m)."""
    omega = np.asarray(omega, dtype=float)
    return g / omega**2 * np.abs(k_n - m * omega**2 + 1j * gamma_n * omega) / k_n


def friction_loss_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07):
    """Smallest amplitude at which the normal force N = k_n delta - gamma_n u_n of the
    steady orbit first reaches 0 while the block is still embedded:
    A_N = (g / omega^2) |k_n - m omega^2 + i gamma_n omega| / sqrt(k_n^2 + gamma_n^2 omega^2).

    Below A_c everywhere, by sqrt(2) at omega = k_n / gamma_n, and falling as 1/omega
    beyond: from here on the Coulomb bound mu_s N vanishes once per period."""
    omega = np.asarray(omega, dtype=float)
    return (g / omega**2 * np.abs(k_n - m * omega**2 + 1j * gamma_n * omega)
            / np.sqrt(k_n**2 + (gamma_n * omega) ** 2))
