"""FMI access and co-simulation masters: :mod:`.fmu` (extraction, instances, pools through
fmpy), :mod:`.masters` (libcosim), :mod:`.ssp` (SSP files connecting Excitation -> Block).

A process that imports this package releases, when it exits, the interpreter guard of
every pythonfmu FMU library it loaded (:mod:`.exit_guard`): plain pythonfmu 0.7.0 FMUs
otherwise corrupt the heap at process exit."""
from . import exit_guard as _exit_guard

_exit_guard.install()
