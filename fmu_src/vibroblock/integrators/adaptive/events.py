"""Event location: the first switch within an accepted step, to EVENT_TOL after the true one.

After an accepted step the event values are checked on its interpolant at EVENT_SAMPLES
points; in the first sub-interval where one changes sign, the earliest root of the
interpolant is the first guess (``first_event``), and the switch is then refined on full
steps of the method in use from the step's start (``locate_switch``), until the bracket is
shorter than EVENT_TOL.  The state is restarted from the far end of that bracket -- the
full-order step to within EVENT_TOL after the true zero, on the far side -- and the reset
rule is applied there, not at a step's end.

Both searches are one root finder (``regula_falsi``) on one value function
(``_value_along``), which evaluates an event value either on the step's interpolant at a
fraction of the step or at the end of a full step of a given length.
"""
import math

from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from .methods import EVENT_SAMPLES, interpolate, sample_state, step
from .regimes import EV_NONE, NV, event_at, event_value, events_of, plate, switch_values, value_at
from .rodas4 import EPS
from .workspace import BEST, PROBE

# Switch times are located to this (tau_0) after the true zero.
EVENT_TOL = 1e-12
# Iterations of the search on the interpolant (cheap, a first guess) and on full steps.
INTERPOLANT_ROUNDS = 40
FULL_STEP_ROUNDS = 100


@njit(inline="always")
def _value_along(search, x, out):
    """The searched event value at x: with ``full_steps`` at the end of a full step of
    length x from the step's start, else on the step's interpolant at fraction x.  The
    state there is left in ``out``.  ``search`` is (full_steps, event index, the step:
    (explicit, system, clock, start state, end state, length, local start, clock's origin
    time, workspace))."""
    full_steps, event_index, taken = search
    explicit, system, clk, v, trial, h, u, t_base, ws = taken
    if full_steps:
        step(explicit, system, clk, v, t_base + u, u, x, ws, out)
        time = u + x
    else:
        interpolate(explicit, v, trial, ws, h, x, out)
        time = u + x * h
    return value_at(system, clk, event_index, out, t_base + time, time)


@njit
def regula_falsi(search, lo, g_lo, hi, g_hi, scale, tolerance, out, keep):
    """The zero of the searched value in (lo, hi), g_lo >= 0 > g_hi: regula falsi with the
    end that stays halved in value (Illinois), until (hi - lo) scale <= tolerance.  Returns
    hi, the first point past the zero; ``keep`` gets the state there (``out`` is scratch).
    On the interpolant, whose values are cheap and only a first guess, the end that stays
    is halved at every iteration; on full steps at the second in a row from one side."""
    full_steps = search[0]
    rounds = FULL_STEP_ROUNDS if full_steps else INTERPOLANT_ROUNDS
    patience = 2 if full_steps else 1
    kept_lo = kept_hi = 0  # iterations in a row that kept that end
    for _ in range(rounds):
        guess = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_lo > g_hi else 0.5 * (lo + hi)
        if not (lo < guess < hi):
            guess = 0.5 * (lo + hi)
            if not (lo < guess < hi):
                break
        g = _value_along(search, guess, out)
        if g < 0.0:
            hi, g_hi = guess, g
            for i in range(NV):
                keep[i] = out[i]
            kept_lo, kept_hi = kept_lo + 1, 0
            if kept_lo >= patience:
                g_lo *= 0.5
        else:
            lo, g_lo = guess, g
            kept_hi, kept_lo = kept_hi + 1, 0
            if kept_hi >= patience:
                g_hi *= 0.5
        if (hi - lo) * scale <= tolerance:
            break
    return hi


@njit(inline="always")
def _interpolant_root(taken, e, previous, s, g_s):
    """The interpolant's root of event value e in (previous, s), where it is g_s < 0."""
    ws = taken[8]
    best = ws[0][BEST]
    search = (False, e, taken)
    g_a = _value_along(search, previous, best)
    if previous == 0.0:
        g_a = max(g_a, 0.0)
    if not g_a > 0.0:
        return previous
    return regula_falsi(search, previous, g_a, s, g_s, taken[5], EVENT_TOL, best, best)


@njit(inline="always")
def first_event(taken):
    """The first sub-interval of the step's interpolant in which an event value changes
    sign: (the event, its root on the interpolant, the sample that showed it), or EV_NONE."""
    explicit, system, clk, v, trial, h, u, t_base, ws = taken
    kind, regime, drv, prm, track_energy = system
    probe = ws[0][PROBE]
    n_events = events_of(kind, regime)[1]
    previous = 0.0
    for sample in range(1, EVENT_SAMPLES + 1):
        s = sample / EVENT_SAMPLES
        sample_state(explicit, v, trial, ws, h, sample, probe)
        pz, pv = plate(drv, clk, u + s * h)
        event = EV_NONE
        earliest = math.inf
        pen, bound_now, spring = switch_values(kind, probe, t_base + (u + s * h), pz, pv, prm)
        for e in range(n_events):
            g = event_value(event_at(kind, regime, e), pen, bound_now, spring)
            if g < 0.0:
                root = _interpolant_root(taken, e, previous, s, g)
                if root < earliest:
                    earliest = root
                    event = event_at(kind, regime, e)
        if event != EV_NONE:
            return event, earliest, s
        previous = s
    return EV_NONE, 1.0, 1.0


@njit
def locate_switch(taken, event, s_hi, s_sample):
    """Refine the switch on full steps from the step's start: a step length whose value is
    past zero (the interpolant's root, the sample that showed the sign change, the whole
    step), then ``regula_falsi`` between it and the last length short of zero.  Returns
    that length, the state there in ws BEST, or -1 where the full steps see no switch
    (the value dipped below zero and back on the interpolant only: a graze within the
    tolerances)."""
    explicit, system, clk, v, trial, h, u, t_base, ws = taken
    kind, regime = system[0], system[1]
    probe, best = ws[0][PROBE], ws[0][BEST]
    e_index = 0
    for e in range(events_of(kind, regime)[1]):
        if event_at(kind, regime, e) == event:
            e_index = e
    t_abs = t_base + u
    tol = max(EVENT_TOL, 4.0 * EPS * (abs(t_abs) + h))
    search = (True, e_index, taken)
    lo, g_lo = 0.0, max(value_at(system, clk, e_index, v, t_abs, u), 0.0)
    for attempt in range(3):
        length = s_hi * h if attempt == 0 else (s_sample * h if attempt == 1 else h)
        if length <= lo:
            continue
        if attempt == 2:
            for i in range(NV):
                probe[i] = trial[i]
            g = value_at(system, clk, e_index, probe, t_base + (u + length), u + length)
        else:
            g = _value_along(search, length, probe)
        if g < 0.0:
            for i in range(NV):
                best[i] = probe[i]
            if length - lo <= tol:
                return length
            return regula_falsi(search, lo, g_lo, length, g, 1.0, tol, probe, best)
        lo, g_lo = length, g
    return -1.0
