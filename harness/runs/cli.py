"""Command line: ``vibroblock run | sweep | continuation | record`` (also ``python -m harness``).

Examples::

    vibroblock run --model A --set A=0.5 --set omega=0.8 --horizon 20000 --out out/run.nc
    vibroblock sweep --grid A=0.1:2:8 --grid omega=0.2:1.5:8 --store out/store --out out/phase.nc
    vibroblock sweep --grid k_n=0.5:4:6 --grid ratio=10,20 --derive gamma_n=k_n/ratio --model C
    vibroblock sweep --grid-file grid.toml --scheduler tcp://127.0.0.1:8786
    vibroblock continuation --parameter omega --values 0.3:1.2:10 --set A=2 --out out/loop.nc
    vibroblock record station.mseed --inventory station.xml --peak-g 0.8 --time-stretch 200

Every command prints its result (observables, or a summary) as JSON on the last line
of standard output.  Model A starts from the ``scaled`` preset, B and C from the FMU's
defaults (the paper's values; ``--preset`` chooses); ``--set NAME=VALUE`` overrides any
model parameter.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .settings import (PRESETS, RESERVED_PARAMETERS, InitialCondition, Integration, ObservableSettings, Parameters,
                       PointSettings, RunSettings, default_fmu)
from vibroblock.parameters import DEFAULT_INTEGRATOR

# The switches that set the FMU parameters --set does not (RESERVED_PARAMETERS).
OWN_SWITCHES = {"dt": "--dt", "integrator": "--integrator", "initial_state": "--initial-state",
                "x_start": "--x-start", "z_start": "--z-start", "vx_start": "--vx-start", "vz_start": "--vz-start"}
# What --out writes, by suffix.
OUT_SUFFIXES = {".nc": "NetCDF", ".zarr": "Zarr", ".csv": "a table of the data, without the settings"}


def _models() -> list[str]:
    """The model variants, from the core's registry."""
    from vibroblock.models import VARIANTS
    return sorted(VARIANTS)


def _choices(switch: str) -> list[str] | None:
    """The names an FMU offers for an Integer switch, from the built model A FMU's model
    description (None before a build: the FMU then checks the name when the run starts)."""
    fmu = Path(default_fmu("A"))
    if not fmu.is_file():
        return None
    from fmpy import read_model_description
    from harness.cosim.fmu import FmuInterface
    variable = next((v for v in read_model_description(str(fmu)).modelVariables if v.name == switch), None)
    if variable is None:
        return None
    return sorted(FmuInterface.parse_choices(variable.description or ""))


def _assignment(text: str) -> tuple[str, float | bool | str]:
    """NAME=NUMBER, NAME=true|false (a Boolean parameter) or NAME=CHOICE (an Integer
    parameter's value by name, e.g. formulation=tangent_frame: resolved with the FMU)."""
    name, sep, value = text.partition("=")
    name, value = name.strip(), value.strip()
    if not sep or not name or not value:
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=NUMBER, NAME=true|false or NAME=CHOICE")
    if value.lower() in ("true", "false"):
        return name, value.lower() == "true"
    try:
        return name, float(value)
    except ValueError:
        return name, value


def _limit(text: str) -> tuple[str, float]:
    """NAME=NUMBER: a parameter's limit for --switch."""
    name, sep, value = text.partition("=")
    try:
        if not sep or not name.strip():
            raise ValueError
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=NUMBER") from None


