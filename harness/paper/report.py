"""Measured values -> verdicts, figures and ``out/report.md``.

The report iterates the registry :data:`harness.paper.claims.CLAIMS`: each claim's module
computes its rows of the claims table from the numbers its study measured (its docstring
states the criteria) and draws its figures.  Nothing in the table is written by hand.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

from .claims import CLAIMS, DEFAULT_READING, READINGS, Study, study_name
from .claims.readings import ALL_READINGS, law_readings
from .claims.verdicts import AGREES, DISAGREES, FLIPS, FORMULA_TOLERANCE, NOT_REPRODUCED, UNCHANGED_TOLERANCE, Row

CLAIM_TEXT = {part: text for claim in CLAIMS.values() for part, text in claim.text.items()}
FIGURES = {part: files for claim in CLAIMS.values() for part, files in claim.figures.items()}


def _rows(name: str, study: Study) -> list[Row]:
    made = CLAIMS[name].verdicts(study.measured)
    made = [made] if isinstance(made, Row) else list(made)
    for row in made:
        row.figures = FIGURES.get(row.claim, [])
        row.settings = _settings_text(study.settings)
    return made


def reading_rows(studies: dict[str, Study], laws: bool = False, single: bool = False) -> dict[str, dict]:
    """{claim part: {reading: Row}} for every claim measured under more than one reading
    (the readings in the claim's order, the default first); with ``laws`` the law
    readings measured too, with ``single`` the claims measured under one reading too."""
    table: dict[str, dict] = {}
    for name, claim in CLAIMS.items():
        candidates = claim.readings + (law_readings(claim.readings) if laws else ())
        present = [r for r in candidates if study_name(name, r) in studies]
        if claim.verdicts is None or len(present) < (1 if single else 2):
            continue
        for reading in present:
            for row in _rows(name, studies[study_name(name, reading)]):
                table.setdefault(row.claim, {})[reading] = row
    return table


def flips(verdicts) -> bool:
    """A verdict flips with the reading when some readings agree with the paper and others
    do not (disagrees and not reproduced under two readings is no flip: neither agrees)."""
    verdicts = set(verdicts)
    return AGREES in verdicts and len(verdicts) > 1


def claim_rows(studies: dict[str, Study]) -> list[Row]:
    """Every row of the claims table, from the studies' measured values under the default
    reading; a part that agrees under some readings and not under others gets the verdict
    FLIPS, one that agrees under none gets the worst of its verdicts (disagrees before not
    reproduced), each with a reason that names the verdict of each reading."""
    by_reading = reading_rows(studies)
    rows: list[Row] = []
    for name, claim in CLAIMS.items():
        if claim.verdicts is None or name not in studies:
            continue
        for row in _rows(name, studies[name]):
            verdicts = {r: other.verdict for r, other in by_reading.get(row.claim, {}).items()}
            if len(set(verdicts.values())) > 1:
                row.reason = ("; ".join(f"{r.label}: {v}" for r, v in verdicts.items())
                              + f". Under the default reading ({DEFAULT_READING.label}): {row.reason}")
                row.verdict = FLIPS if flips(verdicts.values()) else (
                    DISAGREES if DISAGREES in verdicts.values() else NOT_REPRODUCED)
            rows.append(row)
    return rows


def readings_markdown(studies: dict[str, Study]) -> list[str]:
    """The section that sets the readings side by side: one row per claim part, one column
    per reading, and per reading the parts on which it agrees with the paper."""
    table = reading_rows(studies)
    if not table:
        return []
    readings = _columns(table)
    lines = ["## The readings side by side", "",
             "Models B and C are integrated in fixed axes (Newton's law for the point) or in the tangent frame "
             "(the paper's Eqs. 3-6 as printed); the Coulomb bound mu_s N takes N as the contact force or as the "
             "applied load (docs/physics.md). The claims these readings can change were measured under each; "
             "model A has no corrugation, so its parts differ only with the bound. Cells: verdict, then why.", "",
             "| part | " + " | ".join(r.label for r in readings) + " |", "|---|" + "---|" * len(readings)]
    for part, per_part in table.items():
        cells = [f"**{per_part[r].verdict}**: {_cell(per_part[r].reason)}" if r in per_part else "n/a" for r in readings]
        lines.append(f"| {part} | " + " | ".join(cells) + " |")
    lines += [""] + [f"- {line}" for line in reading_summary(studies)] + [""]
    return lines


def _columns(table: dict) -> list:
    """The readings present in a reading_rows table, in the order of ALL_READINGS."""
    present = {r for per_part in table.values() for r in per_part}
    return [r for r in ALL_READINGS if r in present]


# The paper's Fig. 5 names the two transitions of model C that C6b and C6c check.
FIGURE_5 = {"C6b": "Fig. 5, first transition at A = P_l/(m omega^2)",
            "C6c": "Fig. 5, recovery near k_n/gamma_n, independent of A"}


def reproduction_markdown(studies: dict[str, Study]) -> list[str]:
    """Per claim part: under which readings and laws it agrees with the paper, and under
    which it does not (with the verdict); the laws appear where they were measured
    (``python -m harness.main`` unless ``--no-laws``)."""
    table = reading_rows(studies, laws=True, single=True)
    if not table:
        return []
    measured = _columns(table)
    laws_measured = any(r not in READINGS for r in measured)
    lines = ["## Which readings and laws reproduce the paper", "",
             "Per claim part: the readings (formulation, Coulomb bound) and contact laws under which its verdict is "
             "**agrees**, and the others with their verdicts. A part measured under the default reading only lists "
             "that one. "
             + ("The load-only bound and the linear_along_normal and linear_no_pull contacts were measured too "
                "(C6 under them: Fig. 5's diagram, C6a-C6c)." if laws_measured else
                "The load-only bound and the linear_along_normal and linear_no_pull contacts were not measured in "
                "this run (`python -m harness.main` measures them unless given `--no-laws` or "
                "`--default-reading-only`)."), "",
             "| part | reproduces the paper under | does not, under |", "|---|---|---|"]
    for part, per_part in table.items():
        order = [r for r in measured if r in per_part]
        agreeing = [r.label for r in order if per_part[r].verdict == AGREES]
        others = [f"{r.label} ({per_part[r].verdict})" for r in order if per_part[r].verdict != AGREES]
        name = f"{part} ({FIGURE_5[part]})" if part in FIGURE_5 else part
        lines.append(f"| {name} | {'; '.join(agreeing) or 'none'} | {'; '.join(others) or 'none'} |")
    return lines + [""]


def reading_summary(studies: dict[str, Study]) -> list[str]:
    """Per reading: the parts it agrees with the paper on, out of those measured under it;
    then the parts whose verdict flips with the reading."""
    table = reading_rows(studies)
    readings = _columns(table)
    lines = []
    for reading in readings:
        parts = [part for part, per_part in table.items() if reading in per_part]
        agreeing = [part for part in parts if table[part][reading].verdict == AGREES]
        lines.append(f"{reading.label}: agrees on {len(agreeing)} of {len(parts)} parts"
                     + (f" ({', '.join(agreeing)})" if agreeing else ""))
    flipping = [part for part, per_part in table.items() if flips(row.verdict for row in per_part.values())]
    lines.append("verdict flips with the reading: " + (", ".join(flipping) if flipping else "none"))
    return lines


def _settings_text(settings: dict) -> str:
    keys = ("model", "models", "parameters", "initial", "horizon", "step_duration", "phi_threshold", "transient",
            "window")
    return "; ".join(f"{k}: {settings[k]}" for k in keys if k in settings)


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def markdown(studies: dict[str, Study], figures_present: Sequence[str] = (), header: dict | None = None) -> str:
    rows = claim_rows(studies)
    header = header or {}
    lines = ["# vibroblock: claims C1-C8 against our simulations", ""]
    if header:
        lines += [f"- {k}: {v}" for k, v in header.items()] + [""]
    lines += ["Verdicts are computed from the measured numbers by the criteria stated in each claim's module (`harness/paper/claims/`) "
              f"(relative tolerance {FORMULA_TOLERANCE:.0%} for formulas, {UNCHANGED_TOLERANCE:.0%} for 'unchanged', "
              "bracket tests on the sweep grids). 'Friction' means regime stick_slip, micro_slip, stuck or jammed (held in the "
              "window); 'sliding' means following the drive (phi at most the threshold, drift >= V_d/2); 'hopping' large phi "
              "without rests and with contact less than half the window; 'flying' no contact. The rules are in "
              "`harness/runs/observables.py`.", "",
              "The table keeps the numbers that decide each verdict; what was measured in full, why the verdict "
              "follows and the settings are in \"Per claim\" below, and every figure has its caption under "
              "\"Figures\".", "",
              "| claim | statement | deciding numbers | verdict | figures |", "|---|---|---|---|---|"]
    summary = {}
    for row in rows:
        figures = " ".join(f"[{f}]({f})" for f in row.figures if f in figures_present)
        lines.append(f"| {row.claim} | {_cell(_short(CLAIM_TEXT[row.claim]))} | "
                     f"{_cell(_short(row.measured))} [details](#{_anchor(row.claim)}) | **{row.verdict}** | {figures} |")
        summary[row.verdict] = summary.get(row.verdict, 0) + 1
    lines += ["", "Summary: " + ", ".join(f"{v}: {n}" for v, n in sorted(summary.items()))]
    if reading_rows(studies):
        lines += ["", "Readings (see \"The readings side by side\"):"] + [f"- {line}" for line in reading_summary(studies)]
    lines += [""] + reproduction_markdown(studies)
    lines += readings_markdown(studies)
    described = [(name, CLAIMS[name].describe(study.measured)) for name, study in studies.items()
                 if name in CLAIMS and CLAIMS[name].describe is not None]
    if described:
        lines += ["## Studies without a verdict of their own", ""] + [f"- {name}: {text}" for name, text in described]
        lines += [""]
    lines += ["## Parameter sets and classification per study", "",
              "| study | settings |", "|---|---|"]
    for name, study in studies.items():
        lines.append(f"| {name} | {_cell(_settings_text(study.settings))}; merge gap {study.settings.get('merge_gap', 'n/a')}, "
                     f"min slip fraction {study.settings.get('slip_min_fraction', 'n/a')} |")
    timed = {name: study.timing for name, study in studies.items() if study.timing}
    if timed:
        lines += ["", "## Time per study", "",
                  "On a Dask client the studies run side by side, so their wall times overlap; "
                  "the compute time is a study's own cost: the seconds the workers spent on the points and runs "
                  "it computed.", "",
                  "| study | wall time | compute time | from | points computed / from the store | "
                  "runs and ramps computed / from the store |", "|---|---|---|---|---|---|"]
        lines += [f"| {name} | {t['wall_time']:.1f} s | {t.get('compute_time', 0.0):.1f} s | {t['source']} "
                  f"| {t['points_computed']} / {t['points_reused']} | {t['tasks_computed']} / {t['tasks_reused']} |"
                  for name, t in timed.items()]
    lines += ["", "## Per claim", ""] + per_claim_markdown(rows, figures_present)
    if figures_present:
        lines += ["", "## Figures", ""]
        for number, name in enumerate(figures_present, start=1):
            lines += [f"![{name}]({name})", "", f"*Figure {number} ({name}): {figure_caption(name, rows)}*", ""]
    return "\n".join(lines) + "\n"


# The table shows a cell's first clauses up to this many characters; the full text is in
# the claim's own section.
TABLE_CELL = 220


def _short(text: str, limit: int = TABLE_CELL) -> str:
    """The first clauses of ``text`` that fit in ``limit`` characters (cut at "; " or ". ")."""
    text = " ".join(str(text).split())
    if len(text) <= limit:
        return text
    cut = max(text.rfind("; ", 0, limit), text.rfind(". ", 0, limit))
    return (text[:cut] if cut > limit // 3 else text[:limit].rsplit(" ", 1)[0]) + " ... (see below)"


def _anchor(part: str) -> str:
    return f"claim-{part.lower()}"


def per_claim_markdown(rows: Sequence[Row], figures_present: Sequence[str]) -> list[str]:
    """One section per claim part: statement, measured, verdict and why, settings, figures.
    A measurement shared with the part before it is named, not repeated."""
    lines, previous = [], None
    for row in rows:
        lines += [f'<a id="{_anchor(row.claim)}"></a>', f"### {row.claim}: {row.verdict}", "",
                  f"*Claim:* {CLAIM_TEXT[row.claim]}", ""]
        if previous is not None and row.measured == previous.measured:
            lines += [f"*Measured:* the same runs and numbers as {previous.claim} (above).", ""]
        else:
            lines += [f"*Measured:* {row.measured}", ""]
            previous = row
        lines += [f"*Why {row.verdict}:* {row.reason}", ""]
        if row.settings:
            lines += [f"*Settings:* {row.settings}", ""]
        shown = [f for f in row.figures if f in figures_present]
        if shown:
            lines += ["*Figures:* " + ", ".join(f"[{f}]({f}) (Figure {list(figures_present).index(f) + 1})"
                                               for f in shown), ""]
    return lines


def figure_caption(name: str, rows: Sequence[Row]) -> str:
    """What a figure shows: the claim parts it stands for and their statements."""
    parts = [row for row in rows if name in row.figures]
    if not parts:
        return "drawn by the main job beside the claims (see the section that links to it)."
    statements = []
    for row in parts:
        text = _short(CLAIM_TEXT[row.claim], 160).replace(" ... (see below)", " ...")
        if text not in statements:
            statements.append(text)
    return (f"evidence for {', '.join(row.claim for row in parts)} -- " + "; ".join(statements)
            + " Lengths in delta_0 = m g / k_n, times in tau_0 = sqrt(m / k_n), frequencies in 1/tau_0.")


def make_figures(studies: dict[str, Study], out: str | os.PathLike) -> list[str]:
    """Draw every figure the studies allow into ``out``; the file names written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []

    def save(fig, name):
        fig.tight_layout()
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        written.append(name)

    for name, claim in CLAIMS.items():
        if claim.draw is not None and name in studies:  # the figures show the default reading
            claim.draw(studies[name], save)
    return written


def timing_lines(studies: dict[str, Study]) -> list[str]:
    """One line per study: its wall time and where its results came from (for the main job's output)."""
    return [f"{name}: {s.timing['wall_time']:.1f} s, computing {s.timing.get('compute_time', 0.0):.1f} s "
            f"({s.timing['source']}; points {s.timing['points_computed']} "
            f"computed / {s.timing['points_reused']} from the store, runs and ramps {s.timing['tasks_computed']} / "
            f"{s.timing['tasks_reused']})" for name, s in studies.items() if s.timing]


def write_report(studies: dict[str, Study], out: str | os.PathLike, extra_figures: Sequence[str] = (),
                 header: dict | None = None) -> Path:
    """Figures and ``<out>/report.md`` from the studies; the report's path."""
    out = Path(out)
    figures = list(extra_figures) + make_figures(studies, out)
    path = out / "report.md"
    path.write_text(markdown(studies, figures, header))
    return path


__all__ = ["AGREES", "CLAIM_TEXT", "DISAGREES", "FIGURES", "FLIPS", "NOT_REPRODUCED", "Row", "claim_rows",
           "make_figures", "markdown", "reading_rows", "reading_summary", "timing_lines", "write_report"]
