"""libcosim master against fmpy, on small FMUs built here with pythonfmu.

Comparisons are bit for bit (``assert_array_equal``): both masters call the same
FMU code with the same parameter and input values in the same order, and these
FMUs never compute with the time values a master passes (they count their own
internal steps), so there is nothing that could round differently.  The one
output that echoes the master's time (``t_seen``) is compared to 1e-12 against
fmpy and bit for bit against libcosim's documented nanosecond clock.
"""

from __future__ import annotations

import shutil
import textwrap

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from pythonfmu.builder import FmuBuilder

from harness.cosim.masters import LibcosimError, SetupError, run_libcosim, run_libcosim_system

OSCILLATOR = '''
from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status


class VbTestOscillator(Fmi2Slave):
    """Damped oscillator x'' = -w^2 x - c x' + gain u, symplectic Euler at a fixed dt."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.omega0, self.zeta, self.x0, self.v0 = 2.0, 0.1, 1.0, 0.0
        self.dt, self.gain, self.fail_after = 1e-3, 1.0, -1.0
        self.substeps, self.damped = 1, True
        self.u, self.brake = 0.0, False
        self.x = self.v = self.t_seen = 0.0
        self.n_dt, self.n_internal, self.positive = 0, 0, False
        for name in ("omega0", "zeta", "x0", "v0", "dt", "gain", "fail_after"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
        self.register_variable(Integer("substeps", causality=Fmi2Causality.parameter,
                                       variability=Fmi2Variability.fixed))
        self.register_variable(Boolean("damped", causality=Fmi2Causality.parameter,
                                       variability=Fmi2Variability.fixed))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Boolean("brake", causality=Fmi2Causality.input,
                                       variability=Fmi2Variability.discrete))
        for name in ("x", "v", "t_seen"):
            self.register_variable(Real(name, causality=Fmi2Causality.output, initial=Fmi2Initial.exact))
        self.register_variable(Integer("n_internal", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete, initial=Fmi2Initial.exact))
        self.register_variable(Boolean("positive", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete, initial=Fmi2Initial.exact))

    def exit_initialization_mode(self):
        if not self.dt > 0.0:
            raise ValueError(f"dt = {self.dt} must be positive")
        self.x, self.v = self.x0, self.v0
        self.positive = self.x > 0.0

    def do_step(self, current_time, step_size):
        n = int(round(step_size / self.dt))
        if 0.0 <= self.fail_after <= (self.n_dt + n) * self.dt:
            self.log(f"oscillator gives up after {self.n_dt} steps of dt", Fmi2Status.error)
            return False
        h = self.dt / self.substeps
        k = self.omega0 ** 2
        c = 2.0 * self.zeta * self.omega0 * (3.0 if self.brake else 1.0) if self.damped else 0.0
        for _ in range(n * self.substeps):
            self.v += h * (-k * self.x - c * self.v + self.gain * self.u)
            self.x += h * self.v
        self.n_dt += n
        self.n_internal += n * self.substeps
        self.positive = self.x > 0.0
        self.t_seen = current_time + step_size
        return True
'''

SOURCE = '''
import math

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class VbTestSource(Fmi2Slave):
    """y = amp sin(omega n dt + phi0) on its own step count n; on = y > 0."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.amp, self.omega, self.phi0, self.dt = 1.0, 3.0, 0.3, 1e-3
        self.n = 0
        self.y, self.on = 0.0, False
        for name in ("amp", "omega", "phi0", "dt"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
        self.register_variable(Real("y", causality=Fmi2Causality.output, initial=Fmi2Initial.exact))
        self.register_variable(Boolean("on", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete, initial=Fmi2Initial.exact))

    def _update(self):
        self.y = self.amp * math.sin(self.omega * self.n * self.dt + self.phi0)
        self.on = self.y > 0.0

    def exit_initialization_mode(self):
        self._update()

    def do_step(self, current_time, step_size):
        self.n += int(round(step_size / self.dt))
        self._update()
        return True
'''

