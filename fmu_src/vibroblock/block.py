"""A block on a vibrating plate: the one object the FMUs and the harness drive.

``Block`` is the runner: it holds the checked ``Settings``, the state arrays, and
advances the registered integrator's kernels to any time.  It knows nothing of FMI;
the FMU classes are thin facades over it.
"""
from __future__ import annotations

import math
from functools import partial

import numpy as np

from . import interface, run_arrays
from . import layout as L
from .initial_state import place
from .native import NativeLink, NativeStep
from .observation import contact_energy, observables, stored_energy
from .settings import ModelError, Settings

OUTPUTS = tuple(interface.OUTPUTS)
# A time within this fraction of dt of a grid point is that grid point.
GRID_TOLERANCE = 1e-6
# One call advances a fixed-step scheme by at most this many internal steps (about ten
# minutes at 1e8 steps/s on one core).  An FMI master cannot interrupt a doStep, so a
# request beyond it (e.g. a horizon of 1e9 at dt = 4e-4: 2.5e12 steps, hours) is refused
# with its cost and the ways around it instead of holding the host.
STEP_BUDGET_PER_CALL = 2**36
# An fmi2Integer is a C int: a count output is held at its largest value beyond it.
FMI_INTEGER_MAX = 2**31 - 1
# Attributes of a Block that are its settings' (``Settings``).
FROM_SETTINGS = frozenset({"model", "parameters", "integrator", "initial_state", "energy_balance", "scene", "readings",
                           "options", "set_integrator", "set_initial_state", "set_energy_balance", "set_reading",
                           "set_scene_option", "set_integrator_option"})
__all__ = ["Block", "ModelError", "OUTPUTS"]


