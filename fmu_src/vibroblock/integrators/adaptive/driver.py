"""The driver: a call's loop over named steps, and the ``advance``/``observe`` kernels.

``evolve`` reads like the method: the initial regime (``_start``), then per iteration the
method for this step and the clock (``_prepare``), a stroboscopic jump where one may pay
(``_try_jump``), a step attempted (``_attempt``) and rejected or kept, the events on its
interpolant and their location on full steps (``events``), and the commit of the step or
the switch at the located event (``_commit``, ``_switch``).

A call's scalars live in three small arrays with named slots: ``ic`` the counters and the
integer controls (its first six slots are the costs a call reports), ``tm`` the times and
step lengths, ``acc`` the quadratures' sums.
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import contact
from ...laws import friction_energy, friction_integrated, friction_interface_slips, friction_spring_force, friction_stored
from ...unowned import data_pointer, keep_alive, unowned, unowned_each
from ...layout import (C_ACCEPTED, C_EVENTS, C_JACOBIANS, C_JUMPED, C_REJECTED, C_SLIPS, C_STEP, D_AMP, D_DT,
                       D_EXT_A, D_EXT_V, D_EXT_Z, D_OMEGA, D_T0, N_OBS, P_MAX_JUMP, P_RTOL, Y_DISSIPATED,
                       Y_E_NORMAL, Y_F, Y_FRICTION_STATE, Y_PHI, Y_PHI_C, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from ..fixed_step import kahan_add, record_observation
from .dop853 import stiffness
from .events import EVENT_TOL, first_event, locate_switch
from .jumps import (STROBE_MIN, STROBE_PAYBACK, STROBE_SHARE, STROBE_TRY, STROBE_WAIT, STROBE_WAIT_MAX,
                    stroboscopic)
from .methods import (EVENT_SAMPLES, EXPLICIT_CALM, EXPLICIT_STIFF, STIFF_AFTER, STIFF_FORGET, STIFF_HOLD,
                      growth, interpolate, shrink, step, stiffest_rate)
from .regimes import (CASCADE, EV_CONTACT, EV_DETACH, EV_HOLD, EV_NONE, EV_REARM, EV_RESET_MINUS, EV_RESET_PLUS,
                      FLIGHT, HELD, LOADED, NS, NV, THETA, advance_clock, bound, clearance, clock, plate, rates,
                      reach_time, regime_after_contact)
from .rodas4 import EPS, jacobian_norm, linearise, rosenbrock
from .workspace import F0, KX, PROBE, TRIAL, BEST, EXPLICIT_STAGES, workspace

# Statuses (negative: failure, the arrays untouched).
OK = 0
NON_FINITE = -1
STEP_TOO_SMALL = -2
TOO_MANY_STEPS = -3
TOO_MANY_EVENTS = -4

# Largest step while the plate moves harmonically, as a fraction of its period.
CYCLE_FRACTION = 1.0 / 16.0
# A flight above the plate's reach (the block higher than the plate at its highest) may
# step past that cap, up to this share of the time its clearance model gives until the
# block could first be within the reach again (``regimes.reach_time``).
REACH_SHARE = 0.5
# Resets closer together than this (tau_0) are the accumulation before a zero of N.
CASCADE_GAP = 1e-9
# Internal steps (accepted + rejected) one call may take.
MAX_STEPS = 1 << 24
# Events in a row without the time moving by more than EVENT_TOL before the run stops.
MAX_IMMEDIATE = 64
# A call moves the plate's clock to its local time at least every REBASE_CYCLES plate
# periods, so omega u stays below ~400 rad (rounding ~6e-14 rad).
REBASE_CYCLES = 64
# Leaps across the error estimate's hump: a lightly damped mode (the friction spring
# rings for 2m/gamma_t ~ 1e4) whose amplitude the local errors keep at the tolerance
# makes the estimate grow with h while h |lambda| ~ 1-1000 and vanish beyond (both
# embedded solutions damp it).  After LEAP_AFTER accepted steps in a row that could not
# grow, a step LEAP times longer is tried; it is kept only if its own error estimate
# passes (else it counts as rejected).
LEAP_AFTER, LEAP = 8, 1e4

# ic: the costs (in the order a call reports them), then the controls.
(I_SLIPS, I_ACCEPTED, I_REJECTED, I_EVENTS, I_JACOBIANS, I_JUMPED, I_REGIME, I_EXPLICIT, I_NEXT_EXPLICIT,
 I_FRESH, I_STIFF, I_CALM, I_HOLD, I_STAGNANT, I_IMMEDIATE, I_WITHIN_REACH, I_STROBE_WAIT, I_REFUSED,
 I_LAST) = range(19)
N_COSTS = 6
# tm: the local time u, the clock origin's absolute time, the time covered before it, the
# call's end, the last reset, the next jump try; the step, the error control's step before
# the cap, the next step; the cap, the plate's period (0: no jumps), its highest point
# (nan: unknown), when to move the clock, the stiffest contact rate.
(T_U, T_BASE, T_DONE, T_END, T_LAST_RESET, T_STROBE_NEXT, T_H, T_H_WANT, T_H_NEXT, T_CAP, T_PERIOD, T_TOP,
 T_REBASE_AFTER, T_STIFFEST) = range(14)
# acc: phi with its compensation, work, dissipation, normal-spring energy.
A_PHI, A_PHI_C, A_WORK, A_DISSIPATED, A_E_NORMAL = range(5)


@njit(inline="always")
def _system(run, ic):
    """The right-hand side's constants in the current regime (``regimes.rates``)."""
    kind, drv, prm, track_energy = run
    return kind, ic[I_REGIME], drv, prm, track_energy


