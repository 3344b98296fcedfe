"""Run FMI 2.0 co-simulation FMUs in libcosim (DNV's master, through ``libcosimpy``).

Two functions with an fmpy-like interface::

    from .libcosim import run_libcosim, run_libcosim_system

    result = run_libcosim("BlockA.fmu", start_values={"A": 0.5, "omega": 0.8},
                          stop_time=100.0, step_size=0.01, outputs=["x", "z", "contact"])
    result["time"], result["x"], result["contact"]

    result = run_libcosim_system(
        {"plate": "Excitation.fmu", "block": "BlockA.fmu"},
        connections=[("plate", "z", "block", "plate_z")],
        start_values={"block": {"mu_s": 0.5}},
        outputs={"block": ["x"], "plate": ["z"]},
        stop_time=100.0, step_size=0.01)
    result["block.x"]

Results have the layout of fmpy's ``simulate_fmu``: ``time`` holds
``start_time + k * step_size`` for k = 0..n (computed the way fmpy computes it), and
each output holds its value at those points: row 0 after initialisation, then one
row after each communication step.  Real outputs are float64, Integer int32,
Boolean bool.

Conventions of libcosim that matter when comparing with another master:

* **Clock.** libcosim counts time in integer nanoseconds, so ``start_time`` and
  ``step_size`` must be whole numbers of nanoseconds, and ``stop_time - start_time``
  a whole number of steps.  An FMU is called with ``t_ns / 1e9`` and a step of
  ``t_next / 1e9 - t / 1e9``; fmpy passes ``start + k * h`` and the difference of
  those.  The two can differ in the last bit, so an FMU whose results depend on
  the time values it is given (rather than on its own step count) agrees with fmpy
  to rounding, not bit for bit.
* **Coupling.** All FMUs take step k in parallel; afterwards every connected output
  is copied to its input (Jacobi coupling).  An input therefore holds its source's
  value at the start of the step.  During initialisation libcosim runs one round
  of transfers per FMU in initialization mode and one more after
  ``fmi2ExitInitializationMode``.
* **Recorded inputs.** An input listed in ``outputs`` is read back from the FMU
  after each step, so row k + 1 shows the value used during step k; row 0 shows
  what was set during initialisation (for a connected input, its source's value
  in initialization mode).
* **Inputs.** ``inputs(t)`` is evaluated here, before the run, at every
  communication point t_k = start_time + k * step_size (k = 0..n-1), and the value
  is applied just before the step from t_k, as fmpy does with its input table.  The
  value at the start time is also the input's initial value, so the FMU sees it
  during initialisation (fmpy applies it there too).

Each run happens in a fresh Python process (``_libcosim_worker.py``), because
libcosim changes the process it runs in:

* an FMU that fails during initialisation makes libcosim 0.11 call
  ``std::terminate`` (the exception escapes one of its worker threads): the whole
  process aborts.  In a child process that becomes a :class:`LibcosimError`;
* libcosim's log level and console sink are process-wide, and it logs to stdout;
* pythonfmu FMUs import their model module into ``sys.modules`` of the host
  process and prepend their resources folder to ``sys.path``: run in this process,
  libcosim would reuse a module that fmpy imported from its own copy of the FMU
  (or a stale one), and so would not show that the FMU loads in libcosim;
* the fixed-step algorithm keeps a pool of worker threads that call the FMUs;
* libcosim unpacks every FMU into a new temporary folder; the child's ``TMPDIR``
  points into a folder removed after the run, even when the child aborted.  (Any
  cache keyed by the FMU's unpacked path, such as numba's on-disk cache, is
  therefore cold in every libcosim run;)
* pythonfmu 0.7.0 FMU libraries loaded by libcosim damage the heap when the
  process exits (a use-after-free in their unload hook, seen with valgrind); the
  child writes its results and leaves without running exit handlers.

The cost is a Python start-up and an FMU load per run (a fraction of a second).
"""

from __future__ import annotations

import difflib
import json
import logging
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import read_model_description

from ..fmu import FmuInterface
from .errors import LibcosimError, SetupError

__all__ = ["run_libcosim", "run_libcosim_system", "LibcosimError", "SetupError"]

