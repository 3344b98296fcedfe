"""The many-blocks spring model the paper's conclusion names: a chain of blocks
(BlockChain3.fmu, docs/chain.md), its event catalogue and its triggering by periodic loading.

No verdict of its own (the paper makes no claim about the chain); the report states what
was measured beside the published descriptions it is read against:

* **Catalogue.** Carlson and Langer's standard parameters
  (:data:`harness.chain.run.CARLSON_LANGER`), the cluster catalogue, run through fmpy on
  BlockChain3.fmu with N set at run time: the Gutenberg-Richter b-value by maximum
  likelihood with its completeness, the size exponent of the events smaller than the
  chain over a stated fit range, the recurrence of system-wide events.  Carlson and
  Langer describe a power-law family of small events beside characteristic system-wide
  ones.
* **Triggering.** The rate-and-state chain of
  :data:`harness.chain.triggering.RATE_STATE_STUDY` under periodic loading of the plate's
  acceleration from phases of its loading cycle: the clock advance of the next large event
  against the period P, below and above T_0, the time left before the undisturbed event.
  Perfettini, Schmittbuhl and Cochard (2003) find the response independent of P below T_0
  and strongly dependent on it above.
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from harness.chain.statistics import catalogue_summary, magnitudes
from harness.cosim.fmu import fmu_sha256

from .study import Claim, Runner, Study

TEXT: dict = {}
FIGURES: dict = {}
CHAIN_FMU = "BlockChain3.fmu"  # N a structural parameter: one FMU for any chain length
COMMUNICATION_STEP = 1000.0  # tau_0; the catalogue, written by the FMU, keeps every event between


def catalogue_run(item: dict) -> dict:
    """One catalogue run of the chain FMU (``item``: fmu, n_blocks, horizon, parameters):
    the events' start times, sizes (blocks) and potencies, and the catalogue's first line."""
    from harness.chain.run import simulate_chain

    with tempfile.TemporaryDirectory() as folder:
        _, events = simulate_chain(item["fmu"], stop_time=item["horizon"], step_size=COMMUNICATION_STEP,
                                   catalog=Path(folder) / "catalog.csv", outputs=("event_count",),
                                   start_values={**item["parameters"], "N": item["n_blocks"]})
    return {"thresholds": events.attrs["thresholds"], "t_start": events.t_start.tolist(),
            "n_blocks": events.n_blocks.astype(int).tolist(), "potency": events.potency.tolist()}


def triggering_run(item: dict) -> dict:
    """The reference cycle of the rate-and-state chain and the clock advance under periodic
    loading at every (phase, period) of ``item``, at its acceleration amplitude."""
    from harness.chain.triggering import RATE_STATE_STUDY, periodic_advance, reference_cycle

    reference = reference_cycle(RATE_STATE_STUDY)
    rows = [periodic_advance(reference, RATE_STATE_STUDY, phase, period, item["acceleration"])
            for phase in item["phases"] for period in item["periods"]]
    return {"t_s": reference.t_s, "t_ref": reference.t_ref, "rows": rows}


def chain_task(item: dict, pool) -> dict:
    """A worker's part of the study (``item["part"]``: catalogue or triggering)."""
    return catalogue_run(item) if item["part"] == "catalogue" else triggering_run(item)


def triggering_shape(rows) -> list[dict]:
    """Per phase: the clock advances for periods below T_0 and above it, and their spans
    as fractions of T_0 (the shape Perfettini et al. describe: a small span below, a
    large one above).  A run with no large event within a cycle counts as not finite."""
    shapes = []
    for phase in sorted({row["phase"] for row in rows}):
        group = [row for row in rows if row["phase"] == phase]
        t0 = group[0]["T0"]
        below = [row["advance"] for row in group if row["period"] < t0 and math.isfinite(row["advance"])]
        above = [row["advance"] for row in group if row["period"] >= t0 and math.isfinite(row["advance"])]
        shapes.append({"phase": phase, "T0": t0, "below": below, "above": above,
                       "span_below": (max(below) - min(below)) / t0 if len(below) > 1 else math.nan,
                       "span_above": (max(above) - min(above)) / t0 if len(above) > 1 else math.nan,
                       "no_event": sum(not math.isfinite(row["advance"]) for row in group)})
    return shapes


