"""Triggered slips: a block in stick-slip hit by a real record at chosen phases of its stick.

The experiment (``examples/triggering.py`` runs it and saves the figure and table):

1. A Block FMU (model A, scaled set k_d = V_d = 1e-2, gamma_t = 5e-3: stick ~5.2e3,
   slip ~50) starts at rest and runs through ``warmup_slips`` slips, so that the
   next stick is one of the regular cycle.  That stick is run to its end (the
   *reference* slip) while the FMU state is saved every ``state_interval``.
2. For every phase p the state nearest before the branch time is restored
   (fmi2SetFMUstate, nothing is re-run from the start) and the block is hit by the
   record, timed so that the record's peak acceleration arrives at
   ``t_s + p T`` (t_s: end of the previous slip, T: the reference stick time), at
   every peak acceleration in ``peak_accelerations`` (in g).  Each branch runs until
   its next slip is over.
3. Clock advance = (reference slip onset) - (slip onset with the record); positive:
   the record brought the slip forward.

The record is the strong-motion part of obspy's bundled event (BW.RJOB, vertical,
2009-08-24: the 5-95 % energy of its acceleration lies within record seconds 5-8),
cut to ``record_window``, processed in 1-20 Hz, and stretched by ``time_scale``
(200: its acceleration, centred near 10.6 Hz, arrives at 0.33 rad/tau_0, a third
of the contact frequency, and its strong part lasts ~600 tau_0, ~12 % of the stick).
The plate motion goes to the block through its inputs at every communication point
(fmpy, the convention of :mod:`harness.ground.excitation`), computed by the same playback
the Excitation FMU runs.

Mechanism: during a stick the tangential spring holds the drive's force,
k_t F = p mu_s m g at stress ratio p.  The record changes the normal force N and with
it the Coulomb bound mu_s N, not F.  In contact and below the contact frequency
N ~ m (g + a_plate) (slightly amplified: :func:`normal_force_response`), so a downward
plate acceleration beyond ~(1 - p) g resets the spring, and one beyond ~g lifts the
block off (F = 0 in flight, resets by the thousand while it bounces).
:func:`reset_thresholds` computes both thresholds from the linear in-contact response
of N, for comparison with the simulated resets.  What a reset leads to is measured,
not assumed: a cascade into the (shorter) slip late in the stick; earlier, a burst of
small slips after which the block sticks again with its drive spring relaxed, so the
next slip comes *later* (by about the burst's travel / V_d); see docs/excitation.md.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .excitation import BUNDLED_SETTINGS, excitation_of, peak_scaled_parameters, playback_of
from harness.cosim.fmu import FmuInstance
from harness.runs.observables import slip_events
from .records import GroundMotion, ProcessingSettings, Record, process_record
from harness.runs.settings import PRESETS, default_fmu

__all__ = ["Branch", "Cycle", "TriggeringResult", "TriggeringSettings", "normal_force_response", "prepare_cycle",
           "reset_thresholds", "run_branch", "run_triggering", "triggering_motion"]

OUTPUTS = ("x", "vx", "contact", "coulomb_resets", "friction_force", "normal_force")
OUTCOMES = ("no effect", "reset, re-stuck", "early slip", "lifted off")


@dataclass(frozen=True)
class TriggeringSettings:
    """Everything the experiment depends on (reported with the results)."""

    block_fmu: str = field(default_factory=lambda: default_fmu("A"))
    # The paper's fixed-step scheme, chosen explicitly (the FMUs default to adaptive): the
    # tables in docs/excitation.md were measured with it, and its grid t0 + n dt does not
    # change with the communication step, so what differs between runs is the plate input.
    parameters: dict = field(default_factory=lambda: {**PRESETS["scaled"], "integrator": 0})
    record_window: tuple[float, float] = (3.5, 11.5)  # seconds of obspy's example record
    pad_seconds: float = 1.0
    time_scale: float = 200.0  # model time units per record second
    step_size: float = 0.25  # communication step
    phases: tuple[float, ...] = (0.2, 0.4, 0.6, 0.8, 0.9, 0.95)
    peak_accelerations: tuple[float, ...] = (0.001, 0.1, 0.3, 0.6, 0.9, 1.2)  # peak |a_plate| in g
    onset_velocity: float = 0.05  # a slip starts when vx exceeds this [delta_0/tau_0]
    release_velocity: float = 0.02  # ... and is over when vx falls below this
    min_slip: float = 10.0  # shorter forward jumps are not slips [delta_0]
    warmup_slips: int = 1
    state_interval: float = 50.0
    max_wait: float = 1.5  # a branch gives up after this many stick times past the hit
    advance_tolerance: float = 10.0  # clock advances up to this are "no effect" [tau_0]

    def __post_init__(self):
        if not all(0.0 < p < 1.0 for p in self.phases):
            raise ValueError(f"phases {self.phases} must lie in (0, 1)")
        if not all(a >= 0.0 for a in self.peak_accelerations):
            raise ValueError(f"peak accelerations {self.peak_accelerations} must be >= 0")
        if not (self.time_scale > 0.0 and self.step_size > 0.0 and self.state_interval >= self.step_size):
            raise ValueError("time_scale and step_size must be > 0 and state_interval >= step_size")


def triggering_motion(window: tuple[float, float] = (3.5, 11.5), pad_seconds: float = 1.0) -> GroundMotion:
    """The strong-motion part of obspy's bundled event, processed like the bundled record."""
    import obspy

    from .records import read_record

    record = read_record(obspy.read(), inventory=obspy.read_inventory(), trace_id="BW.RJOB..EHZ")
    first, last = (int(round(s / record.dt)) for s in window)
    if not 0 <= first < last <= record.npts:
        raise ValueError(f"window {window} s lies outside the record (0 to {record.duration:g} s)")
    cut = Record(data=record.data[first:last], dt=record.dt, quantity=record.quantity,
                 source=f"{record.source} [{window[0]:g} s, {window[1]:g} s]", trace_id=record.trace_id,
                 start_time=record.start_time, response_removed=record.response_removed,
                 history=record.history + (f"cut to record seconds {window[0]:g}-{window[1]:g}",))
    settings = ProcessingSettings(freqmin=BUNDLED_SETTINGS.freqmin, freqmax=BUNDLED_SETTINGS.freqmax,
                                  pad_seconds=pad_seconds)
    return process_record(cut, settings)


