"""The readings of the paper a run chooses (docs/physics.md): ``formulation``,
``coulomb_normal`` and ``flight``, encoded in the kernels' literal ``kind``.

They are constants of a run, so they are compile-time constants of the kernels: ``kind``
is the variant's index plus one bit per non-default reading, and the compiled helpers
below (``tangent_frame(kind)``, ``applied_load(kind)``, ``free_flight(kind)``) return
constants resolved when a kernel is specialised, so every branch on them folds away.
The default reading (all three 0) is the variant's index alone: its kernels are the
ones compiled before these options existed.

``kind`` = variant index (bits 0-2) | TANGENT_FRAME | APPLIED_LOAD | FREE_FLIGHT.
"""
from __future__ import annotations

from . import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import types  # noqa: E402
from numba.extending import overload  # noqa: E402

VARIANT_MASK = 0b111
TANGENT_FRAME = 1 << 3  # formulation = 1
APPLIED_LOAD = 1 << 4  # coulomb_normal = 1
FREE_FLIGHT = 1 << 5  # flight = 1


def encode(variant_kind: int, formulation: int = 0, coulomb_normal: int = 0, flight: int = 0) -> int:
    """The kernels' ``kind`` for a variant and its readings."""
    return (variant_kind | (TANGENT_FRAME if formulation else 0) | (APPLIED_LOAD if coulomb_normal else 0)
            | (FREE_FLIGHT if flight else 0))


def variant_kind(kind: int) -> int:
    return kind & VARIANT_MASK


# ---------------------------------------------------------------- compiled constants
def tangent_frame(kind):
    """True if ``kind`` integrates the paper's Eqs. (3)-(6) as printed (compiled code only)."""


def applied_load(kind):
    """True if the Coulomb bound's N is the applied load (compiled code only)."""


def free_flight(kind):
    """True if a block off contact is a free particle (compiled code only)."""


def _constant(bit):
    def typer(kind):
        if isinstance(kind, types.IntegerLiteral):
            value = bool(kind.literal_value & bit)
            return lambda kind: value
        return None  # the kernel must pass kind as a literal (numba.literally)
    return typer


overload(tangent_frame, inline="always")(_constant(TANGENT_FRAME))
overload(applied_load, inline="always")(_constant(APPLIED_LOAD))
overload(free_flight, inline="always")(_constant(FREE_FLIGHT))