def _resolve_choices(fmu: str, assignments: list) -> dict:
    """The --set values with choice names (formulation=tangent_frame) replaced by their
    codes, read from the FMU's description of that Integer parameter.  A value that has a
    switch of its own (dt, integrator, the initial condition) is refused with that switch."""
    for name, value in assignments:
        if name in RESERVED_PARAMETERS:
            text = f"{value:g}" if isinstance(value, float) else str(value)
            raise ValueError(f"--set {name}={text}: {name} is not a model parameter and is not set with --set; "
                             f"use {OWN_SWITCHES[name]} {text}")
    named = {name: value for name, value in assignments if isinstance(value, str)}
    values = dict(assignments)
    if not named:
        return values
    from harness.cosim.fmu import FmuInterface, extract_fmu
    from harness.user_errors import require_fmu
    interface = FmuInterface(extract_fmu(require_fmu(fmu)))
    for name, value in named.items():
        variable = interface.variables.get(name)
        if variable is None:
            raise ValueError(f"--set {name}={value}: {interface.model_name} has no parameter {name!r}; its "
                             f"parameters are {', '.join(sorted(interface.parameters))}")
        try:
            values[name] = variable.typed(value)
        except ValueError as exc:
            raise ValueError(f"--set {name}={value}: {exc}") from None
    return values


def _check_out(text: str | None) -> None:
    """--out: a file name whose suffix says what to write (OUT_SUFFIXES), checked before the run."""
    if text is None:
        return
    suffix = Path(text).suffix
    if suffix not in OUT_SUFFIXES:
        raise ValueError(f"--out {text}: the suffix {suffix or '(none)'!r} is not one this command writes; end the "
                         "name in " + ", ".join(f"{s} ({kind})" for s, kind in OUT_SUFFIXES.items()))


def _add_run_options(parser: argparse.ArgumentParser, horizon: float, horizon_help: str = "run length") -> None:
    group = parser.add_argument_group("model and run")
    group.add_argument("--model", default="A", choices=_models(), help="FMU of this model (default A)")
    group.add_argument("--fmu", help="FMU file (overrides --model; default build/fmus/Block<model>.fmu, "
                                     "built by 'make fmus')")
    group.add_argument("--preset", default=None, choices=sorted(PRESETS),
                       help="starting parameter set (default: scaled for model A -- k_d = V_d = 1e-2, "
                            "gamma_t = 5e-3 -- and the FMU's own (paper) values for B and C)")
    group.add_argument("--set", dest="parameters", action="append", default=[], type=_assignment,
                       metavar="NAME=VALUE", help="model parameter (repeatable): a number, true/false for a Boolean, "
                       "or an Integer's value by name, e.g. formulation=tangent_frame")
    group.add_argument("--horizon", type=float, default=horizon, help=f"{horizon_help} (default {horizon:g})")
    group.add_argument("--interval", type=float, default=1.0,
                       help="output interval = communication step, in tau_0 (default 1)")
    group.add_argument("--integrator", default=DEFAULT_INTEGRATOR, choices=_choices("integrator"),
                       help=f"internal integrator, as the FMU names it (default {DEFAULT_INTEGRATOR}, the FMUs' own "
                            "default and the recommended one: exact flows on model A, error-controlled steps on B "
                            "and C; symplectic_euler is the paper's first-order scheme)")
    group.add_argument("--dt", type=float, default=4e-4,
                       help="internal step of the fixed-step integrators, the output grid of adaptive and "
                            "event_driven, in tau_0 (default 4e-4)")
    group.add_argument("--switch", action="append", default=[], type=_limit, metavar="NAME=LIMIT",
                       help="with --integrator-above (repeatable): a run in which NAME (a parameter, or "
                            "plate_speed = A omega) exceeds LIMIT uses --integrator-above instead of --integrator, "
                            "chosen per sweep point, e.g. "
                            "--integrator adaptive --switch omega=2 --integrator-above symplectic_euler "
                            "(README, 'Choosing speed or accuracy')")
    group.add_argument("--integrator-above", default=None, choices=_choices("integrator"),
                       help="the integrator of the runs beyond a --switch limit")
    group.add_argument("--initial-state", default="steady_orbit", choices=_choices("initial_state"),
                       help="the FMU's initial_state (default steady_orbit)")
    for name in ("x_start", "z_start", "vx_start", "vz_start"):
        group.add_argument(f"--{name.replace('_', '-')}", type=float, default=0.0,
                           help=f"the FMU's {name} (where the initial state uses it)")
    group = parser.add_argument_group("observables")
    group.add_argument("--transient", type=float, default=None,
                       help="discarded start of the run (of each ramp step), in tau_0 (default: a fifth of it)")
    group.add_argument("--window", type=float, default=None,
                       help="measuring window at the end of the run, in tau_0 (default: all after the transient)")
    group.add_argument("--phi-threshold", type=float, default=ObservableSettings.phi_threshold,
                       help="phi = <(vx - V_d)^2>/V_d^2 above which the block is held by friction (stick_slip or "
                            f"hopping), below which it slides or is stuck (default {ObservableSettings.phi_threshold:g};"
                            " harness.runs.observables)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")


