"""The main job: every claim study, the paper's figures and ``out/report.md``.

    python -m harness.main [--quick] [--scheduler ADDRESS] [--workers N] [--out out]

Runs the studies of :mod:`harness.paper.claims` on a Dask LocalCluster (or the scheduler
given), persisting every sweep point and task under ``<out>/store`` so an interrupted
job resumes where it stopped; draws the figures; writes the measured values
(``<out>/claims.json``) and the report (``<out>/report.md``).  The claims the readings of
the paper's equations can change (C2, C5-C8) are measured under each reading
(:mod:`harness.paper.claims.readings`) unless ``--default-reading-only``, and under the
law readings beside them (the load-only bound, the non-conservative and the no-pull
contacts; C6 there measures Fig. 5's diagram) unless ``--no-laws``.  ``--quick`` is a
few-minute version at a coarser resolution.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from harness.paper.claims import RESOLUTIONS, Runner, StudiesFailed, run_studies, save_studies
from harness.paper.claims.study import CORRUGATED_INTEGRATION, CORRUGATED_TOLERANCES, MODEL_A_INTEGRATOR
from harness.cosim.fmu import REPO_ROOT
from harness.paper.report import timing_lines, write_report
from harness.runs.sweep import INLINE, Execution, close_client, open_client

def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(prog="python -m harness.main", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="coarse one-minute version")
    parser.add_argument("--resolution", choices=sorted(RESOLUTIONS), help="explicit resolution (overrides --quick)")
    parser.add_argument("--scheduler", help="address of an existing Dask scheduler, or 'inline' (no Dask)")
    parser.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "out", help="folder of figures, store and report")
    parser.add_argument("--fmu-dir", type=Path, help="folder holding BlockA/B/C.fmu (default: build/fmus)")
    parser.add_argument("--default-reading-only", action="store_true",
                        help="measure C2 and C5-C8 under the default reading only, not under each reading of the "
                             "paper's equations (formulation x Coulomb bound)")
    parser.add_argument("--no-laws", action="store_true",
                        help="skip the law readings: C2 and C5-C8 under the load-only Coulomb bound and the "
                             "linear_along_normal and linear_no_pull contacts (C6: Fig. 5's diagram) "
                             "(harness.paper.claims.readings.LAW_READINGS)")
    parser.add_argument("--ensembles-every-reading", action="store_true",
                        help="run C6's start-phase ensemble under every reading, not only the default one (beyond "
                             "the default job's time budget)")
    parser.add_argument("--no-progress", action="store_true")
    parser.add_argument("--report-only", action="store_true", help="redraw figures and report from <out>/claims.json")
    args = parser.parse_args(argv)

    resolution = RESOLUTIONS[args.resolution or ("quick" if args.quick else "default")]
    os.environ.setdefault("NUMBA_CACHE_DIR", str(REPO_ROOT / ".cache" / "numba"))
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    execution = Execution(scheduler=args.scheduler, workers=args.workers, progress=not args.no_progress)
    started = time.perf_counter()
    if args.report_only:
        from harness.paper.claims import load_studies

        studies = load_studies(out / "claims.json")
        path = write_report(studies, out, (), {"resolution": "from claims.json"})
        print(f"report: {path}")
        return path
    client = None if args.scheduler == INLINE else open_client(execution)
    try:
        fmus = {m: args.fmu_dir / f"Block{m}.fmu" for m in "ABC"} if args.fmu_dir else None
        runner = Runner(out / "store", resolution, execution, client, fmus)
        runner.ensembles_every_reading = args.ensembles_every_reading
        studies = run_studies(runner, progress=not args.no_progress, readings=not args.default_reading_only,
                              laws=not args.no_laws)
    except StudiesFailed as exc:
        raise SystemExit(f"python -m harness.main: {exc}") from exc
    finally:
        if client is not None:
            close_client(client)
    save_studies(studies, out / "claims.json")
    elapsed = time.perf_counter() - started
    header = {"resolution": resolution.name, "points computed / reused from the store":
              f"{runner.points_computed} / {runner.points_reused}", "wall time": f"{elapsed:.0f} s",
              "compute time (summed over the workers)": f"{runner.compute_time:.0f} s",
              "integrators": f"model A {MODEL_A_INTEGRATOR} (symplectic_euler under the applied-load bound, which "
                             f"it does not offer), models B and C {CORRUGATED_INTEGRATION.describe()} (adaptive: "
                             + ", ".join(f"{k} {v:g}" for k, v in CORRUGATED_TOLERANCES.items())
                             + "; symplectic_euler: dt = 4e-4), unless a study says otherwise",
              "measured values": "claims.json"}
    path = write_report(studies, out, (), header)
    for line in timing_lines(studies):
        print(line)
    print(f"report: {path}  ({elapsed:.0f} s, resolution {resolution.name})")
    return path


if __name__ == "__main__":
    main(sys.argv[1:])
