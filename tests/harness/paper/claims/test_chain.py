"""The main job's chain study (``harness.paper.claims.chain``): its statistics on catalogues
of known laws, its reading of the triggering rows, and its catalogue run through
BlockChain3.fmu against the chain's core."""
import math

import numpy as np
import pytest

from harness.chain.run import CARLSON_LANGER
from harness.paper.claims.chain import catalogue_run, catalogue_statistics, triggering_shape
from vibroblock.chain import Chain


def test_the_statistics_recover_a_drawn_size_law_and_count_each_family():
    rng = np.random.default_rng(3)
    n_blocks, tau = 64, 1.7
    # Small forward events of potency ~ s^-tau above 0.5 (inverse transform), ten
    # system-wide events every 500 tau_0, and back-slips.
    small = 0.5 * rng.uniform(size=4000) ** (-1.0 / (tau - 1.0))
    sizes = np.concatenate([rng.integers(1, n_blocks // 2, size=small.size), np.full(10, n_blocks), [1, 2, 3]])
    potencies = np.concatenate([small, np.full(10, 1e4), [-0.5, -1.0, -0.2]])
    t_start = np.concatenate([rng.uniform(0, 5000, size=small.size), 250.0 + 500.0 * np.arange(10), [1.0, 2.0, 3.0]])
    measured = catalogue_statistics(n_blocks, sizes, potencies, t_start)
    assert measured["events"] == small.size + 13 and measured["system_wide"] == 10
    assert measured["back_slips"] == 3 and measured["small_forward"] == small.size
    fit = measured["size_exponent"]
    assert fit["s_min"] == pytest.approx(np.quantile(small, 0.2))
    assert abs(fit["tau"] - tau) < 3 * fit["sigma"] + 0.02
    # Potency ~ s^-tau is magnitude M = (2/3) log10 s with b = (3/2)(tau - 1) above the
    # completeness (events below M_c missing are the fit's business).
    assert measured["b_value"]["b"] == pytest.approx(1.5 * (tau - 1.0), rel=0.15)
    assert measured["system_wide_recurrence"] == {"mean": pytest.approx(500.0), "std": pytest.approx(0.0, abs=1e-9)}


def test_too_few_events_give_a_stated_reason_not_a_number():
    measured = catalogue_statistics(8, [8, 8], [100.0, 120.0], [10.0, 30.0])
    assert "too few" in measured["size_exponent"]["error"]
    assert measured["system_wide"] == 2 and measured["system_wide_recurrence"]["mean"] == 20.0


def test_the_shape_separates_periods_below_and_above_t0():
    rows = [{"phase": 0.3, "T0": 400.0, "period": p, "advance": a}
            for p, a in ((10.0, 2.0), (100.0, -2.0), (1000.0, -200.0), (2000.0, 100.0))]
    rows += [{"phase": 0.9, "T0": 50.0, "period": p, "advance": a}
             for p, a in ((10.0, 1.0), (100.0, math.nan), (1000.0, 5.0))]
    low, high = triggering_shape(rows)
    assert low["span_below"] == pytest.approx(4.0 / 400.0) and low["span_above"] == pytest.approx(300.0 / 400.0)
    assert low["no_event"] == 0
    # One finite advance on a side gives no span; a run without a large event is counted, not spanned.
    assert math.isnan(high["span_below"]) and high["no_event"] == 1
    assert math.isnan(high["span_above"]) and high["above"] == [5.0]


def test_the_catalogue_run_through_blockchain3_is_the_cores_catalogue(fmu_dir):
    # N set at run time in the FMI 3.0 FMU; the same chain run by the core directly.
    n_blocks, horizon = 12, 3000.0
    parameters = {**CARLSON_LANGER, "cluster_catalog": True}
    run = catalogue_run({"fmu": str(fmu_dir / "BlockChain3.fmu"), "n_blocks": n_blocks, "horizon": horizon,
                         "parameters": parameters})
    core = Chain(n_blocks, clusters=True, **{k: v for k, v in parameters.items() if k != "cluster_catalog"})
    core.start()
    core.advance_to(horizon)
    events = np.asarray(core.events)
    assert len(run["t_start"]) == len(events) >= 5
    # The file holds each float's repr, so the FMU's catalogue is the core's to the bit.
    assert run["t_start"] == events[:, 0].tolist() and run["potency"] == events[:, 4].tolist()
    assert run["n_blocks"] == events[:, 3].astype(int).tolist()
    assert f"N = {n_blocks}" in run["thresholds"] and "clusters" in run["thresholds"]
