"""Fixtures of the harness tests (runs, sweeps, stores, continuation).

The FMU comes from the session's fresh build of the working tree (``fmu_dir`` in
tests/conftest.py), so a rebuild of build/fmus while the tests run cannot swap the FMU
(and its physics core) under them.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def fmu_a(fmu_dir) -> Path:
    return Path(fmu_dir) / "BlockA.fmu"


@pytest.fixture
def subprocess_env() -> dict:
    """Environment for harness processes started by a test (same compiled-kernel cache)."""
    env = dict(os.environ)
    env["NUMBA_CACHE_DIR"] = os.environ["NUMBA_CACHE_DIR"]
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), env.get("PYTHONPATH")]))
    return env


@pytest.fixture(scope="module")
def quick_fmus(tmp_path_factory):
    """BlockA.fmu and Excitation.fmu of the working tree, without shipped kernels."""
    import build_fmus

    dest = tmp_path_factory.mktemp("quick_fmus")
    for name in ("BlockA", "Excitation"):
        build_fmus.build(name, dest, ship_kernels=False)
    return dest
