"""Figures are drawn from harness results without a display."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from harness.paper.plots import plot_hysteresis, plot_phase_diagram, plot_trajectories  # noqa: E402


def test_figures_draw_every_regime_and_branch(tmp_path):
    omega, amplitude = np.array([0.5, 1.0]), np.array([0.5, 2.0, 4.0])
    regime = np.array([["stick_slip", "stick_slip"], ["stick_slip", "sliding"], ["sliding", "stuck"]])
    sweep = xr.Dataset({"regime": (("A", "omega"), regime)}, coords={"A": amplitude, "omega": omega},
                       attrs={"g": 1.0})
    ax = plot_phase_diagram(sweep, onset=lambda w: 1 / w**2, onset_label="A_c")
    labels = ax.get_legend_handles_labels()[1]
    assert {"stick-slip", "sliding", "no slip in window", "A_c"} <= set(labels)
    assert sum(len(c.get_offsets()) for c in ax.collections) == 6

    loop = xr.Dataset({"phi": ("step", [100.0, 0.2, 0.3])},
                      coords={"direction": ("step", ["up", "up", "down"]), "omega": ("step", [0.5, 0.9, 0.5])},
                      attrs={"ramp_parameter": "omega"})
    ax = plot_hysteresis({"gamma_n=0.07": loop})
    assert len(ax.lines) == 2

    t = np.arange(0.0, 10.0)
    run = xr.Dataset({"x": ("time", 0.01 * t)}, coords={"time": t}, attrs={"V_d": 0.01})
    ax = plot_trajectories({"A=0": run})
    ax.figure.savefig(tmp_path / "x.png")
    assert (tmp_path / "x.png").stat().st_size > 0
