"""The chain's compiled step: N single blocks, each stepped by the single block's own
scheme and laws, coupled by the springs between neighbours; and the event catalogue.

Each block is a single block (``Settings(model, integrator)``, model A by default): its slots of the
per-block arrays ``Y`` (state, ``layout.Y_*``) and ``PRM`` (parameters, with its own
mu_s) are handed, as row pointers (``unowned.row_pointer``), to the functions the single
block's schemes and driver call, and the driver's ``settle`` (friction rule,
quadratures) ends every block's step.  Two schemes:

* ``symplectic_euler`` (``symplectic_euler.euler_step``): the coupling enters each
  block's step as an extra horizontal force, computed from the positions at the step's
  start (the scheme's forces are all taken there).
* ``rk4`` (the stage rates of ``rk4``): the four stages run over all blocks in lockstep,
  each stage's coupling taken from the neighbours' positions at that stage, so the chain
  is one fourth-order system and its energy balance closes as the single block's does.

Either way a chain of one block is the single block, bit for bit, and the physics of
contact, friction and plate is written nowhere here.

Under the oblique plate law (``laws.plate_oblique``) each block is integrated in the
plate's frame, as the single block is: its x and vx are relative to the plate (the
slip), the friction and contact see them, and the plate's horizontal motion enters as
each block's frame force -m p_x'' - k_p p_x (``integrators.plate.frame_force``: the
loader and the leaf springs stay in the lab).  The coupling springs see differences of
positions, the same in either frame.  So the event catalogue follows the slip velocity
relative to the plate; ``lab_offset`` gives what the lab's x and vx add.

x is each block's displacement from its place in the unloaded chain; the loader of
block i sits at V_d t, so the drive spring of the single block is the chain's leaf
spring k_p, and a coupling spring's stretch is the difference of two displacements.
"""
import math

import numpy as np

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, coulomb_bound
from ..integrators.fixed_step import NON_FINITE, OK, settle
from ..integrators.plate import (drive_sin_cos, frame_force, next_sin_cos, phase_after, plate_at, plate_moves,
                                 plate_sideways)
