"""The main job's chain study (``harness.paper.claims.chain``): its reading of the
triggering rows, and its catalogue run through BlockChain3.fmu against the chain's core
(its statistics: tests/harness/chain/test_statistics.py)."""
import math

import numpy as np
import pytest

from harness.chain.run import CARLSON_LANGER
from harness.paper.claims.chain import catalogue_run, triggering_shape
from vibroblock.chain import Chain


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
