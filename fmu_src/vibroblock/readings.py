"""The physics a run chooses, as the kernels' ``kind``: the variant, the readings of the
paper (docs/physics.md: ``formulation``, ``flight``) and the laws (``vibroblock.laws``:
``contact``, ``coulomb_normal``, ...).

They are constants of a run.  ``kind`` is a plain integer the kernels branch on (a
perfectly predicted branch), so one compiled kernel serves every combination: the
compiled helpers below (``tangent_frame(kind)``, ``free_flight(kind)``) and the laws'
dispatch read their bits at run time.  (Given a numba literal instead, they fold to
constants.)  The defaults (every choice 0) are the variant's index alone.

``kind`` = variant index (bits 0-2) | TANGENT_FRAME | FREE_FLIGHT | the laws' bits
(``laws.AXES``: the contact law bits 6-7, the Coulomb bound bits 10-11, ...).
"""
from __future__ import annotations

from . import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import types  # noqa: E402
from numba.extending import overload  # noqa: E402

VARIANT_MASK = 0b111
TANGENT_FRAME = 1 << 3  # formulation = 1
FREE_FLIGHT = 1 << 5  # flight = 1


def encode(variant_kind: int, choices: dict | None = None) -> int:
    """The kernels' ``kind`` for a variant and its readings and laws ({name: value},
    absent: 0)."""
    from .laws import encode as law_bits  # (the laws import the variants, which import this module)
    choices = choices or {}
    return (variant_kind | (TANGENT_FRAME if choices.get("formulation") else 0)
            | (FREE_FLIGHT if choices.get("flight") else 0) | law_bits(choices))


def choices() -> dict[str, tuple[str, dict[int, str]]]:
    """Every Integer choice of the physics, in the FMU's order: the readings
    (``parameters.READINGS``) and the laws (``laws.choices``), name -> (variants,
    {value: "name: meaning"})."""
    from .laws import choices as law_choices
    from .parameters import READINGS
    laws = law_choices()
    return {"formulation": READINGS["formulation"], "coulomb_normal": laws.pop("coulomb_normal"),
            "flight": READINGS["flight"], **laws}


def variant_kind(kind: int) -> int:
    return kind & VARIANT_MASK


# ---------------------------------------------------------------- compiled constants
def tangent_frame(kind):
    """True if ``kind`` integrates the paper's Eqs. (3)-(6) as printed (compiled code only)."""


def free_flight(kind):
    """True if a block off contact is a free particle (compiled code only)."""


def _constant(bit):
    def typer(kind):
        if isinstance(kind, types.IntegerLiteral):  # folded away where a kernel is specialised on kind
            value = bool(kind.literal_value & bit)
            return lambda kind: value
        if isinstance(kind, types.Integer):  # a run constant: a perfectly predicted branch
            return lambda kind: (kind & bit) != 0
        return None
    return typer


overload(tangent_frame, inline="always")(_constant(TANGENT_FRAME))
overload(free_flight, inline="always")(_constant(FREE_FLIGHT))
