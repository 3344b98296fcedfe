"""Reading ground-motion records into SI units.

:func:`read_record` turns a file (or an obspy ``Stream``/``Trace``) into a
:class:`Record`: one uniformly sampled channel of acceleration, velocity or
displacement in SI units.

Where the units come from
-------------------------
* **Seismic formats read by obspy** (MiniSEED, SAC, GSE2, SEISAN, …): the
  samples are normally raw counts. They become physical by removing the
  instrument response, taken from ``inventory=`` (an obspy ``Inventory`` or a
  StationXML/RESP/dataless SEED path) or from a response already attached to
  a trace (``trace.stats.response``). If the samples are already physical,
  state ``quantity=`` and ``unit=`` instead; giving both an inventory and
  units is an error.
* **PEER NGA ``.AT2``** (and ``.VT2``/``.DT2``): the header states the
  quantity and unit (acceleration in g for AT2).
* **Two-column text/CSV** (time in seconds, value): the caller must state
  ``quantity=`` and ``unit=``; a file with unknown units is refused.

Instrument response removal
---------------------------
Done with :meth:`obspy.core.trace.Trace.remove_response` under
:class:`ResponseSettings`. By default the output is the instrument's native
quantity (velocity for a seismometer, acceleration for an accelerometer), so
the water level (60 dB below the peak of the inverse spectrum) acts where the
response is flat and does not suppress valid parts of the band; obspy removes
the mean and applies a 5 % cosine taper before the deconvolution.
Conversion between quantities is left to :mod:`.processing`, which does it in
the frequency band the user chose.
"""

from __future__ import annotations

import fnmatch
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Union

import numpy as np

from ._text import parse_at2, parse_two_column
from .errors import RecordError
from .quantities import Quantity, parse_quantity, si_factor

if TYPE_CHECKING:
    import obspy

__all__ = ["MIN_SAMPLES", "Record", "ResponseSettings", "read_record"]

#: Fewest samples a record may have.
MIN_SAMPLES: int = 16

_TWO_COLUMN_SUFFIXES = {".csv", ".txt", ".dat", ".tsv"}
_PEER_SUFFIXES = {".at2": "acceleration", ".vt2": "velocity", ".dt2": "displacement"}
_OBSPY_OUTPUT = {Quantity.ACCELERATION: "ACC", Quantity.VELOCITY: "VEL",
                 Quantity.DISPLACEMENT: "DISP"}
_NATIVE_UNITS = {"M": Quantity.DISPLACEMENT, "M/S": Quantity.VELOCITY,
                 "M/S**2": Quantity.ACCELERATION, "M/S/S": Quantity.ACCELERATION,
                 "M/S2": Quantity.ACCELERATION}

PathLike = Union[str, os.PathLike]
"""A file path: ``str`` or ``pathlib.Path``."""


def _check_finite(data: np.ndarray, where: str) -> None:
    bad = ~np.isfinite(data)
    if bad.any():
        first = int(np.argmax(bad))
        raise RecordError(
            f"{where}: {int(bad.sum())} of {data.size} samples are NaN or "
            f"infinite (first at sample {first}); the record is corrupt or has "
            "gaps: repair or cut it before use"
        )


