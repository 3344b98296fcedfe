"""The regime arithmetic of the studies on known cases."""
from __future__ import annotations

import math

from harness.paper.claims.measure import recovery, stable_roots_near, transition_bracket


def test_helpers_on_known_cases():
    assert transition_bracket([1, 2, 3], ["stick_slip", "stuck", "sliding"]) == (2.0, 3.0)
    assert transition_bracket([1, 2], ["stick_slip", "stick_slip"]) == (2.0, None)
    found = recovery([1, 2, 3, 4], ["stuck", "sliding", "sliding", "stick_slip"])
    assert (found["omega_1"], found["omega_2"], found["last_sliding"]) == (2.0, 4.0, 3.0)
    # K small: the stable root near the valley (sin < 0) at drive = x.
    root = stable_roots_near(3 * math.pi / (2 * 0.02), 3 * math.pi / (2 * 0.02), -5e-4)
    assert math.sin(0.02 * root) < 0 and abs(math.cos(0.02 * root)) < 1e-3
