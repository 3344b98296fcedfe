"""Transitions located by bisection, starting from the brackets a coarse grid shows.

A sweep along one parameter classifies every grid value as "held by friction" or not.
Each change between neighbours brackets a transition; :func:`locate_transitions`
halves every bracket (in log scale for positive values, the geometric mean, since the
grids are geometric) until ``hi / lo - 1 <= resolution``, classifying the midpoints of all
open brackets of one round in a single batch so that they run in parallel.
:func:`refine` does the same for brackets gathered elsewhere (several columns of a phase
diagram at once, each transition carrying where it lies in ``where``).

Bisection finds *a* change of class inside each bracket.  Where the class flips more
than once between two grid values (near-marginal or chaotic points), the located value
is one of those changes; the grid is kept for the figure so that a reader can see it.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Callable, Sequence

LOSS, RECOVERY = "loss", "recovery"  # held -> not held, not held -> held, along ascending values


@dataclass
class Transition:
    """One located change of class between ``lo`` (class ``held_lo``) and ``hi``."""

    lo: float
    hi: float
    held_lo: bool
    evaluations: list[tuple[float, bool]] = field(default_factory=list)  # bisection points, in order
    where: dict = field(default_factory=dict)  # the other coordinates of the bracket, if any

    @property
    def kind(self) -> str:
        return LOSS if self.held_lo else RECOVERY

    @property
    def value(self) -> float:
        """Best estimate: the bracket's midpoint (geometric for positive brackets)."""
        return _midpoint(self.lo, self.hi)

    @property
    def resolution(self) -> float:
        """Relative width of the bracket."""
        return _relative_width(self.lo, self.hi)

    def as_dict(self) -> dict:
        return {**asdict(self), "kind": self.kind, "value": self.value, "resolution": self.resolution}


def _midpoint(lo: float, hi: float) -> float:
    return math.sqrt(lo * hi) if lo > 0 and hi > 0 else 0.5 * (lo + hi)


def _relative_width(lo: float, hi: float) -> float:
    return hi / lo - 1.0 if lo > 0 and hi > 0 else abs(hi - lo) / max(abs(lo), abs(hi))


def brackets(values: Sequence[float], held: Sequence[bool]) -> list[Transition]:
    """Every change of class between neighbouring grid values (ascending values)."""
    if len(values) != len(held):
        raise ValueError(f"{len(values)} values but {len(held)} classes")
    if any(b <= a for a, b in zip(values[:-1], values[1:])):
        raise ValueError("grid values must be strictly ascending")
    return [Transition(float(a), float(b), bool(ha))
            for a, b, ha, hb in zip(values[:-1], values[1:], held[:-1], held[1:]) if bool(ha) != bool(hb)]


def locate_transitions(classify: Callable[[list[float]], list[bool]], values: Sequence[float],
                       held: Sequence[bool], resolution: float = 0.03, max_rounds: int = 20) -> list[Transition]:
    """Bisect every bracket of the grid ``values`` (classes ``held``) to ``resolution``.

    ``classify(points)`` returns, for a batch of parameter values, whether each is held by
    friction; it is called once per round with the midpoints of all open brackets."""
    return refine(lambda pairs: classify([point for _, point in pairs]), brackets(values, held), resolution,
                  max_rounds)


def refine(classify: Callable[[list[tuple[Transition, float]]], list[bool]], found: list[Transition],
           resolution: float = 0.03, max_rounds: int = 20) -> list[Transition]:
    """Bisect the given brackets in place to ``resolution``; ``classify`` gets, once per
    round, (transition, midpoint) for every open bracket and returns whether each midpoint
    is held.  Returns ``found``."""
    if not resolution > 0:
        raise ValueError(f"resolution = {resolution!r} must be > 0")
    for _ in range(max_rounds):
        open_ = [t for t in found if t.resolution > resolution]
        if not open_:
            break
        midpoints = [_midpoint(t.lo, t.hi) for t in open_]
        classes = classify(list(zip(open_, midpoints)))
        if len(classes) != len(midpoints):
            raise ValueError(f"classify returned {len(classes)} classes for {len(midpoints)} points")
        for transition, point, held_mid in zip(open_, midpoints, classes):
            transition.evaluations.append((point, bool(held_mid)))
            if bool(held_mid) == transition.held_lo:
                transition.lo = point
            else:
                transition.hi = point
    return found


__all__ = ["LOSS", "RECOVERY", "Transition", "brackets", "locate_transitions", "refine"]
