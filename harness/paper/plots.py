"""Figures from harness results (matplotlib; every function draws on a given or new Axes
and returns it, so figures compose and scripts can save them without a display).

* :func:`plot_trajectories` -- x(t) of runs against the drive's x = V_d t (Fig. 1b).
* :func:`plot_phase_diagram` -- regimes of a two-dimensional sweep, with the paper's
  line A = g / omega^2 and, if given, another onset curve (Fig. 1c, model C).
* :func:`regime_scatter` -- regime markers at given points (the claims' diagrams).
* :func:`plot_hysteresis` -- phi along continuation ramps, up and down branches (C4).
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np
import xarray as xr

from harness.runs.observables import FLYING, HOPPING, JAMMED, MICRO_SLIP, SLIDING, STICK_SLIP, STUCK

REGIME_STYLE = {
    STICK_SLIP: {"marker": "s", "color": "tab:red", "label": "stick-slip"},
    MICRO_SLIP: {"marker": "P", "color": "tab:pink", "label": "micro-slip (slides, short slips)"},
    SLIDING: {"marker": "o", "color": "tab:blue", "label": "sliding"},
    HOPPING: {"marker": "D", "color": "tab:orange", "label": "hopping (no rests, intermittent contact)"},
    STUCK: {"marker": "x", "color": "tab:gray", "label": "no slip in window"},
    JAMMED: {"marker": "v", "color": "tab:purple", "label": "jammed (self-locked)"},
    FLYING: {"marker": "^", "color": "tab:green", "label": "flying (no contact)"},
}


def axis_label(name: str) -> str:
    """A parameter's name with its unit, from the FMUs' parameter table (model units:
    delta_0, tau_0, m_0)."""
    from vibroblock.parameters import COMMON_PARAMETERS

    units = {p.name: p.unit for p in COMMON_PARAMETERS}
    units.update({"A_x": "delta_0", "omega_x": "1/delta_0", "P_l": "m_0 delta_0/tau_0^2", "phi": "1"})
    unit = units.get(name)
    return f"{name} [{unit}]" if unit else name


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure().add_subplot()


def regime_scatter(ax, xs, ys, regimes):
    """One marker per point (xs[i], ys[i]) in the style of its regime, one legend entry per regime."""
    xs, ys, regimes = np.asarray(xs), np.asarray(ys), np.asarray(regimes)
    for name, style in REGIME_STYLE.items():
        chosen = regimes == name
        if chosen.any():
            ax.scatter(xs[chosen], ys[chosen], marker=style["marker"], color=style["color"], label=style["label"])


def regime_grid(ax, omegas, amplitudes, regimes, onset, load_label: str, onset_label: str, loss=None,
                loss_label: str = r"$A_N(\omega)$: $N$ reaches 0") -> None:
    """Regimes on an omega x A grid (``regimes[i][j]`` at amplitudes[i], omegas[j]) with the
    lines A = load/(m omega^2) (load = m = 1 in the studies' units), ``onset(omega)`` (the
    detachment onset A_c) and, if given, ``loss(omega)`` (the friction-loss onset A_N, where
    the contact force and with it the Coulomb bound first vanish, the block still embedded)."""
    omega, amplitude = np.meshgrid(omegas, amplitudes)
    regime_scatter(ax, omega.ravel(), amplitude.ravel(), np.asarray(regimes).ravel())
    line = np.geomspace(min(omegas), max(omegas), 300)
    ax.plot(line, 1 / line**2, "k:", label=load_label)
    ax.plot(line, onset(line), "k-", lw=1, label=onset_label)
    if loss is not None:
        ax.plot(line, loss(line), "--", color="tab:red", lw=1, label=loss_label)


def plot_trajectories(runs: Mapping[str, xr.Dataset], ax=None, drive: bool = True):
    """x(t) of each run (label -> trajectory Dataset); the drive's V_d t as a dashed line."""
    ax = _axes(ax)
    # A sliding block follows the drive within a few delta_0: the runs wide and pale
    # underneath, the drive thin and dashed on top, so that neither hides the other.
    for label, ds in runs.items():
        ax.plot(ds.time, ds.x, lw=3.0, alpha=0.6, zorder=1, label=label)
    if drive and runs:
        first = next(iter(runs.values()))
        ax.plot(first.time, first.attrs["V_d"] * first.time, "k--", lw=0.8, zorder=3, label="drive $V_d t$")
    ax.set_xlabel(r"$t$ [$\tau_0$]")
    ax.set_ylabel(r"$x$ [$\delta_0$]")
    ax.legend()
    return ax


def plot_phase_diagram(sweep: xr.Dataset, x: str = "omega", y: str = "A", ax=None, paper_line: bool = True,
                       onset: Callable[[np.ndarray], np.ndarray] | None = None, onset_label: str = "onset",
                       log_y: bool = False):
    """Regime markers over a sweep with dimensions (x, y); optional transition lines.

    ``paper_line`` draws A = g / omega^2 (g from the sweep's attributes, or P_l / m for
    model C); ``onset`` is any other curve y(x), e.g. ``vibroblock.detachment_amplitude``.
    """
    ax = _axes(ax)
    xs, ys = np.meshgrid(sweep[x].values, sweep[y].values)
    regime_scatter(ax, xs.ravel(), ys.ravel(), sweep["regime"].transpose(y, x).values.ravel())
    grid = np.linspace(sweep[x].values.min(), sweep[x].values.max(), 200)
    grid = grid[grid > 0]
    if paper_line and x == "omega" and y == "A":
        load = sweep.attrs.get("g", sweep.attrs.get("P_l", 1.0) / sweep.attrs.get("m", 1.0))
        ax.plot(grid, load / grid**2, "k:", label=r"$A = g/\omega^2$")
    if onset is not None:
        ax.plot(grid, onset(grid), "k-", lw=1, label=onset_label)
    ax.set_xlabel(axis_label(x))
    ax.set_ylabel(axis_label(y))
    if log_y:
        ax.set_yscale("log")
    span = sweep[y].values
    ax.set_ylim(span.min() * (0.8 if log_y else 1) - (0 if log_y else 0.05 * np.ptp(span)),
                span.max() * (1.25 if log_y else 1) + (0 if log_y else 0.05 * np.ptp(span)))
    ax.legend(fontsize="small")
    return ax


def plot_hysteresis(loops: Mapping[str, xr.Dataset], ax=None, log_phi: bool = True):
    """phi against the ramped parameter, up (filled) and down (open) per loop (label -> Dataset)."""
    ax = _axes(ax)
    for number, (label, ds) in enumerate(loops.items()):
        parameter = ds.attrs["ramp_parameter"]
        color = f"C{number}"
        for direction, fill in (("up", color), ("down", "none")):
            part = ds.where(ds.direction == direction, drop=True)
            if part.sizes.get("step", 0):
                ax.plot(part[parameter], part.phi, marker="s" if direction == "up" else "o", color=color,
                        markerfacecolor=fill, label=f"{label} ({direction})")
        ax.set_xlabel(axis_label(parameter))
    ax.set_ylabel(r"$\phi$ [1]")
    if log_phi:
        ax.set_yscale("log")
    ax.legend(fontsize="small")
    return ax
