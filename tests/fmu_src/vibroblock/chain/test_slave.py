"""The BlockChain facade (``vibroblock.chain.slave``) in this process, without building the
FMU: its ``jump_sticks`` parameter."""
from pythonfmu import Fmi2Slave

from vibroblock.chain import Chain
from vibroblock.chain.slave import chain_fmu


@chain_fmu(4)
class FourBlocks(Fmi2Slave):
    """A chain of four blocks."""


def facade():
    slave = FourBlocks(instance_name="chain", resources=None)
    return slave, {v.name: v for v in slave.vars.values()}


def positions(variables):
    return [variables[f"x[{i}]"].getter() for i in range(1, 5)]


def test_jump_sticks_is_off_by_default_and_on_gives_the_jumped_cores_bits_and_restores():
    slave, variables = facade()
    assert variables["jump_sticks"].getter() is False
    variables["jump_sticks"].setter(True)
    variables["mu_s_spread"].setter(0.3)
    slave.setup_experiment(0.0)
    assert slave.exit_initialization_mode()
    core = Chain(4, jump_sticks=True, mu_s_spread=0.3)
    core.start()
    for t in (2000.0, 4000.0):
        assert slave.do_step(t - 2000.0, 2000.0)
        core.advance_to(t)
    assert positions(variables) == core.x.tolist() and core.jumped_steps > 0
    state = slave._get_fmu_state()
    slave.do_step(4000.0, 6000.0)
    first = positions(variables), variables["event_count"].getter()
    slave._set_fmu_state(state)
    slave.do_step(4000.0, 6000.0)
    assert (positions(variables), variables["event_count"].getter()) == first and first[1] > 0


def test_jump_sticks_with_the_energy_balance_is_refused_with_its_reason():
    slave, variables = facade()
    variables["jump_sticks"].setter(True)
    variables["energy_balance"].setter(True)
    slave.setup_experiment(0.0)
    assert not slave.exit_initialization_mode()
    assert "jump_sticks with energy_balance" in slave.log_queue[-1].msg
