"""Onsets located numerically per contact law (``harness.paper.onsets``)."""
import pytest

from harness.paper.onsets import located_detachment_amplitude
from vibroblock.orbits import detachment_amplitude, friction_loss_amplitude


@pytest.mark.parametrize("omega", [0.5, 2.0])
def test_the_search_finds_the_linear_laws_closed_form(omega):
    """Bracketed from the quasi-static g / omega^2, not from the answer."""
    located = located_detachment_amplitude(omega, 0, tolerance=1e-7)
    assert located == pytest.approx(float(detachment_amplitude(omega)), rel=1e-6)


def test_a_contact_that_cannot_pull_lets_go_between_the_friction_loss_and_the_linear_onset():
    """Between A_N (where the linear law's N first turns negative) and A_c the linear
    dashpot holds the block down by pulling; without the pull it leaves sooner."""
    omega = 14.0  # k_n / gamma_n: A_N = A_c / sqrt(2)
    located = located_detachment_amplitude(omega, 2)
    assert float(friction_loss_amplitude(omega)) * 1.05 < located < 0.97 * float(detachment_amplitude(omega))


def test_a_hertz_contact_is_nearer_the_rigid_limit_below_resonance():
    """Stiffer at rest than the linear contact (1.5 k_n against k_n), the Hertz contact's
    onset lies between the linear law's and the rigid plate's g / omega^2."""
    omega = 0.5
    located = located_detachment_amplitude(omega, 3)
    assert float(detachment_amplitude(omega)) * 1.01 < located < 0.99 / omega**2
