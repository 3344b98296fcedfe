"""The model variants: a registry built from the modules in this package.

A variant is one module ``model_<name>.py`` stating:

* its docstring, whose first line describes it in the FMU and the docs;
* ``PARAMETERS``: the optional common parameters it has (e.g. ``"g"``) and its own
  ``Parameter`` records (corrugation, confining force, ...), in the FMU's order;
* ``DEFAULTS``: common parameters whose default differs for this variant;
* ``profile(x, prm) -> (height, slope)``: the plate surface's static shape, added to
  the plate's vertical motion (Z_p(x, t) = plate(t) + height(x));
* ``load(cos_a, sin_a, prm) -> (fx, fz)``: the confining force on the block, given the
  unit tangent (cos a, sin a) of the surface under it;
* ``curvature(x, prm)`` (optional; zero, a plane, if absent): the profile's second
  derivative h''(x) (the tangent frame's map to a point, ``vibroblock.readings``; not on any kernel's hot path).
* ``FLAT = True`` (optional): the profile has no slope anywhere, so the contact and the
  forces take the lab's frame directly (``flat_plate``), skipping the products by
  cos a = 1 and sin a = 0 on every step.

Everything else (contact, friction, integrators, the FMU, the docs) is shared and
reads this registry: adding a variant is adding a module.  The compiled kernels reach a
variant's ``profile`` and ``load`` through ``profile(kind, ...)`` and
``load(kind, ...)`` below, resolved at compile time from the kernel's constant ``kind``
(the kernels take ``kind`` as a literal; its low bits are the variant's index, the
others the run's readings, ``vibroblock.readings``), so each kernel is compiled for the
variants it is used with only.
"""
from __future__ import annotations

import importlib
import math
import pkgutil
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Callable

from .. import jitcache  # noqa: F401  (before numba: the kernel cache's folder and locator)
from numba import njit, types  # noqa: E402
from numba.extending import overload  # noqa: E402

from ..dispatch import by_kind  # noqa: E402
from ..parameters import COMMON_PARAMETERS, OPTIONAL_COMMON, VARIANT_AFTER, Parameter  # noqa: E402
from ..readings import VARIANT_MASK  # noqa: E402

MODULE_PREFIX = "model_"


@dataclass(frozen=True)
class Variant:
    name: str
    kind: int  # index in the registry; a compile-time constant of the kernels
    description: str
    own_parameters: tuple[Parameter, ...]  # the common ones and the variant's, in the FMU's order
    profile: Callable
    load: Callable
    curvature: Callable
    module: ModuleType

    @property
    def parameters(self) -> tuple[Parameter, ...]:
        """The FMU's parameters of this variant, in order: its own, then the laws' (every
        variant offers them; asked for once the laws are registered, which import the
        variants)."""
        from ..laws import law_parameters
        return self.own_parameters + law_parameters()

    @property
    def fmu_name(self) -> str:
        return f"Block{self.name}"

    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self.parameters}


def _assemble_parameters(module: ModuleType) -> tuple[Parameter, ...]:
    declared = getattr(module, "PARAMETERS", ())
    optional = {p for p in declared if isinstance(p, str)}
    unknown = optional - set(OPTIONAL_COMMON)
    if unknown:
        raise ValueError(f"{module.__name__}: {sorted(unknown)} are not optional common parameters {OPTIONAL_COMMON}")
    own = tuple(p for p in declared if isinstance(p, Parameter))
    overrides = dict(getattr(module, "DEFAULTS", {}))
    out = []
    for p in COMMON_PARAMETERS:
        if p.name in OPTIONAL_COMMON and p.name not in optional:
            continue
        out.append(replace(p, default=overrides.pop(p.name)) if p.name in overrides else p)
        if p.name == VARIANT_AFTER:
            out.extend(own)
    if overrides:
        raise ValueError(f"{module.__name__}: DEFAULTS names unknown parameters {sorted(overrides)}")
    return tuple(out)


@njit(inline="always")
def _flat(x, prm):
    """Curvature of a variant that states none: a plane surface (flat or tilted)."""
    return 0.0


def _discover() -> dict[str, Variant]:
    names = sorted(info.name for info in pkgutil.iter_modules(__path__) if info.name.startswith(MODULE_PREFIX))
    found = {}
    if len(names) > VARIANT_MASK + 1:
        raise RuntimeError(f"more variants than the kernels' kind can hold ({VARIANT_MASK + 1}): widen readings.VARIANT_MASK")
    for kind, module_name in enumerate(names):
        module = importlib.import_module(f"{__name__}.{module_name}")
        name = module_name[len(MODULE_PREFIX):].upper()
        description = module.__doc__.strip().splitlines()[0].rstrip(".")
        found[name] = Variant(name, kind, description, _assemble_parameters(module), module.profile,
                              module.load, getattr(module, "curvature", _flat), module)
    return found


