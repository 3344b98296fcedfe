"""Runs of the BlockChain FMU through fmpy: with its own drive or with a plate motion
(a record, bursts: :func:`harness.ground.excitation.plate_input`), its catalogue read back.

Example::

    from harness.chain.run import simulate_chain
    result, events = simulate_chain("build/fmus/BlockChain.fmu", stop_time=2e5, step_size=50.0,
                                    catalog="out/chain.csv", start_values={"mu_s_spread": 0.2})
    print(len(events), b_value(events.magnitude))
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..ground.excitation import simulate_block
from .catalog import read_catalog

AGGREGATES = ("mean_slip_velocity", "moment_rate", "slipping_fraction", "event_count", "last_event_potency",
              "coulomb_resets")


def simulate_chain(fmu: str | os.PathLike, *, stop_time: float, step_size: float, catalog: str | os.PathLike,
                   start_values: dict | None = None, plate: np.ndarray | None = None, outputs=AGGREGATES):
    """Run the chain to ``stop_time`` with communication step ``step_size``, its events
    written to ``catalog``; ``plate``: an fmpy input table of plate_z, plate_v, plate_a on
    that step (else the FMU's own drive, A and omega).  Returns (fmpy result, catalogue
    frame)."""
    from fmpy import simulate_fmu

    catalog = Path(catalog)
    values = {**dict(start_values or {}), "catalog_file": str(catalog.resolve())}
    if plate is None:
        result = simulate_fmu(str(fmu), stop_time=stop_time, output_interval=step_size, start_values=values,
                              output=list(outputs))
    else:
        result = simulate_block(fmu, plate, start_values=values, outputs=outputs, stop_time=stop_time)
    return result, read_catalog(catalog)