def _point(args) -> PointSettings:
    fmu = args.fmu or default_fmu(args.model)
    run = RunSettings.for_model(
        args.model, args.preset, fmu=fmu, parameters=Parameters(_resolve_choices(fmu, args.parameters)),
        horizon=args.horizon, output_interval=args.interval,
        integration=Integration(args.integrator, args.dt, tuple(args.switch), args.integrator_above),
        initial=InitialCondition(args.initial_state, args.x_start, args.z_start, args.vx_start, args.vz_start))
    transient = args.horizon / 5 if args.transient is None else args.transient
    observe = ObservableSettings(transient=transient, window=args.window, phi_threshold=args.phi_threshold)
    return PointSettings(run, observe)


def _print_result(payload: dict) -> None:
    def clean(value):
        return None if isinstance(value, float) and math.isnan(value) else value

    print(json.dumps({k: clean(v) for k, v in payload.items()}))


def command_run(args) -> int:
    from .observables import observe
    from .run import simulate

    point = _point(args)
    from harness.user_errors import require_fmu
    require_fmu(point.run.fmu)
    ds = simulate(point.run, progress=not args.no_progress)
    result = observe(ds, point.observe).as_dict()
    if args.out:
        from .dataset_files import save_dataset

        for name, value in result.items():
            ds.attrs[f"observed_{name}"] = value
        result["out"] = str(save_dataset(ds, args.out))
    _print_result(result)
    return 0


def command_sweep(args) -> int:
    from .sweep import Execution, Grid, SweepError, run_sweep

    if args.grid_file:
        grid = Grid.from_file(args.grid_file)
        if args.grid or args.derive:
            extra = Grid.parse(args.grid or [], args.derive)
            grid = Grid(grid.axes + extra.axes, grid.derived + extra.derived) if args.grid else \
                Grid(grid.axes, grid.derived + extra.derived)
    elif args.grid:
        grid = Grid.parse(args.grid, args.derive)
    else:
        print("sweep: give --grid NAME=SPEC (repeatable) or --grid-file FILE", file=sys.stderr)
        return 2
    execution = Execution(scheduler=args.scheduler, workers=args.workers, progress=not args.no_progress)
    try:
        outcome = run_sweep(grid, _point(args), args.store, execution)
    except SweepError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    summary = {"points": len(grid), "computed": outcome.computed, "reused": outcome.reused,
               "store": args.store, "stick_slip_points": int(outcome.dataset.stick_slip.sum())}
    if args.out:
        from .dataset_files import save_dataset

        summary["out"] = str(save_dataset(outcome.dataset, args.out))
    _print_result(summary)
    return 0


