"""The linear contact that never pulls: N = max(0, k_n delta - gamma_n u_n)."""
import numpy as np
import pytest

from vibroblock import Block
from vibroblock.block import ModelError

BOUNCING = dict(A=2.5, omega=0.9, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, gamma_n=0.3, x_start=3.0)


def normal_forces(contact_law, integrator, t_end=60.0, **options):
    block = Block("A", integrator, 0, True, dt=1e-3, contact_law=contact_law, **BOUNCING, **options)
    block.start()
    forces = []
    for t in np.arange(0.05, t_end, 0.05):
        block.advance_to(t)
        forces.append(block.output("normal_force"))
    return np.array(forces), block.outputs()


@pytest.mark.parametrize("integrator, options", [("rk4", {}), ("adaptive", {"exact_flows": False, "rtol": 1e-9})])
def test_the_contact_never_pulls_where_the_paper_s_dashpot_does(integrator, options):
    clipped, _ = normal_forces("linear_no_pull", integrator, **options)
    paper, _ = normal_forces("linear", integrator, **options)
    assert paper.min() < -0.05  # the separating block is pulled by the dashpot
    assert clipped.min() >= 0.0


@pytest.mark.parametrize("integrator, dt, options, tolerance", [
    ("rk4", 1e-3, {}, 1e-6), ("adaptive", 1e-2, {"exact_flows": False, "rtol": 1e-10}, 1e-7)])
def test_the_energy_balance_books_the_clipped_work_as_dissipated(integrator, dt, options, tolerance):
    """Work in = energy stored + dissipated, with (k_n delta - N) u_n >= 0 dissipated by the
    contact: the residual is the integrator's error, not a law's bookkeeping gap."""
    block = Block("A", integrator, 0, True, dt=dt, contact_law="linear_no_pull", **BOUNCING, **options)
    block.start()
    block.advance_to(60.0)
    out = block.outputs()
    assert out["energy_dissipated"] > 1.0
    assert abs(out["energy_residual"]) < tolerance * out["energy_dissipated"]


def test_on_a_resting_block_it_is_the_paper_s_contact():
    """The clip never acts on a block settling onto a resting plate (N > 0 throughout):
    the same bits as the linear law, and the rest penetration delta_0 = m g / k_n."""
    outputs = []
    for contact_law in ("linear", "linear_no_pull"):
        block = Block("A", "rk4", 1, k_d=0.0, V_d=0.0, k_n=4.0, contact_law=contact_law)
        block.start()
        block.advance_to(2000.0)
        outputs.append(block.outputs())
    assert outputs[0] == outputs[1]
    assert outputs[1]["penetration"] == pytest.approx(0.25, rel=1e-6)


@pytest.mark.parametrize("integrator, reason", [("event_driven", "linear"), ("implicit_contact", "clip")])
def test_integrators_with_the_linear_contact_s_closed_forms_refuse_it(integrator, reason):
    with pytest.raises(ModelError, match=reason):
        Block("A", integrator, contact_law="linear_no_pull").start()