def study_chain(runner: Runner) -> Study:
    """The catalogue and the triggering runs, side by side on the workers."""
    from harness.chain.run import CARLSON_LANGER

    r = runner.resolution
    fmu = str(Path(runner.fmus["A"]).parent / CHAIN_FMU)
    catalogue = {"part": "catalogue", "fmu": fmu, "fmu_sha256": fmu_sha256(fmu), "n_blocks": r.chain_blocks,
                 "horizon": r.chain_horizon, "parameters": {**CARLSON_LANGER, "cluster_catalog": True}}
    triggering = {"part": "triggering", "phases": list(r.chain_phases), "periods": list(r.chain_periods),
                  "acceleration": r.chain_acceleration}
    events, trigger = runner.tasks(chain_task, [catalogue, triggering])
    measured = {"catalogue": catalogue_summary(r.chain_blocks, events["n_blocks"], events["potency"],
                                               events["t_start"]),
                "triggering": {"t_s": trigger["t_s"], "t_ref": trigger["t_ref"],
                               "shape": triggering_shape(trigger["rows"])}}
    settings = {"models": f"catalogue: {r.chain_blocks} blocks of model A ({CHAIN_FMU}); triggering: the "
                          "16-block rate-and-state chain (the chain's core)",
                "parameters": "catalogue: Carlson and Langer's (" + ", ".join(f"{k} {v:g}" for k, v in
                                                                      CARLSON_LANGER.items()) + "), cluster "
                              f"catalogue; triggering: periodic loading at {r.chain_acceleration:g} g from phases "
                              f"{', '.join(f'{p:g}' for p in r.chain_phases)}, periods "
                              f"{', '.join(f'{p:g}' for p in r.chain_periods)} tau_0",
                "horizon": r.chain_horizon,
                "catalogue": {"fmu": CHAIN_FMU, "n_blocks": r.chain_blocks, "horizon": r.chain_horizon,
                              **CARLSON_LANGER, "catalogue": events["thresholds"]},
                "triggering": {"chain": "harness.chain.triggering.RATE_STATE_STUDY", "acceleration":
                               r.chain_acceleration, "phases": list(r.chain_phases), "periods": list(r.chain_periods)}}
    data = {"n_blocks": r.chain_blocks, "events": events, "rows": trigger["rows"]}
    return Study("Chain", measured, settings, data)


def describe(measured: dict) -> str:
    """The study's paragraph in the report."""
    c, t = measured["catalogue"], measured["triggering"]
    parts = [f"a chain of blocks at Carlson and Langer's standard parameters (cluster catalogue) gave {c['events']} "
             f"events: {c['system_wide']} system-wide, {c['at_least_half']} of at least half the chain, "
             f"{c['single_block']} of a single block, {c['back_slips']} back-slips (negative potency)"]
    b = c["b_value"]
    parts.append(f"b-value {b['b']:.2f} +- {b['sigma']:.2f} (M >= {b['completeness']:.2f}, {b['n_events']} events)"
                 if "b" in b else f"no b-value ({b['error']})")
    s = c["size_exponent"]
    parts.append(f"size exponent of the smaller events tau = {s['tau']:.2f} +- {s['sigma']:.2f} over potency "
                 f">= {s['s_min']:.3g} ({s['n_events']} events; Carlson and Langer's description reads as ~2)"
                 if "tau" in s else f"no size exponent ({s['error']})")
    if "system_wide_recurrence" in c:
        rec = c["system_wide_recurrence"]
        parts.append(f"system-wide events recur every {rec['mean']:.4g} tau_0 (std {rec['std']:.3g})")
    spans = "; ".join(f"phase {row['phase']:g} (T_0 = {row['T0']:.0f}): spans {row['span_below']:.3f} T_0 below, "
                      f"{row['span_above']:.3f} T_0 above" + (f", {row['no_event']} runs without a large event"
                                                               if row["no_event"] else "")
                      for row in t["shape"])
    parts.append(f"periodic loading of the rate-and-state chain: the clock advance against the period {spans} "
                 "(Perfettini et al. 2003: independent of the period below T_0, strongly dependent above)")
    return "; ".join(parts) + ". Figures chain_catalog.png, chain_triggering.png; docs/chain.md."


