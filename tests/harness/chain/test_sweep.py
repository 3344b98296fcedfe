"""Chain sweeps (``harness.chain.sweep``): each point is the chain FMU's run, stored as it
arrives, so a sweep started again computes only what is missing; a record's scaling is an
axis."""
import json

import pytest

from harness.chain.run import simulate_chain
from harness.chain.sweep import ChainSweep, chain_point, chain_sweep, point_item
from harness.runs.sweep import INLINE, Execution, Grid

INLINE_RUN = Execution(scheduler=INLINE, progress=False)
FIXED = (("mu_s_spread", 0.3), ("seed", 1.0))


@pytest.fixture
def sweep(fmu_dir):
    return ChainSweep(fmu=str(fmu_dir / "BlockChain3.fmu"), n_blocks=8, stop_time=8000.0, step=50.0,
                      parameters=FIXED, record="example", record_onset=3000.0, time_scale=100.0)


def test_each_point_is_the_fmus_run_and_a_restart_computes_only_the_missing(sweep, tmp_path, fmu_dir):
    grid = Grid.parse(["A=0,0.3", "omega=0.8"])
    first = chain_sweep(grid, sweep, tmp_path, INLINE_RUN)
    assert dict(first.sizes) == {"A": 2, "omega": 1} and first.attrs["points_computed"] == 2
    # The point at A = 0.3 is BlockChain.fmu's own run (N = 8 there through BlockChain3).
    _, events = simulate_chain(fmu_dir / "BlockChain3.fmu", stop_time=8000.0, step_size=50.0,
                               catalog=tmp_path / "direct.csv",
                               start_values={**dict(FIXED), "A": 0.3, "omega": 0.8, "N": 8})
    assert first.events.sel(A=0.3, omega=0.8).item() == len(events) > 0
    assert first.system_wide.sel(A=0.3, omega=0.8).item() == int((events.n_blocks == 8).sum())
    again = chain_sweep(grid, sweep, tmp_path, INLINE_RUN)
    assert (again.attrs["points_computed"], again.attrs["points_reused"]) == (0, 2)
    assert again.events.values.tolist() == first.events.values.tolist()
    # A sweep killed before its second point finished: that point alone is computed again.
    stored = sorted((tmp_path / "points").glob("*.json"))
    assert len(stored) == 2
    lost = next(p for p in stored if json.loads(p.read_text())["item"]["start_values"]["A"] == 0.3)
    lost.unlink()
    resumed = chain_sweep(grid, sweep, tmp_path, INLINE_RUN)
    assert (resumed.attrs["points_computed"], resumed.attrs["points_reused"]) == (1, 1)
    assert resumed.events.values.tolist() == first.events.values.tolist()


def test_a_record_scaled_to_nothing_is_the_still_plate_and_a_strong_one_counts_its_events(sweep):
    still = chain_point(point_item(sweep, {"A": 0.0}))
    silent = chain_point(point_item(sweep, {"A": 0.0, "record_scale": 0.0}))
    strong = chain_point(point_item(sweep, {"A": 0.0, "record_scale": 0.3}))
    assert silent["events"] == still["events"] and still["events_during_record"] == -1
    assert silent["events_during_record"] >= 0 and strong["events_during_record"] >= 0
    assert strong["events"] != still["events"] or strong["events_during_record"] > silent["events_during_record"]


def test_a_record_axis_needs_a_record(sweep):
    with pytest.raises(ValueError, match="a record_scale axis needs a record"):
        point_item(ChainSweep(fmu=sweep.fmu), {"record_scale": 0.1})
