"""Verdict words, the :class:`Row` of the claims table and the arithmetic the verdicts share.

Verdicts are computed from the numbers a study measured, never written by hand:

* ``agrees``: the claim's criterion holds;
* ``disagrees``: it was measured and does not hold;
* ``not reproduced``: the study could not measure what the criterion needs (e.g. no
  transition in the scanned range, no complete slip in the window);
* ``flips with the reading``: the claim was measured under several readings of the
  paper's equations (:mod:`.readings`) and it agrees under some of them and not under
  others (the report gives each); where it agrees under none, the verdict is the worse
  one (``disagrees`` before ``not reproduced``).

Each claim's module states its criteria; the tolerances several claims use are here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

AGREES, DISAGREES, NOT_REPRODUCED = "agrees", "disagrees", "not reproduced"
FLIPS = "flips with the reading"
FORMULA_TOLERANCE = 0.10    # relative, a measured value against its formula
UNCHANGED_TOLERANCE = 0.10  # relative, "unchanged" against a reference run


@dataclass
class Row:
    claim: str
    measured: str
    verdict: str
    reason: str
    figures: list = field(default_factory=list)
    settings: str = ""


def fmt(value, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return f"{float(value):.{digits}g}"


def relative(measured, expected) -> float:
    if measured is None or expected in (None, 0) or not math.isfinite(float(measured)):
        return math.inf
    return abs(float(measured) / float(expected) - 1.0)


def combine(parts: Sequence[tuple[str, str]]) -> tuple[str, str]:
    """Overall verdict of parts (verdict, text): any disagreement wins, then not reproduced."""
    verdicts = [v for v, _ in parts]
    overall = DISAGREES if DISAGREES in verdicts else NOT_REPRODUCED if NOT_REPRODUCED in verdicts else AGREES
    return overall, "; ".join(f"{text} ({v})" for v, text in parts)


