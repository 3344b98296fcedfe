"""DOP853: Dormand & Prince's explicit pair of order 8 with error estimators of orders 5
and 3 (Hairer, Norsett & Wanner, Solving ODEs I, Sec. II.10), the tableau as scipy ships
it (stored beside this module in ``dop853_tableau.npz``, so that an FMU's first step
does not import scipy.integrate, a third of a second; a test checks it against scipy's
to the bit): 12 stages, the 13th rate f(t + h, y1) serving the error estimate, the step's cubic
Hermite interpolant and the next step's first stage.

Where the motion is not stiff (ringing contact and friction springs, flights, slips: the
step is limited by accuracy, not stability) this pair takes the steps: its eighth order
needs several times fewer steps than RODAS4 at rtol <= 1e-6, and a step costs 13 rates
instead of 17 rates and an LU.  Its stability bound is h |lambda| ~ 6 on the negative
axis; ``stiffness`` is Hairer's estimate of h rho from its last two rates.
"""
import math
from pathlib import Path

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...layout import P_ATOL, P_RTOL
from .regimes import NS, NV, rates
from .rodas4 import error_components
from .workspace import EXPLICIT_STAGES, F0, KX, STAGE

TABLEAU = Path(__file__).with_name("dop853_tableau.npz")
with np.load(TABLEAU) as _tableau:
    EXPLICIT_A = np.ascontiguousarray(_tableau["A"][:EXPLICIT_STAGES, :EXPLICIT_STAGES])
    EXPLICIT_B = np.ascontiguousarray(_tableau["B"])
    EXPLICIT_C = np.ascontiguousarray(_tableau["C"][:EXPLICIT_STAGES])
    EXPLICIT_E5 = np.ascontiguousarray(_tableau["E5"])
    EXPLICIT_E3 = np.ascontiguousarray(_tableau["E3"])


@njit(cache=True)
def explicit_step(system, clk, v, t_abs, u, h, ws, out):
    """One DOP853 step of length h from v (quadratures of v are 0; ws F0 the rate at v):
    fills ``out`` with the new state and the quadrature increments, ws KX with the 12
    stages and the rate at the new state, ws STAGE with the last stage's argument;
    returns the weighted RMS error of the state (the two estimators combined as in DOP853)."""
    rows = ws[0]
    prm = system[3]
    f0, stage, kx = rows[F0], rows[STAGE], rows[KX:KX + EXPLICIT_STAGES + 1]
    for i in range(NV):
        kx[0, i] = f0[i]
    for s in range(1, EXPLICIT_STAGES):
        for i in range(NV):
            acc = 0.0
            for j in range(s):
                acc += EXPLICIT_A[s, j] * kx[j, i]
            stage[i] = v[i] + h * acc
        rates(system, clk, stage, t_abs + EXPLICIT_C[s] * h, u + EXPLICIT_C[s] * h, kx[s])
    for i in range(NV):
        acc = 0.0
        for j in range(EXPLICIT_STAGES):
            acc += EXPLICIT_B[j] * kx[j, i]
        out[i] = v[i] + h * acc
    rates(system, clk, out, t_abs + h, u + h, kx[EXPLICIT_STAGES])
    rtol, atol = prm[P_RTOL], prm[P_ATOL]
    err5 = err3 = 0.0
    for i in range(NS):
        e5 = e3 = 0.0
        for j in range(EXPLICIT_STAGES + 1):
            e5 += EXPLICIT_E5[j] * kx[j, i]
            e3 += EXPLICIT_E3[j] * kx[j, i]
        weight = atol + rtol * max(abs(v[i]), abs(out[i]))
        err5 += (e5 / weight) ** 2
        err3 += (e3 / weight) ** 2
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    err = abs(h) * err5 / math.sqrt((err5 + 0.01 * err3) * error_components(system[0]))
    if not math.isfinite(err):
        return math.inf
    return err


@njit(inline="always")
def stiffness(h, ws, out):
    """h rho with rho ~ |f(y1) - f(y12)| / |y1 - y12| over the state (DOP853's test)."""
    rows = ws[0]
    num = den = 0.0
    for i in range(NS):
        num += (rows[KX + EXPLICIT_STAGES, i] - rows[KX + EXPLICIT_STAGES - 1, i]) ** 2
        den += (out[i] - rows[STAGE, i]) ** 2
    return h * math.sqrt(num / den) if den > 0.0 else 0.0


@njit(inline="always")
def hermite(v, out, ws, h, s, res):
    """The cubic Hermite interpolant of the step's end values and rates at fraction s."""
    rows = ws[0]  # indexed in place: a view per call costs reference counting in the event loop
    s2 = s * s
    s3 = s2 * s
    a0, a1 = 2.0 * s3 - 3.0 * s2 + 1.0, -2.0 * s3 + 3.0 * s2
    b0, b1 = h * (s3 - 2.0 * s2 + s), h * (s3 - s2)
    for i in range(NS):
        res[i] = a0 * v[i] + a1 * out[i] + b0 * rows[KX, i] + b1 * rows[KX + EXPLICIT_STAGES, i]