OSC_OUTPUTS = ["x", "v", "n_internal", "positive"]
OSC_START = {"omega0": 3.0, "zeta": 0.2, "x0": 0.8, "substeps": 2, "damped": False}


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fmus")
    built = {}
    for module, source in (("vb_test_oscillator", OSCILLATOR), ("vb_test_source", SOURCE)):
        script = folder / f"{module}.py"
        script.write_text(textwrap.dedent(source))
        built[module] = str(FmuBuilder.build_FMU(script, dest=folder))
    return built["vb_test_oscillator"], built["vb_test_source"]


def fmpy_run(fmu, *, start_values, stop_time, step_size, outputs, start_time=0.0, input=None):
    return simulate_fmu(fmu, start_time=start_time, stop_time=stop_time, output_interval=step_size,
                        start_values=start_values, output=outputs, input=input)


def assert_same(libcosim, reference, names):
    assert list(libcosim) == ["time", *names]
    np.testing.assert_array_equal(libcosim["time"], reference["time"])
    for name in names:
        assert libcosim[name].dtype == reference[name].dtype, name
        np.testing.assert_array_equal(libcosim[name], reference[name], err_msg=name)


def libcosim_fmu_times(start_time, step_size, n_steps):
    """Times an FMU sees in libcosim: integer nanoseconds divided by 1e9."""
    ns = round(start_time * 1e9) + np.arange(n_steps + 1, dtype=np.int64) * round(step_size * 1e9)
    return ns / 1e9


@pytest.mark.parametrize("start_time", [0.0, 2.5])
def test_single_fmu_matches_fmpy_bit_for_bit(fmus, start_time):
    osc, _ = fmus
    settings = dict(start_values=OSC_START, start_time=start_time, stop_time=start_time + 2.0, step_size=0.01)
    reference = fmpy_run(osc, outputs=[*OSC_OUTPUTS, "t_seen"], **settings)
    result = run_libcosim(osc, outputs=[*OSC_OUTPUTS, "t_seen"], **settings)

    assert len(result["time"]) == 201 and result["time"][0] == start_time
    assert_same({k: v for k, v in result.items() if k != "t_seen"}, reference, OSC_OUTPUTS)
    assert result["n_internal"][-1] == 4000 and result["positive"].any() and not result["positive"].all()
    # The master's time as the FMU saw it: libcosim's nanosecond clock, fmpy's start + k h.
    np.testing.assert_array_equal(result["t_seen"][1:], libcosim_fmu_times(start_time, 0.01, 200)[1:])
    np.testing.assert_allclose(result["t_seen"], reference["t_seen"], rtol=0, atol=1e-12)

    # The start values took effect (the default parameters give another trajectory) ...
    default = run_libcosim(osc, stop_time=start_time + 2.0, start_time=start_time, step_size=0.01,
                           outputs=["x", "n_internal"])
    assert not np.array_equal(default["x"], result["x"])
    assert default["n_internal"][-1] == 2000  # the Integer start value took effect too
    # ... and a second run in this process repeats the first exactly.
    again = run_libcosim(osc, outputs=OSC_OUTPUTS, **settings)
    for name in OSC_OUTPUTS:
        np.testing.assert_array_equal(again[name], result[name])


def test_inputs_match_fmpy_input_table(fmus):
    osc, _ = fmus
    h, stop = 0.01, 3.0

    def inputs(t):
        return {"u": 0.5 * np.sin(4.0 * t) + 0.1 * t, "brake": bool(1.0 <= t < 2.0)}

    times = np.arange(round(stop / h) + 1) * h
    table = np.zeros(len(times), dtype=[("time", np.float64), ("u", np.float64), ("brake", np.bool_)])
    table["time"] = times
    for k, t in enumerate(times):
        table["u"][k], table["brake"][k] = inputs(t)["u"], inputs(t)["brake"]

    settings = dict(start_values=OSC_START | {"damped": True}, stop_time=stop, step_size=h, outputs=OSC_OUTPUTS)
    reference = fmpy_run(osc, input=table, **settings)
    result = run_libcosim(osc, inputs=inputs, **settings)
    assert_same(result, reference, OSC_OUTPUTS)

    # The Boolean input acts from the step that starts at t = 1.0 (row 100) on, not before.
    no_brake = run_libcosim(osc, inputs=lambda t: {"u": inputs(t)["u"], "brake": False}, **settings)
    np.testing.assert_array_equal(no_brake["x"][:101], result["x"][:101])
    assert no_brake["x"][101] != result["x"][101]


