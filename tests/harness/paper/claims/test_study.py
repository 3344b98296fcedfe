"""The studies' runner: which integrator each model's runs take."""
from __future__ import annotations

import numpy as np
import pytest

from harness.paper.claims import Runner
from harness.paper.claims.readings import Reading
from harness.paper.claims.study import CORRUGATED_INTEGRATION, CORRUGATED_TOLERANCES, MODEL_A_INTEGRATOR, RESOLUTIONS
from harness.runs.settings import Integration


@pytest.fixture
def runner(tmp_path, fmu_dir):
    return Runner(tmp_path / "store", RESOLUTIONS["tiny"], fmus={m: fmu_dir / f"Block{m}.fmu" for m in "ABC"})


def test_model_a_runs_exactly_where_the_event_driven_scheme_applies(runner):
    assert MODEL_A_INTEGRATOR == "event_driven"
    assert runner.run("A").integration == Integration("event_driven")
    # It does not offer the applied-load bound: that reading (or a study setting it) keeps Euler.
    assert runner.run("A", parameters={"coulomb_normal": 1.0}).integration == Integration("symplectic_euler")
    runner.reading = Reading(coulomb_normal=1)
    assert runner.run("A").integration == Integration("symplectic_euler")


@pytest.mark.parametrize("contact_law, exact", [(1, True), (2, False)])
def test_model_a_keeps_the_exact_flows_only_under_a_linear_contact_law(runner, fmu_dir, contact_law, exact):
    """The law readings (measured by the main job): the contact along the normal is linear (exact flows); the
    no-pull contact is clipped, which event_driven refuses, so its runs take Euler, and
    the FMU accepts the run the runner chose."""
    from harness.runs.run import simulate

    runner.reading = Reading(contact_law=contact_law)
    run = runner.run("A", horizon=1.0)
    assert run.integration == Integration("event_driven" if exact else "symplectic_euler")
    trajectory = simulate(run, outputs=("x",))  # initialized and ran (event_driven would refuse the no-pull law)
    assert trajectory["x"].size == 2 and np.all(np.isfinite(trajectory["x"].values))


def test_a_study_s_own_integration_is_left_alone(runner):
    own = Integration("rk4", dt=1e-3)
    for model in "ABC":
        run = runner.run(model, integration=own)
        assert run.integration == own
        assert "rtol" not in run.parameters


def test_corrugated_models_run_adaptive_at_low_omega_and_the_paper_s_scheme_above(runner):
    for model in "BC":
        run = runner.run(model)
        assert run.integration == CORRUGATED_INTEGRATION
        assert {name: run.parameters[name] for name in CORRUGATED_TOLERANCES} == CORRUGATED_TOLERANCES
        limits = dict(CORRUGATED_INTEGRATION.switch)
        assert set(limits) == {"omega", "plate_speed", "V_d"}
        # omega and V_d at their limits, the plate speed A omega just inside its own.
        at_limits = run.with_parameters({"omega": limits["omega"], "V_d": limits["V_d"],
                                         "A": 0.999 * limits["plate_speed"] / limits["omega"]})
        assert at_limits.fmu_values()["integrator"] == "adaptive"
        for name in ("omega", "V_d", "A"):  # A: beyond the plate-speed limit
            beyond = at_limits.with_parameters({name: at_limits.parameters[name] * 1.01})
            assert beyond.fmu_values()["integrator"] == "symplectic_euler", name
    # A study's own tolerance wins over the default one.
    assert runner.run("C", parameters={"rtol": 1e-9}).parameters["rtol"] == 1e-9
