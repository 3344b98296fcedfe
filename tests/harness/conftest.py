"""Shared fixtures of the harness tests (runs, sweeps, stores, continuation)."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
# FMU instances in this process and in the workers it starts load compiled kernels from here.
os.environ.setdefault("NUMBA_CACHE_DIR", str(REPO / ".cache" / "numba"))


@pytest.fixture(scope="session")
def fmu_a() -> Path:
    path = REPO / "build" / "fmus" / "BlockA.fmu"
    if not path.is_file():
        pytest.fail(f"{path} is missing: build the FMUs first (make fmus)")
    return path


@pytest.fixture
def subprocess_env() -> dict:
    """Environment for harness processes started by a test."""
    env = dict(os.environ)
    env["NUMBA_CACHE_DIR"] = os.environ["NUMBA_CACHE_DIR"]
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), env.get("PYTHONPATH")]))
    return env
