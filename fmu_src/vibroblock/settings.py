"""Checked settings of one block: model variant, parameters, integrator and its options,
initial state, readings of the paper (formulation, Coulomb bound, flight), energy balance
and scene reductions.

Every value is checked when it is set (``ModelError`` says which value and why), and the
settings are checked together (``check``) before a run starts; once a run has started
only the tunable parameters may change.
"""
from __future__ import annotations

import math

import numpy as np

from .integrators import INTEGRATORS, REDUCED_SCENE, Integrator, integrator as integrator_record
from .models import offered_by, variant
from .laws import AXES, LAWS
from .parameters import DEFAULT_INTEGRATOR, INITIAL_STATES, INTEGRATOR_OPTIONS, SCENE_OPTIONS, reading_names
from .readings import choices, encode
from .scenes import COULOMB, FROZEN, RIGID

CHOICES = choices()  # the readings of the paper and the laws: Integer choices fixed before a run


class ModelError(ValueError):
    """A value or request the model cannot accept; the message says which and why."""


def _unsupported(record: Integrator, model: str) -> str:
    models = offered_by(record.models)
    return (f"the {record.name} integrator is available only for model{'s' if len(models) > 1 else ''} "
            f"{', '.join(models)}, not model {model} ({record.summary}); choose another integrator")