@njit(inline="always")
def _finite(v):
    return math.isfinite(v[0] + v[1] + v[2] + v[3] + v[4] + v[THETA])


@njit(inline="always")
def _move_origin(tm, shift):
    """The call's local times after its origin moves forward by ``shift`` (the local time u
    there becomes 0): the origin's absolute time, the time covered before it, the call's end
    and the last reset."""
    tm[T_BASE] += shift
    tm[T_DONE] += shift
    tm[T_END] -= shift
    tm[T_LAST_RESET] -= shift


@njit(inline="always")
def _commit(v, acc, src):
    """Take the state of src and add its quadrature increments."""
    for i in range(NS):
        v[i] = src[i]
    acc[A_PHI], acc[A_PHI_C] = kahan_add(acc[A_PHI], acc[A_PHI_C], src[NS])
    acc[A_WORK] += src[NS + 1]
    acc[A_DISSIPATED] += src[NS + 2]
    acc[A_E_NORMAL] += src[NS + 3]


@njit
def _initial_regime(run, v, acc, ic, t_base, clk):
    """The regime of the stored state, with the friction rule applied to it (a law whose
    interface slips has no reset: its spring is released only where the bound's N is not
    positive)."""
    kind, drv, prm, track_energy = run
    pz, pv = plate(drv, clk, 0.0)
    pen, bound_now = bound(kind, v, t_base, pz, pv, prm)
    if pen > 0.0:
        slips = friction_interface_slips(kind)
        if (bound_now <= 0.0 if slips else abs(friction_spring_force(kind, v[4], prm)) >= bound_now):
            if v[4] != 0.0:
                ic[I_SLIPS] += 1
                acc[A_DISSIPATED] += friction_energy(kind, v[4], prm)
            v[4] = 0.0
        ic[I_REGIME] = regime_after_contact(bound_now)
    else:
        if v[4] != 0.0:
            acc[A_DISSIPATED] += friction_energy(kind, v[4], prm)
            v[4] = 0.0
        ic[I_REGIME] = FLIGHT


