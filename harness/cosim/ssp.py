"""Systems of FMUs as SSP files (System Structure and Parameterization 1.0), run in two masters.

An ``.ssp`` file is a zip archive holding ``SystemStructure.ssd`` (the components,
their connectors, parameter values and connections) and the FMUs under
``resources/``.  This module writes one from a :class:`System`, reads it back, and
runs it in fmpy (:func:`run_ssp_fmpy`) or in libcosim (:func:`run_ssp_libcosim`)::

    from .ssp import excitation_block_system, run_ssp_fmpy, run_ssp_libcosim, write_ssp

    system = excitation_block_system("Excitation.fmu", "BlockA.fmu",
                                     excitation={"mode": 0, "amplitude": 2.0, "omega": 0.3},
                                     block={"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3})
    write_ssp("plate_block.ssp", system)
    fmpy_result = run_ssp_fmpy("plate_block.ssp", stop_time=100.0, step_size=0.5)
    cosim_result = run_ssp_libcosim("plate_block.ssp", stop_time=100.0, step_size=0.5)
    fmpy_result["block.x"], cosim_result["block.x"]

Both results have the same layout: ``time`` holds the communication points
``start + k h`` for k = 1..n (the end of each step) and ``"component.variable"`` the
values there.

Conventions of the two masters (found in fmpy 0.3.32's ``fmpy/ssp/simulation.py`` and
libcosim 0.11, see ``harness.cosim.masters.libcosim``)
-------------------------------------------------------------------------------------
* Parameters.  fmpy's ``simulate_ssp`` reads the SSD's ParameterBindings but does not
  apply them; it applies only a ParameterSet passed by the caller (names
  ``component.variable``), before ``fmi2EnterInitializationMode``.
  :func:`run_ssp_fmpy` passes the SSD's own bindings that way.  fmpy sets Real,
  Integer and Boolean values only (a String raises; a Boolean is set from its text,
  so ``false`` would become true): :func:`run_ssp_fmpy` refuses String and Boolean
  bindings instead.  The libcosim runner sets Real, Integer and Boolean start values.
* Coupling.  Both are Jacobi: every FMU steps from t_k with the inputs it was given
  before the step, then outputs are copied to inputs.  An input therefore holds its
  source's output at t_k during the step from t_k, in both masters.
* Start.  libcosim copies outputs to inputs during initialisation, so the first step
  sees the sources' start values.  fmpy starts every connector at 0.0 and copies the
  first time after the first step: during the first step every connected input is 0.
  The two agree when the sources start at 0 (e.g. the Excitation FMU with
  ``ramp_time > 0``, or a record played from its first, resting sample).
* Time.  fmpy accumulates ``time += step_size`` and labels each result row with the
  time at which the step *started* although the values are those after it; it runs
  while ``time < stop_time``, so an accumulated time just short of ``stop_time`` adds
  a step.  libcosim counts integer nanoseconds.  :func:`run_ssp_fmpy` asks for exactly
  n steps and relabels the rows with their end times.  The time values the FMUs are
  given differ between the masters in the last bits, which is the only difference
  left when the sources start at 0 (see docs/excitation.md for the measured size).
"""
from __future__ import annotations

import math
import os
import sys
import shutil
import tempfile
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

__all__ = ["Component", "System", "SspError", "excitation_block_system", "read_ssp", "run_ssp_fmpy",
           "run_ssp_libcosim", "write_ssp"]

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)
FMU_TYPE = "application/x-fmu-sharedlibrary"
PLATE_CONNECTIONS = (("plate_z", "plate_z"), ("plate_v", "plate_v"), ("plate_a", "plate_a"))
# A block on an oblique plate (plate_motion = 1) also takes the motion along x.
HORIZONTAL_CONNECTIONS = (("plate_x", "plate_x"), ("plate_vx", "plate_vx"), ("plate_ax", "plate_ax"))
BLOCK_OUTPUTS = ("x", "z", "vx", "vz", "phi_integral", "coulomb_resets", "contact", "normal_force")


