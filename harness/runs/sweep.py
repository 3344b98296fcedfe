"""Parameter sweeps: a grid of points -> one observable set per point, as a Dataset.

::

    from .sweep import Grid, sweep
    from .settings import PointSettings, RunSettings

    grid = Grid.parse(["A=0.1:2:8", "omega=0.2:1.5:8"])
    base = PointSettings(run=RunSettings.for_model("A", horizon=20_000))
    ds = sweep(grid, base, store="out/store")   # ds.phi[A, omega], ds.regime, ...

Grid
----
An axis is a name and values: ``name=start:stop:n`` (n points, linear),
``name=start:stop:n:log`` (geometric), ``name=v1,v2,...`` or ``name=v``.  A name is an
FMU parameter, ``dt``, or an auxiliary variable used by a derived parameter:
``derived={"gamma_n": "k_n / ratio"}`` with axes ``k_n`` and ``ratio`` sweeps k_n at
fixed k_n/gamma_n.  Derived expressions are arithmetic (+ - * / **, parentheses, sqrt,
exp, log, pi) over axis names and the base run's parameters.

Execution
---------
On dask.distributed: a LocalCluster (processes, one thread each, one worker per core)
unless ``Execution.scheduler`` names an existing scheduler (``tcp://host:port``);
``scheduler="inline"`` evaluates in this process without Dask.  Each worker holds an
:class:`~harness.cosim.fmu.InstancePool` installed by :class:`FmuPoolPlugin`: the FMU is
extracted once (a folder keyed by its sha256) and instantiated once per worker, then
reset between points; ``NUMBA_CACHE_DIR`` is handed to the workers so compiled
kernels are loaded, not recompiled.

Workers read the FMU file from the path in the settings and extract it under
``Execution.cache``: with an external cluster both must be reachable from the worker
hosts (same host or a shared file system).  A worker process holds one physics core:
an FMU built from other core sources than one it already loaded is refused with an
FmuError naming both; restart long-lived workers after rebuilding the FMUs.

Results: with a store (:mod:`harness.runs.store`) each point is written as soon as it
arrives, by this process (one writer), and points already stored are not computed
again.  Points that fail are reported together in a :class:`SweepError` after all
others are stored.
"""
from __future__ import annotations

import ast
import dataclasses
import hashlib
import itertools
import json
import math
import operator
import os
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Mapping, Sequence

import dask
import numpy as np
import xarray as xr

from harness.cosim.fmu import DEFAULT_CACHE, REPO_ROOT, FmuInterface, InstancePool, fmu_sha256
from .observables import MEASURED, PHI_STICK_SLIP
from .run import run_point
from .settings import PointSettings, canonical_json, to_jsonable
from .store import PointStore, point_key

# Bumped whenever the definition of an observable changes, so stored points of the old
# definition get other keys.
OBSERVABLES_VERSION = 3  # 2: regimes jammed and flying, slope angles at the stick sites; 3: hopping, rest fraction
POOL_PLUGIN = "vibroblock-fmu-pool"
INLINE = "inline"


# ---------------------------------------------------------------------- grid
@dataclass(frozen=True)
class Axis:
    name: str
    values: tuple[float, ...]

    def __post_init__(self):
        object.__setattr__(self, "values", tuple(float(v) for v in self.values))
        if not self.values:
            raise ValueError(f"axis {self.name} has no values")
        if len(set(self.values)) != len(self.values):
            raise ValueError(f"axis {self.name} repeats a value: {self.values}")

    @classmethod
    def parse(cls, text: str) -> "Axis":
        """``name=start:stop:n[:log]``, ``name=v1,v2,...`` or ``name=v``."""
        name, sep, spec = text.partition("=")
        name, spec = name.strip(), spec.strip()
        if not sep or not name or not spec:
            raise ValueError(f"grid axis {text!r} is not of the form name=start:stop:n or name=v1,v2,...")
        try:
            if ":" in spec:
                parts = spec.split(":")
                if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("lin", "log")):
                    raise ValueError
                start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
                spacing = np.geomspace if len(parts) == 4 and parts[3] == "log" else np.linspace
                values = spacing(start, stop, count)
            else:
                values = [float(v) for v in spec.split(",")]
        except ValueError:
            raise ValueError(f"grid axis {text!r}: use start:stop:n, start:stop:n:log or v1,v2,...") from None
        return cls(name, tuple(values))


_OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
              ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}
_FUNCTIONS = {"sqrt": math.sqrt, "exp": math.exp, "log": math.log, "abs": abs}
_CONSTANTS = {"pi": math.pi}


def evaluate_expression(expression: str, names: Mapping[str, float]) -> float:
    """Value of an arithmetic expression over ``names`` (no other Python is evaluated)."""

    def value(node):
        if isinstance(node, ast.Expression):
            return value(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id in names:
                return float(names[node.id])
            if node.id in _CONSTANTS:
                return _CONSTANTS[node.id]
            raise ValueError(f"{expression!r}: unknown name {node.id!r}; known: {sorted(names)}")
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](value(node.left), value(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](value(node.operand))
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCTIONS
                and len(node.args) == 1 and not node.keywords):
            return float(_FUNCTIONS[node.func.id](value(node.args[0])))
        raise ValueError(f"{expression!r}: only numbers, names, + - * / **, and "
                         f"{', '.join(_FUNCTIONS)} are allowed")

    try:
        tree = ast.parse(expression, mode="eval")
    except SyntaxError:
        raise ValueError(f"{expression!r} is not an arithmetic expression") from None
    return value(tree)


@dataclass(frozen=True)
class Grid:
    """Axes (the sweep's dimensions, in order) and parameters derived from them."""

    axes: tuple[Axis, ...]
    derived: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "axes", tuple(self.axes))
        derived = self.derived.items() if isinstance(self.derived, Mapping) else self.derived
        object.__setattr__(self, "derived", tuple((str(n), str(e)) for n, e in derived))
        names = [a.name for a in self.axes]
        if not names:
            raise ValueError("a grid needs at least one axis")
        if len(set(names)) != len(names):
            raise ValueError(f"grid axes repeat a name: {names}")
        clash = set(names) & {n for n, _ in self.derived}
        if clash:
            raise ValueError(f"{sorted(clash)} are both axes and derived parameters")

    @classmethod
    def parse(cls, axes: Iterable[str], derived: Iterable[str] = ()) -> "Grid":
        """From command-line texts: axes ``name=spec``, derived ``name=expression``."""
        pairs = []
        for text in derived:
            name, sep, expression = text.partition("=")
            if not sep or not name.strip() or not expression.strip():
                raise ValueError(f"derived parameter {text!r} is not of the form name=expression")
            pairs.append((name.strip(), expression.strip()))
        return cls(tuple(Axis.parse(a) for a in axes), tuple(pairs))

    @classmethod
    def from_file(cls, path: str | os.PathLike) -> "Grid":
        """A TOML or JSON file: ``[axes]`` name = [values] or "start:stop:n", ``[derived]`` name = "expr"."""
        path = Path(path)
        text = path.read_text()
        data = tomllib.loads(text) if path.suffix == ".toml" else json.loads(text)
        axes = []
        for name, spec in data.get("axes", {}).items():
            axes.append(Axis(name, tuple(spec)) if isinstance(spec, list) else Axis.parse(f"{name}={spec}"))
        return cls(tuple(axes), tuple(data.get("derived", {}).items()))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.axes)

    def __len__(self) -> int:
        return int(np.prod(self.shape))

    def combinations(self) -> Iterable[tuple[tuple[int, ...], dict[str, float]]]:
        for index in itertools.product(*(range(n) for n in self.shape)):
            yield index, {a.name: a.values[i] for a, i in zip(self.axes, index)}


# ---------------------------------------------------------------------- points
@dataclass(frozen=True)
class GridPoint:
    index: tuple[int, ...]
    coordinates: dict
    derived: dict
    settings: PointSettings
    key: str
    inputs: dict


