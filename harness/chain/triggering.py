"""Triggered events in the chain: a plate motion (a harmonic burst, a chirp, a real
record) at a chosen phase of the loading cycle, and the clock advance of the next large
event.

The experiment (``examples/chain_triggering.py`` runs it and prints the table):

1. A chain (``vibroblock.chain.Chain``, the core the BlockChain FMU runs) is loaded
   through ``warmup`` large events (at least ``large_fraction`` of its blocks slip), so
   that the next cycle is one of its regular ones.  From the end t_s of the last one it
   runs to the start t_ref of the next large event (the *reference*), its state saved
   every ``snapshot_interval`` (``Chain.get_state``, restored bit for bit).
2. For every phase p, period P and acceleration amplitude a, the chain is restored and
   run to t_b = t_s + p T (T = t_ref - t_s), and the plate then moves by a Hann-tapered
   burst z = A sin(2 pi tau / P) sin^2(pi tau / (n P)), A = a (P / 2 pi)^2,
   tau = t - t_b, over n whole periods,
   given to the chain as its plate input (height, velocity, acceleration) at
   ``steps_per_period`` points per period.
3. The clock advance is t_ref - (start of the next large event after t_b): positive, the
   burst brought it forward.  The event is *triggered* if it comes earlier than the
   reference and starts during the burst.

The same experiment takes any :class:`PlateSignal` in place of the burst
(:func:`signal_advance`): :class:`Burst`, :class:`Chirp` (a Hann-tapered linear or
logarithmic sweep, scaled by acceleration like the burst) and :class:`RecordSignal`
(the vertical acceleration of a processed record, e.g. obspy's example event, stretched
in time and scaled to a peak acceleration by the product's record playback,
``harness.ground.excitation``).  Each starts at t_b; after its end the plate rests at
the signal's last height.  The row also counts the smaller events between t_b and the
large one.  :func:`periodic_advance` keeps a :class:`Harmonic` plate
acceleration a sin(2 pi tau / P) up until the event: the periodic loading of Perfettini
et al.

The threshold a(P) (:func:`threshold_sweep`): per phase and period, the smallest burst
acceleration that triggers the next large event, bisected, beside what the static picture
predicts: the amplitude at which the normal-force dip of a block held on the plate (the
contact's linear response to the burst, which counts its resonance) brings the first
block's Coulomb bound below the load its friction spring holds (:func:`predicted_threshold`).

The threshold a(P) (:func:`threshold_sweep`): per phase and period, the smallest burst
acceleration that triggers the next large event, bisected, beside what the static picture
predicts: the amplitude at which the normal-force dip of a block held on the plate (the
contact's linear response to the burst, which counts its resonance) brings the first
block's Coulomb bound below the load its friction spring holds (:func:`predicted_threshold`).

The burst is scaled by its acceleration: in contact the plate's acceleration changes the
normal force, and with it the Coulomb bound mu_s N, by m a (the stress perturbation of
Perfettini et al.); a burst of fixed height would perturb it by A (2 pi / P)^2, mixing
the period's own effect with an amplitude that falls as 1/P^2.

T_0 = t_ref - t_b, the time left before the instability when the burst arrives, is the
scale of Perfettini, Schmittbuhl and Cochard (2003, JGR 108(B9), 2409): for a periodic
stress perturbation their single-degree-of-freedom and continuum models respond
independently of the period for P < T_0 and depend strongly on it for P > T_0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vibroblock.chain import Chain


@dataclass(frozen=True)
class TriggerSettings:
    n_blocks: int = 16
    mu_s_spread: float = 0.3
    seed: int = 1
    load_spread: float = 0.0
    # Any other parameter of the chain or its blocks (e.g. a friction law), as (name, value) pairs.
    parameters: tuple = ()
    large_fraction: float = 0.5  # an event of at least this fraction of the blocks is large
    warmup: int = 3  # large events before the reference cycle
    snapshot_interval: float = 200.0
    cycles: int = 3  # whole periods of a burst
    steps_per_period: int = 64
    chunk: float = 50.0  # how far the chain runs between looks at its catalogue


@dataclass(frozen=True)
class Reference:
    t_s: float  # end of the last large event before the cycle
    t_ref: float  # start of the next large event, undisturbed
    snapshots: tuple  # (time, Chain state), every snapshot_interval from t_s

    @property
    def cycle(self) -> float:
        return self.t_ref - self.t_s


def _large(chain: Chain, settings: TriggerSettings, since: float):
    """The first large event that started at or after ``since``, or None."""
    threshold = settings.large_fraction * chain.n_blocks
    return next((e for e in chain.events if e[0] >= since and e[3] >= threshold), None)


def _unstarted_chain(settings: TriggerSettings) -> Chain:
    return Chain(settings.n_blocks, mu_s_spread=settings.mu_s_spread, seed=settings.seed,
                 load_spread=settings.load_spread, **dict(settings.parameters))


def new_chain(settings: TriggerSettings) -> Chain:
    chain = _unstarted_chain(settings)
    chain.start()
    return chain


def reference_cycle(settings: TriggerSettings = TriggerSettings(), limit: float = 1e6) -> Reference:
    """Load the chain through ``warmup`` large events, then follow one cycle undisturbed."""
    chain, t = new_chain(settings), 0.0
    threshold = settings.large_fraction * chain.n_blocks
    while sum(e[3] >= threshold for e in chain.events) < settings.warmup:
        t += settings.chunk
        if t > limit:
            raise RuntimeError(f"fewer than {settings.warmup} large events in {limit:g} tau_0")
        chain.advance_to(t)
    t_s = max(e[1] for e in chain.events if e[3] >= threshold)
    snapshots, t = [], math.ceil(t_s / settings.snapshot_interval) * settings.snapshot_interval
    if t <= chain.time:  # (the last large event ended within the last chunk)
        t = chain.time + settings.snapshot_interval
    while _large(chain, settings, t_s + 1e-9) is None:
        chain.advance_to(t)
        snapshots.append((t, chain.get_state()))
        t += settings.snapshot_interval
    return Reference(t_s, _large(chain, settings, t_s + 1e-9)[0], tuple(snapshots))


def restored(reference: Reference, settings: TriggerSettings, t_b: float) -> Chain:
    """The chain of the reference cycle at the last snapshot before t_b, run to t_b."""
    time, state = max((s for s in reference.snapshots if s[0] <= t_b), key=lambda s: s[0],
                      default=reference.snapshots[0])
    if time > t_b:
        raise ValueError(f"no snapshot before t_b = {t_b:g}: the first is at {time:g}")
    chain = _unstarted_chain(settings)
    chain.set_state(state)
    if t_b > chain.time:
        chain.advance_to(t_b)
    return chain


def burst(amplitude: float, period: float, cycles: int, tau: float) -> tuple[float, float, float]:
    """Height, velocity and acceleration of the Hann-tapered burst at tau after its start."""
    duration = cycles * period
    if not 0.0 <= tau <= duration:
        return 0.0, 0.0, 0.0
    w, W = 2.0 * math.pi / period, math.pi / duration
    s, c = math.sin(w * tau), math.cos(w * tau)
    h, dh, ddh = math.sin(W * tau) ** 2, W * math.sin(2.0 * W * tau), 2.0 * W * W * math.cos(2.0 * W * tau)
    return (amplitude * s * h, amplitude * (w * c * h + s * dh),
            amplitude * (-w * w * s * h + 2.0 * w * c * dh + s * ddh))


class PlateSignal:
    """A plate motion that starts at tau = 0: (height, velocity, acceleration) at tau, its
    ``duration``, the ``step`` at which the chain is given it, and the motion the plate
    keeps ``after`` it (height, velocity, acceleration at its end)."""

    duration: float
    step: float

    def __call__(self, tau: float) -> tuple[float, float, float]:
        raise NotImplementedError

    @property
    def after(self) -> tuple[float, float, float]:
        """The plate's motion from the signal's end on: at rest at its last height."""
        return (float(self(self.duration)[0]), 0.0, 0.0)


class Burst(PlateSignal):
    """The Hann-tapered harmonic burst of :func:`burst`, of acceleration amplitude
    ``acceleration``: height amplitude acceleration (P / 2 pi)^2."""

    def __init__(self, acceleration: float, period: float, cycles: int, steps_per_period: int):
        self.amplitude = acceleration * (period / (2.0 * math.pi)) ** 2
        self.period, self.cycles = period, cycles
        self.duration, self.step = cycles * period, period / steps_per_period

    def __call__(self, tau):
        return burst(self.amplitude, self.period, self.cycles, tau)

    @property
    def after(self):
        return (0.0, 0.0, 0.0)


class Harmonic(PlateSignal):
    """Periodic loading: the plate's acceleration is a sin(2 pi tau / P) from tau = 0 on,
    held for ``duration``, the plate starting at rest:

        v = (a / w) (1 - cos w tau),   z = (a / w) tau - (a / w^2) sin w tau,   w = 2 pi / P.

    Height, velocity and acceleration start at zero without a jump, whatever P: no ramp
    is needed.  (A ramp of z = A sin(w tau) over a fixed time would have to bring the
    plate to the speed a / w within it, an acceleration of order a P / (2 pi ramp) that
    exceeds a at long periods.)  The price is the plate's mean rise at a / w: a uniform
    motion, which the flat plate's contact (it sees the relative penetration and its
    rate only) does not feel.  After the duration the plate goes on at its last velocity."""

    def __init__(self, acceleration: float, period: float, duration: float, steps_per_period: int = 64):
        self.acceleration, self.omega = acceleration, 2.0 * math.pi / period
        self.duration, self.step = duration, period / steps_per_period

    def __call__(self, tau):
        if tau < 0.0:
            return 0.0, 0.0, 0.0
        if tau > self.duration:
            z, v, _ = self.after
            return z + v * (tau - self.duration), v, 0.0
        a, w = self.acceleration, self.omega
        return a / w * tau - a / (w * w) * math.sin(w * tau), a / w * (1.0 - math.cos(w * tau)), a * math.sin(w * tau)

    @property
    def after(self):
        z, v, _ = self(self.duration)
        return z, v, 0.0


class Chirp(PlateSignal):
    """A Hann-tapered sweep from period ``period_start`` to ``period_end`` over ``duration``,
    linear or logarithmic in frequency, scaled by acceleration:

        z = a h(tau) sin(phi(tau)) / omega(tau)^2,   h = sin^2(pi tau / D),

    with phi' = omega the instantaneous angular frequency:
    - linear: omega = omega_0 + (omega_1 - omega_0) tau / D, phi = omega_0 tau + (omega_1 - omega_0) tau^2 / 2D;
    - log: omega = omega_0 exp(k tau), k = ln(omega_1 / omega_0) / D, phi = omega_0 (exp(k tau) - 1) / k.

    Dividing by omega^2 makes the acceleration's leading term -a h sin(phi), so ``a`` is
    the acceleration amplitude at every frequency, as for the bursts; velocity and
    acceleration are the exact derivatives of the height (the slow terms included).
    Height and velocity vanish at both ends; the taper's curvature 2 (pi/D)^2 leaves an
    acceleration a P^2 sin(phi) / (2 D^2) at the end (P the end's period), a small step
    for a chirp of many periods."""

    SWEEPS = ("linear", "log")

    def __init__(self, acceleration: float, period_start: float, period_end: float, duration: float,
                 sweep: str = "log", steps_per_period: int = 64):
        if sweep not in self.SWEEPS:
            raise ValueError(f"sweep = {sweep!r}: a chirp sweeps 'linear' or 'log' in frequency")
        if not (period_start > 0.0 and period_end > 0.0 and duration > 0.0):
            raise ValueError("a chirp's periods and duration must be > 0")
        self.acceleration, self.sweep, self.duration = acceleration, sweep, duration
        self.omega_start, self.omega_end = 2.0 * math.pi / period_start, 2.0 * math.pi / period_end
        self.step = min(period_start, period_end) / steps_per_period
        self.rate = (self.omega_end - self.omega_start) / duration if sweep == "linear" else \
            math.log(self.omega_end / self.omega_start) / duration

    def frequency(self, tau):
        """omega(tau) and its first two derivatives."""
        if self.sweep == "linear":
            return self.omega_start + self.rate * tau, self.rate, 0.0
        omega = self.omega_start * math.exp(self.rate * tau)
        return omega, self.rate * omega, self.rate * self.rate * omega

    def phase(self, tau):
        if self.sweep == "linear":
            return self.omega_start * tau + 0.5 * self.rate * tau * tau
        if self.rate == 0.0:
            return self.omega_start * tau
        return self.omega_start * math.expm1(self.rate * tau) / self.rate

    def __call__(self, tau):
        if not 0.0 <= tau <= self.duration:
            return 0.0, 0.0, 0.0
        W = math.pi / self.duration
        h, dh, ddh = math.sin(W * tau) ** 2, W * math.sin(2.0 * W * tau), 2.0 * W * W * math.cos(2.0 * W * tau)
        omega, d_omega, dd_omega = self.frequency(tau)
        q = 1.0 / (omega * omega)  # the acceleration scaling 1/omega^2 and its derivatives
        dq = -2.0 * d_omega / omega ** 3
        ddq = 6.0 * d_omega * d_omega / omega ** 4 - 2.0 * dd_omega / omega ** 3
        g, dg, ddg = h * q, dh * q + h * dq, ddh * q + 2.0 * dh * dq + h * ddq
        phi = self.phase(tau)
        s, c = math.sin(phi), math.cos(phi)
        a = self.acceleration
        return (a * g * s, a * (dg * s + g * omega * c),
                a * (ddg * s + (2.0 * dg * omega + g * d_omega) * c - g * omega * omega * s))

    @property
    def after(self):
        return (0.0, 0.0, 0.0)


class RecordSignal(PlateSignal):
    """A record's vertical motion played from tau = 0, stretched by ``time_scale`` (model time
    units per record second) and scaled so that its peak acceleration is
    ``peak_acceleration`` (in g), by the playback the Excitation FMU runs
    (``harness.ground.excitation``: piecewise-linear acceleration, its exact integrals).
    ``motion``: a processed GroundMotion; by default the strong-motion part of obspy's
    example event (``harness.ground.triggering.triggering_motion``)."""

    def __init__(self, peak_acceleration: float, time_scale: float = 200.0, motion=None,
                 samples_per_step: float = 0.5):
        from ..ground.excitation import excitation_of, peak_scaled_parameters, playback_of

        if motion is None:
            from ..ground.triggering import triggering_motion
            motion = triggering_motion()
        record = playback_of(motion)
        self.excitation = excitation_of(record, **peak_scaled_parameters(record, peak_acceleration, time_scale))
        self.duration = record.duration * time_scale
        self.step = record.dt * time_scale * samples_per_step  # the chain is given the motion twice a sample

    def __call__(self, tau):
        z, v, a = self.excitation.evaluate(float(tau))
        return float(z), float(v), float(a)


def signal_advance(reference: Reference, settings: TriggerSettings, phase: float, signal: PlateSignal) -> dict:
    """The plate moves by ``signal`` from phase ``phase`` of the reference cycle on: the
    next large event's start, the clock advance and whether the signal triggered it
    (the event came earlier than the reference and started while the signal played)."""
    t_b = reference.t_s + phase * reference.cycle
    chain = restored(reference, settings, t_b)
    end_of_signal = t_b + signal.duration
    t, k = t_b, 0
    while _large(chain, settings, t_b) is None:
        if t < end_of_signal:
            chain.set_plate_input(*signal(t - t_b))
            k += 1
            t = min(t_b + k * signal.step, end_of_signal)
        else:
            if t == end_of_signal:
                chain.set_plate_input(*signal.after)
            t += settings.chunk
        if t > reference.t_ref + reference.cycle:
            return {"phase": phase, "T0": reference.t_ref - t_b, "t_event": math.nan, "advance": math.nan,
                    "triggered": False, "smaller_events": sum(1 for e in chain.events if e[0] >= t_b)}
        chain.advance_to(t)
    t_event = _large(chain, settings, t_b)[0]
    advance = reference.t_ref - t_event
    # Smaller events between: slip that released part of the load before the large event.
    smaller = sum(1 for e in chain.events if t_b <= e[0] < t_event)
    return {"phase": phase, "T0": reference.t_ref - t_b, "t_event": t_event, "advance": advance,
            "triggered": bool(advance > 0.0 and t_event <= end_of_signal), "smaller_events": smaller}


def clock_advance(reference: Reference, settings: TriggerSettings, phase: float, period: float,
                  acceleration: float) -> dict:
    """One burst of acceleration amplitude ``acceleration`` (delta_0/tau_0^2, g = 1) at
    ``phase`` of the reference cycle: the next large event's start, the clock advance and
    whether the burst triggered it."""
    row = signal_advance(reference, settings, phase,
                         Burst(acceleration, period, settings.cycles, settings.steps_per_period))
    return {"phase": phase, "period": period, "acceleration": acceleration, **row}


def periodic_advance(reference: Reference, settings: TriggerSettings, phase: float, period: float,
                     acceleration: float) -> dict:
    """Periodic loading (:class:`Harmonic`) of acceleration amplitude ``acceleration`` from
    ``phase`` of the reference cycle on, kept up until the next large event (at most a
    cycle after the reference one): its start, the clock advance, and whether it came
    earlier than the reference."""
    t_b = reference.t_s + phase * reference.cycle
    harmonic = Harmonic(acceleration, period, reference.t_ref - t_b + reference.cycle, settings.steps_per_period)
    row = signal_advance(reference, settings, phase, harmonic)
    return {"phase": phase, "period": period, "acceleration": acceleration, **row}


# The chain of the rate-and-state study (examples/chain_rate_state_triggering.py,
# docs/chain.md): aging law, a = 0.01, b = 0.015 (velocity weakening, b - a = 0.005),
# D_c = 0.1, V_0 = V_d and theta_0 = D_c / V_d (steady sliding at the loading rate at the
# start).  Ruina's critical stiffness (b - a) N / D_c = 0.05 N against the loading
# stiffness of the chain's uniform mode, k_p in series with the contact's k_t,
# 0.01 * 0.28 / 0.29 = 0.0097: k / k_c = 0.15-0.28 over the spread weights N = m g (1 +/- 0.3),
# so the chain stick-slips.  No dashpot on the friction spring (the law dissipates by
# slip).  The blocks differ by their weights (load_spread), the friction law ignoring
# mu_s.  Its large events peak at slip speeds ~0.4-0.7 and the creep between them
# and the after-slips stay below ~0.1, so v_start = 0.2 opens only the large events.
RATE_STATE_STUDY = TriggerSettings(
    n_blocks=16, mu_s_spread=0.0, load_spread=0.3, seed=1, snapshot_interval=100.0, chunk=25.0,
    parameters=(("friction_law", 3), ("rs_a", 0.01), ("rs_b", 0.015), ("rs_D_c", 0.1), ("rs_V_0", 1e-2),
                ("rs_mu_0", 0.5), ("rs_theta_0", 10.0), ("gamma_t", 0.05), ("v_start", 0.2), ("v_stop", 0.05)))


# ---------------------------------------------------------------------- thresholds a(P)
def trigger_threshold(reference: Reference, settings: TriggerSettings, phase: float, period: float,
                      low: float = 1e-3, high: float = 1.0, rel: float = 0.02) -> dict:
    """The smallest acceleration amplitude of a burst of period ``period`` at ``phase`` of
    the reference cycle that triggers the next large event, bisected in log a between
    ``low`` and ``high`` (in g) to a relative width ``rel``.  Returns the bracket
    (``below``: a burst that did not trigger, ``above``: one that did; nan where
    ``high`` did not trigger or ``low`` already did) and the runs it took.  The bisection
    takes triggering to grow with a: it reports the bracket it found, not a proof that
    no smaller a triggers."""
    def triggers(acceleration):
        return clock_advance(reference, settings, phase, period, acceleration)["triggered"]

    runs = 2
    if not triggers(high):
        return {"phase": phase, "period": period, "below": high, "above": math.nan, "runs": 1}
    if triggers(low):
        return {"phase": phase, "period": period, "below": math.nan, "above": low, "runs": runs}
    while high / low > 1.0 + rel:
        middle = math.sqrt(low * high)
        runs += 1
        if triggers(middle):
            high = middle
        else:
            low = middle
    return {"phase": phase, "period": period, "below": low, "above": high, "runs": runs}


def margins(chain: Chain, settings: TriggerSettings) -> tuple[float, float]:
    """How far the plate must accelerate downwards, held, for the Coulomb bound
    mu_s,i m (g_i - a) of the first block, and of half the blocks, to fall below the load
    k_t |F_i| its friction spring holds now (every block at rest on the flat plate, so its
    normal force is its weight)."""
    from vibroblock import layout as L

    p = chain.settings.parameters
    load = p["k_t"] * np.abs(chain.Y[:, L.Y_F])
    margin = np.sort(chain.PRM[:, L.P_G] - load / (chain.PRM[:, L.P_MUS] * p["m"]))
    return float(margin[0]), float(margin[int(math.ceil(settings.large_fraction * chain.n_blocks)) - 1])


def normal_force_dip(signal: PlateSignal, parameters: dict, sample_step: float):
    """The normal force's drop below the weight, over m, of a block held on the plate
    (the spring-dashpot contact m, k_n, gamma_n of ``parameters``, a base-excited linear
    oscillator that never leaves the plate) while the plate moves by ``signal``: times
    ``sample_step`` apart over the signal and the drops there (scipy's ``solve_ivp``,
    rtol 1e-10)."""
    from scipy.integrate import solve_ivp

    m, k_n, gamma_n = parameters["m"], parameters["k_n"], parameters["gamma_n"]

    def rates(tau, y):  # y: the block's height and velocity relative to the plate
        return (y[1], -(k_n * y[0] + gamma_n * y[1]) / m - signal(tau)[2])

    taus = np.linspace(0.0, signal.duration, int(round(signal.duration / sample_step)) + 1)
    solution = solve_ivp(rates, (0.0, signal.duration), (0.0, 0.0), t_eval=taus, rtol=1e-10, atol=1e-12,
                         max_step=2.0 * sample_step)
    # The contact force is -k_n y - gamma_n y' over the weight's: its drop is their sum's negative.
    return taus, (k_n * solution.y[0] + gamma_n * solution.y[1]) / m


def predicted_threshold(reference: Reference, settings: TriggerSettings, phase: float, period: float) -> dict:
    """The acceleration amplitude a burst needs, by the static picture, to bring the
    Coulomb bound of the first block, and of half the blocks, below the load their springs
    hold: the smallest margin(t_b + tau) / dip(tau) over the burst, the margins of the
    undisturbed chain (:func:`margins`) and the dip of a unit burst's normal force
    (:func:`normal_force_dip`), which counts the contact's resonance and ringing."""
    t_b = reference.t_s + phase * reference.cycle
    chain = restored(reference, settings, t_b)
    signal = Burst(1.0, period, settings.cycles, settings.steps_per_period)
    # 32 samples per period: the sampled peak is within cos(pi/32) (0.5 %) of the true one.
    taus, dips = normal_force_dip(signal, chain.settings.parameters, period / 32.0)
    first = half = math.inf
    for tau, dip in zip(taus, dips):
        if tau > 0.0:
            chain.advance_to(t_b + tau)
        if dip > 0.0:
            m_first, m_half = margins(chain, settings)
            first, half = min(first, m_first / dip), min(half, m_half / dip)
    return {"phase": phase, "period": period, "first_block": first, "half_chain": half}


def threshold_sweep(reference: Reference, settings: TriggerSettings, phases, periods, rel: float = 0.02) -> list[dict]:
    """Per phase and period: the bisected threshold (:func:`trigger_threshold`) beside the
    static prediction (:func:`predicted_threshold`).  Only bursts shorter than the time
    left, ``cycles`` P < T_0: a longer one still plays when the undisturbed event comes,
    and any perturbation that moves that event earlier would count as a trigger."""
    rows = []
    for phase in phases:
        t0 = (1.0 - phase) * reference.cycle
        for period in periods:
            if settings.cycles * period >= t0:
                continue
            measured = trigger_threshold(reference, settings, phase, period, rel=rel)
            predicted = predicted_threshold(reference, settings, phase, period)
            rows.append({**measured, "T0": t0, "first_block": predicted["first_block"],
                         "half_chain": predicted["half_chain"]})
    return rows
