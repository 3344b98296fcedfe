"""Horizontal shaking: where a block on a shaken plate starts to slip, against the closed form.

    python examples/horizontal_shaking.py [--fmu build/fmus/BlockA.fmu] [--omega 0.05]

BlockA.fmu with ``plate_motion = 1`` (oblique) and ``drive_angle = pi/2`` shakes the plate
horizontally, A sin(omega t); the drive spring is slack (k_d = 0), so only the shaking
loads the friction spring.  Started on the steady stuck response, the block rides the
plate until the spring's steady force k_t |X| reaches mu_s m g, at

    A_s = mu_s g |k_t - m omega^2 + i gamma_t omega| / (k_t omega^2)

(the rigid block's m A omega^2 = mu_s m g when m omega^2 << k_t).  The script runs a few
amplitudes around A_s through fmpy, prints whether the spring broke within two periods and
how far the block moved relative to the plate, and saves out/horizontal_shaking.png.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parents[1]
K_T, GAMMA_T, MU_S = 0.28, 2.5e-4, 0.5  # the paper's k_t, gamma_t and mu_s (m = g = k_n = 1)


def slip_threshold(omega: float) -> float:
    """A_s: the amplitude where the steady spring force reaches mu_s m g."""
    return MU_S * abs(complex(K_T - omega ** 2, GAMMA_T * omega)) / (K_T * omega ** 2)


def run(fmu: Path, amplitude: float, omega: float, periods: float = 2.0):
    """One run from the steady stuck response: (resets, largest slip relative to the plate)."""
    response = amplitude * omega ** 2 / complex(K_T - omega ** 2, GAMMA_T * omega)
    x0, v0 = response.imag, (response * 1j * omega).imag  # X on the steady orbit at t = 0
    stop = periods * 2 * math.pi / omega
    result = simulate_fmu(str(fmu), stop_time=stop, output_interval=stop / 400, output=["x", "coulomb_resets"],
                          start_values={"plate_motion": 1, "drive_angle": math.pi / 2, "A": amplitude,
                                        "omega": omega, "k_d": 0.0, "V_d": 0.0, "integrator": 1, "dt": 4e-3,
                                        "initial_state": 1, "x_start": x0, "vx_start": v0 + amplitude * omega,
                                        "z_start": -1.0, "vz_start": 0.0})
    relative = result["x"] - amplitude * np.sin(omega * result["time"])
    return int(result["coulomb_resets"][-1]), float(np.max(np.abs(relative - relative[0]))), result


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / "BlockA.fmu")
    parser.add_argument("--omega", type=float, default=0.05)
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    args = parser.parse_args(argv)
    threshold = slip_threshold(args.omega)
    print(f"omega = {args.omega:g}: A_s = {threshold:.4g} delta_0 (closed form); the rigid block's mu_s g / omega^2 "
          f"= {MU_S / args.omega ** 2:.4g}")
    rows = []
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for factor in (0.8, 0.95, 1.05, 1.2):
        resets, slip, result = run(args.fmu, factor * threshold, args.omega)
        rows.append({"A_over_A_s": factor, "resets": resets, "relative_travel": slip})
        print(f"  A = {factor:4.2f} A_s: {resets:5d} resets, block moved {slip:9.3g} delta_0 relative to the plate "
              f"({'slips' if resets else 'rides the plate'})")
        ax.plot(result["time"], result["x"] - factor * threshold * np.sin(args.omega * result["time"]),
                label=f"A = {factor:.2f} A_s")
    ax.set_xlabel(r"time [$\tau_0$]")
    ax.set_ylabel(r"x relative to the plate [$\delta_0$]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "horizontal_shaking.png", dpi=120)
    print(f"saved {args.out / 'horizontal_shaking.png'}")
    return rows


if __name__ == "__main__":
    main()