# ---------------------------------------------------------------------------- stepping
class _Run:
    """A started Block FMU advanced on the grid t0 + k h with an optional plate motion,
    keeping the sampled outputs."""

    def __init__(self, instance: FmuInstance, t0: float, h: float, plate=None):
        self.instance, self.t0, self.h, self.k = instance, t0, h, 0
        self.plate = plate
        self.read = instance.reader(OUTPUTS)
        self.rows = [[t0, *self.read()]]

    @property
    def time(self) -> float:
        return self.t0 + self.k * self.h

    def step(self) -> None:
        t = self.time
        if self.plate is not None:
            z, v, a = self.plate.evaluate(t)
            self.instance.set({"plate_z": z, "plate_v": v, "plate_a": a})
        self.instance.do_step(t, self.h)
        self.k += 1
        self.rows.append([self.time, *self.read()])

    def table(self) -> dict[str, np.ndarray]:
        rows = np.asarray(self.rows)
        return {"time": rows[:, 0], **{name: rows[:, j + 1] for j, name in enumerate(OUTPUTS)}}


def _slips(table: dict, settings: TriggeringSettings):
    return slip_events(table["time"], table["x"], table["vx"], settings.onset_velocity, settings.release_velocity,
                       settings.min_slip)


def _onset(table: dict, slips, settings: TriggeringSettings) -> float:
    """Onset of the first slip: where vx first exceeds the onset velocity within it,
    interpolated between samples (finer than the communication step)."""
    t, vx = table["time"], table["vx"]
    start = int(np.searchsorted(t, slips.onset[0]))
    j = start + int(np.argmax(vx[start:] > settings.onset_velocity))
    return float(t[j - 1] + (settings.onset_velocity - vx[j - 1]) / (vx[j] - vx[j - 1]) * (t[j] - t[j - 1]))


