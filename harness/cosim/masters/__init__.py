"""Co-simulation masters that run vibroblock's FMUs besides fmpy.

* :mod:`.libcosim` — :func:`run_libcosim` (one FMU) and :func:`run_libcosim_system`
  (several FMUs coupled output -> input) run FMI 2.0 co-simulation FMUs in DNV's
  libcosim through ``libcosimpy``, with fmpy's result layout (``time`` plus one
  array per output, first row at the start time).  Each run happens in its own
  process; the module docstring says why and lists libcosim's stepping and
  coupling conventions.
* :mod:`.errors` — :class:`SetupError` for requests that cannot be run (unknown
  names, wrong types, a grid libcosim cannot represent) and :class:`LibcosimError`
  for failures reported by libcosim or the FMU, carrying the FMU's log lines.
"""

from .errors import LibcosimError, SetupError
from .libcosim import run_libcosim, run_libcosim_system

__all__ = ["run_libcosim", "run_libcosim_system", "LibcosimError", "SetupError"]
