"""examples/chain_trigger_threshold.py bisects the triggering threshold of bursts and sets
it beside the static prediction."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "chain_trigger_threshold.py"


def test_late_in_the_cycle_the_threshold_is_the_first_blocks_and_the_figure_is_saved(tmp_path):
    spec = importlib.util.spec_from_file_location("example_chain_trigger_threshold", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.run_experiment(phases=(0.9,), n_periods=4, out=tmp_path)
    assert len(rows) == 4 and all(3 * r["period"] < r["T0"] for r in rows)
    for row in rows:
        assert row["above"] / row["below"] <= 1.02
        assert abs(row["above"] / row["first_block"] - 1.0) <= 0.03, row
    # The contact filters bursts faster than its period 2 pi sqrt(m/k_n): P = 2 needs far more.
    shortest, *others = sorted(rows, key=lambda r: r["period"])
    assert shortest["period"] == 2.0 and shortest["above"] > 5 * max(r["above"] for r in others)
    assert (tmp_path / "chain_trigger_threshold.png").stat().st_size > 0
