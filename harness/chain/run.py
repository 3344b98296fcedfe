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

# Carlson and Langer's standard parameters (l = 10, alpha = 2.5, sigma = 0.01, nu = 0.01;
# Carlson, Langer and Shaw, Rev. Mod. Phys. 66, 657, 1994) in the chain's units
# (docs/chain.md): mu_k = (1 - sigma) mu_s, v_w = (1 - sigma) v_1 / (2 alpha) and
# V_d = nu v_1 with the velocity unit v_1 = mu_s m g omega_p / k_p = 5; the chain's
# k_c = 1, k_p = 1e-2 give l^2 = 100.  gamma_t = 0.2 damps the ringing of a re-stuck
# block within a few tau_0; mu_s spread by 5 %.
CARLSON_LANGER = {"friction_law": 2, "mu_k": 0.495, "v_w": 0.99, "V_d": 0.05, "gamma_t": 0.2, "mu_s_spread": 0.05,
                  "seed": 1}

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
