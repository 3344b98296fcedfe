"""examples/onsets_per_law.py locates A_c per contact law and draws it."""
import importlib.util
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "onsets_per_law.py"


def test_the_hertz_contact_moves_the_resonance_dip(tmp_path):
    spec = importlib.util.spec_from_file_location("example_onsets_per_law", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    result = module.run_experiment(omegas=(1.0, 1.2), out=tmp_path)
    linear, hertz = result["located"][0], result["located"][3]
    # The linear contact resonates at omega = 1, the Hertz contact (1.5 k_n at rest) near 1.22.
    assert linear[0] < linear[1] and hertz[1] < hertz[0]
    assert linear[0] == pytest.approx(0.07, rel=1e-3)
    assert (tmp_path / "onsets_per_law.png").stat().st_size > 10_000
