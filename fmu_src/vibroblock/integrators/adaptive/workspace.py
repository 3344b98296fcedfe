"""The scratch arrays every step shares, allocated once per call: rows of one float64
array with named slots, the Jacobian, its LU factors and pivots.

A row is one vector of the integration (``regimes.NV`` components); several consecutive
rows are a stage table.  The slots are fixed roles: the rate at the step's start (F0, the
explicit pair's last rate carried into the next step), the time derivative (FT), a stage's
argument (STAGE) and rate (RATE), a step's end (TRIAL), the state at a located switch
(BEST), a probe (PROBE), three rows for the central differences and interpolant samples
(SCRATCH), RODAS4's six stages (K) and DOP853's twelve plus the end rate (KX).
"""
import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from .regimes import NS, NV

EXPLICIT_STAGES = 12  # DOP853's stages; the 13th rate is the end's
F0, FT, STAGE, RATE, TRIAL, BEST, PROBE = range(7)
SCRATCH = 7
K = SCRATCH + 3
KX = K + 6
ROWS = KX + EXPLICIT_STAGES + 1


@njit(inline="always")
def workspace():
    """(rows, Jacobian on the state block, LU factors, pivots)."""
    return (np.zeros((ROWS, NV)), np.zeros((NV, NS)), np.zeros((NS, NS)), np.zeros(NS, dtype=np.int64))
