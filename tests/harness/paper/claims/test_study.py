"""The studies' runner: which integrator each model's runs take."""
from __future__ import annotations

import pytest

from harness.paper.claims import Runner
from harness.paper.claims.readings import Reading
from harness.paper.claims.study import MODEL_A_INTEGRATOR, RESOLUTIONS
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


def test_a_study_s_own_integration_and_other_models_are_left_alone(runner):
    own = Integration("rk4", dt=1e-3)
    assert runner.run("A", integration=own).integration == own
    for model in "BC":
        assert runner.run(model).integration == Integration()