@njit
def _plan_times(kind, drv, prm, tm):
    """The cap of a step, the period of the jumps (0: none: they need a plate that repeats,
    the harmonic drive with the external input at rest, and a friction law without a state
    of its own: a held block's theta grows without bound), the plate's highest point
    (known then too; nan otherwise), when to move the clock, the first step."""
    omega = drv[D_OMEGA]
    cap = math.inf
    if omega > 0.0 and drv[D_AMP] != 0.0:
        cap = CYCLE_FRACTION * 2.0 * math.pi / omega
    repeats = cap < math.inf and drv[D_EXT_V] == 0.0 and drv[D_EXT_A] == 0.0
    tm[T_CAP] = cap
    jumps = repeats and prm[P_MAX_JUMP] >= STROBE_MIN and not friction_interface_slips(kind)
    tm[T_PERIOD] = 2.0 * math.pi / omega if jumps else 0.0
    tm[T_TOP] = abs(drv[D_AMP]) + drv[D_EXT_Z] if repeats else math.nan
    tm[T_REBASE_AFTER] = REBASE_CYCLES * 2.0 * math.pi / omega if cap < math.inf else math.inf
    tm[T_LAST_RESET] = -math.inf
    tm[T_H] = tm[T_H_WANT] = min(cap, 0.1 * prm[P_RTOL] ** 0.25)  # T_H_WANT: the error control's step, before the cap
    tm[T_STIFFEST] = stiffest_rate(prm)


@njit
def _start(run, y, cnt, n0, u_end, clk, ws):
    """The call's state (v), quadratures (acc), counters and controls (ic) and times (tm)
    at grid step n0; the first method: the explicit pair unless the first step already
    meets its stability bound."""
    kind, drv, prm, track_energy = run
    v = np.zeros(NV)
    v[0], v[1], v[2], v[3], v[4] = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    v[THETA] = friction_integrated(kind, y[Y_FRICTION_STATE])  # ln theta under rate-and-state
    acc = np.zeros(5)
    acc[A_PHI], acc[A_PHI_C] = y[Y_PHI], y[Y_PHI_C]
    acc[A_WORK], acc[A_DISSIPATED], acc[A_E_NORMAL] = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    ic = np.zeros(I_LAST + 1, dtype=np.int64)
    ic[I_SLIPS] = cnt[C_SLIPS]
    ic[I_STROBE_WAIT] = STROBE_WAIT
    tm = np.zeros(T_STIFFEST + 1)
    tm[T_BASE] = drv[D_T0] + n0 * drv[D_DT]  # the time at the clock's origin; local times u count from there
    tm[T_END] = u_end
    _initial_regime(run, v, acc, ic, tm[T_BASE], clk)
    _plan_times(kind, drv, prm, tm)
    linearise(_system(run, ic), clk, v, tm[T_BASE], 0.0, ws)
    ic[I_JACOBIANS] += 1
    explicit = tm[T_H] * max(jacobian_norm(ws[1]), tm[T_STIFFEST]) < EXPLICIT_CALM
    ic[I_EXPLICIT] = ic[I_NEXT_EXPLICIT] = explicit
    ic[I_FRESH] = not explicit  # the linearisation at (u, v, regime) is current (the explicit pair: F0 only)
    return v, acc, ic, tm


@njit(inline="always")
def _prepare(drv, ic, tm, clk):
    """The method for this step (chosen after the last one), and the clock's origin moved
    here once it is REBASE_CYCLES periods behind, so that the plate's phase omega u never
    carries the rounding of a long local time."""
    if ic[I_NEXT_EXPLICIT] != ic[I_EXPLICIT]:
        ic[I_EXPLICIT] = ic[I_NEXT_EXPLICIT]
        ic[I_FRESH] = 0
        ic[I_STAGNANT] = 0
    u = tm[T_U]
    if u >= tm[T_REBASE_AFTER]:
        advance_clock(drv, clk, u, False)
        _move_origin(tm, u)
        tm[T_STROBE_NEXT] -= u
        tm[T_U] = 0.0
        ic[I_FRESH] = 0  # the rate read on the moved clock, as after a try (whose bits it then matches)


@njit(inline="always")
def _jump_due(ic, tm):
    """A held block on a repeating plate, the next try's time reached, room in the call
    for a try to pay, and this call's refused tries within their share (``jumps``)."""
    period, u = tm[T_PERIOD], tm[T_U]
    return (period > 0.0 and ic[I_REGIME] == LOADED and u >= tm[T_STROBE_NEXT]
            and tm[T_END] - u >= STROBE_PAYBACK * period
            and STROBE_SHARE * (tm[T_DONE] + u) >= (ic[I_REFUSED] + STROBE_TRY) * period)