Value = float | int | bool
_WORKER = Path(__file__).with_name("_libcosim_worker.py")
# The worker's EXIT_REPORTED (status when it wrote error.json), not imported from it:
# importing the worker would load libcosimpy into this process.
_EXIT_REPORTED = 3
_TYPES = {"Real": "real", "Integer": "integer", "Boolean": "boolean"}
_INT32 = (-(2**31), 2**31 - 1)
_PYTHON_TYPES = {"real": "float or int", "integer": "32-bit int", "boolean": "bool"}
_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class _Grid:
    """The communication grid in libcosim's integer nanoseconds."""

    start_ns: int
    step_ns: int
    n_steps: int
    start_time: float
    step_size: float

    @classmethod
    def from_times(cls, start_time: float, stop_time: float, step_size: float) -> _Grid:
        for name, value in (("start_time", start_time), ("stop_time", stop_time), ("step_size", step_size)):
            if not (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
                    and math.isfinite(value)):
                raise SetupError(f"{name} = {value!r} is not a finite number")
        if step_size <= 0:
            raise SetupError(f"step_size = {step_size!r} must be positive")
        start_ns, step_ns = _nanoseconds("start_time", start_time), _nanoseconds("step_size", step_size)
        steps = (stop_time - start_time) / step_size
        n_steps = round(steps)
        if n_steps < 1 or abs(steps - n_steps) > 1e-9 * max(1.0, abs(steps)):
            raise SetupError(
                f"stop_time - start_time = {stop_time - start_time!r} is not a positive whole number of "
                f"steps of {step_size!r}; libcosim runs a fixed number of equal steps")
        return cls(start_ns, step_ns, n_steps, float(start_time), float(step_size))

    def times(self, count: int) -> np.ndarray:
        """start_time + k * step_size for k < count, rounded as fmpy rounds it."""
        return self.start_time + np.arange(count) * self.step_size


def _nanoseconds(name: str, seconds: float) -> int:
    scaled = float(seconds) * 1e9
    ns = round(scaled)
    if abs(scaled - ns) > 4 * math.ulp(scaled) + 1e-6:
        raise SetupError(f"{name} = {seconds!r} s is not a whole number of nanoseconds, "
                         "the resolution of libcosim's clock")
    return ns


@dataclass(frozen=True)
class _Variable:
    """One variable of one instance, resolved through the model description."""

    instance: int
    instance_name: str
    name: str
    vr: int
    type: str  # real | integer | boolean
    causality: str
    # An Integer switch's named values, from its description ("0 = name, 1 = name").
    choices: dict = field(default_factory=dict, compare=False)

    @property
    def key(self) -> str:
        return f"{self.instance_name}.{self.name}"


class _Instance:
    """An FMU under an instance name, with its variables by name."""

    def __init__(self, number: int, name: str, fmu: str | os.PathLike):
        if not isinstance(name, str) or not name or "." in name or not name.isprintable():
            raise SetupError(f"instance name {name!r} must be a non-empty printable string without '.'")
        path = Path(fmu)
        if not path.is_file():
            raise SetupError(f"FMU file {str(path)!r} (instance {name!r}) does not exist")
        try:
            description = read_model_description(str(path), validate=False)
        except Exception as exc:  # fmpy raises several types for unreadable files
            raise SetupError(f"cannot read the model description of {str(path)!r}: {exc}") from exc
        if description.fmiVersion != "2.0" or description.coSimulation is None:
            raise SetupError(f"{str(path)!r} is not an FMI 2.0 co-simulation FMU "
                             f"(fmiVersion {description.fmiVersion!r})")
        self.number, self.name, self.path = number, name, str(path.resolve())
        self.model_name = description.modelName
        self.variables = {v.name: v for v in description.modelVariables}

    def variable(self, name: str, role: str) -> _Variable:
        var = self.variables.get(name)
        if var is None:
            close = difflib.get_close_matches(str(name), list(self.variables), n=3)
            hint = f" (did you mean {' or '.join(map(repr, close))}?)" if close else ""
            raise SetupError(
                f"{role}: FMU {self.model_name!r} (instance {self.name!r}) has no variable named {name!r}{hint}. "
                f"Its variables: {', '.join(sorted(self.variables))}")
        kind = _TYPES.get(var.type)
        if kind is None:
            raise SetupError(f"{role}: {self.name}.{name} is of type {var.type}; "
                             "only Real, Integer and Boolean variables are supported")
        return _Variable(self.number, self.name, name, int(var.valueReference), kind,
                         var.causality or "local",
                         FmuInterface.parse_choices(var.description) if kind == "integer" else {})


