"""The law readings (load-only bound, the other linear contacts) and the report's table of
which readings and laws reproduce each part."""
from __future__ import annotations

import dataclasses

import pytest

from harness.paper import report
from harness.paper.claims import CLAIMS, READINGS, Runner, Study, run_studies, study_name
from harness.paper.claims.readings import (A_LAW_READINGS, A_READINGS, LAW_READINGS, Reading, law_readings,
                                           split_study_name)
from harness.paper.claims.study import RESOLUTIONS
from harness.paper.claims.verdicts import AGREES


def test_law_readings_set_the_fmu_s_law_parameters_and_their_names_round_trip():
    load_only, along_normal, no_pull = LAW_READINGS
    assert load_only.parameters("C") == {"coulomb_normal": 2.0}
    assert along_normal.parameters("B") == {"contact_law": 1.0}
    assert no_pull.parameters("A") == {"contact_law": 2.0}
    for reading in READINGS + LAW_READINGS:
        assert split_study_name(study_name("C6", reading)) == ("C6", reading)
    assert study_name("C6", no_pull) == "C6@fixed_axes+contact_force+linear_no_pull"
    assert "linear no pull contact" in no_pull.label


def test_the_law_parameters_name_the_fmu_s_own_laws():
    """The integers the readings set are the ids of the FMU's law modules of those names."""
    from vibroblock.laws import LAWS

    from harness.paper.claims.readings import CONTACT_LAWS, COULOMB_NORMALS
    assert {law.name: law.id for law in LAWS["bound"].values()} == {n: i for i, n in enumerate(COULOMB_NORMALS)}
    contacts = {law.name: law.id for law in LAWS["contact"].values()}
    assert all(contacts[name] == number for number, name in enumerate(CONTACT_LAWS))


def test_laws_are_measured_on_request_only_for_claims_the_readings_change():
    assert law_readings(CLAIMS["C1"].readings) == ()
    assert law_readings(CLAIMS["C2"].readings) == A_LAW_READINGS
    assert law_readings(CLAIMS["C6"].readings) == LAW_READINGS


@pytest.fixture
def runner(tmp_path, fmu_dir):
    return Runner(tmp_path / "store", RESOLUTIONS["tiny"], fmus={m: fmu_dir / f"Block{m}.fmu" for m in "ABC"})


def test_run_studies_adds_the_law_readings_with_laws(runner, monkeypatch):
    monkeypatch.setitem(CLAIMS, "C7", dataclasses.replace(CLAIMS["C7"], study=lambda r: Study("C7", {}, {})))
    assert list(run_studies(runner, ["C7"], progress=False)) == [study_name("C7", r) for r in READINGS]
    assert list(run_studies(runner, ["C7"], progress=False, laws=True)) == [
        study_name("C7", r) for r in READINGS + LAW_READINGS]


def _c7(fractions: list) -> Study:
    """A C7 study whose curves leave contact and return ([1, 0.5, 1]) or never leave."""
    curve = {"A": 0.3, "omega": [0.1, 1.0, 14.0], "contact_fraction": fractions, "regime": ["stick_slip"] * 3}
    return Study("C7", {"curves": {"B": [curve], "C": [curve]}, "k_n_over_gamma_n": 14.3,
                        "embedded_threshold": 0.99}, {"models": "B, C"})


def test_the_reproduction_table_names_where_each_part_agrees():
    agrees, fails = _c7([1.0, 0.5, 1.0]), _c7([1.0, 1.0, 1.0])
    assert CLAIMS["C7"].verdicts(agrees.measured).verdict == AGREES  # the synthetic curve leaves and returns
    no_pull = LAW_READINGS[2]
    studies = {study_name("C7", r): agrees for r in READINGS}
    studies[study_name("C7", no_pull)] = fails
    text = report.markdown(studies)
    assert "## Which readings and laws reproduce the paper" in text
    section = text.split("## Which readings and laws reproduce the paper")[1]
    line = next(x for x in section.splitlines() if x.startswith("| C7"))
    agreeing, failing = line.split("|")[2], line.split("|")[3]
    assert all(r.label in agreeing for r in READINGS) and no_pull.label in failing
    # The main table's verdict comes from the paper's readings only: the law does not flip it.
    assert next(r for r in report.claim_rows(studies) if r.claim == "C7").verdict == AGREES
    # Without the laws, the table says how to measure them.
    assert "--no-laws" in report.markdown({study_name("C7", r): agrees for r in READINGS})


def test_fig_5_s_transitions_are_named_in_the_table():
    assert "P_l/(m omega^2)" in report.FIGURE_5["C6b"] and "k_n/gamma_n" in report.FIGURE_5["C6c"]


def test_c6_ensembles_under_other_readings_run_on_request_only(runner):
    assert runner.ensembles_every_reading is False
    runner.ensembles_every_reading = True
    assert runner.for_reading(READINGS[2]).ensembles_every_reading is True
