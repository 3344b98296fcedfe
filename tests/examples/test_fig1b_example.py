"""examples/fig1b_stick_slip_vs_sliding.py runs and shows the two regimes."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fig1b_stick_slip_vs_sliding.py"


def test_fig1b_example_separates_stick_slip_from_sliding(fmu_path, tmp_path):
    spec = importlib.util.spec_from_file_location("example_fig1b", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    runs = module.run_experiment(fmu=fmu_path("A"), out_dir=tmp_path)
    assert (tmp_path / "fig1b.png").is_file()
    stick, slide = runs["stick-slip"], runs["sliding"]
    # below the onset the block is embedded, above it bounces: the chosen frequencies straddle A_c
    assert stick["onset"] > module.AMPLITUDE > slide["onset"]
    assert stick["phi"] > 50 * slide["phi"]
