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
               c6r_recovery_question, c7_contact, c8_drive_velocity, fig1b)
from .measure import friction_held, onset_amplitude, recovery, stable_roots_near, transition_bracket
from .study import RESOLUTIONS, Claim, Resolution, Runner, Study, counts, load_studies, save_studies, timing

CLAIMS: dict[str, Claim] = {module.CLAIM.name: module.CLAIM for module in (
    fig1b, c1_rest, c2_below_g, c3_onset, c4_hysteresis, c5_corrugated_plate, c6_recovery, c6r_recovery_question,
    c7_contact, c8_drive_velocity)}
STUDIES = {name: claim.study for name, claim in CLAIMS.items()}


def run_studies(runner: Runner, names: Sequence[str] = tuple(CLAIMS), progress: bool = True) -> dict[str, Study]:
    """Run the named studies in order; {claim: Study}, each with its timing."""
    results = {}
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(names), desc="claims", unit="claim", position=0)
    try:
        for name in names:
            if bar is not None:
                bar.set_postfix_str(name)
            before, started = counts(runner), time.perf_counter()
            results[name] = CLAIMS[name].study(runner)
            results[name].timing = timing(time.perf_counter() - started, before, counts(runner))
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return results


__all__ = ["CLAIMS", "Claim", "RESOLUTIONS", "Resolution", "Runner", "STUDIES", "Study", "friction_held",
           "load_studies", "onset_amplitude", "recovery", "run_studies", "save_studies", "stable_roots_near",
           "transition_bracket"]
