"""Settings of runs, observables and sweeps as frozen dataclasses.

A run is fully described by a :class:`RunSettings`; what is measured on it by an
:class:`ObservableSettings`; a sweep point by a :class:`PointSettings` (both).  All are
immutable, hashable, picklable (they travel to Dask workers) and convert to plain JSON
(:func:`to_jsonable`) for stores and Dataset attributes.  Change a copy with
:func:`dataclasses.replace` or the ``with_*`` helpers.

Units are the paper's: lengths in delta_0 = m g / k_n, times in tau_0 = sqrt(m / k_n).
"""
from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from harness.cosim.fmu import REPO_ROOT
from vibroblock.parameters import DEFAULT_INTEGRATOR

# Parameter sets a run can start from.  "scaled" keeps model A quasi-static while making a
# stick-slip cycle affordable: stick ~5.2e3 tau_0, slip ~50 delta_0 (see docs/claims.md, Conventions).
PRESETS: dict[str, dict[str, float]] = {
    "paper": {},
    "scaled": {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3},
}

# Integrators and initial states are named here as the FMU names them: the FMU's model
# description lists its choices (``FmuInterface.choices``), and the name is checked and
# turned into the FMU's value when the run starts.

# FMU parameters owned by a settings object other than ``RunSettings.parameters``:
# each value has exactly one place to be given.
RESERVED_PARAMETERS = frozenset({"dt", "integrator", "initial_state", "x_start", "z_start", "vx_start", "vz_start"})


def default_fmu(model: str) -> str:
    """Path of the built FMU of model ``model`` ("A", "B" or "C") in this repository."""
    return str(REPO_ROOT / "build" / "fmus" / f"Block{model.upper()}.fmu")


class Parameters(Mapping):
    """An immutable, hashable name -> value mapping (model parameters of a run).

    Values are floats, except booleans, which stay bool (the FMUs' Boolean parameters,
    e.g. the scene options).  Integer parameters (e.g. ``formulation``) are held as
    floats like every number and reach the FMU as int, checked to be whole
    (``harness.cosim.fmu.FmuInterface.typed``)."""

    __slots__ = ("_items",)

    def __init__(self, values: Mapping | None = None, **more: float):
        merged = dict(values or {}, **more)
        items = []
        for name, value in merged.items():
            if not isinstance(name, str) or not name:
                raise TypeError(f"parameter names are non-empty strings, not {name!r}")
            if isinstance(value, (bool, np.bool_)):
                items.append((name, bool(value)))
                continue
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise TypeError(f"parameter {name} = {value!r} is not a number or a bool") from None
            items.append((name, number))
        self._items = tuple(sorted(items))

    def __getitem__(self, name):
        for key, value in self._items:
            if key == name:
                return value
        raise KeyError(name)

    def __iter__(self):
        return (key for key, _ in self._items)

    def __len__(self):
        return len(self._items)

    def __hash__(self):
        return hash(self._items)

    def __eq__(self, other):
        if isinstance(other, Parameters):
            return self._items == other._items
        return isinstance(other, Mapping) and dict(self._items) == dict(other)

    def __repr__(self):
        return f"Parameters({dict(self._items)!r})"

    def __reduce__(self):
        return (Parameters, (dict(self._items),))

    def updated(self, values: Mapping | None = None, **more: float) -> "Parameters":
        return Parameters({**dict(self._items), **dict(values or {}), **more})


# What an integration's switch can name besides the FMU's parameters: name -> (the
# parameters it is computed from, how).  The plate's peak speed A omega measures how hard
# the block is struck at each landing, which is what an error-controlled integrator pays
# for (README, "Choosing speed or accuracy").
SWITCH_QUANTITIES = {"plate_speed": (("A", "omega"), lambda amplitude, omega: amplitude * omega)}


