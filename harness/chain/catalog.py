"""Event catalogues of the BlockChain FMU: the CSV it writes, as a pandas frame or an
obspy ``Catalog``.

The file's first line states the thresholds that made it (an event starts when a block's
slip speed exceeds v_start and ends when every block is below v_stop); ``read_catalog``
keeps that line in ``frame.attrs["thresholds"]``.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

COLUMNS = ("t_start", "t_end", "first_block", "n_blocks", "potency", "peak_slip_speed", "magnitude")


class CatalogError(ValueError):
    """A file that is not a BlockChain event catalogue."""


def read_catalog(path: str | Path) -> pd.DataFrame:
    """The catalogue at ``path``: one row per event, the columns of ``COLUMNS`` (times in
    tau_0, first block 1-based, potency in delta_0), ``attrs["thresholds"]`` its first line."""
    path = Path(path)
    try:
        first = path.open().readline()
    except OSError as exc:
        raise CatalogError(f"cannot read the event catalogue {str(path)!r}: {exc.strerror}") from None
    if not first.startswith("# vibroblock BlockChain event catalogue"):
        raise CatalogError(f"{str(path)!r} is not a BlockChain event catalogue (its first line: {first.strip()!r})")
    frame = pd.read_csv(path, comment="#")
    missing = [column for column in COLUMNS if column not in frame.columns]
    if missing:
        raise CatalogError(f"{str(path)!r} lacks the columns {missing}")
    frame.attrs["thresholds"] = first.lstrip("# ").strip()
    return frame


def to_obspy(frame: pd.DataFrame, origin: str = "2000-01-01T00:00:00", seconds_per_tau: float = 1.0):
    """The catalogue as an obspy ``Catalog``: one ``Event`` per row, its origin time
    ``origin`` + t_start * ``seconds_per_tau``, its magnitude (type "Mp": the potency
    magnitude (2/3) log10(potency)) and the first block as the origin's comment."""
    from obspy import UTCDateTime
    from obspy.core.event import Catalog, Comment, Event, Magnitude, Origin

    zero, catalog = UTCDateTime(origin), Catalog(description=frame.attrs.get("thresholds", "BlockChain events"))
    for row in frame.itertuples(index=False):
        event = Event(event_type="earthquake")
        origin_ = Origin(time=zero + row.t_start * seconds_per_tau, latitude=0.0, longitude=0.0,
                         comments=[Comment(text=f"first block {int(row.first_block)}, {int(row.n_blocks)} blocks")])
        event.origins.append(origin_)
        event.magnitudes.append(Magnitude(mag=float(row.magnitude), magnitude_type="Mp",
                                          origin_id=origin_.resource_id))
        catalog.append(event)
    return catalog
