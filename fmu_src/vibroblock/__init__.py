"""vibroblock: a spring-block on a vibrating plate (Giacco, Lippiello, Pica Ciamarra).

The physics core bundled into the FMUs and used by the harness.  Importing the package
(or ``vibroblock.orbits``, ``vibroblock.parameters``) loads no compiler and changes no
setting; the names below are loaded on first use.
"""
from __future__ import annotations

import importlib

# name -> module that defines it, imported on first access (PEP 562)
_LAZY = {
    "Block": "block", "ModelError": "settings", "OUTPUTS": "interface",
    "MODELS": "models", "MODEL_DESCRIPTIONS": "models", "VARIANTS": "models", "parameters_for": "models",
    "defaults": "models",
    "INTEGRATORS": "integrators",
    "INITIAL_STATES": "parameters", "PARAMETERS": "parameters",
    "detachment_amplitude": "orbits", "friction_loss_amplitude": "orbits", "steady_orbit": "orbits",
}
_RENAMED = {"MODEL_DESCRIPTIONS": "DESCRIPTIONS", "PARAMETERS": "COMMON_PARAMETERS"}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'vibroblock' has no attribute {name!r}")
    module = importlib.import_module(f".{_LAZY[name]}", __name__)
    value = getattr(module, _RENAMED.get(name, name))
    globals()[name] = value
    return value
