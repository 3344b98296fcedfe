"""The readings of the paper's equations a claim is measured under (docs/physics.md).

The paper's Eqs. (3)-(6) admit two formulations of models B and C (``formulation``:
``fixed_axes``, Newton's law for the point in fixed axes, or ``tangent_frame``, the
equations as printed) and two readings of the N in the Coulomb bound mu_s N
(``coulomb_normal``: ``contact_force`` or ``applied_load``).  The claims these readings
can change (C2, C5-C8) are measured under all four combinations; the report shows the
verdicts side by side and says where a verdict flips with the reading.

Model A has no corrugation, so ``formulation`` does not exist for it: its runs under the
two formulations are the same run (the point store holds it once).  A parameter a study
sets itself is never overridden by the reading.
"""
from __future__ import annotations

from dataclasses import dataclass

FORMULATIONS = ("fixed_axes", "tangent_frame")
COULOMB_NORMALS = ("contact_force", "applied_load")
# Models whose FMU has the ``formulation`` parameter (the corrugated ones).
CORRUGATED = frozenset("BC")


@dataclass(frozen=True)
class Reading:
    formulation: int = 0
    coulomb_normal: int = 0

    @property
    def key(self) -> str:
        """Short name, used in study names (``C7@tangent_frame+applied_load``)."""
        return f"{FORMULATIONS[self.formulation]}+{COULOMB_NORMALS[self.coulomb_normal]}"

    @property
    def label(self) -> str:
        return f"{FORMULATIONS[self.formulation].replace('_', ' ')}, {COULOMB_NORMALS[self.coulomb_normal].replace('_', ' ')}"

    @property
    def is_default(self) -> bool:
        return self == DEFAULT_READING

    def parameters(self, model: str) -> dict[str, float]:
        """The FMU parameters this reading sets on a run of ``model`` (none for the default,
        so default runs keep the point store's keys they always had)."""
        values = {}
        if self.formulation and model.upper() in CORRUGATED:
            values["formulation"] = float(self.formulation)
        if self.coulomb_normal:
            values["coulomb_normal"] = float(self.coulomb_normal)
        return values


DEFAULT_READING = Reading()
READINGS = (DEFAULT_READING, Reading(1, 0), Reading(0, 1), Reading(1, 1))
# The readings that differ for a claim measured on model A alone.
A_READINGS = (DEFAULT_READING, Reading(0, 1))


def study_name(claim: str, reading: Reading) -> str:
    """The name a claim's study under ``reading`` is stored as (the default: the claim's name)."""
    return claim if reading.is_default else f"{claim}@{reading.key}"


def split_study_name(name: str) -> tuple[str, Reading]:
    """Inverse of :func:`study_name`."""
    claim, _, key = name.partition("@")
    if not key:
        return claim, DEFAULT_READING
    formulation, _, bound = key.partition("+")
    return claim, Reading(FORMULATIONS.index(formulation), COULOMB_NORMALS.index(bound))