def command_continuation(args) -> int:
    from .continuation import Ramp, continuation, fresh_starts
    from .sweep import Axis

    ramp = Ramp(args.parameter, Axis.parse(f"{args.parameter}={args.values}").values, not args.one_way)
    point = _point(args)
    ds = continuation(point, ramp, progress=not args.no_progress)
    summary = {"steps": int(ds.sizes["step"]), "parameter": args.parameter,
               "up_stick_slip": [bool(v) for v in ds.stick_slip.values[ds.direction.values == "up"]],
               "down_stick_slip": [bool(v) for v in ds.stick_slip.values[ds.direction.values == "down"]]}
    if args.fresh:
        import xarray as xr

        ds = xr.concat([ds, fresh_starts(point, ramp).assign_coords(step=lambda d: d.step + ds.sizes["step"])],
                       dim="step", combine_attrs="override")
    if args.out:
        from .dataset_files import save_dataset

        summary["out"] = str(save_dataset(ds, args.out))
    _print_result(summary)
    return 0


def command_record(args) -> int:
    from harness.ground.record_run import run_record, settings_from

    outcome = run_record(settings_from(args))
    result = outcome["result"]
    _print_result({"figure": str(outcome["figure"]), "stop_time": outcome["stop_time"],
                   "record_duration": outcome["duration_tau0"], "notes": outcome["notes"],
                   "coulomb_resets": int(result["coulomb_resets"][-1]),
                   "contact_fraction": float(result["contact"].mean()),
                   "x_advance": float(result["x"][-1] - result["x"][0])})
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vibroblock",
                                     description="Runs, sweeps and continuation on the vibroblock FMUs.",
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n", 1)[1])
    commands = parser.add_subparsers(dest="command", required=True)

    run = commands.add_parser("run", help="one run: trajectories and observables")
    _add_run_options(run, 20_000.0)
    run.add_argument("--out", help="write the trajectories: .nc (NetCDF), .zarr or .csv")
    run.set_defaults(handler=command_run)

    sweep = commands.add_parser("sweep", help="observables over a parameter grid (Dask, resumable)")
    _add_run_options(sweep, 20_000.0)
    sweep.add_argument("--grid", action="append", default=[], metavar="NAME=SPEC",
                       help="axis: NAME=start:stop:n, NAME=start:stop:n:log or NAME=v1,v2,... (repeatable)")
    sweep.add_argument("--grid-file", help="TOML/JSON file with [axes] and [derived] tables")
    sweep.add_argument("--derive", action="append", default=[], metavar="NAME=EXPR",
                       help="derived parameter, e.g. gamma_n=k_n/20 (repeatable)")
    sweep.add_argument("--store", help="folder of finished points: a rerun computes only missing ones")
    sweep.add_argument("--scheduler", help="address of a running Dask scheduler, or 'inline' (no Dask)")
    sweep.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    sweep.add_argument("--out", help="write the sweep Dataset: .nc (NetCDF), .zarr or .csv")
    sweep.set_defaults(handler=command_sweep)

    ramp = commands.add_parser("continuation", help="quasi-static ramp up then down (hysteresis)")
    _add_run_options(ramp, 10_000.0, "duration of each ramp step")
    ramp.add_argument("--parameter", default="omega", choices=("A", "omega"), help="ramped tunable parameter")
    ramp.add_argument("--values", required=True, help="up-ramp values: start:stop:n or v1,v2,...")
    ramp.add_argument("--one-way", action="store_true", help="up only, no way back")
    ramp.add_argument("--fresh", action="store_true", help="also evaluate each value from a fresh start")
    ramp.add_argument("--out", help="write the per-step Dataset: .nc (NetCDF), .zarr or .csv")
    ramp.set_defaults(handler=command_continuation)

    from harness.ground.record_run import add_arguments
    record = commands.add_parser("record", help="a block on a plate moving like the ground in a seismic record")
    add_arguments(record)
    record.set_defaults(handler=command_record)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one command; a bad record, bad settings or a refused FMU call end it with a
    one-line message on standard error and exit status 2, not a traceback."""
    args = build_parser().parse_args(argv)
    from harness.user_errors import run_main

    def handle():
        if args.command != "record":  # record's --out is a folder
            _check_out(getattr(args, "out", None))
        return args.handler(args)

    return run_main(f"vibroblock {args.command}", handle)


if __name__ == "__main__":
    sys.exit(main())
