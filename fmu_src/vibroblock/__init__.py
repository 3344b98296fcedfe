"""vibroblock: a spring-block on a vibrating plate (Giacco, Lippiello, Pica Ciamarra).

The physics core bundled into the FMUs and used by the harness.
"""
import os as _os

# Compiled kernels are cached on disk; an FMU is often extracted to a fresh folder, so
# unless the host chose a cache folder, use a stable per-user one (numba reads the
# setting when it is first imported, which happens just below).
_os.environ.setdefault("NUMBA_CACHE_DIR", _os.path.join(
    _os.environ.get("XDG_CACHE_HOME") or _os.path.join(_os.path.expanduser("~"), ".cache"), "vibroblock", "numba"))

from . import jitcache  # noqa: E402

jitcache.install()

from .block import OUTPUTS, Block, ModelError, detachment_amplitude, steady_orbit  # noqa: E402
from .models import DESCRIPTIONS as MODEL_DESCRIPTIONS  # noqa: E402
from .models import MODELS  # noqa: E402
from .parameters import INITIAL_STATES, PARAMETERS, defaults, parameters_for  # noqa: E402
from .stepping import FORCE_EVALUATIONS, INTEGRATORS  # noqa: E402

__all__ = ["Block", "ModelError", "OUTPUTS", "MODELS", "MODEL_DESCRIPTIONS", "INTEGRATORS", "FORCE_EVALUATIONS",
           "INITIAL_STATES", "PARAMETERS", "defaults", "parameters_for", "detachment_amplitude", "steady_orbit"]
