"""Three-component records: the vertical ground motion and the horizontal one along a slip azimuth.

A block shaken by the ground feels the vertical component (the plate's height) and the
horizontal component along its slip direction (+x, the drive spring's direction); the
perpendicular horizontal component does not enter a model in the x-z plane.  With the
slip direction at ``azimuth`` degrees clockwise from north::

    horizontal(t) = N(t) cos(azimuth) + E(t) sin(azimuth)

Each channel is read and processed on its own, exactly as a single channel is
(:func:`~.processing.load_ground_motion`: instrument response removed with the
inventory, band-pass, integration, baseline correction), with the same settings; the
processing is linear, so rotating the processed north and east motions is rotating the
ground's.  Channels named ``..1`` and ``..2`` (a sensor not aligned with north and east)
are first rotated to north and east with obspy's ``Stream.rotate("->ZNE")`` from the
orientations in the inventory.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .errors import RecordError
from .processing import GroundMotion, ProcessingSettings, load_ground_motion


def load_ground_motion_components(source, azimuth: float, settings: ProcessingSettings | None = None,
                                  **read_kwargs) -> tuple[GroundMotion, GroundMotion]:
    """The processed vertical motion and the horizontal motion along ``azimuth`` (degrees
    clockwise from north) of a three-component record (a file obspy reads, or a
    ``Stream``), in SI units.  ``read_kwargs`` go to :func:`~.readers.read_record` for
    every channel (``inventory``, ``format``, ``quantity`` and ``unit``, ...); a
    ``trace_id`` pattern picks the station and band (e.g. ``"BW.RJOB..EH?"``) where the
    file holds several."""
    if not math.isfinite(azimuth):
        raise RecordError(f"azimuth = {azimuth!r} must be a finite number of degrees clockwise from north")
    stream = _stream(source, read_kwargs.get("format"))
    pattern = read_kwargs.pop("trace_id", None)
    if pattern:
        stream = stream.select(id=pattern)
    where = str(source) if not hasattr(source, "traces") else "<obspy stream>"
    ids = sorted({trace.id for trace in stream})
    verticals = [i for i in ids if i.endswith("Z")]
    if len(verticals) != 1:
        raise RecordError(f"{where}: a three-component record needs one vertical channel (..Z) among "
                          f"{', '.join(ids) or 'none'}; pick the station and band with a trace_id pattern such as "
                          "'NET.STA.LOC.HH?'")
    prefix = verticals[0][:-1]
    own = {i[-1]: i for i in ids if i.startswith(prefix)}
    pair = ("N", "E") if {"N", "E"} <= set(own) else ("1", "2") if {"1", "2"} <= set(own) else None
    if pair is None:
        raise RecordError(f"{where}: {verticals[0]} has no horizontal pair (..N and ..E, or ..1 and ..2) beside "
                          f"it among {', '.join(ids)}")
    motions = {axis: load_ground_motion(stream, settings, trace_id=own[axis], **read_kwargs)
               for axis in ("Z", *pair)}
    vertical, first, second = (motions[axis] for axis in ("Z", *pair))
    for other in (first, second):
        if other.time.size != vertical.time.size or not np.allclose(other.time, vertical.time, rtol=0,
                                                                    atol=1e-9 * vertical.dt):
            raise RecordError(f"{where}: the channels of {prefix}? differ in sampling or start; cut them to one "
                              "common window first")
    azimuths = (0.0, 90.0) if pair == ("N", "E") else _azimuths(stream, [own[a] for a in pair], where,
                                                                  read_kwargs.get("inventory"))
    # Channel i records the motion along its azimuth: (c_i, s_i) . (N, E).  Solve for (N, E),
    # then project on the slip azimuth.
    rows = np.array([[math.cos(math.radians(a)), math.sin(math.radians(a))] for a in azimuths])
    if abs(np.linalg.det(rows)) < 1e-3:
        raise RecordError(f"{where}: the horizontal channels {own[pair[0]]} and {own[pair[1]]} point along the same "
                          f"line (azimuths {azimuths[0]:g} and {azimuths[1]:g} degrees)")
    target = np.array([math.cos(math.radians(azimuth)), math.sin(math.radians(azimuth))])
    weights = np.linalg.solve(rows.T, target)  # horizontal = w_1 channel_1 + w_2 channel_2
    horizontal = replace(
        first, **{q: weights[0] * getattr(first, q) + weights[1] * getattr(second, q)
                  for q in ("acceleration", "velocity", "displacement")},
        trace_id=f"{prefix}{pair[0]},{pair[1]} at azimuth {azimuth:g}",
        history=(*first.history, f"combined with {own[pair[1]]} (azimuths {azimuths[0]:g}, {azimuths[1]:g} "
                                 f"degrees) into the motion along the azimuth {azimuth:g} degrees"))
    return vertical, horizontal


def _stream(source, fmt):
    import obspy

    if isinstance(source, obspy.Stream):
        return source.copy()
    if isinstance(source, obspy.Trace):
        return obspy.Stream([source.copy()])
    from .readers import _obspy_read
    from pathlib import Path

    path = Path(source)
    if not path.is_file():
        raise RecordError(f"{path}: no such file; check the path")
    return _obspy_read(path, fmt)


def _azimuths(stream, ids, where: str, inventory) -> tuple[float, float]:
    """The azimuths (degrees clockwise from north) of horizontal channels named ..1, ..2,
    from the inventory (their names do not say where they point)."""
    if inventory is None:
        raise RecordError(f"{where}: horizontal channels ..1 and ..2 need the inventory (with their azimuth and dip) "
                          "to say where they point")
    import obspy

    if not isinstance(inventory, obspy.Inventory):
        inventory = obspy.read_inventory(str(inventory))
    found = []
    for seed_id in ids:
        start = stream.select(id=seed_id)[0].stats.starttime
        try:
            orientation = inventory.get_orientation(seed_id, start)
        except Exception as exc:  # obspy raises several kinds for missing metadata
            raise RecordError(f"{where}: the inventory has no orientation for {seed_id} ({exc})") from None
        if abs(abs(orientation["dip"]) % 180.0) > 1.0:
            raise RecordError(f"{where}: {seed_id} dips {orientation['dip']:g} degrees; horizontal channels are "
                              "needed")
        found.append(float(orientation["azimuth"]))
    return found[0], found[1]