VARIANTS: dict[str, Variant] = _discover()
_BY_KIND = {v.kind: v for v in VARIANTS.values()}
MODELS = {name: v.kind for name, v in VARIANTS.items()}  # name -> kind
DESCRIPTIONS = {name: v.description for name, v in VARIANTS.items()}


def variant(model: str) -> Variant:
    try:
        return VARIANTS[model]
    except KeyError:
        raise KeyError(f"unknown model {model!r}; choose one of {sorted(VARIANTS)}") from None


def parameters_for(model: str) -> tuple[Parameter, ...]:
    """The parameters of one model variant, with that variant's defaults."""
    return variant(model).parameters


def defaults(model: str) -> dict[str, float]:
    return variant(model).defaults()


def offered_by(models: str) -> list[str]:
    """The variants a table entry names: ``*`` for all, else a string of variant names."""
    return sorted(VARIANTS) if models == "*" else [m for m in models if m in VARIANTS]


# ---------------------------------------------------------------- compiled dispatch
# The variants whose module states ``FLAT = True`` (no slope anywhere), one bit per index.
_FLAT_MASK = sum(1 << v.kind for v in VARIANTS.values() if getattr(v.module, "FLAT", False))


@njit(inline="always")
def flat_plate(kind):
    """Whether variant ``kind``'s plate is flat (its module's ``FLAT``).  There the surface's
    frame is the lab's, and the contact and forces skip the products by cos a = 1 and
    sin a = 0: they change no value (at an exact zero, only its sign) but cost a tenth of
    a flat block's step (a folded constant, with the kernels' constant kind)."""
    return (_FLAT_MASK >> (kind & VARIANT_MASK)) & 1 != 0


@njit(inline="always")
def frame(slope):
    """cos a and sin a of the surface's tangent at a point of the given slope (a = arctan
    slope); a flat plate skips the square root (model A's hot path)."""
    if slope == 0.0:
        return 1.0, 0.0
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    return cos_a, slope * cos_a


def profile(kind, x, prm):
    """Surface height and slope of variant ``kind`` at x (compiled code only)."""


def load(kind, cos_a, sin_a, prm):
    """Confining force of variant ``kind`` (compiled code only)."""


def curvature(kind, x, prm):
    """Second derivative h''(x) of variant ``kind``'s surface (compiled code only)."""


def _by_variant(attribute: str, arguments: str):
    """A compiled ``(kind, arguments) -> variant(kind).attribute(arguments)``, branching on
    the variant's index at run time (``vibroblock.dispatch``)."""
    return by_kind({v.kind: getattr(v, attribute) for v in _BY_KIND.values()}, f"kind & {VARIANT_MASK}", arguments)


_PROFILE_BY_VARIANT = _by_variant("profile", "x, prm")
_LOAD_BY_VARIANT = _by_variant("load", "cos_a, sin_a, prm")
_CURVATURE_BY_VARIANT = _by_variant("curvature", "x, prm")


@overload(profile, inline="always")
def _profile(kind, x, prm):
    if isinstance(kind, types.IntegerLiteral):  # specialised on one variant
        geometry = _BY_KIND[kind.literal_value & VARIANT_MASK].profile
        return lambda kind, x, prm: geometry(x, prm)
    if isinstance(kind, types.Integer):
        return lambda kind, x, prm: _PROFILE_BY_VARIANT(kind, x, prm)
    return None


@overload(load, inline="always")
def _load(kind, cos_a, sin_a, prm):
    if isinstance(kind, types.IntegerLiteral):
        force = _BY_KIND[kind.literal_value & VARIANT_MASK].load
        return lambda kind, cos_a, sin_a, prm: force(cos_a, sin_a, prm)
    if isinstance(kind, types.Integer):
        return lambda kind, cos_a, sin_a, prm: _LOAD_BY_VARIANT(kind, cos_a, sin_a, prm)
    return None


@overload(curvature, inline="always")
def _curvature(kind, x, prm):
    if isinstance(kind, types.IntegerLiteral):
        second = _BY_KIND[kind.literal_value & VARIANT_MASK].curvature
        return lambda kind, x, prm: second(x, prm)
    if isinstance(kind, types.Integer):
        return lambda kind, x, prm: _CURVATURE_BY_VARIANT(kind, x, prm)
    return None
