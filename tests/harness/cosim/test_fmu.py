"""harness.cosim.fmu: the FMU's messages reach the log of the instance that logged them,
and no message is handed to a logger that is gone.

fmpy's native logger proxy calls one process-wide Python logger.  A harness instance that
put its own there left it behind, freed, when it was collected; the next message any FMU
logged through the proxy then called freed memory (a segfault in
fmi2ExitInitializationMode of a later plain fmpy run, or another Python function called).
"""
from __future__ import annotations

import subprocess
import sys

import pytest

from harness.cosim.fmu import FmuError, FmuInstance

REFUSAL = "record_components = 2 plays a three-component seismic record_file in mode 4"

# Harness instances of both FMUs run, fail their initialization and are collected, many
# times over; then a plain fmpy run (fmpy's default callbacks) fails its initialization.
MANY_INSTANCES_THEN_A_FAILING_INIT = """
import gc, sys
from fmpy import simulate_fmu
from harness.cosim.fmu import FmuError, FmuInstance

folder, cache, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
for i in range(rounds):
    for name in ("Excitation", "BlockA"):
        instance = FmuInstance(f"{folder}/{name}.fmu", cache=cache, name=f"{name}{i}")
        instance.start({})
        instance.do_step(0.0, 0.5)
        instance.close()
    failing = FmuInstance(f"{folder}/Excitation.fmu", cache=cache, name=f"failing{i}")
    try:
        failing.start({"record_components": 2})
    except FmuError as exc:
        print("harness refused:", exc.log)
    failing.close()
    del instance, failing
    gc.collect()
try:
    simulate_fmu(f"{folder}/Excitation.fmu", stop_time=1.0, start_values={"mode": 0, "record_components": 2})
except Exception as exc:
    print("raised:", exc)
print("alive")
"""


def test_a_failing_initialization_after_many_collected_instances_returns_fmi2error(quick_fmus, tmp_path,
                                                                                   subprocess_env):
    rounds = 4
    done = subprocess.run([sys.executable, "-c", MANY_INSTANCES_THEN_A_FAILING_INIT, str(quick_fmus),
                           str(tmp_path / "cache"), str(rounds)], capture_output=True, text=True, timeout=600,
                          env=subprocess_env)
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}"
    lines = done.stdout.splitlines()
    # Each harness instance's refusal is in its own log ...
    refused = [line for line in lines if line.startswith("harness refused:")]
    assert len(refused) == rounds and all(REFUSAL in line for line in refused), done.stdout[-2000:]
    # ... and the plain fmpy run's reaches fmpy's default logger once, with fmi2Error.
    printed = [line for line in lines if line.startswith("[ERROR]")]
    assert len(printed) == 1 and REFUSAL in printed[0], done.stdout[-2000:]
    assert "raised: fmi2ExitInitializationMode failed with status 3 (error)." in lines
    assert lines[-1] == "alive"


def test_two_live_instances_keep_their_own_messages(quick_fmus, tmp_path):
    first = FmuInstance(quick_fmus / "Excitation.fmu", cache=tmp_path, name="first")
    second = FmuInstance(quick_fmus / "Excitation.fmu", cache=tmp_path, name="second")
    try:
        with pytest.raises(FmuError) as refused:
            first.start({"record_components": 2})
        assert any(REFUSAL in line for line in refused.value.log), refused.value.log
        second.start({"amplitude": 0.1})
        second.do_step(0.0, 0.5)
        with pytest.raises(FmuError) as again:
            second.set({"amplitude": float("nan")})
        assert not any(REFUSAL in line for line in again.value.log)
        assert any("amplitude" in line for line in again.value.log), again.value.log
    finally:
        first.close()
        second.close()
