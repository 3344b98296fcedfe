"""The cluster catalogue (``vibroblock.chain.clusters``): events as slipping blocks
connected in space and time."""
import pytest

from vibroblock.chain import Chain

VIBRATED = dict(A=0.3, omega=0.8, dt=1e-2)


def test_a_lone_block_gives_the_chain_wide_catalogue():
    """With one block both catalogues follow the same speed through the same thresholds."""
    chains = [Chain(1, clusters=clusters, **VIBRATED) for clusters in (False, True)]
    for chain in chains:
        chain.start()
        chain.advance_to(20000.0)
    wide, clusters = chains[0].events, chains[1].events
    assert len(wide) > 3 and len(clusters) == len(wide)
    for a, b in zip(wide, clusters):
        assert a[:4] == b[:4] and a[5] == b[5]
        assert b[4] == pytest.approx(a[4], rel=1e-12)  # the slip summed step by step


def test_both_catalogues_count_the_same_slip():
    """A coupled, heterogeneous chain on a still plate: the clusters split what the
    chain-wide catalogue merges, and together hold about the same slip (they differ by
    the slow motion below v_stop that a chain-wide event also counts)."""
    runners = [Chain(16, clusters=clusters, mu_s_spread=0.3, seed=4) for clusters in (False, True)]
    for runner in runners:
        runner.start()
        runner.advance_to(20000.0)
    wide, clusters = runners[0].events, runners[1].events
    assert len(clusters) > len(wide) > 3
    assert sum(e[4] for e in clusters) == pytest.approx(sum(e[4] for e in wide), rel=0.05)
    assert max(e[3] for e in clusters) == 16 and min(e[3] for e in clusters) < 16


@pytest.mark.parametrize("kicked, expected", [((0, 4), [1, 1]), ((0, 1, 2), [3])])
def test_neighbours_slipping_together_are_one_event_apart_they_are_two(kicked, expected):
    """Uncoupled blocks kicked at the start: adjacent ones share a cluster."""
    chain = Chain(5, clusters=True, k_c=0.0, V_d=0.0, gamma_t=0.5)
    chain.start()
    chain.set_velocities([2.0 if i in kicked else 0.0 for i in range(5)])
    chain.advance_to(200.0)
    assert [int(e[3]) for e in chain.events] == expected
    assert sorted(int(e[2]) for e in chain.events) == sorted({min(kicked)} | ({4} if 4 in kicked else set()))
