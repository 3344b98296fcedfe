"""Jumping through a stick of the whole chain (``Chain(..., jump_sticks=True)``): while
every block sticks, the chain's symplectic Euler steps form a linear recurrence driven by
the loader's ramp, and a run takes many of them at once, in closed form, up to a step
before which no block can break its bound.

The recurrence, as ``kernel.euler_sweep`` steps a stuck block in contact on the flat,
resting plate (``symplectic_euler.euler_step``, then the friction law's stick):

    v_i(n+1) = v_i(n) + (h/m) [-k_p (x_i(n) - V_d t_n) - gamma_t v_i(n) - k_t F_i(n) + k_c (L x(n))_i]
    x_i(n+1) = x_i(n) + h v_i(n+1)
    F_i(n+1) = F_i(n) + h v_i(n+1)

(L x)_i = x_{i-1} - x_i + x_{i+1} - x_i, the chain's ends free or periodic.  The height
and the contact force N_i do not move (``kernel.rest_probe`` checks it to the bit), and
F_i moves with x_i, so F_i(n) - F_i(0) = x_i(n) - x_i(0).  With c = k_p V_d/(k_p + k_t)
(the creep every stuck block follows: L leaves a uniform motion alone) and

    x(n) = x(0) + c h n + y* + u(n),   v(n) = c + w(n),   F(n) = F(0) + c h n + y* + u(n),

y* = K^-1 s, K = (k_p + k_t) I + k_c (-L), s = the static force at the start less the
dashpot's gamma_t c, the ringing (u, w) obeys the homogeneous recurrence.  K and the
damping are uniform over the blocks, so the ringing splits into the normal modes of -L
(eigenvalues lambda_k, orthonormal vectors Q[:, k]), each the 2x2 map

    M_k = [[1 - a_k, h (1 - b)], [-a_k/h, 1 - b]],   a_k = h^2 kappa_k/m, b = h gamma_t/m,

kappa_k = k_p + k_t + k_c lambda_k, whose powers are rho^n (A cos n theta_k + B sin n
theta_k), rho = sqrt(1 - b), theta_k = atan2(sqrt(4 a_k - (a_k + b)^2), 2 - a_k - b)
(every mode rings: 4 a_k > (a_k + b)^2, else no jump).  So |u_i(n)| <= rho^n sum_k
|Q_ik| R_k (or rho^n |R|), R_k the mode's amplitude: the bound of block i, |F_i(n)| < mu_s N_i/k_t, holds
up to step n if it holds with that envelope at steps 0 and n (the envelope plus
|F_i(0) + y*_i + c h n| is convex in n).  The jump lands on the last such step (less a
margin for rounding), and the velocities stay below v_start on the way (the envelope at
step 0): with no event open, the catalogue sees nothing; then the run steps on to the failure.

The quadrature phi_i (the sum of h (v_i - V_d)^2 over the steps) is booked in closed
form: the ringing's sum is (u(n) - u(0))/h, its squares' sum the modes' geometric sums.
The energy balance is not booked: a chain that keeps it refuses to jump.
"""
from __future__ import annotations

import math

import numpy as np

from .. import layout as L
from . import kernel as K

# Steps between two tests for a jump (``kernel.advance``'s jump_every), and the shortest
# jump taken: a jump costs O(N^2), about as much as a few hundred steps of the chain.
JUMP_EVERY = 1024
# A test that finds no jump doubles the steps to the next one, up to JUMP_EVERY << MAX_BACKOFF
# (82 tau_0 at dt = 1e-2, against a ringing that decays over ~400 tau_0 at the defaults).
MAX_BACKOFF = 3
# The bound's margin over a jump, relative: the closed form and the steps differ by
# rounding, about n eps relative after n steps, far below it.
MARGIN = 1e-8
EPS = np.finfo(float).eps