class SspError(ValueError):
    """An SSP file or system that cannot be written, read or run as asked; the message says why."""


Value = float | int | bool | str


@dataclass(frozen=True)
class Component:
    """An FMU in a system: its instance name, file, parameter values, and the outputs
    exposed as connectors besides the connected ones (fmpy records connectors only)."""

    name: str
    fmu: str
    parameters: Mapping[str, Value] = field(default_factory=dict)
    outputs: tuple[str, ...] = ()


@dataclass(frozen=True)
class System:
    """Components and connections ``(start component, output, end component, input)``."""

    name: str
    components: tuple[Component, ...]
    connections: tuple[tuple[str, str, str, str], ...]
    start_time: float | None = None
    stop_time: float | None = None

    def component(self, name: str) -> Component:
        for component in self.components:
            if component.name == name:
                return component
        raise SspError(f"the system has no component {name!r}; it has {[c.name for c in self.components]}")


def excitation_block_system(excitation_fmu: str | os.PathLike, block_fmu: str | os.PathLike, *,
                            excitation: Mapping[str, Value] | None = None, block: Mapping[str, Value] | None = None,
                            block_outputs: Sequence[str] = BLOCK_OUTPUTS, name: str = "plate_and_block") -> System:
    """The Excitation FMU driving a Block FMU: plate_z, plate_v, plate_a connected one to one,
    and plate_x, plate_vx, plate_ax too where the block runs the oblique plate
    (``plate_motion`` 1 or "oblique" among its values)."""
    block = dict(block or {})
    pairs = PLATE_CONNECTIONS + (HORIZONTAL_CONNECTIONS if block.get("plate_motion") in (1, "oblique") else ())
    return System(
        name=name,
        components=(Component("plate", str(excitation_fmu), dict(excitation or {})),
                    Component("block", str(block_fmu), block, tuple(block_outputs))),
        connections=tuple(("plate", out, "block", inp) for out, inp in pairs))


# ---------------------------------------------------------------------------- writing
def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _variables(fmu: str) -> dict:
    from fmpy import read_model_description

    if not Path(fmu).is_file():
        raise SspError(f"FMU {fmu!r} does not exist")
    return {v.name: v for v in read_model_description(fmu, validate=False).modelVariables}


def _type_element(parent: ET.Element, prefix: str, kind: str, value: Value | None = None) -> None:
    attributes = {}
    if value is not None:
        if kind == "Boolean":
            attributes["value"] = "true" if value else "false"
        elif kind == "Real":
            attributes["value"] = repr(float(value))  # shortest text that reads back to the same double
        else:
            attributes["value"] = str(value)
    ET.SubElement(parent, _q(prefix, kind), attributes)


def _as_type(kind: str, value: Value) -> Value:
    """An Integer given as a whole float (``RunSettings.parameters`` holds numbers as floats)
    is that int; every other value is checked as it is."""
    if (kind == "Integer" and isinstance(value, (float, np.floating)) and math.isfinite(value)
            and float(value).is_integer()):
        return int(value)
    return value


def _check_value(component: Component, name: str, variable, value: Value) -> None:
    kind = variable.type
    ok = {"Real": isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
          and math.isfinite(float(value)),
          "Integer": isinstance(value, (int, np.integer)) and not isinstance(value, bool),
          "Boolean": isinstance(value, (bool, np.bool_)),
          "String": isinstance(value, str)}.get(kind, False)
    if not ok:
        raise SspError(f"{component.name}.{name} is a {kind} variable and cannot take {value!r}")
    if variable.causality not in ("parameter", "input"):
        raise SspError(f"{component.name}.{name} has causality {variable.causality!r}; "
                       "only parameters and inputs can be bound")


