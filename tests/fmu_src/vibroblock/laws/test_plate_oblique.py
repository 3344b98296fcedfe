"""The oblique plate (plate_motion = 1): horizontal shaking against closed forms and an
independent solve_ivp reference, superposition of an oblique drive where the motion is
linear, the energy balance in the plate's frame, the inputs, and the refusals."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroblock import Block
from vibroblock.block import ModelError

FIXED_STEP = ("symplectic_euler", "rk4", "implicit_contact")
K_T, GAMMA_T, MU_S = 0.28, 5e-3, 0.5
HORIZONTAL = math.pi / 2


def shaken(integrator, amplitude, omega, angle=HORIZONTAL, initial_state=0, energy=False, **parameters):
    """Model A on a plate shaken along ``angle`` from the vertical, no drive spring."""
    settings = dict(k_d=0.0, V_d=0.0, gamma_t=GAMMA_T, A=amplitude, omega=omega, plate_motion=1,
                    drive_angle=angle, dt=1e-3)
    settings.update(parameters)
    block = Block("A", integrator, initial_state, energy, **settings)
    block.start()
    return block


def sampled(block, times, names=("x", "vx", "z", "vz")):
    rows = []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        rows.append([out[name] for name in names])
    return np.array(rows)


def stuck_reference(amplitude, omega, times, k_d=0.0):
    """The block held by its friction spring on a horizontally shaken plate (in contact,
    no reset): in the plate's frame m X'' = -k_t (X - X_0) - gamma_t X' - k_d (X + p_x)
    - m p_x'', p_x = A sin(omega t), from rest on the plate at X_0 = 0; solved by scipy's
    DOP853 at rtol 1e-12 (independent of the kernels).  Returns the lab's x = X + p_x."""
    def rates(t, y):
        x, v = y
        p_x, a_x = amplitude * math.sin(omega * t), -amplitude * omega * omega * math.sin(omega * t)
        return [v, -K_T * x - GAMMA_T * v - k_d * (x + p_x) - a_x]
    solution = solve_ivp(rates, (0.0, times[-1]), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                         t_eval=times)
    return solution.y[0] + amplitude * np.sin(omega * times)


@pytest.mark.parametrize("integrator", FIXED_STEP)
def test_a_block_held_by_friction_moves_with_the_shaken_plate_as_the_closed_form_says(integrator):
    """Below the friction threshold the block rides the plate, displaced from it only by
    its friction spring's compliance: the lab motion matches the reference of the linear
    equations (rk4 and implicit_contact to their accuracy at dt = 1e-3, the first-order
    scheme to its own), the block never resets and stays on the plate vertically."""
    amplitude, omega = 0.05, 0.3
    times = np.arange(1.0, 300.0, 1.0)
    block = shaken(integrator, amplitude, omega)
    got = sampled(block, times, ("x", "z", "coulomb_resets", "contact"))
    want = stuck_reference(amplitude, omega, times)
    tolerance = {"symplectic_euler": 1e-4, "rk4": 1e-9, "implicit_contact": 1e-6}[integrator]
    assert np.max(np.abs(got[:, 0] - want)) < tolerance * amplitude
    # The lab motion is the plate's, plus a relative sway of the spring's compliance.
    relative = got[:, 0] - amplitude * np.sin(omega * times)
    assert 0.1 * amplitude < np.max(np.abs(relative)) < amplitude
    assert got[-1, 2] == 0 and np.all(got[:, 3] == 1)
    assert np.max(np.abs(got[:, 1] + 1.0)) < 1e-12  # at rest penetration delta_0 = m g / k_n throughout


def steady_spring_force(amplitude, omega):
    """|k_t X| of the steady stuck response X'' + gamma_t X' + k_t X = A omega^2 sin(omega t)."""
    return K_T * amplitude * omega ** 2 / abs(complex(K_T - omega ** 2, GAMMA_T * omega))


@pytest.mark.parametrize("integrator", ("symplectic_euler", "rk4"))
def test_the_block_slips_where_the_spring_s_steady_force_reaches_mu_s_m_g(integrator):
    """The friction threshold of horizontal shaking: the steady spring force k_t |X|
    reaches mu_s m g at A_s = mu_s g |k_t - m omega^2 + i gamma_t omega| / (k_t omega^2),
    which for omega^2 << k_t/m is the rigid block's m A omega^2 = mu_s m g.  Started on the
    steady response (no transient), a plate at 0.95 A_s never breaks the spring over
    five periods; at 1.05 A_s it does, within the first period."""
    omega = 0.05
    threshold = MU_S / (steady_spring_force(1.0, omega))  # A_s, with g = m = 1
    rigid = MU_S / omega ** 2
    assert abs(threshold / rigid - 1.0) < 0.01  # (the rigid-block limit, to the spring's amplification)
    period = 2 * math.pi / omega
    for factor, slips in ((0.95, False), (1.05, True)):
        amplitude = factor * threshold
        response = amplitude * omega ** 2 / complex(K_T - omega ** 2, GAMMA_T * omega)  # X = Im(response e^{i w t})
        # On the steady orbit at t = 0 (lab position and velocity); the spring is anchored
        # at the start, which leaves a transient of a fraction ~gamma_t omega / k_t (1e-3).
        x0, v0 = response.imag, (response * 1j * omega).imag
        block = shaken(integrator, amplitude, omega, initial_state=1, x_start=x0, vx_start=v0 + amplitude * omega,
                       z_start=-1.0, vz_start=0.0, dt=4e-3)
        block.advance_to(5 * period if not slips else period)
        assert (block.outputs()["coulomb_resets"] > 0) is slips


