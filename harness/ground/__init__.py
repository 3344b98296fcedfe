"""Ground motion: :mod:`.records` (seismic record ingest), :mod:`.excitation` (a record or
signal -> plate input), :mod:`.compose` (Excitation and Block FMUs together) and
:mod:`.triggering` (when a record triggers a slip)."""