def _typed(var: _Variable, value: object, role: str) -> Value:
    """value converted to the variable's type, refusing lossy or surprising conversions."""
    if var.type == "boolean":
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
    elif isinstance(value, (bool, np.bool_)):
        pass
    elif var.type == "integer" and isinstance(value, str):  # a switch's value by name
        if value in var.choices:
            return var.choices[value]
        raise SetupError(f"{role}: {var.key} = {value!r} is not one of its named values "
                         f"{sorted(var.choices) or '(it has none)'}")
    elif var.type == "integer":
        # a whole float is that int (``RunSettings.parameters`` holds numbers as floats)
        whole = isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer()
        if (isinstance(value, (int, np.integer)) or whole) and _INT32[0] <= value <= _INT32[1]:
            return int(value)
    elif isinstance(value, (int, float, np.integer, np.floating)):
        return float(value)
    raise SetupError(f"{role}: {var.key} ({var.type.capitalize()}) cannot take {value!r} of type "
                     f"{type(value).__name__}; give a {_PYTHON_TYPES[var.type]}")


def run_libcosim(
    fmu_path: str | os.PathLike,
    *,
    start_values: Mapping[str, Value] | None = None,
    stop_time: float,
    step_size: float,
    outputs: Sequence[str],
    start_time: float = 0.0,
    inputs: Callable[[float], Mapping[str, Value]] | None = None,
    timeout: float | None = None,
) -> dict[str, np.ndarray]:
    """Run one FMU in libcosim with a fixed communication step.

    Parameters
    ----------
    fmu_path: the ``.fmu`` file.
    start_values: variable name -> value for parameters and inputs, set before
        initialisation; the Python type must suit the variable (bool for Boolean,
        int, a whole float or a named value, e.g. "rate_state_slip", for Integer, int or
        float for Real).
    stop_time, step_size, start_time: the communication grid, in seconds; see the
        module docstring for libcosim's nanosecond clock.
    outputs: names of the Real, Integer and Boolean variables to record.
    inputs: ``inputs(t) -> {name: value}`` for input variables, evaluated at every
        communication point t_k before the run and applied for the step from t_k.
    timeout: seconds after which the run is abandoned (None: no limit).

    Returns ``{"time": ..., name: ...}`` with n + 1 rows (module docstring).
    Raises :class:`SetupError` for an invalid request (unknown variable, wrong
    type, bad grid) and :class:`LibcosimError` when libcosim or the FMU fails.
    """
    name = re.sub(r"\W", "_", Path(fmu_path).stem) or "model"

    def prefixed(t: float) -> dict[str, Value]:  # the system's names are "<instance>.<variable>"
        return {f"{name}.{key}": value for key, value in _mapping(inputs(t), "inputs(t)").items()}

    result = run_libcosim_system(
        {name: fmu_path},
        start_values={name: start_values or {}},
        outputs={name: outputs},
        stop_time=stop_time, step_size=step_size, start_time=start_time,
        inputs=None if inputs is None else prefixed, timeout=timeout)
    return {key.split(".", 1)[1] if key != "time" else key: value for key, value in result.items()}


