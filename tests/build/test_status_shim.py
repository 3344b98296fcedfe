"""The FMI status shim: problems a Python slave logs become the call's FMI status.

A throwaway pythonfmu slave is built twice: as pythonfmu makes it ("plain") and
with the shim installed ("wrapped").  The slave never raises; it logs bad input
with an error status and keeps its last good state.
"""
from __future__ import annotations

import contextlib
import ctypes
import importlib.util
import math
import shutil
import sys
import textwrap
import threading
import zipfile
from ctypes import byref
from pathlib import Path
from types import SimpleNamespace

import fmpy
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Discard,
    fmi2Error,
    fmi2LastSuccessfulTime,
    fmi2OK,
    fmi2Real,
    fmi2ValueReference,
    fmi2Warning,
    printLogMessage,
)
from fmpy.logging import addLoggerProxy
from fmpy.validation import validate_fmu
from pythonfmu.builder import FmuBuilder

from fmu_testing import FmuLog, do_step, fmu_log, set_real, status_of  # noqa: F401 (fixture)

REPO = Path(__file__).resolve().parents[2]

_spec = importlib.util.spec_from_file_location("status_shim", REPO / "build" / "status_shim.py")
status_shim = importlib.util.module_from_spec(_spec)
sys.modules.setdefault("status_shim", status_shim)
_spec.loader.exec_module(status_shim)

MODEL = "ShimProbe"
GAIN, U, Y = 0, 1, 2  # value references, in registration order

SLAVE_SOURCE = textwrap.dedent(
    '''
    import math

    from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real
    from pythonfmu.enums import Fmi2Status


    class ShimProbe(Fmi2Slave):
        """y integrates gain * u over time; bad input is logged, never raised."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.gain = 2.0
            self.u = 1.0
            self.y = 0.0
            self.register_variable(Real("gain", causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.tunable, setter=self._set_gain))
            self.register_variable(Real("u", causality=Fmi2Causality.input, setter=self._set_u))
            self.register_variable(Real("y", causality=Fmi2Causality.output, initial=Fmi2Initial.exact))

        def _set_gain(self, value):
            if not math.isfinite(value) or value < 0:
                self.log(f"gain must be finite and >= 0, got {value!r}; keeping {self.gain!r}",
                         Fmi2Status.error)
                return
            self.gain = value

        def _set_u(self, value):
            if abs(value) > 100:
                # printf conversions on purpose: the text must reach the host as it is
                self.log(f"u = {value!r} is unusually large (100% = %s %n)", Fmi2Status.warning)
            self.u = value

        def exit_initialization_mode(self):
            self.log(f"initialized with gain {self.gain!r}")

        def do_step(self, current_time, step_size):
            if not step_size > 0:
                self.log(f"step size must be > 0, got {step_size!r}", Fmi2Status.error)
                return True
            if step_size > 1.0:
                self.log(f"step size {step_size!r} is too long", Fmi2Status.discard)
                return False  # pythonfmu itself answers fmi2Discard
            self.y += self.gain * self.u * step_size
            return True
    '''
)

SHIM_EXPORTS = """
    fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
    fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
    fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean
    fmi2SetString fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
    fmi2SerializeFMUstate fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative
    fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep fmi2GetStatus
    fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus
""".split()


# ---- fixtures ---------------------------------------------------------------


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """The probe slave built plain and wrapped, each also extracted."""
    root = tmp_path_factory.mktemp("status_shim")
    script = root / "src" / "shimprobe_slave.py"
    script.parent.mkdir()
    script.write_text(SLAVE_SOURCE)

    plain = FmuBuilder.build_FMU(script, dest=root / "plain")
    wrapped = root / "wrapped" / plain.name
    wrapped.parent.mkdir()
    shutil.copy(plain, wrapped)
    status_shim.wrap_fmu(wrapped)

    return SimpleNamespace(
        plain=plain,
        wrapped=wrapped,
        plain_dir=Path(fmpy.extract(plain, unzipdir=root / "plain_x")),
        wrapped_dir=Path(fmpy.extract(wrapped, unzipdir=root / "wrapped_x")),
        guid=fmpy.read_model_description(plain).guid,
    )


@contextlib.contextmanager
def running(fmus, log, name="probe", wrapped=True, logging_on=False, before_init=None):
    """An initialized FMU2Slave instance; terminated and freed afterwards."""
    slave = FMU2Slave(
        guid=fmus.guid,
        unzipDirectory=str(fmus.wrapped_dir if wrapped else fmus.plain_dir),
        modelIdentifier=MODEL,
        instanceName=name,
    )
    slave.instantiate(callbacks=log.callbacks, loggingOn=logging_on)
    try:
        if before_init is not None:
            before_init(slave)
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        yield slave
        slave.terminate()
    finally:
        slave.freeInstance()


