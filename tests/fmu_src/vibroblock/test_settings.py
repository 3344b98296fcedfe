"""Settings: the FMUs' default integrator and the scene reductions."""
import pytest

from vibroblock.parameters import DEFAULT_INTEGRATOR
from vibroblock.settings import ModelError, Settings


def test_the_default_integrator_runs_every_model_and_reading():
    assert DEFAULT_INTEGRATOR == "adaptive"
    for model in "ABC":
        Settings(model, DEFAULT_INTEGRATOR).check()
        Settings(model, DEFAULT_INTEGRATOR, coulomb_normal=1).check()
    Settings("B", DEFAULT_INTEGRATOR, formulation=1).check()


@pytest.mark.parametrize("option", ["rigid_contact", "coulomb_friction"])
def test_a_reduced_scene_takes_the_default_integrator_or_the_papers_scheme_but_no_other(option):
    """A master that leaves integrator at its default must not be refused a reduction; one
    that chose another scheme is told that the reduction runs its own first-order kernel."""
    Settings("A", DEFAULT_INTEGRATOR, **{option: True}).check()
    Settings("A", "symplectic_euler", **{option: True}).check()
    with pytest.raises(ModelError, match=r"^integrator = rk4 cannot run with rigid_contact or coulomb_friction: .* "
                                         r"set integrator = symplectic_euler \(0\) or leave the default \(adaptive\)$"):
        Settings("A", "rk4", **{option: True}).check()
