"""vibroblock harness: runs, observables, sweeps and continuation on the Block FMUs.

The harness drives the FMUs through fmpy (it never calls the physics core directly)::

    from harness.settings import ObservableSettings, PointSettings, RunSettings
    from harness.run import simulate, run_point
    from harness.observables import observe
    from harness.sweep import Grid, sweep, run_sweep, Execution
    from harness.continuation import Ramp, continuation, fresh_starts

* :mod:`harness.settings` -- frozen dataclasses: RunSettings (FMU, parameters, horizon,
  output interval, Integration, InitialCondition), ObservableSettings, PointSettings.
* :mod:`harness.fmu` -- extraction keyed by the FMU's sha256, FmuInstance (instantiate
  once, reset between runs, FMI errors as FmuError with the FMU's log), InstancePool.
* :mod:`harness.run` -- simulate(settings) -> xarray Dataset; run_point(point) -> Observables.
* :mod:`harness.observables` -- phi, regime, slip statistics, contact fraction, drift.
* :mod:`harness.sweep` -- grids, Dask execution (LocalCluster or a given scheduler),
  resumable through :mod:`harness.store` (one JSON file per finished point).
* :mod:`harness.continuation` -- quasi-static ramps carrying the FMU state (hysteresis).
* :mod:`harness.cli` -- ``vibroblock run | sweep | continuation`` (``python -m harness``).

Importing this package imports nothing else, so ``harness.records`` and the other
subpackages load only what they use.
"""
