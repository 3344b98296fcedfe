"""examples/horizontal_shaking.py: the block rides the shaken plate below the closed-form
threshold and slips above it, through BlockA.fmu in fmpy."""
import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "horizontal_shaking.py"


def test_the_block_slips_above_the_closed_form_threshold_only(fmu_dir, tmp_path):
    spec = importlib.util.spec_from_file_location("example_horizontal_shaking", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.main(["--fmu", str(fmu_dir / "BlockA.fmu"), "--out", str(tmp_path)])
    assert [row["resets"] > 0 for row in rows] == [False, False, True, True]
    assert (tmp_path / "horizontal_shaking.png").stat().st_size > 10_000
