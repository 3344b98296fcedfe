"""Runs and what is built on them: :mod:`.settings`, :mod:`.run` (one run -> Dataset),
:mod:`.observables`, :mod:`.sweep` (grids on Dask), :mod:`.store` (resumable point
store), :mod:`.continuation` (ramps carrying the FMU state), :mod:`.dataset_files` and
the command line :mod:`.cli`."""