def run_libcosim_system(
    fmus: Mapping[str, str | os.PathLike],
    *,
    connections: Sequence[tuple[str, str, str, str]] = (),
    start_values: Mapping[str, Mapping[str, Value]] | None = None,
    outputs: Mapping[str, Sequence[str]],
    stop_time: float,
    step_size: float,
    start_time: float = 0.0,
    inputs: Callable[[float], Mapping[str, Value]] | None = None,
    timeout: float | None = None,
) -> dict[str, np.ndarray]:
    """Run several FMUs, coupled output -> input, in one libcosim execution.

    Parameters
    ----------
    fmus: instance name -> ``.fmu`` file; the same file may appear under several
        names.  Instance names must not contain '.'.
    connections: ``(src_instance, src_output, dst_instance, dst_input)`` tuples;
        both variables must have the same type, each input at most one source.
    start_values: instance name -> {variable name: value} (see :func:`run_libcosim`).
    outputs: instance name -> variable names to record.
    inputs: ``inputs(t) -> {"instance.variable": value}`` for unconnected inputs.
    stop_time, step_size, start_time, timeout: as for :func:`run_libcosim`.

    Returns ``{"time": ..., "instance.variable": ...}``; coupling conventions are in
    the module docstring.
    """
    grid = _Grid.from_times(start_time, stop_time, step_size)
    fmus = _mapping(fmus, "fmus")
    if not fmus:
        raise SetupError("fmus is empty: give at least one instance name -> FMU file")
    instances = {name: _Instance(i, name, path) for i, (name, path) in enumerate(fmus.items())}

    def instance(name: object, role: str) -> _Instance:
        if name not in instances:
            raise SetupError(f"{role}: there is no instance {name!r}; instances: {', '.join(instances)}")
        return instances[name]

    starts: dict[_Variable, Value] = {}
    for inst_name, values in _mapping(start_values or {}, "start_values").items():
        inst = instance(inst_name, "start_values")
        for var_name, value in _mapping(values, f"start_values[{inst_name!r}]").items():
            var = inst.variable(var_name, "start_values")
            if var.causality not in ("parameter", "input"):
                raise SetupError(f"start_values: {var.key} has causality {var.causality!r}; "
                                 "only parameters and inputs take start values")
            starts[var] = _typed(var, value, "start_values")

    recorded: list[_Variable] = []
    for inst_name, names in _mapping(outputs, "outputs").items():
        inst = instance(inst_name, "outputs")
        if isinstance(names, str):
            raise SetupError(f"outputs[{inst_name!r}] must be a list of names, not the string {names!r}")
        for var_name in names:
            var = inst.variable(var_name, "outputs")
            if var.type == "boolean" and var.causality == "local":
                raise SetupError(f"outputs: {var.key} is a local Boolean; libcosim records Booleans only "
                                 "through its file observer, which skips local variables")
            if var not in recorded:
                recorded.append(var)

    links: list[tuple[_Variable, _Variable]] = []
    driven: set[_Variable] = set()
    for conn in connections:
        if len(conn) != 4:
            raise SetupError(f"connection {conn!r} must be (src_instance, src_var, dst_instance, dst_var)")
        src = instance(conn[0], "connections").variable(conn[1], "connections")
        dst = instance(conn[2], "connections").variable(conn[3], "connections")
        if src.causality != "output":
            raise SetupError(f"connection {conn!r}: the source {src.key} has causality {src.causality!r}, "
                             "libcosim connects only outputs")
        if dst.causality != "input":
            raise SetupError(f"connection {conn!r}: the target {dst.key} has causality {dst.causality!r}, "
                             "libcosim connects only to inputs")
        if src.type != dst.type:
            raise SetupError(f"connection {conn!r}: {src.key} is {src.type} but {dst.key} is {dst.type}")
        if dst in driven:
            raise SetupError(f"connection {conn!r}: {dst.key} is already connected")
        driven.add(dst)
        links.append((src, dst))

    fed, table = _input_table(inputs, grid, instance)
    for var in fed:
        if var in driven:
            raise SetupError(f"inputs: {var.key} is also the target of a connection")
        if var in starts:
            raise SetupError(f"inputs: {var.key} also has a start value; its start value is inputs(start_time)")

    plan = {
        "start_ns": grid.start_ns, "step_ns": grid.step_ns, "n_steps": grid.n_steps,
        "log_level": "WARNING",
        "instances": [{"name": inst.name, "fmu": inst.path} for inst in instances.values()],
        "start_values": [_var_json(var) | {"value": value} for var, value in starts.items()],
        "outputs": [_var_json(var) for var in recorded],
        "connections": [{"type": src.type, "src_instance": src.instance, "src_vr": src.vr, "src_key": src.key,
                         "dst_instance": dst.instance, "dst_vr": dst.vr, "dst_key": dst.key}
                        for src, dst in links],
        "inputs": [_var_json(var) for var in fed],
    }
    arrays = _execute(plan, table, timeout)
    result = {"time": grid.times(grid.n_steps + 1)}
    for var in recorded:
        result[var.key] = arrays[var.key]
    return result


def _mapping(value: object, role: str) -> Mapping:
    if not isinstance(value, Mapping):
        raise SetupError(f"{role} must be a mapping (dict), not {type(value).__name__}")
    return value


def _var_json(var: _Variable) -> dict:
    return {"instance": var.instance, "vr": var.vr, "type": var.type, "key": var.key, "name": var.name}


def _input_table(inputs, grid: _Grid,
                 instance: Callable[[object, str], _Instance]) -> tuple[list[_Variable], np.ndarray]:
    """Evaluate inputs(t_k) for k < n_steps into a float64 table (one column per input).

    Integer and Boolean values are exact in float64; the worker converts them back.
    """
    if inputs is None:
        return [], np.zeros((grid.n_steps, 0))
    if not callable(inputs):
        raise SetupError(f"inputs must be a function of time, not {type(inputs).__name__}")
    times = grid.times(grid.n_steps)
    first = _mapping(inputs(float(times[0])), "inputs(t)")
    keys = list(first)
    fed = []
    for key in keys:
        inst_name, _, var_name = str(key).partition(".")
        var = instance(inst_name, "inputs").variable(var_name, "inputs")
        if var.causality != "input":
            raise SetupError(f"inputs: {var.key} has causality {var.causality!r}, not 'input'")
        fed.append(var)
    table = np.empty((grid.n_steps, len(keys)))
    for k, t in enumerate(times):
        values = first if k == 0 else _mapping(inputs(float(t)), "inputs(t)")
        if set(values) != set(keys):
            raise SetupError(f"inputs(t) returned keys {sorted(values)} at t = {t!r} but {sorted(keys)} at the "
                             "start; it must return the same inputs at every time")
        for col, (key, var) in enumerate(zip(keys, fed)):
            table[k, col] = _typed(var, values[key], f"inputs(t = {t!r})")
    return fed, table


