"""The Cundall-Strack spring held at the Coulomb bound while sliding."""
import pytest

from vibroblock import Block
from vibroblock.block import ModelError

LAW = "cundall_strack_at_bound"
# Model A, no vibration, the scaled drive: the paper's law stick-slips here.
DRIVEN = dict(k_d=1e-2, V_d=1e-2, gamma_t=5e-3, A=0.0)


def run(friction_law, t_end, integrator="rk4", dt=1e-2, energy=False, **parameters):
    block = Block("A", integrator, 0, energy, dt=dt, friction_law=friction_law, **{**DRIVEN, **parameters})
    block.start()
    block.advance_to(t_end)
    return block.outputs()


def test_a_sliding_block_feels_the_full_coulomb_force_and_slides_steadily():
    """Held at the bound, friction is mu_s N while the block slides: the drive spring's
    m x'' = k_d (V_d t - x) - mu_s m g - gamma_t x' settles (over 2 m / gamma_t = 400) to
    steady sliding at V_d with the stretch (mu_s m g + gamma_t V_d) / k_d."""
    out = run(LAW, 8000.0)
    mu_s, m, g = 0.5, 1.0, 1.0
    assert abs(out["friction_force"]) == pytest.approx(mu_s * out["normal_force"], rel=1e-12)
    assert out["normal_force"] == pytest.approx(m * g, rel=1e-9)
    assert out["vx"] == pytest.approx(DRIVEN["V_d"], rel=1e-4)
    stretch = DRIVEN["V_d"] * 8000.0 - out["x"]
    assert stretch == pytest.approx((mu_s * m * g + DRIVEN["gamma_t"] * DRIVEN["V_d"]) / DRIVEN["k_d"], rel=1e-4)
    # The paper's reset law on the same run is not sliding steadily at the bound.
    paper = run("cundall_strack", 8000.0)
    assert abs(paper["friction_force"]) < 0.9 * mu_s * paper["normal_force"] or abs(paper["vx"] - 1e-2) > 1e-3


def test_before_the_bound_is_met_it_is_the_paper_s_spring():
    """A stick that has not reached the bound: the same bits under both laws."""
    t_end = 0.8 * 0.5 / DRIVEN["k_d"] / DRIVEN["V_d"]  # the drive's pull reaches 0.8 mu_s m g
    assert run(LAW, t_end) == run("cundall_strack", t_end)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4", "implicit_contact"])
def test_the_energy_the_bound_takes_from_the_spring_is_booked_as_dissipated(integrator):
    """Vibrated so that the block also lifts off and lands: work in = stored + dissipated,
    the scaling of the spring counted as dissipated (k_t (F_before^2 - F_after^2) / 2)."""
    out = run(LAW, 3000.0, integrator, dt=1e-3, energy=True, A=1.5, omega=0.9)
    assert out["coulomb_resets"] > 100
    assert out["energy_dissipated"] > 10.0
    assert abs(out["energy_residual"]) < 1e-3 * out["energy_dissipated"]


@pytest.mark.parametrize("integrator, reason", [("adaptive", "meets it continuously"),
                                                ("event_driven", "reset the spring to 0")])
def test_integrators_that_locate_the_bound_as_events_refuse_it(integrator, reason):
    with pytest.raises(ModelError, match=reason):
        Block("A", integrator, friction_law=LAW).start()