def _run_until_slip(run: _Run, settings: TriggeringSettings, deadline: float, count: int = 1,
                    check_every: int = 400, on_step=None):
    """Advance until ``count`` slips are complete; their SlipEvents, or None at the deadline."""
    while run.time < deadline:
        for _ in range(check_every):
            run.step()
            if on_step is not None:
                on_step(run)
        slips = _slips(run.table(), settings)
        if slips.count >= count:
            return slips
    return None


def _coulomb_bound(parameters: dict) -> float:
    """mu_s m g, the bound on k_t F with the plate at rest."""
    return parameters.get("mu_s", 0.5) * parameters.get("m", 1.0) * parameters.get("g", 1.0)


# ---------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Cycle:
    """The reference stick: from the end of a slip (t_s) to the next slip's onset."""

    stick_start: float
    next_slip: float
    slip_length: float
    reference: dict  # sampled outputs from the first saved state to the end of the next slip
    states: tuple  # (time, serialized FMU state), every state_interval

    @property
    def stick_time(self) -> float:
        return self.next_slip - self.stick_start


@dataclass(frozen=True)
class Branch:
    phase: float  # (hit time - stick start) / stick time; the hit is the record's peak
    peak_acceleration: float  # peak |plate acceleration| in g
    downward_peak: float  # most negative plate acceleration of the record, in g
    stress_ratio: float  # k_t F / (mu_s m g) at the hit, from the reference run
    hit_time: float
    slip_onset: float
    clock_advance: float  # reference onset - this onset (> 0: earlier)
    slip_length: float
    resets: int  # Coulomb resets while the record plays, before the reference slip
    jump: float  # largest forward travel beyond the reference's in that time [delta_0]
    contact_fraction: float  # over the record
    lifted_off: bool  # the block left the plate before its slip
    min_normal_force: float  # over the record, in m g
    predicted_reset: float  # reset_thresholds at this phase: peak (in g) that resets the spring
    predicted_liftoff: float  # ... and that lifts the block off
    outcome: str


@dataclass(frozen=True)
class TriggeringResult:
    settings: TriggeringSettings
    cycle: Cycle
    branches: tuple[Branch, ...]
    record_duration: float  # model time units of the played record
    strong_motion: tuple[float, float]  # 5-95 % energy window, model time after the record's start
    peak_lead: float  # model time from the record's start to its peak acceleration

    def rows(self) -> list[dict]:
        return [asdict(b) for b in self.branches]

    def to_csv(self, path) -> Path:
        import csv

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        rows = self.rows()
        with open(path, "w", newline="") as stream:
            writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
            writer.writeheader()
            for row in rows:
                writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
        return path

    def to_markdown(self) -> str:
        head = ("| phase | stress ratio | peak a [g] | down peak [g] | predicted reset / lift-off [g] | resets | "
                "jump [δ₀] | contact | clock advance [τ₀] | advance / T | slip [δ₀] | outcome |")
        lines = [head, "|" + "---|" * 12]
        T = self.cycle.stick_time
        for b in self.branches:
            lines.append(f"| {b.phase:.2f} | {b.stress_ratio:.2f} | {b.peak_acceleration:g} | "
                         f"{b.downward_peak:.3f} | {b.predicted_reset:.2f} / {b.predicted_liftoff:.2f} | "
                         f"{b.resets} | {b.jump:.2f} | {b.contact_fraction:.4f} | {b.clock_advance:.1f} | "
                         f"{b.clock_advance / T:+.3f} | {b.slip_length:.1f} | {b.outcome} |")
        return "\n".join(lines)


# ---------------------------------------------------------------------------- physics
def normal_force_response(acceleration: np.ndarray, times: np.ndarray, parameters: dict) -> np.ndarray:
    """Change of the normal force caused by a plate acceleration, block in contact.

    The penetration d obeys m d'' + gamma_n d' + k_n d = m (g + a_plate) and
    N = k_n d + gamma_n d', so dN = m a_plate (k_n + gamma_n s) / (m s^2 + gamma_n s + k_n):
    m a_plate well below the contact frequency, amplified near it.
    """
    from scipy import signal

    m, k_n, gamma_n = (parameters.get(k, d) for k, d in (("m", 1.0), ("k_n", 1.0), ("gamma_n", 0.07)))
    system = signal.lti([m * gamma_n, m * k_n], [m, gamma_n, k_n])
    _, response, _ = signal.lsim(system, np.asarray(acceleration, dtype=float), np.asarray(times, dtype=float))
    return response