def write_ssp(path: str | os.PathLike, system: System) -> Path:
    """Write ``system`` as an SSP archive: ``SystemStructure.ssd`` plus each FMU under ``resources/``."""
    path = Path(path)
    names = [c.name for c in system.components]
    if len(set(names)) != len(names) or any(not n or "." in n for n in names):
        raise SspError(f"component names must be unique, non-empty and free of '.': {names}")
    variables = {c.name: _variables(c.fmu) for c in system.components}
    connectors: dict[str, list[str]] = {c.name: [] for c in system.components}
    for start, output, end, input_ in system.connections:
        for comp, var, causality in ((start, output, "output"), (end, input_, "input")):
            if comp not in variables:
                raise SspError(f"connection {start}.{output} -> {end}.{input_}: no component {comp!r}")
            if var not in variables[comp]:
                raise SspError(f"connection {start}.{output} -> {end}.{input_}: {comp} has no variable {var!r}")
            if variables[comp][var].causality != causality:
                raise SspError(f"connection {start}.{output} -> {end}.{input_}: {comp}.{var} is not an {causality}")
            if var not in connectors[comp]:
                connectors[comp].append(var)
    for component in system.components:
        for var in component.outputs:
            if var not in variables[component.name]:
                raise SspError(f"{component.name} has no variable {var!r} to expose")
            if var not in connectors[component.name]:
                connectors[component.name].append(var)

    root = ET.Element(_q("ssd", "SystemStructureDescription"), {"version": "1.0", "name": system.name})
    xml_system = ET.SubElement(root, _q("ssd", "System"), {"name": system.name})
    elements = ET.SubElement(xml_system, _q("ssd", "Elements"))
    sources = {}
    for component in system.components:
        source = f"resources/{component.name}_{Path(component.fmu).name}"
        sources[source] = component.fmu
        xml_component = ET.SubElement(elements, _q("ssd", "Component"),
                                      {"name": component.name, "type": FMU_TYPE, "source": source})
        xml_connectors = ET.SubElement(xml_component, _q("ssd", "Connectors"))
        for var in connectors[component.name]:
            variable = variables[component.name][var]
            kind = variable.causality if variable.causality in ("input", "output", "parameter") else "output"
            connector = ET.SubElement(xml_connectors, _q("ssd", "Connector"), {"name": var, "kind": kind})
            _type_element(connector, "ssc", variable.type)
        if component.parameters:
            bindings = ET.SubElement(xml_component, _q("ssd", "ParameterBindings"))
            binding = ET.SubElement(bindings, _q("ssd", "ParameterBinding"))
            values = ET.SubElement(binding, _q("ssd", "ParameterValues"))
            parameter_set = ET.SubElement(values, _q("ssv", "ParameterSet"),
                                          {"version": "1.0", "name": f"{component.name}_parameters"})
            parameters = ET.SubElement(parameter_set, _q("ssv", "Parameters"))
            for name, value in component.parameters.items():
                if name not in variables[component.name]:
                    raise SspError(f"{component.name} has no parameter {name!r}")
                variable = variables[component.name][name]
                value = _as_type(variable.type, value)
                _check_value(component, name, variable, value)
                xml_parameter = ET.SubElement(parameters, _q("ssv", "Parameter"), {"name": name})
                _type_element(xml_parameter, "ssv", variable.type, value)
    if system.connections:
        xml_connections = ET.SubElement(xml_system, _q("ssd", "Connections"))
        for start, output, end, input_ in system.connections:
            ET.SubElement(xml_connections, _q("ssd", "Connection"), {
                "startElement": start, "startConnector": output, "endElement": end, "endConnector": input_})
    if system.start_time is not None or system.stop_time is not None:
        experiment = {}
        if system.start_time is not None:
            experiment["startTime"] = repr(float(system.start_time))
        if system.stop_time is not None:
            experiment["stopTime"] = repr(float(system.stop_time))
        ET.SubElement(root, _q("ssd", "DefaultExperiment"), experiment)
    ET.indent(root)
    text = ET.tostring(root, encoding="UTF-8", xml_declaration=True)

    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=path.parent, suffix=".ssp", delete=False) as tmp:
        staging = Path(tmp.name)
    try:
        with zipfile.ZipFile(staging, "w", zipfile.ZIP_DEFLATED) as archive:
            archive.writestr("SystemStructure.ssd", text)
            for source, fmu in sources.items():
                archive.write(fmu, source)
        staging.chmod(0o644)
        staging.replace(path)
    finally:
        staging.unlink(missing_ok=True)
    return path


