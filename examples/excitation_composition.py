"""Excitation -> Block in three compositions, and what the communication step does to the block.

    python examples/excitation_composition.py [--steps 0.05 0.1 0.25 0.5 1 2 4] [--horizon 12000] [--out out]

A harmonic plate motion (A = 0.4, omega = 0.5: A omega^2 = 0.1 g) drives model A
(scaled stick-slip set) four ways: the block's own drive (reference), fmpy's input
table, the Excitation FMU connected to the block in an SSP file run by fmpy, and the
same file run by libcosim (harness/ground/compose.py).  For each communication step the
script prints the errors against the reference sampled at the same step and saves
out/communication_step.md and out/communication_step.png.  The default set takes about
two minutes of CPU (measured from a fresh clone: 102 s user + 15 s system, 1 min 58 s of
wall time on an idle 2-core machine; 4-9 min of wall time where other work shared it).
Most of it is fmpy's 240,000 communication steps at h = 0.05.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def run_experiment(steps=None, horizon=None, out_dir=ROOT / "out", fmu_dir=ROOT / "build" / "fmus",
                   show_plot=False):
    from harness.ground.compose import StudySettings, communication_step_study, markdown_table

    settings = StudySettings(block_fmu=str(Path(fmu_dir) / "BlockA.fmu"),
                             excitation_fmu=str(Path(fmu_dir) / "Excitation.fmu"))
    changes = {k: v for k, v in (("steps", tuple(steps) if steps else None), ("horizon", horizon)) if v}
    settings = dataclasses.replace(settings, **changes)
    rows = communication_step_study(settings, progress=lambda r: print(f"\r{r['master']:>13s} h = {r['step_size']:g}",
                                                                        end="", flush=True))
    print()
    table = markdown_table(rows)
    header = (f"Model A, scaled set, plate A sin(omega t) with A = {settings.amplitude:g}, omega = {settings.omega:g}, "
              f"{settings.horizon:g} tau_0 from the steady in-contact orbit; errors against the internal drive "
              "sampled at the same step.")
    print(header)
    print(table)
    print("What the columns mean: h = communication step [tau_0]; master = how the plate reaches the block "
          "(internal: its own drive, the reference; input: fmpy's input table; ssp_fmpy / ssp_libcosim: the "
          "Excitation FMU connected in an SSP file); max |z - z_int| = largest height difference from the "
          "reference [delta_0]; first slip - int = onset of the first slip minus the reference's [tau_0]; mean slip "
          "- int = mean slip length minus the reference's [delta_0] (slips counted from the motion); final x - int "
          "[delta_0]; phi/phi_int - 1 = relative error of the order parameter; plate bounds = the plate's largest "
          "height and velocity error per step from holding its acceleration, |j| h^3/6 [delta_0] and |j| h^2/2 "
          "[delta_0/tau_0] with |j| = A omega^3.")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "communication_step.md").write_text(header + "\n\n" + table + "\n")

    import matplotlib
    if not show_plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    for master, style in (("input", "o-"), ("ssp_libcosim", "x--"), ("ssp_fmpy", "s:")):
        chosen = [r for r in rows if r["master"] == master]
        if chosen:
            ax.loglog([r["step_size"] for r in chosen], [r["max_z_error"] for r in chosen], style, label=master)
    h = np.array(sorted(settings.steps))
    jerk = settings.amplitude * settings.omega**3
    ax.loglog(h, jerk * h**2 / 2, "k:", lw=0.8, label="plate velocity error |j| h²/2")
    ax.loglog(h, jerk * h**3 / 6, "k-.", lw=0.8, label="plate height error |j| h³/6")
    ax.set_xlabel("communication step h [τ₀]")
    ax.set_ylabel("max |z − z_internal| [δ₀]")
    ax.set_title("block height against the internal drive", fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    figure = out_dir / "communication_step.png"
    fig.savefig(figure, dpi=140)
    print(f"saved {figure} and {out_dir / 'communication_step.md'}")
    if show_plot:
        plt.show()
    plt.close(fig)
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=float, nargs="+",
                        help="communication steps to compare, in tau_0 (default 0.05 0.1 0.25 0.5 1 2 4)")
    parser.add_argument("--horizon", type=float, help="run length of each composition, in tau_0 (default 12000)")
    parser.add_argument("--fmu-dir", type=Path, default=ROOT / "build" / "fmus",
                        help="folder holding BlockA.fmu and Excitation.fmu (default: build/fmus/ of this "
                             "repository, built by 'make fmus')")
    parser.add_argument("--out", type=Path, default=ROOT / "out",
                        help="folder for communication_step.md and .png (default: out/)")
    args = parser.parse_args(argv)
    from harness.user_errors import require_fmu, run_main

    def run():
        for name in ("BlockA.fmu", "Excitation.fmu"):
            require_fmu(Path(args.fmu_dir) / name, "--fmu-dir")
        run_experiment(args.steps, args.horizon, args.out, args.fmu_dir)

    return run_main("excitation_composition.py", run)


if __name__ == "__main__":
    raise SystemExit(main())
