"""The closed forms in ``vibroblock.orbits``, and that importing them has no side effects."""
import json
import subprocess
import sys

import numpy as np
import pytest

from vibroblock.orbits import detachment_amplitude, friction_loss_amplitude, steady_orbit


def test_importing_the_formulas_loads_no_compiler_and_changes_no_setting():
    code = ("import os, sys, json; before = dict(os.environ); import vibroblock; from vibroblock import orbits, "
            "parameters; vibroblock.steady_orbit; print(json.dumps({'numba': 'numba' in sys.modules, "
            "'env_changed': dict(os.environ) != before}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(out.stdout) == {"numba": False, "env_changed": False}


def test_the_steady_orbit_solves_the_driven_oscillator():
    m, k_n, gamma_n, weight, amplitude, omega = 1.3, 2.0, 0.1, 0.7, 0.4, 0.9
    phases = np.linspace(0.0, 2 * np.pi, 9)
    h = 1e-5
    for phase in phases:
        y, v = steady_orbit(m, k_n, gamma_n, weight, amplitude, omega, phase)
        y1, v1 = steady_orbit(m, k_n, gamma_n, weight, amplitude, omega, phase + omega * h)
        y0, v0 = steady_orbit(m, k_n, gamma_n, weight, amplitude, omega, phase - omega * h)
        assert (y1 - y0) / (2 * h) == pytest.approx(v, abs=1e-8)
        accel = (v1 - v0) / (2 * h)
        # m y'' + gamma_n y' + k_n y = -W + m A omega^2 sin(theta)
        assert m * accel + gamma_n * v + k_n * y == pytest.approx(-weight + m * amplitude * omega**2 * np.sin(phase),
                                                                   abs=1e-7)


def test_detachment_amplitude_is_where_the_orbit_reaches_zero_penetration():
    for omega in (0.3, 1.0, 3.0):
        a_c = float(detachment_amplitude(omega))
        deepest = max(steady_orbit(1.0, 1.0, 0.07, 1.0, a_c, omega, p)[0] for p in np.linspace(0, 2 * np.pi, 20001))
        assert deepest == pytest.approx(0.0, abs=1e-7)


def test_friction_is_lost_before_contact_and_by_sqrt2_at_kn_over_gamma():
    omegas = np.geomspace(0.05, 100.0, 50)
    assert np.all(friction_loss_amplitude(omegas) < detachment_amplitude(omegas))
    ratio = friction_loss_amplitude(1.0 / 0.07) / detachment_amplitude(1.0 / 0.07)
    assert ratio == pytest.approx(1 / np.sqrt(2), rel=1e-12)
    # At A_N the steady orbit's normal force k_n delta - gamma_n u_n just reaches zero.
    omega = 2.0
    a_n = float(friction_loss_amplitude(omega))
    normal = [-(y * 1.0) - 0.07 * v for y, v in (steady_orbit(1.0, 1.0, 0.07, 1.0, a_n, omega, p)
                                                 for p in np.linspace(0, 2 * np.pi, 20001))]
    assert min(normal) == pytest.approx(0.0, abs=1e-6)


def test_an_undamped_contact_driven_at_its_resonance_has_no_steady_orbit_and_says_so():
    """m y'' + k_n y = m A omega^2 sin(theta) at omega^2 = k_n / m grows without bound: the
    formula refuses it, and a run asked to start on that orbit is refused with a message
    that names the way out, instead of failing on a division by zero."""
    from vibroblock import Block, ModelError
    from vibroblock.orbits import orbit_response

    with pytest.raises(ValueError, match="resonance"):
        orbit_response(1.0, 4.0, 0.0, 0.5, 2.0)
    assert orbit_response(1.0, 4.0, 0.0, 0.0, 2.0) == 0.0  # no drive, no orbit to grow
    assert abs(orbit_response(1.0, 4.0, 1e-9, 0.5, 2.0)) > 1e8  # damped: finite, huge
    for model in "AC":
        block = Block(model, "adaptive", initial_state=2, gamma_n=0.0, A=2.0, omega=1.0)
        with pytest.raises(ModelError, match=r"no steady in-contact orbit.*initial_state = 0 or 1"):
            block.start()
    # event_driven's closed-form contact flow has the same denominator: refused up front.
    block = Block("A", "event_driven", initial_state=0, gamma_n=0.0, A=2.0, omega=1.0)
    with pytest.raises(ModelError, match=r"undamped contact .* resonance .* use adaptive"):
        block.start()
    # adaptive integrates it from rest: finite, and the energy balance closes.
    block = Block("A", "adaptive", initial_state=0, gamma_n=0.0, A=2.0, omega=1.0, energy_balance=True)
    block.start()
    block.advance_to(1e3)
    out = block.outputs()
    assert all(np.isfinite(float(value)) for value in out.values()), out
    assert abs(out["energy_residual"]) < 1e-4 * (out["energy_dissipated"] + abs(out["work_input"]))
