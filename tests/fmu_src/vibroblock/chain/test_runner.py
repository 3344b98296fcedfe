"""``Chain``: settings refused in one line, a failed step that loses nothing, state restore."""
import numpy as np
import pytest

from vibroblock import layout as L
from vibroblock.chain import Chain
from vibroblock.settings import ModelError


@pytest.mark.parametrize("settings, message", [
    ({"v_start": 0.1, "v_stop": 0.3}, "0 < v_stop <= v_start"),
    ({"k_c": -1.0}, "k_c = -1.0 must be >= 0"),
    ({"mu_s_spread": 1.0}, "every mu_s stays positive"),
    ({"seed": 1.5}, "non-negative integer"),
    ({"k_c": 1e4}, "too large for the coupling"),
])
def test_settings_that_cannot_run_are_refused_at_the_start(settings, message):
    with pytest.raises(ModelError, match=message):
        Chain(4, **settings).start()


def test_a_chain_needs_a_block():
    with pytest.raises(ModelError, match="at least one block"):
        Chain(0)


def test_parameters_are_fixed_once_running():
    chain = Chain(3)
    chain.start()
    with pytest.raises(ModelError, match="cannot change during a run"):
        chain.set_parameter("k_c", 2.0)


def test_a_step_that_turns_non_finite_is_refused_and_the_state_kept():
    chain = Chain(3)
    chain.start()
    chain.advance_to(10.0)
    kept = chain.Y.copy()
    chain.PRM[1, L.P_KN] = np.nan  # (past the checks) block 2's contact force becomes NaN at once
    with pytest.raises(ModelError, match="non-finite"):
        chain.advance_to(20.0)
    assert chain.Y.tolist() == kept.tolist() and chain.time == 10.0 and np.all(np.isfinite(chain.Y))


def test_a_restored_state_continues_bit_for_bit():
    chain = Chain(8, mu_s_spread=0.3, seed=2, A=0.05, omega=1.3)
    chain.start()
    chain.advance_to(3000.0)
    state = chain.get_state()
    chain.advance_to(9000.0)
    other = Chain(8)
    other.set_state(state)
    other.advance_to(9000.0)
    assert other.Y.tolist() == chain.Y.tolist() and other.events == chain.events and len(chain.events) > 0
