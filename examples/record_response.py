"""A block on a plate that moves like the ground in a record: read, process, scale, run, plot.

    python examples/record_response.py RECORD_FILE [--format MSEED] [--inventory station.xml]
        [--quantity acceleration --unit m/s^2] [--peak-g 0.5] [--time-stretch 1] [--out out]

The record (any format obspy reads, with the instrument response removed through
``--inventory``; PEER ``.AT2``; or two-column time/value text with ``--quantity`` and
``--unit``) is processed to consistent ground acceleration, velocity and displacement
(harness.ground.records), optionally rescaled to a peak acceleration of ``--peak-g`` times the
block's gravity, and converted to the block's units for a 1 kg block on a 1e5 N/m
contact (delta_0 = 98 um, tau_0 = 3.2 ms; change with ``--mass``, ``--stiffness``).
``--time-stretch`` plays the record that many times slower.  BlockA.fmu (scaled
stick-slip set) runs with the plate motion as fmpy input, evaluated exactly at each
communication point.  Saves out/record_response.png and prints what happened.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
OUTPUTS = ("x", "z", "vx", "normal_force", "contact", "slip_count")


def run_experiment(record_file, *, fmu=ROOT / "build" / "fmus" / "BlockA.fmu", out_dir=ROOT / "out",
                   format=None, inventory=None, quantity=None, unit=None, peak_g=None, time_stretch=1.0,
                   mass=1.0, stiffness=1e5, freqmin=0.5, freqmax=None, step_size=0.25, show_plot=False):
    from harness.ground.excitation import plate_input, simulate_block
    from harness.ground.records import ModelScales, ProcessingSettings, load_ground_motion, scale_to_peak_acceleration

    read = {key: value for key, value in (("format", format), ("inventory", inventory), ("quantity", quantity),
                                          ("unit", unit)) if value is not None}
    motion = load_ground_motion(str(record_file), ProcessingSettings(freqmin=freqmin, freqmax=freqmax), **read)
    scales = ModelScales.from_block(mass=mass, normal_stiffness=stiffness)
    if peak_g is not None:
        motion = scale_to_peak_acceleration(motion, peak_g, gravity=scales.gravity)
    stretched = {"time_scale": time_stretch / scales.time_scale}  # model time units per record second
    duration = (motion.time[-1] - motion.time[0]) * stretched["time_scale"]
    stop = step_size * np.floor(duration / step_size)
    table = plate_input(motion, scales=scales, step_size=step_size, stop_time=stop, **stretched)
    result = simulate_block(fmu, table, start_values=SCALED, outputs=OUTPUTS)

    t, a = table["time"], table["plate_a"]
    summary = {
        "source": motion.source, "trace_id": motion.trace_id, "samples": motion.time.size, "dt_s": motion.dt,
        "length_scale_m": scales.length_scale, "time_scale_s": scales.time_scale, "time_stretch": time_stretch,
        "duration_tau0": float(duration), "peak_plate_acceleration_g": float(np.max(np.abs(a))),
        "peak_plate_displacement_delta0": float(np.max(np.abs(table["plate_z"]))),
        "contact_fraction": float(np.mean(result["contact"])), "coulomb_resets": int(result["slip_count"][-1]),
        "x_advance_delta0": float(result["x"][-1] - result["x"][0]),
        "min_normal_force_mg": float(np.min(result["normal_force"])),
    }
    for key, value in summary.items():
        print(f"{key:32s} {value}")

    import matplotlib
    if not show_plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(4, 1, figsize=(7.0, 8.0), sharex=True)
    axes[0].plot(t, a, lw=0.6)
    axes[0].set_ylabel("plate acc. [g]")
    axes[0].set_title(f"{motion.trace_id or Path(str(record_file)).name}: {summary['peak_plate_acceleration_g']:.3g} g "
                      f"peak, δ₀ = {scales.length_scale:.3g} m, τ₀ = {scales.time_scale:.3g} s")
    axes[1].plot(result["time"], result["normal_force"], lw=0.6)
    axes[1].axhline(0.0, color="k", lw=0.5)
    axes[1].set_ylabel("normal force [m g]")
    axes[2].plot(result["time"], result["x"], lw=0.8, label="block x")
    axes[2].plot(result["time"], SCALED["V_d"] * result["time"], "k:", lw=0.8, label="drive V_d t")
    axes[2].set_ylabel("x [δ₀]")
    axes[2].legend(fontsize=8)
    axes[3].plot(result["time"], result["vx"], lw=0.6)
    axes[3].set_ylabel("vx [δ₀/τ₀]")
    axes[3].set_xlabel("time [τ₀]")
    fig.tight_layout()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figure = out_dir / "record_response.png"
    fig.savefig(figure, dpi=130)
    print(f"saved {figure}")
    if show_plot:
        plt.show()
    plt.close(fig)
    return {"summary": summary, "table": table, "result": result, "figure": figure}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("record_file", type=Path)
    parser.add_argument("--format", help="obspy format name when the suffix does not tell (e.g. MSEED, SAC)")
    parser.add_argument("--inventory", help="StationXML/RESP/dataless SEED with the instrument response")
    parser.add_argument("--quantity", help="acceleration, velocity or displacement (text files, physical units)")
    parser.add_argument("--unit", help="unit of the samples, e.g. m/s^2, g, cm/s")
    parser.add_argument("--peak-g", type=float, help="rescale to this peak acceleration, in the block's g")
    parser.add_argument("--time-stretch", type=float, default=1.0, help="play the record this many times slower")
    parser.add_argument("--mass", type=float, default=1.0, help="block mass [kg]")
    parser.add_argument("--stiffness", type=float, default=1e5, help="normal contact stiffness [N/m]")
    parser.add_argument("--freqmin", type=float, default=0.5, help="high-pass corner [Hz]")
    parser.add_argument("--freqmax", type=float, help="low-pass corner [Hz] (default 0.4 x sampling rate)")
    parser.add_argument("--step", type=float, default=0.25, help="communication step [tau_0]")
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockA.fmu")
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    args = parser.parse_args(argv)
    run_experiment(args.record_file, fmu=args.fmu, out_dir=args.out, format=args.format, inventory=args.inventory,
                   quantity=args.quantity, unit=args.unit, peak_g=args.peak_g, time_stretch=args.time_stretch,
                   mass=args.mass, stiffness=args.stiffness, freqmin=args.freqmin, freqmax=args.freqmax,
                   step_size=args.step)


if __name__ == "__main__":
    main()