def grid_points(grid: Grid, base: PointSettings, interface: FmuInterface, sha256: str) -> list[GridPoint]:
    """Every point of the grid as full settings, with its store key and inputs."""
    parameters = set(interface.parameters)
    used_by_derivations = {n.id for _, e in grid.derived for n in ast.walk(ast.parse(e, mode="eval"))
                           if isinstance(n, ast.Name)}
    for name in grid.names:
        if name not in parameters and name != "dt" and name not in used_by_derivations:
            raise ValueError(f"grid axis {name!r} is not a parameter of {interface.model_name} "
                             f"({sorted(parameters)}), not dt, and not used by a derived parameter")
    for name, _ in grid.derived:
        if name not in parameters or name == "dt":
            raise ValueError(f"derived {name!r} is not a parameter of {interface.model_name}")
    defaults = interface.defaults()
    points = []
    for index, coordinates in grid.combinations():
        run = base.run
        known = {**defaults, **dict(run.parameters), **coordinates}
        derived = {name: evaluate_expression(expression, known) for name, expression in grid.derived}
        overrides = {n: v for n, v in {**coordinates, **derived}.items() if n in parameters and n != "dt"}
        run = run.with_parameters(overrides)
        if "dt" in coordinates:
            run = dataclasses.replace(run, integration=dataclasses.replace(run.integration, dt=coordinates["dt"]))
        settings = dataclasses.replace(base, run=run)
        inputs = point_inputs(settings, sha256, interface)
        points.append(GridPoint(index, coordinates, derived, settings, point_key(inputs), inputs))
    return points


def point_inputs(point: PointSettings, sha256: str, interface: FmuInterface) -> dict:
    """Everything a point's result depends on (its store key is the hash of this)."""
    run, defaults = point.run, interface.defaults()
    return {
        "fmu_sha256": sha256, "model_name": interface.model_name,
        "fmu_values": {**defaults, **run.fmu_values(defaults)},
        "integration": to_jsonable(run.integration), "initial": to_jsonable(run.initial),
        "horizon": run.horizon, "output_interval": run.output_interval, "start_time": run.start_time,
        "observe": to_jsonable(point.observe), "observables_version": OBSERVABLES_VERSION,
    }


# ---------------------------------------------------------------------- execution
@dataclass(frozen=True)
class Execution:
    """Where and how points are evaluated (see module doc)."""

    scheduler: str | None = None
    workers: int | None = None
    progress: bool = True
    cache: str = str(DEFAULT_CACHE)
    numba_cache_dir: str | None = None
    # Dask priority of the points and tasks submitted: among those ready, higher runs
    # first (work that others wait on, e.g. a study's chain of bisection rounds).
    priority: int = 0

    def numba_cache(self) -> str:
        return self.numba_cache_dir or os.environ.get("NUMBA_CACHE_DIR") or str(REPO_ROOT / ".cache" / "numba")


class SweepError(RuntimeError):
    """Some points failed; the others are stored.  ``failures`` maps coordinates to messages."""

    def __init__(self, failures: list[tuple[dict, str]]):
        self.failures = failures
        lines = [f"{len(failures)} point(s) failed:"]
        lines += [f"  {coords}: {message}" for coords, message in failures[:5]]
        if len(failures) > 5:
            lines.append(f"  ... and {len(failures) - 5} more")
        super().__init__("\n".join(lines))


try:
    from distributed import WorkerPlugin as _WorkerPluginBase
except ImportError:  # pragma: no cover - distributed is a dependency; inline sweeps work without it
    _WorkerPluginBase = object


class FmuPoolPlugin(_WorkerPluginBase):
    """Gives each Dask worker its own InstancePool (FMUs loaded once per worker)."""

    idempotent = True
    name = POOL_PLUGIN

    def __init__(self, cache: str, numba_cache_dir: str):
        self.cache, self.numba_cache_dir = cache, numba_cache_dir
        self.pool: InstancePool | None = None

    def setup(self, worker):
        # numba reads the cache folder when first imported, i.e. when the first FMU loads.
        os.environ.setdefault("NUMBA_CACHE_DIR", self.numba_cache_dir)
        self.pool = InstancePool(self.cache)

    def teardown(self, worker):
        if self.pool is not None:
            self.pool.close()


def evaluate(point: PointSettings, pool: InstancePool, sha256: str) -> dict:
    """Observables of one point as a plain dict, plus its wall time."""
    started = time.perf_counter()
    observables = run_point(point, pool, expect_sha256=sha256).as_dict()
    return {"observables": observables, "elapsed_s": time.perf_counter() - started}


def evaluate_on_worker(point: PointSettings, sha256: str) -> dict:
    """Task run on a Dask worker: uses the worker's pool (see FmuPoolPlugin)."""
    from distributed import get_worker

    worker = get_worker()
    plugin = worker.plugins.get(POOL_PLUGIN)
    if plugin is None or plugin.pool is None:
        raise RuntimeError(f"worker {worker.address} has no {POOL_PLUGIN} plugin; register FmuPoolPlugin first")
    result = evaluate(point, plugin.pool, sha256)
    result["worker"] = worker.address
    return result


