"""Triggered events in the chain: a harmonic burst of the plate at a chosen phase of the
loading cycle, and the clock advance of the next large event.

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

from vibroblock.chain import Chain


@dataclass(frozen=True)
class TriggerSettings:
    n_blocks: int = 16
    mu_s_spread: float = 0.3
    seed: int = 1
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


def new_chain(settings: TriggerSettings) -> Chain:
    chain = Chain(settings.n_blocks, mu_s_spread=settings.mu_s_spread, seed=settings.seed)
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
    chain = Chain(settings.n_blocks, mu_s_spread=settings.mu_s_spread, seed=settings.seed)
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


def clock_advance(reference: Reference, settings: TriggerSettings, phase: float, period: float,
                  acceleration: float) -> dict:
    """One burst of acceleration amplitude ``acceleration`` (delta_0/tau_0^2, g = 1) at
    ``phase`` of the reference cycle: the next large event's start, the clock advance and
    whether the burst triggered it."""
    amplitude = acceleration * (period / (2.0 * math.pi)) ** 2
    t_b = reference.t_s + phase * reference.cycle
    chain = restored(reference, settings, t_b)
    step = period / settings.steps_per_period
    end_of_burst = t_b + settings.cycles * period
    t, k = t_b, 0
    while _large(chain, settings, t_b) is None:
        if t < end_of_burst:
            chain.set_plate_input(*burst(amplitude, period, settings.cycles, t - t_b))
            k += 1
            t = min(t_b + k * step, end_of_burst)
        else:
            if t == end_of_burst:
                chain.set_plate_input(0.0, 0.0, 0.0)
            t += settings.chunk
        if t > reference.t_ref + reference.cycle:
            return {"phase": phase, "period": period, "acceleration": acceleration, "T0": reference.t_ref - t_b,
                    "t_event": math.nan, "advance": math.nan, "triggered": False}
        chain.advance_to(t)
    t_event = _large(chain, settings, t_b)[0]
    advance = reference.t_ref - t_event
    return {"phase": phase, "period": period, "acceleration": acceleration, "T0": reference.t_ref - t_b,
            "t_event": t_event, "advance": advance, "triggered": bool(advance > 0.0 and t_event <= end_of_burst)}