# ---------------------------------------------------------------------------- reading
_PARSERS = {"Real": float, "Integer": int, "Boolean": lambda text: text.strip() in ("true", "1"), "String": str}


def read_ssp(path: str | os.PathLike, fmu_dir: str | os.PathLike | None = None) -> System:
    """Read an SSP archive written by :func:`write_ssp` (flat system, inline parameter sets).

    The FMUs are extracted to ``fmu_dir`` (a new temporary folder when None; the caller
    removes it) and the returned components point there.  The file is validated
    against the SSP 1.0 schema shipped with fmpy first.
    """
    from fmpy.ssp.ssd import read_ssd

    path = Path(path)
    if not zipfile.is_zipfile(path):
        raise SspError(f"{str(path)!r} is not an SSP archive (zip)")
    try:
        read_ssd(str(path), validate=True)  # schema check only; its object model drops the values' types
    except Exception as exc:
        raise SspError(f"{str(path)!r} is not a valid SSP 1.0 file: {exc}") from None
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read("SystemStructure.ssd"))
        xml_system = root.find("ssd:System", NS)
        if xml_system.find("ssd:Elements/ssd:System", NS) is not None:
            raise SspError("nested systems are not supported here")
        folder = Path(fmu_dir) if fmu_dir is not None else Path(tempfile.mkdtemp(prefix="vibroblock-ssp-"))
        folder.mkdir(parents=True, exist_ok=True)
        components = []
        for xml_component in xml_system.findall("ssd:Elements/ssd:Component", NS):
            name, source = xml_component.get("name"), xml_component.get("source")
            if xml_component.get("type", FMU_TYPE) != FMU_TYPE:
                raise SspError(f"component {name!r} is not an FMU ({xml_component.get('type')})")
            target = folder / Path(source).name
            with archive.open(source) as src, open(target, "wb") as dst:
                shutil.copyfileobj(src, dst)
            parameters: dict[str, Value] = {}
            for binding in xml_component.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS):
                if binding.get("source"):
                    raise SspError(f"component {name!r}: parameter files (source=...) are not supported here")
                prefix = binding.get("prefix", "")
                for xml_parameter in binding.findall("ssd:ParameterValues/ssv:ParameterSet/ssv:Parameters/"
                                                     "ssv:Parameter", NS):
                    for kind, parse in _PARSERS.items():
                        typed = xml_parameter.find(f"ssv:{kind}", NS)
                        if typed is not None:
                            parameters[prefix + xml_parameter.get("name")] = parse(typed.get("value"))
                            break
            outputs = tuple(c.get("name") for c in xml_component.findall("ssd:Connectors/ssd:Connector", NS)
                            if c.get("kind") == "output")
            components.append(Component(name, str(target), parameters, outputs))
        connections = tuple((c.get("startElement"), c.get("startConnector"), c.get("endElement"),
                             c.get("endConnector"))
                            for c in xml_system.findall("ssd:Connections/ssd:Connection", NS))
        experiment = root.find("ssd:DefaultExperiment", NS)
        start = stop = None
        if experiment is not None:
            start = float(experiment.get("startTime")) if experiment.get("startTime") else None
            stop = float(experiment.get("stopTime")) if experiment.get("stopTime") else None
    for start_name, _, end_name, _ in connections:
        if None in (start_name, end_name):
            raise SspError("connections to the system's own connectors are not supported here")
    return System(xml_system.get("name"), tuple(components), connections, start, stop)


# ---------------------------------------------------------------------------- running
def _steps(start_time: float, stop_time: float, step_size: float) -> int:
    if not all(math.isfinite(v) for v in (start_time, stop_time, step_size)) or step_size <= 0.0:
        raise SspError(f"start_time, stop_time and step_size must be finite, step_size > 0: "
                       f"{start_time!r}, {stop_time!r}, {step_size!r}")
    steps = (stop_time - start_time) / step_size
    n = round(steps)
    if n < 1 or abs(steps - n) > 1e-9 * max(1.0, steps):
        raise SspError(f"stop_time - start_time = {stop_time - start_time!r} is not a whole number of steps of "
                       f"{step_size!r}")
    return n