def _call_with_worker_pool(function, item):
    from distributed import get_worker

    plugin = get_worker().plugins.get(POOL_PLUGIN)
    if plugin is None or plugin.pool is None:
        raise RuntimeError(f"this worker has no {POOL_PLUGIN} plugin; register FmuPoolPlugin first")
    return function(item, plugin.pool)


def map_with_pool(function, items: Sequence, execution: Execution = Execution(), client=None,
                  arrived: Callable[[int, object], None] | None = None) -> list:
    """``[function(item, pool) for item in items]`` in parallel, each call on a Dask worker
    with that worker's InstancePool (inline with ``scheduler="inline"``); results in order.
    ``arrived(index, result)`` is called in this process as each result arrives (e.g. to
    store it at once, so that an interrupted map loses no finished item).

    For work other than grid points, e.g. several continuation ramps at once::

        loops = map_with_pool(lambda p, pool: continuation(p, ramp, pool), points)
    """
    items = list(items)
    if execution.scheduler == INLINE and client is None:
        results = []
        with InstancePool(execution.cache) as pool:
            for index, item in enumerate(items):
                results.append(function(item, pool))
                if arrived is not None:
                    arrived(index, results[-1])
        return results
    own_client = client is None
    if own_client:
        client = open_client(execution)
    try:
        client.register_plugin(FmuPoolPlugin(execution.cache, execution.numba_cache()), name=POOL_PLUGIN)
        futures = [client.submit(_call_with_worker_pool, function, item, pure=False, priority=execution.priority)
                   for item in items]
        index_of = {future.key: index for index, future in enumerate(futures)}
        bar = _progress(execution.progress, len(items), 0) if execution.progress else None
        try:
            from distributed import as_completed

            for future in as_completed(futures, loop=client.loop):
                if arrived is not None and future.status == "finished":
                    arrived(index_of[future.key], future.result())
                _tick(bar)
        finally:
            if bar is not None:
                bar.close()
        return client.gather(futures)
    finally:
        if own_client:
            close_client(client)


@dataclass(frozen=True)
class _Timed:
    """``function(item, pool)`` as ``{"result": ..., "elapsed_s": seconds}``, timed where
    it runs (on a Dask worker, its own time, not the caller's wait)."""

    function: Callable

    def __call__(self, item, pool) -> dict:
        started = time.perf_counter()
        result = self.function(item, pool)
        return {"result": result, "elapsed_s": time.perf_counter() - started}


@dataclass
class CachedOutcome:
    results: list  # function(item, pool) per item, in order
    computed: int
    reused: int
    compute_time: float  # seconds the computed items took where they ran


def task_key(function: Callable, item, identity=None) -> str:
    """The store key of ``function(item)``: sha256 of the canonical JSON of the function's
    name, the item and ``identity`` (what else the result depends on, e.g. FMU hashes)."""
    text = canonical_json({"function": f"{function.__module__}.{function.__qualname__}", "item": item,
                           "identity": identity, "observables_version": OBSERVABLES_VERSION})
    return hashlib.sha256(text.encode()).hexdigest()


def cached_map(function: Callable, items: Sequence[dict], folder: str | os.PathLike, identity=None,
               execution: Execution = Execution(), client=None) -> CachedOutcome:
    """``function(item, pool)`` for every item (:func:`map_with_pool`), each result kept in
    ``folder`` as one JSON file (:func:`task_key`, with the seconds it took, ``elapsed_s``),
    written as it arrives: items already in the folder are read, not computed, so a map
    that was killed and started again computes only what had not finished."""
    from .store import write_json_atomically

    folder = Path(folder)
    keys = [task_key(function, item, identity) for item in items]
    results: dict[int, object] = {}
    for number, key in enumerate(keys):
        path = folder / f"{key}.json"
        if path.exists():
            results[number] = json.loads(path.read_text())["result"]
    missing = [n for n in range(len(items)) if n not in results]
    outcome = CachedOutcome([], len(missing), len(items) - len(missing), 0.0)

    def arrived(index: int, timed: dict) -> None:
        number = missing[index]
        write_json_atomically(folder / f"{keys[number]}.json", {"item": to_jsonable(items[number]), **timed})
        results[number] = timed["result"]
        outcome.compute_time += timed["elapsed_s"]

    if missing:
        map_with_pool(_Timed(function), [items[n] for n in missing], execution, client, arrived)
    outcome.results = [results[n] for n in range(len(items))]
    return outcome


