"""Excitation -> Block as an SSP file: valid SSP 1.0, run by fmpy and by libcosim, equal
to the direct fmpy composition (plate motion through ``simulate_fmu``'s input).

Stated tolerances (docs/excitation.md explains them):

* communication step 0.25 (times k/4 are exact in every master's clock): fmpy's SSP
  run, libcosim's SSP run and the direct composition give the same bits;
* step 0.1: libcosim and the direct composition agree to 1e-12; fmpy's SSP run
  accumulates its time (time += h), so by t ~ 100 the block sees times off by more
  than its internal-grid tolerance and splits some steps 249/251 internal steps:
  differences up to 1e-5 in height and normal force, 1e-10 in x.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy.ssp.ssd import read_ssd

from harness.ground.excitation import bundled_ground_motion, peak_scaled_parameters, plate_input, simulate_block, write_record
from harness.cosim.ssp import (SspError, System, Component, excitation_block_system, read_ssp, run_ssp_fmpy,
                         run_ssp_libcosim, write_ssp)
from vibroblock.excitation import Excitation, load_record

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
OUTPUTS = ("x", "z", "vx", "phi_integral", "slip_count", "normal_force")
# The bundled record at 0.6 g, 20x slower, starting at t = 10: the plate starts at rest.
RECORD = {"mode": 4, **peak_scaled_parameters(load_record(""), 0.6, 20.0, onset=10.0)}


@pytest.fixture(scope="module")
def fmus(fmu_dir):
    return str(fmu_dir / "Excitation.fmu"), str(fmu_dir / "BlockA.fmu")


@pytest.fixture(scope="module")
def record_ssp(fmus, tmp_path_factory):
    system = excitation_block_system(*fmus, excitation=RECORD, block=SCALED, block_outputs=OUTPUTS)
    return write_ssp(tmp_path_factory.mktemp("ssp") / "record.ssp", system)


@pytest.fixture(scope="module")
def runs(record_ssp, fmus):
    """The record system in the three compositions at two communication steps."""
    out = {}
    for h in (0.25, 0.1):
        table = plate_input(Excitation(**RECORD), step_size=h, stop_time=400.0)
        direct = simulate_block(fmus[1], table, start_values=SCALED, outputs=OUTPUTS)
        out[h] = {
            "input": {f"block.{k}": direct[k][1:] for k in OUTPUTS},
            "ssp_fmpy": run_ssp_fmpy(record_ssp, stop_time=400.0, step_size=h),
            "ssp_libcosim": run_ssp_libcosim(record_ssp, stop_time=400.0, step_size=h),
        }
    return out


def test_the_file_is_valid_ssp_and_reads_back(record_ssp, fmus):
    read_ssd(str(record_ssp), validate=True)  # fmpy's SSP 1.0 schema check
    system = read_ssp(record_ssp, record_ssp.parent / "unpacked")
    plate, block = system.component("plate"), system.component("block")
    assert plate.parameters == RECORD and isinstance(plate.parameters["mode"], int)
    assert block.parameters == SCALED
    assert system.connections == tuple(("plate", n, "block", n) for n in ("plate_z", "plate_v", "plate_a"))
    assert set(OUTPUTS) <= set(block.outputs)
    with open(plate.fmu, "rb") as a, open(fmus[0], "rb") as b:
        assert a.read() == b.read()


def test_ssp_runs_equal_the_direct_composition_bit_for_bit_at_an_exact_step(runs):
    r = runs[0.25]
    assert 0.5 < np.max(np.abs(r["ssp_fmpy"]["plate.plate_a"])) <= 0.6 + 1e-12  # sampled peak of 0.6
    assert np.max(np.abs(r["input"]["block.normal_force"] - 1.0)) > 0.3  # the record shook the block
    for name in OUTPUTS:
        key = f"block.{name}"
        np.testing.assert_array_equal(r["ssp_fmpy"][key], r["input"][key], err_msg=key)
        np.testing.assert_array_equal(r["ssp_libcosim"][key], r["ssp_fmpy"][key], err_msg=key)
    np.testing.assert_array_equal(r["ssp_fmpy"]["time"], r["ssp_libcosim"]["time"])


def test_at_a_step_with_rounded_times_the_masters_agree_within_the_stated_tolerances(runs):
    r = runs[0.1]
    for name, fmpy_tolerance in (("x", 1e-10), ("vx", 1e-10), ("phi_integral", 1e-10), ("z", 1e-5),
                                 ("normal_force", 1e-5)):
        key = f"block.{name}"
        np.testing.assert_allclose(r["ssp_libcosim"][key], r["input"][key], rtol=0, atol=1e-12, err_msg=key)
        np.testing.assert_allclose(r["ssp_fmpy"][key], r["ssp_libcosim"][key], rtol=0, atol=fmpy_tolerance,
                                   err_msg=key)
    np.testing.assert_array_equal(r["ssp_fmpy"]["block.slip_count"], r["ssp_libcosim"]["block.slip_count"])


def test_first_step_convention_of_the_two_masters(fmus, tmp_path):
    """A harmonic starts with the plate moving: libcosim hands the block the start
    values at initialisation (as simulate_fmu's input does), fmpy's SSP run gives it 0
    during the first step; the difference rings down with the contact's damping."""
    harmonic = {"mode": 0, "amplitude": 2.0, "omega": 0.3}
    path = write_ssp(tmp_path / "harmonic.ssp", excitation_block_system(*fmus, excitation=harmonic, block=SCALED,
                                                                         block_outputs=OUTPUTS))
    fmpy = run_ssp_fmpy(path, stop_time=200.0, step_size=0.5)
    cosim = run_ssp_libcosim(path, stop_time=200.0, step_size=0.5)
    direct = simulate_block(fmus[1], plate_input(Excitation(**harmonic), step_size=0.5, stop_time=200.0),
                            start_values=SCALED, outputs=OUTPUTS)
    np.testing.assert_array_equal(cosim["block.z"], direct["z"][1:])
    difference = np.abs(fmpy["block.z"] - cosim["block.z"])
    assert difference[:10].max() > 1e-2  # 2.0 * 0.3 * 0.5 of plate travel missed in the first step
    assert difference[-10:].max() < 1e-2 * difference[:10].max()


def test_a_record_file_given_as_string_plays_in_libcosim_and_fmpy_says_it_cannot(fmus, tmp_path):
    path = write_record(bundled_ground_motion(), tmp_path / "rjob.npz")
    from_file = {**RECORD, "record_file": str(path)}
    ssp = write_ssp(tmp_path / "file.ssp", excitation_block_system(*fmus, excitation=from_file, block=SCALED,
                                                                   block_outputs=("z",)))
    bundled = write_ssp(tmp_path / "bundled.ssp", excitation_block_system(*fmus, excitation=RECORD, block=SCALED,
                                                                          block_outputs=("z",)))
    a = run_ssp_libcosim(ssp, stop_time=250.0, step_size=0.25)
    b = run_ssp_libcosim(bundled, stop_time=250.0, step_size=0.25)
    assert np.max(np.abs(a["plate.plate_a"])) > 0.1
    # The file holds the record processed here and now; the bundled one was processed when
    # the FMU's data were made: the same samples up to the rounding of the processing's
    # floating-point kernels on another CPU (seen: 4e-17 on peaks of 0.3).
    np.testing.assert_allclose(a["plate.plate_a"], b["plate.plate_a"], rtol=1e-9,
                               atol=1e-12 * np.max(np.abs(b["plate.plate_a"])))
    with pytest.raises(SspError, match="cannot set str values"):
        run_ssp_fmpy(ssp, stop_time=100.0, step_size=0.25)


def test_bad_systems_are_refused(fmus, tmp_path):
    plate, block = fmus
    cases = {
        "no variable 'plate_q'": [("plate", "plate_q", "block", "plate_z")],
        "is not an output": [("block", "plate_z", "plate", "plate_z")],
        "no component 'ground'": [("ground", "plate_z", "block", "plate_z")],
    }
    for message, connections in cases.items():
        system = System("bad", (Component("plate", plate), Component("block", block)), tuple(connections))
        with pytest.raises(SspError, match=message):
            write_ssp(tmp_path / "bad.ssp", system)
    with pytest.raises(SspError, match="cannot take"):
        write_ssp(tmp_path / "bad.ssp", excitation_block_system(plate, block, excitation={"mode": 2.5}))
    with pytest.raises(SspError, match="whole number of steps"):
        run_ssp_fmpy(write_ssp(tmp_path / "ok.ssp", excitation_block_system(plate, block)), stop_time=1.0,
                     step_size=0.3)
    (tmp_path / "not.ssp").write_text("plain text")
    with pytest.raises(SspError, match="not an SSP archive"):
        read_ssp(tmp_path / "not.ssp")


def test_an_oblique_plate_gets_both_components_in_fmpy_and_libcosim(fmus, tmp_path):
    """The Excitation FMU shaking along 60 degrees from the vertical drives a block on an
    oblique plate through both masters: the SSP connects plate_x, plate_vx, plate_ax too,
    and the result equals fmpy's run with the same six columns as an input table."""
    shaking = {"mode": 0, "amplitude": 0.3, "omega": 0.4, "direction": math.radians(60.0)}
    block = {**SCALED, "plate_motion": 1, "integrator": 1}
    system = excitation_block_system(*fmus, excitation=shaking, block=block, block_outputs=OUTPUTS)
    assert {c[1] for c in system.connections} >= {"plate_x", "plate_vx", "plate_ax"}
    path = write_ssp(tmp_path / "oblique.ssp", system)
    cosim = run_ssp_libcosim(path, stop_time=100.0, step_size=0.5)
    table = plate_input(Excitation(**shaking), step_size=0.5, stop_time=100.0, horizontal=True)
    assert "plate_ax" in table.dtype.names
    direct = simulate_block(fmus[1], table, start_values=block, outputs=OUTPUTS)
    np.testing.assert_array_equal(cosim["block.x"], direct["x"][1:])
    assert np.ptp(direct["x"]) > 0.1  # the horizontal component moves the block
