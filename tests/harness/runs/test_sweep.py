"""Sweeps: grids, equality with direct runs, worker-side FMU reuse."""
from __future__ import annotations

import dataclasses
import json
import os

import numpy as np
import pytest

from harness.runs.observables import MEASURED
from harness.runs.run import run_point
from harness.runs.settings import Integration, ObservableSettings, PointSettings, RunSettings
from harness.runs.sweep import (INLINE, Axis, Execution, Grid, SweepError, close_client, evaluate_expression, open_client,
                           points_of, run_sweep, worker_pool_loads)


def base_point(fmu, horizon=3000.0, transient=500.0):
    return PointSettings(RunSettings.for_model("A", fmu=str(fmu), horizon=horizon),
                         ObservableSettings(transient=transient))


def test_axis_and_grid_parsing():
    np.testing.assert_allclose(Axis.parse("A=0.1:2:8").values, np.linspace(0.1, 2, 8))
    np.testing.assert_allclose(Axis.parse("V_d=1e-3:1e-1:3:log").values, [1e-3, 1e-2, 1e-1])
    assert Axis.parse("omega=0.2, 0.5,1").values == (0.2, 0.5, 1.0)
    assert Axis.parse("A=2").values == (2.0,)
    for bad in ("A", "A=", "A=1:2", "A=1:2:3:cubic", "A=x", "A=1,1"):
        with pytest.raises(ValueError):
            Axis.parse(bad)
    grid = Grid.parse(["A=0:1:3", "omega=0.5,0.7"], ["gamma_n=A/10"])
    assert grid.shape == (3, 2) and len(grid) == 6 and grid.derived == (("gamma_n", "A/10"),)


def test_derived_expressions_are_arithmetic_only():
    assert evaluate_expression("k_n / ratio + 2**2 - sqrt(4)", {"k_n": 6.0, "ratio": 3.0}) == 4.0
    for bad in ("__import__('os').getcwd()", "k_n.real", "[1][0]", "lambda: 1", "unknown * 2"):
        with pytest.raises(ValueError):
            evaluate_expression(bad, {"k_n": 1.0})


def test_grid_with_a_derived_parameter_holds_the_ratio_fixed(fmu_a, tmp_path):
    grid = Grid.parse(["k_n=1,2", "ratio=10,20"], ["gamma_n=k_n/ratio"])
    base = base_point(fmu_a, horizon=60.0, transient=10.0)
    points = points_of(grid, base)
    for point in points:
        values = point.inputs["fmu_values"]
        assert values["gamma_n"] == pytest.approx(values["k_n"] / point.coordinates["ratio"])
    ds = run_sweep(grid, base, tmp_path / "store", Execution(scheduler=INLINE, progress=False)).dataset
    assert ds.phi.dims == ("k_n", "ratio")
    np.testing.assert_allclose(ds.gamma_n.values, ds.k_n.values[:, None] / ds.ratio.values[None, :])
    with pytest.raises(ValueError, match="not a parameter"):
        points_of(Grid.parse(["stiffness=1,2"]), base)


def test_an_integration_switched_by_omega_runs_each_point_with_its_own_integrator(fmu_a, tmp_path):
    switched = Integration("event_driven", switch=(("omega", 0.6),), integrator_above="symplectic_euler")
    base = base_point(fmu_a, horizon=200.0, transient=50.0)
    base = dataclasses.replace(base, run=dataclasses.replace(base.run, integration=switched))
    grid = Grid.parse(["omega=0.5,0.6,0.9"])
    points = points_of(grid, base)
    assert [p.inputs["fmu_values"]["integrator"] for p in points] == ["event_driven", "event_driven",
                                                                      "symplectic_euler"]
    ds = run_sweep(grid, base, tmp_path / "store", Execution(scheduler=INLINE, progress=False)).dataset
    assert ds.attrs["integrator_name"] == switched.describe() and "integrator" not in ds.attrs
    # Each point equals the run with its integrator named outright (which differs between them).
    for point, integrator in zip(points, ("event_driven", "event_driven", "symplectic_euler")):
        run = dataclasses.replace(point.settings.run, integration=Integration(integrator))
        direct = run_point(dataclasses.replace(point.settings, run=run)).as_dict()
        assert ds.phi.sel(omega=point.coordinates["omega"]).item() == direct["phi"]
    other = run_point(dataclasses.replace(points[0].settings, run=dataclasses.replace(
        points[0].settings.run, integration=Integration("symplectic_euler")))).as_dict()
    assert other["phi"] != ds.phi.sel(omega=0.5).item()
    # Without omega a switched run cannot choose, and says so.
    with pytest.raises(ValueError, match="switched by omega needs the run's value"):
        RunSettings(integration=switched).fmu_values()
    assert RunSettings(integration=switched).fmu_values({"omega": 0.9})["integrator"] == "symplectic_euler"
    with pytest.raises(ValueError, match="together"):
        Integration("adaptive", switch=(("omega", 1.0),))