@dataclass(frozen=True, eq=False)
class Record:
    """One uniformly sampled ground-motion channel in SI units.

    Attributes:
        data: samples in SI units of ``quantity`` (m, m/s or m/s²); a
            read-only float64 array.
        dt: sample interval in seconds.
        quantity: what the samples are.
        source: where the record came from (path or stream description).
        trace_id: SEED id ``NET.STA.LOC.CHA`` when known, else ``""``.
        start_time: ISO 8601 UTC time of the first sample when known, else
            ``""``.
        response_removed: whether an instrument response was deconvolved.
        history: human-readable steps applied so far.
    """

    data: np.ndarray
    dt: float
    quantity: Quantity
    source: str = ""
    trace_id: str = ""
    start_time: str = ""
    response_removed: bool = False
    history: tuple[str, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        data = np.array(self.data, dtype=float, copy=True)
        if data.ndim != 1:
            raise RecordError(
                f"{self.source}: record data must be one-dimensional, got shape "
                f"{data.shape}; pass a single channel"
            )
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise RecordError(
                f"{self.source}: sample interval dt={self.dt!r} s is not a "
                "positive number; fix the header or the time column"
            )
        if data.size < MIN_SAMPLES:
            raise RecordError(
                f"{self.source}: only {data.size} samples; a record needs at "
                f"least {MIN_SAMPLES} (and, for processing, at least one period "
                "of the high-pass corner)"
            )
        _check_finite(data, self.source or "record")
        data.setflags(write=False)
        object.__setattr__(self, "data", data)
        object.__setattr__(self, "quantity", parse_quantity(self.quantity))
        object.__setattr__(self, "dt", float(self.dt))
        object.__setattr__(self, "history", tuple(self.history))

    @property
    def npts(self) -> int:
        """Number of samples."""
        return int(self.data.size)

    @property
    def sampling_rate(self) -> float:
        """Samples per second."""
        return 1.0 / self.dt

    @property
    def duration(self) -> float:
        """Time from first to last sample, in seconds."""
        return (self.npts - 1) * self.dt

    def times(self) -> np.ndarray:
        """Sample times in seconds from the first sample."""
        return np.arange(self.npts) * self.dt


@dataclass(frozen=True)
class ResponseSettings:
    """How to deconvolve an instrument response (obspy ``remove_response``).

    Attributes:
        output: ``"native"`` (default) deconvolves to the quantity the
            instrument senses (from the response's input units: ``M/S`` →
            velocity, ``M/S**2`` → acceleration, ``M`` → displacement);
            ``"ACC"``, ``"VEL"`` or ``"DISP"`` force an output.
        water_level: water level in dB below the maximum of the inverse
            spectrum, or ``None`` for no water level (then give
            ``pre_filt``).
        pre_filt: four corner frequencies ``(f1, f2, f3, f4)`` in Hz of a
            cosine taper applied to the spectrum before deconvolution
            (pass band ``f2``–``f3``), or ``None``.
    """

    output: Literal["native", "ACC", "VEL", "DISP"] = "native"
    water_level: float | None = 60.0
    pre_filt: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.output not in ("native", "ACC", "VEL", "DISP"):
            raise RecordError(
                f"ResponseSettings.output={self.output!r} is not supported; use "
                "'native', 'ACC', 'VEL' or 'DISP'"
            )
        if self.pre_filt is not None:
            pf = tuple(float(f) for f in self.pre_filt)
            if len(pf) != 4 or not all(0 < a < b for a, b in zip(pf, pf[1:])) or pf[0] <= 0:
                raise RecordError(
                    f"ResponseSettings.pre_filt={self.pre_filt!r} must be four "
                    "increasing positive frequencies (f1 < f2 < f3 < f4) in Hz"
                )
            object.__setattr__(self, "pre_filt", pf)
        if self.water_level is None and self.pre_filt is None:
            raise RecordError(
                "ResponseSettings needs a water_level or a pre_filt (or both); "
                "without either the deconvolution amplifies noise without bound"
            )


def read_record(
    source: PathLike | obspy.Stream | obspy.Trace,
    *,
    quantity: Quantity | str | None = None,
    unit: str | None = None,
    format: str | None = None,
    inventory: obspy.Inventory | PathLike | None = None,
    trace_id: str | None = None,
    response: ResponseSettings | None = None,
    time_tolerance: float = 0.01,
    sensitivity: float | None = None,
) -> Record:
    """Read one ground-motion channel and return it in SI units.

    Args:
        source: path to a record file, or an obspy ``Stream``/``Trace``.
        quantity: what the samples are (``"acceleration"``, ``"velocity"``,
            ``"displacement"``); required for two-column files and for obspy
            data that are already physical.
        unit: unit of the samples (see :mod:`.quantities`), required together
            with *quantity*.
        format: ``"AT2"`` (PEER; also .VT2/.DT2), ``"TWOCOLUMN"`` (alias
            ``"CSV"``), or an obspy format name (``"MSEED"``, ``"SAC"``,
            ``"GSE2"``, …). ``None`` picks by suffix: ``.at2/.vt2/.dt2`` →
            PEER, ``.csv/.txt/.dat/.tsv`` → two-column, anything else → obspy
            auto-detection.
        inventory: station metadata with the instrument response (obspy
            ``Inventory`` or a path readable by ``obspy.read_inventory``).
        trace_id: ``fnmatch`` pattern on ``NET.STA.LOC.CHA`` selecting the
            channel of a multi-channel file (e.g. ``"*Z"``). Without it a
            single channel is taken as is, and among several the single
            vertical (``…Z``) one, since the plate moves vertically.
        response: response removal settings (default :class:`ResponseSettings`).
        time_tolerance: for two-column files, the largest allowed deviation
            of a time stamp from the uniform grid, as a fraction of the
            sample interval.
        sensitivity: for seismic formats whose samples are counts (integers, as
            a digitizer writes them): counts per *unit* of *quantity*, the
            recording chain's overall sensitivity (flat response assumed).
            Counts are refused with *quantity* and *unit* alone: declaring
            counts to be m/s would make them physical by fiat.

    Returns:
        The :class:`Record`.

    Raises:
        RecordError: for missing, empty or corrupt files, unknown formats,
            unsupported quantity/unit strings, data without known units,
            non-uniform sampling, gaps, NaN/inf samples, too few samples, or
            a missing response.
    """
    response = response or ResponseSettings()
    if not (np.isfinite(time_tolerance) and 0 < time_tolerance < 0.5):
        raise RecordError(
            f"time_tolerance={time_tolerance!r} must lie between 0 and 0.5 "
            "(a fraction of the sample interval)"
        )
    if (quantity is None) != (unit is None):
        raise RecordError(
            "give quantity= and unit= together (e.g. quantity='acceleration', "
            f"unit='m/s^2'); got quantity={quantity!r}, unit={unit!r}"
        )
    q = parse_quantity(quantity) if quantity is not None else None
    if q is not None:
        si_factor(q, unit)  # validate early, before touching the file
    if sensitivity is not None:
        if q is None:
            raise RecordError(f"sensitivity = {sensitivity!r} counts per unit needs quantity= and unit= (what one "
                              "unit is, e.g. quantity='velocity', unit='m/s')")
        if not (np.isfinite(sensitivity) and sensitivity > 0):
            raise RecordError(f"sensitivity = {sensitivity!r} must be a finite number > 0 (counts per unit)")
        if inventory is not None:
            raise RecordError("give either an inventory (the full response) or a sensitivity (a flat one), not both")

    try:
        import obspy
    except ImportError as exc:  # pragma: no cover - obspy is a dependency
        raise RecordError("obspy is required to read seismic formats") from exc
    if isinstance(source, (obspy.Stream, obspy.Trace)):
        stream = obspy.Stream([source]) if isinstance(source, obspy.Trace) else source
        return _from_stream(stream.copy(), "<obspy stream>", q, unit, inventory,
                            trace_id, response, sensitivity)

    path = Path(source)
    if not path.is_file():
        raise RecordError(f"{path}: no such file; check the path")
    if path.stat().st_size == 0:
        raise RecordError(
            f"{path}: the file is empty (0 bytes); check that it was written or "
            "downloaded completely"
        )
    fmt = (format or "").upper()
    suffix = path.suffix.lower()
    if fmt == "AT2" or (not fmt and suffix in _PEER_SUFFIXES):
        return _read_peer(path, q, unit)
    if fmt in ("TWOCOLUMN", "CSV") or (not fmt and suffix in _TWO_COLUMN_SUFFIXES):
        return _read_two_column(path, q, unit, time_tolerance)
    stream = _obspy_read(path, fmt or None)
    return _from_stream(stream, str(path), q, unit, inventory, trace_id, response, sensitivity)


# --------------------------------------------------------------------------- text


def _read_peer(path: Path, q: Quantity | None, unit: str | None) -> Record:
    content = parse_at2(path)
    default_q = _PEER_SUFFIXES.get(path.suffix.lower(), "acceleration")
    file_q = parse_quantity(content.quantity) if content.quantity else None
    file_unit = content.unit
    if file_unit is not None:
        file_q = file_q or parse_quantity(default_q)
        si_factor(file_q, file_unit)  # unsupported header unit -> clear error
    if q is not None and file_q is not None and q is not file_q:
        raise RecordError(
            f"{path}: the header says {file_q.value}, but quantity={q.value!r} "
            "was given; drop the argument or fix the file"
        )
    if q is not None and file_unit is not None:
        if q is not file_q or si_factor(q, unit) != si_factor(file_q, file_unit):
            raise RecordError(
                f"{path}: the header says {file_q.value} in {file_unit}, but "
                f"quantity={q.value!r}, unit={unit!r} was given; drop the "
                "arguments or fix the file"
            )
    if file_unit is not None:
        q_final, unit_final, note = file_q, file_unit, "units from the header"
    elif q is not None:
        q_final, unit_final, note = q, unit, "units given by the caller"
    else:
        q_final = file_q or parse_quantity(default_q)
        if q_final is not Quantity.ACCELERATION:
            raise RecordError(
                f"{path}: the header states no unit; pass quantity= and unit="
            )
        unit_final, note = "g", "no unit in header: PEER AT2 convention (g)"
    factor = si_factor(q_final, unit_final)
    return Record(
        data=content.values * factor,
        dt=content.dt,
        quantity=q_final,
        source=str(path),
        history=(f"read PEER file {path.name} ({content.values.size} samples, "
                 f"dt={content.dt} s), {q_final.value} in {unit_final} ({note})",),
    )


def _read_two_column(path: Path, q: Quantity | None, unit: str | None,
                     time_tolerance: float) -> Record:
    if q is None:
        raise RecordError(
            f"{path}: a two-column text file carries no units; pass quantity= "
            "('acceleration', 'velocity' or 'displacement') and unit= (e.g. "
            "'m/s^2', 'cm/s', 'g'); time must be in seconds"
        )
    t, v = parse_two_column(path)
    if t.size < MIN_SAMPLES:
        raise RecordError(
            f"{path}: only {t.size} rows; a record needs at least {MIN_SAMPLES}"
        )
    _check_finite(t, f"{path} (time column)")
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise RecordError(
            f"{path}: time is not strictly increasing (row {i + 2} has t={t[i + 1]!r} "
            f"after t={t[i]!r}); sort the rows and remove duplicates"
        )
    dt = (t[-1] - t[0]) / (t.size - 1)
    deviation = np.abs(t - (t[0] + dt * np.arange(t.size)))
    worst = int(np.argmax(deviation))
    if deviation[worst] > time_tolerance * dt:
        raise RecordError(
            f"{path}: not uniformly sampled: time stamps deviate from a uniform "
            f"grid of dt={dt:.6g} s by up to {deviation[worst]:.3g} s "
            f"({deviation[worst] / dt:.1%} of dt, at row {worst + 1}; tolerance "
            f"{time_tolerance:.1%}); resample the data to a uniform step first, "
            "or fill the gaps"
        )
    factor = si_factor(q, unit)
    return Record(
        data=v * factor,
        dt=dt,
        quantity=q,
        source=str(path),
        history=(f"read two-column file {path.name} ({t.size} samples, "
                 f"dt={dt:.6g} s, t0={t[0]:.6g} s), {q.value} in {unit}",),
    )


# ------------------------------------------------------------------------- obspy


def _obspy_read(path: Path, fmt: str | None) -> obspy.Stream:
    import obspy

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            stream = obspy.read(str(path), format=fmt)
        except Exception as exc:  # obspy raises bare Exception/TypeError/…
            raise RecordError(
                f"{path}: cannot be read as "
                f"{'format ' + fmt if fmt else 'any seismic format obspy knows'} "
                f"({type(exc).__name__}: {exc}); the file is corrupt or of "
                "another kind: for PEER files use format='AT2', for plain "
                "(time, value) text use format='TWOCOLUMN' with quantity= and unit="
            ) from exc
    for w in caught:
        text = str(w.message)
        if w.category.__name__ == "InternalMSEEDWarning" or "end of file" in text.lower():
            raise RecordError(
                f"{path}: the file is damaged or truncated (obspy: {text}); "
                "get a complete copy of the record"
            )
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return stream


def _select_trace(stream: obspy.Stream, where: str, trace_id: str | None) -> obspy.Trace:
    if len(stream) == 0:
        raise RecordError(f"{where}: contains no waveform data (empty stream)")
    ids = sorted({tr.id for tr in stream})
    if trace_id is not None:
        chosen = [i for i in ids if fnmatch.fnmatchcase(i, trace_id)]
        if len(chosen) != 1:
            raise RecordError(
                f"{where}: trace_id={trace_id!r} matches {len(chosen)} channels "
                f"({', '.join(chosen) or 'none'}); available: {', '.join(ids)}"
            )
    elif len(ids) == 1:
        chosen = ids
    else:
        chosen = [i for i in ids if i.endswith("Z")]
        if len(chosen) != 1:
            raise RecordError(
                f"{where}: holds {len(ids)} channels ({', '.join(ids)}); choose "
                "one with trace_id= (an fnmatch pattern such as '*HZ')"
            )
    selected = stream.select(id=chosen[0])
    try:
        selected.merge(method=0)
    except Exception as exc:
        raise RecordError(
            f"{where}: the pieces of {chosen[0]} cannot be joined ({exc}); "
            "cut the record to one continuous segment"
        ) from exc
    if len(selected) != 1:
        raise RecordError(f"{where}: {chosen[0]} could not be merged into one trace")
    tr = selected[0]
    if np.ma.isMaskedArray(tr.data) and np.ma.is_masked(tr.data):
        n_gap = int(np.ma.getmaskarray(tr.data).sum())
        raise RecordError(
            f"{where}: {tr.id} has gaps ({n_gap} missing samples); cut the "
            "record to a gap-free segment or fill the gaps "
            "(e.g. Stream.merge(fill_value='interpolate')) first"
        )
    # Integer samples are counts as a digitizer writes them (_is_counts); noted before they become floats.
    tr.stats.integer_samples = bool(np.issubdtype(np.ma.getdata(tr.data).dtype, np.integer))
    tr.data = np.asarray(np.ma.getdata(tr.data), dtype=float)
    return tr


def _is_counts(tr: obspy.Trace) -> bool:
    """Samples as an instrument writes them, not ground motion: integers (MiniSEED's
    integer encodings, GSE2's CM6, ...), or a SAC file whose header says its dependent
    variable is volts (idep = 50), or unknown (idep = 5) with integral values."""
    if tr.stats.get("integer_samples") or np.issubdtype(tr.data.dtype, np.integer):
        return True
    sac = getattr(tr.stats, "sac", None)
    idep = None if sac is None else sac.get("idep")
    return idep == 50 or (idep == 5 and bool(np.all(np.mod(tr.data, 1.0) == 0.0)))


def _from_stream(stream: obspy.Stream, where: str, q: Quantity | None, unit: str | None,
                 inventory: obspy.Inventory | PathLike | None, trace_id: str | None,
                 response: ResponseSettings, sensitivity: float | None = None) -> Record:
    tr = _select_trace(stream, where, trace_id)
    if tr.stats.npts < MIN_SAMPLES:
        raise RecordError(
            f"{where}: {tr.id} has only {tr.stats.npts} samples; a record needs "
            f"at least {MIN_SAMPLES}"
        )
    _check_finite(tr.data, f"{where} ({tr.id})")
    common = dict(source=where, trace_id=tr.id, dt=float(tr.stats.delta),
                  start_time=tr.stats.starttime.isoformat() + "Z")
    read_note = f"read {tr.id} from {where} ({tr.stats.npts} samples at {tr.stats.sampling_rate:g} Hz)"

    if q is not None:
        if inventory is not None:
            raise RecordError(
                f"{where}: both units (quantity/unit) and an inventory were "
                "given; pass units if the samples are already physical, an "
                "inventory if they are counts, not both"
            )
        if sensitivity is not None:
            return Record(data=np.asarray(tr.data, dtype=float) / sensitivity * si_factor(q, unit), quantity=q,
                          history=(read_note, f"counts divided by the stated sensitivity {sensitivity:g} counts per "
                                              f"{unit} ({q.value}, flat response)"), **common)
        if _is_counts(tr) and getattr(tr.stats, "response", None) is None:
            raise RecordError(
                f"{where}: the samples of {tr.id} are the instrument's output (counts or volts, as its header or "
                f"integer samples say), so declaring them {q.value} in {unit} would not make them physical; give "
                "the instrument response "
                "(inventory: StationXML, RESP or dataless SEED; --inventory on the command line) or the "
                f"recording chain's sensitivity in counts (or volts) per {unit} (--sensitivity)")
        return Record(data=tr.data * si_factor(q, unit), quantity=q,
                      history=(read_note, f"{q.value} in {unit} as stated by the caller"),
                      **common)

    resp = _find_response(tr, where, inventory)
    if response.output == "native":
        units = (resp.instrument_sensitivity.input_units
                 if resp.instrument_sensitivity is not None else None)
        if units is None and resp.response_stages:
            units = resp.response_stages[0].input_units
        native = _NATIVE_UNITS.get(str(units).upper().replace(" ", ""))
        if native is None:
            raise RecordError(
                f"{where}: the response of {tr.id} has input units {units!r}, "
                "which is not ground motion (M, M/S or M/S**2); choose a "
                "seismometer or accelerometer channel"
            )
        out_q = native
    else:
        out_q = parse_quantity(response.output)
    try:
        tr.stats.response = resp
        tr.remove_response(output=_OBSPY_OUTPUT[out_q],
                           water_level=response.water_level,
                           pre_filt=response.pre_filt)
    except Exception as exc:
        raise RecordError(
            f"{where}: removing the response of {tr.id} failed ({exc}); "
            "check the inventory matches the record"
        ) from exc
    _check_finite(tr.data, f"{where} ({tr.id}, after response removal)")
    sens = getattr(resp.instrument_sensitivity, "value", None)
    note = (f"removed instrument response to {_OBSPY_OUTPUT[out_q]} "
            f"(overall sensitivity {sens if sens is None else format(sens, '.4g')}, "
            f"water_level={response.water_level}, pre_filt={response.pre_filt})")
    return Record(data=tr.data, quantity=out_q, response_removed=True,
                  history=(read_note, note), **common)


def _find_response(tr: obspy.Trace, where: str,
                   inventory: obspy.Inventory | PathLike | None) -> obspy.core.inventory.Response:
    if inventory is not None:
        import obspy

        if not isinstance(inventory, obspy.Inventory):
            try:
                inventory = obspy.read_inventory(str(inventory))
            except Exception as exc:
                raise RecordError(
                    f"cannot read inventory {inventory!s} ({exc}); give a "
                    "StationXML, RESP or dataless SEED file or an obspy Inventory"
                ) from exc
        try:
            return inventory.get_response(tr.id, tr.stats.starttime)
        except Exception as exc:
            raise RecordError(
                f"{where}: the inventory has no response for {tr.id} at "
                f"{tr.stats.starttime} ({exc}); use station metadata that cover "
                "this channel and time"
            ) from exc
    resp = getattr(tr.stats, "response", None)
    if resp is not None:
        return resp
    raise RecordError(
        f"{where}: {tr.id} has no instrument response and no stated units, so "
        "its samples (usually counts) have no physical meaning; give the "
        "response (inventory=, --inventory: StationXML, RESP or dataless SEED) "
        "or the sensitivity (sensitivity= with quantity= and unit=, --sensitivity "
        "--quantity --unit), or quantity= and unit= if the samples are already physical"
    )