def run_ssp_fmpy(path: str | os.PathLike, *, stop_time: float, step_size: float,
                 start_time: float = 0.0) -> dict[str, np.ndarray]:
    """Run an SSP file in fmpy's ``simulate_ssp`` (module doc: conventions).

    Returns ``{"time": start + k h (k = 1..n), "component.connector": values after each step}``.
    """
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet

    n = _steps(start_time, stop_time, step_size)
    with tempfile.TemporaryDirectory(prefix="vibroblock-ssp-") as folder:
        system = read_ssp(path, folder)
    parameter_set = ParameterSet(name="bindings")
    for component in system.components:
        for name, value in component.parameters.items():
            if isinstance(value, (str, bool)):
                raise SspError(f"{component.name}.{name} = {value!r}: fmpy 0.3.32's simulate_ssp cannot set "
                               f"{type(value).__name__} values; run this system with run_ssp_libcosim or "
                               "leave the value at its default")
            parameter_set.parameters.append(Parameter(name=f"{component.name}.{name}", type=None,
                                                      value=repr(value)))
    # fmpy loops while its accumulated time is below stop_time: ask for n - 1/2 steps.
    rows = simulate_ssp(str(path), start_time=start_time, stop_time=start_time + (n - 0.5) * step_size,
                        step_size=step_size, parameter_set=parameter_set)
    if len(rows) != n:
        raise SspError(f"fmpy took {len(rows)} steps instead of {n}")
    result = {"time": start_time + np.arange(1, n + 1) * step_size}
    for name in rows.dtype.names[1:]:
        result[name] = np.asarray(rows[name])
    return result


def run_ssp_libcosim(path: str | os.PathLike, *, stop_time: float, step_size: float, start_time: float = 0.0,
                     outputs: Mapping[str, Sequence[str]] | None = None,
                     timeout: float | None = None) -> dict[str, np.ndarray]:
    """Run an SSP file in libcosim, loaded by libcosim's own SSP reader.

    libcosim reads the components, parameter bindings (String values too) and
    connections from the file itself; this function only picks the recorded
    variables (``outputs``: component -> names; default every output connector in
    the file) and the fixed step.  As with ``harness.cosim.masters.run_libcosim`` the run
    happens in a child process (libcosim aborts its process when an FMU fails during
    initialisation; that becomes :class:`harness.cosim.masters.LibcosimError`).  Returns the
    layout of :func:`run_ssp_fmpy` (rows after each step; the start row is dropped).
    """
    import json

    from harness.cosim.masters.libcosim import _nanoseconds, run_worker

    n = _steps(start_time, stop_time, step_size)
    path = Path(path).resolve()
    with tempfile.TemporaryDirectory(prefix="vibroblock-ssp-") as folder:
        system = read_ssp(path, folder)
    recorded = ({c.name: list(c.outputs) for c in system.components} if outputs is None
                else {name: list(names) for name, names in outputs.items()})
    plan = {"ssp": str(path), "start_ns": _nanoseconds("start_time", start_time),
            "step_ns": _nanoseconds("step_size", step_size), "n_steps": n,
            "outputs": [[component, name] for component, names in recorded.items() for name in names]}
    with tempfile.TemporaryDirectory(prefix="vibroblock-libcosim-ssp-") as tmp:
        work = Path(tmp)
        (work / "plan.json").write_text(json.dumps(plan))
        arrays = run_worker(["-m", "harness.cosim.ssp", "--libcosim-worker", str(work)], work, timeout,
                            cwd=Path(__file__).resolve().parents[2])
    out = {"time": start_time + np.arange(1, n + 1) * step_size}
    for component, name in plan["outputs"]:
        out[f"{component}.{name}"] = arrays[f"{component}.{name}"][1:]
    return out


