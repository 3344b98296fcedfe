"""Shared fixtures for the record ingest tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest


@dataclass(frozen=True)
class AnalyticMotion:
    """A Hann-windowed sinusoidal displacement and its exact derivatives.

    z(t) = D sin²(π s) sin(ω (t - t0)),  s = (t - t0)/Tw  for t0 <= t <= t0 + Tw,
    zero outside, so z, v and a all start and end at zero.
    """

    t: np.ndarray
    a: np.ndarray
    v: np.ndarray
    z: np.ndarray
    dt: float
    omega: float


def make_analytic(dt: float = 0.005, duration: float = 20.0, t0: float = 5.0,
                  window: float = 10.0, freq: float = 2.0, amp: float = 1e-3) -> AnalyticMotion:
    t = np.arange(int(round(duration / dt)) + 1) * dt
    s = np.clip((t - t0) / window, 0.0, 1.0)
    inside = (t >= t0) & (t <= t0 + window)
    w = np.sin(np.pi * s) ** 2
    w1 = np.pi / window * np.sin(2 * np.pi * s)
    w2 = 2 * (np.pi / window) ** 2 * np.cos(2 * np.pi * s)
    om = 2 * np.pi * freq
    ph = om * (t - t0)
    sn, cs = np.sin(ph), np.cos(ph)
    z = amp * w * sn
    v = amp * (w1 * sn + w * om * cs)
    a = amp * (w2 * sn + 2 * w1 * om * cs - w * om**2 * sn)
    z, v, a = (np.where(inside, x, 0.0) for x in (z, v, a))
    return AnalyticMotion(t=t, a=a, v=v, z=z, dt=dt, omega=om)


@pytest.fixture
def analytic() -> AnalyticMotion:
    """The default analytic motion (2 Hz, 10 s window in 20 s, dt = 5 ms)."""
    return make_analytic()


@pytest.fixture(name="make_analytic")
def make_analytic_fixture():
    """The factory :func:`make_analytic`, for tests that vary its parameters."""
    return make_analytic