from ..integrators.rk4 import stage_rates
from ..integrators.symplectic_euler import euler_step
from ..laws import plate_moves_sideways
from ..models import MODELS
from ..readings import encode
from ..layout import (C_STEP, D_DT, D_OMEGA, D_T0, P_KT, P_M, P_MUS, Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_PHI_C,
                      Y_FRICTION_STATE, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from ..unowned import data_pointer, keep_alive, row_pointer, unowned
from .clusters import close, follow

# The chain's own constants, float64 array ``chn``: coupling stiffness, periodic ends
# (1.0) or free (0.0), the slip velocities that start and end an event, the
# catalogue: chain-wide (0.0) or clusters (1.0, ``clusters``), and the scheme (the
# integrator's id: SYMPLECTIC_EULER or RK4).
H_KC, H_PERIODIC, H_V_START, H_V_STOP, H_CLUSTERS, H_SCHEME = range(6)
N_CHN = 6
SYMPLECTIC_EULER, RK4 = 0, 1
# The chain's default physics (model A, every reading and law at its default): its
# symplectic Euler pass is compiled with this kind as a constant, so that every law's
# dispatch folds away; any other kind runs the same pass branching on its bits.  (A numpy
# integer, not a Python one: numba takes it as a plain int64 constant, so the laws' other
# branches, dead after LLVM's folding, compile no extra version of their called functions.)
DEFAULT_KIND = np.int64(encode(MODELS["A"]))
# The open event and the catalogue's bookkeeping, float64 array ``evt``: an event is open
# (1.0), its start time, first block, peak slip speed; events closed in all, rows of the
# catalogue filled since the runner last emptied it, and the last event's potency.
E_OPEN, E_START, E_FIRST, E_PEAK, E_CLOSED, E_ROWS, E_LAST = range(7)
N_EVT = 7
# Per-block scratch, float64 array (N, N_SCRATCH): a slot no longer written (it held the
# coupling force, which the step's pass now computes in place; kept so that saved states
# keep their layout), the position before the step, the position when the open event
# started, whether the block has slipped in the open event, the Coulomb resets of the
# block so far, and for the cluster catalogue the block's cluster now (slot + 1, 0 for
# none); for rk4 the block's position at the current stage, its rates there
# (``rk4.stage_rates``: x, z, vx, vz, F, phi, work, dissipation, normal spring) and their
# weighted sum over the stages so far.
S_PUSH, S_X_BEFORE, S_X_AT_START, S_JOINED, S_RESETS, S_LABEL, S_STAGE_X = range(7)
N_RATES = 9
S_RATES = S_STAGE_X + 1
S_SUM = S_RATES + N_RATES
N_SCRATCH = S_SUM + N_RATES
# One row of the catalogue, float64 array (capacity, N_ROW): start and end time, first
# block (0-based), blocks that slipped, potency (sum of their slips), peak slip speed.
R_START, R_END, R_FIRST, R_BLOCKS, R_POTENCY, R_PEAK = range(6)
N_ROW = 6
CATALOGUE_FULL = 2  # a status: the steps so far are stored; empty the catalogue and call again
STUCK = 3  # a status: every block sticks, quiet, with no event open (``jump_every``); the runner may jump


@njit(inline="always")
def pull_on(scratch, column, i, periodic):
    """x_left - x + x_right - x of block i, the positions in ``column`` of the per-block
    scratch (free ends: no neighbour, no spring).  Indexed in place, not through a
    column view: a view taken per block costs two atomic reference counts."""
    n_blocks = scratch.shape[0]
    x, pull = scratch[i, column], 0.0
    if i > 0 or periodic:
        pull += scratch[i - 1 if i > 0 else n_blocks - 1, column] - x
    if i < n_blocks - 1 or periodic:
        pull += scratch[i + 1 if i < n_blocks - 1 else 0, column] - x
    return pull


@njit(inline="always")
def euler_sweep(kind, drv, Y, PRM, chn, scratch, clock, plate, drive, following, track_energy):
    """One symplectic Euler step of every block in a single pass over the chain: each
    block's coupling k_c (x_left - x + x_right - x) from the positions at the step's start
    (its right neighbour is not stepped yet, its left one's position was kept on the way),
    its step (``step_block``), and what the catalogue needs of its new slip speed.  One
    pass, not one per task: the per-block rows are read once per step, and no index
    wraps around by a division (periodic ends take the two end positions kept before
    the pass).  ``clock`` = (t, t + h, h); ``plate`` = (height, velocity) at t and t + h;
    ``drive`` = the drive's (sin, cos) at t, for the oblique plate's frame force;
    ``following``: an open chain-wide event, whose slipping blocks the pass marks.
    Returns (the first block slipping faster than v_start, -1 if none; whether any slips
    at v_stop or faster; the largest slip speed)."""
    t = clock[0]
    n_blocks = Y.shape[0]
    k_c, periodic, v_start, v_stop = chn[H_KC], chn[H_PERIODIC] != 0.0, chn[H_V_START], chn[H_V_STOP]
    sideways = plate_moves_sideways(kind)
    first_before, left = Y[0, Y_X], Y[n_blocks - 1, Y_X]  # (block 0's left neighbour under periodic ends)
    first, moving, peak = -1, False, 0.0
    for i in range(n_blocks):
        prm, y, own = row_pointer(PRM, i), row_pointer(Y, i), row_pointer(scratch, i)
        x = y[Y_X]
        right = Y[i + 1, Y_X] if i + 1 < n_blocks else first_before
        pull = 0.0  # (summed as pull_on sums it: a lone block's 0.0 adds nothing to its push)
        if i > 0 or periodic:
            pull += left - x
        if i < n_blocks - 1 or periodic:
            pull += right - x
        own[S_X_BEFORE] = left = x
        frame = frame_force(kind, drv, prm, drive[0], drive[1], t) if sideways else 0.0
        own[S_RESETS] = step_block(kind, prm, y, clock, plate, (k_c * pull, frame), own[S_RESETS], track_energy)
        speed = abs(y[Y_VX])
        if speed > v_start:
            first = i if first < 0 else first
            if following:
                own[S_JOINED] = 1.0
        moving = moving or speed >= v_stop
        peak = max(peak, speed)
    return first, moving, peak


@njit(inline="always")
def slip_survey(Y, chn, scratch, following):
    """``euler_sweep``'s findings on the slip speeds after a step taken by another
    scheme (rk4): the first block faster than v_start (-1: none), whether any slips at
    v_stop or faster, the largest speed; an open event's slipping blocks are marked."""
    first, moving, peak = -1, False, 0.0
    for i in range(Y.shape[0]):
        speed = abs(Y[i, Y_VX])
        if speed > chn[H_V_START]:
            first = i if first < 0 else first
            if following:
                scratch[i, S_JOINED] = 1.0
        moving = moving or speed >= chn[H_V_STOP]
        peak = max(peak, speed)
    return first, moving, peak


@njit(inline="always")
def step_block(kind, prm, y, clock, plate, forces, resets, track_energy):
    """One step of one block: the single block's symplectic Euler step with the coupling
    and the plate frame's force ``forces`` = (coupling, frame) at t, then its driver's
    friction rule and quadratures (``fixed_step.settle``).  ``y``, ``prm``: the block's
    slots; ``clock`` = (t, t + h, h); ``plate`` = (height, velocity) at t and t + h.
    Returns the block's Coulomb resets after the step."""
    t, t1, h = clock
    pz0, pv0, pz1, pv1 = plate
    coupling, frame = forces
    # (the single block's push is the frame's force alone: a lone block's coupling 0.0 adds nothing to it)
    push = coupling + frame if frame != 0.0 else coupling
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    contact0 = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    x, z, vx, vz, shear, contact1, d_phi, d_work, d_dissipated, d_normal = euler_step(
        kind, prm, (x, z, vx, vz, shear), t, h, contact0, (pv0, pz1, pv1), track_energy, push)
    if track_energy and frame != 0.0:  # the frame's force works on the block, as in symplectic_euler.step
        d_work += h * frame * y[Y_VX]
    return finish_block(kind, prm, y, (x, z, vx, vz, shear), contact1, (t1, h),
                        (d_phi, d_work, d_dissipated, d_normal), resets, track_energy)


@njit(inline="always")
def finish_block(kind, prm, y, state, contact1, clock, increments, resets, track_energy):
    """A block's step ends as the single block's does: the friction rule and the
    quadratures (``fixed_step.settle``) at the new ``state``, whose contact quantities are
    ``contact1``; ``clock`` = (t + h, h).  Stores the block's slots; returns its resets."""
    x, z, vx, vz, shear = state
    t1, h = clock
    d_phi, d_work, d_dissipated, d_normal = increments
    rule_normal = coulomb_bound(kind, contact1[5], x, t1, prm)
    shear, friction_state, resets, phi, phi_c, work, dissipated, e_normal = settle(
        kind, prm, (shear, y[Y_FRICTION_STATE]), (contact1[0], rule_normal, contact1[2], h), resets,
        (y[Y_PHI], y[Y_PHI_C], y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]), (d_phi, d_work, d_dissipated, d_normal),
        track_energy)
    y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F], y[Y_FRICTION_STATE] = x, z, vx, vz, shear, friction_state
    y[Y_PHI], y[Y_PHI_C], y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL] = phi, phi_c, work, dissipated, e_normal
    return resets