def get(slave, vr) -> float:
    return slave.getReal([vr])[0]


# ---- the wrapped archive ------------------------------------------------------


def test_wrap_moves_pythonfmu_binary_and_installs_shim(fmus):
    with zipfile.ZipFile(fmus.plain) as plain, zipfile.ZipFile(fmus.wrapped) as wrapped:
        plain_names, wrapped_names = set(plain.namelist()), set(wrapped.namelist())
        outer, inner = f"binaries/linux64/{MODEL}.so", f"binaries/linux64/{MODEL}_pythonfmu.so"

        assert wrapped_names == plain_names | {inner}
        assert wrapped.read(inner) == plain.read(outer)
        assert wrapped.read(outer) == status_shim.build_shim().read_bytes()
        for name in plain_names - {outer}:  # win64 binary, resources, modelDescription
            assert wrapped.read(name) == plain.read(name), name


def test_wrapping_twice_only_refreshes_the_shim(fmus, tmp_path):
    again = tmp_path / fmus.wrapped.name
    shutil.copy(fmus.wrapped, again)
    status_shim.wrap_fmu(again)
    with zipfile.ZipFile(fmus.wrapped) as once, zipfile.ZipFile(again) as twice:
        assert twice.namelist() == once.namelist()
        for name in once.namelist():
            assert twice.read(name) == once.read(name), name


def test_command_line_wraps_in_place(fmus, tmp_path):
    target = tmp_path / fmus.plain.name
    shutil.copy(fmus.plain, target)
    assert status_shim.main([str(target)]) == 0
    with zipfile.ZipFile(target) as zf:
        assert f"binaries/linux64/{MODEL}_pythonfmu.so" in zf.namelist()


def test_shim_is_rebuilt_when_source_changes(tmp_path, monkeypatch):
    source = tmp_path / "fmi_status_shim.c"
    source.write_text(status_shim.SHIM_SOURCE.read_text())
    monkeypatch.setattr(status_shim, "SHIM_SOURCE", source)
    monkeypatch.setattr(status_shim, "WORK_DIR", tmp_path / "work")

    first = status_shim.build_shim()
    assert status_shim.build_shim() == first  # cached
    source.write_text(source.read_text() + "\n/* changed */\n")
    second = status_shim.build_shim()
    assert second != first and second.is_file()
    assert not first.exists()  # the stale build is gone


def test_fmpy_validation_passes(fmus):
    assert validate_fmu(str(fmus.wrapped)) == []


# ---- the shim library on its own ---------------------------------------------


def test_shim_exports_the_co_simulation_api_and_survives_null_instances(tmp_path, fmu_log):
    lonely = tmp_path / "Lonely.so"  # no Lonely_pythonfmu.so next to it
    shutil.copy(status_shim.build_shim(), lonely)
    lib = ctypes.CDLL(str(lonely))

    for name in SHIM_EXPORTS:
        assert hasattr(lib, name), name
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    lib.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    assert lib.fmi2GetVersion() == b"2.0"
    assert lib.fmi2GetTypesPlatform() == b"default"

    real = ctypes.c_double(0.0)
    vr = ctypes.c_uint(0)
    assert lib.fmi2SetReal(None, byref(vr), ctypes.c_size_t(1), byref(real)) == fmi2Error
    assert lib.fmi2GetReal(None, byref(vr), ctypes.c_size_t(1), byref(real)) == fmi2Error
    assert lib.fmi2DoStep(None, ctypes.c_double(0.0), ctypes.c_double(0.1), 1) == fmi2Error
    assert lib.fmi2SetDebugLogging(None, 1, ctypes.c_size_t(0), None) == fmi2Error
    assert lib.fmi2Terminate(None) == fmi2Error
    lib.fmi2FreeInstance(None)

    lib.fmi2Instantiate.restype = ctypes.c_void_p
    component = lib.fmi2Instantiate(b"lonely", 1, b"{}", b"file:///nowhere",
                                    byref(fmu_log.callbacks), 0, 0)
    assert component is None
    (record,) = fmu_log.records
    assert record[1] == 4 and "Lonely_pythonfmu.so" in record[3]


# ---- statuses through fmpy ------------------------------------------------------


