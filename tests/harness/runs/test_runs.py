"""Runs through the FMU: Dataset layout, instance reuse, errors, state, extraction."""
from __future__ import annotations

import dataclasses
import math
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from harness.cosim.fmu import FmuError, FmuInstance, FmuInterface, InstancePool, extract_fmu, fmu_sha256
from harness.runs.observables import SLIDING, STICK_SLIP
from harness.runs.run import run_point, simulate
from harness.runs.settings import (InitialCondition, Integration, ObservableSettings, PointSettings, RunSettings,
                              PRESETS)


def settings(fmu, horizon=200.0, **parameters):
    return RunSettings.for_model("A", fmu=str(fmu), parameters=parameters, horizon=horizon, output_interval=2.0)


def test_a_run_is_a_dataset_with_every_output_and_its_settings(fmu_a):
    run = dataclasses.replace(settings(fmu_a, A=0.3, omega=0.9), integration=Integration("rk4", 2e-4),
                              initial=InitialCondition("equilibrium", x_start=1.5))
    ds = simulate(run)
    outputs = FmuInterface(fmu_a).outputs
    assert set(outputs) <= set(ds.data_vars) and "contact" in outputs
    np.testing.assert_array_equal(ds.time.values, 2.0 * np.arange(101))
    assert ds.contact.dtype == bool and ds.coulomb_resets.dtype == np.int64
    # slip_count is the old name of coulomb_resets, kept for one release: the same values.
    np.testing.assert_array_equal(ds.slip_count.values, ds.coulomb_resets.values)
    assert ds.x.values[0] == 1.5
    attrs = ds.attrs
    assert attrs["fmu_sha256"] == fmu_sha256(fmu_a)
    assert attrs["A"] == 0.3 and attrs["omega"] == 0.9 and attrs["k_d"] == PRESETS["scaled"]["k_d"]
    assert attrs["dt"] == 2e-4 and attrs["integrator_name"] == "rk4" and attrs["integrator"] == 1
    assert attrs["initial_condition"] == "equilibrium" and attrs["initial_state"] == 0
    assert attrs["k_t"] == 0.28  # FMU default, filled in
    assert attrs["horizon"] == 200.0 and attrs["output_interval"] == 2.0


def test_a_reused_instance_gives_the_bits_of_a_fresh_one(fmu_a):
    first = settings(fmu_a, A=0.5, omega=0.7)
    other = dataclasses.replace(settings(fmu_a, A=2.0, omega=0.4, k_n=2.0), initial=InitialCondition("given", z_start=2.0))
    fresh = simulate(first)
    with InstancePool() as pool:
        simulate(first, pool)
        simulate(other, pool)
        again = simulate(first, pool)
        assert pool.loads == 1
        assert pool.get(str(fmu_a)).runs == 3
    xr.testing.assert_identical(fresh, again)


def test_fmi_errors_become_exceptions_with_the_fmu_log(fmu_a):
    # The one value refused, after the function's name only (not every name the call set).
    with pytest.raises(FmuError, match=r"^fmi2SetReal refused: k_n = -1\.0 is not admissible: it must be a finite "
                                       r"number > 0 \(normal contact stiffness\)$"):
        simulate(settings(fmu_a, k_n=-1.0))
    with pytest.raises(FmuError, match=r"^fmi2ExitInitializationMode refused: dt = 1 is too large"):
        simulate(dataclasses.replace(settings(fmu_a), integration=Integration("symplectic_euler", dt=1.0)))
    with pytest.raises(KeyError, match="no parameter 'P_l'"):
        simulate(settings(fmu_a, P_l=1.0))
    with InstancePool() as pool:  # an instance that saw a failing start runs normally afterwards
        with pytest.raises(FmuError):
            simulate(settings(fmu_a, k_n=-1.0), pool)
        xr.testing.assert_identical(simulate(settings(fmu_a), pool), simulate(settings(fmu_a)))