@njit
def _try_jump(run, v, acc, ic, tm, clk, ws):
    """A stroboscopic jump from here.  The try runs on a clock whose origin is here; the
    call's clock moves there only if a jump is taken (a refused try leaves the run as it
    was, bit for bit).  Returns OK or NON_FINITE."""
    drv = run[1]
    u = tm[T_U]
    owned = (np.empty(2), np.zeros(4, dtype=np.int64), np.zeros(4))
    try_clk, tally, dq = unowned_each(owned)
    try_clk[0], try_clk[1] = clk[0], clk[1]
    advance_clock(drv, try_clk, u, False)
    plan = (tm[T_PERIOD], tm[T_CAP], tm[T_H], ic[I_EXPLICIT] != 0)
    u_jumped = stroboscopic(_system(run, ic), v, tm[T_BASE] + u, try_clk, tm[T_END] - u, plan, dq, tally, ws)
    ic[I_ACCEPTED] += tally[0]
    ic[I_REJECTED] += tally[1]
    ic[I_JACOBIANS] += tally[2]
    ic[I_JUMPED] += tally[3]
    ic[I_FRESH] = 0  # the try's replays used the workspace
    if u_jumped > 0.0:
        # Whole periods: the plate's phase at the landing is the try's, exactly.
        advance_clock(drv, try_clk, u_jumped, True)
        clk[0], clk[1] = try_clk[0], try_clk[1]
        _move_origin(tm, u + u_jumped)
        tm[T_U] = 0.0
        acc[A_PHI], acc[A_PHI_C] = kahan_add(acc[A_PHI], acc[A_PHI_C], dq[0])
        acc[A_WORK] += dq[1]
        acc[A_DISSIPATED] += dq[2]
        acc[A_E_NORMAL] += dq[3]
        ic[I_STROBE_WAIT] = STROBE_WAIT
        status = OK if _finite(v) else NON_FINITE
    else:
        status = OK
        ic[I_STROBE_WAIT] = min(2 * ic[I_STROBE_WAIT], STROBE_WAIT_MAX)
        ic[I_REFUSED] += STROBE_TRY
    tm[T_STROBE_NEXT] = tm[T_U] + ic[I_STROBE_WAIT] * tm[T_PERIOD]
    keep_alive(owned)
    return status


@njit(inline="always")
def _attempt(run, v, ic, tm, clk, ws):
    """The step from (u, v): its rate (and Jacobian) where not current, its length (past
    the cap in a flight above the plate's reach; after a stagnant run of RODAS4 steps a
    leap LEAP times longer first; the call's end), the step itself into ws TRIAL.
    Returns its error."""
    kind, drv, prm, track_energy = run
    system = _system(run, ic)
    rows = ws[0]
    explicit = ic[I_EXPLICIT] != 0
    u, cap = tm[T_U], tm[T_CAP]
    t_abs = tm[T_BASE] + u
    if not ic[I_FRESH]:
        if explicit:
            rates(system, clk, v, t_abs, u, rows[F0])
        else:
            linearise(system, clk, v, t_abs, u, ws)
            ic[I_JACOBIANS] += 1
        ic[I_FRESH] = 1
    if ic[I_REGIME] == FLIGHT and tm[T_H_WANT] > cap and not ic[I_WITHIN_REACH] and tm[T_TOP] == tm[T_TOP]:
        reach = reach_time(kind, v, rows[F0], tm[T_TOP], cap, rows[PROBE], prm)
        tm[T_H] = min(tm[T_H_WANT], max(cap, REACH_SHARE * reach))
    remaining = tm[T_END] - u
    err = math.inf
    if not explicit and ic[I_STAGNANT] >= LEAP_AFTER and LEAP * tm[T_H] < cap:
        ic[I_STAGNANT] = 0
        h_leap = min(LEAP * tm[T_H], remaining)
        err = rosenbrock(system, clk, v, t_abs, u, h_leap, ws, rows[TRIAL])
        if err <= 1.0:
            tm[T_H] = h_leap
        else:
            ic[I_REJECTED] += 1
    ic[I_LAST] = tm[T_H] >= remaining
    if ic[I_LAST]:
        tm[T_H] = remaining
    if not err <= 1.0:
        err = step(explicit, system, clk, v, t_abs, u, tm[T_H], ws, rows[TRIAL])
    return err


