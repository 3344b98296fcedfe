"""examples/chain_catalog.py runs the chain FMU, writes its catalogue and reads it back."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "chain_catalog.py"


def test_the_catalogue_is_written_read_and_summarised(fmu_dir, tmp_path):
    spec = importlib.util.spec_from_file_location("example_chain_catalog", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.run_experiment(fmu_dir / "BlockChain.fmu", stop_time=3e4, out=tmp_path)
    events = result["events"]
    # Every event closed inside the run, in time order, sizes consistent with its blocks.
    assert len(events) > 5 and (events.t_end <= 3e4).all() and events.t_start.is_monotonic_increasing
    assert (events.t_end > events.t_start).all() and events.n_blocks.between(1, 16).all()
    assert result["system_wide"] >= 3 and "recurrence" in result
    assert (tmp_path / "chain_catalog.png").stat().st_size > 10_000