class HandMaster:
    """Two FMU2Slave instances stepped in lockstep, in libcosim's order (or Gauss-Seidel)."""

    def __init__(self, fmus, tmp_path):
        self.slaves, self.dirs, self.vrs = {}, [], {}
        for name, path in fmus.items():
            md = read_model_description(path)
            unzipped = extract(path, unzipdir=tmp_path / f"unzip_{name}")
            self.dirs.append(unzipped)
            self.slaves[name] = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                                          modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
            self.vrs[name] = {v.name: (v.valueReference, v.type) for v in md.modelVariables}

    def get(self, name, var):
        vr, kind = self.vrs[name][var]
        return getattr(self.slaves[name], f"get{kind}")([vr])[0]

    def set(self, name, var, value):
        vr, kind = self.vrs[name][var]
        getattr(self.slaves[name], f"set{kind}")([vr], [value])

    def run(self, *, start_values, connections, outputs, times, gauss_seidel=False):
        def transfer(source=None):
            for src, src_var, dst, dst_var in connections:
                if source is None or src == source:
                    self.set(dst, dst_var, self.get(src, src_var))

        def record():
            for name, names in outputs.items():
                for var in names:
                    rows[f"{name}.{var}"].append(self.get(name, var))

        rows = {f"{name}.{var}": [] for name, names in outputs.items() for var in names}
        for name, slave in self.slaves.items():
            slave.instantiate()
            for var, value in start_values.get(name, {}).items():
                self.set(name, var, value)
            slave.setupExperiment(startTime=times[0])
            slave.enterInitializationMode()
        for _ in self.slaves:  # libcosim: one transfer round per slave in initialization mode
            transfer()
        for slave in self.slaves.values():
            slave.exitInitializationMode()
        transfer()
        record()
        for t, t_next in zip(times[:-1], times[1:]):
            for name, slave in self.slaves.items():
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
                if gauss_seidel:
                    transfer(source=name)
            if not gauss_seidel:
                transfer()
            record()
        for slave in self.slaves.values():
            slave.terminate()
            slave.freeInstance()
        for folder in self.dirs:
            shutil.rmtree(folder, ignore_errors=True)
        return {key: np.array(values) for key, values in rows.items()}


def test_two_fmu_system_matches_hand_composition(fmus, tmp_path):
    osc, src = fmus
    h, stop = 0.01, 2.0
    connections = [("src", "y", "osc", "u"), ("src", "on", "osc", "brake")]
    start_values = {"osc": {"omega0": 2.5, "gain": 4.0}, "src": {"omega": 5.0, "amp": 1.5}}
    outputs = {"osc": ["x", "v", "positive", "t_seen"], "src": ["y", "on"]}
    result = run_libcosim_system({"osc": osc, "src": src}, connections=connections, start_values=start_values,
                                 outputs=outputs, stop_time=stop, step_size=h)

    times = libcosim_fmu_times(0.0, h, round(stop / h))  # the time values libcosim passes
    jacobi = HandMaster({"osc": osc, "src": src}, tmp_path).run(
        start_values=start_values, connections=connections, outputs=outputs, times=times)
    assert list(result) == ["time", *jacobi]
    for key, values in jacobi.items():
        np.testing.assert_array_equal(result[key], values, err_msg=key)
    assert result["src.on"].any() and not result["src.on"].all()

    # The order matters and libcosim's is Jacobi: feeding the source's new output
    # into the same step (Gauss-Seidel, source first) gives another trajectory.
    seidel = HandMaster({"src": src, "osc": osc}, tmp_path).run(
        start_values=start_values, connections=connections, outputs=outputs, times=times, gauss_seidel=True)
    assert not np.array_equal(result["osc.x"], seidel["osc.x"])


