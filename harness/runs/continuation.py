"""Quasi-static continuation: ramp a drive parameter up then down on one live run.

::

    from .continuation import Ramp, continuation
    ramp = Ramp("omega", (0.3, 0.5, 0.7, 0.9))           # up, then back down
    ds = continuation(PointSettings(run=RunSettings.for_model("A", parameters={"A": 2.0},
                                                              horizon=12_000)), ramp)
    ds.phi.where(ds.direction == "up")                      # the up branch

The block is started once, with the point's initial condition, at the ramp's first
value.  Each ramp step then sets the tunable parameter (``A`` or ``omega``) on the
running FMU instance -- the drive's phase stays continuous -- and advances by the
run's ``horizon``; the step's observables are measured on that stretch with the
point's :class:`ObservableSettings` (its ``transient`` is the settling time after the
change).  The state (position, velocity, friction history, flight) is carried from
step to step, which is what makes a hysteresis loop visible: where two regimes
coexist, the ramp stays on the branch it came from while a fresh start picks the one
its initial condition leads to.  :func:`fresh_starts` evaluates the same values from
fresh starts for comparison.

Result: a Dataset over ``step`` with coordinates ``direction`` ("up"/"down") and the
ramped parameter's value, the observables of :mod:`harness.runs.observables` per step,
and the settings as attributes.  ``keep_states=True`` adds each step's final FMU state
(serialized, restorable with :meth:`FmuInstance.set_state`) as ``fmu_state``.
"""
from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from harness.cosim.fmu import InstancePool
from .observables import MEASURED, PHI_STICK_SLIP, observe
from .run import POINT_OUTPUTS, Recorder, open_instance, resolved_parameters, run_attributes, run_point, \
    trajectory_dataset
from .settings import PointSettings, canonical_json, to_jsonable


@dataclass(frozen=True)
class Ramp:
    """A ramp of one tunable parameter: ``values`` up, then (round_trip) back down."""

    parameter: str
    values: tuple[float, ...]
    round_trip: bool = True

    def __post_init__(self):
        object.__setattr__(self, "values", tuple(float(v) for v in self.values))
        if len(self.values) < 1 or not all(math.isfinite(v) for v in self.values):
            raise ValueError("a ramp needs at least one finite value")

    @classmethod
    def linear(cls, parameter: str, start: float, stop: float, steps: int, round_trip: bool = True) -> "Ramp":
        return cls(parameter, tuple(np.linspace(start, stop, steps)), round_trip)

    def schedule(self) -> list[tuple[str, float]]:
        """(direction, value) per step; the turning value is not repeated."""
        steps = [("up", v) for v in self.values]
        if self.round_trip:
            steps += [("down", v) for v in reversed(self.values[:-1])]
        return steps


def continuation(point: PointSettings, ramp: Ramp, pool: InstancePool | None = None, progress: bool = False,
                 keep_states: bool = False) -> xr.Dataset:
    """Run the ramp on one live instance; observables per step (see module doc)."""
    run = point.run
    schedule = ramp.schedule()
    first_run = run.with_parameters({ramp.parameter: schedule[0][1]})
    with open_instance(first_run, pool, None) as instance:
        if ramp.parameter not in instance.interface.tunable:
            raise ValueError(f"{ramp.parameter!r} is not a tunable parameter of {instance.interface.model_name}; "
                             f"tunable: {sorted(instance.interface.tunable)}")
        values = resolved_parameters(instance, first_run)
        instance.start(values, run.start_time)
        recorder = Recorder(instance, POINT_OUTPUTS, run.start_time, run.output_interval)
        rows_per_step = run.n_outputs
        records, states = [], []
        bar = _bar(progress, len(schedule), ramp.parameter)
        try:
            for number, (direction, value) in enumerate(schedule):
                if number > 0:
                    instance.set({ramp.parameter: value})
                step_start = recorder.time
                first_row = np.array([recorder.sample()])
                rows = recorder.advance(rows_per_step)
                times = step_start + run.output_interval * np.arange(rows_per_step + 1)
                step_values = {**values, ramp.parameter: value}
                segment = trajectory_dataset(times, np.vstack([first_row, rows]), POINT_OUTPUTS, instance,
                                             run_attributes(instance, first_run, step_values))
                records.append(observe(segment, point.observe).as_dict())
                if keep_states:
                    states.append(instance.get_state())
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        sha256 = instance.sha256
        model_name = instance.interface.model_name
    data = _columns(records, ("step",))
    if keep_states:
        data["fmu_state"] = ("step", np.array(states, dtype=object))
    coords = {"step": np.arange(len(schedule)),
              "direction": ("step", np.array([d for d, _ in schedule])),
              ramp.parameter: ("step", np.array([v for _, v in schedule]))}
    attrs = _attributes(point, ramp, values, sha256, model_name, "continuation")
    return xr.Dataset(data, coords=coords, attrs=attrs)


def fresh_starts(point: PointSettings, ramp: Ramp, pool: InstancePool | None = None) -> xr.Dataset:
    """The ramp's distinct values, each from a fresh start with the point's initial
    condition: the reference a continuation is compared with.  Over ``step`` like
    :func:`continuation` with direction "fresh"."""
    records = []
    with (InstancePool() if pool is None else _borrowed(pool)) as shared:
        for value in ramp.values:
            settings = dataclasses.replace(point, run=point.run.with_parameters({ramp.parameter: value}))
            records.append(run_point(settings, shared).as_dict())
        instance = shared.get(point.run.fmu)
        values = resolved_parameters(instance, point.run)
        sha256, model_name = instance.sha256, instance.interface.model_name
    data = _columns(records, ("step",))
    coords = {"step": np.arange(len(ramp.values)), "direction": ("step", np.array(["fresh"] * len(ramp.values))),
              ramp.parameter: ("step", np.array(ramp.values))}
    return xr.Dataset(data, coords=coords, attrs=_attributes(point, ramp, values, sha256, model_name, "fresh_starts"))


class _borrowed:
    """A pool used but not closed (it belongs to the caller)."""

    def __init__(self, pool):
        self.pool = pool

    def __enter__(self):
        return self.pool

    def __exit__(self, *exc):
        return False


def _columns(records: list[dict], dims: tuple[str, ...]) -> dict:
    data = {}
    for name in MEASURED:
        column = [r[name] for r in records]
        data[name] = (dims, np.array(column, dtype=str) if isinstance(column[0], str) else np.array(column))
    data["stick_slip"] = (dims, np.array([r["regime"] in PHI_STICK_SLIP for r in records]))
    return data


def _attributes(point: PointSettings, ramp: Ramp, values: dict, sha256: str, model_name: str, kind: str) -> dict:
    attrs = {name: int(value) if isinstance(value, bool) else value
             for name, value in values.items() if name != ramp.parameter}
    observe_settings = point.observe
    attrs.update({
        "kind": kind, "ramp_parameter": ramp.parameter, "ramp": json.dumps(to_jsonable(ramp)),
        "step_duration": point.run.horizon, "output_interval": point.run.output_interval,
        "fmu_path": point.run.fmu, "fmu_sha256": sha256, "model_name": model_name,
        # values: the parameters as the ramp started (its first value included).
        "integrator_name": point.run.integration.for_values(values),
        "initial_condition": point.run.initial.initial_state,
        "transient": observe_settings.transient,
        "window": "rest of step" if observe_settings.window is None else observe_settings.window,
        "phi_threshold": observe_settings.phi_threshold, "point_settings": canonical_json(point),
    })
    return attrs


def _bar(enabled: bool, total: int, parameter: str):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=f"ramp {parameter}", unit="step")
