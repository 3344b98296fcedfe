"""Runs: an FMU with its settings -> an xarray Dataset of trajectories.

::

    from .run import simulate
    from .settings import RunSettings

    settings = RunSettings.for_model("A", parameters={"A": 0.5, "omega": 0.8}, horizon=20_000)
    ds = simulate(settings)          # ds.x, ds.vx, ds.contact, ... over ds.time

The Dataset holds every output of the FMU over a ``time`` coordinate (start included),
and as attributes: every FMU parameter's value as used (defaults filled in), the FMU
path, its sha256 and model name, the integrator, dt, the initial condition, the
horizon and output interval, and the whole :class:`RunSettings` as JSON
(``run_settings``).  Times are ``start + k * output_interval``, never accumulated.
"""
from __future__ import annotations

import contextlib
import json
from typing import Callable

import numpy as np
import xarray as xr

from harness.cosim.fmu import FmuError, FmuInstance, InstancePool
from .observables import Observables, observe
from .settings import PointSettings, RunSettings, canonical_json

# What the observables read; recording only these keeps a sweep point cheap.
POINT_OUTPUTS = ("x", "vx", "phi_integral", "contact", "coulomb_resets")
# Rows between progress-bar updates (a bar update costs more than an FMU step).
PROGRESS_CHUNK = 500


def resolved_parameters(instance: FmuInstance, settings: RunSettings) -> dict[str, float | int]:
    """All FMU parameter values of a run: the FMU's defaults overridden by the settings."""
    instance.interface.require(settings.parameters, "parameter")
    try:
        defaults = instance.interface.defaults()
        return {**defaults, **instance.interface.typed(settings.fmu_values(defaults))}
    except ValueError as exc:
        raise ValueError(f"{settings.fmu}: {exc}") from None


@contextlib.contextmanager
def open_instance(settings: RunSettings, pool: InstancePool | None, expect_sha256: str | None = None):
    """The pool's instance of the run's FMU, or (no pool) a fresh one freed afterwards."""
    if pool is not None:
        yield pool.get(settings.fmu, expect_sha256)
        return
    with FmuInstance(settings.fmu) as instance:
        if expect_sha256 is not None and instance.sha256 != expect_sha256:
            raise FmuError("load", None, [], f"{settings.fmu} has sha256 {instance.sha256}, expected {expect_sha256}")
        yield instance


class Recorder:
    """Advances a started instance on the grid start + k h and keeps the outputs."""

    def __init__(self, instance: FmuInstance, outputs: tuple[str, ...], start_time: float, step: float):
        self.instance, self.outputs = instance, outputs
        self.start_time, self.step = start_time, step
        self.read = instance.reader(outputs)
        self.k = 0  # communication steps taken since start_time

    @property
    def time(self) -> float:
        return self.start_time + self.k * self.step

    def sample(self) -> list[float]:
        return self.read()

    def advance(self, n_steps: int, keep: bool = True, progress: Callable[[int], None] | None = None) -> np.ndarray:
        """Take n_steps communication steps; the outputs after each (rows) if ``keep``."""
        rows = np.empty((n_steps if keep else 0, len(self.outputs)))
        step, start, do_step, read = self.step, self.start_time, self.instance.do_step, self.read
        for i in range(n_steps):
            do_step(start + self.k * step, step)
            self.k += 1
            if keep:
                rows[i] = read()
            if progress is not None and (i + 1) % PROGRESS_CHUNK == 0:
                progress(PROGRESS_CHUNK)
        if progress is not None and n_steps % PROGRESS_CHUNK:
            progress(n_steps % PROGRESS_CHUNK)
        return rows


def trajectory_dataset(times: np.ndarray, rows: np.ndarray, outputs: tuple[str, ...], instance: FmuInstance,
                       attrs: dict) -> xr.Dataset:
    """Rows of outputs over times as a Dataset, each variable with the FMU's type."""
    data = {}
    for j, name in enumerate(outputs):
        kind = instance.interface.variables[name].type
        column = rows[:, j]
        if kind == "Boolean":
            column = column != 0.0
        elif kind == "Integer":
            column = column.astype(np.int64)
        data[name] = ("time", column)
    return xr.Dataset(data, coords={"time": ("time", times)}, attrs=attrs)


def run_attributes(instance: FmuInstance, settings: RunSettings, values: dict) -> dict:
    """Attributes describing a run completely (NetCDF-safe scalars and strings)."""
    # NetCDF has no boolean attributes: flags are stored as 0/1.
    # Switches given by name are stored as the FMU's values (their names as *_name).
    integrator = settings.integration.for_values(values)  # values: every parameter as used
    values = {name: instance.interface.encode(name, value) for name, value in values.items()}
    attrs = {name: int(value) if isinstance(value, bool) else value for name, value in values.items()}
    attrs.update({
        "fmu_path": settings.fmu, "fmu_sha256": instance.sha256, "model_name": instance.interface.model_name,
        "integrator_name": integrator, "initial_condition": settings.initial.initial_state,
        "horizon": settings.horizon, "output_interval": settings.output_interval,
        "start_time": settings.start_time, "run_settings": canonical_json(settings),
        "initial_state_codes": json.dumps(instance.interface.choices("initial_state")),
    })
    return attrs


def simulate(settings: RunSettings, pool: InstancePool | None = None, progress: bool = False,
             outputs: tuple[str, ...] | None = None, expect_sha256: str | None = None) -> xr.Dataset:
    """Run one FMU simulation and return its trajectories (see module doc).

    ``pool`` supplies a reused instance (reset before the run); without one a fresh
    instance is created and freed.  ``outputs`` limits the recorded outputs (default:
    all of them).  ``expect_sha256`` refuses an FMU file other than the one expected.
    """
    with open_instance(settings, pool, expect_sha256) as instance:
        values = resolved_parameters(instance, settings)
        instance.start(values, settings.start_time)
        names = tuple(outputs or instance.interface.outputs)
        recorder = Recorder(instance, names, settings.start_time, settings.output_interval)
        n = settings.n_outputs
        rows = np.empty((n + 1, len(names)))
        rows[0] = recorder.sample()
        bar = _progress_bar(progress, n, f"run {instance.interface.model_name}")
        try:
            rows[1:] = recorder.advance(n, progress=bar.update if bar else None)
        finally:
            if bar:
                bar.close()
        times = settings.start_time + settings.output_interval * np.arange(n + 1)
        return trajectory_dataset(times, rows, names, instance, run_attributes(instance, settings, values))


def _progress_bar(enabled: bool, total: int, description: str):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=description, unit="step", mininterval=0.5)


def run_point(point: PointSettings, pool: InstancePool | None = None, expect_sha256: str | None = None) -> Observables:
    """Simulate one point and measure it: the unit of work of a sweep."""
    return observe(simulate(point.run, pool, outputs=POINT_OUTPUTS, expect_sha256=expect_sha256), point.observe)