@dataclass(frozen=True)
class Integration:
    """The FMU's internal integrator and step, optionally switched by parameter values.

    With ``switch`` (pairs of name and limit), a run in which any of those values exceeds
    its limit uses ``integrator_above`` instead of ``integrator``.  A name is a parameter
    or one of :data:`SWITCH_QUANTITIES` (e.g. ``plate_speed``, A omega).  No
    integrator is the cheapest everywhere (README, "Choosing speed or accuracy":
    ``adaptive`` spends its steps on the plate's cycles and on the surface's crests, the
    fixed-step schemes on the contact's period), so a sweep can run each point with the
    cheaper one.  The choice is made per run (:meth:`RunSettings.integrator_for`) and
    recorded with its results.

    The default integrator is the FMUs' own, ``adaptive`` (``vibroblock.parameters.DEFAULT_INTEGRATOR``:
    event_driven's exact flows on model A, error-controlled steps on B and C); the paper's
    scheme is ``Integration("symplectic_euler")``.
    """

    integrator: str = DEFAULT_INTEGRATOR
    dt: float = 4e-4
    switch: tuple = ()
    integrator_above: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "switch", tuple((str(name), float(limit)) for name, limit in self.switch))
        for name in (self.integrator, self.integrator_above or "unset"):
            if not (isinstance(name, str) and name.isidentifier()):
                raise ValueError(f"integrator {name!r} must be a name, e.g. 'symplectic_euler' (the FMU's "
                                 "description of its integrator parameter lists them)")
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"dt = {self.dt!r} must be a finite number > 0")
        if bool(self.switch) != (self.integrator_above is not None):
            raise ValueError("switch and integrator_above are given together (or neither)")
        for name, limit in self.switch:
            if not math.isfinite(limit):
                raise ValueError(f"the switch's limit on {name} = {limit!r} must be finite")

    def for_values(self, values: Mapping) -> str:
        """The integrator of a run with these parameter values."""
        needed = {name: SWITCH_QUANTITIES[name][0] if name in SWITCH_QUANTITIES else (name,)
                  for name, _ in self.switch}
        missing = [name for name, inputs in needed.items() if any(i not in values for i in inputs)]
        if missing:
            raise ValueError(f"an integration switched by {', '.join(missing)} needs the run's value of "
                             + ", ".join(sorted({i for n in missing for i in needed[n]})))

        def value(name):
            if name in SWITCH_QUANTITIES:
                inputs, function = SWITCH_QUANTITIES[name]
                return function(*(values[i] for i in inputs))
            return values[name]

        above = any(value(name) > limit for name, limit in self.switch)
        return self.integrator_above if above else self.integrator

    def describe(self) -> str:
        if not self.switch:
            return self.integrator
        limits = " and ".join(f"{name} <= {limit:g}" for name, limit in self.switch)
        return f"{self.integrator} at {limits}, {self.integrator_above} otherwise"


@dataclass(frozen=True)
class InitialCondition:
    """How the block starts.

    The fields are the FMU's parameters of the same names.  ``initial_state``:
    ``steady_orbit`` puts the block on the steady in-contact orbit of the harmonic drive
    (the gentle start for vibrated runs); ``equilibrium`` at rest at the rest penetration
    under the plate's initial position (an impact if the plate moves); ``given`` at
    (x_start, z_start, vx_start, vz_start).  x_start is used by every initial state,
    vx_start and vz_start by ``equilibrium`` and ``given``.
    """

    initial_state: str = "steady_orbit"
    x_start: float = 0.0
    z_start: float = 0.0
    vx_start: float = 0.0
    vz_start: float = 0.0

    def __post_init__(self):
        if not (isinstance(self.initial_state, str) and self.initial_state.isidentifier()):
            raise ValueError(f"initial_state {self.initial_state!r} must be a name, e.g. 'steady_orbit' (the FMU's "
                             "description of its initial_state parameter lists them)")

    def fmu_values(self) -> dict[str, float | str]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class RunSettings:
    """One run: FMU, parameters, horizon, output interval, integrator, initial condition.

    ``parameters`` holds model parameters only (not dt, the integrator or the initial
    state, which have their own fields); parameters not given keep the FMU's defaults.
    The run covers [start_time, start_time + horizon] and records the outputs every
    ``output_interval``, which is also the communication step.
    """

    fmu: str = field(default_factory=lambda: default_fmu("A"))
    parameters: Parameters = field(default_factory=Parameters)
    horizon: float = 20_000.0
    output_interval: float = 1.0
    integration: Integration = field(default_factory=Integration)
    initial: InitialCondition = field(default_factory=InitialCondition)
    start_time: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "fmu", str(self.fmu))
        if not isinstance(self.parameters, Parameters):
            object.__setattr__(self, "parameters", Parameters(self.parameters))
        reserved = sorted(RESERVED_PARAMETERS & set(self.parameters))
        if reserved:
            owners = {name: "Integration(dt=...)" if name == "dt" else "Integration(integrator=...)"
                      if name == "integrator" else f"InitialCondition({name}=...)" for name in reserved}
            raise ValueError("; ".join(f"{name} = {self.parameters[name]:g} is not a model parameter: give it as "
                                       f"{owner}" for name, owner in owners.items()))
        for name in ("horizon", "output_interval"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r} must be a finite number > 0")
        if not math.isfinite(self.start_time):
            raise ValueError(f"start_time = {self.start_time!r} must be finite")
        steps = self.horizon / self.output_interval
        if abs(steps - round(steps)) > 1e-9 * max(1.0, steps):
            raise ValueError(f"horizon {self.horizon!r} is not a whole number of output intervals "
                             f"{self.output_interval!r}")

    @property
    def n_outputs(self) -> int:
        """Number of communication steps (the record has one more row: the start)."""
        return int(round(self.horizon / self.output_interval))

    def integrator_for(self, defaults: Mapping | None = None) -> str:
        """The integrator this run uses: its integration's choice at its parameter values
        (a value it does not set is the FMU's default, from ``defaults``)."""
        return self.integration.for_values({**dict(defaults or {}), **dict(self.parameters)})

    def fmu_values(self, defaults: Mapping | None = None) -> dict[str, float | int]:
        """Values to set on the FMU besides its ``defaults``: parameters, integration, start."""
        return {**dict(self.parameters), "dt": self.integration.dt,
                "integrator": self.integrator_for(defaults), **self.initial.fmu_values()}

    def with_parameters(self, values: Mapping | None = None, **more: float) -> "RunSettings":
        return dataclasses.replace(self, parameters=self.parameters.updated(values, **more))

    @classmethod
    def for_model(cls, model: str = "A", preset: str | None = None, **fields) -> "RunSettings":
        """Settings for one of the repository's FMUs starting from a named parameter preset
        (default: ``scaled`` for model A, the FMU's own values -- ``paper`` -- for B and C)."""
        preset = preset or ("scaled" if model.upper() == "A" else "paper")
        if preset not in PRESETS:
            raise ValueError(f"preset {preset!r} is not one of {sorted(PRESETS)}")
        parameters = Parameters(PRESETS[preset]).updated(fields.pop("parameters", {}))
        return cls(fmu=fields.pop("fmu", default_fmu(model)), parameters=parameters, **fields)


