"""Shared fixtures: FMUs built from the current sources, once per test session."""
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Compiled kernels are shared with the Makefile's runs (same folder) unless set otherwise.
os.environ.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".cache" / "numba"))
sys.path.insert(0, str(ROOT / "build"))
# Shared test helpers (tests/fmu_testing.py); test folders mirror the source tree, so
# they are imported by path (--import-mode=importlib) rather than put on sys.path.
sys.path.insert(0, str(Path(__file__).resolve().parent))

# Tests run plain pythonfmu FMUs (built without the project's front end) through fmpy in
# this process; their library would corrupt the heap at exit (harness/cosim/exit_guard.py).
from harness.cosim import exit_guard  # noqa: E402

exit_guard.install()


@pytest.fixture(scope="session", autouse=True)
def kernels_compiled_by_the_build():
    """The build compiles every integrator's kernels once (build/kernels.py: one numba
    cache per integrator, the FMUs ship their defaults'); the tests' own cache starts from
    all of them instead of compiling them again."""
    import kernels
    from vibroblock import jitcache

    folder = kernels.kept_kernels(ROOT / "fmu_src" / "vibroblock")
    if folder is not None:
        for job in sorted(path for path in folder.iterdir() if path.is_dir()):
            jitcache.seed_cache(job)


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory):
    """BlockA/B/C.fmu built from the working tree into a fresh folder."""
    import build_fmus

    dest = tmp_path_factory.mktemp("fmus")
    for name in build_fmus.fmu_names():
        build_fmus.build(name, dest)
    return dest


@pytest.fixture(scope="session")
def fmu_path(fmu_dir):
    return lambda model: str(fmu_dir / f"Block{model}.fmu")
