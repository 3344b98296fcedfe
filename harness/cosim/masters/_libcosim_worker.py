"""Child-process side of :mod:`harness.cosim.masters.libcosim`: one libcosim execution per process.

Run as ``python _libcosim_worker.py WORKDIR``.  ``WORKDIR/plan.json`` describes the
run with value references already resolved (built by
``libcosim.run_libcosim_system``); ``WORKDIR/inputs.npy`` holds the input table, one
row per communication step.  On success the sampled outputs go to
``WORKDIR/result.npz`` and the exit status is 0; when libcosim refuses a request or
reports an FMU error the message goes to ``WORKDIR/error.json`` and the exit status
is :data:`EXIT_REPORTED`.  libcosim writes its log (including the FMUs' log
messages) to stdout.

This module imports only the standard library, numpy and libcosimpy, so that it
can run by path without the rest of the package.

How libcosim is driven (libcosimpy 0.0.6, libcosim 0.11):

* time is an integer count of nanoseconds; the FMUs see ``t_ns / 1e9``;
* the fixed-step algorithm sets start values in the instantiated state, calls
  ``fmi2SetupExperiment`` and ``fmi2EnterInitializationMode``, runs as many rounds
  of (set inputs, read outputs, copy connected outputs to inputs) as there are
  slaves, calls ``fmi2ExitInitializationMode``, reads the outputs and copies them
  once more; then each step calls ``fmi2DoStep`` on every slave in parallel and
  afterwards copies each connected output to its input, so an input holds its
  source's value at the start of the step (Jacobi coupling);
* Real and Integer outputs come from a time-series observer, which samples step 0
  (after initialisation) and every step after it; the observer cannot hold
  Booleans, so those come from libcosim's file observer (CSV, written as 0/1);
* inputs are applied through an override manipulator, which libcosim applies just
  before the step it was set for; the value at the start time is also given as the
  input's initial value, so the FMU sees it during initialisation.
"""

from __future__ import annotations

import os
import sys

# Run by path, this file's folder would shadow top-level modules: drop it.
if sys.path and os.path.abspath(sys.path[0] or ".") == os.path.dirname(os.path.abspath(__file__)):
    del sys.path[0]

import json  # noqa: E402
import re  # noqa: E402
import traceback  # noqa: E402
from ctypes import POINTER, c_int64  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from libcosimpy.CosimEnums import CosimVariableType  # noqa: E402
from libcosimpy.CosimExecution import CosimExecution  # noqa: E402
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level  # noqa: E402
from libcosimpy.CosimManipulator import CosimManipulator  # noqa: E402
from libcosimpy.CosimObserver import CosimObserver  # noqa: E402
from libcosimpy.CosimSlave import CosimLocalSlave  # noqa: E402
from libcosimpy._internal import get_last_error_message, libcosimc, wrap_function  # noqa: E402

EXIT_REPORTED = 3
CHUNK = 65536  # samples read from the time-series observer per call
_COSIM_TYPES = {"real": CosimVariableType.REAL, "integer": CosimVariableType.INTEGER,
                "boolean": CosimVariableType.BOOLEAN}
_DTYPES = {"real": np.float64, "integer": np.int32, "boolean": np.bool_}


class Failure(Exception):
    """libcosim refused a request or reported an error; the message says which."""


def _libcosim_says(what: str) -> Failure:
    return Failure(f"{what}: {get_last_error_message().strip() or 'libcosim gave no message'}")


def create_execution(start_ns: int, step_ns: int) -> CosimExecution:
    """A fixed-step execution starting at ``start_ns``.

    libcosimpy 0.0.6 only creates executions that start at 0; for any other start
    the same C function is called with the start time and the result wrapped the
    way libcosimpy's own constructors do.
    """
    if start_ns == 0:
        return CosimExecution.from_step_size(step_ns)
    create = wrap_function(lib=libcosimc(), funcname="cosim_execution_create",
                           argtypes=[c_int64, c_int64], restype=POINTER(CosimExecution))
    pointer = create(start_ns, step_ns)
    if not pointer:
        raise _libcosim_says("creating the execution")
    return CosimExecution(getattr(CosimExecution, "_CosimExecution__create_key"), pointer)


def _set_initial(execution: CosimExecution, index: int, kind: str, vr: int, value) -> bool:
    if kind == "real":
        return execution.real_initial_value(index, vr, float(value))
    if kind == "integer":
        return execution.integer_initial_value(index, vr, int(value))
    return execution.boolean_initial_value(index, vr, bool(value))