# rk4's stages: (offset from the step's start in units of the step, weight in the sum).
STAGE_OFFSETS = (0.0, 0.5, 0.5, 1.0)
STAGE_WEIGHTS = (1.0, 2.0, 2.0, 1.0)


@njit(inline="always")
def rk4_stage(kind, drv, Y, PRM, chn, scratch, stage, clock, plate, track_energy):
    """Stage ``stage`` of rk4 for every block: its state at the stage from the previous
    stage's rates, the coupling from the neighbours' positions there, its rates
    (``rk4.stage_rates`` with the plate frame's force, plus the coupling), added to the
    weighted sum.  ``clock`` = (t, span); ``plate`` = (height, velocity) at the stage, and
    the drive's sine, cosine and the time at which the single block's driver takes the
    frame's force for the stage."""
    t, span = clock
    sideways = plate_moves_sideways(kind)
    offset = STAGE_OFFSETS[stage] * span
    for i in range(Y.shape[0]):  # every stage position first: the coupling needs the neighbours'
        scratch[i, S_STAGE_X] = Y[i, Y_X] + offset * scratch[i, S_RATES] if stage > 0 else Y[i, Y_X]
    periodic = chn[H_PERIODIC] != 0.0
    for i in range(Y.shape[0]):
        prm, own = row_pointer(PRM, i), row_pointer(scratch, i)
        state = (Y[i, Y_X], Y[i, Y_Z], Y[i, Y_VX], Y[i, Y_VZ], Y[i, Y_F])
        if stage > 0:  # (the first stage at the state itself, to the bit)
            state = (own[S_STAGE_X], state[1] + offset * own[S_RATES + 1], state[2] + offset * own[S_RATES + 2],
                     state[3] + offset * own[S_RATES + 3], state[4] + offset * own[S_RATES + 4])
        frame = frame_force(kind, drv, prm, plate[2], plate[3], plate[4]) if sideways else 0.0
        new = stage_rates(kind, prm, state[0], state[1], state[2], state[3], state[4], t + offset, plate[0],
                          plate[1], frame, track_energy)
        push = chn[H_KC] * pull_on(scratch, S_STAGE_X, i, periodic)
        weight = STAGE_WEIGHTS[stage]
        for k in range(N_RATES):
            value = new[k]
            if k == 2 and push != 0.0:  # (a lone block adds nothing, not even the sign of a zero)
                value += push / prm[P_M]
            own[S_RATES + k] = value
            own[S_SUM + k] = value if stage == 0 else own[S_SUM + k] + weight * value