class Block:
    """One block on a vibrating plate.

    Parameters are the paper's symbols (see ``vibroblock.parameters``).  Typical use::

        block = Block("A", A=0.5, omega=0.8)
        block.start()
        block.advance_to(100.0)
        block.outputs()["x"]
    """

    def __init__(self, model: str = "A", integrator: str | int = "symplectic_euler", initial_state: int = 0,
                 energy_balance: bool = False, **parameters):
        self.settings = Settings(model, integrator, initial_state, energy_balance, **parameters)
        self.started = False
        self.frozen_released = False  # the frozen_vertical guard has handed over to the full model
        self._observed = None
        self._observed_time = math.nan
        # The run's time, and what a native front end needs to advance it (vibroblock.native).
        self._link = NativeLink(GRID_TOLERANCE)

    # ------------------------------------------------------------------ settings
    def __getattr__(self, name: str):
        """What the run is (``model``, ``parameters``, ``integrator``, ``readings``, ...) and
        the setters of what it will be, each value checked as it is set: the settings'."""
        if name in FROM_SETTINGS:
            return getattr(self.settings, name)
        raise AttributeError(f"'Block' object has no attribute {name!r}")

    def set_parameter(self, name: str, value: float) -> None:
        """Set a parameter; during a run only A and omega, which retune the drive.  A
        retuned drive is checked with the rest of the settings (e.g. event_driven refuses
        an undamped contact driven at its own resonance) and on refusal the previous value
        is kept.  Where the retuned drive changes what runs (adaptive's exact flows on
        model A stop where event_driven cannot run), the kernels are bound anew."""
        previous = self.parameters.get(name)
        self.settings.set_parameter(name, value)
        if self.started:
            try:
                self.settings.check(self.frozen_released)
            except ModelError:
                self.parameters[name] = previous
                raise
            run_arrays.retune_drive(self.cnt, self.drv, self.parameters, self.readings)  # the phase continuous
            self._observed = None
            if self.settings.kernel(self.frozen_released) is not self._kernel:
                self._bind_kernels()

    # ------------------------------------------------------------------ native front end
    _native = property(lambda self: self._link.record, doc="The NativeStep record (vibroblock.native).")
    time = property(lambda self: self._link.record.time, lambda self, t: setattr(self._link.record, "time", t),
                    doc="The run's time (kept in the NativeStep record, which a native front end advances).")

    def drive_natively(self, record: NativeStep, time_tolerance: float, output_refs: dict | None = None) -> None:
        """Let a native front end advance this block through ``record`` (``NativeLink.attach``);
        ``output_refs`` (output name -> value reference) lets it read those outputs too."""
        self._link.attach(record, time_tolerance, output_refs)
        if self.started:
            self._bind_kernels()

    def _release_frozen_vertical(self) -> None:
        """The frozen_vertical guard hands over to the full model, which must run at this dt
        (if not, the block stays frozen: the next call meets the guard, and the error, again)."""
        self.settings.check_hand_over(self.time)
        self.frozen_released = True
        self._bind_kernels()

    # ------------------------------------------------------------------ running
    def start(self, t0: float = 0.0) -> None:
        """Check the settings together and set the initial state at time t0."""
        if not math.isfinite(t0):
            raise ModelError(f"start time {t0!r} is not finite")
        self.settings.check(self.frozen_released)
        self.y, self.cnt, self.drv, self.prm = run_arrays.fresh(self.parameters, t0, self.settings.readings)
        self.obs = np.zeros(L.N_OBS)
        self._native.ready = 0
        self.time = t0
        self._bind_kernels()
        if not place(self.settings, self.prm, self.drv, self.y):
            self._release_frozen_vertical()
        self.started = True
        self._link.publish(self)
        self.settings.locked = True
        self._observed = None
        obs = self._observe()
        self.y[L.Y_E_NORMAL] = contact_energy(self.settings, self.prm, obs[L.O_PENETRATION])  # the kernels' book of it
        self.y[L.Y_E_START] = stored_energy(self.settings, self.prm, obs, t0)

    def set_plate_input(self, z: float, v: float, a: float, *along_x: float) -> None:
        """External plate motion from the current time on: z + v tau + a tau^2 / 2, and
        ``along_x`` = (x, vx, ax): x + vx tau + ax tau^2 / 2 (plate_motion = 1 only)."""
        run_arrays.check_plate_input((z, v, a, *along_x), self.readings)
        self._require_started()
        run_arrays.set_plate_input(self.drv, self.time, z, v, a, *along_x)
        self._observed = None

    def _bind_kernels(self) -> None:
        """Resolve what a call runs once, not per call: the integrator that runs now, its
        compiled kernels bound to this run's arrays, the grid and the step budget.  They
        change only when the arrays are made (start, set_state) or the frozen_vertical
        guard hands over; the settings that select them are fixed once a run has started."""
        settings, released = self.settings, self.frozen_released
        kernel = settings.kernel(released)
        arrays = (settings.kind, settings.scene_flags(released), self.y, self.cnt, self.drv, self.prm)
        self._kernel = kernel
        self._advance = kernel.bind_advance(*arrays)
        self._observe_at = kernel.bind_observe(*arrays)
        self._track_energy = settings.energy_balance
        self._grid = (float(self.drv[L.D_T0]), float(self.drv[L.D_DT]))
        self._grid_step = partial(self.cnt.item, L.C_STEP)  # the grid index, read without a lookup
        self._step_budget = STEP_BUDGET_PER_CALL if kernel.force_evaluations > 0 else math.inf
        self._link.publish(self)

    def advance_to(self, t_end: float) -> None:
        """Advance to t_end > current time; on failure the state is left unchanged."""
        # An FMU's doStep is this call, thousands of times per second at ~15 us of work
        # each: everything a call can do without is resolved in _bind_kernels, the checks
        # are inline (no helper frames) and the usual case is one kernel call.
        if not self.started:
            self._require_started()
        if not self.time < t_end < math.inf:  # NaN fails too
            raise ModelError(f"cannot advance from t = {self.time!r} to t = {t_end!r}: "
                             "the end time must be finite and later than the current time")
        t0, dt = self._grid
        # Grid point at or just below t_end.  The tolerance absorbs masters that
        # accumulate time (t += h drifts by ~1e-10 over thousands of steps).
        target = math.floor((t_end - t0) / dt + GRID_TOLERANCE)
        step = self._grid_step()
        if target - step > self._step_budget:
            raise ModelError(self._kernel.budget_message(t=self.time, t_end=t_end, todo=target - step,
                                                         dt=dt, budget=STEP_BUDGET_PER_CALL))
        while step < target:
            status = self._advance(target - step, self._track_energy)
            if status:
                self._stopped(status, t_end, step)
            step = self._grid_step()
        self.time = float(t_end)
        self._observed = None

    def _stopped(self, status: int, t_end: float, step: int) -> None:
        """A kernel call that did not simply finish: a failure (the state is as it was
        before the call) or a scene's guard handing the frozen vertical motion over."""
        if status < 0:
            raise ModelError(self._kernel.message(status, t=self.time, t_end=t_end, dt=self._grid[1]))
        t0, dt = self._grid
        self.time = float(t0 + self._grid_step() * dt)
        self._observed = None
        self._release_frozen_vertical()

    def _require_started(self) -> None:
        if not self.started:
            raise ModelError("the run has not started: call start() (FMI: exit initialization mode) first")

    # ------------------------------------------------------------------ observing
    def outputs(self) -> dict[str, float | int | bool]:
        """Observables at the current time (the FMU's outputs)."""
        return dict(self._observables())

    def output(self, name: str):
        return self._observables()[name]

    @property
    def counters(self) -> dict[str, int]:
        """Cost counters of the run: grid steps, Coulomb resets, located events, rejected steps,
        and the adaptive integrator's accepted internal steps, Jacobian evaluations and the
        plate periods it crossed by stroboscopic jumps."""
        self._require_started()
        return run_arrays.counters(self.cnt)

    def _observe(self):
        """The observation array (``layout.O_*``) at the current time."""
        t0, dt = self._grid
        grid_time = t0 + self.cnt.item(L.C_STEP) * dt
        h = self.time - grid_time
        if h < GRID_TOLERANCE * dt:  # on the grid up to rounding of the master's time
            h = 0.0
        self._observe_at(min(h, dt), self._track_energy, self.obs)
        return self.obs

    def _observables(self) -> dict:
        # A native front end advances the time without dropping the cache: the cache is the
        # observation at one time.
        if self._observed is None or self._observed_time != self.time:
            self._require_started()
            self._observed = observables(self.settings, self.prm, self._observe(), self.y[L.Y_E_START])
            counters = self.counters
            self._observed.update({name: min(counters[key], FMI_INTEGER_MAX)
                                   for name, key in interface.COST_OUTPUTS.items()})
            self._observed_time = self.time
        return self._observed

    grid_step = property(lambda self: int(self.cnt[L.C_STEP]), doc="The grid index of the stored state.")

    # ------------------------------------------------------------------ state
    def get_state(self) -> dict:
        """Everything needed to continue the run bit for bit, as plain (JSON-able) values."""
        self._require_started()
        return {**self.settings.to_dict(), "frozen_released": self.frozen_released, "time": self.time,
                **run_arrays.saved(self.y, self.cnt, self.drv, self.prm)}

    def set_state(self, state: dict) -> None:
        settings = Settings.from_dict(state, self.model)
        arrays = run_arrays.restored(state)
        settings.locked = True
        self.settings = settings
        self._native.ready = 0
        self.y, self.cnt, self.drv, self.prm = arrays
        self.obs = np.zeros(L.N_OBS)
        self.frozen_released = bool(state.get("frozen_released", False))
        self.time = float(state["time"])
        self.started = True
        self._bind_kernels()
        self._observed = None