def _connect(execution: CosimExecution, kind: str, *ids: int) -> bool:
    connect = {"real": execution.connect_real_variables,
               "integer": execution.connect_integer_variables,
               "boolean": execution.connect_boolean_variables}[kind]
    return connect(*ids) == 0  # these return libcosim's status code, 0 = success


def _override(manipulator: CosimManipulator, index: int, kind: str, vrs: list[int], values) -> bool:
    if kind == "real":
        return manipulator.slave_real_values(index, vrs, [float(v) for v in values])
    if kind == "integer":
        return manipulator.slave_integer_values(index, vrs, [int(v) for v in values])
    return manipulator.slave_boolean_values(index, vrs, [bool(v) for v in values])


def _read_series(observer: CosimObserver, index: int, kind: str, vr: int,
                 start_ns: int, step_ns: int, n_steps: int) -> np.ndarray:
    """Samples of steps 0..n_steps from the time-series observer, checked step by step."""
    read = observer.time_series_real_samples if kind == "real" else observer.time_series_integer_samples
    # libcosimpy 0.0.6 trims its sample lists by counting step numbers equal to 0,
    # which also drops a real sample when reading from step 0: read step 0 alone
    # (asking for two samples returns exactly the first) and the rest from step 1.
    times, steps, values = read(index, vr, from_step=0, sample_count=2)
    if not values or steps[0] != 0 or times[0] != start_ns:
        raise Failure(f"the time-series observer has no start sample for value reference {vr}")
    out = [values[0]]
    step = 1
    while step <= n_steps:
        count = min(CHUNK, n_steps - step + 1)
        times, steps, values = read(index, vr, from_step=step, sample_count=count)
        expected = np.arange(step, step + count)
        if len(values) != count or not np.array_equal(steps, expected) \
                or not np.array_equal(times, start_ns + expected * step_ns):
            raise Failure(f"the time-series observer returned steps {steps[:3]}... for value reference {vr}, "
                          f"expected {count} consecutive steps from step {step}")
        out.extend(values)
        step += count
    return np.asarray(out, dtype=_DTYPES[kind])


def _read_booleans(log_dir: Path, instance: str, names: list[str], n_steps: int) -> dict[str, np.ndarray]:
    """Boolean columns of the file observer's CSV for one instance."""
    pattern = re.compile(re.escape(instance) + r"_\d{8}_\d{6}_\d+\.csv")
    files = [p for p in log_dir.glob("*.csv") if pattern.fullmatch(p.name)]
    if len(files) != 1:
        raise Failure(f"expected one file-observer CSV for {instance!r} in {log_dir}, found {len(files)}")
    lines = files[0].read_text().splitlines()
    header = lines[0].split(",")
    if header[:2] != ["Time", "StepCount"]:
        raise Failure(f"unexpected file-observer header in {files[0].name}: {lines[0][:120]!r}")
    rows = [line.split(",") for line in lines[1:] if line]
    steps = [int(row[1]) for row in rows]
    if steps != list(range(n_steps + 1)):
        raise Failure(f"the file observer recorded steps {steps[:3]}...{steps[-3:]} for {instance!r}, "
                      f"expected 0..{n_steps}")
    columns = {}
    for name in names:
        where = [i for i, title in enumerate(header) if title == name]
        if len(where) != 1:
            raise Failure(f"cannot find Boolean {name!r} in the file-observer CSV of {instance!r}")
        columns[name] = np.array([row[where[0]] == "1" for row in rows], dtype=np.bool_)
    return columns


def _add_slave(execution: CosimExecution, fmu: str, name: str) -> tuple[CosimLocalSlave, int]:
    slave = CosimLocalSlave(fmu_path=fmu, instance_name=name)
    if not slave.ptr():  # libcosimpy does not check this itself
        raise _libcosim_says(f"loading {fmu} as {name!r}")
    index = execution.add_local_slave(slave)
    if index < 0:
        raise _libcosim_says(f"adding {name!r} to the execution")
    return slave, index