def reset_thresholds(acceleration_per_g: np.ndarray, times: np.ndarray, stress: np.ndarray,
                     parameters: dict) -> tuple[float, float]:
    """Smallest scale factors of a plate acceleration that (1) reset the loaded
    tangential spring, (2) lift the block off, if it stays in contact until then.

    ``acceleration_per_g``: the plate acceleration for a scale factor of 1 (model units,
    g = 1); ``stress``: k_t F on ``times`` without the record (the reference run).
    A reset needs mu_s (m g + s dN(t)) <= k_t F(t) at some t, a lift-off
    m g + s dN(t) <= 0; dN from :func:`normal_force_response` scales with s.
    """
    m, g, mu_s = (parameters.get(k, d) for k, d in (("m", 1.0), ("g", 1.0), ("mu_s", 0.5)))
    response = normal_force_response(acceleration_per_g, times, parameters)
    pulls = response < 0.0
    if not np.any(pulls):
        return math.inf, math.inf
    margin = mu_s * m * g - np.asarray(stress)[pulls]
    reset = float(max(np.min(margin / (mu_s * -response[pulls])), 0.0))
    liftoff = float(np.min(m * g / -response[pulls]))
    return reset, liftoff


def _classify(resets: int, lifted_off: bool, clock_advance: float, tolerance: float) -> str:
    if lifted_off:
        return "lifted off"
    if clock_advance > tolerance:
        return "early slip"
    if resets > 0:
        return "reset, re-stuck"
    return "no effect"


# ---------------------------------------------------------------------------- experiment
def prepare_cycle(instance: FmuInstance, settings: TriggeringSettings) -> Cycle:
    """Run from rest through the warm-up slips, then through one whole reference stick."""
    instance.start({**settings.parameters, "initial_state": 0})
    h = settings.step_size
    run = _Run(instance, 0.0, h)
    nominal = settings.parameters.get("mu_s", 0.5) / max(settings.parameters["k_d"] * settings.parameters["V_d"],
                                                         1e-300)
    deadline = 3.0 * nominal * (settings.warmup_slips + 1)
    slips = _run_until_slip(run, settings, deadline, count=settings.warmup_slips)
    if slips is None:
        raise RuntimeError(f"fewer than {settings.warmup_slips} slips by t = {deadline:g}; is the block in "
                           "stick-slip?")
    stick_start = float(slips.end[settings.warmup_slips - 1])
    # The reference stick, saving states on the way (the branches restore them).
    run = _Run(instance, run.time, h)
    states = [(run.time, instance.get_state())]
    every = int(round(settings.state_interval / h))

    def keep_states(r: _Run) -> None:
        if r.k % every == 0:
            states.append((r.time, instance.get_state()))

    slips = _run_until_slip(run, settings, run.time + 3.0 * nominal, on_step=keep_states)
    if slips is None:
        raise RuntimeError("the reference stick did not end in a slip")
    table = run.table()
    return Cycle(stick_start=stick_start, next_slip=_onset(table, slips, settings),
                 slip_length=float(slips.length[0]), reference=table, states=tuple(states))


