"""vibroblock harness: runs, observables, sweeps and continuation on the Block FMUs.

The harness drives the FMUs through fmpy (it never calls the physics core directly)::

    from harness.runs.settings import ObservableSettings, PointSettings, RunSettings
    from harness.runs.run import simulate, run_point
    from harness.runs.observables import observe
    from harness.runs.sweep import Grid, sweep, run_sweep, Execution
    from harness.runs.continuation import Ramp, continuation, fresh_starts

* :mod:`harness.runs.settings` -- frozen dataclasses: RunSettings (FMU, parameters, horizon,
  output interval, Integration, InitialCondition), ObservableSettings, PointSettings.
* :mod:`harness.cosim.fmu` -- extraction keyed by the FMU's sha256, FmuInstance (instantiate
  once, reset between runs, FMI errors as FmuError with the FMU's log), InstancePool.
* :mod:`harness.runs.run` -- simulate(settings) -> xarray Dataset; run_point(point) -> Observables.
* :mod:`harness.runs.observables` -- phi, regime, slip statistics, contact fraction, drift.
* :mod:`harness.runs.sweep` -- grids, Dask execution (LocalCluster or a given scheduler),
  resumable through :mod:`harness.runs.store` (one JSON file per finished point).
* :mod:`harness.runs.continuation` -- quasi-static ramps carrying the FMU state (hysteresis).
* :mod:`harness.runs.cli` -- ``vibroblock run | sweep | continuation`` (``python -m harness``).

Importing this package imports nothing else, so ``harness.ground.records`` and the other
subpackages load only what they use.
"""
