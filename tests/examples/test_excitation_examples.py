"""The excitation examples run end to end (small settings) and save what they promise."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def example(name):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_record_response_from_a_two_column_file(fmu_path, tmp_path):
    t = np.arange(0.0, 20.0, 0.01)
    acc = np.exp(-((t - 8.0) / 1.5) ** 2) * np.sin(2 * np.pi * 3.0 * t)  # m/s^2, a 3 Hz burst
    record = tmp_path / "burst.csv"
    np.savetxt(record, np.column_stack([t, acc]), delimiter=",", header="time,acceleration")
    out = example("record_response").run_experiment(record, fmu=fmu_path("A"), out_dir=str(tmp_path),
                                                    quantity="acceleration", unit="m/s^2", peak_g=1.3,
                                                    step_size=0.5)
    assert out["figure"].is_file()
    summary = out["summary"]
    assert summary["peak_plate_acceleration_g"] == pytest.approx(1.3, rel=0.05)
    assert summary["contact_fraction"] < 1.0 and summary["min_normal_force_mg"] < 0.1  # 1.3 g lifts it off


def test_triggering_example_saves_figure_and_table(fmu_path, tmp_path):
    result = example("triggering").run_experiment(fmu_path("A"), tmp_path, phases=(0.9,), peak_accelerations=(0.3,))
    assert (tmp_path / "triggering.png").is_file() and (tmp_path / "triggering.csv").is_file()
    assert "early slip" in (tmp_path / "triggering.md").read_text()
    assert result.branches[0].clock_advance > 0


def test_composition_example_prints_the_step_table(fmu_dir, tmp_path):
    rows = example("excitation_composition").run_experiment(steps=(0.5,), horizon=300.0, out_dir=tmp_path,
                                                            fmu_dir=fmu_dir)
    by_master = {r["master"]: r for r in rows}
    assert set(by_master) == {"internal", "input", "ssp_fmpy", "ssp_libcosim"}
    assert by_master["input"]["max_z_error"] == by_master["ssp_libcosim"]["max_z_error"] < 5e-3
    assert (tmp_path / "communication_step.png").is_file()
