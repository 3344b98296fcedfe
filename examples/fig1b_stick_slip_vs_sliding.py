"""The paper's Fig. 1b with BlockA.fmu: x(t) in stick-slip and in sliding.

    python examples/fig1b_stick_slip_vs_sliding.py [--fmu build/fmus/BlockA.fmu] [--out out]

At a fixed plate amplitude A, a frequency below the detachment onset keeps the block
embedded and the spring-block sticks and slips; a frequency above it makes the block
bounce, friction is lost and the block follows the drive.  The scaled parameter set
(k_d = V_d = 1e-2, gamma_t = 5e-3) makes a stick-slip cycle ~5e3 time units long.
Prints phi for both runs and saves out/fig1b.png.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parent.parent
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
AMPLITUDE = 10.0
FREQUENCIES = {"stick-slip": 0.25, "sliding": 0.40}  # onset A_c(omega) = 10 near omega = 0.30
HORIZON, TRANSIENT = 20_000.0, 2_000.0


def run_experiment(fmu=ROOT / "build" / "fmus" / "BlockA.fmu", out_dir=ROOT / "out", show_plot=False):
    from vibroblock import detachment_amplitude

    runs = {}
    from harness.user_errors import require_fmu

    fmu = require_fmu(fmu)
    print(f"Model A at plate amplitude A = {AMPLITUDE:g} delta_0, the scaled drive, the FMU's default integrator "
          "(adaptive: exact flows on model A).\nphi = <(vx - V_d)^2> / V_d^2 after the transient: ~1 or more while "
          "friction holds the block (stick-slip), ~0 when it slides with the drive.")
    for label, omega in FREQUENCIES.items():
        result = simulate_fmu(str(fmu), stop_time=HORIZON, output_interval=5.0,
                              start_values={**SCALED, "A": AMPLITUDE, "omega": omega, "initial_state": 2})
        late = result["time"] >= TRANSIENT
        integral = result["phi_integral"][late]
        phi = (integral[-1] - integral[0]) / ((HORIZON - TRANSIENT) * SCALED["V_d"] ** 2)
        runs[label] = {"omega": omega, "time": result["time"], "x": result["x"], "phi": phi,
                       "onset": float(detachment_amplitude(omega))}
        print(f"{label:10s} omega = {omega:.2f} 1/tau_0: detachment onset A_c(omega) = {runs[label]['onset']:6.2f} "
              f"delta_0 {'above' if runs[label]['onset'] > AMPLITUDE else 'below'} A = {AMPLITUDE:g} delta_0; "
              f"phi over t = {TRANSIENT:g}-{HORIZON:g} tau_0 = {phi:.3g}")

    import matplotlib
    if not show_plot:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.0))
    t = np.linspace(0.0, HORIZON, 2)
    # The sliding block follows the drive within a few delta_0: its curve is drawn wide and
    # pale underneath, the drive thin, dashed and dark on top, so that both stay visible.
    colours = {"stick-slip": "tab:red", "sliding": "tab:blue"}
    for label, run in runs.items():
        wide = label == "sliding"
        ax.plot(run["time"], run["x"], color=colours.get(label), lw=4.0 if wide else 1.2, alpha=0.45 if wide else 1.0,
                zorder=1, label=f"{label}: $\\omega$ = {run['omega']:g} $\\tau_0^{{-1}}$, $\\phi$ = {run['phi']:.2g}")
    ax.plot(t, SCALED["V_d"] * t, color="k", ls="--", lw=0.9, zorder=3, label="drive $V_d t$")
    ax.set_xlabel(r"time $t$ [$\tau_0$]")
    ax.set_ylabel(r"block position $x$ [$\delta_0$]")
    ax.set_title(f"Model A, A = {AMPLITUDE:g} $\\delta_0$ (scaled drive $k_d = V_d = 10^{{-2}}$)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(out_dir / "fig1b.png", dpi=150)
    print(f"saved {out_dir / 'fig1b.png'}")
    if show_plot:
        plt.show()
    return runs


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockA.fmu",
                        help="BlockA.fmu to run (default: build/fmus/BlockA.fmu of this repository, built by "
                             "'make fmus')")
    parser.add_argument("--out", type=Path, default=ROOT / "out", help="folder for fig1b.png (default: out/)")
    args = parser.parse_args(argv)
    from harness.user_errors import run_main
    return run_main("fig1b_stick_slip_vs_sliding.py", lambda: run_experiment(args.fmu, args.out) and 0)


if __name__ == "__main__":
    raise SystemExit(main())
