"""Triggered slips: a block in stick-slip hit by a real record at several phases and amplitudes.

    python examples/triggering.py [--fmu build/fmus/BlockA.fmu] [--out out] [--quick]

Model A with the scaled set (stick ~5e3 tau_0, slip ~50 delta_0) is run into its
regular stick-slip cycle once; its FMU state is saved along one stick and restored at
each branch point, where the strong-motion part of obspy's bundled event (BW.RJOB,
stretched 200x: ~600 tau_0 of strong shaking) hits it so that the record's peak
arrives at the chosen phase of the stick.  Prints the table and saves
out/triggering.png, out/triggering.csv and out/triggering.md.  See
harness/ground/triggering.py for the method and the expected physics.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
MARKERS = {"no effect": ("o", "0.6"), "reset, re-stuck": ("s", "tab:blue"), "early slip": ("^", "tab:red"),
           "lifted off": ("x", "k")}


def run_experiment(fmu=ROOT / "build" / "fmus" / "BlockA.fmu", out_dir=ROOT / "out", phases=None,
                   peak_accelerations=None, show_plot=False):
    from harness.ground.triggering import TriggeringSettings, run_triggering

    settings = TriggeringSettings(block_fmu=str(fmu))
    changes = {k: tuple(v) for k, v in (("phases", phases), ("peak_accelerations", peak_accelerations)) if v}
    settings = dataclasses.replace(settings, **changes)
    result = run_triggering(settings, progress=lambda i, n: print(f"\rbranch {i}/{n}", end="", flush=True))
    print()
    cycle = result.cycle
    header = (f"reference cycle: stick {cycle.stick_time:.1f} tau_0 (from t = {cycle.stick_start:.1f}), slip "
              f"{cycle.slip_length:.1f} delta_0; record: {result.record_duration:.0f} tau_0 played, strong motion "
              f"(5-95 % energy) {result.strong_motion[0]:.0f}-{result.strong_motion[1]:.0f} tau_0 after its start, "
              f"peak {result.peak_lead:.0f} tau_0 after its start; communication step {settings.step_size:g}")
    table = result.to_markdown()
    print(header)
    print(table)
    print("What the columns mean: phase = when the record's peak hits, as a share of the stick (0: just after a "
          "slip, 1: at the next one); stress ratio = k_t F / (mu_s m g) then, how close the friction spring is to "
          "breaking; peak a and down peak = the record's largest and most negative plate acceleration [g]; "
          "predicted reset / lift-off = the peak that breaks the spring / lifts the block off at that phase [g]; "
          "resets = Coulomb resets (breaks of the friction spring) while the record plays; jump = largest travel "
          "beyond the unshaken run in that time [delta_0]; contact = share of the record's time in contact; clock "
          "advance = how much earlier the next slip came than without the record [tau_0] (> 0: earlier), and as a "
          "share of the stick T; slip = length of that slip [delta_0]; outcome = what the record did.")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    result.to_csv(out_dir / "triggering.csv")
    (out_dir / "triggering.md").write_text(header + "\n\n" + table + "\n")

    import matplotlib
    if not show_plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    T = cycle.stick_time
    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.4))
    for peak in settings.peak_accelerations:
        rows = [b for b in result.branches if b.peak_acceleration == peak]
        left.plot([b.phase for b in rows], [b.clock_advance / T for b in rows], lw=0.8, label=f"{peak:g} g")
        for b in rows:
            marker, color = MARKERS[b.outcome]
            left.plot(b.phase, b.clock_advance / T, marker=marker, color=color, ms=6, ls="none")
    p = np.linspace(0.0, 1.0, 2)
    left.plot(p, 1.0 - p, "k:", lw=0.8, label="slip at the peak: 1 − phase")
    left.axhline(0.0, color="k", lw=0.5)
    left.set_xlabel("phase of the stick when the record peaks [1]")
    left.set_ylabel("clock advance / stick time [1]")
    left.legend(fontsize=7, title="peak |a|", title_fontsize=7)
    left.set_title("slip brought forward (> 0) or delayed (< 0)")

    for b in result.branches:
        marker, color = MARKERS[b.outcome]
        right.plot(b.phase, b.peak_acceleration, marker=marker, color=color, ms=8, ls="none")
    phases_sorted = sorted(set(b.phase for b in result.branches))
    reset = [next(b.predicted_reset for b in result.branches if b.phase == q) for q in phases_sorted]
    liftoff = [next(b.predicted_liftoff for b in result.branches if b.phase == q) for q in phases_sorted]
    right.plot(phases_sorted, reset, "tab:blue", lw=1, label="predicted reset (in-contact N)")
    right.plot(phases_sorted, liftoff, "k--", lw=1, label="predicted lift-off")
    for outcome, (marker, color) in MARKERS.items():
        right.plot([], [], marker=marker, color=color, ls="none", label=outcome)
    right.set_xlabel("phase of the stick when the record peaks [1]")
    right.set_ylabel("peak plate acceleration [g]")
    right.set_yscale("log")
    right.legend(fontsize=7)
    right.set_title("outcome")
    fig.suptitle(f"Model A (k_d = V_d = 1e-2): BW.RJOB record stretched {settings.time_scale:g}x", fontsize=10)
    fig.tight_layout()
    figure = out_dir / "triggering.png"
    fig.savefig(figure, dpi=140)
    print(f"saved {figure}, {out_dir / 'triggering.csv'}, {out_dir / 'triggering.md'}")
    if show_plot:
        plt.show()
    plt.close(fig)
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockA.fmu",
                        help="BlockA.fmu to run (default: build/fmus/BlockA.fmu of this repository, built by "
                             "'make fmus')")
    parser.add_argument("--out", type=Path, default=ROOT / "out",
                        help="folder for triggering.png, .csv and .md (default: out/)")
    parser.add_argument("--quick", action="store_true", help="three phases and three amplitudes only")
    args = parser.parse_args(argv)
    quick = {"phases": (0.3, 0.7, 0.9), "peak_accelerations": (0.001, 0.3, 0.9)} if args.quick else {}
    from harness.user_errors import require_fmu, run_main
    return run_main("triggering.py", lambda: run_experiment(require_fmu(args.fmu), args.out, **quick) and 0)


if __name__ == "__main__":
    raise SystemExit(main())