def _execute(plan: dict, table: np.ndarray, timeout: float | None) -> dict[str, np.ndarray]:
    """Run the worker in a child process and collect its results or its error."""
    with tempfile.TemporaryDirectory(prefix="vibroblock-libcosim-") as tmp:
        work = Path(tmp)
        (work / "plan.json").write_text(json.dumps(plan))
        np.save(work / "inputs.npy", table)
        return run_worker([str(_WORKER), str(work)], work, timeout)


def run_worker(arguments: list[str], work: Path, timeout: float | None, cwd: Path | None = None
               ) -> dict[str, np.ndarray]:
    """Run ``python arguments...``, a libcosim worker that reads its plan from ``work``, in a
    child process (a crash or a hang of libcosim or an FMU cannot take this process with it),
    its console captured in ``work``; the arrays it saved in ``work/result.npz``.  Raises
    :class:`LibcosimError` with the worker's message (``error.json``, written before it exits
    with ``_EXIT_REPORTED``), or how it crashed, or that it ran out of ``timeout``."""
    (work / "tmp").mkdir(exist_ok=True)
    env = dict(os.environ, TMPDIR=str(work / "tmp"), PYTHONUNBUFFERED="1")
    if cwd is not None:  # a worker started as a module of this package (python -m ...)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(cwd), env.get("PYTHONPATH")]))
    with open(work / "stdout.txt", "wb") as out, open(work / "stderr.txt", "wb") as err:
        try:
            proc = subprocess.run([sys.executable, *arguments], stdout=out, stderr=err, env=env, timeout=timeout,
                                  check=False, cwd=cwd)
        except subprocess.TimeoutExpired:
            proc = None
    stdout = (work / "stdout.txt").read_text(errors="replace")
    stderr = (work / "stderr.txt").read_text(errors="replace")
    fmu_log = _fmu_log_lines(stdout)
    if proc is None:
        raise LibcosimError(f"the libcosim run did not finish within {timeout} s and was stopped",
                            fmu_log=fmu_log, console=stdout + stderr)
    if proc.returncode == 0:
        for line in fmu_log:
            _log.warning("FMU log (libcosim): %s", line)
        with np.load(work / "result.npz") as data:
            return {key: data[key] for key in data.files}
    if proc.returncode == _EXIT_REPORTED and (work / "error.json").is_file():
        message = json.loads((work / "error.json").read_text())["message"]
    else:
        message = _crash_message(proc.returncode, stderr)
    raise LibcosimError(message, fmu_log=fmu_log, console=stdout + stderr, returncode=proc.returncode)


def _crash_message(returncode: int, stderr: str) -> str:
    if returncode < 0:
        try:
            how = f"was killed by {signal.Signals(-returncode).name}"
        except ValueError:
            how = f"was killed by signal {-returncode}"
    else:
        how = f"exited with status {returncode}"
    message = f"the libcosim process {how}"
    _, found, what = stderr.rpartition("what():")
    if found:
        message += (f"; libcosim aborted on an uncaught error: {what.strip()[:2000]} "
                    "(libcosim 0.11 aborts when an FMU fails during initialisation)")
    else:
        tail = stderr.strip().splitlines()[-5:]
        if tail:
            message += ": " + " | ".join(tail)
    return message


_RECORD = re.compile(r"^\[\d{4}-\d\d-\d\d [^\]]*\] \[[^\]]*\] \[\w+\]\s+(.*)$")
_FMI = re.compile(r"^\[FMI status=(\w+), category=([^\]]*)\]\s?(.*)$", re.S)


def _fmu_log_lines(console: str) -> tuple[str, ...]:
    """The FMU log messages in libcosim's console output, as ``"[status] message"``.

    libcosim prints each FMU message as one log record ``[FMI status=..., category=...]
    text``; lines that follow a record without a record header of their own belong to
    it (multi-line messages).  libcosim does not say which instance logged.
    """
    records: list[list[str]] = []
    for line in console.splitlines():
        match = _RECORD.match(line)
        if match:
            records.append([match.group(1)])
        elif records and line.strip():
            records[-1].append(line)
    lines = []
    for record in records:
        fmi = _FMI.match("\n".join(record))
        if fmi:
            status, category, text = fmi.groups()
            lines.append(f"[{status}{'/' + category if category else ''}] {text}")
    return tuple(lines)
