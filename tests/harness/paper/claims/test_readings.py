"""Readings of the paper's equations: what a runner's reading sets on each model's runs,
and how the report sets the verdicts of several readings side by side."""
from __future__ import annotations

import dataclasses

import pytest

from harness.paper import report
from harness.paper.claims import CLAIMS, READINGS, Runner, Study, run_studies, study_name
from harness.paper.claims.readings import (A_READINGS, DEFAULT_READING, Reading, split_study_name)
from harness.paper.claims.study import CORRUGATED_TOLERANCES, RESOLUTIONS
from harness.paper.claims.verdicts import AGREES, DISAGREES, FLIPS, NOT_REPRODUCED


@pytest.fixture
def runner(tmp_path, fmu_dir):
    return Runner(tmp_path / "store", RESOLUTIONS["tiny"], fmus={m: fmu_dir / f"Block{m}.fmu" for m in "ABC"})


def test_the_default_reading_sets_nothing_so_stored_points_keep_their_keys(runner):
    # (Models B and C carry the adaptive integrator's tolerances: the runner's, not the reading's.)
    for model in "ABC":
        expected = {"A": 1.0, **({} if model == "A" else CORRUGATED_TOLERANCES)}
        assert dict(runner.run(model, parameters={"A": 1.0}).parameters) == expected


def test_a_reading_sets_the_formulation_on_corrugated_models_only_and_never_overrides_a_study(runner):
    runner.reading = Reading(formulation=1, coulomb_normal=1)
    assert dict(runner.run("A").parameters) == {"coulomb_normal": 1.0}
    for model in "BC":
        assert dict(runner.run(model).parameters) == {"formulation": 1.0, "coulomb_normal": 1.0,
                                                      **CORRUGATED_TOLERANCES}
    assert dict(runner.run("C", parameters={"formulation": 0.0}).parameters) == {"formulation": 0.0,
                                                                                 "coulomb_normal": 1.0,
                                                                                 **CORRUGATED_TOLERANCES}


def test_study_names_round_trip():
    for reading in READINGS:
        name = study_name("C7", reading)
        assert split_study_name(name) == ("C7", reading)
        assert (name == "C7") == reading.is_default


def test_claims_that_readings_change_are_measured_under_each():
    assert CLAIMS["C1"].readings == (DEFAULT_READING,)  # model A at rest: no corrugation, no vibration
    assert CLAIMS["C2"].readings == A_READINGS
    for name in ("C5", "C6", "C7", "C8"):
        assert set(CLAIMS[name].readings) == set(READINGS) and CLAIMS[name].readings[0] == DEFAULT_READING


def test_each_reading_runs_under_its_own_parameters(runner, monkeypatch):
    """run_studies switches the runner's reading per study and restores the default after."""
    seen = []

    def fake_study(r):
        seen.append((r.reading, dict(r.run("B").parameters)))
        return Study("C7", {}, {})

    monkeypatch.setitem(CLAIMS, "C7", dataclasses.replace(CLAIMS["C7"], study=fake_study))
    studies = run_studies(runner, ["C7"], progress=False)
    assert list(studies) == [study_name("C7", r) for r in READINGS]
    assert [s.reading for s in studies.values()] == [r.key for r in READINGS]
    assert seen == [(r, {**r.parameters("B"), **CORRUGATED_TOLERANCES}) for r in READINGS]
    assert runner.reading == DEFAULT_READING
    assert list(run_studies(runner, ["C7"], progress=False, readings=False)) == ["C7"]
    runner.resolution = dataclasses.replace(runner.resolution, readings=False)  # as --quick
    assert list(run_studies(runner, ["C7"], progress=False)) == ["C7"]