@njit(inline="always")
def rk4_step(kind, drv, Y, PRM, chn, scratch, clock, plates, track_energy):
    """One rk4 step of the whole chain, each block then finished as the single block's
    (``finish_block``).  ``clock`` = (t, t + h, h, span); ``plates`` = the stage plates
    of ``rk4_stage`` at t, t + h/2 and t + h.  The block's own rk4 arithmetic, to the
    bit, where no coupling acts."""
    t, t1, h, span = clock
    start, half, end = plates
    pz1, pv1 = end[0], end[1]
    for i in range(Y.shape[0]):
        scratch[i, S_X_BEFORE] = Y[i, Y_X]
    rk4_stage(kind, drv, Y, PRM, chn, scratch, 0, (t, span), start, track_energy)
    rk4_stage(kind, drv, Y, PRM, chn, scratch, 1, (t, span), half, track_energy)
    rk4_stage(kind, drv, Y, PRM, chn, scratch, 2, (t, span), half, track_energy)
    rk4_stage(kind, drv, Y, PRM, chn, scratch, 3, (t, span), end, track_energy)
    sixth = span / 6.0
    for i in range(Y.shape[0]):
        prm, y, own = row_pointer(PRM, i), row_pointer(Y, i), row_pointer(scratch, i)
        sums = (own[S_SUM], own[S_SUM + 1], own[S_SUM + 2], own[S_SUM + 3], own[S_SUM + 4], own[S_SUM + 5],
                own[S_SUM + 6], own[S_SUM + 7], own[S_SUM + 8])
        x, z = y[Y_X] + sixth * sums[0], y[Y_Z] + sixth * sums[1]
        vx, vz, shear = y[Y_VX] + sixth * sums[2], y[Y_VZ] + sixth * sums[3], y[Y_F] + sixth * sums[4]
        contact1 = contact(kind, x, z, vx, vz, pz1, pv1, prm)
        own[S_RESETS] = finish_block(kind, prm, y, (x, z, vx, vz, shear), contact1, (t1, h),
                                     (sixth * sums[5], sixth * sums[6], sixth * sums[7], sixth * sums[8]),
                                     own[S_RESETS], track_energy)


@njit(inline="always")
def open_event(Y, evt, scratch, v_start, first, t):
    """Open an event at block ``first``, the first whose slip speed exceeds v_start: the
    positions before the step as the event's start, and the blocks slipping now as its
    first members."""
    evt[E_OPEN], evt[E_START], evt[E_FIRST], evt[E_PEAK] = 1.0, t, first, 0.0
    for i in range(Y.shape[0]):
        scratch[i, S_X_AT_START] = scratch[i, S_X_BEFORE]
        scratch[i, S_JOINED] = 1.0 if abs(Y[i, Y_VX]) > v_start else 0.0


@njit(inline="always")
def catalogue(Y, chn, evt, scratch, rows, survey, clock):
    """After a step from t to t1 (``clock``) whose slip speeds the pass surveyed
    (``survey``: ``euler_sweep``'s findings, the open event's slipping blocks marked):
    open an event, follow the open one's peak speed, and close it into the next row of
    ``rows`` once every block's slip speed is below v_stop.  Returns CATALOGUE_FULL when
    the last row was filled."""
    first, moving, peak = survey
    t, t1 = clock
    if evt[E_OPEN] == 0.0:
        if first < 0:
            return OK
        open_event(Y, evt, scratch, chn[H_V_START], first, t)
    evt[E_PEAK] = max(evt[E_PEAK], peak)  # (the largest of the speeds, in any order)
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


