"""The chain's compiled step: N single blocks, each stepped by the single block's own
scheme and laws, coupled by the springs between neighbours; and the event catalogue.

Each block is a model-A block (``Settings("A", "symplectic_euler")``): its slots of
the per-block arrays ``Y`` (state, ``layout.Y_*``) and ``PRM`` (parameters, with its
own mu_s) are handed, as row pointers (``unowned.row_pointer``), to the functions the
single block's driver calls: ``symplectic_euler.euler_step`` and the driver's
``settle`` (friction rule, quadratures).  The coupling enters each block's step as an
extra horizontal force, computed from the positions at the step's start (the scheme's
forces are all taken there).  So a chain of one block is the single block, bit for bit,
and the physics of contact, friction and plate is written nowhere here.

x is each block's displacement from its place in the unloaded chain; the loader of
block i sits at V_d t, so the drive spring of the single block is the chain's leaf
spring k_p, and a coupling spring's stretch is the difference of two displacements.
"""
import math

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, coulomb_bound
from ..integrators.fixed_step import NON_FINITE, OK, settle
from ..integrators.plate import drive_sin_cos, next_sin_cos, plate_at, plate_moves
from ..integrators.symplectic_euler import euler_step
from ..layout import (C_STEP, D_DT, D_OMEGA, D_T0, Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_PHI_C, Y_FRICTION_STATE,
                      Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from ..unowned import data_pointer, row_pointer
from .clusters import close, follow

# The chain's own constants, float64 array ``chn``: coupling stiffness, periodic ends
# (1.0) or free (0.0), the slip velocities that start and end an event, and the
# catalogue: chain-wide (0.0) or clusters (1.0, ``clusters``).
H_KC, H_PERIODIC, H_V_START, H_V_STOP, H_CLUSTERS = range(5)
N_CHN = 5
# The open event and the catalogue's bookkeeping, float64 array ``evt``: an event is open
# (1.0), its start time, first block, peak slip speed; events closed in all, rows of the
# catalogue filled since the runner last emptied it, and the last event's potency.
E_OPEN, E_START, E_FIRST, E_PEAK, E_CLOSED, E_ROWS, E_LAST = range(7)
N_EVT = 7
# Per-block scratch, float64 array (N, N_SCRATCH): the coupling force of this step, the
# position before it, the position when the open event started, whether the block has
# slipped in the open event, the Coulomb resets of the block so far, and for the cluster
# catalogue the block's cluster now (slot + 1, 0 for none).
S_PUSH, S_X_BEFORE, S_X_AT_START, S_JOINED, S_RESETS, S_LABEL = range(6)
N_SCRATCH = 6
# One row of the catalogue, float64 array (capacity, N_ROW): start and end time, first
# block (0-based), blocks that slipped, potency (sum of their slips), peak slip speed.
R_START, R_END, R_FIRST, R_BLOCKS, R_POTENCY, R_PEAK = range(6)
N_ROW = 6
CATALOGUE_FULL = 2  # a status: the steps so far are stored; empty the catalogue and call again


@njit(inline="always")
def couple(Y, chn, scratch):
    """Each block's coupling force k_c (x_left - x + x_right - x) from the positions now,
    free ends (no neighbour, no spring) or periodic; and the positions, kept as the
    positions before the step."""
    n_blocks = Y.shape[0]
    k_c, periodic = chn[H_KC], chn[H_PERIODIC] != 0.0
    for i in range(n_blocks):
        x = Y[i, Y_X]
        scratch[i, S_X_BEFORE] = x
        pull = 0.0
        if i > 0 or periodic:
            pull += Y[(i - 1) % n_blocks, Y_X] - x
        if i < n_blocks - 1 or periodic:
            pull += Y[(i + 1) % n_blocks, Y_X] - x
        scratch[i, S_PUSH] = k_c * pull


@njit(inline="always")
def step_block(kind, prm, y, clock, plate, push, resets, track_energy):
    """One step of one block: the single block's symplectic Euler step with the coupling
    ``push``, then its driver's friction rule and quadratures (``fixed_step.settle``).
    ``y``, ``prm``: the block's slots; ``clock`` = (t, t + h, h); ``plate`` = (height,
    velocity) at t and t + h.  Returns the block's Coulomb resets after the step."""
    t, t1, h = clock
    pz0, pv0, pz1, pv1 = plate
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    contact0 = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    x, z, vx, vz, shear, contact1, d_phi, d_work, d_dissipated, d_normal = euler_step(
        kind, prm, (x, z, vx, vz, shear), t, h, contact0, (pv0, pz1, pv1), track_energy, push)
    rule_normal = coulomb_bound(kind, contact1[5], x, t1, prm)
    shear, friction_state, resets, phi, phi_c, work, dissipated, e_normal = settle(
        kind, prm, (shear, y[Y_FRICTION_STATE]), (contact1[0], rule_normal, contact1[2], h), resets,
        (y[Y_PHI], y[Y_PHI_C], y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]), (d_phi, d_work, d_dissipated, d_normal),
        track_energy)
    y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F], y[Y_FRICTION_STATE] = x, z, vx, vz, shear, friction_state
    y[Y_PHI], y[Y_PHI_C], y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL] = phi, phi_c, work, dissipated, e_normal
    return resets


