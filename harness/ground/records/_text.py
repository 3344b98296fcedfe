"""Parsers for the two text formats obspy does not read: PEER ``.AT2`` and
plain two-column (time, value) text/CSV files.

Both return raw numbers plus what the file itself says about them; unit
handling and validation of the samples happen in :mod:`.readers`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import RecordError

# A Fortran-style real: optional sign, digits with optional point, optional
# exponent (E or D). Written without separators, consecutive fixed-width
# fields such as "-.1234E-02-.5678E-03" still split into two matches.
_REAL = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?"
_REAL_RE = re.compile(_REAL)
_NPTS_RE = re.compile(r"NPTS\s*=\s*(\d+)", re.IGNORECASE)
_DT_RE = re.compile(r"DT\s*=\s*(" + _REAL + r")", re.IGNORECASE)
# Older PEER header: "  3930    0.0100    NPTS, DT" (values first, names after).
_OLD_HEADER_RE = re.compile(
    r"^\s*(\d+)\s+(" + _REAL + r")\s+NPTS\s*,?\s*DT\b", re.IGNORECASE
)
_UNITS_RE = re.compile(r"UNITS?\s+OF\s+([A-Z0-9/*^]+)", re.IGNORECASE)
_QUANTITY_WORDS = ("ACCELERATION", "VELOCITY", "DISPLACEMENT")
_HEADER_SEARCH_LINES = 12


@dataclass(frozen=True)
class At2Content:
    """Samples and header facts of a PEER strong-motion file."""

    values: np.ndarray
    dt: float
    quantity: str | None  # "acceleration", ... when the header says so
    unit: str | None  # e.g. "G", "CM/S" when the header says so
    title: str


def _read_text(path: Path) -> str:
    raw = path.read_bytes()
    if not raw.strip():
        raise RecordError(
            f"{path}: the file is empty; check that it was written or "
            "downloaded completely"
        )
    if b"\x00" in raw:
        raise RecordError(
            f"{path}: the file contains binary data (NUL bytes), so it is not a "
            "text record; it is corrupt, or pass format= to read it as a "
            "binary seismic format"
        )
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def _to_float(token: str) -> float:
    return float(token.replace("D", "E").replace("d", "e"))


def parse_at2(path: Path) -> At2Content:
    """Parse a PEER NGA ``.AT2``-style file (also ``.VT2``/``.DT2``).

    The header (first lines) must contain the number of points and the
    sample interval, either as ``NPTS= 3930, DT= .0100 SEC`` (in either order,
    with or without the comma) or in the older form
    ``3930  0.0100  NPTS, DT``. All numbers after that line are samples; their
    count must equal NPTS.

    Raises:
        RecordError: empty file, missing/invalid header, garbage among the
            samples, or a sample count that disagrees with NPTS.
    """
    text = _read_text(path)
    lines = text.splitlines()
    header_index = None
    npts = dt = None
    for i, line in enumerate(lines[:_HEADER_SEARCH_LINES]):
        old = _OLD_HEADER_RE.match(line)
        if old:
            npts, dt = int(old.group(1)), _to_float(old.group(2))
            header_index = i
            break
        m_n, m_dt = _NPTS_RE.search(line), _DT_RE.search(line)
        if m_n and m_dt:
            npts, dt = int(m_n.group(1)), _to_float(m_dt.group(1))
            header_index = i
            break
    if header_index is None or npts is None or dt is None:
        raise RecordError(
            f"{path}: no 'NPTS=..., DT=...' line in the first "
            f"{_HEADER_SEARCH_LINES} lines, so this is not a readable PEER "
            "AT2 file; check the header, or read it as a two-column file with "
            "format='TWOCOLUMN', quantity= and unit="
        )
    if npts <= 0 or not np.isfinite(dt) or dt <= 0:
        raise RecordError(
            f"{path}: header gives NPTS={npts}, DT={dt}; both must be positive"
        )
    header = "\n".join(lines[:header_index])
    quantity = next(
        (w.lower() for w in _QUANTITY_WORDS if w in header.upper()), None
    )
    m_unit = _UNITS_RE.search(header)
    unit = m_unit.group(1) if m_unit else None

    values: list[float] = []
    for lineno, line in enumerate(lines[header_index + 1 :], start=header_index + 2):
        tokens = _REAL_RE.findall(line)
        rest = _REAL_RE.sub(" ", line).replace(",", " ").strip()
        if rest:
            raise RecordError(
                f"{path}, line {lineno}: unexpected text {rest[:40]!r} among the "
                "samples; the file is corrupt (or not an AT2 file)"
            )
        values.extend(_to_float(t) for t in tokens)
    if len(values) != npts:
        hint = "truncated" if len(values) < npts else "has extra values"
        raise RecordError(
            f"{path}: header says NPTS={npts} but {len(values)} samples follow; "
            f"the file is {hint} or corrupt, get a complete copy"
        )
    title = " | ".join(line.strip() for line in lines[:header_index] if line.strip())
    return At2Content(np.asarray(values, dtype=float), dt, quantity, unit, title)


_SPLIT_RE = re.compile(r"[,;\s]+")
_COMMENT_PREFIXES = ("#", "%", "//")


def parse_two_column(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Parse a plain text/CSV file of (time, value) rows.

    Separators may be commas, semicolons, tabs or spaces. Blank lines and
    lines starting with ``#``, ``%`` or ``//`` are ignored, as are
    non-numeric header lines *before* the first data row.

    Returns:
        ``(time, value)`` as float arrays, in file order.

    Raises:
        RecordError: empty file, no numeric rows, a row with other than two
            columns, or a non-numeric row among the data.
    """
    text = _read_text(path)
    times: list[float] = []
    values: list[float] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith(_COMMENT_PREFIXES):
            continue
        tokens = [t for t in _SPLIT_RE.split(stripped) if t]
        try:
            numbers = [float(t) for t in tokens]
        except ValueError:
            if not times:
                continue  # header line before the data
            raise RecordError(
                f"{path}, line {lineno}: cannot read {stripped[:40]!r} as "
                "numbers; the file is corrupt or mixes text into the data"
            ) from None
        if len(numbers) != 2:
            raise RecordError(
                f"{path}, line {lineno}: expected two columns (time, value), "
                f"found {len(numbers)}; write one (time, value) pair per line"
            )
        times.append(numbers[0])
        values.append(numbers[1])
    if not times:
        raise RecordError(
            f"{path}: no numeric (time, value) rows found; the file is empty "
            "or holds only a header"
        )
    return np.asarray(times, dtype=float), np.asarray(values, dtype=float)