@pytest.mark.parametrize("integrator", FIXED_STEP)
def test_an_oblique_drive_is_the_sum_of_its_vertical_and_horizontal_parts_where_the_motion_is_linear(integrator):
    """In contact and held by friction the equations are linear: the response to a drive
    at 30 degrees from the vertical is the response to its vertical part plus that to its
    horizontal part (each less the block at rest), to rounding."""
    amplitude, omega, angle = 0.2, 0.8, math.radians(30)
    times = np.arange(0.5, 100.0, 0.5)
    parts = {}
    for name, (amp, ang) in {"oblique": (amplitude, angle), "vertical": (amplitude * math.cos(angle), 0.0),
                             "horizontal": (amplitude * math.sin(angle), HORIZONTAL),
                             "rest": (0.0, 0.0)}.items():
        parts[name] = sampled(shaken(integrator, amp, omega, ang, initial_state=1, x_start=0.0, z_start=-1.0,
                                     vx_start=0.0, vz_start=0.0), times)
    summed = parts["vertical"] + parts["horizontal"] - parts["rest"]
    assert np.max(np.abs(parts["oblique"] - summed)) < 1e-12
    # and both parts move the block: the sum is not one part alone
    assert np.max(np.abs(parts["horizontal"][:, 0] - parts["rest"][:, 0])) > 0.05
    assert np.max(np.abs(parts["vertical"][:, 2] - parts["rest"][:, 2])) > 0.05


@pytest.mark.parametrize("integrator", ("rk4", "implicit_contact"))
def test_the_energy_balance_closes_in_the_plate_s_frame_through_slips(integrator):
    """Horizontal shaking above the threshold, with the drive spring pulling: resets and
    slips, and the energy balance (kept in the plate's frame, its inertial force booked as
    work) closes to the scheme's accuracy."""
    block = shaken(integrator, 3.0, 0.5, energy=True, k_d=1e-2, V_d=1e-2)
    block.advance_to(300.0)
    out = block.outputs()
    assert out["coulomb_resets"] > 10
    assert abs(out["energy_residual"]) < 1e-6 * out["energy_dissipated"]


def test_the_horizontal_inputs_shake_the_plate_like_its_own_drive():
    """plate_x, plate_vx, plate_ax sampled at each communication point and held over the
    step (constant acceleration) reproduce the internal horizontal drive: the held
    acceleration lags the true one by half a step on average, so the block's motion
    differs by ~A omega h / 2, halving with the step."""
    amplitude, omega = 0.05, 0.3
    internal = {}
    errors = []
    for step in (0.05, 0.025):
        times = np.arange(step, 60.0 + step / 2, step)
        internal = sampled(shaken("rk4", amplitude, omega), times, ("x", "vx"))
        driven = shaken("rk4", 0.0, omega)
        rows = []
        for t in times:
            s = t - step
            driven.set_plate_input(0.0, 0.0, 0.0, amplitude * math.sin(omega * s),
                                   amplitude * omega * math.cos(omega * s), -amplitude * omega ** 2 * math.sin(omega * s))
            driven.advance_to(t)
            out = driven.outputs()
            rows.append([out["x"], out["vx"]])
        errors.append(np.max(np.abs(np.array(rows) - internal)))
        assert errors[-1] < amplitude * omega * step / 2
    assert 1.6 < errors[0] / errors[1] < 2.4


def test_horizontal_inputs_are_refused_under_the_vertical_plate_law():
    block = Block("A", "rk4", 0, False, k_d=0.0, dt=1e-3)
    block.start()
    with pytest.raises(ModelError, match="plate_motion = 1"):
        block.set_plate_input(0.0, 0.0, 0.0, 0.1, 0.0, 0.0)
    block.set_plate_input(0.1, 0.0, 0.0)  # a vertical input is taken as before


@pytest.mark.parametrize("integrator", ("adaptive", "event_driven"))
def test_integrators_that_take_the_plate_as_vertical_refuse_it_saying_why(integrator):
    with pytest.raises(ModelError, match="plate_motion = 1 .oblique.*vertical"):
        shaken(integrator, 0.1, 0.5)


def test_the_tangent_frame_refuses_an_oblique_plate():
    with pytest.raises(ModelError, match="formulation = 1.*normal only"):
        Block("B", "rk4", 0, False, plate_motion=1, drive_angle=1.0, formulation=1).start()


@pytest.mark.parametrize("angle", [math.nan, math.inf])
def test_a_direction_that_is_not_finite_is_refused(angle):
    with pytest.raises(ModelError, match="drive_angle"):
        Block("A", "rk4", 0, False, plate_motion=1, drive_angle=angle)


def test_under_a_vertical_drive_the_oblique_law_is_the_vertical_one_to_the_bit():
    """drive_angle = 0 moves the plate vertically: the same run as plate_motion = 0."""
    runs = []
    for plate_motion in (0, 1):
        block = Block("B", "rk4", 2, True, A=0.3, omega=0.8, plate_motion=plate_motion, k_d=1e-2, V_d=1e-2,
                      dt=1e-3)
        block.start()
        block.advance_to(50.0)
        runs.append(block.outputs())
    assert runs[0] == runs[1]