def test_fmu_state_restore_continues_bit_for_bit(fmu_a):
    with FmuInstance(fmu_a) as instance:
        instance.start({**PRESETS["scaled"], "A": 0.6, "omega": 0.8, "initial_state": 2})
        read = instance.reader(["x", "z", "vx", "vz", "phi_integral"])
        instance.do_step(0.0, 50.0)
        saved = instance.get_state()
        instance.do_step(50.0, 50.0)
        straight = read()
        instance.set_state(saved)
        instance.do_step(50.0, 50.0)
        assert read() == straight


def _extract(args):
    path, cache = args
    return str(extract_fmu(path, cache))


def test_concurrent_extraction_yields_one_complete_folder(fmu_a, tmp_path):
    with ProcessPoolExecutor(4) as executor:
        folders = set(executor.map(_extract, [(str(fmu_a), str(tmp_path))] * 8))
    assert folders == {str(tmp_path / "fmus" / fmu_sha256(fmu_a))}
    assert (Path(folders.pop()) / "modelDescription.xml").is_file()
    assert [p.name for p in (tmp_path / "fmus").iterdir()] == [fmu_sha256(fmu_a)]  # no staging left over


def test_classification_of_known_cases(fmu_a):
    """Model A, scaled set: stick-slip without vibration, sliding well above A_c."""
    observe_settings = ObservableSettings(transient=1000.0)
    at_rest = run_point(PointSettings(settings(fmu_a, horizon=17_000.0, A=0.0, omega=0.0), observe_settings))
    assert at_rest.regime == STICK_SLIP and at_rest.phi > 50
    assert at_rest.slip_events >= 2
    nominal_slip = 0.5 * 1.0 * 1.0 / PRESETS["scaled"]["k_d"]  # mu_s m g / k_d
    assert at_rest.slip_length_mean == pytest.approx(nominal_slip, rel=0.1)
    assert at_rest.contact_fraction == 1.0

    # A_c(0.5) = 3.0 for the default gamma_n; A = 8 is far above it.
    flying = run_point(PointSettings(settings(fmu_a, horizon=17_000.0, A=8.0, omega=0.5), observe_settings))
    assert flying.regime == SLIDING and flying.phi < 5
    assert flying.slip_events == 0 and math.isnan(flying.stick_time_mean)
    assert flying.contact_fraction < 0.5
    assert flying.drift_velocity == pytest.approx(PRESETS["scaled"]["V_d"], rel=0.02)


OTHER_CORE_SCRIPT = """
import sys
from harness.cosim.fmu import FmuError, FmuInstance
source, other = sys.argv[1], sys.argv[2]
first = FmuInstance(source)
first.start({"k_d": 1e-2})
try:
    FmuInstance(other)
except FmuError as exc:
    print("refused:", str(exc).replace("\\n", " "))
first.close()
print("process still alive")
"""


def test_an_fmu_with_another_core_in_the_same_process_is_refused_cleanly(fmu_a, tmp_path, subprocess_env):
    import subprocess
    import sys

    from fmu_testing import with_another_core

    other = with_another_core(fmu_a, tmp_path / "Other.fmu")
    done = subprocess.run([sys.executable, "-c", OTHER_CORE_SCRIPT, str(fmu_a), other],
                          env=subprocess_env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "refused: fmi2Instantiate refused:" in done.stdout and "different vibroblock core" in done.stdout
    assert done.stdout.strip().endswith("process still alive")



def test_the_harness_takes_switch_names_from_the_fmus_model_description(fmu_path):
    """Integrator and initial-state names are the FMU's (its model description lists
    them), and they are the core registry's."""
    from harness.cosim.fmu import FmuInstance
    from vibroblock.integrators import INTEGRATORS
    from vibroblock.parameters import INITIAL_STATES

    with FmuInstance(fmu_path("A")) as instance:
        assert instance.interface.choices("integrator") == INTEGRATORS
        assert instance.interface.choices("initial_state") == {
            text.split(":")[0]: i for i, text in INITIAL_STATES.items()}
        with pytest.raises(ValueError, match="is not one of"):
            instance.interface.encode("integrator", "leapfrog")
