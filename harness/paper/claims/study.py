"""What every claim's study shares: its sizes (:class:`Resolution`), its result
(:class:`Study`), the :class:`Runner` that executes and caches its runs, and the
:class:`Claim` record a claim module registers.

A study runs sweeps (through :func:`harness.runs.sweep.run_sweep`, persisted in the
runner's point store) and single runs or continuation ramps (through
:func:`harness.runs.sweep.cached_map`, each result cached as JSON under
``<store>/studies`` keyed by its inputs and the FMUs' sha256 as it arrives), and returns
plain numbers.
The claim's verdict function turns those numbers into verdicts by explicit criteria.

Sizes (grid points, horizons, ramp steps) come from a :class:`Resolution`; ``default``
is the main job's, ``quick`` a few-minute version (the default reading only), ``tiny``
the tests'.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from harness.cosim.fmu import fmu_sha256
from harness.runs.settings import Integration, PointSettings, RunSettings, default_fmu
from harness.runs.store import write_json_atomically
from harness.runs.sweep import Execution, Grid, cached_map, run_sweep

from vibroblock.integrators import INTEGRATOR_RECORDS

from .readings import DEFAULT_READING, Reading


# Model A's integrator in the studies where it applies (see Runner.run).
MODEL_A_INTEGRATOR = "event_driven"
def exact_flows_apply(parameters: dict) -> bool:
    """Whether ``event_driven``'s closed forms run model A under these parameters, as its
    registry record decides (the contact-force bound and a linear contact law: the no-pull
    contact's clipped force is not)."""
    readings = {"coulomb_normal": int(parameters.get("coulomb_normal", 0)),
                "contact_law": int(parameters.get("contact_law", 0))}
    return INTEGRATOR_RECORDS["event_driven"].unsupported_reading(readings) is None


# Models B and C: ``adaptive`` where it is the cheaper one, the paper's scheme elsewhere
# (see Runner.run), with the adaptive integrator's tolerances.
CORRUGATED_INTEGRATION = Integration("adaptive", switch=(("omega", 20.0), ("plate_speed", 16.0), ("V_d", 1.0)),
                                     integrator_above="symplectic_euler")
CORRUGATED_TOLERANCES = {"rtol": 1e-6, "atol": 1e-8}


@dataclass(frozen=True)
class Resolution:
    """Sizes of the studies (see module doc)."""

    name: str
    horizon_a: float           # model A runs and sweep points
    c2_amplitudes: tuple
    c3_omegas: tuple
    c3_amplitudes: tuple
    c4_gammas: tuple
    c4_omegas: tuple           # down to below the bouncing-ball floor of the two smallest gamma_n
    c4_step: float             # duration of a ramp step
    b_horizon: float           # model B x(t) runs
    b_amplitudes: tuple
    c_horizon: float           # model C sweep points
    c6_amplitudes: tuple
    c6_omegas: tuple
    c6_ratios: tuple           # k_n / gamma_n
    c6_stiffnesses: tuple      # k_n
    c6_relative_omegas: tuple  # omega / (k_n / gamma_n)
    c6_ramp: tuple
    c6_ramp_step: float
    c7_omegas: tuple
    contact_horizon: float
    c8_velocities: tuple
    c8_omegas: tuple
    # Window (corrugation wavelengths of drive travel) of the start-phase ensemble that
    # re-checks both sides of C6's located transitions from four starts; 0: no check
    # (quick and tiny: its 16 runs of >= 1.5 wavelengths, ~2 CPU-minutes, do not fit their budgets).
    ensemble_wavelengths: float = 3.0
    readings: bool = True      # measure C2, C5-C8 under every reading of the paper's equations
    # The paper's Fig. 1c at the paper's own parameters (model A; empty: not drawn) and the
    # complete stick-slip cycles each point's window holds.
    fig1c_omegas: tuple = ()
    fig1c_amplitudes: tuple = ()
    fig1c_cycles: int = 2
    # The chain study (harness.paper.claims.chain): the catalogue's chain length and
    # duration (tau_0; ~1 CPU-minute at the default), and the periodic loading's
    # acceleration amplitude (g), phases of the loading cycle and periods (tau_0).
    chain_blocks: int = 256
    chain_horizon: float = 1e5
    chain_acceleration: float = 0.005
    chain_phases: tuple = (0.3, 0.6, 0.9)
    chain_periods: tuple = (10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0)


RESOLUTIONS = {
    "default": Resolution(
        name="default", horizon_a=20_000.0, c2_amplitudes=(0.0, 4.0, 8.0, 12.0, 15.0),
        c3_omegas=tuple(np.round(np.geomspace(0.1, 4.0, 9), 4)),
        c3_amplitudes=tuple(np.round(np.geomspace(0.02, 300.0, 10), 4)),
        c4_gammas=(0.035, 0.07, 0.14, 0.28), c4_omegas=tuple(np.round(np.arange(0.075, 0.5001, 0.025), 4)),
        c4_step=12_000.0, b_horizon=100_000.0, b_amplitudes=(0.0, 1.0, 2.5, 5.0, 10.0), c_horizon=10_000.0,
        c6_amplitudes=(0.3, 1.0, 3.0, 10.0), c6_omegas=tuple(np.round(np.geomspace(0.1, 50.0, 10), 4)),
        c6_ratios=(14.29, 28.57), c6_stiffnesses=(0.5, 1.0, 2.0),
        c6_relative_omegas=(0.25, 0.5, 1.0, 1.5, 2.0, 3.0), c6_ramp=(5.0, 8.0, 11.0, 14.0, 17.0, 22.0, 30.0, 40.0),
        c6_ramp_step=8_000.0, c7_omegas=tuple(np.round(np.geomspace(0.1, 50.0, 10), 4)), contact_horizon=5_000.0,
        c8_velocities=(1e-3, 1e-2, 0.1, 1.0, 10.0), c8_omegas=(0.1, 0.3, 1.0, 3.0, 10.0, 30.0),
        fig1c_omegas=tuple(np.round(np.geomspace(0.1, 1.0, 6), 4)),
        fig1c_amplitudes=tuple(np.round(np.geomspace(0.3, 300.0, 6), 4))),
    "quick": Resolution(
        name="quick", horizon_a=14_000.0, c2_amplitudes=(0.0, 8.0, 15.0), c3_omegas=(0.1, 0.3, 1.0, 3.0),
        c3_amplitudes=(0.03, 0.3, 3.0, 30.0, 300.0), c4_gammas=(0.035, 0.07, 0.28),
        c4_omegas=(0.08, 0.12, 0.2, 0.3, 0.4, 0.5), c4_step=8_000.0, b_horizon=40_000.0, b_amplitudes=(0.0, 5.0),
        c_horizon=5_000.0, c6_amplitudes=(0.3, 3.0), c6_omegas=(0.1, 1.0, 5.0, 14.0, 40.0),
        c6_ratios=(7.0, 14.29), c6_stiffnesses=(1.0, 2.0), c6_relative_omegas=(0.5, 2.0),
        c6_ramp=(5.0, 14.0, 40.0), c6_ramp_step=4_000.0, c7_omegas=(0.1, 1.0, 14.0, 40.0),
        contact_horizon=3_000.0, c8_velocities=(1e-2, 10.0), c8_omegas=(0.3, 3.0), ensemble_wavelengths=0.0,
        readings=False, chain_blocks=64, chain_horizon=2e4, chain_phases=(0.3, 0.9), chain_periods=(10.0, 100.0, 1000.0)),
    "tiny": Resolution(
        name="tiny", horizon_a=6_000.0, c2_amplitudes=(0.0, 8.0), c3_omegas=(0.2, 2.0), c3_amplitudes=(0.1, 100.0),
        c4_gammas=(0.07, 0.28), c4_omegas=(0.25, 0.45), c4_step=3_000.0, b_horizon=8_000.0, b_amplitudes=(0.0, 5.0),
        c_horizon=3_000.0, c6_amplitudes=(3.0,), c6_omegas=(0.3, 14.0), c6_ratios=(14.29,), c6_stiffnesses=(1.0,),
        c6_relative_omegas=(0.5, 2.0), c6_ramp=(5.0, 30.0), c6_ramp_step=2_500.0, c7_omegas=(0.3, 14.0),
        contact_horizon=2_500.0, c8_velocities=(10.0,), c8_omegas=(0.3,), ensemble_wavelengths=0.0,
        fig1c_omegas=(0.2,), fig1c_amplitudes=(0.3,), fig1c_cycles=1, chain_blocks=16, chain_horizon=5e3,
        chain_phases=(0.6,), chain_periods=(10.0, 50.0, 1000.0, 2000.0)),
}


@dataclass
class Study:
    """What one claim's study measured.

    ``measured``: the numbers the verdict is computed from (JSON-able);
    ``settings``: parameter set, start, threshold, window, transient per part;
    ``data``: arrays for the figures (JSON-able lists);
    ``timing``: wall time of the study and what of it came from the store (:func:`timing`);
    ``reading``: the reading of the paper's equations it ran under (:mod:`.readings`)."""

    claim: str
    measured: dict
    settings: dict
    data: dict = field(default_factory=dict)
    timing: dict = field(default_factory=dict)
    reading: str = DEFAULT_READING.key


class Runner:
    """Runs sweeps and cached tasks for the studies on one Dask client (or inline).

    ``reading`` (:class:`~.readings.Reading`) is applied to every run the runner makes:
    the claims that depend on the reading are run once per reading by switching it."""

    def __init__(self, store: str | os.PathLike, resolution: Resolution, execution: Execution = Execution(),
                 client=None, fmus: dict | None = None):
        self.store = Path(store)
        self.resolution = resolution
        self.execution = execution
        self.client = client
        self.fmus = {m: str((fmus or {}).get(m, default_fmu(m))) for m in "ABC"}
        self._sha = {m: fmu_sha256(path) for m, path in self.fmus.items()}
        self.points_computed = 0
        self.points_reused = 0
        self.tasks_computed = 0
        self.tasks_reused = 0
        # Seconds the workers spent on the points and tasks this runner computed: with
        # studies side by side, a study's own cost (its wall time overlaps the others').
        self.compute_time = 0.0
        self.reading: Reading = DEFAULT_READING
        # C6's start ensemble under every reading, not only the default one: each costs
        # 16 runs of 3.5 corrugation wavelengths (~11 diagram points each), beyond the
        # main job's 20-minute budget under the other three readings.
        self.ensembles_every_reading = False

    def run(self, model: str, **fields) -> RunSettings:
        """A run of ``model`` under the runner's reading (parameters the study sets win).

        Without an ``integration`` of the study's own, model A runs with ``event_driven``
        (exact flows with located events, cheaper and more accurate than the paper's
        first-order scheme through the FMU: docs/benchmarks.md) where
        it applies, i.e. under the contact-force bound and a contact law linear in the
        penetration and its rate (``exact_flows_apply``), else with the paper's
        ``symplectic_euler`` at dt = 4e-4.  Models B and C run with ``adaptive`` (rtol
        1e-6, atol 1e-8) at omega <= 20, A omega <= 16 and V_d <= 1, ``symplectic_euler``
        otherwise: the paper's scheme costs the same at every omega and A (its step is
        fixed), while ``adaptive`` pays for the plate's cycles (a step spans at most a
        sixteenth of one) and for the landings, whose violence grows with the plate's
        speed A omega.  The limits come from the studies' runs measured both ways
        (``python -m harness.benchmarks.study_integrators --full``; figures in
        docs/benchmarks.md): inside them ``adaptive`` is the cheaper and, with the same
        regime on every run, the accurate one of the two.  V_d = 10 keeps the paper's
        scheme: there the two disagree on the regime and no reference decides between them."""
        parameters = {**self.reading.parameters(model), **dict(fields.pop("parameters", {}) or {})}
        if "integration" not in fields:
            if model == "A" and exact_flows_apply(parameters):
                fields["integration"] = Integration(MODEL_A_INTEGRATOR)
            elif model in "BC":
                fields["integration"] = CORRUGATED_INTEGRATION
                parameters = {**CORRUGATED_TOLERANCES, **parameters}
            else:  # the studies choose explicitly, whatever the FMUs' default
                fields["integration"] = Integration("symplectic_euler")
        return RunSettings(fmu=self.fmus[model], parameters=parameters, **fields)

    def for_reading(self, reading: Reading, progress: bool | None = None, priority: int | None = None) -> "Runner":
        """A runner on this one's store, resolution, client and FMUs under ``reading``, with
        counters of its own (so that studies can run side by side); ``progress`` switches
        its sweeps' progress bars, ``priority`` sets its work's Dask priority."""
        other = copy.copy(self)
        other.reading = reading
        other.points_computed = other.points_reused = other.tasks_computed = other.tasks_reused = 0
        other.compute_time = 0.0
        if progress is not None:
            other.execution = dataclasses.replace(other.execution, progress=progress)
        if priority is not None:
            other.execution = dataclasses.replace(other.execution, priority=priority)
        return other

    def add_counts(self, other: "Runner") -> None:
        """Count what ``other`` (made by :meth:`for_reading`) computed and reused as this runner's."""
        for name, value in counts(other).items():
            setattr(self, name, getattr(self, name) + value)

    def sweep(self, grid: Grid, base: PointSettings):
        outcome = run_sweep(grid, base, self.store / "points", self.execution, self.client)
        self.points_computed += outcome.computed
        self.points_reused += outcome.reused
        self.compute_time += outcome.compute_time
        return outcome.dataset

    def tasks(self, function: Callable, items: Sequence[dict]) -> list[dict]:
        """``function(item, pool)`` for every item, cached by (function, item, FMU hashes)
        in ``<store>/studies`` with the seconds it took (``elapsed_s``) beside the result,
        each stored as it arrives (:func:`harness.runs.sweep.cached_map`)."""
        outcome = cached_map(function, items, self.store / "studies", {"fmu_sha256": self._sha}, self.execution,
                             self.client)
        self.tasks_computed += outcome.computed
        self.tasks_reused += outcome.reused
        self.compute_time += outcome.compute_time
        return outcome.results


def counts(runner: Runner) -> dict:
    """What the runner has computed and reused from its store so far, and the seconds the
    computing took (``compute_time``, summed over points and tasks)."""
    return {"points_computed": runner.points_computed, "points_reused": runner.points_reused,
            "tasks_computed": runner.tasks_computed, "tasks_reused": runner.tasks_reused,
            "compute_time": runner.compute_time}


def timing(wall_time: float, before: dict, after: dict) -> dict:
    """A study's wall time, its points and tasks computed or read from the store and the
    compute time they took, from the runner's :func:`counts` before and after it;
    ``source`` says where its results came from."""
    spent = {key: after[key] - before[key] for key in after}
    computed = spent["points_computed"] + spent["tasks_computed"]
    reused = spent["points_reused"] + spent["tasks_reused"]
    source = "store" if reused and not computed else "computed" if not reused else "partly from the store"
    return {"wall_time": wall_time, "source": source, **spent}


@dataclass(frozen=True)
class Claim:
    """One claim of docs/claims.md as the report sees it: its study, the verdict rows computed
    from what the study measured, the statement of each part and the figures of each part.

    ``verdicts(measured) -> list[Row]`` is None for a study that only draws a figure
    (Fig. 1b); ``draw(study, save)`` hands each figure to ``save(figure, file name)``.
    ``readings``: the readings of the paper's equations the claim is measured under
    (the first is the one its figures and main verdict row use); a claim the readings
    cannot change has the default reading only.  ``describe(measured) -> str``: what a
    study without verdicts found, in one paragraph of the report."""

    name: str
    study: Callable[[Runner], Study]
    verdicts: Callable[[dict], list] | None = None
    text: dict = field(default_factory=dict)
    figures: dict = field(default_factory=dict)
    draw: Callable | None = None
    readings: tuple = (DEFAULT_READING,)
    describe: Callable[[dict], str] | None = None


def save_studies(studies: dict[str, Study], path: str | os.PathLike) -> None:
    write_json_atomically(Path(path), {name: dataclasses.asdict(s) for name, s in studies.items()})


def load_studies(path: str | os.PathLike) -> dict[str, Study]:
    data = json.loads(Path(path).read_text())
    return {name: Study(**fields) for name, fields in data.items()}
