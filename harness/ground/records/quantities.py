"""Kinematic quantities and their units.

A record holds one of three kinematic quantities, :class:`Quantity`. Units
are given as short strings and converted to SI with :func:`si_factor`::

    >>> si_factor("acceleration", "cm/s^2")
    0.01
    >>> si_factor("acceleration", "g")
    9.80665

Accepted spellings (case-insensitive, spaces ignored, ``²``/``**2``/``/s/s``
all mean "per second squared", ``sec`` means ``s``, ``µ`` may be written
``u``):

============  =================================================
quantity      units
============  =================================================
displacement  ``m``, ``cm``, ``mm``, ``um``, ``nm``
velocity      ``m/s``, ``cm/s``, ``mm/s``, ``um/s``, ``nm/s``
acceleration  ``m/s^2``, ``cm/s^2`` (= ``gal``), ``mm/s^2``,
              ``um/s^2``, ``nm/s^2``, ``g``
============  =================================================

The unit ``g`` is standard gravity, :data:`STANDARD_GRAVITY` = 9.80665 m/s²
(the convention of strong-motion databases such as PEER NGA).
"""

from __future__ import annotations

import enum
import re

from .errors import RecordError

__all__ = ["STANDARD_GRAVITY", "Quantity", "parse_quantity", "si_factor", "SI_UNITS"]

#: Standard gravity in m/s², the value of the acceleration unit ``g``.
STANDARD_GRAVITY: float = 9.80665


class Quantity(str, enum.Enum):
    """Kinematic quantity of a time series (value is the lower-case name)."""

    DISPLACEMENT = "displacement"
    VELOCITY = "velocity"
    ACCELERATION = "acceleration"

    @property
    def order(self) -> int:
        """Number of time derivatives from displacement (0, 1 or 2)."""
        return {"displacement": 0, "velocity": 1, "acceleration": 2}[self.value]


#: SI unit string of each quantity, as written into dataset attributes.
SI_UNITS: dict[Quantity, str] = {
    Quantity.DISPLACEMENT: "m",
    Quantity.VELOCITY: "m/s",
    Quantity.ACCELERATION: "m/s^2",
}

_QUANTITY_ALIASES: dict[str, Quantity] = {
    "displacement": Quantity.DISPLACEMENT,
    "disp": Quantity.DISPLACEMENT,
    "velocity": Quantity.VELOCITY,
    "vel": Quantity.VELOCITY,
    "acceleration": Quantity.ACCELERATION,
    "accel": Quantity.ACCELERATION,
    "acc": Quantity.ACCELERATION,
}

_PREFIX = {"": 1.0, "c": 1e-2, "m": 1e-3, "u": 1e-6, "n": 1e-9}

_UNITS: dict[str, tuple[Quantity, float]] = {}
for _p, _f in _PREFIX.items():
    _UNITS[f"{_p}m"] = (Quantity.DISPLACEMENT, _f)
    _UNITS[f"{_p}m/s"] = (Quantity.VELOCITY, _f)
    _UNITS[f"{_p}m/s^2"] = (Quantity.ACCELERATION, _f)
_UNITS["gal"] = (Quantity.ACCELERATION, 1e-2)
_UNITS["g"] = (Quantity.ACCELERATION, STANDARD_GRAVITY)


def parse_quantity(quantity: Quantity | str) -> Quantity:
    """Return the :class:`Quantity` named by *quantity*.

    Accepts the enum itself, the full names and the short forms ``disp``,
    ``vel``, ``acc``/``accel`` (any case, so obspy's ``"DISP"``, ``"VEL"``,
    ``"ACC"`` work too).

    Raises:
        RecordError: for any other string.
    """
    if isinstance(quantity, Quantity):
        return quantity
    key = str(quantity).strip().lower()
    try:
        return _QUANTITY_ALIASES[key]
    except KeyError:
        raise RecordError(
            f"unsupported quantity {quantity!r}; use one of 'acceleration', "
            "'velocity' or 'displacement' (or 'acc', 'vel', 'disp')"
        ) from None


def _normalise_unit(unit: str) -> str:
    u = str(unit).strip().replace(" ", "").replace("µ", "u").replace("μ", "u")
    if u == "G":  # the only case-sensitive spelling: capital G is gravity too
        return "g"
    u = u.lower()
    u = u.replace("²", "^2").replace("**2", "^2").replace("sec", "s")
    u = re.sub(r"/s/s$", "/s^2", u)
    u = re.sub(r"/s2$", "/s^2", u)
    return u


def si_factor(quantity: Quantity | str, unit: str) -> float:
    """Factor that converts values of *quantity* given in *unit* to SI.

    Args:
        quantity: the kinematic quantity the values represent.
        unit: the unit the values are expressed in (see module docstring).

    Returns:
        The multiplier to SI (m, m/s or m/s²).

    Raises:
        RecordError: if the unit is unknown or does not belong to *quantity*
            (e.g. ``"cm/s"`` for an acceleration).
    """
    q = parse_quantity(quantity)
    key = _normalise_unit(unit)
    if key not in _UNITS:
        known = ", ".join(sorted(k for k, (qq, _) in _UNITS.items() if qq is q))
        raise RecordError(
            f"unsupported unit {unit!r} for {q.value}; use one of: {known}"
        )
    unit_quantity, factor = _UNITS[key]
    if unit_quantity is not q:
        raise RecordError(
            f"unit {unit!r} is a unit of {unit_quantity.value}, but the data "
            f"were declared as {q.value}; fix the quantity or the unit"
        )
    return factor
