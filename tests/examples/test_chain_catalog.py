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


def test_a_record_shakes_the_chain_and_the_figure_marks_it(fmu_dir, tmp_path):
    """--record: the plate plays obspy's example event; scaled to nothing it leaves the
    catalogue of the still plate, scaled up it is counted against as long a time before."""
    spec = importlib.util.spec_from_file_location("example_chain_catalog_record", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    common = dict(stop_time=1.2e4, record_onset=5000.0, time_scale=200.0)
    still = module.run_experiment(fmu_dir / "BlockChain.fmu", stop_time=1.2e4, out=tmp_path / "still")
    silent = module.run_experiment(fmu_dir / "BlockChain.fmu", out=tmp_path / "silent", record="example",
                                   record_scale=0.0, **common)
    shaken = module.run_experiment(fmu_dir / "BlockChain.fmu", out=tmp_path / "shaken", record="example",
                                   record_scale=0.3, **common)
    assert silent["events"][["t_start", "n_blocks", "potency"]].equals(still["events"][["t_start", "n_blocks",
                                                                                          "potency"]])
    start, end = shaken["record"]["window"]
    assert start == 5000.0 and end > start
    t = shaken["events"].t_start
    assert shaken["record"]["during"] == int(((t >= start) & (t < end)).sum())
    assert not shaken["events"][["t_start", "potency"]].equals(still["events"][["t_start", "potency"]])
    assert (tmp_path / "shaken" / "chain_catalog.png").stat().st_size > 10_000