def draw(study: Study, save) -> None:
    """The catalogue's magnitude-frequency and size distributions, and the clock advance
    against the period."""
    import matplotlib.pyplot as plt

    n, events, measured = study.data["n_blocks"], study.data["events"], study.measured
    sizes, potencies = np.asarray(events["n_blocks"]), np.asarray(events["potency"], float)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    m = np.sort(magnitudes(potencies))
    left.semilogy(m, np.arange(m.size, 0, -1), ".", ms=3, label="events with M >= m")
    b = measured["catalogue"]["b_value"]
    if "b" in b:
        grid = np.linspace(b["completeness"], m[-1], 50)
        left.semilogy(grid, b["n_events"] * 10.0 ** (-b["b"] * (grid - b["completeness"])), "k--",
                      label=f"b = {b['b']:.2f} $\\pm$ {b['sigma']:.2f} above $M_c$ = {b['completeness']:.2f}")
    left.set(xlabel="magnitude (2/3) log$_{10}$(potency)", ylabel="events", title=f"{n} blocks: magnitude-frequency")
    left.legend(fontsize=8)
    small = potencies[(sizes < n / 2) & (potencies > 0)]
    large = potencies[(sizes >= n / 2) & (potencies > 0)]
    edges = np.geomspace(max(potencies[potencies > 0].min(), 1e-6), potencies.max() * 1.01, 40)
    for values, label in ((small, f"fewer than {n // 2} blocks"), (large, f"at least {n // 2} blocks")):
        counts, _ = np.histogram(values, edges)
        density = counts / np.diff(edges) / max(potencies.size, 1)
        shown = counts > 0
        right.loglog(np.sqrt(edges[:-1] * edges[1:])[shown], density[shown], "o-", ms=3, label=label)
    s = measured["catalogue"]["size_exponent"]
    if "tau" in s:
        counts, _ = np.histogram(small, edges)
        density = counts / np.diff(edges) / max(potencies.size, 1)
        centres = np.sqrt(edges[:-1] * edges[1:])
        anchor = np.argmin(np.abs(np.log(centres / s["s_min"])))
        grid = np.geomspace(s["s_min"], small.max(), 20)
        right.loglog(grid, density[anchor] * (grid / centres[anchor]) ** -s["tau"], "k--",
                     label=f"$\\tau$ = {s['tau']:.2f} from {s['s_min']:.2g}")
    right.set(xlabel=r"potency [$\delta_0$]", ylabel="density", title="event sizes")
    right.legend(fontsize=8)
    save(fig, "chain_catalog.png")

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for shape in measured["triggering"]["shape"]:
        rows = [row for row in study.data["rows"] if row["phase"] == shape["phase"]]
        ax.plot([row["period"] / shape["T0"] for row in rows], [row["advance"] / shape["T0"] for row in rows], "o-",
                label=f"phase {shape['phase']:g} ($T_0$ = {shape['T0']:.0f} $\\tau_0$)")
    ax.axvline(1.0, color="k", lw=0.8, ls=":")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xscale("log")
    ax.set(xlabel="$P / T_0$", ylabel="clock advance / $T_0$",
           title=f"periodic loading, a = {study.settings['triggering']['acceleration']:g} g (rate-and-state chain)")
    ax.legend(fontsize=8)
    save(fig, "chain_triggering.png")


CLAIM = Claim("Chain", study_chain, None, TEXT, FIGURES, draw, describe=describe)
