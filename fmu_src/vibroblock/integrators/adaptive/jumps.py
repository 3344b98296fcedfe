"""Stroboscopic jumps: whole plate periods taken many at a time while the block is held.

A block held by friction on a harmonically vibrating plate settles on an orbit that
repeats every plate period while the slow variables (the spring's stretch, the
tangential spring, the position along the corrugation) creep: at the paper's parameters
a stick lasts 1e7-1e9 periods, and resolving each costs ~16-30 steps.  The map over one
period, P(y, D) (D the drive's far end, V_d t), is then nearly affine: the contact and
spring forces are linear in the state, only the surface's slope moves with x, and that by
little per period.  So from y_0 the periods are taken K at a time:
  delta_{n+1} = M delta_n + r + n q,   delta_n = y_n - y_0,
with r = P(y_0, D_0) - y_0 from one resolved period (whose step sequence is recorded),
M = dP/dy and q = V_d T dP/dD from replays of that sequence on perturbed starts (finite
differences that share every step, so they carry no step-selection noise).  Ringing
modes that have not died are carried exactly by M^n (they are linear); K periods cost
log2(K) products of 11 x 11 matrices.  The quadratures (phi, energies) are quadratic in
the velocities: the linear model sums their per-period increments to first order in
delta, and as the state drifts (delta_n ~ n d) the true increment leaves it by
rho(n) ~ c n^2.  That second-order term is measured, not neglected: c from the period the
jump lands on, the sum corrected by c (K-1) K (2K-1) / 6.

Error control.  The state a jump lands on is checked by replaying the same step sequence
from it: the increment of that period against the linear model's prediction must stay
within rtol/atol (error per period crossed), else the jump is retaken shorter.  phi is
checked halfway: the period there is replayed too, and its residual must be the
c (K/2)^2 of the quadratic law within rtol of a period's increment -- a ringing that the
jump carries linearly breaks that law first.  The landing's replay is the next jump's
resolved period, and a model that passed is kept for the next jump (its error, should the
state have drifted too far for it, is the next check's).  Events: each event value's
minimum over the resolved periods (its margin) is watched; a jump may use up at most
STROBE_MARGIN of any margin at the rate the last jump showed, and a period whose replay
(halfway or at the landing) meets an event, or a jump allowed fewer than STROBE_MIN
periods, hands back to resolved stepping, which locates the switch on its own step.
(Envelope following, as for circuits driven by a fast periodic source.)  Every period is
replayed on the clock's phase (the jumps span whole periods), so the plate it sees is the
recorded one to the bit.
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...layout import P_ATOL, P_KD, P_MAX_JUMP, P_RTOL, P_VD
from ...unowned import keep_alive, unowned_each
from .methods import EVENT_SAMPLES, growth, sample_state, shrink, step
from .regimes import NS, NS_MOTION, NV, THETA, event_at, event_value, events_of, plate, rates, switch_values
from .rodas4 import EPS, linearise
from .workspace import F0, PROBE, SCRATCH, TRIAL

STROBE_MIN = 4          # fewest periods a jump spans
STROBE_FIRST = 8        # the first jump of a session, before a margin's rate is known
STROBE_GROW = 8.0       # largest growth of the jump from one jump to the next
STROBE_MARGIN = 0.5     # largest fraction of an event's margin one jump may use up
STROBE_STEPS = 2048     # steps the recorded period may hold
STROBE_KEEP = 1.0       # a model whose jump passed within this fraction of the tolerance is kept
STROBE_WAIT = 2         # periods of resolved stepping before the next try, doubled after each failed try
STROBE_WAIT_MAX = 1024
# What a try costs and when it may pay.  A try replays ~STROBE_TRY periods (the recorded
# one, two per state column and for the pull, the landing and the halfway check) for a
# first jump of STROBE_FIRST, so it pays only where the longer jumps that reuse its model
# have room: a call tries only while STROBE_PAYBACK periods remain, and only while its
# refused tries, this one counted, stay within STROBE_SHARE of the periods it has advanced
# (the first try after 32 periods).  So a run whose tries are all refused (a ringing
# spring) pays at most that share, and a short call is resolved as with jumps off.
STROBE_TRY = 16
STROBE_PAYBACK = 32
STROBE_SHARE = 0.5
STROBE_EPS = 1e-6       # relative perturbation of the state's finite differences
STROBE_PULL = 1e-4      # change of the drive's pull (k_d times its far end's shift) of the drive's difference
NA = NV + 2             # affine model on (delta, quadratures, 1, n)

# Rows (of NA) of a try's work array: the model's origin y0 and its resolved period's end
# (BASE), the landed state and its replay (MOVED, CHECK), the same halfway, the model's
# vectors, the event margins (of the base, the landing, before the last jump, halfway),
# the orbit's scale, the quadratures' curvature, and the model's columns dP/dy, dP/dD.
(Y0, BASE, MOVED, CHECK, MOVED_MID, CHECK_MID, VEC, TMP, VEC_MID, MARGINS, MARGINS_MOVED, MARGINS_BEFORE,
 MARGINS_MID, SCALE, SCALE_MOVED, SCALE_MID, CURVATURE, COLS) = range(18)
STROBE_ROWS = COLS + NS + 1
# The one-period map, its powers, a product's scratch.
G, POWERS, SQUARE = range(3)


@njit(inline="always")
def _sample_margins(system, clk, explicit, start, end, ws, h, local, t_now, margins):
    """Each event value's minimum, kept in ``margins``, over the step's samples; False if
    one is not positive."""
    kind, regime, drv, prm, track_energy = system
    row = ws[0][SCRATCH]
    for sample in range(1, EVENT_SAMPLES + 1):
        s = sample / EVENT_SAMPLES
        sample_state(explicit, start, end, ws, h, sample, row)
        pz, pv = plate(drv, clk, local + s * h)
        pen, bound_now, spring = switch_values(kind, row, t_now + s * h, pz, pv, prm)
        for e in range(events_of(kind, regime)[1]):
            g = event_value(event_at(kind, regime, e), pen, bound_now, spring)
            if g <= 0.0:
                return False
            margins[e] = min(margins[e], g)
    return True


@njit(cache=True)
def period_map(system, v0, t_abs, shift, clk, plan, hs, n_hs, res, ws, tally):
    """One plate period from v0 at the clock's origin (quadratures of v0 are 0): with
    n_hs = 0 by error-controlled steps whose lengths are recorded in hs, else by replaying
    hs[:n_hs].  ``shift`` moves the drive's far end (the time the forces see, not the
    plate's); ``plan`` is (period, cap, first step, explicit).  ``res`` = (out, margins,
    scale) gets the end state and the period's quadrature increments, each event value's
    minimum over the step ends and interpolant samples, and each state component's largest
    magnitude at the step ends (the orbit's size, for the error weights).  tally counts
    (accepted, rejected, Jacobians).  Returns the number of steps, or -1 if an event value
    went negative or a step failed."""
    kind, regime, drv, prm, track_energy = system
    period, cap, h_first, explicit = plan
    out, margins, scale = res
    probe, trial = ws[0][PROBE], ws[0][TRIAL]
    for i in range(NV):
        out[i] = 0.0
        probe[i] = v0[i]
    pz, pv = plate(drv, clk, 0.0)
    pen, bound_now, spring = switch_values(kind, v0, t_abs + shift, pz, pv, prm)
    for e in range(events_of(kind, regime)[1]):
        margins[e] = event_value(event_at(kind, regime, e), pen, bound_now, spring)
        if margins[e] <= 0.0:
            return -1
    for i in range(NS):
        scale[i] = abs(v0[i])
    record = n_hs == 0
    local = 0.0
    h = min(h_first, cap, period)
    steps = 0
    while True:
        if record:
            if local >= period:
                break
            if steps >= STROBE_STEPS:
                return -1
            h = min(h, period - local)
        else:
            if steps >= n_hs:
                break
            h = hs[steps]
        t_now = t_abs + shift + local
        if explicit:
            rates(system, clk, probe, t_now, local, ws[0][F0])
        else:
            linearise(system, clk, probe, t_now, local, ws)
            tally[2] += 1
        err = step(explicit, system, clk, probe, t_now, local, h, ws, trial)
        if record and not err <= 1.0:
            tally[1] += 1
            h *= shrink(err, explicit)
            if h <= 16.0 * EPS * max(1.0, abs(t_abs + local)):
                return -1
            continue
        if not math.isfinite(err):
            return -1
        tally[0] += 1
        if not _sample_margins(system, clk, explicit, probe, trial, ws, h, local, t_now, margins):
            return -1
        for i in range(NS):
            probe[i] = trial[i]
            scale[i] = max(scale[i], abs(trial[i]))
        for i in range(NS, NV):
            out[i] += trial[i]
        local += h
        if record:
            hs[steps] = h
            h = min(h * growth(err, explicit), cap)
        steps += 1
    for i in range(NS):
        out[i] = probe[i]
    return steps


@njit(cache=True)
def _affine_power(g, power, vec, sq, tmp):
    """vec <- g^power vec (binary powering; g is overwritten by its squares)."""
    while power > 0:
        if power & 1:
            for i in range(NA):
                acc = 0.0
                for j in range(NA):
                    acc += g[i, j] * vec[j]
                tmp[i] = acc
            for i in range(NA):
                vec[i] = tmp[i]
        power >>= 1
        if power == 0:
            break
        for i in range(NA):
            for j in range(NA):
                acc = 0.0
                for l in range(NA):
                    acc += g[i, l] * g[l, j]
                sq[i, j] = acc
        for i in range(NA):
            for j in range(NA):
                g[i, j] = sq[i, j]


@njit(inline="always")
def _apply_periods(sw, mats, periods, vec, moved):
    """The model's K periods from y0: vec <- g^K (0, 0, 1, 0) (state change, quadratures'
    sums, 1, K) and moved <- the state there (quadratures 0)."""
    g, work, y0 = mats[G], mats[POWERS], sw[Y0]
    for i in range(NA):
        vec[i] = 0.0
        for j in range(NA):
            work[i, j] = g[i, j]
    vec[NV] = 1.0
    _affine_power(work, periods, vec, mats[SQUARE], sw[TMP])
    for i in range(NS):
        moved[i] = y0[i] + vec[i]
    for i in range(NS, NV):
        moved[i] = 0.0


@njit(inline="always")
def _period_matrix(sw, g):
    """g: the one-period map of (delta, quadratures, 1, n):
    delta' = M delta + r + n q; quadratures' = quadratures + (their rows of M) delta + r + n q."""
    cols, base, y0 = sw[COLS:COLS + NS + 1], sw[BASE], sw[Y0]
    for i in range(NA):
        for j in range(NA):
            g[i, j] = 0.0
    for i in range(NV):
        for j in range(NS):
            g[i, j] = cols[j, i]
        if i >= NS:
            g[i, i] = 1.0
        g[i, NV] = base[i] - y0[i] if i < NS else base[i]
        g[i, NV + 1] = cols[NS, i]
    g[NV, NV] = 1.0
    g[NV + 1, NV] = 1.0
    g[NV + 1, NV + 1] = 1.0


@njit
def _model_columns(job, t_abs, at):
    """The linear model at y0: columns of dP/dy and dP/dD by replays of the recorded
    period, central differences (the slope's dependence on x makes one-sided ones biased).
    False if a replay met an event."""
    system, plan, hs, n_hs, sw, mats, ws, tally = job
    prm, period = system[3], plan[0]
    y0, moved, check, cols = sw[Y0], sw[MOVED], sw[CHECK], sw[COLS:COLS + NS + 1]
    res = (check, sw[MARGINS_MOVED], sw[SCALE_MOVED])
    for j in range(NS):
        for i in range(NV):
            cols[j, i] = 0.0
        if j == THETA:  # a law with a state never jumps (driver): theta stays as it is
            cols[j, j] = 1.0
            continue
        step_j = STROBE_EPS * max(1.0, abs(y0[j]))
        for side in range(2):
            for i in range(NV):
                moved[i] = y0[i]
            moved[j] = y0[j] + step_j if side == 0 else y0[j] - step_j
            if period_map(system, moved, t_abs, 0.0, at, plan, hs, n_hs, res, ws, tally) < 0:
                return False
            for i in range(NV):
                if side == 0:
                    cols[j, i] = check[i]
                else:
                    cols[j, i] = (cols[j, i] - check[i]) / (2.0 * step_j)
    for i in range(NV):
        cols[NS, i] = 0.0
    vd = prm[P_VD]
    if vd != 0.0 and prm[P_KD] > 0.0:
        # The pull is linear in the far end's position: a shift the finite difference
        # resolves far above the rounding of the positions (k_d is ~1e-6 at the paper's),
        # taken both ways so that the quadratures (quadratic in the velocities) lose
        # their second-order term.
        shift = STROBE_PULL / (prm[P_KD] * abs(vd))
        for side in range(2):
            sign = 1.0 if side == 0 else -1.0
            if period_map(system, y0, t_abs, sign * shift, at, plan, hs, n_hs, res, ws, tally) < 0:
                return False
            for i in range(NV):
                cols[NS, i] += sign * check[i] * period / (2.0 * shift)  # per period of drive travel
    return True


@njit(inline="always")
def _allowed_periods(jump, room, prm, last_jump, n_events, sw):
    """The jump's length: the call's end, and each margin at the rate the last jump used it up."""
    margins, margins_before = sw[MARGINS], sw[MARGINS_BEFORE]
    allowed = min(jump, room, math.floor(prm[P_MAX_JUMP]))
    if last_jump > 0.0:
        for e in range(n_events):
            rate_e = (margins_before[e] - margins[e]) / last_jump
            if rate_e > 0.0:
                allowed = min(allowed, math.floor(STROBE_MARGIN * margins[e] / rate_e))
    return allowed


@njit(inline="always")
def _landing_error(sw, count, mid, prm, period):
    """The landed period's increment against the model's, r + (M - I) delta_K + K q, within
    the tolerances (error per period crossed, as a resolved period's steps are held to
    theirs; the rounding of the plate's phase and of the positions sets a floor of ~1e-12
    per period that no jump length can get under); then the quadratures' second order: c
    from the landed period (into sw CURVATURE), and phi's residual halfway against
    c (K/2)^2, to rtol of a period's increment."""
    rtol, atol, vd = prm[P_RTOL], prm[P_ATOL], prm[P_VD]
    y0, base, moved, check, vec, scale = sw[Y0], sw[BASE], sw[MOVED], sw[CHECK], sw[VEC], sw[SCALE]
    cols, curvature = sw[COLS:COLS + NS + 1], sw[CURVATURE]
    err = 0.0
    for i in range(NS):
        predicted = base[i] - y0[i] + cols[NS, i] * count
        for j in range(NS):
            predicted += (cols[j, i] - (1.0 if i == j else 0.0)) * vec[j]
        weight = atol + rtol * max(abs(y0[i]), abs(moved[i]), scale[i])
        e = (check[i] - moved[i] - predicted) / weight
        err += e * e
    for i in range(NS, NV):
        at_end = base[i] + cols[NS, i] * count
        for j in range(NS):
            at_end += cols[j, i] * vec[j]
        curvature[i - NS] = (check[i] - at_end) / (float(count) * count)
    vec_mid = sw[VEC_MID]
    at_mid = base[NS] + cols[NS, NS] * mid
    for j in range(NS):
        at_mid += cols[j, NS] * vec_mid[j]
    e = ((sw[CHECK_MID][NS] - at_mid) - curvature[0] * float(mid) * mid) / (
        rtol * (abs(base[NS]) + vd * vd * period) + 1e-300)
    err += e * e
    return math.sqrt(err / (NS_MOTION + 1))  # theta's rows are 0 here: jumps run the sticking laws only


@njit
def _try_periods(job, count, t_abs, at, clk_u):
    """A jump of ``count`` periods from y0 by the model: its landing replayed (sw MOVED,
    CHECK), the period halfway replayed (sw MOVED_MID, CHECK_MID); the landing's error
    (inf where a replay met an event or the model is not finite).  clk_u is the clock's
    external-input time at y0."""
    system, plan, hs, n_hs, sw, mats, ws, tally = job
    period = plan[0]
    _period_matrix(sw, mats[G])
    vec, moved = sw[VEC], sw[MOVED]
    _apply_periods(sw, mats, count, vec, moved)
    if not math.isfinite(vec[0] + vec[1] + vec[2] + vec[3] + vec[4] + vec[NS]):
        return math.inf
    at[1] = clk_u + count * period
    res = (sw[CHECK], sw[MARGINS_MOVED], sw[SCALE_MOVED])
    if period_map(system, moved, t_abs + count * period, 0.0, at, plan, hs, n_hs, res, ws, tally) <= 0:
        return math.inf
    mid = count // 2
    _apply_periods(sw, mats, mid, sw[VEC_MID], sw[MOVED_MID])
    at[1] = clk_u + mid * period
    res = (sw[CHECK_MID], sw[MARGINS_MID], sw[SCALE_MID])
    if period_map(system, sw[MOVED_MID], t_abs + mid * period, 0.0, at, plan, hs, n_hs, res, ws, tally) <= 0:
        return math.inf
    return _landing_error(sw, count, mid, system[3], period)


@njit(inline="always")
def _land(sw, v, dq, count, n_events):
    """Accept a jump of ``count`` periods: the landed state is the new y0 (and v), its
    replayed period the next model's base; dq sums the quadratures with their second order."""
    y0, moved, check, base, vec, curvature = sw[Y0], sw[MOVED], sw[CHECK], sw[BASE], sw[VEC], sw[CURVATURE]
    for i in range(NS):
        y0[i] = moved[i]
        v[i] = moved[i]
    kk = float(count)
    for i in range(4):
        dq[i] += vec[NS + i] + curvature[i] * (kk - 1.0) * kk * (2.0 * kk - 1.0) / 6.0
    for i in range(NV):
        base[i] = check[i]
    for e in range(n_events):
        sw[MARGINS_BEFORE][e] = sw[MARGINS][e]
        sw[MARGINS][e] = sw[MARGINS_MOVED][e]
    for i in range(NS):
        sw[SCALE][i] = sw[SCALE_MOVED][i]


@njit(cache=True)
def stroboscopic(system, v, t_base, clk, u_end, plan, dq, tally, ws):
    """``jump_periods`` with its scratch allocated here and read through unowned views
    (a counted view costs two atomic operations, and the jumps take many)."""
    owned = (np.empty(STROBE_STEPS), np.zeros((STROBE_ROWS, NA)), np.zeros((3, NA, NA)), np.empty(2))
    scratch = unowned_each(owned)
    jumped = jump_periods(system, v, t_base, clk, u_end, plan, (dq, tally, ws), scratch)
    keep_alive(owned)
    return jumped


@njit
def jump_periods(system, v, t_base, clk, u_end, plan, shared, scratch):
    """Take the plate periods from the clock's origin (time t_base) K at a time while the
    block stays in its regime (LOADED) without a switch (the module's doc), up to local
    time u_end; ``plan`` is (period, cap, first step, explicit).  Moves v (state slots) and
    returns the time jumped (0 if no jump was taken); dq gets the quadratures' increments,
    tally (accepted, rejected, Jacobians, periods jumped) the costs."""
    prm, period = system[3], plan[0]
    n_events = events_of(system[0], system[1])[1]
    dq, tally, ws = shared
    hs, sw, mats, at = scratch  # at: the clock of a replayed period's start
    for i in range(4):
        dq[i] = 0.0
    for i in range(NS):
        sw[Y0][i] = v[i]
    n_hs = period_map(system, sw[Y0], t_base, 0.0, clk, plan, hs, 0, (sw[BASE], sw[MARGINS], sw[SCALE]), ws, tally)
    if n_hs <= 0:
        return 0.0
    job = (system, plan, hs, n_hs, sw, mats, ws, tally)
    u = 0.0
    jump = float(STROBE_FIRST)
    last_jump = 0.0
    model_current = False  # cols hold dP/dy, dP/dD taken at this or an earlier y0
    while True:
        t_abs = t_base + u
        at[0], at[1] = clk[0], clk[1] + u
        # A model that predicted the last landing well is kept (it changes slowly along a
        # stick; only r = P(y0) - y0 is new, from the landing's replay).
        model_fresh = not model_current  # ... taken at this y0
        model_current = True
        if model_fresh and not _model_columns(job, t_abs, at):
            return u
        while True:
            allowed = _allowed_periods(jump, math.floor((u_end - u) / period) - 1.0, prm, last_jump, n_events, sw)
            if allowed < STROBE_MIN:
                return u
            count = int(allowed)
            err = _try_periods(job, count, t_abs, at, clk[1] + u)
            if err <= 1.0 or not model_fresh:
                break
            # Retake it shorter (the model at y0 stands); an event met right after the
            # jump may have happened within it.
            jump = count * (0.25 if not math.isfinite(err) else max(0.1, min(0.5, 0.8 * err ** -0.5)))
        if not err <= 1.0:
            model_current = False  # a kept model failed: take it afresh at y0 and try again
            continue
        u += count * period
        tally[3] += count
        _land(sw, v, dq, count, n_events)
        last_jump = float(count)
        jump = count * min(STROBE_GROW, max(1.0, 0.8 * max(err, 1e-12) ** -0.5))
        model_current = err <= STROBE_KEEP