@njit(inline="always")
def _reject(ic, tm, err):
    """A step that failed its error test: retaken shorter.  OK or STEP_TOO_SMALL."""
    ic[I_REJECTED] += 1
    ic[I_STAGNANT] = 0
    tm[T_H] *= shrink(err, ic[I_EXPLICIT] != 0)
    tm[T_H_WANT] = tm[T_H]
    if tm[T_H] <= 16.0 * EPS * max(1.0, abs(tm[T_BASE] + tm[T_U])):
        return STEP_TOO_SMALL
    return OK


@njit(inline="always")
def _met_reach(run, v, ic, tm, ws):
    """A step past the cap (only in a flight above the plate's reach) must stay there at its
    samples and its end, else it is retaken at the cap (and the flight keeps the cap until
    its landing).  True if it is to be retaken."""
    h, cap = tm[T_H], tm[T_CAP]
    if not h > cap:
        return False
    kind, drv, prm, track_energy = run
    explicit = ic[I_EXPLICIT] != 0
    probe, trial = ws[0][PROBE], ws[0][TRIAL]
    for sample in range(1, EVENT_SAMPLES + 1):
        if sample == EVENT_SAMPLES:
            for i in range(NS):
                probe[i] = trial[i]
        else:
            interpolate(explicit, v, trial, ws, h, sample / EVENT_SAMPLES, probe)
        if not clearance(kind, probe, tm[T_TOP], prm) > 0.0:
            ic[I_WITHIN_REACH] = 1
    if ic[I_WITHIN_REACH]:
        ic[I_REJECTED] += 1
        tm[T_H] = cap
        return True
    return False


@njit(inline="always")
def _accept(ic, tm, err, ws):
    """Count the accepted step, take the next step's length, and choose the method for the
    next step (taken there, so that this step's events are refined with the method that
    took it): DOP853's stiffness test, or RODAS4's step back inside the explicit bound."""
    ic[I_ACCEPTED] += 1
    explicit = ic[I_EXPLICIT] != 0
    grow = growth(err, explicit)
    ic[I_STAGNANT] = ic[I_STAGNANT] + 1 if grow < 2.0 else 0
    tm[T_H_NEXT] = tm[T_H] * grow
    if explicit:
        if stiffness(tm[T_H], ws, ws[0][TRIAL]) > EXPLICIT_STIFF:
            ic[I_STIFF] += 1
            ic[I_CALM] = 0
            if ic[I_STIFF] >= STIFF_AFTER:
                ic[I_NEXT_EXPLICIT], ic[I_STIFF], ic[I_HOLD] = 0, 0, STIFF_HOLD
        else:
            ic[I_CALM] += 1
            if ic[I_CALM] >= STIFF_FORGET:
                ic[I_STIFF] = 0
    else:
        ic[I_HOLD] = max(ic[I_HOLD] - 1, 0)
        if ic[I_HOLD] == 0 and min(tm[T_H_NEXT], tm[T_CAP]) * max(jacobian_norm(ws[1]), tm[T_STIFFEST]) < EXPLICIT_CALM:
            ic[I_NEXT_EXPLICIT], ic[I_STIFF], ic[I_CALM] = 1, 0, 0


