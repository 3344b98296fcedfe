"""A block on a vibrating plate: the one object the FMUs and the harness drive.

``Block`` owns the state arrays, checks every value it is given, sets the initial
state, advances the compiled integrators to any time and reports observables.  It
knows nothing of FMI; the FMU classes are thin facades over it.
"""
from __future__ import annotations

import cmath
import math

import numpy as np

from . import interface
from . import layout as L
from .models import MODELS, load, profile
from .parameters import INITIAL_STATES, SCENE_OPTIONS, parameters_for
from .event_driven import observe_event_driven
from .stepping import FORCE_EVALUATIONS, INTEGRATORS, advance, observe
from .scenes import COULOMB, FROZEN, RIGID, advance_scene, observe_scene
from .implicit_contact import (MAX_PIECES, MAX_SEGMENTS, MAX_TURN_PER_STEP, TOO_FAST_FOR_CORRUGATION,
                               TOO_MANY_SWITCHES)

# Largest dt^2 k/m + 2 dt gamma/m an integrator accepts for a spring-dashpot pair
# (symplectic Euler is stable below 4; RK4 on the imaginary axis below 8, on the real
# axis below ~5.6): margins that keep the ringing of the contact resolved.
STABILITY_LIMIT = {"symplectic_euler": 1.0, "rk4": 4.0}

OUTPUTS = tuple(interface.OUTPUTS)
# A time within this fraction of dt of a grid point is that grid point.
GRID_TOLERANCE = 1e-6
# One call advances a fixed-step scheme by at most this many internal steps (about ten
# minutes at 1e8 steps/s on one core).  An FMI master cannot interrupt a doStep, so a
# request beyond it (e.g. a horizon of 1e9 at dt = 4e-4: 2.5e12 steps, hours) is refused
# with its cost and the ways around it instead of holding the host.
STEP_BUDGET_PER_CALL = 2**36


class ModelError(ValueError):
    """A value or request the model cannot accept; the message says which and why."""