def laplacian(n_blocks: int, periodic: bool) -> np.ndarray:
    """The matrix L of the kernel's pull, (L x)_i = x_{i-1} - x_i + x_{i+1} - x_i, with the
    kernel's ends: free (a missing neighbour adds nothing) or periodic (two blocks with
    periodic ends pull each other twice)."""
    lap = np.zeros((n_blocks, n_blocks))
    for i in range(n_blocks):
        for j in (i - 1, i + 1):
            if 0 <= j < n_blocks or periodic:
                lap[i, j % n_blocks] += 1.0
                lap[i, i] -= 1.0
    return lap


class Modes:
    """The chain's normal modes: -L = Q diag(lambda) Q^T, and what every jump of this
    chain shares."""

    def __init__(self, n_blocks: int, periodic: bool):
        self.lap = laplacian(n_blocks, periodic)
        eigenvalues, self.Q = np.linalg.eigh(-self.lap)
        self.eigenvalues = np.maximum(eigenvalues, 0.0)  # (-L is positive semi-definite; -1e-16 is 0)
        self.abs_Q = np.abs(self.Q)


def pull(x: np.ndarray, periodic: bool) -> np.ndarray:
    """(L x)_i summed as the kernel sums it: left difference first, then the right one."""
    n = x.shape[0]
    result = np.zeros(n)
    if n > 1 or periodic:
        left = np.roll(x, 1)
        right = np.roll(x, -1)
        if periodic:
            result = (left - x) + (right - x)
        else:
            result[1:] = left[1:] - x[1:]
            result[:-1] = result[:-1] + (right[:-1] - x[:-1])
    return result


def _geometric(rho2, phase_step, n, powers):
    """sum_{m=1}^{n} r^m for r = rho2 e^(i phase_step) (complex arrays), with r^n given as
    ``powers``: r (1 - r^n)/(1 - r), 1 - r written without cancellation."""
    r = rho2 * np.exp(1j * phase_step)
    one_minus = (1.0 - rho2) + rho2 * (2.0 * np.sin(0.5 * phase_step) ** 2 - 1j * np.sin(phase_step))
    return r * (1.0 - powers) / one_minus


def envelope(modes: Modes, amplitudes: np.ndarray) -> np.ndarray:
    """Each block's bound on sum_k Q_ik q_k for modes of these amplitudes (|q_k| <=
    amplitude_k): the smaller of sum_k |Q_ik| amplitude_k and, the rows of Q being unit
    vectors, the amplitudes' Euclidean norm (Cauchy-Schwarz)."""
    return np.minimum(modes.abs_Q @ amplitudes, math.sqrt(float(np.sum(amplitudes * amplitudes))))


