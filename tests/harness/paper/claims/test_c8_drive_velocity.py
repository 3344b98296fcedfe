"""C8's verdicts: sliding at the largest V_d, the sign of the offset x0."""
from __future__ import annotations

from harness.paper.claims.c8_drive_velocity import verdict_c8
from harness.paper.claims.verdicts import AGREES, DISAGREES


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