@njit(inline="always")
def all_stuck(kind, Y, PRM, chn, evt, scratch, t, plate_z, plate_v):
    """Whether every block sticks quietly and the catalogue has nothing open: no chain-wide
    event (or no block in a cluster), every block's friction law in its stick (state 0),
    its spring inside the Coulomb bound (|k_t F| < mu_s N, N the bound's normal at time t
    with the plate at (``plate_z``, ``plate_v``), as ``rest_probe`` takes it) and its slip
    speed below v_stop.  The cheap test
    ``advance`` makes every ``jump_every`` steps; the runner's jump (``chain.jump``) checks
    the rest."""
    clusters, v_stop = chn[H_CLUSTERS] != 0.0, chn[H_V_STOP]
    if not clusters and evt[E_OPEN] != 0.0:
        return False
    for i in range(Y.shape[0]):
        if Y[i, Y_FRICTION_STATE] != 0.0 or not abs(Y[i, Y_VX]) < v_stop:
            return False
        if clusters and scratch[i, S_LABEL] != 0.0:
            return False
        prm = row_pointer(PRM, i)
        normal = coulomb_bound(kind, contact(kind, Y[i, Y_X], Y[i, Y_Z], Y[i, Y_VX], Y[i, Y_VZ], plate_z, plate_v,
                                             prm)[5], Y[i, Y_X], t, prm)
        if not abs(prm[P_KT] * Y[i, Y_F]) < prm[P_MUS] * normal:
            return False
    return True


@njit(cache=True)
def advance(kind, Y, PRM, cnt, drv, chn, evt, scratch, rows, clu, steps, track_energy):
    """Advance the chain by up to n_steps grid steps, ``steps`` = (n_steps, jump_every).
    Returns OK, CATALOGUE_FULL (the steps taken so far are stored: empty ``rows`` and call
    again), STUCK (``jump_every`` > 0: after a step whose number is a multiple of it,
    every block sticks quietly, ``all_stuck``; the steps so far are stored) or NON_FINITE
    (the arrays are then partly advanced: the runner restores its copy).  ``jump_every``
    = 0: no test, the pass is the plain one."""
    n_steps, jump_every = steps
    drv, cnt, chn = data_pointer(drv), data_pointer(cnt), data_pointer(chn)
    # The per-block arrays through views numba does not count: handed to the step's
    # functions, the counted arrays cost atomic counts at every step (a chain of one
    # block took 117 ns per step with them, 19 without).
    owned = (Y, PRM, evt, scratch, rows, clu)
    Y, PRM, evt, scratch = unowned(Y), unowned(PRM), unowned(evt), unowned(scratch)
    rows, clu = unowned(rows), unowned(clu)
    t0, dt = drv[D_T0], drv[D_DT]
    moving = plate_moves(drv)
    n = cnt[C_STEP]
    rot_s, rot_c = math.sin(drv[D_OMEGA] * dt), math.cos(drv[D_OMEGA] * dt)
    half_s, half_c = math.sin(0.5 * drv[D_OMEGA] * dt), math.cos(0.5 * drv[D_OMEGA] * dt)
    rk4 = chn[H_SCHEME] == RK4
    s, c = drive_sin_cos(drv, cnt, n)
    t = t0 + n * dt
    pz0, pv0 = plate_at(drv, s, c, t)
    status = OK
    for _ in range(n_steps):
        n1 = n + 1
        t1 = t0 + n1 * dt
        s0, c0 = s_half, c_half = s, c
        pz1, pv1 = pzh, pvh = pz0, pv0
        if moving:
            s_half, c_half = s * half_c + c * half_s, c * half_c - s * half_s
            if rk4:  # the half step's plate, as the single block's driver takes it
                pzh, pvh = plate_at(drv, s_half, c_half, t + 0.5 * dt)
            s, c = next_sin_cos(drv, cnt, n1, s, c, rot_s, rot_c)
            pz1, pv1 = plate_at(drv, s, c, t1)
        chain_wide = chn[H_CLUSTERS] == 0.0
        following = chain_wide and evt[E_OPEN] != 0.0
        if rk4:
            rk4_step(kind, drv, Y, PRM, chn, scratch, (t, t1, dt, t1 - t),
                     ((pz0, pv0, s0, c0, t), (pzh, pvh, s_half, c_half, t + 0.5 * dt), (pz1, pv1, s, c, t1)),
                     track_energy)
            survey = slip_survey(Y, chn, scratch, following) if chain_wide else (-1, False, 0.0)
        elif kind == DEFAULT_KIND:  # the same pass with every law's branch settled at compile time
            survey = euler_sweep(DEFAULT_KIND, drv, Y, PRM, chn, scratch, (t, t1, dt), (pz0, pv0, pz1, pv1),
                                 (s0, c0), following, track_energy)
        else:
            survey = euler_sweep(kind, drv, Y, PRM, chn, scratch, (t, t1, dt), (pz0, pv0, pz1, pv1), (s0, c0),
                                 following, track_energy)
        if chain_wide:
            status = catalogue(Y, chn, evt, scratch, rows, survey, (t, t1))
        else:
            status = cluster_catalogue(Y, chn, clu, scratch, rows, evt, t, t1)
        n, t, pz0, pv0 = n1, t1, pz1, pv1
        if status != OK:
            break
        if jump_every > 0 and n % jump_every == 0 and all_stuck(kind, Y, PRM, chn, evt, scratch, t, pz0, pv0):
            status = STUCK
            break
    cnt[C_STEP] = n
    finite = True
    for i in range(Y.shape[0]):
        finite = finite and math.isfinite(Y[i, Y_X] + Y[i, Y_Z] + Y[i, Y_VX] + Y[i, Y_VZ] + Y[i, Y_F])
    keep_alive(owned)
    return status if finite else NON_FINITE


