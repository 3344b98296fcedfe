"""A block on a plate that moves like the ground in a record: read, process, scale, run, plot.

    python examples/record_response.py RECORD_FILE [--format MSEED] [--inventory station.xml]
        [--sensitivity COUNTS_PER_UNIT --quantity velocity --unit m/s] [--peak-g 0.5]
        [--time-stretch 1] [--model A] [--integrator adaptive] [--out out]

The same as ``vibroblock record`` (harness/ground/record_run.py).  The record (any format
obspy reads, with the instrument response removed through ``--inventory`` or a stated
``--sensitivity``; PEER ``.AT2``; or two-column time/value text with ``--quantity`` and
``--unit``) is processed to consistent ground acceleration, velocity and displacement,
optionally rescaled to a peak acceleration of ``--peak-g`` times the block's gravity,
and converted to the block's units for a 1 kg block on a 1e5 N/m contact (delta_0 =
98 um, tau_0 = 3.2 ms; change with ``--mass``, ``--stiffness``).  ``--time-stretch``
plays the record that many times slower.  The Block FMU (model A: scaled stick-slip set)
runs with the plate motion as fmpy input, evaluated exactly at each communication point.
Prints what each number means and saves out/record_response.png (model time in tau_0
below, the record's seconds on top).  A record in counts without a response or a
sensitivity is refused with one line saying how to give them.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_experiment(record_file, *, show_plot=False, **settings):
    """Run the block on ``record_file`` (keywords: harness.ground.record_run.RecordRun's fields)."""
    from harness.ground.record_run import RecordRun, run_record

    return run_record(RecordRun(record_file=str(record_file), **settings), show_plot=show_plot)


def main(argv=None) -> int:
    from harness.ground.record_run import add_arguments, run_record, settings_from
    from harness.user_errors import run_main

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(parser)
    args = parser.parse_args(argv)
    return run_main("record_response.py", lambda: run_record(settings_from(args)) and 0)


if __name__ == "__main__":
    sys.exit(main())