def test_a_switch_on_the_plate_speed_compares_a_omega_with_its_limit():
    switched = Integration("adaptive", switch=(("plate_speed", 16.0),), integrator_above="symplectic_euler")
    choose = lambda a, w: RunSettings(integration=switched).fmu_values({"A": a, "omega": w})["integrator"]  # noqa: E731
    assert [choose(10.0, 1.5), choose(10.0, 1.7), choose(0.3, 50.0), choose(0.3, 53.4)] == [
        "adaptive", "symplectic_euler", "adaptive", "symplectic_euler"]
    assert "plate_speed <= 16" in switched.describe()
    with pytest.raises(ValueError, match="switched by plate_speed needs the run's value of A, omega"):
        RunSettings(integration=switched).fmu_values()


def test_a_small_sweep_on_dask_equals_the_points_run_directly(fmu_a, tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    grid = Grid.parse(["A=0,3.5", "omega=0.5,0.9"])
    base = base_point(fmu_a)
    client = open_client(Execution(workers=2))
    try:
        outcome = run_sweep(grid, base, None, Execution(progress=False), client=client)
        loads = worker_pool_loads(client)
        worker_numba = set(client.run(lambda: os.environ.get("NUMBA_CACHE_DIR")).values())
        # Two sweeps asking for the same points at once (studies side by side) share each
        # point's one evaluation: both stores hold the same measured time for it.
        with ThreadPoolExecutor(2) as pool:
            twins = list(pool.map(lambda n: run_sweep(grid, base, tmp_path / f"store{n}", Execution(progress=False),
                                                      client=client), range(2)))
    finally:
        close_client(client)
    assert [t.computed for t in twins] == [4, 4]
    times = [sorted(json.loads(f.read_text())["elapsed_s"] for f in (tmp_path / f"store{n}" / "points").glob("*.json"))
             for n in range(2)]
    assert len(times[0]) == 4 and times[0] == times[1]
    assert outcome.computed == 4 and outcome.reused == 0
    # 4 points on 2 workers: some worker evaluated several, and none loaded the FMU twice.
    assert sorted(loads.values()) in ([1, 1], [0, 1])
    assert worker_numba == {os.environ["NUMBA_CACHE_DIR"]}
    ds = outcome.dataset
    assert ds.attrs["fmu_sha256"] and ds.attrs["transient"] == 500.0 and ds.attrs["phi_threshold"] == 10.0
    for point in points_of(grid, base):
        direct = run_point(point.settings).as_dict()
        at = ds.isel(dict(zip(grid.names, point.index)))
        for name in MEASURED:
            value = at[name].item()
            if isinstance(direct[name], float) and np.isnan(direct[name]):
                assert np.isnan(value), name
            else:
                assert value == direct[name], name
    # No slip within 3000 < t_stick at A = 0; far above A_c(0.9) = 0.25 the block slides.
    assert list(ds.regime.sel(A=0.0).values) == ["stuck", "stuck"]
    assert ds.regime.sel(A=3.5, omega=0.9).item() == "sliding" and not ds.stick_slip.sel(A=3.5, omega=0.9)


def test_failing_points_are_reported_together_after_the_others_are_stored(fmu_a, tmp_path):
    grid = Grid.parse(["k_n=1,-1,2"])
    base = base_point(fmu_a, horizon=50.0, transient=10.0)
    with pytest.raises(SweepError, match=r"(?s)1 point\(s\) failed.*'k_n': -1.0.*not admissible"):
        run_sweep(grid, base, tmp_path / "store", Execution(scheduler=INLINE, progress=False))
    assert len(list((tmp_path / "store" / "points").glob("*.json"))) == 2
