"""A block on a vibrating plate: the one object the FMUs and the harness drive.

``Block`` is the runner: it holds the checked ``Settings``, the state arrays, and
advances the registered integrator's kernels to any time.  It knows nothing of FMI;
the FMU classes are thin facades over it.
"""
from __future__ import annotations

import math
from functools import partial

import numpy as np

from . import interface
from . import layout as L
from .initial_state import frame_to_point, place
from .integrators.plate import reduced_phase
from .laws import law
from .native import LAYOUT, OBSERVED_OK, RETURNED_OK, SURFACE_Z, ZERO, NativeStep, entry_address
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
# The outputs that are plain entries of the observation in every reading: a native front
# end may read them without Python (vibroblock.native; _observables is the reference).
# The Boolean contact and the Integer coulomb_resets (and its old name slip_count) are stored as 0.0/1.0 and a whole count;
# the front end converts them as _observables does (!= 0, truncation).
OBSERVED_OUTPUTS = {"x": L.O_X, "friction_force": L.O_FRICTION, "normal_force": L.O_NORMAL,
                    "phi_integral": L.O_PHI, "penetration": L.O_PENETRATION, "work_input": L.O_WORK,
                    "energy_dissipated": L.O_DISSIPATED, "contact": L.O_CONTACT, "coulomb_resets": L.O_SLIPS,
                    "slip_count": L.O_SLIPS}