@njit
def _switch(run, v, acc, ic, tm, clk, event):
    """The regime after the located event, with the friction rule at the switch."""
    kind, drv, prm, track_energy = run
    u = tm[T_U]
    pz, pv = plate(drv, clk, u)
    pen, bound_now = bound(kind, v, tm[T_BASE] + u, pz, pv, prm)
    if event == EV_CONTACT:
        v[4] = 0.0
        ic[I_REGIME] = regime_after_contact(bound_now)
    elif event == EV_DETACH:
        acc[A_DISSIPATED] += friction_energy(kind, v[4], prm)
        v[4] = 0.0
        ic[I_REGIME] = FLIGHT
    elif event == EV_RESET_PLUS or event == EV_RESET_MINUS:
        if v[4] != 0.0:
            ic[I_SLIPS] += 1
            acc[A_DISSIPATED] += friction_energy(kind, v[4], prm)
        v[4] = 0.0
        if bound_now > 0.0:
            ic[I_REGIME] = CASCADE if u - tm[T_LAST_RESET] < CASCADE_GAP else LOADED
        else:
            ic[I_REGIME] = HELD
        tm[T_LAST_RESET] = u
    elif event == EV_REARM:
        v[4] = 0.0
        ic[I_REGIME] = LOADED
    else:  # EV_HOLD: N reached zero (the cascade's limit; a slipping interface's spring released)
        if v[4] != 0.0:
            acc[A_DISSIPATED] += friction_energy(kind, v[4], prm)
            v[4] = 0.0
        ic[I_REGIME] = HELD


@njit(inline="always")
def _step_on(ic, tm, trial, v, acc):
    """Commit the step's end and move on by its length (to the call's end on its last step)."""
    _commit(v, acc, trial)
    tm[T_U] = tm[T_END] if ic[I_LAST] else tm[T_U] + tm[T_H]
    tm[T_H_WANT] = tm[T_H_NEXT]
    tm[T_H] = min(tm[T_H_WANT], tm[T_CAP])


@njit(inline="always")
def _events(run, v, acc, ic, tm, clk, ws):
    """The accepted step's events: none (commit it), a graze seen on the interpolant only
    (commit it), or a switch located on full steps (restart there, in the regime after it).
    Returns OK, TOO_MANY_EVENTS or NON_FINITE."""
    rows = ws[0]
    explicit = ic[I_EXPLICIT] != 0
    trial = rows[TRIAL]
    taken = (explicit, _system(run, ic), clk, v, trial, tm[T_H], tm[T_U], tm[T_BASE], ws)
    event, s_hi, s_sample = first_event(taken)
    if event == EV_NONE:
        _step_on(ic, tm, trial, v, acc)
        ic[I_FRESH] = explicit  # the explicit pair's last rate is the next step's first
        if explicit:
            for i in range(NV):
                rows[F0, i] = rows[KX + EXPLICIT_STAGES, i]
        ic[I_IMMEDIATE] = 0
        return OK
    hi = locate_switch(taken, event, s_hi, s_sample)
    if hi < 0.0:
        _step_on(ic, tm, trial, v, acc)
        ic[I_FRESH] = 0
        return OK
    _commit(v, acc, rows[BEST])
    tm[T_U] = tm[T_END] if hi >= tm[T_END] - tm[T_U] else tm[T_U] + hi
    ic[I_EVENTS] += 1
    if hi <= EVENT_TOL:
        ic[I_IMMEDIATE] += 1
        if ic[I_IMMEDIATE] > MAX_IMMEDIATE:
            return TOO_MANY_EVENTS
    else:
        ic[I_IMMEDIATE] = 0
    _switch(run, v, acc, ic, tm, clk, event)
    ic[I_FRESH] = 0
    ic[I_WITHIN_REACH] = 0
    tm[T_H_WANT] = max(tm[T_H_NEXT], tm[T_H])
    tm[T_H] = min(tm[T_H_WANT], tm[T_CAP])
    return OK if _finite(v) else NON_FINITE


