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


def test_the_chirp_and_the_record_rows_follow_the_reference_at_zero_amplitude():
    """run_signals: one chirp and one record row per phase and acceleration; at zero
    amplitude both give the reference event (advance 0), and no advance exceeds T_0."""
    spec = importlib.util.spec_from_file_location("example_chain_triggering_signals", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.run_signals(phases=(0.9,), accelerations=(0.0, 0.2))
    assert [(r["signal"], r["acceleration"]) for r in rows] == [("chirp", 0.0), ("record", 0.0), ("chirp", 0.2),
                                                                ("record", 0.2)]
    assert rows[0]["advance"] == 0.0 and rows[1]["advance"] == 0.0
    assert all(0.0 <= r["advance"] <= r["T0"] for r in rows)


def test_the_triggered_fractions_count_the_rows():
    spec = importlib.util.spec_from_file_location("example_chain_triggering_fractions", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = [{"acceleration": a, "period": p, "phase": 0.5, "triggered": t}
            for a, p, t in ((0.05, 1.0, False), (0.05, 10.0, True), (0.2, 1.0, False), (0.2, 10.0, True))]
    text = module.triggered_fractions(rows)
    assert text.startswith("triggered: 2/4 bursts") and "by period: 1 0/2, 10 2/2" in text
    assert "by acceleration: 0.05 g 1/2, 0.2 g 1/2" in text and "by phase: 0.5 2/4" in text
