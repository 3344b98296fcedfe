"""examples/chain_triggering.py runs bursts through a chain's cycle and prints the advances."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "chain_triggering.py"


def test_every_burst_gives_an_advance_no_larger_than_the_time_left():
    spec = importlib.util.spec_from_file_location("example_chain_triggering", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.run_experiment(phases=(0.5,), periods=(1.0, 10.0), accelerations=(0.3,))
    assert len(rows) == 2
    for row in rows:
        assert 0.0 <= row["advance"] <= row["T0"]
        assert row["triggered"] == (row["advance"] > 0.0)
    # Above the contact's natural frequency the plate's acceleration does not reach the contact.
    assert rows[0]["advance"] == 0.0 and rows[1]["triggered"]