@njit(cache=True)
def evolve(kind, y, cnt, drv, prm, n0, u_end, track_energy, out, costs):
    """Integrate from grid step n0 (state y) over local time u_end.  Writes the final state
    to ``out`` (layout of y), the slip count to costs[0] and the cost counters (accepted,
    rejected, events, Jacobians, periods jumped) to costs[1:6].  Returns OK or a negative status."""
    drv, prm = data_pointer(drv), data_pointer(prm)
    run = (kind, drv, prm, track_energy)
    owned_clock = clock(drv, cnt, n0)
    clk = unowned(owned_clock)
    # The loop reads its scratch and state through unowned views: every view taken of a
    # counted array costs two atomic operations, a quarter of a step's time.
    owned = workspace()
    ws = unowned_each(owned)
    state = _start(run, y, cnt, n0, u_end, clk, ws)
    v, acc, ic, tm = unowned_each(state)
    status = OK
    while tm[T_U] < tm[T_END]:
        if ic[I_ACCEPTED] + ic[I_REJECTED] >= MAX_STEPS:
            status = TOO_MANY_STEPS
            break
        _prepare(drv, ic, tm, clk)
        if _jump_due(ic, tm):
            status = _try_jump(run, v, acc, ic, tm, clk, ws)
        else:
            err = _attempt(run, v, ic, tm, clk, ws)
            if not err <= 1.0:
                status = _reject(ic, tm, err)
            elif not _met_reach(run, v, ic, tm, ws):
                _accept(ic, tm, err, ws)
                status = _events(run, v, acc, ic, tm, clk, ws)
        if status != OK:
            break
    if status == OK and not math.isfinite(v[0] + v[1] + v[2] + v[3] + v[4] + v[THETA] + acc[A_PHI]
                                          + acc[A_WORK] + acc[A_DISSIPATED]):
        status = NON_FINITE
    out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F] = v[0], v[1], v[2], v[3], v[4]
    out[Y_FRICTION_STATE] = friction_stored(kind, v[THETA])
    out[Y_PHI], out[Y_PHI_C] = acc[A_PHI], acc[A_PHI_C]
    out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL] = acc[A_WORK], acc[A_DISSIPATED], acc[A_E_NORMAL]
    for i in range(N_COSTS):
        costs[i] = ic[i]
    keep_alive((owned, state, owned_clock))
    return status


@njit(cache=True)
def advance(kind, method, flags, y, cnt, drv, prm, n_steps, track_energy):
    """Advance by n_steps grid steps (the package's doc): the end time t0 + (n + n_steps) dt
    is reached by error-controlled steps whatever n_steps is.  Returns 0, or a negative
    status with the arrays untouched."""
    out = y.copy()
    costs = np.zeros(N_COSTS, dtype=np.int64)
    n = cnt[C_STEP]
    status = evolve(kind, y, cnt, drv, prm, n, n_steps * drv[D_DT], track_energy, out, costs)
    if status < 0:
        return status
    y[:] = out
    cnt[C_STEP] = n + n_steps
    cnt[C_SLIPS] = costs[0]
    cnt[C_ACCEPTED] += costs[1]
    cnt[C_REJECTED] += costs[2]
    cnt[C_EVENTS] += costs[3]
    cnt[C_JACOBIANS] += costs[4]
    cnt[C_JUMPED] += costs[5]
    return status


@njit(cache=True)
def observe(kind, method, flags, y, cnt, drv, prm, h, track_energy, obs):
    """Fill ``obs`` with the state at t_n + h (0 <= h < dt) by a short integration from
    the grid state, without touching the stored state (layout of ``fixed_step.observe``)."""
    n = cnt[C_STEP]
    out = y.copy()
    costs = np.zeros(N_COSTS, dtype=np.int64)
    slips = cnt[C_SLIPS]
    if h > 0.0:
        status = evolve(kind, y, cnt, drv, prm, n, h, track_energy, out, costs)
        if status < 0:
            out[:] = math.nan
        else:
            slips = costs[0]
    t = drv[D_T0] + n * drv[D_DT] + h
    pz, pv = plate(drv, clock(drv, cnt, n), h)
    pen, u_n, u_t, cos_a, sin_a, normal = contact(kind, out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], pz, pv, prm)
    friction = -friction_spring_force(kind, out[Y_F], prm) if pen > 0.0 else 0.0
    record_observation(obs, (out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F]), (pen, normal, cos_a, pen > 0.0),
                       (out[Y_PHI], slips, out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL]), t, friction)
    return N_OBS