class Settings:
    """What a run is made of, each value checked as it is set."""

    def __init__(self, model: str = "A", integrator: str | int = "symplectic_euler", initial_state: int = 0,
                 energy_balance: bool = False, **parameters):
        try:
            self.variant = variant(model)
        except KeyError as exc:
            raise ModelError(exc.args[0]) from None
        self.model = model
        self._specs = {p.name: p for p in self.variant.parameters}
        self.parameters = {name: spec.default for name, spec in self._specs.items()}
        self.locked = False  # set when the run starts: then only tunable parameters change
        self.integrator = "symplectic_euler"
        self.initial_state = 0
        self.energy_balance = False
        self.scene = {name: False for name in SCENE_OPTIONS}
        self.readings = {name: 0 for name in CHOICES}  # the readings and the laws
        self.options = {name: default for name, (_, default, _) in INTEGRATOR_OPTIONS.items()}
        self.set_integrator(integrator)
        self.set_initial_state(initial_state)
        self.set_energy_balance(energy_balance)
        for name, value in parameters.items():  # scene options, readings and options come as keywords
            if name in SCENE_OPTIONS:
                self.set_scene_option(name, value)
            elif name in INTEGRATOR_OPTIONS:
                self.set_integrator_option(name, value)
            elif name in CHOICES:
                self.set_reading(name, value)
            else:
                self.set_parameter(name, value)

    # ------------------------------------------------------------------ one value each
    def set_parameter(self, name: str, value: float) -> None:
        spec = self._specs.get(name)
        if spec is None:
            raise ModelError(f"model {self.model} has no parameter {name!r}; it has {sorted(self._specs)}")
        problem = spec.problem(value)
        if problem:
            raise ModelError(problem)
        if self.locked and not spec.tunable:
            raise ModelError(f"{name} is fixed once the run has started; only A and omega can change during a run")
        self.parameters[name] = float(value)

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
        record = integrator_record(integrator)
        if not record.supports(self.model):
            raise ModelError(_unsupported(record, self.model))
        self._require_unlocked("integrator")
        self.integrator = integrator

    def set_energy_balance(self, track: bool) -> None:
        """Account work, dissipation and stored energy during the run (costs ~1/3 more per step)."""
        self._require_unlocked("energy_balance")
        self.energy_balance = bool(track)

    def set_scene_option(self, name: str, enabled: bool) -> None:
        """Drop physics the scene does not need (``parameters.SCENE_OPTIONS``)."""
        if name not in SCENE_OPTIONS:
            raise ModelError(f"unknown scene option {name!r}; choose one of {sorted(SCENE_OPTIONS)}")
        models, _ = SCENE_OPTIONS[name]
        offered = offered_by(models)
        if enabled and self.model not in offered:
            raise ModelError(f"{name} is available for models {', '.join(offered)}, not model {self.model}: "
                             "on a corrugated plate the vertical motion follows the surface (use rigid_contact)")
        self._require_unlocked(name)
        self.scene[name] = bool(enabled)

    def set_integrator_option(self, name: str, enabled: bool) -> None:
        """Set an option of the integrator (``parameters.INTEGRATOR_OPTIONS``); a variant that
        does not offer it keeps its default."""
        if name not in INTEGRATOR_OPTIONS:
            raise ModelError(f"unknown integrator option {name!r}; choose one of {sorted(INTEGRATOR_OPTIONS)}")
        models, default, _ = INTEGRATOR_OPTIONS[name]
        if not isinstance(enabled, (bool, np.bool_, int, np.integer)):
            raise ModelError(f"{name} = {enabled!r} is not admissible: it must be true or false")
        offered = offered_by(models)
        if bool(enabled) != default and self.model not in offered:
            raise ModelError(f"{name} is an option of model{'s' if len(offered) > 1 else ''} {', '.join(offered)} "
                             f"only, not of model {self.model} ({INTEGRATOR_OPTIONS[name][2]})")
        self._require_unlocked(name)
        self.options[name] = bool(enabled)

    def set_reading(self, name: str, value: int | str) -> None:
        """Choose a reading of the paper or a law (``readings.CHOICES``: formulation,
        coulomb_normal, flight, contact, ...), by its Integer value or its name."""
        if name not in CHOICES:
            raise ModelError(f"unknown reading or law {name!r}; choose one of {sorted(CHOICES)}")
        models, _ = CHOICES[name]
        names = reading_names(name, CHOICES)
        if isinstance(value, str) and value in names.values():
            value = {text: code for code, text in names.items()}[value]
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or int(value) not in names:
            raise ModelError(f"{name} = {value!r} is not admissible: it must be one of "
                             f"{', '.join(f'{code} ({text})' for code, text in names.items())}")
        offered = offered_by(models)
        if value and self.model not in offered:
            raise ModelError(f"{name} = {value} ({names[int(value)]}) is available for models {', '.join(offered)}, "
                             f"not model {self.model}; model {self.model} has {name} = 0 ({names[0]}) only")
        self._require_unlocked(name)
        self.readings[name] = int(value)

    @property
    def kind(self) -> int:
        """The kernels' ``kind``: the variant, its readings and its laws (``vibroblock.readings``)."""
        return encode(self.variant.kind, self.readings)

    @property
    def tangent_frame(self) -> bool:
        return self.readings["formulation"] == 1

    def set_initial_state(self, mode: int) -> None:
        if mode not in INITIAL_STATES:
            raise ModelError(f"initial_state = {mode!r} is not one of {INITIAL_STATES}")
        self._require_unlocked("initial_state")
        self.initial_state = int(mode)

    def _require_unlocked(self, what: str) -> None:
        if self.locked:
            raise ModelError(f"{what} is fixed once the run has started")

    # ------------------------------------------------------------------ together
    def scene_flags(self, frozen_released: bool = False) -> int:
        """The reductions in effect (0: the full model); ``frozen_released`` once the
        frozen_vertical guard has handed over."""
        return ((RIGID if self.scene["rigid_contact"] else 0)
                | (FROZEN if self.scene["frozen_vertical"] and not frozen_released else 0)
                | (COULOMB if self.scene["coulomb_friction"] else 0))

    def kernel(self, frozen_released: bool = False) -> Integrator:
        """The integrator that runs now: the reduced scene's scheme while reductions are in
        effect, else the chosen integrator, or the exact flows it hands over to (option
        exact_flows)."""
        if self.scene_flags(frozen_released):
            return REDUCED_SCENE
        record = integrator_record(self.integrator)
        exact = record.hand_over(self.model, self.readings, self.parameters) if self.options["exact_flows"] else None
        return exact or record

    def check(self, frozen_released: bool = False) -> None:
        """Refuse settings that cannot run together (e.g. a dt the integrator cannot resolve)."""
        self._check_readings()
        for axis in AXES.values():  # a law that states what its parameters must satisfy, and where it cannot run
            chosen = LAWS[axis.name][self.readings.get(axis.parameter, 0)]
            check = getattr(chosen.module, "check", None)
            problem = check(self.parameters) if check else None
            if problem:
                raise ModelError(problem)
            for (reading, value), why in getattr(chosen.module, "REFUSED_READINGS", {}).items():
                if self.readings.get(reading) == value:
                    raise ModelError(f"{axis.parameter} = {chosen.id} ({chosen.name}) cannot run with {reading} = "
                                     f"{value}: {why}")
        if self.scene_flags(frozen_released):
            self._check_scene_step()
            return
        record = integrator_record(self.integrator)
        if not record.supports(self.model):
            raise ModelError(_unsupported(record, self.model))
        problem = record.unsupported_reading(self.readings)
        if problem:
            raise ModelError(f"the {record.name} integrator {problem}; choose symplectic_euler or rk4")
        for axis in AXES.values():  # a law that states which integrators cannot run it
            if axis.parameter in self.readings:
                chosen = LAWS[axis.name][self.readings[axis.parameter]]
                if record.name in chosen.refused_by:
                    raise ModelError(f"the {record.name} integrator cannot run {axis.parameter} = "
                                     f"{chosen.id} ({chosen.name}): {chosen.refused_by[record.name]}")
        problem = record.check_step(self.parameters, self.model, record.name)
        if problem:
            raise ModelError(problem)

    def _check_readings(self) -> None:
        r = self.readings
        if r["formulation"] == 1 and r["flight"] == 1:
            raise ModelError(
                "flight = 1 (free) cannot be combined with formulation = 1 (tangent_frame): the tangent frame has "
                "no position in the plane, only the foot's abscissa x and the normal coordinate zeta, so a free "
                "flight and its landing on the vibrating curved plate are not defined in it (docs/physics.md, "
                "Sec. 6); its flight is the printed equations with Theta = 0 (flight = 0)")
        if any(r.values()) and any(self.scene.values()):
            active = [name for name, on in self.scene.items() if on]
            readings = [f"{name} = {value}" for name, value in r.items() if value]
            raise ModelError(f"the scene reductions ({', '.join(active)}) run the default reading only "
                             f"(formulation, coulomb_normal and flight 0), not {', '.join(readings)}; "
                             "switch the reduction off or the reading back to 0")

    def _check_scene_step(self) -> None:
        """Reduced scenes run their own first-order scheme (vibroblock.scenes): it needs
        only the springs and dashpots the scene keeps resolved, as symplectic Euler does."""
        if self.scene["rigid_contact"] and self.scene["frozen_vertical"]:
            raise ModelError("rigid_contact and frozen_vertical exclude each other (a rigid contact has no "
                             "compliant orbit to freeze); choose one")
        # The FMUs' default integrator is accepted too: a master that did not choose one must
        # not be refused, and the reduced scene's kernel runs either way.
        if ((self.scene["rigid_contact"] or self.scene["coulomb_friction"])
                and self.integrator not in ("symplectic_euler", DEFAULT_INTEGRATOR)):
            raise ModelError(f"integrator = {self.integrator} cannot run with rigid_contact or coulomb_friction: "
                             f"those run on their own first-order kernel; set integrator = symplectic_euler (0) or "
                             f"leave the default ({DEFAULT_INTEGRATOR})")
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

    # ------------------------------------------------------------------ as plain values
    def to_dict(self) -> dict:
        return {"model": self.model, "integrator": self.integrator, "initial_state": self.initial_state,
                "energy_balance": self.energy_balance, "scene": dict(self.scene),
                "readings": dict(self.readings), "options": dict(self.options), "parameters": dict(self.parameters)}

    def check_hand_over(self, time: float) -> None:
        """The full model the frozen_vertical guard hands over to at ``time`` can run."""
        try:
            self.check(True)
        except ModelError as exc:
            raise ModelError(f"the frozen_vertical guard handed over to the full model at t = {time:g} (the "
                             f"block would detach), which cannot run at this dt: {exc}") from None

    @classmethod
    def from_dict(cls, data: dict, model: str | None = None) -> "Settings":
        """The settings saved in ``data`` (``to_dict``), which must be of ``model`` if given."""
        if model is not None and data.get("model") != model:
            raise ModelError(f"state of model {data.get('model')!r} cannot be set on a model {model} block")
        try:
            return cls(data["model"], data["integrator"], data["initial_state"], data["energy_balance"],
                       **data["parameters"], **data.get("scene", {}), **data.get("readings", {}),
                       **data.get("options", {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"not a valid block state: {exc}") from None