def run(plan: dict, inputs: np.ndarray, workdir: Path) -> dict[str, np.ndarray]:
    start_ns, step_ns, n_steps = plan["start_ns"], plan["step_ns"], plan["n_steps"]
    execution = create_execution(start_ns, step_ns)
    slaves = [_add_slave(execution, instance["fmu"], instance["name"]) for instance in plan["instances"]]
    indices = [index for _, index in slaves]

    # Without an explicit size the observer keeps only the latest 10 000 samples.
    series = CosimObserver.create_time_series(buffer_size=n_steps + 1)
    if not execution.add_observer(series):
        raise _libcosim_says("adding the time-series observer")
    booleans = [o for o in plan["outputs"] if o["type"] == "boolean"]
    files = None
    log_dir = workdir / "file_observer"
    if booleans:
        files = CosimObserver.create_to_dir(str(log_dir))
        if not execution.add_observer(files):
            raise _libcosim_says("adding the file observer")
    for out in plan["outputs"]:
        if out["type"] != "boolean" and not series.start_time_series(
                indices[out["instance"]], out["vr"], _COSIM_TYPES[out["type"]]):
            raise _libcosim_says(f"observing {out['key']}")

    for start in plan["start_values"]:
        if not _set_initial(execution, indices[start["instance"]], start["type"], start["vr"], start["value"]):
            raise _libcosim_says(f"setting the start value of {start['key']}")
    for conn in plan["connections"]:
        if not _connect(execution, conn["type"], indices[conn["src_instance"]], conn["src_vr"],
                        indices[conn["dst_instance"]], conn["dst_vr"]):
            raise _libcosim_says(f"connecting {conn['src_key']} to {conn['dst_key']}")

    manipulator = None
    groups = []  # (slave index, type, value references, input table columns)
    if plan["inputs"]:
        for col, inp in enumerate(plan["inputs"]):
            if not _set_initial(execution, indices[inp["instance"]], inp["type"], inp["vr"], inputs[0, col]):
                raise _libcosim_says(f"setting the start-time value of input {inp['key']}")
            key = (indices[inp["instance"]], inp["type"])
            for group in groups:
                if group[:2] == key:
                    group[2].append(inp["vr"])
                    group[3].append(col)
                    break
            else:
                groups.append((key[0], key[1], [inp["vr"]], [col]))
        manipulator = CosimManipulator.create_override()
        if not execution.add_manipulator(manipulator):
            raise _libcosim_says("adding the override manipulator")

    if manipulator is None:
        ok = execution.step(n_steps)
    else:
        ok = True
        for k in range(n_steps):
            for index, kind, vrs, cols in groups:
                if not _override(manipulator, index, kind, vrs, inputs[k, cols]):
                    raise _libcosim_says(f"setting inputs for step {k}")
            ok = execution.step(1)
            if not ok:
                break
    if not ok:
        message = get_last_error_message().strip()
        now = execution.status().current_time
        step = (now - start_ns) // step_ns
        raise Failure(f"the step from t = {now / 1e9:.9g} (step {step + 1} of {n_steps}) failed: {message}")

    results = {}
    for out in plan["outputs"]:
        if out["type"] != "boolean":
            results[out["key"]] = _read_series(series, indices[out["instance"]], out["type"], out["vr"],
                                               start_ns, step_ns, n_steps)
    # The file observer writes its CSV when libcosim releases it, i.e. when both the
    # observer and the execution are gone.
    del manipulator, files, series, execution, slaves
    if booleans:
        by_instance: dict[int, list[dict]] = {}
        for out in booleans:
            by_instance.setdefault(out["instance"], []).append(out)
        for number, outs in by_instance.items():
            name = plan["instances"][number]["name"]
            columns = _read_booleans(log_dir, name, [o["name"] for o in outs], n_steps)
            for out in outs:
                results[out["key"]] = columns[out["name"]]
    return results


def main(argv: list[str]) -> None:
    workdir = Path(argv[1])
    plan = json.loads((workdir / "plan.json").read_text())
    inputs = np.load(workdir / "inputs.npy")
    log_output_level(CosimLogLevel[plan["log_level"]])
    try:
        results = run(plan, inputs, workdir)
    except Failure as failure:
        (workdir / "error.json").write_text(json.dumps({"message": str(failure)}))
        _leave(EXIT_REPORTED)  # also skips tearing down FMU instances that have just failed
    except BaseException:
        traceback.print_exc()
        _leave(1)
    np.savez(workdir / "result.npz", **results)
    _leave(0)


def _leave(status: int) -> None:
    """Exit without the process's exit handlers.

    pythonfmu 0.7.0 FMU libraries that libcosim has loaded are still mapped at
    exit, and their unload hook then touches the interpreter state object that a
    static destructor has already freed (valgrind: invalid read in
    ``finalizePythonInterpreter``).  The heap damage aborts about one exit in
    seven ("corrupted double-linked list") after all results have been written.
    Everything this process produces is on disk at this point, so skip exit
    handlers altogether.
    """
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)


if __name__ == "__main__":
    main(sys.argv)
