"""Closed-form results of docs/physics.md, for checking the reference and the core.

Pure numpy/scipy; shares nothing with the compiled core.  ``load`` is always the normal
load pressing the block into the plate, N_a = -(confining load + drive spring) . n:
m g on a flat plate (model A), m g cos a - k_d (x - V_d t) sin a (B), P_l - k_d (x - V_d t) sin a (C).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq


def detachment_amplitude(omega, load=1.0, m=1.0, k_n=1.0, gamma_n=0.07):
    """A_c: the plate amplitude (along the normal) at which the steady in-contact orbit of
    m y'' + gamma_n y' + k_n y = -load - m Z_p'' first reaches zero penetration."""
    omega = np.asarray(omega, dtype=float)
    return load / (m * omega ** 2) * np.abs(k_n - m * omega ** 2 + 1j * gamma_n * omega) / k_n


def friction_loss_amplitude(omega, load=1.0, m=1.0, k_n=1.0, gamma_n=0.07):
    """A_N: the amplitude (along the normal) at which the contact force
    N = k_n delta - gamma_n u_n of that orbit first reaches zero, the block still embedded."""
    omega = np.asarray(omega, dtype=float)
    return (load / (m * omega ** 2) * np.abs(k_n - m * omega ** 2 + 1j * gamma_n * omega)
            / np.hypot(k_n, gamma_n * omega))


def normal_amplitude_factor(formulation: str, cos_a: float) -> float:
    """The plate's amplitude along the normal per unit A: cos a in fixed axes (the plate
    moves vertically), 1 in the tangent frame (Z'_p = A sin(omega t) along the normal).
    An onset in plate amplitude A is the onset above divided by this factor."""
    return cos_a if formulation == "fixed_axes" else 1.0


def tilt(x, A_x, omega_x):
    slope = A_x * omega_x * math.cos(omega_x * x)
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    return cos_a, slope * cos_a


def applied_normal(model: str, p: dict, x: float, t: float = 0.0) -> float:
    """N_a = -(load + drive spring) . n at abscissa x and time t (p: the model's parameters)."""
    if model == "A":
        return p["m"] * p["g"]
    cos_a, sin_a = tilt(x, p["A_x"], p["omega_x"])
    load = p["P_l"] if model == "C" else p["m"] * p["g"] * cos_a
    return load - p["k_d"] * (x - p["V_d"] * t) * sin_a


def applied_tangential(model: str, p: dict, x: float, t: float = 0.0) -> float:
    """(load + drive spring) . t: what the tangential spring holds at rest, k_t F = this."""
    if model == "A":
        return -p["k_d"] * (x - p["V_d"] * t)
    cos_a, sin_a = tilt(x, p["A_x"], p["omega_x"])
    load = 0.0 if model == "C" else -p["m"] * p["g"] * sin_a
    return -p["k_d"] * (x - p["V_d"] * t) * cos_a + load


def model_b_equilibria(p: dict, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Roots x* of the paper's Eq. (9), cos(omega_x x*) = K (x* - V_d t), K = -k_d / (A_x omega_x m g),
    i.e. k_d (x* - V_d t) + m g Z_p'(x*) = 0, and whether each is stable
    (k_d + m g Z_p''(x*) > 0, the paper's 'positive slope side')."""
    mg, ax, wx, kd = p["m"] * p["g"], p["A_x"], p["omega_x"], p["k_d"]
    centre, reach = p["V_d"] * t, mg * ax * wx / kd  # |x* - V_d t| <= reach

    def f(x):
        return kd * (x - centre) + mg * ax * wx * math.cos(wx * x)

    # f is monotonic between its critical points sin(omega_x x) = k_d / (m g A_x omega_x^2):
    # one root at most in each such piece, so none is missed however close two roots are.
    nodes = [centre - reach, centre + reach]
    ratio = kd / (mg * ax * wx * wx)
    if ratio <= 1.0:
        first, second = math.asin(ratio), math.pi - math.asin(ratio)
        for j in range(math.floor((wx * (centre - reach) - math.pi) / (2 * math.pi)),
                       math.ceil((wx * (centre + reach) + math.pi) / (2 * math.pi)) + 1):
            nodes += [(first + 2 * math.pi * j) / wx, (second + 2 * math.pi * j) / wx]
    nodes = sorted(x for x in nodes if centre - reach <= x <= centre + reach)
    roots = []
    for a, b in zip(nodes[:-1], nodes[1:]):
        fa, fb = f(a), f(b)
        if fa == 0.0:
            roots.append(a)
        elif fa * fb < 0.0:
            roots.append(brentq(f, a, b, xtol=1e-13))
    roots = np.array(roots)
    stable = kd - mg * ax * wx * wx * np.sin(wx * roots) > 0.0
    return roots, stable


def drift_velocity(p: dict, x_star: float) -> float:
    """The paper's Eq. (10): dx*/dt of a stable root of Eq. (9)."""
    return p["V_d"] / (1.0 - p["m"] * p["g"] * p["A_x"] * p["omega_x"] ** 2 / p["k_d"] * math.sin(p["omega_x"] * x_star))


def self_locking(alpha: float, mu_s: float) -> bool:
    """A drive pulling the block up a flank of angle alpha presses it in as hard as it pulls
    it along: it never slips once tan(alpha) >= 1 / mu_s."""
    return math.tan(alpha) >= 1.0 / mu_s


def restitution(k_n=1.0, gamma_n=0.07, m=1.0):
    """The contact's coefficient of restitution e: a block meeting the plate at normal
    speed v leaves it at e v.  In contact it is the damped oscillator m y'' + gamma_n y' +
    k_n y = 0 (N may pull, so contact ends when the penetration returns to 0, after half
    a damped period): e = exp(-pi zeta / sqrt(1 - zeta^2)), zeta = gamma_n / (2 sqrt(k_n m)).
    Gravity is left out (exact for g = 0; for g > 0 valid when m g << k_n times the largest
    penetration)."""
    zeta = np.asarray(gamma_n, dtype=float) / (2.0 * np.sqrt(k_n * m))
    if np.any(zeta >= 1.0):
        raise ValueError("the contact is overdamped (zeta >= 1): the block does not rebound")
    return np.exp(-math.pi * zeta / np.sqrt(1.0 - zeta ** 2))


def bouncing_floor(e):
    """Gamma* = A omega^2 / g below which a bouncing ball with restitution e on a plate
    vibrating as A sin(omega t) cannot keep bouncing: Gamma* = pi (1 - e) / (1 + e) (the
    period-one orbit's existence bound: the plate must return the energy an impact loses)."""
    e = np.asarray(e, dtype=float)
    return math.pi * (1.0 - e) / (1.0 + e)


def bouncing_floor_omega(amplitude, load=1.0, m=1.0, k_n=1.0, gamma_n=0.07):
    """omega* = sqrt(Gamma* g / A), g = load / m: the lowest frequency at which a plate of
    amplitude A keeps the block bouncing (the bouncing branch ends below it)."""
    g = load / m
    return np.sqrt(bouncing_floor(restitution(k_n, gamma_n, m)) * g / np.asarray(amplitude, dtype=float))