def test_studies_side_by_side_keep_their_readings_order_and_counts(runner, monkeypatch):
    """With several studies at once each runs on a runner of its own under its reading;
    the results come back in the order of the claims and readings, each study's counts
    are its own and the caller's runner gets their sum."""
    import threading
    import time

    threads, started, priorities = set(), threading.Barrier(2, timeout=30), {}

    def fake_study(name, delay):
        def study(r):
            threads.add(threading.current_thread().name)
            priorities[name] = r.execution.priority
            if r.reading == DEFAULT_READING:
                started.wait()  # the two default-reading studies run at the same time
            time.sleep(delay)  # and they finish out of order
            r.points_computed += 2
            r.tasks_reused += 1
            return Study(name, {"reading": r.reading.key}, {})
        return study

    monkeypatch.setitem(CLAIMS, "C7", dataclasses.replace(CLAIMS["C7"], study=fake_study("C7", 0.2)))
    monkeypatch.setitem(CLAIMS, "C8", dataclasses.replace(CLAIMS["C8"], study=fake_study("C8", 0.0)))
    studies = run_studies(runner, ["C7", "C8"], progress=False, at_once=4)
    assert list(studies) == [study_name(c, r) for c in ("C7", "C8") for r in READINGS]
    assert all(s.measured["reading"] == s.reading == split_study_name(name)[1].key for name, s in studies.items())
    assert all(s.timing["points_computed"] == 2 and s.timing["tasks_reused"] == 1 for s in studies.values())
    assert (runner.points_computed, runner.tasks_reused) == (2 * len(studies), len(studies))
    assert runner.reading == DEFAULT_READING and len(threads) > 1
    # The costlier study's work goes first on the workers; the caller's runner keeps its own.
    assert priorities["C8"] > priorities["C7"] > runner.execution.priority == 0


def test_a_study_that_fails_beside_others_lets_them_finish_and_is_named(runner, monkeypatch, capsys):
    from harness.paper.claims import StudiesFailed

    finished = []

    def failing(r):
        if r.reading != DEFAULT_READING:
            raise ValueError("no such point")
        return Study("C7", {}, {})

    def slow(r):
        import time

        time.sleep(0.3)  # still running when the C7 studies fail
        finished.append(r.reading)
        return Study("C8", {}, {})

    monkeypatch.setitem(CLAIMS, "C7", dataclasses.replace(CLAIMS["C7"], study=failing))
    monkeypatch.setitem(CLAIMS, "C8", dataclasses.replace(CLAIMS["C8"], study=slow))
    failure = r"3 studies failed \(C7@.*\); the first: ValueError: no such point"
    with pytest.raises(StudiesFailed, match=failure) as caught:
        run_studies(runner, ["C7", "C8"], progress=False, at_once=8)
    assert sorted(name for name, _ in caught.value.failures) == sorted(
        study_name("C7", r) for r in READINGS if r != DEFAULT_READING)
    assert len(finished) == len(READINGS)  # every C8 study ran to its end
    assert capsys.readouterr().err.count("failed (ValueError: no such point); the other studies go on") == 3


def _c7(fractions: list) -> Study:
    curve = {"A": 0.3, "omega": [0.1, 1.0, 14.0], "contact_fraction": fractions, "regime": ["stick_slip"] * 3}
    return Study("C7", {"curves": {"B": [curve], "C": [curve]}, "k_n_over_gamma_n": 14.3,
                        "embedded_threshold": 0.99}, {"models": "B, C"})


def test_a_verdict_that_differs_between_readings_is_reported_as_flipping():
    leaves_and_returns, never_leaves = _c7([1.0, 0.5, 1.0]), _c7([1.0, 1.0, 1.0])
    studies = {"C7": leaves_and_returns}
    same = {study_name("C7", r): leaves_and_returns for r in READINGS}
    assert next(r for r in report.claim_rows(same) if r.claim == "C7").verdict == AGREES

    tangent = Reading(formulation=1)
    studies = {**same, study_name("C7", tangent): never_leaves}
    row = next(r for r in report.claim_rows(studies) if r.claim == "C7")
    assert row.verdict == FLIPS
    assert f"{DEFAULT_READING.label}: {AGREES}" in row.reason and f"{tangent.label}: {NOT_REPRODUCED}" in row.reason
    text = report.markdown(studies)
    assert "## The readings side by side" in text
    assert f"{tangent.label}: agrees on 0 of 1 parts" in text
    assert f"{DEFAULT_READING.label}: agrees on 1 of 1 parts (C7)" in text
    assert "verdict flips with the reading: C7" in text
    # Two readings that both fail the claim, in different ways: no flip, the worse verdict.
    disagrees = _c7([1.0, 0.5, 0.5])
    assert next(r for r in report.claim_rows(same) if r.claim == "C7").verdict == AGREES
    both_fail = {**{study_name("C7", r): disagrees for r in READINGS}, study_name("C7", tangent): never_leaves}
    row = next(r for r in report.claim_rows(both_fail) if r.claim == "C7")
    assert row.verdict == DISAGREES and f"{tangent.label}: {NOT_REPRODUCED}" in row.reason
    assert "verdict flips with the reading: none" in report.markdown(both_fail)
    # One reading alone: no side-by-side section and the plain verdict.
    assert "side by side" not in report.markdown({"C7": leaves_and_returns})