class Block:
    """One block on a vibrating plate.

    Parameters are the paper's symbols (see ``vibroblock.parameters``).  Typical use::

        block = Block("A", A=0.5, omega=0.8)
        block.start()
        block.advance_to(100.0)
        block.outputs()["x"]
    """

    def __init__(self, model: str = "A", integrator: str = "symplectic_euler", initial_state: int = 0,
                 energy_balance: bool = False, **parameters: float):
        if model not in MODELS:
            raise ModelError(f"unknown model {model!r}; choose one of {sorted(MODELS)}")
        self.model = model
        self.kind = MODELS[model]
        self._specs = {p.name: p for p in parameters_for(model)}
        self.parameters = {name: spec.default for name, spec in self._specs.items()}
        self.started = False
        self.energy_balance = False
        self.integrator = "symplectic_euler"
        self.initial_state = 0
        self.set_integrator(integrator)
        self.set_initial_state(initial_state)
        self.set_energy_balance(energy_balance)
        # Scene reductions (vibroblock.scenes) come as Boolean keywords among the parameters.
        self.scene = {name: False for name in SCENE_OPTIONS}
        self.frozen_released = False  # the frozen_vertical guard has handed over to the full model
        for name, value in parameters.items():
            if name in SCENE_OPTIONS:
                self.set_scene_option(name, value)
            else:
                self.set_parameter(name, value)

    # ------------------------------------------------------------------ settings
    def set_parameter(self, name: str, value: float) -> None:
        spec = self._specs.get(name)
        if spec is None:
            raise ModelError(f"model {self.model} has no parameter {name!r}; it has {sorted(self._specs)}")
        problem = spec.problem(value)
        if problem:
            raise ModelError(problem)
        if self.started and not spec.tunable:
            raise ModelError(f"{name} is fixed once the run has started; only A and omega can change during a run")
        self.parameters[name] = float(value)
        if self.started:
            self._retune_drive()

    def set_integrator(self, integrator: str | int) -> None:
        names = list(INTEGRATORS)
        if isinstance(integrator, (int, np.integer)) and not isinstance(integrator, bool):
            # By id, not by position: ids are the FMU's stable values, whatever the table's order.
            by_id = {i: name for name, i in INTEGRATORS.items()}
            if integrator not in by_id:
                raise ModelError(f"integrator = {integrator} is not one of {by_id}")
            integrator = by_id[int(integrator)]
        if integrator not in INTEGRATORS:
            raise ModelError(f"unknown integrator {integrator!r}; choose one of {names}")
        if integrator == "event_driven" and self.model != "A":
            raise ModelError(f"the event_driven integrator is exact only for model A (a flat plate, piecewise linear); "
                             f"choose another integrator for model {self.model}")
        self._require_not_started("integrator")
        self.integrator = integrator

    def set_energy_balance(self, track: bool) -> None:
        """Account work, dissipation and stored energy during the run (costs ~1/3 more per step)."""
        self._require_not_started("energy_balance")
        self.energy_balance = bool(track)

    def set_scene_option(self, name: str, enabled: bool) -> None:
        """Drop physics the scene does not need (``parameters.SCENE_OPTIONS``)."""
        if name not in SCENE_OPTIONS:
            raise ModelError(f"unknown scene option {name!r}; choose one of {sorted(SCENE_OPTIONS)}")
        models, _ = SCENE_OPTIONS[name]
        if enabled and self.model not in models:
            raise ModelError(f"{name} is available for models {', '.join(models)}, not model {self.model}: "
                             "on a corrugated plate the vertical motion follows the surface (use rigid_contact)")
        self._require_not_started(name)
        self.scene[name] = bool(enabled)

    def _scene_flags(self) -> int:
        """The reductions in effect now (0: the full model)."""
        return ((RIGID if self.scene["rigid_contact"] else 0)
                | (FROZEN if self.scene["frozen_vertical"] and not self.frozen_released else 0)
                | (COULOMB if self.scene["coulomb_friction"] else 0))

    def set_initial_state(self, mode: int) -> None:
        if mode not in INITIAL_STATES:
            raise ModelError(f"initial_state = {mode!r} is not one of {INITIAL_STATES}")
        self._require_not_started("initial_state")
        self.initial_state = int(mode)

    def _require_not_started(self, what: str) -> None:
        if self.started:
            raise ModelError(f"{what} is fixed once the run has started")

    def check_stability(self) -> None:
        """Refuse an internal step that the chosen explicit integrator cannot resolve."""
        if self._scene_flags():
            self._check_scene_step()
            return
        if self.integrator == "event_driven":  # exact flows: dt only sets the storage grid
            if self.model != "A":
                raise ModelError(f"the event_driven integrator is exact only for model A, not model {self.model}")
            return
        p, dt = self.parameters, self.parameters["dt"]
        if self.integrator == "implicit_contact":
            self._check_implicit_contact_step()
            return
        limit = STABILITY_LIMIT[self.integrator]
        for what, k, gamma in (("normal contact", p["k_n"], p["gamma_n"]),
                               ("tangential contact", p["k_t"], p["gamma_t"])):
            k_m, c_m = k / p["m"], gamma / p["m"]
            if dt * dt * k_m + 2.0 * dt * c_m > limit:
                dt_max = (limit / (2.0 * c_m) if k_m == 0.0
                          else (-c_m + math.sqrt(c_m * c_m + limit * k_m)) / k_m)
                raise ModelError(
                    f"dt = {dt:g} is too large for the {what} (k/m = {k_m:g}, gamma/m = {c_m:g}) with "
                    f"{self.integrator}: dt^2 k/m + 2 dt gamma/m must stay <= {limit:g}; use dt <= {dt_max:.3g}")

    def _check_scene_step(self) -> None:
        """Reduced scenes run their own first-order kernel (vibroblock.scenes): it needs
        only the springs and dashpots the scene keeps resolved, as symplectic Euler does."""
        if self.scene["rigid_contact"] and self.scene["frozen_vertical"]:
            raise ModelError("rigid_contact and frozen_vertical exclude each other (a rigid contact has no "
                             "compliant orbit to freeze); choose one")
        if (self.scene["rigid_contact"] or self.scene["coulomb_friction"]) and self.integrator != "symplectic_euler":
            raise ModelError(f"rigid_contact and coulomb_friction run on their own first-order kernel; set "
                             f"integrator = symplectic_euler (0), not {self.integrator}")
        p, dt = self.parameters, self.parameters["dt"]
        kept = [("drive spring", p["k_d"], 0.0)]
        if not self.scene["coulomb_friction"]:
            kept.append(("tangential contact", p["k_t"], p["gamma_t"]))
        else:
            kept.append(("tangential damping", 0.0, p["gamma_t"]))
        if not (self.scene["rigid_contact"] or self.scene["frozen_vertical"]):
            kept.append(("normal contact", p["k_n"], p["gamma_n"]))
        for what, k, gamma in kept:
            k_m, c_m = k / p["m"], gamma / p["m"]
            if dt * dt * k_m + 2.0 * dt * c_m > 1.0:
                dt_max = (1.0 / (2.0 * c_m) if k_m == 0.0 else (-c_m + math.sqrt(c_m * c_m + k_m)) / k_m)
                raise ModelError(
                    f"dt = {dt:g} is too large for the {what} (k/m = {k_m:g}, gamma/m = {c_m:g}) in this reduced "
                    f"scene: dt^2 k/m + 2 dt gamma/m must stay <= 1; use dt <= {dt_max:.3g}")

    def _release_frozen_vertical(self) -> None:
        """The frozen_vertical guard hands over to the full model, which must run at this dt."""
        self.frozen_released = True
        try:
            self.check_stability()
        except ModelError as exc:
            self.frozen_released = False  # stays frozen: the next call meets the guard, and this error, again
            raise ModelError(f"the frozen_vertical guard handed over to the full model at t = {self.time:g} (the "
                             f"block would detach), which cannot run at this dt: {exc}") from None

    def _check_implicit_contact_step(self) -> None:
        """implicit_contact integrates the contact spring-dashpots, and the drive spring's
        pull along the tangent, exactly: on a flat plate nothing limits dt but the search
        for a release inside a step (at most MAX_PIECES half contact periods).  On a
        corrugated plate the frame is frozen over a step and what couples through it stays
        explicit - the drive's pull across the slope and the load's pull along the curved
        surface (stiffness up to load x A_x omega_x^2): dt^2 (k_d + load A_x omega_x^2)/m <= 1."""
        p, dt = self.parameters, self.parameters["dt"]
        curvature = p.get("A_x", 0.0) * p.get("omega_x", 0.0) ** 2  # largest |Z_p''| of the corrugation
        if curvature > 0.0:
            confining = p["P_l"] if "P_l" in p else p["m"] * p["g"]
            k_m = (p["k_d"] + confining * curvature) / p["m"]
            if dt * dt * k_m > 1.0:
                raise ModelError(
                    f"dt = {dt:g} is too large for the corrugated plate with implicit_contact: the drive spring and "
                    f"the load's pull along the curved surface (k_d + load A_x omega_x^2)/m = {k_m:g} stay explicit, "
                    f"dt^2 times it must stay <= 1; use dt <= {1.0 / math.sqrt(k_m):.3g}")
        half_periods = dt * math.sqrt(p["k_n"] / p["m"]) / math.pi
        if half_periods >= MAX_PIECES:
            raise ModelError(
                f"dt = {dt:g} spans {half_periods:.3g} half periods of the normal contact (k_n/m = "
                f"{p['k_n'] / p['m']:g}); implicit_contact searches at most {MAX_PIECES} per step for a release; "
                f"use dt <= {MAX_PIECES * math.pi / math.sqrt(p['k_n'] / p['m']):.3g}")

    # ------------------------------------------------------------------ running
    def start(self, t0: float = 0.0) -> None:
        """Check the settings together and set the initial state at time t0."""
        if not math.isfinite(t0):
            raise ModelError(f"start time {t0!r} is not finite")
        self.check_stability()
        p = self.parameters
        self.prm = np.zeros(L.N_PRM)
        for i, name in enumerate(L.PRM_NAMES):
            self.prm[i] = p.get(name, 0.0)
        self.drv = np.zeros(L.N_DRV)
        self.drv[L.D_T0], self.drv[L.D_DT] = t0, p["dt"]
        self.drv[L.D_AMP], self.drv[L.D_OMEGA] = p["A"], p["omega"]
        self.drv[L.D_PHASE], self.drv[L.D_EXT_T] = p["omega"] * t0, t0
        self.cnt = np.zeros(L.N_CNT, dtype=np.int64)
        self.y = np.zeros(L.N_Y)
        self.time = t0
        self._set_initial_state()
        self._place_for_scene()
        self.started = True
        self._observed = None
        # The normal spring's energy starts at k_n delta^2 / 2 and then integrates its power.
        penetration = self.output("penetration")
        self.y[L.Y_E_NORMAL] = 0.5 * p["k_n"] * penetration**2 if penetration > 0.0 else 0.0
        self._observed = None
        self.y[L.Y_E_START] = self._stored_energy(*self._observation_raw()[:5], self.y[L.Y_E_NORMAL], t0)

    def _set_initial_state(self) -> None:
        p, y = self.parameters, self.y
        x = p["x_start"]
        height, slope = profile(self.kind, x, self.prm)
        cos_a, sin_a = 1.0 / math.sqrt(1.0 + slope * slope), slope / math.sqrt(1.0 + slope * slope)
        phase = self.drv[L.D_PHASE]
        plate_z = p["A"] * math.sin(phase) + height
        plate_v = p["A"] * p["omega"] * math.cos(phase)
        # The confining load's component into the plate sets the rest penetration.
        load_x, load_z = load(self.kind, cos_a, sin_a, self.prm)
        weight = max(0.0, -(-load_x * sin_a + load_z * cos_a))
        y[L.Y_X], y[L.Y_VX] = x, p["vx_start"]
        if self.initial_state == 0:
            y[L.Y_Z] = plate_z - weight / (p["k_n"] * cos_a)
            y[L.Y_VZ] = p["vz_start"]
        elif self.initial_state == 1:
            y[L.Y_Z], y[L.Y_VZ] = p["z_start"], p["vz_start"]
        else:
            offset, rate = steady_orbit(p["m"], p["k_n"], p["gamma_n"], weight, p["A"], p["omega"], phase)
            y[L.Y_Z], y[L.Y_VZ] = plate_z + offset, plate_v + rate

    def _place_for_scene(self) -> None:
        """A rigid contact starts on the surface (moving with it unless initial_state = 1);
        a frozen vertical motion starts on its orbit, or hands over at once if the orbit
        does not keep contact."""
        p, y = self.parameters, self.y
        phase = self.drv[L.D_PHASE]
        plate_z, plate_v = p["A"] * math.sin(phase), p["A"] * p["omega"] * math.cos(phase)
        if self.scene["rigid_contact"] and self.initial_state != 1:
            height, slope = profile(self.kind, y[L.Y_X], self.prm)
            y[L.Y_Z], y[L.Y_VZ] = plate_z + height, plate_v + slope * y[L.Y_VX]
        if self.scene["frozen_vertical"]:
            offset, rate = steady_orbit(p["m"], p["k_n"], p["gamma_n"], p["m"] * p["g"], p["A"], p["omega"], phase)
            if offset >= 0.0:
                self._release_frozen_vertical()
            else:
                y[L.Y_Z], y[L.Y_VZ] = plate_z + offset, plate_v + rate

    def _retune_drive(self) -> None:
        """Take new A, omega from the current grid step on, keeping the phase continuous."""
        n = self.cnt[L.C_STEP]
        phase = self.drv[L.D_PHASE] + self.drv[L.D_OMEGA] * self.drv[L.D_DT] * (n - self.cnt[L.C_PHASE_STEP])
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

    def advance_to(self, t_end: float) -> None:
        """Advance to t_end > current time; on failure the state is left unchanged."""
        self._require_started()
        if not (math.isfinite(t_end) and t_end > self.time):
            raise ModelError(f"cannot advance from t = {self.time!r} to t = {t_end!r}: "
                             "the end time must be finite and later than the current time")
        dt, t0 = self.drv[L.D_DT], self.drv[L.D_T0]
        # Grid point at or just below t_end.  The tolerance absorbs masters that
        # accumulate time (t += h drifts by ~1e-10 over thousands of steps).
        target = math.floor((t_end - t0) / dt + GRID_TOLERANCE)
        todo = target - int(self.cnt[L.C_STEP])
        if todo > STEP_BUDGET_PER_CALL and FORCE_EVALUATIONS.get(self.integrator, 1) > 0:
            raise ModelError(
                f"advancing from t = {self.time:g} to t = {t_end:g} takes {todo:.3g} internal steps of dt = {dt:g} "
                f"with {self.integrator} (hours: ~{todo / 1e8 / 3600:.2g} h or more at 1e8 steps/s); one call may take "
                f"at most {STEP_BUDGET_PER_CALL:.3g} steps so that a master is never held. Use shorter communication "
                "steps, or a larger dt with implicit_contact (no contact stiffness limit), or event_driven (model A); "
                "the state is kept.")
        while todo > 0:
            flags = self._scene_flags()
            if flags:
                done, released = advance_scene(self.kind, flags, self.y, self.cnt, self.drv, self.prm, todo,
                                               self.energy_balance)
                if done >= 0:
                    todo -= done
                    if released:
                        self.time = float(self.drv[L.D_T0] + self.cnt[L.C_STEP] * dt)
                        self._observed = None
                        self._release_frozen_vertical()
                        continue
            else:
                done = advance(self.kind, INTEGRATORS[self.integrator], self.y, self.cnt, self.drv, self.prm, todo,
                               self.energy_balance)
                todo = 0
            if done == TOO_MANY_SWITCHES:
                raise ModelError(
                    f"more than {MAX_SEGMENTS} contact switches within one step of dt = {dt:g} between t = "
                    f"{self.time:g} and t = {t_end:g} ({self.integrator}): the contact chatters faster than the step "
                    f"resolves; the state at t = {self.time:g} is kept. Reduce dt.")
            if done == TOO_FAST_FOR_CORRUGATION:
                raise ModelError(
                    f"the block crosses the corrugation too fast for dt = {dt:g} between t = {self.time:g} and "
                    f"t = {t_end:g}: the surface under it turns by more than {MAX_TURN_PER_STEP} rad in one step "
                    f"({self.integrator}); the state at t = {self.time:g} is kept. Reduce dt.")
            if done < 0:
                raise ModelError(
                    f"the state became non-finite while integrating from t = {self.time:g} to t = {t_end:g} "
                    f"(dt = {dt:g}, {self.integrator}); the state at t = {self.time:g} is kept. "
                    "Reduce dt or check the parameters for extreme values.")
        self.time = float(t_end)
        self._observed = None

    def _require_started(self) -> None:
        if not self.started:
            raise ModelError("the run has not started: call start() (FMI: exit initialization mode) first")

    # ------------------------------------------------------------------ observing
    def outputs(self) -> dict[str, float | int | bool]:
        """Observables at the current time (the FMU's outputs)."""
        return dict(self._observables())

    def output(self, name: str):
        return self._observables()[name]

    def _observation_raw(self):
        dt = self.drv[L.D_DT]
        grid_time = self.drv[L.D_T0] + self.cnt[L.C_STEP] * dt
        h = self.time - grid_time
        if h < GRID_TOLERANCE * dt:  # on the grid up to rounding of the master's time
            h = 0.0
        flags = self._scene_flags()
        if flags:
            return observe_scene(self.kind, flags, self.y, self.cnt, self.drv, self.prm, min(h, dt),
                                 self.energy_balance)
        if self.integrator == "event_driven":
            return observe_event_driven(self.y, self.cnt, self.drv, self.prm, min(h, dt), self.energy_balance)
        return observe(self.kind, INTEGRATORS[self.integrator], self.y, self.cnt, self.drv, self.prm, min(h, dt),
                       self.energy_balance)

    def _stored_energy(self, x, z, vx, vz, shear, e_normal, t):
        """Kinetic + drive spring + tangential spring + normal spring energy."""
        p = self.parameters
        stretch = x - p["V_d"] * t
        return (0.5 * p["m"] * (vx * vx + vz * vz) + 0.5 * p["k_d"] * stretch * stretch
                + 0.5 * p["k_t"] * shear * shear + e_normal)

    def _observables(self) -> dict:
        if self._observed is None:
            self._require_started()
            raw = self._observation_raw()
            (x, z, vx, vz, shear, pen, normal, cos_a, phi, slips, work, dissipated, e_normal, t) = raw[:14]
            in_contact = pen > 0.0
            p = self.parameters
            friction = -p["k_t"] * shear if in_contact else 0.0
            if len(raw) > 14:  # a reduced scene reports its own contact state and friction force
                in_contact, friction = bool(raw[14]), raw[15]
            residual = 0.0
            if self.energy_balance:
                stored = self._stored_energy(x, z, vx, vz, shear, e_normal, t)
                residual = stored - self.y[L.Y_E_START] - work + dissipated
            self._observed = {
                "x": x, "z": z, "vx": vx, "vz": vz,
                "friction_force": friction,
                "normal_force": normal,
                "contact": bool(in_contact),
                "slip_count": int(slips),
                "phi_integral": phi,
                "penetration": pen,
                "surface_z": z + pen / cos_a,
                "work_input": work,
                "energy_dissipated": dissipated,
                "energy_residual": residual,
            }
        return self._observed

    @property
    def grid_step(self) -> int:
        return int(self.cnt[L.C_STEP])

    # ------------------------------------------------------------------ state
    def get_state(self) -> dict:
        """Everything needed to continue the run bit for bit, as plain (JSON-able) values."""
        self._require_started()
        return {
            "model": self.model, "integrator": self.integrator, "initial_state": self.initial_state,
            "energy_balance": self.energy_balance,
            "scene": dict(self.scene), "frozen_released": self.frozen_released,
            "parameters": dict(self.parameters), "time": self.time,
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
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"not a valid block state: {exc}") from None
        if (y.shape, cnt.shape, drv.shape, prm.shape) != ((L.N_Y,), (L.N_CNT,), (L.N_DRV,), (L.N_PRM,)):
            raise ModelError("not a valid block state: array sizes differ from this model's")
        self.y, self.cnt, self.drv, self.prm = y, cnt, drv, prm
        self.parameters = dict(state["parameters"])
        self.integrator, self.initial_state = state["integrator"], state["initial_state"]
        self.energy_balance = bool(state.get("energy_balance", False))
        self.scene = {name: bool(state.get("scene", {}).get(name, False)) for name in SCENE_OPTIONS}
        self.frozen_released = bool(state.get("frozen_released", False))
        self.time = float(state["time"])
        self.started = True
        self._observed = None


def steady_orbit(m, k_n, gamma_n, weight, amplitude, omega, phase):
    """Offset and rate of the block relative to a plate moving as A sin(phase), on the
    steady in-contact orbit of m y'' + gamma_n y' + k_n y = -weight - m Z_p''."""
    response = m * amplitude * omega**2 / complex(k_n - m * omega**2, gamma_n * omega)
    rotating = response * cmath.exp(1j * phase)
    return -weight / k_n + rotating.imag, (1j * omega * rotating).imag


def detachment_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07):
    """Smallest amplitude at which the steady in-contact orbit of model A reaches zero
    penetration: A_c = (g / omega^2) |k_n - m omega^2 + i gamma_n omega| / k_n.

    It tends to the paper's A = g / omega^2 for omega << sqrt(k_n / m)."""
    omega = np.asarray(omega, dtype=float)
    return g / omega**2 * np.abs(k_n - m * omega**2 + 1j * gamma_n * omega) / k_n

