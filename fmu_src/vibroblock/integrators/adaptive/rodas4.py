"""RODAS4: a Rosenbrock method of order 4 with an embedded order-3 estimate (Hairer &
Wanner, Solving ODEs II, Sec. IV.7: six stages, L-stable and stiffly accurate, so a step
far longer than the contact's and the friction spring's periods damps what has rung down
instead of amplifying it).

It runs on the state (x, z, vx, vz, F, theta) and the quadratures, which ride along as
extra components that feed nothing back.  Every step solves six linear systems with one LU
factorisation of (I/(h gamma) - J); J is the Jacobian of the forces on the
six-dimensional state by central differences (theta's column only where the friction
law moves it: elsewhere it is 0, and the factorisation's arithmetic on the other five
components is what it was without it) (so any variant, reading or law that
``dynamics`` computes is differentiated the same way), and the explicit time dependence
(plate, drive's far end) enters through a difference quotient in t.  Each step carries
its third-order interpolant (from stages 1-5).
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...layout import D_AMP, D_OMEGA, P_ATOL, P_RTOL
from ...laws import friction_interface_slips
from .regimes import NS, NS_MOTION, NV, plate, rates, rhs
from .workspace import F0, FT, K, RATE, SCRATCH, STAGE

# Hairer & Wanner, Sec. IV.7, Table 7.3: the transformed stages
# (I/(h gamma) - J) k_i = f(t + c_i h, y + sum a_ij k_j) + sum (c_ij / h) k_j + h d_i f_t.
GAMMA = 0.25
STAGE_C = np.array([0.0, 0.386, 0.21, 0.63, 1.0, 1.0])
STAGE_D = np.array([0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0])
STAGE_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1.544, 0.0, 0.0, 0.0, 0.0],
    [0.9466785280815826, 0.2557011698983284, 0.0, 0.0, 0.0],
    [3.314825187068521, 2.896124015972201, 0.9986419139977817, 0.0, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0]])
STAGE_CC = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [-5.6688, 0.0, 0.0, 0.0, 0.0],
    [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0],
    [-0.1073529058151375, -9.594562251023355, -20.47028614809616, 0.0, 0.0],
    [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160, 0.0],
    [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054]])
# Dense output y(s) = (1 - s) y0 + s (y1 + (1 - s) (w2 + s w3)), w_r = sum_j DENSE[r, j] k_j.
DENSE = np.array([
    [10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823, 1.025137723295662],
    [-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386, -6.594389125716872]])

EPS = 2.220446049250313e-16
JAC_STEP = 1e-5  # relative increment of the central differences (~eps^(1/3))


def _factor_of(n):
    """LU (partial pivoting) of c I - J on the first n state components; False if singular."""
    @njit(inline="always")
    def factor(jac, c, lu, piv):
        for i in range(n):
            for j in range(n):
                lu[i, j] = -jac[i, j]
            lu[i, i] += c
        for k in range(n):
            p = k
            best = abs(lu[k, k])
            for i in range(k + 1, n):
                if abs(lu[i, k]) > best:
                    best, p = abs(lu[i, k]), i
            piv[k] = p
            if best == 0.0 or not math.isfinite(best):
                return False
            if p != k:
                for j in range(n):
                    lu[k, j], lu[p, j] = lu[p, j], lu[k, j]
            inv = 1.0 / lu[k, k]
            for i in range(k + 1, n):
                lu[i, k] *= inv
                f = lu[i, k]
                for j in range(k + 1, n):
                    lu[i, j] -= f * lu[k, j]
        return True
    return factor


def _solve_of(n):
    """Solve (c I - J) k = r in place on the first n state components; the quadrature rows
    follow from the state's (their columns of J are zero).  ``factor`` swaps whole rows,
    multipliers included, so r takes all the interchanges before the forward substitution
    (interleaving them would pair a row's value with another row's multipliers after a
    later swap)."""
    @njit(inline="always")
    def solve(jac, c, lu, piv, r):
        for k in range(n):
            p = piv[k]
            if p != k:
                r[k], r[p] = r[p], r[k]
        for k in range(n):
            for i in range(k + 1, n):
                r[i] -= lu[i, k] * r[k]
        for k in range(n - 1, -1, -1):
            s = r[k]
            for j in range(k + 1, n):
                s -= lu[k, j] * r[j]
            r[k] = s / lu[k, k]
        inv_c = 1.0 / c
        for i in range(NS, NV):
            s = r[i]
            for j in range(n):
                s += jac[i, j] * r[j]
            r[i] = s * inv_c
    return solve


# Where theta does not move (the laws without an interface slip) its row and column of
# c I - J are c and 0 and its rates 0, so its stage values stay 0: the factorisation and
# the solves run on the five mechanical components alone, at their cost without theta.
_factor_motion, _factor_all = _factor_of(NS_MOTION), _factor_of(NS)
_solve_motion, _solve_all = _solve_of(NS_MOTION), _solve_of(NS)


# linearise and rosenbrock are compiled functions of their own, called rather than inlined
# (rosenbrock has several call sites): the same arithmetic, its code once.
@njit(cache=True)
def linearise(system, clk, v, t_abs, u, ws):
    """f at the step's start (ws F0), its Jacobian on the state block (central
    differences) and its explicit time derivative (ws FT: a difference quotient over an
    exactly representable increment)."""
    kind, regime, drv, prm, track_energy = system
    rows, jac = ws[0], ws[1]
    f0, ft = rows[F0], rows[FT]
    probe, plus, minus = rows[SCRATCH], rows[SCRATCH + 1], rows[SCRATCH + 2]
    pz, pv = plate(drv, clk, u)  # once: every column is taken at the same time
    rhs(kind, regime, v, t_abs, pz, pv, prm, track_energy, f0)
    for i in range(NV):
        probe[i] = v[i]
    # theta's column only where it moves (else it stays 0, as allocated: its rate is 0)
    for j in range(NS if friction_interface_slips(kind) else NS_MOTION):
        step = JAC_STEP * max(1.0, abs(v[j]))
        probe[j] = v[j] + step
        up = probe[j] - v[j]
        rhs(kind, regime, probe, t_abs, pz, pv, prm, track_energy, plus)
        probe[j] = v[j] - step
        down = v[j] - probe[j]
        rhs(kind, regime, probe, t_abs, pz, pv, prm, track_energy, minus)
        probe[j] = v[j]
        inv = 1.0 / (up + down)
        for i in range(NV):
            jac[i, j] = (plus[i] - minus[i]) * inv
    # time: the increment is what t_abs + dt_probe - t_abs really is
    scale = 1.0
    if drv[D_OMEGA] > 0.0 and drv[D_AMP] != 0.0:
        scale = min(1.0, 1.0 / drv[D_OMEGA])
    dt_probe = max(1e-3 * scale, 64.0 * EPS * abs(t_abs))
    t_up = t_abs + dt_probe
    t_down = t_abs - dt_probe
    span = t_up - t_down
    rates(system, clk, v, t_up, u + (t_up - t_abs), plus)
    rates(system, clk, v, t_down, u - (t_abs - t_down), minus)
    inv = 1.0 / span
    for i in range(NV):
        ft[i] = (plus[i] - minus[i]) * inv


@njit(cache=True)
def rosenbrock(system, clk, v, t_abs, u, h, ws, out):
    """One RODAS4 step of length h from v (quadratures of v are 0), from the linearisation
    in ws: fills ``out`` with the new state and the quadrature increments and ws K with
    the stages; returns the weighted RMS error of the state (inf if the matrix is singular)."""
    rows, jac, lu, piv = ws
    prm = system[3]
    f0, ft, stage, rate, k = rows[F0], rows[FT], rows[STAGE], rows[RATE], rows[K:K + 6]
    c = 1.0 / (h * GAMMA)
    slips = friction_interface_slips(system[0])
    if not (_factor_all(jac, c, lu, piv) if slips else _factor_motion(jac, c, lu, piv)):
        return math.inf
    for s in range(6):
        if s == 0:
            for i in range(NV):
                rate[i] = f0[i]
        else:
            for i in range(NV):
                acc = v[i]
                for j in range(s):
                    acc += STAGE_A[s, j] * k[j, i]
                stage[i] = acc
            rates(system, clk, stage, t_abs + STAGE_C[s] * h, u + STAGE_C[s] * h, rate)
        inv_h = 1.0 / h
        for i in range(NV):
            acc = rate[i] + h * STAGE_D[s] * ft[i]
            for j in range(s):
                acc += STAGE_CC[s, j] * inv_h * k[j, i]
            k[s, i] = acc
        if slips:
            _solve_all(jac, c, lu, piv, k[s])
        else:
            _solve_motion(jac, c, lu, piv, k[s])
    err = 0.0
    for i in range(NV):
        out[i] = stage[i] + k[5, i]  # stiffly accurate: the last stage's argument plus k6
    rtol, atol = prm[P_RTOL], prm[P_ATOL]
    for i in range(NS):
        weight = atol + rtol * max(abs(v[i]), abs(out[i]))
        e = k[5, i] / weight
        err += e * e
    err = math.sqrt(err / error_components(system[0]))
    if not math.isfinite(err):
        return math.inf
    return err


@njit(inline="always")
def error_components(kind):
    """The state components the error norms average over: theta only where it moves (its
    error is 0 otherwise, and the norms stay those of the mechanical state)."""
    return NS if friction_interface_slips(kind) else NS_MOTION


@njit(inline="always")
def dense(v, out, ws, s, res):
    """The step's interpolant at fraction s of the step (state components)."""
    rows = ws[0]  # indexed in place: a view per call costs reference counting in the event loop
    for i in range(NS):
        w2 = 0.0
        w3 = 0.0
        for j in range(5):
            w2 += DENSE[0, j] * rows[K + j, i]
            w3 += DENSE[1, j] * rows[K + j, i]
        res[i] = (1.0 - s) * v[i] + s * (out[i] + (1.0 - s) * (w2 + s * w3))


@njit(inline="always")
def jacobian_norm(jac):
    """||J||_inf on the state block: a bound of the spectral radius."""
    norm = 0.0
    for i in range(NS):
        row = 0.0
        for j in range(NS):
            row += abs(jac[i, j])
        norm = max(norm, row)
    return norm
