"""A block on a plate that moves like the ground in a record: read, process, scale, run, plot.

What ``vibroblock record`` and ``examples/record_response.py`` run.  The record (any
format obspy reads, with the instrument response from an inventory or a stated
sensitivity; PEER ``.AT2``; two-column text in stated physical units) is processed to
consistent ground acceleration, velocity and displacement (``harness.ground.records``),
optionally rescaled to a peak acceleration (in the block's g) and played
``time_stretch`` times slower, converted to the block's units for a block of ``mass``
kg on a contact of ``stiffness`` N/m, and fed to a Block FMU through fmpy's input
table.  The figure's time axes show model time (tau_0) and the record's own seconds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from harness.cosim.fmu import REPO_ROOT
from vibroblock.parameters import DEFAULT_INTEGRATOR

from .records import RecordError

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}  # model A's scaled stick-slip set (harness.runs.settings)
OUTPUTS = ("x", "z", "vx", "normal_force", "contact", "coulomb_resets")
# Integrators that take the plate as moving vertically (laws.plate_oblique refuses them), and
# the one a three-component run takes instead: fourth order, and exact for the plate's
# frame force between the communication points the inputs are held over.
HORIZONTAL_REFUSED = ("adaptive", "event_driven")
HORIZONTAL_INTEGRATOR = "rk4"
# The run keeps its input table and outputs in memory (fmpy), ~0.2 kB a communication step:
# beyond this many steps (~0.4 GB, a few minutes) the command asks for a shorter run instead.
MAX_STEPS = 2_000_000
# What each printed number means.
MEANINGS = {
    "peak_plate_acceleration_g": "largest |plate acceleration|, in the block's g (> 1: the plate can throw it)",
    "peak_plate_displacement_delta0": "largest |plate height|, in delta_0 (the rest penetration)",
    "peak_plate_horizontal_acceleration_g": "largest |plate acceleration along x| (--azimuth), in the block's g "
                                            "(> mu_s: it can drag the block past its friction)",
    "contact_fraction": "share of the output samples with the block in contact",
    "min_normal_force_mg": "lowest normal force, in m g (0: the block left the plate)",
    "coulomb_resets": "breaks of the friction spring (|k_t F| >= mu_s N); one slip holds many",
    "x_advance_delta0": "how far the block moved, in delta_0",
    "drive_advance_delta0": "how far the drive spring's far end moved (V_d t), in delta_0",
}


@dataclass(frozen=True)
class RecordRun:
    """What to read and how to play it (units: SI for the block, tau_0 for the run)."""

    record_file: str
    model: str = "A"
    fmu: str | None = None
    integrator: str = DEFAULT_INTEGRATOR
    format: str | None = None
    inventory: str | None = None
    quantity: str | None = None
    unit: str | None = None
    sensitivity: float | None = None
    peak_g: float | None = None
    time_stretch: float = 1.0
    mass: float = 1.0
    stiffness: float = 1e5
    freqmin: float = 0.5
    freqmax: float | None = None
    step_size: float = 0.25
    stop_time: float | None = None
    out_dir: str = str(REPO_ROOT / "out")
    save_record: str | None = None
    parameters: dict = field(default_factory=dict)
    azimuth: float | None = None  # three components: the slip direction, degrees clockwise from north

    def __post_init__(self):
        for name in ("time_stretch", "mass", "stiffness", "step_size"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise RecordError(f"{name} = {value!r} must be a finite number > 0")
        if self.stop_time is not None and not (math.isfinite(self.stop_time) and self.stop_time > 0):
            raise RecordError(f"stop time = {self.stop_time!r} must be a finite number > 0 (tau_0)")
        if self.peak_g is not None and not (math.isfinite(self.peak_g) and self.peak_g >= 0):
            raise RecordError(f"peak_g = {self.peak_g!r} must be a finite number >= 0 (in the block's g)")
        if self.azimuth is not None and not math.isfinite(self.azimuth):
            raise RecordError(f"azimuth = {self.azimuth!r} must be a finite number of degrees clockwise from north")
        if self.azimuth is not None and self.save_record:
            raise RecordError("--save-record writes one component; leave out --azimuth to save the vertical one")

    def block_fmu(self) -> Path:
        from harness.runs.settings import default_fmu
        from harness.user_errors import require_fmu

        return require_fmu(self.fmu or default_fmu(self.model))


def run_record(settings: RecordRun, show_plot: bool = False) -> dict:
    """Run the block on the record; print what happened, save the figure; the results."""
    from harness.ground.excitation import plate_input, simulate_block, write_record
    from harness.ground.records import (ModelScales, ProcessingSettings, load_ground_motion,
                                        load_ground_motion_components, scale_to_peak_acceleration)

    fmu = settings.block_fmu()
    read = {key: value for key, value in (("format", settings.format), ("inventory", settings.inventory),
                                          ("quantity", settings.quantity), ("unit", settings.unit),
                                          ("sensitivity", settings.sensitivity)) if value is not None}
    processing = ProcessingSettings(freqmin=settings.freqmin, freqmax=settings.freqmax)
    horizontal = None
    if settings.azimuth is None:
        motion = load_ground_motion(str(settings.record_file), processing, **read)
    else:
        motion, horizontal = load_ground_motion_components(str(settings.record_file), settings.azimuth, processing,
                                                           **read)
    scales = ModelScales.from_block(mass=settings.mass, normal_stiffness=settings.stiffness)
    if settings.peak_g is not None:
        # Played time_stretch times slower, accelerations shrink by time_stretch^2: the
        # record is scaled so that the plate's peak is peak_g (with two components, the
        # larger one's, both by the same factor).
        peak = settings.peak_g * settings.time_stretch ** 2
        if horizontal is not None:
            larger = max(motion.peak_acceleration, horizontal.peak_acceleration)
            motion, horizontal = (scale_to_peak_acceleration(m, peak * m.peak_acceleration / larger,
                                                             gravity=scales.gravity) for m in (motion, horizontal))
        else:
            motion = scale_to_peak_acceleration(motion, peak, gravity=scales.gravity)
    if settings.save_record:
        print(f"saved the processed record (SI) for the Excitation FMU's record_file: "
              f"{write_record(motion, settings.save_record)}")
    time_scale = settings.time_stretch / scales.time_scale  # model time units per record second
    record_seconds = float(motion.time[-1] - motion.time[0])
    duration = record_seconds * time_scale
    step = settings.step_size
    whole = step * math.floor(duration / step + 1e-9)
    stop = whole if settings.stop_time is None else step * math.floor(settings.stop_time / step + 1e-9)
    if stop < step:
        raise RecordError(f"the run would be shorter than one communication step ({step:g} tau_0); give a stop "
                          f"time >= {step:g} tau_0 or a smaller --step")
    steps = round(stop / step)
    if steps > MAX_STEPS:
        raise RecordError(
            f"the run would take {steps:.3g} communication steps ({stop:.6g} tau_0 = {stop / time_scale:.4g} s of the "
            f"record at {step:g} tau_0 a step), more than the {MAX_STEPS:.0e} this command holds in memory; give "
            f"--stop-time {MAX_STEPS * step:g} or less, a larger --step, or play the record faster "
            f"(--time-stretch {settings.time_stretch * MAX_STEPS / steps:.2g} or less)")
    notes = []
    if stop < duration - step:
        notes.append(f"the run ({stop:g} tau_0 = {stop / time_scale:.4g} s of the record) is shorter than the "
                     f"processed record ({duration:.6g} tau_0 = {record_seconds:.4g} s): the last "
                     f"{record_seconds - stop / time_scale:.4g} s of the record are not played")
    elif stop > duration + step:
        notes.append(f"the run ({stop:g} tau_0) is longer than the processed record ({duration:.6g} tau_0 = "
                     f"{record_seconds:.4g} s): after it the plate rests")
    table = plate_input(motion, scales=scales, step_size=step, stop_time=stop, time_scale=time_scale,
                        horizontal=horizontal)
    integrator = settings.integrator
    start_values = {**(SCALED if settings.model.upper() == "A" else {}), **settings.parameters}
    if horizontal is not None:
        start_values["plate_motion"] = 1  # the oblique plate: its horizontal inputs move it along x
        if integrator in HORIZONTAL_REFUSED:
            notes.append(f"the horizontal component needs a fixed-step integrator ({integrator} takes the plate "
                         f"as moving vertically): running {HORIZONTAL_INTEGRATOR}")
            integrator = HORIZONTAL_INTEGRATOR
    start_values["integrator"] = _integrator_code(fmu, integrator)
    result = simulate_block(fmu, table, start_values=start_values, outputs=OUTPUTS)

    a = table["plate_a"]
    summary = {
        "record_seconds": record_seconds, "samples": int(motion.time.size), "dt_s": float(motion.dt),
        "length_scale_m": scales.length_scale, "time_scale_s": scales.time_scale,
        "time_stretch": settings.time_stretch, "duration_tau0": float(duration), "stop_time_tau0": float(stop),
        "peak_plate_acceleration_g": float(np.max(np.abs(a))),
        "peak_plate_displacement_delta0": float(np.max(np.abs(table["plate_z"]))),
        "contact_fraction": float(np.mean(result["contact"])),
        "coulomb_resets": int(result["coulomb_resets"][-1]),
        "x_advance_delta0": float(result["x"][-1] - result["x"][0]),
        "drive_advance_delta0": _drive_advance(start_values, stop),
        "min_normal_force_mg": float(np.min(result["normal_force"])),
    }
    if horizontal is not None:
        summary["peak_plate_horizontal_acceleration_g"] = float(np.max(np.abs(table["plate_ax"])))
    print(f"record: {motion.source} ({motion.trace_id or 'one channel'}), {motion.time.size} samples at "
          f"{1 / motion.dt:g} Hz, {record_seconds:.4g} s after processing")
    print(f"block:  {settings.mass:g} kg on {settings.stiffness:g} N/m, so delta_0 = {scales.length_scale:.4g} m and "
          f"tau_0 = {scales.time_scale:.4g} s; the record is played {_pace(settings.time_stretch)}")
    print(f"run:    model {settings.model.upper()}, integrator {integrator}, {stop:g} tau_0 "
          f"(= {stop / time_scale:.4g} s of the record), communication step {step:g} tau_0")
    for note in notes:
        print(f"note:   {note}")
    for key, meaning in MEANINGS.items():
        if key not in summary:
            continue
        value = summary[key]
        print(f"  {key:31s} {value:<12.5g} {meaning}" if isinstance(value, float) else
              f"  {key:31s} {value:<12d} {meaning}")
    figure = _plot(settings, motion, scales, table, result, start_values, time_scale, show_plot)
    print(f"saved {figure}")
    return {"summary": summary, "notes": notes, "table": table, "result": result, "figure": figure,
            "duration_tau0": duration, "stop_time": stop}


def _integrator_code(fmu: Path, name: str) -> int:
    from fmpy import read_model_description

    from harness.cosim.fmu import FmuInterface

    variable = next(v for v in read_model_description(str(fmu)).modelVariables if v.name == "integrator")
    choices = FmuInterface.parse_choices(variable.description or "")
    if name not in choices:
        raise RecordError(f"integrator {name!r} is not one of {sorted(choices)} ({fmu.name}'s model description)")
    return choices[name]


def _pace(stretch: float) -> str:
    if stretch == 1.0:
        return "at its own pace"
    return f"{stretch:g}x slower" if stretch > 1.0 else f"{1.0 / stretch:g}x faster"


def _drive_advance(values: dict, stop: float) -> float:
    return float(values.get("V_d", math.nan)) * stop


def _plot(settings, motion, scales, table, result, start_values, time_scale, show_plot) -> Path:
    import matplotlib
    if not show_plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = table["time"]
    fig, axes = plt.subplots(4, 1, figsize=(7.0, 8.4), sharex=True)
    axes[0].plot(t, table["plate_a"], lw=0.6, color="tab:gray", label="vertical")
    if "plate_ax" in table.dtype.names:
        axes[0].plot(t, table["plate_ax"], lw=0.6, color="tab:orange", label=f"along x ({settings.azimuth:g} deg)")
        axes[0].legend(fontsize=8)
    axes[0].set_ylabel("plate acceleration [g]")
    name = motion.trace_id or Path(str(settings.record_file)).name
    # The title above the figure: the record's seconds run along the top of the first panel.
    fig.suptitle(f"{name}: peak {float(np.max(np.abs(table['plate_a']))):.3g} g; "
                 f"$\\delta_0$ = {scales.length_scale:.3g} m, $\\tau_0$ = {scales.time_scale:.3g} s", fontsize=10)
    # The record's own seconds on top, beside model time: s = t / time_scale.
    top = axes[0].secondary_xaxis("top", functions=(lambda x: x / time_scale, lambda s: s * time_scale))
    top.set_xlabel(f"time in the record [s] (played {_pace(settings.time_stretch)})")
    axes[1].plot(result["time"], result["normal_force"], lw=0.6, color="tab:purple")
    axes[1].axhline(0.0, color="k", lw=0.5)
    axes[1].set_ylabel("normal force [m g]")
    v_d = start_values.get("V_d")
    if v_d is not None:
        axes[2].plot(result["time"], v_d * result["time"], color="0.55", ls="--", lw=0.8, zorder=1,
                     label="drive $V_d t$")
    axes[2].plot(result["time"], result["x"], lw=1.0, color="tab:blue", zorder=2, label="block x")
    axes[2].set_ylabel(r"x [$\delta_0$]")
    axes[2].legend(fontsize=8)
    axes[3].plot(result["time"], result["vx"], lw=0.6, color="tab:blue")
    axes[3].set_ylabel(r"$v_x$ [$\delta_0/\tau_0$]")
    axes[3].set_xlabel(r"model time [$\tau_0$]")
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.97))
    out_dir = Path(settings.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figure = out_dir / "record_response.png"
    fig.savefig(figure, dpi=130)
    if show_plot:
        plt.show()
    plt.close(fig)
    return figure


def add_arguments(parser) -> None:
    """The options of ``vibroblock record`` and ``examples/record_response.py``."""
    from harness.runs.cli import _assignment, _models

    parser.add_argument("record_file", help="the record: any format obspy reads (MiniSEED, SAC, GSE2, ...), PEER "
                                            ".AT2, or two-column time/value text (.csv, .txt)")
    parser.add_argument("--format", help="obspy format name when the suffix does not tell (e.g. MSEED, SAC)")
    parser.add_argument("--inventory", help="instrument response (StationXML, RESP or dataless SEED) for a record "
                                            "in counts")
    parser.add_argument("--sensitivity", type=float,
                        help="instead of a response: counts per --unit of --quantity (flat response assumed)")
    parser.add_argument("--quantity", help="what the samples are: acceleration, velocity or displacement (text "
                                           "files, physical units, or with --sensitivity)")
    parser.add_argument("--unit", help="unit of the samples (or of --sensitivity), e.g. m/s^2, g, cm/s")
    parser.add_argument("--azimuth", type=float,
                        help="three-component record: shake the plate with its vertical channel and, along x, with "
                             "the horizontal motion at this azimuth (degrees clockwise from north; channels N, E, or "
                             "1, 2 with --inventory); needs a fixed-step integrator (rk4 is taken)")
    parser.add_argument("--peak-g", type=float, help="rescale so that the plate's peak acceleration is this, in the "
                                                      "block's g (after --time-stretch)")
    parser.add_argument("--time-stretch", type=float, default=1.0,
                        help="play the record this many times slower (default 1)")
    parser.add_argument("--model", default="A", choices=_models(), help="Block FMU of this model (default A)")
    parser.add_argument("--fmu", help="Block FMU file (default build/fmus/Block<model>.fmu, built by 'make fmus')")
    parser.add_argument("--integrator", default=DEFAULT_INTEGRATOR,
                        help=f"the FMU's integrator by name (default {DEFAULT_INTEGRATOR})")
    parser.add_argument("--set", dest="parameters", action="append", default=[], type=_assignment,
                        metavar="NAME=VALUE", help="model parameter (repeatable; model A starts from the scaled set "
                                                   "k_d = V_d = 1e-2, gamma_t = 5e-3)")
    parser.add_argument("--mass", type=float, default=1.0, help="block mass [kg] (default 1)")
    parser.add_argument("--stiffness", type=float, default=1e5, help="normal contact stiffness [N/m] (default 1e5)")
    parser.add_argument("--freqmin", type=float, default=0.5, help="high-pass corner [Hz] (default 0.5)")
    parser.add_argument("--freqmax", type=float, help="low-pass corner [Hz] (default 0.4 x sampling rate)")
    parser.add_argument("--step", type=float, default=0.25, help="communication step [tau_0] (default 0.25)")
    parser.add_argument("--stop-time", type=float,
                        help="run length [tau_0] (default: the processed record's length; a shorter run says so)")
    parser.add_argument("--save-record", help="also save the processed record as .npz for the Excitation FMU's "
                                              "record_file")
    parser.add_argument("--out", default=str(REPO_ROOT / "out"), help="folder for record_response.png "
                                                                      "(default: out/)")


def settings_from(args) -> RecordRun:
    parameters = dict(args.parameters)
    for name, value in parameters.items():
        if not isinstance(value, float):
            raise ValueError(f"--set {name}={value}: give a number")
    return RecordRun(record_file=args.record_file, model=args.model, fmu=args.fmu, integrator=args.integrator,
                     format=args.format, inventory=args.inventory, quantity=args.quantity, unit=args.unit,
                     sensitivity=args.sensitivity, peak_g=args.peak_g, time_stretch=args.time_stretch,
                     mass=args.mass, stiffness=args.stiffness, freqmin=args.freqmin, freqmax=args.freqmax,
                     step_size=args.step, stop_time=args.stop_time, out_dir=args.out, save_record=args.save_record,
                     parameters=parameters, azimuth=args.azimuth)
