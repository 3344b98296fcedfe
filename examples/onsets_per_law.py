"""The detachment onset A_c(omega) of model A under each contact law, located numerically
and drawn beside the linear law's closed form and the friction-loss onset A_N.

    python examples/onsets_per_law.py [--omegas 0.2,0.5,1,1.2,2,5,14] [--out out]

Prints A_c per law and saves out/onsets_per_law.png.  The linear law's located onset
matches its closed form (vibroblock.orbits.detachment_amplitude); the no-pull contact lets
go between A_N and A_c; the Hertz-Hunt-Crossley contact, stiffer at rest (1.5 k_n), moves
the resonance dip from omega = 1 to about 1.2 (harness/paper/onsets.py).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAWS = {0: "linear", 2: "linear_no_pull", 3: "hertz_hunt_crossley"}


def run_experiment(omegas=(0.2, 0.5, 1.0, 1.2, 2.0, 5.0, 14.0), out=ROOT / "out") -> dict:
    import numpy as np

    from harness.paper.onsets import located_detachment_amplitude
    from vibroblock.orbits import detachment_amplitude, friction_loss_amplitude

    located = {law: [located_detachment_amplitude(w, law) for w in omegas] for law in LAWS}
    print(f"{'omega':>6} {'A_N linear':>11} {'A_c closed':>11} " + " ".join(f"{name:>20}" for name in LAWS.values()))
    for i, w in enumerate(omegas):
        print(f"{w:6g} {float(friction_loss_amplitude(w)):11.5g} {float(detachment_amplitude(w)):11.5g} "
              + " ".join(f"{located[law][i]:20.5g}" for law in LAWS))
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    line = np.geomspace(min(omegas), max(omegas), 300)
    ax.loglog(line, detachment_amplitude(line), "k-", lw=1, label="$A_c$ linear, closed form")
    ax.loglog(line, friction_loss_amplitude(line), "k--", lw=1, label="$A_N$ linear, closed form")
    for law, name in LAWS.items():
        ax.loglog(omegas, located[law], "o", ms=4, label=f"$A_c$ {name}, located")
    ax.set(xlabel=r"$\omega\ [\tau_0^{-1}]$", ylabel=r"$A\ [\delta_0]$", title="model A: detachment onset per contact law")
    ax.legend(fontsize=7)
    fig.tight_layout()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "onsets_per_law.png", dpi=120)
    print(f"saved {out / 'onsets_per_law.png'}")
    return {"omegas": list(omegas), "located": located}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--omegas", type=lambda t: tuple(float(v) for v in t.split(",")),
                        default=(0.2, 0.5, 1.0, 1.2, 2.0, 5.0, 14.0))
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    args = parser.parse_args(argv)
    run_experiment(args.omegas, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
