"""Every mistake a user is known to make with the command line, the examples and the
Excitation FMU ends in one line that names the value, the rule and the fix, with exit
status 2 (the FMU: an error in the master's log with fmpy's default logger), never in a
traceback.

The FMUs here are built without the shipped kernels (quick): the mistakes are refused
before any kernel runs, except where a run is wanted (``--out run.csv``).
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import obspy
import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
OBSPY_DATA = Path(obspy.__file__).parent / "core" / "tests" / "data"
ULN_RECORD = OBSPY_DATA / "IU_ULN_00_LH1_2015-07-18T02.mseed"
ULN_INVENTORY = OBSPY_DATA / "IU_ULN_00_LH1.xml"


def run(args, env, cwd=REPO, timeout=300):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, cwd=str(cwd), env=env,
                          timeout=timeout)


def one_error_line(done, program: str) -> str:
    """The single line on standard error of a refused command, after its prefix."""
    assert done.returncode == 2, (done.returncode, done.stderr[-3000:])
    assert "Traceback" not in done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, done.stderr
    prefix = f"{program}: error: "
    assert lines[0].startswith(prefix), lines[0]
    return lines[0][len(prefix):]


def vibroblock(*args):
    return ["-m", "harness", *args]


# ---------------------------------------------------------------------- example scripts
def test_record_errors_of_the_example_are_one_line(tmp_path, subprocess_env):
    fmu = tmp_path / "BlockA.fmu"
    fmu.write_bytes(b"")  # only its presence is checked before the record is read
    script = EXAMPLES / "record_response.py"
    missing = one_error_line(run([script, tmp_path / "quake.sac", "--fmu", fmu], subprocess_env),
                             "record_response.py")
    assert "quake.sac" in missing and "no such file" in missing and "check the path" in missing
    no_response = one_error_line(run([script, ULN_RECORD, "--fmu", fmu, "--freqmin", "0.02"], subprocess_env),
                                 "record_response.py")
    assert "IU.ULN.00.LH1" in no_response and "no instrument response" in no_response
    assert "--inventory" in no_response and "--sensitivity" in no_response
    # obspy's example inventory (station BW.RJOB) does not hold IU.ULN.
    wrong = tmp_path / "rjob.xml"
    obspy.read_inventory().write(str(wrong), format="STATIONXML")
    wrong_inventory = one_error_line(run([script, ULN_RECORD, "--fmu", fmu, "--inventory", wrong, "--freqmin", "0.02"],
                                         subprocess_env), "record_response.py")
    assert "no response for IU.ULN.00.LH1" in wrong_inventory and "cover this channel" in wrong_inventory


def test_counts_are_not_made_physical_by_declaring_units(tmp_path, subprocess_env):
    fmu = tmp_path / "BlockA.fmu"
    fmu.write_bytes(b"")
    refused = one_error_line(run(vibroblock("record", ULN_RECORD, "--fmu", fmu, "--quantity", "velocity",
                                            "--unit", "m/s", "--freqmin", "0.02"), subprocess_env),
                             "vibroblock record")
    assert "instrument's output (counts or volts" in refused and "velocity in m/s" in refused
    assert "--inventory" in refused and "--sensitivity" in refused


def test_an_example_outside_the_repository_says_where_the_fmu_comes_from(tmp_path, subprocess_env):
    (tmp_path / "examples").mkdir()
    copy = tmp_path / "examples" / "fig1b_stick_slip_vs_sliding.py"  # a clone without build/fmus
    shutil.copy(EXAMPLES / copy.name, copy)
    message = one_error_line(run([copy], subprocess_env, cwd=tmp_path), copy.name)
    assert str(tmp_path / "build" / "fmus" / "BlockA.fmu") in message and "does not exist" in message
    assert "make fmus" in message and "--fmu PATH" in message


@pytest.mark.parametrize("name", ["fig1b_stick_slip_vs_sliding", "record_response", "triggering",
                                  "excitation_composition", "choosing_an_integrator"])
def test_every_example_option_has_help(name, subprocess_env):
    done = run([EXAMPLES / f"{name}.py", "--help"], subprocess_env)
    assert done.returncode == 0, done.stderr
    text = done.stdout.split("options:", 1)[1]
    # argparse starts an option's line with two spaces; its help follows on the line
    # (after a gap of two or more spaces) or on the next, further indented, line.
    lines = text.splitlines()
    options = [i for i, line in enumerate(lines) if re.match(r"^  -", line)]
    assert len(options) >= 3
    for i in options:
        on_line = "  " in lines[i].strip()
        following = lines[i + 1] if i + 1 < len(lines) else ""
        assert on_line or re.match(r"^ {10,}\S", following), (name, lines[i])


# ---------------------------------------------------------------------- the command line
def test_every_command_line_option_has_help():
    from harness.runs.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command")
    for name, sub in commands.choices.items():
        for action in sub._actions:
            if action.option_strings and action.dest != "help":
                assert action.help, (name, action.option_strings)


def test_dt_given_as_a_model_parameter_points_to_its_own_switch(subprocess_env):
    message = one_error_line(run(vibroblock("run", "--set", "dt=-1e-4", "--no-progress"), subprocess_env),
                             "vibroblock run")
    assert message == "--set dt=-0.0001: dt is not a model parameter and is not set with --set; use --dt -0.0001"


def test_a_word_for_a_number_ends_with_status_2(quick_fmus, subprocess_env):
    message = one_error_line(run(vibroblock("run", "--fmu", quick_fmus / "BlockA.fmu", "--set", "A=abc",
                                            "--no-progress"), subprocess_env), "vibroblock run")
    assert message == "--set A=abc: A is a Real parameter and cannot take 'abc': give a number"


def test_a_value_the_fmu_refuses_is_named_alone(quick_fmus, subprocess_env):
    message = one_error_line(run(vibroblock("run", "--fmu", quick_fmus / "BlockA.fmu", "--set", "k_n=-1",
                                            "--no-progress"), subprocess_env), "vibroblock run")
    # Only the refused value, its rule (with what the parameter is) -- not the 19 names the call set.
    assert message == ("fmi2SetReal refused: k_n = -1.0 is not admissible: it must be a finite number > 0 "
                       "(normal contact stiffness)")


def test_out_writes_csv_and_refuses_a_suffix_it_does_not_write(quick_fmus, tmp_path, subprocess_env):
    refused = one_error_line(run(vibroblock("run", "--fmu", quick_fmus / "BlockA.fmu", "--out", tmp_path / "run.txt",
                                            "--no-progress"), subprocess_env), "vibroblock run")
    assert "run.txt" in refused and "'.txt'" in refused and ".nc" in refused and ".csv" in refused
    assert not (tmp_path / "run.txt").exists()
    out = tmp_path / "run.csv"
    done = run(vibroblock("run", "--fmu", quick_fmus / "BlockA.fmu", "--horizon", "20", "--interval", "2",
                          "--transient", "4", "--out", out, "--no-progress"), subprocess_env, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    header, *rows = out.read_text().splitlines()
    assert header.split(",")[0] == "time" and "coulomb_resets" in header.split(",") and len(rows) == 11
    assert np.isclose(float(rows[-1].split(",")[0]), 20.0)


# ---------------------------------------------------------------------- the Excitation FMU
EXCITATION_SCRIPT = """
import sys
from fmpy import simulate_fmu
try:
    simulate_fmu(sys.argv[1], stop_time=1.0, start_values={"mode": 4, "record_file": sys.argv[2]})
except Exception as exc:
    print("raised:", exc)
"""


def test_the_excitation_fmus_refusal_reaches_fmpys_default_logger(quick_fmus, tmp_path, subprocess_env):
    missing = tmp_path / "quake.sac"
    done = run(["-c", EXCITATION_SCRIPT, quick_fmus / "Excitation.fmu", missing], subprocess_env)
    errors = [line for line in done.stdout.splitlines() if line.startswith("[ERROR]")]
    assert errors == [f"[ERROR] record_file = '{missing}' does not exist (or is not a file): give the path of an "
                      f"existing record file, absolute or relative to the master's working directory ({REPO}), "
                      "or leave it empty for the bundled record"]
    assert "raised: fmi2SetString failed" in done.stdout
