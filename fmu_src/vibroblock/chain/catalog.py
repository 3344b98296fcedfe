"""The chain's event catalogue: its columns, the magnitude, and the CSV file the runner
appends closed events to (the harness reads it: ``harness.chain.catalog``)."""
from __future__ import annotations

import math
from pathlib import Path

from ..settings import ModelError

COLUMNS = ("t_start", "t_end", "first_block", "n_blocks", "potency", "peak_slip_speed")
FILE_COLUMNS = (*COLUMNS, "magnitude")


def magnitude(potency: float) -> float:
    """(2/3) log10(potency): a moment magnitude up to its constant, the potency (sum of
    the blocks' slips, in delta_0) standing for the moment in these units; NaN for none."""
    return (2.0 / 3.0) * math.log10(potency) if potency > 0.0 else math.nan


class CatalogFile:
    """A CSV file of closed events: comment lines stating the thresholds, a header, then
    one row per event, flushed as the events close."""

    def __init__(self, path: str | Path):
        self.path = Path(path)

    def begin(self, thresholds: str) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with self.path.open("w") as out:
                out.write(f"# vibroblock BlockChain event catalogue; {thresholds}\n")
                out.write(",".join(FILE_COLUMNS) + "\n")
        except OSError as exc:
            raise ModelError(f"cannot write the event catalogue {str(self.path)!r}: {exc.strerror}") from None

    def append(self, events) -> None:
        try:
            with self.path.open("a") as out:
                for t_start, t_end, first, blocks, potency, peak in events:
                    out.write(f"{t_start!r},{t_end!r},{int(first) + 1},{int(blocks)},{potency!r},{peak!r},"
                              f"{magnitude(potency)!r}\n")
        except OSError as exc:
            raise ModelError(f"cannot append to the event catalogue {str(self.path)!r}: {exc.strerror}") from None