def test_plain_fmu_hides_the_logged_error(fmus, fmu_log):
    """What the shim is for: pythonfmu alone answers fmi2OK and drops the message."""
    with running(fmus, fmu_log, wrapped=False) as slave:
        assert set_real(slave, GAIN, -1.0) == fmi2OK
        assert get(slave, GAIN) == 2.0
    assert fmu_log.records == []


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf, -math.inf])
def test_bad_set_real_is_an_error_and_the_instance_keeps_working(fmus, fmu_log, bad):
    with running(fmus, fmu_log) as slave:
        slave.setReal([GAIN], [4.0])

        with pytest.raises(FMICallException) as raised:
            slave.setReal([GAIN], [bad])
        assert raised.value.status == fmi2Error
        assert raised.value.function == "fmi2SetReal"

        (record,) = fmu_log.records
        assert record[:3] == ("probe", fmi2Error, "logStatusError")
        assert "gain must be finite and >= 0" in record[3] and "keeping 4.0" in record[3]

        assert get(slave, GAIN) == 4.0  # last good value
        assert do_step(slave, 0.0, 0.5) == fmi2OK
        assert get(slave, Y) == pytest.approx(4.0 * 1.0 * 0.5)
        assert slave.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(0.5)
        assert set_real(slave, GAIN, 1.0) == fmi2OK  # the error does not stick


@pytest.mark.parametrize("bad_step", [0.0, -0.1, math.nan])
def test_bad_do_step_is_an_error_and_a_good_step_follows(fmus, fmu_log, bad_step):
    with running(fmus, fmu_log) as slave:
        with pytest.raises(FMICallException) as raised:
            slave.doStep(0.0, bad_step)
        assert raised.value.status == fmi2Error
        assert [r[1] for r in fmu_log.records] == [fmi2Error]
        assert "step size must be > 0" in fmu_log.records[0][3]
        assert get(slave, Y) == 0.0

        assert do_step(slave, 0.0, 0.25) == fmi2OK
        assert get(slave, Y) == pytest.approx(2.0 * 1.0 * 0.25)


def test_logged_warning_is_returned_as_warning_with_its_text_verbatim(fmus, fmu_log):
    with running(fmus, fmu_log) as slave:
        assert set_real(slave, U, 1000.0) == fmi2Warning
        assert get(slave, U) == 1000.0  # accepted, just flagged
        assert fmu_log.records == [
            ("probe", fmi2Warning, "logStatusWarning", "u = 1000.0 is unusually large (100% = %s %n)")
        ]
        assert set_real(slave, U, 1.0) == fmi2OK


@pytest.mark.parametrize("logging_on", [False, True])
def test_discard_passes_through_its_message_only_in_debug_mode(fmus, fmu_log, logging_on):
    with running(fmus, fmu_log, logging_on=logging_on) as slave:
        fmu_log.clear()
        assert do_step(slave, 0.0, 2.0) == fmi2Discard  # do_step returned False
        expected = [("probe", fmi2Discard, "logStatusDiscard", "step size 2.0 is too long")]
        assert fmu_log.records == (expected if logging_on else [])
        assert do_step(slave, 0.0, 0.5) == fmi2OK


def test_errors_of_pythonfmu_itself_pass_through(fmus, fmu_log):
    with running(fmus, fmu_log) as slave:
        status = status_of(lambda: slave.getDirectionalDerivative([Y], [U], [1.0]))
        assert status == fmi2Error
        # pythonfmu's own message, which it only emits with debug logging on, now reaches the host
        assert any("not supported" in r[3] for r in fmu_log.records)


@pytest.mark.parametrize(
    "logging_on, categories, info_expected",
    [
        (False, None, False),
        (True, None, True),
        (False, ["logAll"], True),
        (True, ["logStatusError"], False),
    ],
)
def test_ok_messages_follow_debug_logging_errors_always_pass(
    fmus, fmu_log, logging_on, categories, info_expected
):
    def configure(slave):
        if categories is not None:
            slave.setDebugLogging(True, categories)

    with running(fmus, fmu_log, logging_on=logging_on, before_init=configure) as slave:
        info = [r for r in fmu_log.records if r[3].startswith("initialized with gain")]
        assert len(info) == int(info_expected)
        assert all(r[1] == fmi2OK for r in info)

        assert set_real(slave, GAIN, -2.0) == fmi2Error
        assert fmu_log.records[-1][1] == fmi2Error


def test_fmu_state_round_trip(fmus, fmu_log):
    with running(fmus, fmu_log) as slave:
        slave.doStep(0.0, 0.5)
        state = slave.getFMUstate()
        saved = slave.deSerializeFMUstate(slave.serializeFMUstate(state))
        slave.doStep(0.5, 0.5)
        assert get(slave, Y) == pytest.approx(2.0)

        slave.setFMUstate(state)
        assert get(slave, Y) == pytest.approx(1.0)
        slave.doStep(0.5, 0.5)
        slave.setFMUstate(saved)
        assert get(slave, Y) == pytest.approx(1.0)
        slave.freeFMUstate(state)
        slave.freeFMUstate(saved)
    assert fmu_log.records == []


