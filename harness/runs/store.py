"""Durable, resumable sweep results: one small JSON file per finished point.

Format
------
A store is a folder::

    <store>/store.json                 {"format": "vibroblock-point-store", "version": 1}
    <store>/points/<key>.json          one finished point
    <store>/sweeps/<sweep key>.json    the inputs of each sweep run against the store

A point file holds ``{"key", "inputs", "observables", "elapsed_s"}``.  ``inputs`` is
everything the result depends on: the FMU file's sha256 and model name, every FMU
parameter value as used (defaults filled in), integrator, dt, initial condition,
horizon, output interval, start time, the observable settings and the harness's
observables version.  ``key`` is the sha256 of the canonical JSON of ``inputs``, so a
changed FMU (another sha256) or any changed setting gives other keys: old points are
never picked up for new inputs; they stay in the store for the inputs they belong to.
A file whose stored inputs differ from those its key was asked for raises
:class:`StoreMismatch` rather than being used.

Why files and not a database: each point is written exactly once, by the one process
that drives the sweep, as its result arrives; writing to a temporary file in the same
folder, flushing it to disk and renaming it over the final name makes each point
all-or-nothing, so a sweep killed at any instant (SIGKILL included) leaves only whole
points, and the next run computes exactly the missing ones.  The files are readable
with any JSON tool, and stores merge by copying folders.  Floats are written with
Python's shortest exact repr, so a reloaded point equals the computed one bit for bit.
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
import time
import warnings
from pathlib import Path
from typing import Iterable, Mapping

from .settings import canonical_json

STORE_FORMAT = {"format": "vibroblock-point-store", "version": 1}


class StoreMismatch(RuntimeError):
    """A stored point does not belong to the inputs it was looked up for."""


def point_key(inputs: Mapping) -> str:
    return hashlib.sha256(canonical_json(inputs).encode()).hexdigest()


def write_json_atomically(path: Path, payload) -> None:
    """Write JSON so that ``path`` holds either nothing or the complete document."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as stream:
            json.dump(payload, stream, sort_keys=True, allow_nan=True)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(tmp_name, path)
    except BaseException:
        if os.path.exists(tmp_name):
            os.unlink(tmp_name)
        raise
    # The rename itself must reach the disk for the point to survive a power cut.
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)
    finally:
        os.close(directory)


class PointStore:
    """A folder of finished points (see module doc)."""

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root)
        self.points = self.root / "points"
        self.sweeps = self.root / "sweeps"
        marker = self.root / "store.json"
        # The folder's contents are listed before the marker is looked for: a store writes
        # its marker before anything else, so a folder seen with contents and then found
        # without a marker is not a store, even while another thread or process is
        # creating this one (its marker, then its folders).
        contents = [p for p in self.root.iterdir() if not p.name.startswith(".")] if self.root.exists() else []
        if marker.is_file():
            found = json.loads(marker.read_text())
            if found != STORE_FORMAT:
                raise StoreMismatch(f"{self.root} is a store of format {found}, this harness reads {STORE_FORMAT}")
        elif contents:
            raise StoreMismatch(f"{self.root} exists and is not a point store; choose an empty or new folder")
        else:
            write_json_atomically(marker, STORE_FORMAT)
        self.points.mkdir(parents=True, exist_ok=True)
        self.sweeps.mkdir(parents=True, exist_ok=True)

    def path(self, key: str) -> Path:
        return self.points / f"{key}.json"

    def load(self, key: str, inputs: Mapping) -> dict | None:
        """The stored observables of a point, or None if it has not been computed.

        A point file that cannot be read (truncated or damaged: e.g. written by a tool
        without the atomic rename) is moved aside to ``points/damaged/`` with a warning,
        and the point counts as not computed, so it is computed again."""
        path = self.path(key)
        if not path.is_file():
            return None
        try:
            record = json.loads(path.read_text())
            record["observables"]
        except (OSError, ValueError, KeyError, TypeError) as exc:
            damaged = self.points / "damaged"
            damaged.mkdir(exist_ok=True)
            target = damaged / f"{key}.{int(time.time() * 1e6)}.json"
            path.replace(target)
            warnings.warn(f"point file {path} is damaged ({type(exc).__name__}: {exc}); moved to {target} and "
                          "computed again", RuntimeWarning, stacklevel=2)
            return None
        if record.get("inputs") != json.loads(canonical_json(inputs)):
            raise StoreMismatch(f"{path} holds a point for other inputs than those of key {key}; "
                                "the store was edited by hand or a key collided: remove the file")
        return record["observables"]

    def save(self, key: str, inputs: Mapping, observables: Mapping, elapsed_s: float) -> None:
        write_json_atomically(self.path(key), {"key": key, "inputs": json.loads(canonical_json(inputs)),
                                               "observables": dict(observables), "elapsed_s": elapsed_s})

    def keys(self) -> set[str]:
        return {p.stem for p in self.points.glob("*.json")}

    def record_sweep(self, description: Mapping) -> str:
        """Keep the inputs of a sweep (grid and shared settings); returns its key."""
        key = point_key(description)
        path = self.sweeps / f"{key}.json"
        if not path.is_file():
            write_json_atomically(path, json.loads(canonical_json(description)))
        return key

    def missing(self, keys: Iterable[str]) -> list[str]:
        present = self.keys()
        return [k for k in keys if k not in present]