def _libcosim_worker(workdir: Path) -> int:
    """Child-process side of :func:`run_ssp_libcosim`: one libcosim execution of an SSP file."""
    import json
    from ctypes import POINTER, c_bool, c_char_p, c_int64

    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy._internal import get_last_error_message, libcosimc, wrap_function

    from harness.cosim.masters._libcosim_worker import EXIT_REPORTED, Failure, _read_booleans, _read_series

    plan = json.loads((workdir / "plan.json").read_text())
    log_output_level(CosimLogLevel.WARNING)
    try:
        # libcosimpy's from_ssp_file cannot give a start time; call the same C function itself.
        create = wrap_function(lib=libcosimc(), funcname="cosim_ssp_fixed_step_execution_create",
                               argtypes=[c_char_p, c_bool, c_int64, c_int64], restype=POINTER(CosimExecution))
        pointer = create(plan["ssp"].encode(), True, plan["start_ns"], plan["step_ns"])
        if not pointer:
            raise Failure(f"libcosim cannot load {plan['ssp']}: {get_last_error_message()}")
        execution = CosimExecution(getattr(CosimExecution, "_CosimExecution__create_key"), pointer)
        slaves = {info.name.decode(): info.index for info in execution.slave_infos()}
        kinds = {CosimVariableType.REAL.value: "real", CosimVariableType.INTEGER.value: "integer",
                 CosimVariableType.BOOLEAN.value: "boolean"}
        wanted = []
        for component, name in plan["outputs"]:
            if component not in slaves:
                raise Failure(f"libcosim loaded no component {component!r} from the SSP; it has {sorted(slaves)}")
            variables = {v.name.decode(): v for v in execution.slave_variables(slaves[component])}
            if name not in variables or variables[name].type not in kinds:
                raise Failure(f"{component} has no Real, Integer or Boolean variable {name!r}")
            wanted.append((component, name, slaves[component], variables[name].reference,
                           kinds[variables[name].type]))
        series = CosimObserver.create_time_series(buffer_size=plan["n_steps"] + 1)
        if not execution.add_observer(series):
            raise Failure(f"adding the time-series observer: {get_last_error_message()}")
        files = None
        if any(kind == "boolean" for *_, kind in wanted):
            files = CosimObserver.create_to_dir(str(workdir / "file_observer"))
            if not execution.add_observer(files):
                raise Failure(f"adding the file observer: {get_last_error_message()}")
        for component, name, index, reference, kind in wanted:
            if kind != "boolean" and not series.start_time_series(
                    index, reference, CosimVariableType.REAL if kind == "real" else CosimVariableType.INTEGER):
                raise Failure(f"observing {component}.{name}: {get_last_error_message()}")
        if not execution.step(plan["n_steps"]):
            now = execution.status().current_time
            raise Failure(f"the run failed at t = {now / 1e9:.9g}: {get_last_error_message()}")
        results = {f"{component}.{name}": _read_series(series, index, kind, reference, plan["start_ns"],
                                                        plan["step_ns"], plan["n_steps"])
                   for component, name, index, reference, kind in wanted if kind != "boolean"}
        del files, series, execution  # the file observer writes its CSV when released
        for component in {c for c, _, _, _, kind in wanted if kind == "boolean"}:
            names = [name for c, name, _, _, kind in wanted if c == component and kind == "boolean"]
            for name, values in _read_booleans(workdir / "file_observer", component, names,
                                               plan["n_steps"]).items():
                results[f"{component}.{name}"] = values
    except Failure as failure:
        (workdir / "error.json").write_text(json.dumps({"message": str(failure)}))
        sys.stdout.flush()
        os._exit(EXIT_REPORTED)  # skip the teardown of FMU instances that have just failed
    np.savez(workdir / "result.npz", **results)
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--libcosim-worker":
        sys.exit(_libcosim_worker(Path(sys.argv[2])))
    sys.exit("usage: python -m harness.cosim.ssp --libcosim-worker WORKDIR (used by run_ssp_libcosim)")
