"""The claims of DESIGN.md (C1-C8) and the paper's Fig. 1b, one module each.

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

import time
from typing import Sequence

from . import (c1_rest, c2_below_g, c3_onset, c4_hysteresis, c5_corrugated_plate, c6_recovery,
               c6r_recovery_question, c7_contact, c8_drive_velocity, fig1b, fig1c_paper)
from .readings import DEFAULT_READING, READINGS, Reading, split_study_name, study_name
from .measure import friction_held, onset_amplitude, recovery, stable_roots_near, transition_bracket
from .study import RESOLUTIONS, Claim, Resolution, Runner, Study, counts, load_studies, save_studies, timing

CLAIMS: dict[str, Claim] = {module.CLAIM.name: module.CLAIM for module in (
    fig1b, c1_rest, c2_below_g, c3_onset, fig1c_paper, c4_hysteresis, c5_corrugated_plate, c6_recovery, c6r_recovery_question,
    c7_contact, c8_drive_velocity)}
STUDIES = {name: claim.study for name, claim in CLAIMS.items()}


def run_studies(runner: Runner, names: Sequence[str] = tuple(CLAIMS), progress: bool = True,
                readings: bool = True) -> dict[str, Study]:
    """Run the named studies in order, each under every reading its claim lists (only the
    default one if ``readings`` is false or the resolution measures the default reading
    only); {study name: Study} (:func:`.readings.study_name`), each with its timing."""
    readings = readings and runner.resolution.readings
    jobs = [(name, reading) for name in names
            for reading in (CLAIMS[name].readings if readings else (DEFAULT_READING,))]
    results = {}
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(jobs), desc="claims", unit="study", position=0)
    try:
        for name, reading in jobs:
            key = study_name(name, reading)
            if bar is not None:
                bar.set_postfix_str(key)
            before, started = counts(runner), time.perf_counter()
            runner.reading = reading
            try:
                results[key] = CLAIMS[name].study(runner)
            finally:
                runner.reading = DEFAULT_READING
            results[key].reading = reading.key
            results[key].timing = timing(time.perf_counter() - started, before, counts(runner))
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return results


__all__ = ["CLAIMS", "Claim", "DEFAULT_READING", "READINGS", "RESOLUTIONS", "Reading", "Resolution", "Runner", "STUDIES", "Study", "friction_held",
           "load_studies", "onset_amplitude", "recovery", "run_studies", "save_studies", "split_study_name",
           "stable_roots_near", "study_name", "transition_bracket"]