def plan(chain, modes: Modes, normals: np.ndarray, n_cap: int):
    """The jump from the chain's stored state: (steps, new x, v, F, phi increments), or
    None where no jump of at least one step is safe.  ``normals``: each block's N over the
    jump (``kernel.rest_probe``); ``n_cap``: the most steps wanted."""
    p = chain.settings.parameters
    m, k_p, V, k_t, g_t, h = p["m"], p["k_d"], p["V_d"], p["k_t"], p["gamma_t"], p["dt"]
    k_c = chain.chain_parameters["k_c"]
    Y, Q = chain.Y, modes.Q
    x0, v0, F0 = Y[:, L.Y_X].copy(), Y[:, L.Y_VX].copy(), Y[:, L.Y_F].copy()
    if not np.all(np.isfinite(normals)) or n_cap < 1:
        return None
    limit = chain.PRM[:, L.P_MUS] * normals / k_t  # |F| below it: no reset, no slip
    t = chain.drv[L.D_T0] + chain.cnt[L.C_STEP] * h
    c = k_p * V / (k_p + k_t)
    kappa = k_p + k_t + k_c * modes.eigenvalues
    a, b = h * h * kappa / m, h * g_t / m
    ringing = 4.0 * a - (a + b) ** 2
    if not (np.all(ringing > 0.0) and b < 1.0):
        return None
    rho = math.sqrt(1.0 - b)
    theta = np.arctan2(np.sqrt(ringing), 2.0 - a - b)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    # The static force at the start (as the kernel sums it) less the dashpot's on the creep.
    s = (-k_p * (x0 - V * t) - k_t * F0 + k_c * pull(x0, chain.periodic)) - g_t * c
    y_star_modal = (Q.T @ s) / kappa
    y_star = Q @ y_star_modal
    xi0, eta0 = -y_star_modal, Q.T @ (v0 - c)
    xi1 = (1.0 - a) * xi0 + h * (1.0 - b) * eta0
    eta1 = -(a / h) * xi0 + (1.0 - b) * eta0
    xi_sin = (xi1 / rho - xi0 * cos_t) / sin_t
    eta_sin = (eta1 / rho - eta0 * cos_t) / sin_t
    envelope_F, envelope_v = envelope(modes, np.hypot(xi0, xi_sin)), envelope(modes, np.hypot(eta0, eta_sin))
    margin = 1.0 - MARGIN - 8.0 * EPS * n_cap
    base = F0 + y_star
    # No event or cluster is open (``kernel.all_stuck``): the catalogue only acts on a
    # slip speed above v_start, which the velocities' envelope (largest at step 0) stays below.
    v_start = chain.chain_parameters["v_start"]
    if not np.all(abs(c) + envelope_v < v_start * margin):
        return None

    def safe(n):
        return bool(np.all(np.abs(base + c * h * n) + envelope_F * rho ** n < limit * margin))

    if not safe(0):
        return None
    if safe(n_cap):
        steps = n_cap
    else:
        low, high = 0, n_cap  # safe(low), not safe(high)
        while high - low > 1:
            mid = (low + high) // 2
            low, high = (mid, high) if safe(mid) else (low, mid)
        steps = low
    if steps < 1:
        return None
    decay = math.exp(steps * 0.5 * math.log1p(-b))
    cos_n, sin_n = np.cos(steps * theta), np.sin(steps * theta)
    xi_n = decay * (xi0 * cos_n + xi_sin * sin_n)
    eta_n = decay * (eta0 * cos_n + eta_sin * sin_n)
    ring_n, ring_0 = Q @ xi_n, -y_star
    shift = c * h * steps + (y_star + ring_n)
    v_n = c + Q @ eta_n
    # phi: sum over the steps of h (c - V + w_i(m))^2, the ringing w = Q eta.
    beta = eta0 - 1j * eta_sin  # eta_k(m) = Re(beta_k z_k^m), z_k = rho e^(i theta_k)
    turn_n = np.exp(1j * steps * theta)
    rho2n = decay * decay
    same = _geometric(rho * rho, theta[:, None] + theta[None, :], steps,
                      rho2n * turn_n[:, None] * turn_n[None, :])
    cross = _geometric(rho * rho, theta[:, None] - theta[None, :], steps,
                       rho2n * turn_n[:, None] * np.conj(turn_n)[None, :])
    gram = 0.5 * (np.real(beta[:, None] * beta[None, :] * same)
                  + np.real(beta[:, None] * np.conj(beta)[None, :] * cross))
    squares = np.einsum("ik,ik->i", Q @ gram, Q)
    d_phi = h * (steps * (c - V) ** 2 + squares) + 2.0 * (c - V) * (ring_n - ring_0)
    return steps, x0 + shift, v_n, F0 + shift, d_phi


def apply(chain, jump) -> int:
    """Store a planned jump in the chain's arrays: positions, velocities, shear
    displacements, phi (compensated, as the steps add it), the position before the last
    step, the step counter.  Returns the steps jumped."""
    steps, x, v, F, d_phi = jump
    Y, h = chain.Y, chain.settings.parameters["dt"]
    Y[:, L.Y_X], Y[:, L.Y_VX], Y[:, L.Y_F] = x, v, F
    corrected = d_phi - Y[:, L.Y_PHI_C]
    total = Y[:, L.Y_PHI] + corrected
    Y[:, L.Y_PHI_C] = (total - Y[:, L.Y_PHI]) - corrected
    Y[:, L.Y_PHI] = total
    chain.scratch[:, K.S_X_BEFORE] = x - h * v
    chain.cnt[L.C_STEP] += steps
    return steps