def worker_pool_loads(client) -> dict[str, int]:
    """FMU instances each worker has created so far (one per FMU when reuse works)."""

    def loads(dask_worker):
        plugin = dask_worker.plugins.get(POOL_PLUGIN)
        return -1 if plugin is None or plugin.pool is None else plugin.pool.loads

    return client.run(loads)


def open_client(execution: Execution):
    """A Dask client: to ``execution.scheduler`` if given, else on a new LocalCluster."""
    from distributed import Client, LocalCluster

    if execution.scheduler == INLINE:
        raise ValueError("scheduler 'inline' runs without Dask: there is no client to open")
    if execution.scheduler:
        return Client(execution.scheduler, set_as_default=False)
    workers = execution.workers or os.cpu_count() or 1
    # The workers' statistical profiler samples the running task's stack every 10 ms; deep
    # stacks through the FMU made that cost a fifth of each point's CPU time.
    with dask.config.set({"distributed.worker.profile.enabled": False}):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                               env={"NUMBA_CACHE_DIR": execution.numba_cache()})
    return Client(cluster, set_as_default=False)


def close_client(client) -> None:
    cluster = getattr(client, "cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


# ---------------------------------------------------------------------- sweep
@dataclass
class SweepOutcome:
    dataset: xr.Dataset
    computed: int = 0
    reused: int = 0
    failures: list = field(default_factory=list)
    compute_time: float = 0.0   # seconds the computed points took, summed where they ran


def run_sweep(grid: Grid, base: PointSettings = PointSettings(), store: PointStore | str | os.PathLike | None = None,
              execution: Execution = Execution(), client=None) -> SweepOutcome:
    """Evaluate every grid point not yet in ``store``; return the assembled Dataset and counts.

    ``client``: an existing Dask client to use (left open); otherwise one is opened
    according to ``execution`` and closed at the end.
    """
    if store is not None and not isinstance(store, PointStore):
        store = PointStore(store)
    sha256 = fmu_sha256(base.run.fmu)
    interface = FmuInterface(Path(base.run.fmu))
    points = grid_points(grid, base, interface, sha256)
    results: dict[str, dict] = {}
    if store is not None:
        store.record_sweep(sweep_description(grid, base, sha256, interface))
        for point in points:
            found = store.load(point.key, point.inputs)
            if found is not None:
                results[point.key] = found
    todo = list({p.key: p for p in points if p.key not in results}.values())
    outcome = SweepOutcome(dataset=xr.Dataset(), reused=len({p.key for p in points}) - len(todo))

    def finished(point: GridPoint, result: dict) -> None:
        results[point.key] = result["observables"]
        if store is not None:
            store.save(point.key, point.inputs, result["observables"], result["elapsed_s"])
        outcome.computed += 1
        outcome.compute_time += result["elapsed_s"]

    bar = _progress(execution.progress, len(todo), outcome.reused)
    try:
        if todo and execution.scheduler == INLINE and client is None:
            with InstancePool(execution.cache) as pool:
                for point in todo:
                    try:
                        finished(point, evaluate(point.settings, pool, sha256))
                    except Exception as exc:
                        outcome.failures.append((point.coordinates, str(exc)))
                    _tick(bar)
        elif todo:
            _run_on_dask(todo, sha256, execution, client, finished, outcome, bar)
    finally:
        if bar is not None:
            bar.close()
    if outcome.failures:
        raise SweepError(outcome.failures)
    outcome.dataset = assemble(grid, points, results, base, sha256, interface)
    return outcome


def _run_on_dask(todo, sha256, execution, client, finished, outcome, bar) -> None:
    from distributed import as_completed

    own_client = client is None
    if own_client:
        client = open_client(execution)
    try:
        client.register_plugin(FmuPoolPlugin(execution.cache, execution.numba_cache()), name=POOL_PLUGIN)
        futures = {}
        for point in todo:
            # The key is the point's own (its inputs' hash): sweeps that ask for the same
            # point at once, e.g. studies side by side, share its one evaluation.
            future = client.submit(evaluate_on_worker, point.settings, sha256, pure=False, priority=execution.priority,
                                   key=f"vibroblock-point-{point.key}")
            futures[future] = point
        for future in as_completed(list(futures), loop=client.loop):
            point = futures.pop(future)
            try:
                finished(point, future.result())
            except Exception as exc:
                outcome.failures.append((point.coordinates, str(exc)))
            _tick(bar)
    finally:
        if own_client:
            close_client(client)


def _progress(enabled: bool, total: int, reused: int):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=f"sweep ({reused} stored)" if reused else "tasks", unit="point")


