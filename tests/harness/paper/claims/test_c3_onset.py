"""C3's bracket tests on synthetic columns."""
from __future__ import annotations

from harness.paper.claims.c3_onset import verdict_c3
from harness.paper.claims.measure import onset_amplitude
from harness.paper.claims.verdicts import AGREES, DISAGREES


def c3_column(omega, low, high, changes=1):
    return {"omega": omega, "regimes": [], "last_friction_A": low, "first_sliding_A": high, "changes": changes,
            "paper_line": 1 / omega**2, "onset_curve": float(onset_amplitude(omega))}


def test_c3_bracket_tests():
    amplitudes = [0.1, 1.0, 10.0, 100.0, 1000.0]
    good = {"amplitudes": amplitudes, "columns": [c3_column(0.1, 10.0, 100.0 * 1.01), c3_column(1.0, 0.01, 0.1)]}
    row_a, row_b = verdict_c3(good)
    assert row_a.verdict == AGREES
    assert row_b.verdict == AGREES  # A_c(1) = 0.07 lies in (0.01, 0.1]; g/w^2 = 1 does not
    bad = {"amplitudes": amplitudes, "columns": [c3_column(0.1, 1000.0, None), c3_column(1.0, 0.01, 0.1, 3)]}
    row_a, row_b = verdict_c3(bad)
    assert row_a.verdict == DISAGREES and "1 column(s) with more than one transition" in row_a.reason
    assert row_b.verdict == DISAGREES


def test_a_located_boundary_is_judged_within_the_formula_tolerance():
    amplitudes = [0.1, 1.0, 10.0, 100.0, 1000.0]
    near = {**c3_column(0.1, 10.0, 1000.0), "located_A": 95.0}    # g/w^2 = 100, A_c ~ 99: 5 % off
    far = {**c3_column(0.1, 10.0, 1000.0), "located_A": 80.0}     # 20 % off, though inside the grid bracket
    row_a, row_b = verdict_c3({"amplitudes": amplitudes, "columns": [near], "resolution": 0.03})
    assert row_a.verdict == AGREES and row_b.verdict == AGREES
    row_a, row_b = verdict_c3({"amplitudes": amplitudes, "columns": [far], "resolution": 0.03})
    assert row_a.verdict == DISAGREES and row_b.verdict == DISAGREES