@njit(inline="always")
def open_event(Y, evt, scratch, v_start, t):
    """Open an event if a block's slip speed exceeds v_start: its first such block, the
    positions before the step as the event's start."""
    for first in range(Y.shape[0]):
        if abs(Y[first, Y_VX]) > v_start:
            evt[E_OPEN], evt[E_START], evt[E_FIRST], evt[E_PEAK] = 1.0, t, first, 0.0
            for i in range(Y.shape[0]):
                scratch[i, S_X_AT_START], scratch[i, S_JOINED] = scratch[i, S_X_BEFORE], 0.0
            return


@njit(inline="always")
def catalogue(Y, chn, evt, scratch, rows, t, t1):
    """After a step from t to t1: open an event, follow the open one (which blocks slip,
    its peak speed), and close it into the next row of ``rows`` once every block's slip
    speed is below v_stop.  Returns CATALOGUE_FULL when the last row was filled."""
    if evt[E_OPEN] == 0.0:
        open_event(Y, evt, scratch, chn[H_V_START], t)
        if evt[E_OPEN] == 0.0:
            return OK
    moving = False
    for i in range(Y.shape[0]):
        speed = abs(Y[i, Y_VX])
        if speed > chn[H_V_START]:
            scratch[i, S_JOINED] = 1.0
        moving = moving or speed >= chn[H_V_STOP]
        evt[E_PEAK] = max(evt[E_PEAK], speed)
    if moving:
        return OK
    potency, joined = 0.0, 0.0
    for i in range(Y.shape[0]):
        if scratch[i, S_JOINED] != 0.0:
            potency += Y[i, Y_X] - scratch[i, S_X_AT_START]
            joined += 1.0
    row = int(evt[E_ROWS])
    rows[row, R_START], rows[row, R_END], rows[row, R_FIRST] = evt[E_START], t1, evt[E_FIRST]
    rows[row, R_BLOCKS], rows[row, R_POTENCY], rows[row, R_PEAK] = joined, potency, evt[E_PEAK]
    evt[E_OPEN], evt[E_ROWS], evt[E_CLOSED], evt[E_LAST] = 0.0, row + 1.0, evt[E_CLOSED] + 1.0, potency
    return CATALOGUE_FULL if row + 1 >= rows.shape[0] else OK


@njit(inline="always")
def cluster_catalogue(Y, chn, clu, scratch, rows, evt, t, t1):
    """After a step from t to t1: follow the clusters of slipping blocks (``clusters``)
    and close those no block slips in any more into ``rows``.  Returns CATALOGUE_FULL
    when fewer rows are left than clusters could close at the next step."""
    follow(Y, clu, scratch[:, S_LABEL], scratch[:, S_X_BEFORE], (chn[H_V_START], chn[H_V_STOP]), t,
           chn[H_PERIODIC] != 0.0)
    first_row = int(evt[E_ROWS])
    row, last = close(clu, rows, first_row, t1)
    if row > first_row:
        evt[E_ROWS], evt[E_CLOSED], evt[E_LAST] = row, evt[E_CLOSED] + (row - first_row), last
    return CATALOGUE_FULL if rows.shape[0] - row < clu.shape[0] else OK


@njit(cache=True)
def advance(kind, Y, PRM, cnt, drv, chn, evt, scratch, rows, clu, n_steps, track_energy):
    """Advance the chain by up to n_steps grid steps.  Returns OK, CATALOGUE_FULL (the
    steps taken so far are stored: empty ``rows`` and call again) or NON_FINITE (the
    arrays are then partly advanced: the runner restores its copy)."""
    drv, cnt, chn = data_pointer(drv), data_pointer(cnt), data_pointer(chn)
    t0, dt = drv[D_T0], drv[D_DT]
    moving = plate_moves(drv)
    n = cnt[C_STEP]
    rot_s, rot_c = math.sin(drv[D_OMEGA] * dt), math.cos(drv[D_OMEGA] * dt)
    s, c = drive_sin_cos(drv, cnt, n)
    t = t0 + n * dt
    pz0, pv0 = plate_at(drv, s, c, t)
    status = OK
    for _ in range(n_steps):
        n1 = n + 1
        t1 = t0 + n1 * dt
        pz1, pv1 = pz0, pv0
        if moving:
            s, c = next_sin_cos(drv, cnt, n1, s, c, rot_s, rot_c)
            pz1, pv1 = plate_at(drv, s, c, t1)
        couple(Y, chn, scratch)
        for i in range(Y.shape[0]):
            scratch[i, S_RESETS] = step_block(kind, row_pointer(PRM, i), row_pointer(Y, i), (t, t1, dt),
                                              (pz0, pv0, pz1, pv1), scratch[i, S_PUSH], scratch[i, S_RESETS],
                                              track_energy)
        if chn[H_CLUSTERS] != 0.0:
            status = cluster_catalogue(Y, chn, clu, scratch, rows, evt, t, t1)
        else:
            status = catalogue(Y, chn, evt, scratch, rows, t, t1)
        n, t, pz0, pv0 = n1, t1, pz1, pv1
        if status != OK:
            break
    cnt[C_STEP] = n
    for i in range(Y.shape[0]):
        if not math.isfinite(Y[i, Y_X] + Y[i, Y_Z] + Y[i, Y_VX] + Y[i, Y_VZ] + Y[i, Y_F]):
            return NON_FINITE
    return status
