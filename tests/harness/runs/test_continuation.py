"""Continuation carries the state: where bouncing and embedded states coexist, a ramp
coming down from above the onset stays on the bouncing branch; a fresh start does not."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from harness.runs.continuation import Ramp, continuation, fresh_starts
from harness.cosim.fmu import FmuInstance, InstancePool
from harness.runs.observables import MICRO_SLIP, SLIDING, STICK_SLIP
from harness.runs.settings import ObservableSettings, PointSettings, RunSettings

OMEGA = 0.5
BELOW_ONSET, ABOVE_ONSET = 2.4, 4.0  # model A, default gamma_n: A_c(0.5) = 3.0


def test_the_onset_brackets_the_ramp(subprocess_env):
    # In its own process: an FMU refuses to run next to a core imported from the sources
    # unless both are the same, and the sources may be ahead of the built FMU.
    code = f"import vibroblock; print(float(vibroblock.detachment_amplitude({OMEGA}, gamma_n=0.07)))"
    onset = float(subprocess.run([sys.executable, "-c", code], env=subprocess_env, capture_output=True, text=True,
                                 check=True).stdout)
    assert BELOW_ONSET < 0.85 * onset and ABOVE_ONSET > 1.25 * onset


def test_a_ramp_down_keeps_bouncing_where_a_fresh_start_stays_embedded(fmu_a):
    point = PointSettings(RunSettings.for_model("A", fmu=str(fmu_a), parameters={"omega": OMEGA}, horizon=4000.0),
                          ObservableSettings(transient=1000.0))
    ramp = Ramp("A", (BELOW_ONSET, ABOVE_ONSET))
    with InstancePool() as pool:
        ramped = continuation(point, ramp, pool, keep_states=True)
        fresh = fresh_starts(point, ramp, pool)
    assert list(ramped.direction.values) == ["up", "up", "down"]
    np.testing.assert_array_equal(ramped.A.values, [BELOW_ONSET, ABOVE_ONSET, BELOW_ONSET])

    up_low, top, down_low = (ramped.isel(step=i) for i in range(3))
    fresh_low = fresh.sel(step=0)
    # The first step is a fresh start: same numbers.
    assert up_low.phi.item() == fresh_low.phi.item()
    # Embedded (always in contact) with stick-slip or micro-slips, from a fresh start at A < A_c ...
    assert fresh_low.contact_fraction.item() == 1.0 and fresh_low.regime.item() in (STICK_SLIP, MICRO_SLIP)
    # ... bouncing at the top of the ramp ...
    assert top.contact_fraction.item() < 0.5 and top.regime.item() == SLIDING
    # ... and still bouncing and sliding at the same A < A_c on the way down.
    assert down_low.contact_fraction.item() < 0.5 and down_low.regime.item() == SLIDING
    assert down_low.phi.item() < 1.0 < 100.0 < fresh_low.phi.item()

    # The kept state of the last step continues that branch on a new instance.
    with FmuInstance(fmu_a) as instance:
        instance.start({"k_d": 1e-2})
        instance.set_state(ramped.fmu_state.values[-1])
        read = instance.reader(["contact"])
        time, contacts = float(ramped.window_end.values[-1]), []
        for _ in range(400):
            instance.do_step(time, 1.0)
            time += 1.0
            contacts.append(read()[0])
        assert np.mean(contacts) < 0.5


def test_a_ramp_refuses_a_parameter_that_cannot_change_during_a_run(fmu_a):
    point = PointSettings(RunSettings.for_model("A", fmu=str(fmu_a), horizon=10.0), ObservableSettings(transient=1.0))
    with pytest.raises(ValueError, match="not a tunable parameter"):
        continuation(point, Ramp("k_n", (1.0, 2.0)))


def _ramp_loop(point, pool):
    return continuation(point, Ramp("omega", (0.5, 0.9)), pool)


def test_several_ramps_run_in_parallel_on_dask_workers(fmu_a):
    from harness.runs.sweep import INLINE, Execution, map_with_pool

    points = [PointSettings(RunSettings.for_model("A", fmu=str(fmu_a), parameters={"A": 1.0, "gamma_n": g},
                                                  horizon=800.0), ObservableSettings(transient=200.0))
              for g in (0.07, 0.5)]
    on_dask = map_with_pool(_ramp_loop, points, Execution(workers=2, progress=False))
    inline = map_with_pool(_ramp_loop, points, Execution(scheduler=INLINE, progress=False))
    assert [ds.attrs["gamma_n"] for ds in on_dask] == [0.07, 0.5]
    for a, b in zip(on_dask, inline):
        np.testing.assert_array_equal(a.phi.values, b.phi.values)
