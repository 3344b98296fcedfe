"""The command line: run, sweep from a grid file, continuation; `python -m harness`."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from harness.runs import cli
from harness.runs.dataset_files import load_dataset


def last_json(text: str) -> dict:
    return json.loads(text.strip().splitlines()[-1])


def test_python_m_harness_run_writes_trajectories_and_prints_observables(fmu_a, tmp_path, subprocess_env):
    out = tmp_path / "run.nc"
    done = subprocess.run([sys.executable, "-m", "harness", "run", "--fmu", str(fmu_a), "--set", "A=0.2",
                           "--set", "omega=0.7", "--horizon", "300", "--interval", "2", "--transient", "100",
                           "--integrator", "rk4", "--no-progress", "--out", str(out)],
                          env=subprocess_env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    result = last_json(done.stdout)
    assert result["window_start"] == 100.0 and result["window_end"] == 300.0 and result["regime"] == "stuck"
    ds = load_dataset(out)
    assert ds.sizes["time"] == 151 and ds.attrs["A"] == 0.2 and ds.attrs["integrator_name"] == "rk4"
    assert ds.attrs["observed_regime"] == "stuck"


def test_sweep_from_a_toml_grid_file_with_a_derived_parameter(fmu_a, tmp_path, capsys):
    grid_file = tmp_path / "grid.toml"
    grid_file.write_text('[axes]\nk_n = [1.0, 2.0]\nratio = "10:20:2"\n\n[derived]\ngamma_n = "k_n / ratio"\n')
    out = tmp_path / "sweep.zarr"
    code = cli.main(["sweep", "--fmu", str(fmu_a), "--grid-file", str(grid_file), "--horizon", "100",
                     "--scheduler", "inline", "--store", str(tmp_path / "store"), "--out", str(out), "--no-progress"])
    assert code == 0
    summary = last_json(capsys.readouterr().out)
    assert summary["points"] == 4 and summary["computed"] == 4 and summary["reused"] == 0
    ds = load_dataset(out)
    assert ds.phi.dims == ("k_n", "ratio") and float(ds.gamma_n.sel(k_n=2.0, ratio=20.0)) == 0.1


def test_sweep_with_an_integrator_switched_by_omega(fmu_a, tmp_path, capsys):
    out = tmp_path / "sweep.zarr"
    code = cli.main(["sweep", "--fmu", str(fmu_a), "--grid", "omega=0.5,0.9", "--horizon", "100",
                     "--integrator", "event_driven", "--switch", "omega=0.6", "--integrator-above", "symplectic_euler",
                     "--scheduler", "inline", "--store", str(tmp_path / "store"), "--out", str(out), "--no-progress"])
    assert code == 0, capsys.readouterr().err
    ds = load_dataset(out)
    assert ds.attrs["integrator_name"] == "event_driven at omega <= 0.6, symplectic_euler otherwise"
    stored = sorted(json.loads(path.read_text())["inputs"]["fmu_values"]["integrator"]
                    for path in (tmp_path / "store").rglob("*.json") if "inputs" in json.loads(path.read_text()))
    assert stored == ["event_driven", "symplectic_euler"]
    # A limit without the integrator beyond it is refused in one line.
    assert cli.main(["sweep", "--fmu", str(fmu_a), "--grid", "omega=0.5", "--horizon", "100", "--switch", "omega=0.6",
                     "--scheduler", "inline", "--no-progress"]) == 2
    assert "together" in capsys.readouterr().err


def test_continuation_command(fmu_a, tmp_path, capsys):
    out = tmp_path / "loop.nc"
    code = cli.main(["continuation", "--fmu", str(fmu_a), "--parameter", "omega", "--values", "0.4,0.6",
                     "--set", "A=0.5", "--horizon", "200", "--fresh", "--no-progress", "--out", str(out)])
    assert code == 0
    summary = last_json(capsys.readouterr().out)
    assert summary["steps"] == 3 and len(summary["up_stick_slip"]) == 2 and len(summary["down_stick_slip"]) == 1
    ds = load_dataset(out)
    assert list(ds.direction.values) == ["up", "up", "down", "fresh", "fresh"]


def test_bad_command_lines_are_refused(capsys):
    with pytest.raises(SystemExit):
        cli.main(["run", "--set", "A"])
    assert cli.main(["sweep", "--horizon", "10"]) == 2
    assert "--grid" in capsys.readouterr().err


def test_bad_settings_end_with_one_line_and_status_2_not_a_traceback(tmp_path):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "harness", "run", "--set", "k_n=-1", "--horizon", "1",
                          "--no-progress"], capture_output=True, text=True, cwd=str(Path(__file__).resolve().parents[3]))
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("vibroblock run: error:") and "k_n" in lines[0]
