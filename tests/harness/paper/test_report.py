"""The claims report is computed from measured values (a tiny main job); each claim's verdicts
are tested on synthetic values in tests/harness/paper/claims/."""
from __future__ import annotations

import json

import pytest

from harness.paper import report
from harness.paper.claims import CLAIMS, load_studies, study_name
from harness.paper.claims.readings import law_readings
from harness.paper.claims.verdicts import AGREES, DISAGREES, FLIPS, NOT_REPRODUCED, fmt


@pytest.fixture(scope="module")
def tiny_job(tmp_path_factory, fmu_dir):
    from harness.main import main

    out = tmp_path_factory.mktemp("main_job")
    path = main(["--resolution", "tiny", "--scheduler", "inline", "--out", str(out), "--fmu-dir", str(fmu_dir),
                 "--no-progress"])
    return out, path


def test_tiny_main_job_writes_a_report_from_its_measurements(tiny_job):
    out, path = tiny_job
    text = path.read_text()
    studies = load_studies(out / "claims.json")
    # The main job measures every claim under its readings and, by default, its law readings.
    assert set(studies) == {study_name(name, r) for name, claim in CLAIMS.items()
                            for r in claim.readings + law_readings(claim.readings)}
    assert "The load-only bound and the linear_along_normal and linear_no_pull contacts were measured too" in text
    assert {"Fig1b", "C6r"} | {f"C{n}" for n in range(1, 9)} <= set(studies)
    rows = report.claim_rows(studies)
    for row in rows:
        assert f"| {row.claim} |" in text
        assert f"**{row.verdict}**" in text
        assert row.verdict in (AGREES, DISAGREES, NOT_REPRODUCED, FLIPS)
    # The claims the readings can change are set side by side, each part under every reading.
    assert "## The readings side by side" in text
    for part, per_reading in report.reading_rows(studies).items():
        assert len(per_reading) == len(CLAIMS[part[:2]].readings), part
        assert f"| {part} | **{per_reading[next(iter(per_reading))].verdict}**" in text
    c1 = studies["C1"].measured
    assert f"stick time {fmt(c1['stick_time'])} vs" in text
    assert c1["rest_penetration"] == pytest.approx(1.0, rel=0.02)
    # x0 of stationary sliding carries the force-balance sign, so the paper's printed form fails.
    c8b = next(r for r in rows if r.claim == "C8b")
    assert c8b.verdict == DISAGREES and "sign typo" in c8b.reason
    for name in ("fig1b.png", "fig1c_phase_diagram_A.png", "hysteresis_gamma_n.png", "model_b_x_t.png",
                 "model_c_phase_diagram.png", "omega2_vs_k_n.png", "model_c_Vd_omega.png", "chain_catalog.png",
                 "chain_triggering.png"):
        assert (out / name).stat().st_size > 0 and f"]({name})" in text
    assert "phi_threshold: 10" in text and "transient: 4000" in text
    # The paper's Fig. 1c at the paper's own parameters: a sub-threshold point stick-slips
    # with at least the window's cycles + 1 slips (vibration shortens the cycle, never lengthens it).
    fig1c = studies["Fig1c"]
    (point,) = fig1c.measured["points"]
    assert point["regime"] == "stick_slip" and point["slips_in_window"] >= fig1c.settings["cycles"] + 1
    assert (out / "fig1c_paper_parameters.png").stat().st_size > 0
    assert "- Fig1c: 1 points" in text
    # The chain study: its catalogue ran through BlockChain3.fmu and the report states it.
    chain = studies["Chain"].measured
    assert chain["catalogue"]["events"] > 0 and f"gave {chain['catalogue']['events']} events" in text
    assert "- Chain: a chain of blocks" in text


def test_changed_measurement_changes_the_report(tiny_job):
    out, _ = tiny_job
    studies = load_studies(out / "claims.json")
    studies["C1"].measured["slip_length"] = 10.0
    text = report.markdown(studies)
    assert "slip length off by 80%" in text
    assert next(r for r in report.claim_rows(studies) if r.claim == "C1").verdict == DISAGREES


def test_each_study_reports_its_time_and_a_rerun_comes_from_the_store(tiny_job, fmu_dir, capsys):
    from harness.main import main

    out, path = tiny_job
    first = load_studies(out / "claims.json")
    assert all(s.timing["wall_time"] > 0 and s.timing["source"] != "store" for s in first.values())
    assert "## Time per study" in path.read_text()
    # Each point and task the job computed is counted once, in the study that computed it,
    # with the time stored beside its result.
    stored = [json.loads(f.read_text())["elapsed_s"] for f in (out / "store").glob("*/**/*.json")
              if "elapsed_s" in json.loads(f.read_text())]
    assert len(stored) == sum(s.timing["points_computed"] + s.timing["tasks_computed"] for s in first.values())
    assert sum(s.timing["compute_time"] for s in first.values()) == pytest.approx(sum(stored), rel=1e-9)
    assert all(s.timing["compute_time"] > 0 for s in first.values() if s.timing["source"] == "computed")
    capsys.readouterr()
    main(["--resolution", "tiny", "--scheduler", "inline", "--out", str(out), "--fmu-dir", str(fmu_dir), "--no-progress"])
    printed = capsys.readouterr().out
    again = load_studies(out / "claims.json")
    for name, study in again.items():
        assert study.timing["source"] == "store", name
        assert study.timing["points_computed"] == study.timing["tasks_computed"] == 0
        assert study.timing["compute_time"] == 0.0
        assert f"{name}: {study.timing['wall_time']:.1f} s, computing 0.0 s (store;" in printed


def test_the_table_keeps_the_deciding_numbers_and_each_claim_has_its_section():
    from harness.paper.claims.verdicts import Row

    parts = [part for part in report.CLAIM_TEXT if part.startswith("C3")][:2]
    assert len(parts) == 2
    long_measured = "; ".join(f"omega = {w}: A boundary {w * 40:.3g} vs g/omega^2 {1 / w ** 2:.3g}"
                              for w in (0.1, 0.16, 0.25, 0.4, 0.63, 1.0, 1.6, 2.5, 4.0, 6.3) * 4)
    assert len(long_measured) > 1000
    rows = [Row(parts[0], long_measured, AGREES, "every column within 10 %", figures=["fig1c.png"]),
            Row(parts[1], long_measured, DISAGREES, "3 of 9 columns off by more than 10 %", figures=["fig1c.png"])]
    short = report._short(long_measured)
    assert len(short) <= report.TABLE_CELL + len(" ... (see below)") and short.startswith("omega = 0.1: A boundary")
    assert short.endswith("(see below)")
    sections = "\n".join(report.per_claim_markdown(rows, ["fig1c.png"]))
    # The full measurement once, then named for the part that shares it.
    assert sections.count(long_measured) == 1
    assert f"*Measured:* the same runs and numbers as {parts[0]} (above)." in sections
    assert "*Why disagrees:* 3 of 9 columns" in sections and "(Figure 1)" in sections
    assert sections.count(f'<a id="{report._anchor(parts[0])}"></a>') == 1
    caption = report.figure_caption("fig1c.png", rows)
    assert caption.startswith(f"evidence for {parts[0]}, {parts[1]} -- ") and "delta_0" in caption