def run_branch(instance: FmuInstance, cycle: Cycle, settings: TriggeringSettings, motion: GroundMotion,
               phase: float, peak: float, lead: float) -> Branch:
    """Restore the stick before the branch time and hit it with the record (module doc)."""
    h = settings.step_size
    T = cycle.stick_time
    hit = cycle.stick_start + phase * T
    first = cycle.states[0][0]
    t_branch = first + h * math.floor((hit - lead - first) / h + 1e-9)
    saved = [s for s in cycle.states if s[0] <= t_branch + 1e-9]
    if not saved:
        raise ValueError(f"phase {phase} is too early: the record's peak comes {lead:g} after its start, "
                         f"before the first saved state at t = {first:g}")
    t_saved, state = saved[-1]
    instance.set_state(state)
    run = _Run(instance, t_saved, h)
    while run.time < t_branch - 1e-9:
        run.step()
    t_branch = run.time
    record = playback_of(motion)
    scaled = peak_scaled_parameters(record, 1.0, settings.time_scale, onset=t_branch)  # peak 1 g
    per_g = excitation_of(record, **scaled)
    plate = excitation_of(record, **{**scaled, "amplitude_scale": scaled["amplitude_scale"] * peak})
    record_end = t_branch + record.duration * settings.time_scale
    tolerance = settings.advance_tolerance
    # What the record does before the reference slip would have started anyway.
    window_end = min(record_end, cycle.next_slip - tolerance)
    grid = t_branch + h * np.arange(int(math.floor((window_end - t_branch) / h)) + 1)
    reference = cycle.reference
    stress = np.interp(grid, reference["time"], -reference["friction_force"])
    predicted_reset, predicted_liftoff = reset_thresholds(per_g.evaluate(grid)[2], grid - t_branch, stress,
                                                          settings.parameters)

    run = _Run(instance, t_branch, h, plate)
    slips = _run_until_slip(run, settings, hit + settings.max_wait * T)
    while run.time < record_end - 1e-9:  # the whole record, also after an early slip
        run.step()
    table = run.table()
    onset = _onset(table, slips, settings) if slips is not None else math.inf
    advance = cycle.next_slip - onset
    time = table["time"]
    in_window = time <= window_end
    in_record = time <= record_end
    resets = int(table["coulomb_resets"][in_window][-1] - table["coulomb_resets"][0])
    jump = float(np.max(table["x"][in_window] - np.interp(time[in_window], reference["time"], reference["x"])))
    lifted_off = bool(np.any(table["contact"][time < onset] == 0.0))
    whole_record = t_branch + h * np.arange(int(math.floor((record_end - t_branch) / h)) + 1)
    return Branch(
        phase=phase, peak_acceleration=peak, downward_peak=float(np.min(plate.evaluate(whole_record)[2])),
        stress_ratio=float(np.interp(hit, reference["time"], -reference["friction_force"])
                           / _coulomb_bound(settings.parameters)),
        hit_time=hit, slip_onset=onset, clock_advance=advance,
        slip_length=float(slips.length[0]) if slips is not None else math.nan, resets=resets, jump=jump,
        contact_fraction=float(np.mean(table["contact"][in_record])), lifted_off=lifted_off,
        min_normal_force=float(np.min(table["normal_force"][in_record])),
        predicted_reset=predicted_reset, predicted_liftoff=predicted_liftoff,
        outcome=_classify(resets, lifted_off, advance, tolerance))


def run_triggering(settings: TriggeringSettings = TriggeringSettings(), progress=None) -> TriggeringResult:
    """The whole experiment (module doc); ``progress(i, n)`` is called after each branch."""
    motion = triggering_motion(settings.record_window, settings.pad_seconds)
    record = playback_of(motion)
    t = np.arange(record.acceleration.size) * record.dt
    energy = np.cumsum(record.acceleration**2)
    energy /= energy[-1]
    strong = (float(t[np.searchsorted(energy, 0.05)]) * settings.time_scale,
              float(t[np.searchsorted(energy, 0.95)]) * settings.time_scale)
    lead = float(t[np.argmax(np.abs(record.acceleration))]) * settings.time_scale
    with FmuInstance(settings.block_fmu) as instance:
        cycle = prepare_cycle(instance, settings)
        branches = []
        total = len(settings.phases) * len(settings.peak_accelerations)
        for phase in settings.phases:
            for peak in settings.peak_accelerations:
                branches.append(run_branch(instance, cycle, settings, motion, phase, peak, lead))
                if progress is not None:
                    progress(len(branches), total)
    return TriggeringResult(settings, cycle, tuple(branches), record.duration * settings.time_scale, strong, lead)