@dataclass(frozen=True)
class ObservableSettings:
    """What is measured on a run and how; reported with every result.

    * The measuring window is [t_end - window, t_end] (``window`` None: everything after
      the transient); its start is never earlier than start + ``transient``.
    * Regime: stick-slip when phi > ``phi_threshold`` and the block rests (sticks) part of
      the window, hopping when phi is large but the block neither rests nor stays in
      contact, else sliding (or "stuck" when the block neither slipped nor kept up with
      the drive: the window is too short); the full rules are in
      :mod:`harness.runs.observables`.  A block
      that sticks throughout has phi = 1; one moving with the drive phi = 0; a stick-slip
      cycle adds its slips' share of (vx - V_d)^2 (about 170 for model A's scaled set).
    * Slips (see :func:`harness.runs.observables.slip_events`): a slip is a run of samples with
      vx > ``slip_release`` * V_d that reaches vx > ``slip_onset`` * V_d; runs separated by
      at most ``merge_gap`` are merged; a slip counts when it advanced x by at least
      ``slip_min_length`` (None: ``slip_min_fraction`` of mu_s N0 / k_d, the paper's slip
      length, with N0 = m g or P_l).  This discards the small back-and-forth re-slips of
      the tangential ringing after each slip.
    """

    transient: float = 4000.0
    window: float | None = None
    phi_threshold: float = 10.0
    slip_onset: float = 10.0
    slip_release: float = 1.0
    slip_min_length: float | None = None
    slip_min_fraction: float = 0.25
    merge_gap: float = 0.0

    def __post_init__(self):
        if not (math.isfinite(self.transient) and self.transient >= 0):
            raise ValueError(f"transient = {self.transient!r} must be >= 0")
        if self.window is not None and not (math.isfinite(self.window) and self.window > 0):
            raise ValueError(f"window = {self.window!r} must be > 0 or None")
        if self.slip_release > self.slip_onset:
            raise ValueError("slip_release must not exceed slip_onset (hysteresis)")


@dataclass(frozen=True)
class PointSettings:
    """A run and what to measure on it: one point of a sweep."""

    run: RunSettings = field(default_factory=RunSettings)
    observe: ObservableSettings = field(default_factory=ObservableSettings)


def to_jsonable(value):
    """Plain JSON-able form of settings objects (dataclasses, Parameters, paths)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def canonical_json(value) -> str:
    """One text per value (sorted keys, exact float repr): the input of store keys."""
    return json.dumps(to_jsonable(value), sort_keys=True, separators=(",", ":"), allow_nan=True)


def run_settings_from_json(data: Mapping) -> RunSettings:
    return RunSettings(fmu=data["fmu"], parameters=Parameters(data["parameters"]), horizon=data["horizon"],
                       output_interval=data["output_interval"], integration=Integration(**data["integration"]),
                       initial=InitialCondition(**data["initial"]), start_time=data["start_time"])


def point_settings_from_json(data: Mapping) -> PointSettings:
    return PointSettings(run=run_settings_from_json(data["run"]), observe=ObservableSettings(**data["observe"]))