def _tick(bar) -> None:
    if bar is not None:
        bar.update(1)


def sweep_description(grid: Grid, base: PointSettings, sha256: str, interface: FmuInterface) -> dict:
    return {"grid": {"axes": {a.name: list(a.values) for a in grid.axes}, "derived": dict(grid.derived)},
            "base": to_jsonable(base), "fmu_sha256": sha256, "model_name": interface.model_name,
            "fmu_defaults": interface.defaults(), "observables_version": OBSERVABLES_VERSION}


def assemble(grid: Grid, points: Sequence[GridPoint], results: Mapping[str, dict], base: PointSettings,
             sha256: str, interface: FmuInterface) -> xr.Dataset:
    """The observables of all points as variables over the grid's dimensions."""
    dims, shape = grid.names, grid.shape
    columns: dict[str, np.ndarray] = {}
    for name in MEASURED:
        sample = results[points[0].key][name]
        dtype = object if isinstance(sample, str) else (np.int64 if isinstance(sample, (bool, int)) else float)
        columns[name] = np.empty(shape, dtype=dtype)
    derived = {name: np.empty(shape) for name, _ in grid.derived}
    for point in points:
        record = results[point.key]
        for name in MEASURED:
            value = record[name]
            columns[name][point.index] = math.nan if value is None else value
        for name in derived:
            derived[name][point.index] = point.derived[name]
    data = {name: (dims, values.astype(str) if values.dtype == object else values)
            for name, values in columns.items()}
    data["stick_slip"] = (dims, np.isin(columns["regime"].astype(str), PHI_STICK_SLIP))
    coords = {a.name: (a.name, np.array(a.values)) for a in grid.axes}
    coords.update({name: (dims, values) for name, values in derived.items()})
    defaults = interface.defaults()
    resolved = {**defaults, **base.run.fmu_values(defaults)}
    # A switched integration is named by its rule, not by one point's choice.
    switched = bool(base.run.integration.switch)
    attrs = {name: int(value) if isinstance(value, bool) else value for name, value in resolved.items()
             if name not in grid.names and name not in derived and not (switched and name == "integrator")}
    observe = base.observe
    attrs.update({
        "fmu_path": base.run.fmu, "fmu_sha256": sha256, "model_name": interface.model_name,
        "integrator_name": base.run.integration.describe(), "initial_condition": base.run.initial.initial_state,
        "horizon": base.run.horizon, "output_interval": base.run.output_interval,
        "transient": observe.transient, "window": "rest of run" if observe.window is None else observe.window,
        "phi_threshold": observe.phi_threshold, "point_settings": canonical_json(base),
        "grid": json.dumps({"axes": {a.name: list(a.values) for a in grid.axes}, "derived": dict(grid.derived)}),
        "observables_version": OBSERVABLES_VERSION,
    })
    return xr.Dataset(data, coords=coords, attrs=attrs)


def sweep(grid: Grid, base: PointSettings = PointSettings(), store=None, execution: Execution = Execution(),
          client=None) -> xr.Dataset:
    """The sweep's Dataset (see :func:`run_sweep` for the counts of computed and stored points)."""
    return run_sweep(grid, base, store, execution, client).dataset


def points_of(grid: Grid, base: PointSettings) -> list[GridPoint]:
    """The grid's points as they would be evaluated (e.g. to run some of them directly)."""
    return grid_points(grid, base, FmuInterface(Path(base.run.fmu)), fmu_sha256(base.run.fmu))


__all__ = ["Axis", "Execution", "FmuPoolPlugin", "Grid", "GridPoint", "INLINE", "OBSERVABLES_VERSION",
           "SweepError", "SweepOutcome", "assemble", "close_client", "evaluate_expression", "grid_points",
           "map_with_pool", "open_client", "points_of", "run_sweep", "sweep", "worker_pool_loads"]
