"""The readings of the paper's equations a claim is measured under (docs/physics.md).

The paper's Eqs. (3)-(6) admit two formulations of models B and C (``formulation``:
``fixed_axes``, Newton's law for the point in fixed axes, or ``tangent_frame``, the
equations as printed) and two readings of the N in the Coulomb bound mu_s N
(``coulomb_normal``: ``contact_force`` or ``applied_load``).  The claims these readings
can change (C2, C5-C8) are measured under all four combinations; the report shows the
verdicts side by side and says where a verdict flips with the reading.

Beside the readings, two laws of the FMUs change what a claim may measure
(``LAW_READINGS``, measured by the main job unless ``--no-laws``; C6 under them measures
Fig. 5's diagram, not its k_n sweep and ramp): the Coulomb
bound ``load_only`` (N = the applied load's normal component alone, the paper's "mu_s m g"
without the drive spring's share) and the contact laws ``linear_along_normal`` (the
force k_n delta n of earlier releases, not conservative on a curved plate) and
``linear_no_pull`` (the paper's spring and dashpot, clipped at N = 0); the default
contact ``linear`` is the conservative one in fixed axes.

Model A has no corrugation, so ``formulation`` does not exist for it: its runs under the
two formulations are the same run (the point store holds it once).  A parameter a study
sets itself is never overridden by the reading.
"""
from __future__ import annotations

from dataclasses import dataclass

FORMULATIONS = ("fixed_axes", "tangent_frame")
COULOMB_NORMALS = ("contact_force", "applied_load", "load_only")
CONTACT_LAWS = ("linear", "linear_along_normal", "linear_no_pull")
# Models whose FMU has the ``formulation`` parameter (the corrugated ones).
CORRUGATED = frozenset("BC")


@dataclass(frozen=True)
class Reading:
    formulation: int = 0
    coulomb_normal: int = 0
    contact_law: int = 0

    @property
    def key(self) -> str:
        """Short name, used in study names (``C7@tangent_frame+applied_load``, and the
        contact law third where it is not the default: ``C7@fixed_axes+contact_force+linear_no_pull``)."""
        key = f"{FORMULATIONS[self.formulation]}+{COULOMB_NORMALS[self.coulomb_normal]}"
        return key + (f"+{CONTACT_LAWS[self.contact_law]}" if self.contact_law else "")

    @property
    def label(self) -> str:
        label = (f"{FORMULATIONS[self.formulation].replace('_', ' ')}, "
                 f"{COULOMB_NORMALS[self.coulomb_normal].replace('_', ' ')}")
        return label + (f", {CONTACT_LAWS[self.contact_law].replace('_', ' ')} contact" if self.contact_law else "")

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
        if self.contact_law:
            values["contact_law"] = float(self.contact_law)
        return values


DEFAULT_READING = Reading()
READINGS = (DEFAULT_READING, Reading(1, 0), Reading(0, 1), Reading(1, 1))
# The readings that differ for a claim measured on model A alone.
A_READINGS = (DEFAULT_READING, Reading(0, 1))
# The laws measured beside the readings on request, in fixed axes with the contact-force
# bound unless the law is the bound: the load-only bound, the earlier non-conservative
# contact and the contact that never pulls.  On model A the contact's direction is the
# flat plate's normal, so linear_along_normal is the default contact there.
LAW_READINGS = (Reading(0, 2), Reading(0, 0, 1), Reading(0, 0, 2))
A_LAW_READINGS = (Reading(0, 2), Reading(0, 0, 2))
ALL_READINGS = READINGS + LAW_READINGS


def law_readings(claim_readings: tuple) -> tuple:
    """The law readings measured beside the paper's readings for a claim measured under ``claim_readings``:
    none for a claim the readings cannot change (default reading only)."""
    if len(claim_readings) < 2:
        return ()
    return LAW_READINGS if claim_readings == READINGS else A_LAW_READINGS


def study_name(claim: str, reading: Reading) -> str:
    """The name a claim's study under ``reading`` is stored as (the default: the claim's name)."""
    return claim if reading.is_default else f"{claim}@{reading.key}"


def split_study_name(name: str) -> tuple[str, Reading]:
    """Inverse of :func:`study_name`."""
    claim, _, key = name.partition("@")
    if not key:
        return claim, DEFAULT_READING
    formulation, _, rest = key.partition("+")
    bound, _, contact = rest.partition("+")
    return claim, Reading(FORMULATIONS.index(formulation), COULOMB_NORMALS.index(bound),
                          CONTACT_LAWS.index(contact) if contact else 0)