def test_unknown_names_and_wrong_types_are_refused_before_running(fmus):
    osc, src = fmus
    grid = dict(stop_time=1.0, step_size=0.01)
    with pytest.raises(SetupError, match=r"no variable named 'xx' \(did you mean 'x'"):
        run_libcosim(osc, outputs=["xx"], **grid)
    with pytest.raises(SetupError, match=r"start_values: .*no variable named 'omega'.*'omega0'"):
        run_libcosim(osc, start_values={"omega": 2.0}, outputs=["x"], **grid)
    with pytest.raises(SetupError, match=r"substeps \(Integer\) cannot take 2\.5 of type float"):
        run_libcosim(osc, start_values={"substeps": 2.5}, outputs=["x"], **grid)
    with pytest.raises(SetupError, match=r"substeps = 'many' is not one of its named values \(it has none\)"):
        run_libcosim(osc, start_values={"substeps": "many"}, outputs=["x"], **grid)
    with pytest.raises(SetupError, match=r"damped \(Boolean\) cannot take 1 of type int; give a bool"):
        run_libcosim(osc, start_values={"damped": 1}, outputs=["x"], **grid)
    with pytest.raises(SetupError, match=r"inputs: .*x has causality 'output'"):
        run_libcosim(osc, inputs=lambda t: {"x": 1.0}, outputs=["x"], **grid)
    with pytest.raises(SetupError, match=r"there is no instance 'source'"):
        run_libcosim_system({"osc": osc, "src": src}, connections=[("source", "y", "osc", "u")],
                            outputs={"osc": ["x"]}, **grid)
    with pytest.raises(SetupError, match=r"src\.y is real but osc\.brake is boolean"):
        run_libcosim_system({"osc": osc, "src": src}, connections=[("src", "y", "osc", "brake")],
                            outputs={"osc": ["x"]}, **grid)
    with pytest.raises(SetupError, match=r"whole number of nanoseconds"):
        run_libcosim(osc, outputs=["x"], stop_time=1.0, step_size=1 / 3 * 1e-3)
    with pytest.raises(SetupError, match=r"whole number of steps"):
        run_libcosim(osc, outputs=["x"], stop_time=1.005, step_size=0.01)


def test_fmu_error_during_a_step_carries_the_fmu_log(fmus):
    osc, _ = fmus
    with pytest.raises(LibcosimError) as caught:
        run_libcosim(osc, start_values={"fail_after": 0.5}, outputs=["x"], stop_time=1.0, step_size=0.01)
    error = caught.value
    assert "t = 0.49" in error.message and "step 50 of 100" in error.message
    assert "Step not complete" in error.message
    assert any("[error" in line and "gives up after 490 steps of dt" in line for line in error.fmu_log)
    assert "gives up after 490" in str(error)


def test_fmu_error_during_initialization_aborts_only_the_libcosim_process(fmus):
    osc, _ = fmus
    with pytest.raises(LibcosimError) as caught:
        run_libcosim(osc, start_values={"dt": 0.0}, outputs=["x"], stop_time=1.0, step_size=0.01)
    error = caught.value
    assert error.returncode is not None and error.returncode < 0  # SIGABRT from std::terminate
    assert "exitInitializationMode" in error.message and "initialisation" in error.message
    assert any("[fatal" in line for line in error.fmu_log)
    # This process is unaffected: the next run works.
    result = run_libcosim(osc, outputs=["x"], stop_time=0.1, step_size=0.01)
    assert result["x"][0] == 1.0 and len(result["x"]) == 11
