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
    ({"load_spread": 1.0}, "every block keeps a weight"),
    ({"seed": 1.5}, "non-negative integer"),
    ({"friction_law": 3, "rs_D_c_spread": 1.0}, "every rs_D_c keeps its sign"),
    ({"rs_a_spread": 0.2}, "rs_a_spread = 0.2 spreads rs_a, a parameter of rate-and-state friction"),
    ({"friction_law": 2, "rs_b_spread": 0.1}, "friction_law = 2 has no rs_b"),
    ({"k_c": 1e4}, "too large for the coupling"),
])
def test_settings_that_cannot_run_are_refused_at_the_start(settings, message):
    with pytest.raises(ModelError, match=message):
        Chain(4, **settings).start()


def test_the_heterogeneity_is_the_seeded_draw_of_the_documented_distribution():
    """mu_s (1 + mu_s_spread u_i) and g (1 + load_spread u'_i), u and u' the first and the
    next N uniform draws in [-1, 1] of default_rng(seed): the same seed gives the same
    blocks, another seed others, and spreading the loads leaves the mu_s draws as they were."""
    n = 6
    chain = Chain(n, mu_s_spread=0.3, load_spread=0.2, seed=11)
    chain.start()
    draws = np.random.default_rng(11).uniform(-1.0, 1.0, 2 * n)
    assert chain.mu_s.tolist() == (0.5 * (1.0 + 0.3 * draws[:n])).tolist()
    assert chain.gravity.tolist() == (1.0 * (1.0 + 0.2 * draws[n:])).tolist()
    again, other, mu_s_only = (Chain(n, mu_s_spread=0.3, load_spread=ls, seed=s) for s, ls in ((11, 0.2), (12, 0.2),
                                                                                              (11, 0.0)))
    for c in (again, other, mu_s_only):
        c.start()
    assert again.gravity.tolist() == chain.gravity.tolist() and again.Y.tolist() == chain.Y.tolist()
    assert len(set(other.gravity.tolist()) & set(chain.gravity.tolist())) == 0
    assert mu_s_only.mu_s.tolist() == chain.mu_s.tolist() and set(mu_s_only.gravity.tolist()) == {1.0}


def test_the_rate_state_spreads_draw_after_the_loads_and_leave_them_as_they_were():
    """rs_a, rs_b, rs_D_c: the model's value (1 + spread u), u the third, fourth and fifth
    batches of N draws of default_rng(seed), so spreading them leaves mu_s and g as they
    were; each block's values reach its parameter row."""
    n, law = 5, {"friction_law": 3, "rs_a": 0.01, "rs_b": 0.015, "rs_D_c": 0.1}
    chain = Chain(n, mu_s_spread=0.2, load_spread=0.1, rs_a_spread=0.3, rs_b_spread=0.2, rs_D_c_spread=0.5, seed=4,
                  **law)
    chain.start()
    draws = np.random.default_rng(4).uniform(-1.0, 1.0, 5 * n).reshape(5, n)
    for k, (name, spread) in enumerate((("rs_a", 0.3), ("rs_b", 0.2), ("rs_D_c", 0.5)), start=2):
        expected = (law[name] * (1.0 + spread * draws[k])).tolist()
        assert chain.PRM[:, L.slot(name)].tolist() == expected, name
    plain = Chain(n, mu_s_spread=0.2, load_spread=0.1, seed=4, **law)
    plain.start()
    assert plain.mu_s.tolist() == chain.mu_s.tolist() and plain.gravity.tolist() == chain.gravity.tolist()
    assert set(plain.PRM[:, L.slot("rs_a")].tolist()) == {0.01}


def test_each_block_starts_at_rest_under_its_own_weight():
    """The linear contact's rest penetration is m g_i / k_n for each block's own g_i."""
    chain = Chain(5, load_spread=0.4, seed=3, A=0.0)
    chain.start()
    penetration = chain.plate_height() - chain.Y[:, L.Y_Z]
    np.testing.assert_allclose(penetration, chain.gravity * 1.0 / 1.0, rtol=1e-12)


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