# ... and in the model's own reading, where the state is the point itself.
OBSERVED_POINT = {"z": L.O_Z, "vx": L.O_VX, "vz": L.O_VZ, "surface_z": SURFACE_Z}

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
        self._native = NativeStep(layout=LAYOUT, returned_ok=RETURNED_OK, observed_ok=OBSERVED_OK,
                                  step_slot=L.C_STEP, grid_tolerance=GRID_TOLERANCE, time=math.nan)
        self._natively_driven = False
        self._output_refs: dict[str, int] = {}
        self._native_outputs = np.zeros((0, 2), dtype=np.int64)

    # ------------------------------------------------------------------ settings
    model = property(lambda self: self.settings.model)
    parameters = property(lambda self: self.settings.parameters)
    integrator = property(lambda self: self.settings.integrator)
    initial_state = property(lambda self: self.settings.initial_state)
    energy_balance = property(lambda self: self.settings.energy_balance)
    scene = property(lambda self: self.settings.scene)
    readings = property(lambda self: self.settings.readings)
    options = property(lambda self: self.settings.options)

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
            self._retune_drive()
            if self.settings.kernel(self.frozen_released) is not self._kernel:
                self._bind_kernels()

    def set_integrator(self, integrator: str | int) -> None:
        self.settings.set_integrator(integrator)

    def set_initial_state(self, mode: int) -> None:
        self.settings.set_initial_state(mode)

    def set_energy_balance(self, track: bool) -> None:
        self.settings.set_energy_balance(track)

    def set_reading(self, name: str, value: int | str) -> None:
        self.settings.set_reading(name, value)

    def set_scene_option(self, name: str, enabled: bool) -> None:
        self.settings.set_scene_option(name, enabled)

    def set_integrator_option(self, name: str, enabled: bool) -> None:
        self.settings.set_integrator_option(name, enabled)

    # ------------------------------------------------------------------ native front end
    time = property(lambda self: self._native.time, lambda self, t: setattr(self._native, "time", t),
                    doc="The run's time (kept in the NativeStep record, which a native front end advances).")

    def drive_natively(self, record: NativeStep, time_tolerance: float, output_refs: dict | None = None) -> None:
        """Let a native front end advance this block through ``record`` (its time moves
        there), with ``time_tolerance`` the front end's match of a master's time to the
        block's.  The record takes over this block's time and arrays; a record already
        driving another block is simply re-pointed at this one.  ``output_refs`` (output
        name -> value reference) lets the front end read those outputs too."""
        record.time, record.time_tolerance = self.time, time_tolerance
        self._output_refs = dict(output_refs or {})
        for name in ("layout", "returned_ok", "observed_ok", "step_slot", "grid_tolerance"):
            setattr(record, name, getattr(self._native, name))
        self._native, self._natively_driven = record, True
        record.ready = 0
        if self.started:
            self._bind_kernels()

    def _publish_native(self) -> None:
        """Point the record at the bound kernel and arrays; ready once the run has started."""
        record = self._native
        record.ready = 0
        if not (self._natively_driven and self.started):
            return
        settings, kernel = self.settings, self._kernel
        entry = entry_address(kernel.advance, kernel.id)
        record.advance = entry
        record.kind = settings.kind
        record.flags = settings.scene_flags(self.frozen_released)
        record.y, record.cnt, record.drv, record.prm = (a.ctypes.data for a in (self.y, self.cnt, self.drv, self.prm))
        record.track_energy = int(self._track_energy)
        record.step_budget = self._step_budget
        record.t0, record.dt = self._grid
        record.observe = entry_address(kernel.observe, kernel.id)
        record.obs = self.obs.ctypes.data
        self._native_outputs = self._observed_outputs()
        record.outputs, record.n_outputs = self._native_outputs.ctypes.data, len(self._native_outputs)
        record.ready = int(entry is not None)

    def _observed_outputs(self) -> np.ndarray:
        """(value reference, observation slot or SURFACE_Z / ZERO) of each output a front
        end may read straight from the observation in this run."""
        sources = dict(OBSERVED_OUTPUTS)
        if not self._maps_to_point():  # else z, vx, vz come from _as_point
            sources.update(OBSERVED_POINT)
        if not self.energy_balance:
            sources["energy_residual"] = ZERO
        pairs = [(self._output_refs[name], source) for name, source in sources.items() if name in self._output_refs]
        return np.array(pairs, dtype=np.int64).reshape(-1, 2)

    def _release_frozen_vertical(self) -> None:
        """The frozen_vertical guard hands over to the full model, which must run at this dt."""
        self.frozen_released = True
        try:
            self.settings.check(True)
        except ModelError as exc:
            self.frozen_released = False  # stays frozen: the next call meets the guard, and this error, again
            raise ModelError(f"the frozen_vertical guard handed over to the full model at t = {self.time:g} (the "
                             f"block would detach), which cannot run at this dt: {exc}") from None
        self._bind_kernels()

    # ------------------------------------------------------------------ running
    def start(self, t0: float = 0.0) -> None:
        """Check the settings together and set the initial state at time t0."""
        if not math.isfinite(t0):
            raise ModelError(f"start time {t0!r} is not finite")
        self.settings.check(self.frozen_released)
        p = self.parameters
        self.prm = np.zeros(L.N_PRM)
        for name, index in L.prm_slots().items():
            self.prm[index] = p.get(name, 0.0)
        self.drv = np.zeros(L.N_DRV)
        self.drv[L.D_T0], self.drv[L.D_DT] = t0, p["dt"]
        self.drv[L.D_AMP], self.drv[L.D_OMEGA] = p["A"], p["omega"]
        self.drv[L.D_PHASE], self.drv[L.D_EXT_T] = reduced_phase(0.0, p["omega"], t0), t0
        self.cnt = np.zeros(L.N_CNT, dtype=np.int64)
        self.y = np.zeros(L.N_Y)
        self.obs = np.zeros(L.N_OBS)
        self._native.ready = 0
        self.time = t0
        self._bind_kernels()
        if not place(self.settings, self.prm, self.drv, self.y):
            self._release_frozen_vertical()
        self.started = True
        self._publish_native()
        self.settings.locked = True
        self._observed = None
        obs = self._observe()
        self.y[L.Y_E_NORMAL] = self._contact_energy(obs[L.O_PENETRATION])
        self.y[L.Y_E_START] = self._stored_energy(obs, t0)

    def _retune_drive(self) -> None:
        """Take new A, omega from the current grid step on, keeping the phase continuous."""
        n = self.cnt[L.C_STEP]
        step_rate = self.drv[L.D_OMEGA] * self.drv[L.D_DT]  # the kernels' phase per grid step
        phase = reduced_phase(self.drv[L.D_PHASE], step_rate, n - self.cnt[L.C_PHASE_STEP])
        self.drv[L.D_PHASE], self.cnt[L.C_PHASE_STEP] = phase, n
        self.drv[L.D_AMP], self.drv[L.D_OMEGA] = self.parameters["A"], self.parameters["omega"]
        self._observed = None

    def set_plate_input(self, z: float, v: float, a: float) -> None:
        """External plate motion from the current time on: z + v tau + a tau^2 / 2."""
        for name, value in (("plate_z", z), ("plate_v", v), ("plate_a", a)):
            if not math.isfinite(value):
                raise ModelError(f"input {name} = {value!r} is not finite; the previous input is kept")
        self._require_started()
        self.drv[L.D_EXT_Z], self.drv[L.D_EXT_V], self.drv[L.D_EXT_A] = z, v, a
        self.drv[L.D_EXT_T] = self.time
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
        self._publish_native()

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
            self._refuse_budget(t_end, target - step)
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

    def _refuse_budget(self, t_end: float, todo: int) -> None:
        dt = self._grid[1]
        raise ModelError(
            f"advancing from t = {self.time:g} to t = {t_end:g} takes {todo:.3g} internal steps of dt = {dt:g} "
            f"with {self.integrator} (hours: ~{todo / 1e8 / 3600:.2g} h or more at 1e8 steps/s); one call may take "
            f"at most {STEP_BUDGET_PER_CALL:.3g} steps so that a master is never held. Use shorter communication "
            "steps, or a larger dt with implicit_contact (no contact stiffness limit), or event_driven (model A); "
            "the state is kept.")

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
        return {"steps": int(self.cnt[L.C_STEP]), "resets": int(self.cnt[L.C_SLIPS]),
                "events": int(self.cnt[L.C_EVENTS]), "rejected": int(self.cnt[L.C_REJECTED]),
                "accepted": int(self.cnt[L.C_ACCEPTED]), "jacobians": int(self.cnt[L.C_JACOBIANS]),
                "periods_jumped": int(self.cnt[L.C_JUMPED])}

    def _observe(self):
        """The observation array (``layout.O_*``) at the current time."""
        t0, dt = self._grid
        grid_time = t0 + self.cnt.item(L.C_STEP) * dt
        h = self.time - grid_time
        if h < GRID_TOLERANCE * dt:  # on the grid up to rounding of the master's time
            h = 0.0
        self._observe_at(min(h, dt), self._track_energy, self.obs)
        return self.obs

    def _contact_energy(self, penetration: float) -> float:
        """The contact law's potential U(delta), 0 out of contact (the law's Python function:
        an output read compiles nothing)."""
        potential = law("contact", self.settings.readings.get("contact_law", 0)).module.potential.py_func
        return float(potential(penetration, self.prm)) if penetration > 0.0 else 0.0

    def _stored_energy(self, obs, t):
        """Kinetic + drive spring + friction spring + contact energy, each booked as its
        potential at the observed state (in the tangent frame the kinetic energy is
        m (u^2 + w^2) / 2, from the state's own slots): so the energy residual measures
        the truth, also where a contact law is not conservative."""
        p = self.parameters
        x, vx, vz, shear = obs[L.O_X], obs[L.O_VX], obs[L.O_VZ], obs[L.O_F]
        stretch = x - p["V_d"] * t
        friction = float(law("friction", self.settings.readings.get("friction_law", 0)).module.energy.py_func(shear, self.prm))
        return (0.5 * p["m"] * (vx * vx + vz * vz) + 0.5 * p["k_d"] * stretch * stretch
                + friction + self._contact_energy(obs[L.O_PENETRATION]))

    def _observables(self) -> dict:
        # A native front end advances the time without dropping the cache: the cache is the
        # observation at one time.
        if self._observed is None or self._observed_time != self.time:
            self._require_started()
            obs = self._observe()
            residual = 0.0
            if self.energy_balance:
                stored = self._stored_energy(obs, obs[L.O_T])
                residual = stored - self.y[L.Y_E_START] - obs[L.O_WORK] + obs[L.O_DISSIPATED]
            pen, x, z, vx, vz = obs[L.O_PENETRATION], obs[L.O_X], obs[L.O_Z], obs[L.O_VX], obs[L.O_VZ]
            surface_z = z + pen / obs[L.O_COS]
            if self._maps_to_point():
                surface_z, z, vx, vz = self._as_point(x, z, vx, vz, pen)
            self._observed = {
                "x": float(x), "z": float(z), "vx": float(vx), "vz": float(vz),
                "friction_force": float(obs[L.O_FRICTION]),
                "normal_force": float(obs[L.O_NORMAL]),
                "contact": bool(obs[L.O_CONTACT] != 0.0),
                "coulomb_resets": int(obs[L.O_SLIPS]),
                "slip_count": int(obs[L.O_SLIPS]),  # the old name of coulomb_resets (interface.OUTPUT_ALIASES)
                "phi_integral": float(obs[L.O_PHI]),
                "penetration": float(pen),
                "surface_z": float(surface_z),
                "work_input": float(obs[L.O_WORK]),
                "energy_dissipated": float(obs[L.O_DISSIPATED]),
                "energy_residual": float(residual),
            }
            counters = self.counters
            self._observed.update({name: min(counters[key], FMI_INTEGER_MAX)
                                   for name, key in interface.COST_OUTPUTS.items()})
            self._observed_time = self.time
        return self._observed

    def _maps_to_point(self) -> bool:
        """Whether outputs go through ``_as_point``: any reading other than the default
        (the laws do not change what the state slots mean)."""
        r = self.settings.readings
        return bool(r["formulation"] or r["coulomb_normal"] or r["flight"])

    def _as_point(self, x, z, vx, vz, pen):
        """Surface height under the block and the block as a point (z, vx, vz).  In the
        tangent frame the state (x, zeta, u, w) maps to z = h + zeta / cos a etc.
        (docs/physics.md, Sec. 4) and the plate surface under the block is at normal
        coordinate P = zeta + delta; in fixed axes the state is the point already."""
        height, slope = self.settings.variant.profile(x, self.prm)
        secant = math.sqrt(1.0 + slope * slope)  # 1 / cos a
        if self.settings.tangent_frame:
            z, vx, vz = frame_to_point(self.settings.variant, self.prm, x, z, vx, vz)
        return z + pen * secant, z, vx, vz

    @property
    def grid_step(self) -> int:
        return int(self.cnt[L.C_STEP])

    # ------------------------------------------------------------------ state
    def get_state(self) -> dict:
        """Everything needed to continue the run bit for bit, as plain (JSON-able) values."""
        self._require_started()
        return {
            **self.settings.to_dict(), "frozen_released": self.frozen_released, "time": self.time,
            "y": self.y.tolist(), "cnt": self.cnt.tolist(), "drv": self.drv.tolist(), "prm": self.prm.tolist(),
        }

    def set_state(self, state: dict) -> None:
        if state.get("model") != self.model:
            raise ModelError(f"state of model {state.get('model')!r} cannot be set on a model {self.model} block")
        try:
            y = np.array(state["y"], dtype=float)
            cnt = np.array(state["cnt"], dtype=np.int64)
            drv = np.array(state["drv"], dtype=float)
            prm = np.array(state["prm"], dtype=float)
            settings = Settings.from_dict(state)
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"not a valid block state: {exc}") from None
        if (y.shape, cnt.shape, drv.shape, prm.shape) != ((L.N_Y,), (L.N_CNT,), (L.N_DRV,), (L.N_PRM,)):
            raise ModelError("not a valid block state: array sizes differ from this model's")
        settings.locked = True
        self.settings = settings
        self._native.ready = 0
        self.y, self.cnt, self.drv, self.prm = y, cnt, drv, prm
        self.obs = np.zeros(L.N_OBS)
        self.frozen_released = bool(state.get("frozen_released", False))
        self.time = float(state["time"])
        self.started = True
        self._bind_kernels()
        self._observed = None