def test_two_instances_are_independent(fmus, fmu_log):
    with running(fmus, fmu_log, name="a") as a, running(fmus, fmu_log, name="b") as b:
        assert set_real(b, GAIN, 3.0) == fmi2OK
        assert set_real(a, GAIN, -1.0) == fmi2Error
        assert set_real(b, GAIN, 5.0) == fmi2OK  # a's error does not mark b
        assert do_step(b, 0.0, 0.5) == fmi2OK
        assert do_step(a, 0.0, 0.0) == fmi2Error
        assert do_step(b, 0.5, 0.5) == fmi2OK

        assert get(a, GAIN) == 2.0 and get(a, Y) == 0.0
        assert get(b, GAIN) == 5.0 and get(b, Y) == pytest.approx(5.0)
        assert [r[1] for r in fmu_log.of("a")] == [fmi2Error, fmi2Error]
        assert fmu_log.of("b") == []


def test_instances_on_separate_threads(fmus, fmu_log):
    rounds = 100
    seen: dict[str, list[tuple[int, int]]] = {}

    def drive(slave, name):
        statuses = []
        for i in range(rounds):
            statuses.append((set_real(slave, GAIN, -1.0), set_real(slave, GAIN, 1.0)))
            statuses.append((do_step(slave, 0.1 * i, 0.0), do_step(slave, 0.1 * i, 0.1)))
        seen[name] = statuses

    with running(fmus, fmu_log, name="t1") as t1, running(fmus, fmu_log, name="t2") as t2:
        threads = [threading.Thread(target=drive, args=(s, n)) for s, n in ((t1, "t1"), (t2, "t2"))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for slave in (t1, t2):
            assert get(slave, Y) == pytest.approx(rounds * 0.1)

    for name in ("t1", "t2"):
        assert seen[name] == [(fmi2Error, fmi2OK)] * (2 * rounds)
        assert len(fmu_log.of(name)) == 2 * rounds


# ---- whole runs: plain vs wrapped, fmpy vs libcosim ------------------------------


RUN = dict(start_values={"gain": 3.0, "u": 0.5}, stop_time=1.0, step_size=0.1, output_interval=0.1)


def test_wrapped_run_matches_plain_run(fmus):
    plain = fmpy.simulate_fmu(str(fmus.plain), fmi_type="CoSimulation", **RUN)
    wrapped = fmpy.simulate_fmu(str(fmus.wrapped), fmi_type="CoSimulation", **RUN)

    assert plain["y"][-1] == pytest.approx(3.0 * 0.5 * 1.0)  # the plain FMU still works
    assert np.array_equal(plain["time"], wrapped["time"])
    assert np.array_equal(plain["y"], wrapped["y"])


def fmpy_final_y(fmus, log, steps=10, h=0.1):
    with running(fmus, log, before_init=lambda s: s.setReal([GAIN, U], [3.0, 0.5])) as slave:
        for i in range(steps):
            slave.doStep(i * h, h)
        return get(slave, Y)


def cosim_execution(fmu: Path, step_ns: int):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    execution = CosimExecution.from_step_size(step_ns)
    index = execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="probe"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    override = CosimManipulator.create_override()
    execution.add_manipulator(override)
    return execution, index, observer, override


def test_libcosim_runs_the_wrapped_fmu_like_fmpy(fmus, fmu_log):
    execution, index, observer, _ = cosim_execution(fmus.wrapped, step_ns=100_000_000)
    assert [v.name for v in execution.slave_variables(index)] == [b"gain", b"u", b"y"]
    assert execution.real_initial_value(index, GAIN, 3.0)
    assert execution.real_initial_value(index, U, 0.5)
    assert execution.simulate_until(1_000_000_000)

    cosim_y = observer.last_real_values(index, [Y])[0]
    assert cosim_y == pytest.approx(fmpy_final_y(fmus, fmu_log), rel=1e-12)
    assert cosim_y == pytest.approx(1.5)


def test_libcosim_stops_on_error_status_without_crashing(fmus):
    from libcosimpy._internal import get_last_error_message

    execution, index, observer, override = cosim_execution(fmus.wrapped, step_ns=100_000_000)
    assert execution.step(2)
    y_before = observer.last_real_values(index, [Y])[0]
    assert override.slave_real_values(index, [GAIN], [-5.0])

    assert not execution.step(1)  # the override's fmi2SetReal returned fmi2Error
    assert "gain must be finite" in get_last_error_message()
    assert observer.last_real_values(index, [GAIN, Y]) == [2.0, y_before]
