"""The triggering threshold a(P) of a chain of blocks: the smallest acceleration amplitude
of a harmonic burst that triggers the next large event, against the burst's period, at
phases of the loading cycle, beside the static prediction (harness/chain/triggering.py,
``threshold_sweep``).

    python examples/chain_trigger_threshold.py [--phases 0.3,0.6,0.9] [--periods 16] [--out out]

The chain of examples/chain_triggering.py (16 blocks, the paper's friction, mu_s spread
0.3); bursts of 3 periods, Hann-tapered, periods from 2 tau_0 up to a third of the time
left T_0 (up to 3 P = 0.75 T_0).  Per (phase, period): the bisected bracket of the threshold (to 2 %), the
prediction for the first block (its Coulomb bound, lowered by the contact's dip under the
burst, falls below the load its friction spring holds) and for half the chain.  Saves
out/chain_trigger_threshold.png.  About 20 s.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_experiment(phases=(0.3, 0.6, 0.9), n_periods=16, out=ROOT / "out") -> list[dict]:
    import numpy as np

    from harness.chain.triggering import TriggerSettings, reference_cycle, threshold_sweep

    settings = TriggerSettings()
    started = time.perf_counter()
    reference = reference_cycle(settings)
    # Up to bursts of three quarters of the largest T_0 (threshold_sweep drops the longer ones).
    periods = np.round(np.geomspace(2.0, 0.75 * (1.0 - min(phases)) * reference.cycle / settings.cycles, n_periods), 2)
    rows = threshold_sweep(reference, settings, phases, periods)
    print(f"reference cycle T = {reference.cycle:g} tau_0; bursts of {settings.cycles} periods shorter than T_0")
    print(f"{'phase':>6} {'T_0':>6} {'P':>8} {'threshold a [g]':>17} {'first block':>12} {'half chain':>11} "
          f"{'measured / first':>17}")
    for row in rows:
        ratio = row["above"] / row["first_block"]
        print(f"{row['phase']:6.2f} {row['T0']:6.0f} {row['period']:8g} {row['below']:8.4f}-{row['above']:<8.4f} "
              f"{row['first_block']:12.4f} {row['half_chain']:11.4f} {ratio:17.3f}")
    ratios = [row["above"] / row["first_block"] for row in rows if np.isfinite(row["above"])]
    within = sum(abs(r - 1.0) <= 0.03 for r in ratios)
    print(f"{within} of {len(ratios)} thresholds within 3 % of the first block's static one "
          f"({len(rows)} bursts, {time.perf_counter() - started:.0f} s)")
    _figure(rows, Path(out) / "chain_trigger_threshold.png")
    return rows


def _figure(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    path.parent.mkdir(parents=True, exist_ok=True)
    fig = Figure(figsize=(7, 4.4))
    ax = fig.subplots()
    for k, phase in enumerate(sorted({row["phase"] for row in rows})):
        group = [row for row in rows if row["phase"] == phase]
        colour = f"C{k}"
        ax.loglog([r["period"] for r in group], [r["above"] for r in group], "o", color=colour,
                  label=f"phase {phase:g}: measured ($T_0$ = {group[0]['T0']:.0f})")
        ax.loglog([r["period"] for r in group], [r["first_block"] for r in group], "-", color=colour, lw=1,
                  label="static, first block")
        ax.loglog([r["period"] for r in group], [r["half_chain"] for r in group], ":", color=colour, lw=1,
                  label="static, half the chain")
    ax.axvline(2 * 3.141592653589793, color="k", lw=0.6, ls="--")
    ax.set(xlabel=r"burst period $P$ [$\tau_0$] (dashed: the contact's period $2\pi\sqrt{m/k_n}$)",
           ylabel="threshold acceleration [g]", title="bursts that trigger the next large event")
    ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"saved {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phases", type=lambda text: tuple(float(v) for v in text.split(",")), default=(0.3, 0.6, 0.9))
    parser.add_argument("--periods", type=int, default=16, help="periods per phase, log-spaced")
    parser.add_argument("--out", type=Path, default=ROOT / "out")
    args = parser.parse_args(argv)
    run_experiment(args.phases, args.periods, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