@njit(cache=True)
def penetrations(kind, Y, PRM, plate_z):
    """Each block's penetration as its contact sees it (``dynamics.contact``: on a
    corrugated plate the depth below the surface along its normal), at the plate height
    ``plate_z``: the runner books each block's contact energy from it, as the single
    block does."""
    out = np.empty(Y.shape[0])
    for i in range(Y.shape[0]):
        out[i] = contact(kind, Y[i, Y_X], Y[i, Y_Z], Y[i, Y_VX], Y[i, Y_VZ], plate_z, 0.0, PRM[i])[0]
    return out


@njit(cache=True)
def lab_offset(kind, drv, cnt):
    """The plate's horizontal position and velocity at the stored grid step, which the
    lab's x and vx add to the blocks' (plate-frame) slots: the single block's observation
    at a grid time (``fixed_step.observe``, exact sin/cos), 0 under the vertical law."""
    drv, cnt = data_pointer(drv), data_pointer(cnt)
    if not plate_moves_sideways(kind):
        return 0.0, 0.0
    n = cnt[C_STEP]
    phase = phase_after(drv, cnt, n, 0.0)
    position, velocity, _ = plate_sideways(kind, drv, math.sin(phase), math.cos(phase), drv[D_T0] + n * drv[D_DT])
    return position, velocity


@njit(cache=True)
def rest_probe(kind, Y, PRM, cnt, drv, normals):
    """Each block's Coulomb bound's N over a jump (``chain.jump``), in ``normals``: one
    trial step of each block from the stored state (a copy: the state is not touched),
    without coupling, by the pass's own ``step_block``.  A block whose height and vertical
    velocity that step leaves unchanged, to the bit, in contact, keeps its contact force,
    which on the flat plate does not depend on x or vx: it is that force.  Any other
    block gets NaN (its contact still rings, or it is off the plate)."""
    drv, cnt = data_pointer(drv), data_pointer(cnt)
    n = cnt[C_STEP]
    t0, dt = drv[D_T0], drv[D_DT]
    t, t1 = t0 + n * dt, t0 + (n + 1) * dt
    s, c = drive_sin_cos(drv, cnt, n)
    pz, pv = plate_at(drv, s, c, t)
    for i in range(Y.shape[0]):
        y, prm = Y[i].copy(), PRM[i]
        step_block(kind, prm, y, (t, t1, dt), (pz, pv, pz, pv), (0.0, 0.0), 0.0, False)
        rest = y[Y_Z] == Y[i, Y_Z] and y[Y_VZ] == Y[i, Y_VZ]
        contact1 = contact(kind, y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], pz, pv, prm)
        normals[i] = coulomb_bound(kind, contact1[5], y[Y_X], t1, prm) if rest and contact1[0] > 0.0 else math.nan
