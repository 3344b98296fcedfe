"""The claims of docs/claims.md (C1-C8) and the paper's Fig. 1b, one module each.

Each module holds its claim's study (``study_cN(runner) -> Study``: runs -> measured
numbers), its verdict criteria (``verdict_cN(measured)`` -> rows of the claims table;
the module docstring states them), the statement of each part (``TEXT``), the figures
of each part (``FIGURES``) and the drawing of those figures (``draw``), registered as
one :class:`~harness.paper.claims.study.Claim` named ``CLAIM``.  :data:`CLAIMS` lists them in the
report's order; :mod:`harness.paper.report` iterates it.

Shared: :mod:`.study` (Resolution, Study, Runner, Claim), :mod:`.measure` (conventions,
worker tasks, regime arithmetic), :mod:`.verdicts` (verdict words, Row, tolerances).
"""
from __future__ import annotations

import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from typing import Sequence

from . import (c1_rest, c2_below_g, c3_onset, c4_hysteresis, c5_corrugated_plate, c6_recovery,
               c6r_recovery_question, c7_contact, c8_drive_velocity, chain, fig1b, fig1c_paper)
from .readings import DEFAULT_READING, READINGS, Reading, law_readings, split_study_name, study_name
from .measure import friction_held, onset_amplitude, recovery, stable_roots_near, transition_bracket
from .study import RESOLUTIONS, Claim, Resolution, Runner, Study, counts, load_studies, save_studies, timing

CLAIMS: dict[str, Claim] = {module.CLAIM.name: module.CLAIM for module in (
    fig1b, c1_rest, c2_below_g, c3_onset, fig1c_paper, c4_hysteresis, c5_corrugated_plate, c6_recovery, c6r_recovery_question,
    c7_contact, c8_drive_velocity, chain)}
STUDIES = {name: claim.study for name, claim in CLAIMS.items()}


# On a Dask client every study runs at once, each in a thread of its own that hands its
# sweeps and tasks to the client and waits for them: one study alone would leave a core
# idle whenever it runs a single task (a ramp, a start-phase run, a bisection round of one
# or two points) or waits for the slowest point of a sweep.  The workers take the ready
# work of the costliest studies first (their Dask priority), so that those studies'
# chains of dependent rounds (sweep, bisection, start ensemble) and their longest single
# runs do not trail at the end while the cheap studies fill the gaps.  The order follows
# the compute time of each claim's study under one reading in the main job at the default
# resolution (docs/benchmarks.md, section "make run"; Fig. 1c's runs of the paper's drive
# are the job's longest single tasks).
COSTLIEST_FIRST = ("C6", "Fig1c", "C6r", "Chain", "C8", "C3", "C4", "C7", "C5", "C2", "C1", "Fig1b")


def priority(name: str) -> int:
    """The Dask priority of claim ``name``'s work: higher for a costlier study, 0 if unranked."""
    return len(COSTLIEST_FIRST) - COSTLIEST_FIRST.index(name) if name in COSTLIEST_FIRST else 0


def run_studies(runner: Runner, names: Sequence[str] = tuple(CLAIMS), progress: bool = True,
                readings: bool = True, at_once: int | None = None, laws: bool = False) -> dict[str, Study]:
    """Run the named studies, each under every reading its claim lists (only the default
    one if ``readings`` is false or the resolution measures the default reading only),
    and with ``laws`` under the claim's law readings too (:func:`.readings.law_readings`);
    {study name: Study} (:func:`.readings.study_name`) in that order, each with its
    timing.  Up to ``at_once`` studies run side by side (default: all of them on a Dask
    client, with :func:`priority`; one at a time inline), each on a runner of its own
    (:meth:`Runner.for_reading`); their counts are added to ``runner``'s."""
    readings = readings and runner.resolution.readings
    jobs = [(name, reading) for name in names
            for reading in ((CLAIMS[name].readings + (law_readings(CLAIMS[name].readings) if laws else ()))
                            if readings else (DEFAULT_READING,))]
    at_once = max(1, at_once or (len(jobs) if runner.client is not None else 1))
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(jobs), desc="claims", unit="study", position=0)

    def run_one(name: str, reading) -> tuple[Study, Runner]:
        # Side by side, the sweeps' own progress bars would overwrite each other.
        own = runner.for_reading(reading, progress=None if at_once == 1 else False, priority=priority(name))
        started = time.perf_counter()
        study = CLAIMS[name].study(own)
        study.reading = reading.key
        spent = counts(own)
        study.timing = timing(time.perf_counter() - started, dict.fromkeys(spent, 0), spent)
        return study, own

    results = {}

    def finished(key: str, study: Study, own: Runner) -> None:
        results[key] = study
        runner.add_counts(own)
        if bar is not None:
            bar.set_postfix_str(key)
            bar.update(1)

    try:
        if at_once == 1:  # in this thread (inline, the FMUs run in this process)
            for name, reading in jobs:
                finished(study_name(name, reading), *run_one(name, reading))
        else:
            with ThreadPoolExecutor(max_workers=at_once, thread_name_prefix="study") as pool:
                futures = {pool.submit(run_one, name, reading): study_name(name, reading)
                           for name, reading in sorted(jobs, key=lambda job: -priority(job[0]))}
                failed = []
                try:
                    for future in as_completed(futures):
                        try:
                            finished(futures[future], *future.result())
                        except Exception as exc:
                            # The others go on: what they compute is stored, so that a
                            # rerun has only the failed studies left to compute.
                            failed.append((futures[future], exc))
                            print(f"study {futures[future]} failed ({type(exc).__name__}: {exc}); the other studies "
                                  "go on", file=sys.stderr, flush=True)
                except BaseException:
                    for future in futures:  # the studies not started yet; running ones finish
                        future.cancel()
                    raise
                if failed:
                    raise StudiesFailed(failed) from failed[0][1]
    finally:
        if bar is not None:
            bar.close()
    return {study_name(name, reading): results[study_name(name, reading)] for name, reading in jobs}


class StudiesFailed(RuntimeError):
    """Studies that raised while others ran beside them (which finished and stored their
    results); ``failures``: (study name, exception) pairs."""

    def __init__(self, failures: list):
        self.failures = failures
        names = ", ".join(name for name, _ in failures)
        first = failures[0][1]
        super().__init__(f"{len(failures)} stud{'y' if len(failures) == 1 else 'ies'} failed ({names}); the first: "
                         f"{type(first).__name__}: {first}. The other studies' results are in the store: "
                         "run again to retry the failed ones.")


__all__ = ["CLAIMS", "COSTLIEST_FIRST", "Claim", "DEFAULT_READING", "READINGS", "RESOLUTIONS", "Reading",
           "Resolution", "Runner", "STUDIES", "StudiesFailed", "Study", "friction_held", "load_studies",
           "onset_amplitude", "priority", "recovery", "run_studies", "save_studies", "split_study_name",
           "stable_roots_near", "study_name", "transition_bracket"]
