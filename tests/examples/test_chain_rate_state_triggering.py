"""examples/chain_rate_state_triggering.py: periodic loading of the rate-and-state chain
at chosen phases and periods, the clock advances printed.  What is checked is the
machinery, not the study's result."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "chain_rate_state_triggering.py"


def _example():
    spec = importlib.util.spec_from_file_location("example_chain_rate_state_triggering", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_command_line_replaces_only_what_it_is_given():
    from harness.chain.triggering import RATE_STATE_STUDY

    module = _example()
    parser_defaults = module.study_settings(type("Args", (), {"blocks": None, "seed": None, "load_spread": None,
                                                              "friction_law": None})())
    assert parser_defaults == RATE_STATE_STUDY
    single = module.study_settings(type("Args", (), {"blocks": 1, "seed": None, "load_spread": 0.0,
                                                     "friction_law": 4})())
    assert (single.n_blocks, single.load_spread, dict(single.parameters)["friction_law"]) == (1, 0.0, 4)
    assert dict(single.parameters)["rs_a"] == dict(RATE_STATE_STUDY.parameters)["rs_a"]


def test_no_loading_gives_the_reference_event_and_the_rows_cover_the_grid(capsys):
    module = _example()
    rows = module.run_experiment(phases=(0.6,), periods=(20.0, 1000.0), accelerations=(0.0, 0.02))
    assert [(r["acceleration"], r["period"]) for r in rows] == [(0.0, 20.0), (0.0, 1000.0), (0.02, 20.0),
                                                                 (0.02, 1000.0)]
    # The unloaded runs restore the reference cycle and find its event to the bit.
    assert rows[0]["advance"] == 0.0 and rows[1]["advance"] == 0.0
    assert len({r["T0"] for r in rows}) == 1 and rows[0]["T0"] > 20.0
    # T_0 lies between the two periods: one is marked as below it, the other not.
    table = [line for line in capsys.readouterr().out.splitlines() if "below T_0:" in line]
    assert len(table) == 2 and all(line.count("*") == 1 for line in table)
