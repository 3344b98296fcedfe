"""C8's verdicts: sliding at the largest V_d, the sign of the offset x0."""
from __future__ import annotations

from harness.paper.claims.c8_drive_velocity import verdict_c8
from harness.paper.claims.verdicts import AGREES, DISAGREES, NOT_REPRODUCED


def test_c8_offset_sign():
    def values(x0):
        return {"omegas": [1.0], "model_a": [{"V_d": 10.0, "regimes": ["sliding"]}],
                "model_c": [{"V_d": 10.0, "regimes": ["sliding"]}], "model_a_amplitude": 2.0,
                "model_c_amplitude": 2e4,
                "offsets": [{"V_d": 10.0, "x0": x0, "x0_std": 0.1, "force_balance": 30.0, "paper": -20.0,
                             "regime": "sliding"}]}
    sliding, offset = verdict_c8(values(30.3))
    assert sliding.verdict == AGREES and offset.verdict == DISAGREES
    assert "sign typo" in offset.reason and "agrees to 0.01 relative" in offset.reason
    assert "|x0 - formula| = 0.3" in offset.reason
    assert verdict_c8(values(-20.5))[1].verdict == AGREES
    neither = verdict_c8(values(5.0))[1]
    assert neither.verdict == DISAGREES and "sign typo" not in neither.reason and "neither" in neither.reason


def test_a_flying_block_is_not_sliding():
    """At the printed A = 2e4 model C is thrown off the plate: flying points cannot carry
    "sliding at any omega"; friction at the largest V_d contradicts it."""
    def values(regimes_c, printed):
        return {"omegas": [0.3, 3.0], "model_a": [{"V_d": 10.0, "regimes": ["sliding", "sliding"]}],
                "model_c": [{"V_d": 1.0, "regimes": ["stick_slip", "stuck"]}, {"V_d": 10.0, "regimes": regimes_c}],
                "model_c_printed": [{"V_d": 10.0, "regimes": printed}], "model_a_amplitude": 2.0,
                "model_c_amplitude": 0.5, "model_c_printed_amplitude": 2e4,
                "offsets": [{"V_d": 10.0, "x0": 30.0, "x0_std": 0.1, "force_balance": 30.0, "paper": -20.0,
                             "regime": "sliding"}]}
    sliding, _ = verdict_c8(values(["sliding", "sliding"], ["flying", "flying"]))
    assert sliding.verdict == AGREES
    assert "printed A = 20000 the block flies at 2/2 omegas" in sliding.reason
    assert "C (A = 0.5): V_d = 1: 0/2 sliding" in sliding.measured
    flying, _ = verdict_c8(values(["sliding", "flying"], ["flying", "flying"]))
    assert flying.verdict == NOT_REPRODUCED and "w = 3 (flying)" in flying.reason
    held, _ = verdict_c8(values(["stick_slip", "flying"], ["flying", "flying"]))
    assert held.verdict == DISAGREES


def test_the_figure_for_the_papers_fig_7_says_which_drive_and_amplitude_it_runs():
    import matplotlib

    matplotlib.use("Agg")
    from harness.paper.claims import c8_drive_velocity
    from harness.paper.claims.study import Study

    grid = [["sliding", "stick_slip"], ["sliding", "sliding"]]
    study = Study("C8", {"model_a_amplitude": 2.0, "model_c_amplitude": 0.5}, {},
                  {"omega": [0.1, 1.0], "V_d": [0.01, 10.0], "regime_c": grid, "regime_a": grid})
    titles = {}
    c8_drive_velocity.draw(study, lambda figure, name: titles.setdefault(name, figure.axes[0].get_title()))
    assert "Fig. 7" in titles["model_c_Vd_omega.png"] and "A = 0.5" in titles["model_c_Vd_omega.png"]
    assert "scaled" in titles["model_c_Vd_omega.png"] and "2e4" in titles["model_c_Vd_omega.png"]


def test_model_c_at_the_largest_v_d_is_judged_by_adaptive_where_its_tolerances_agree():
    def values(decided):
        return {"omegas": [0.3, 3.0], "model_a": [{"V_d": 10.0, "regimes": ["sliding", "sliding"]}],
                "model_c": [{"V_d": 10.0, "regimes": ["hopping", "hopping"]}], "model_a_amplitude": 2.0,
                "model_c_amplitude": 0.5,
                "model_c_decided": {"V_d": 10.0, "tolerances": [{"rtol": 1e-6}, {"rtol": 1e-8}], "omegas": decided},
                "offsets": [{"V_d": 10.0, "x0": 30.0, "x0_std": 0.1, "force_balance": 30.0, "paper": -20.0,
                             "regime": "sliding"}]}
    sliding = [{"omega": w, "adaptive": ["sliding", "sliding"], "paper_scheme": "hopping", "regime": "sliding"}
               for w in (0.3, 3.0)]
    row, _ = verdict_c8(values(sliding))
    assert row.verdict == AGREES and "symplectic_euler hopping" in row.measured
    unresolved = [sliding[0], {"omega": 3.0, "adaptive": ["sliding", "stick_slip"], "paper_scheme": "hopping",
                               "regime": "unresolved"}]
    row, _ = verdict_c8(values(unresolved))
    assert row.verdict == NOT_REPRODUCED and "w = 3 (unresolved)" in row.reason
