"""Regimes of ``event_driven``: the closed-form flows of model A between events.

* vertical, in contact: y = z - Z_p obeys m y'' + gamma_n y' + k_n y = -m (g + a_ext)
  + m A omega^2 sin(theta); in flight z is ballistic;
* horizontal: m xi'' + gamma_t xi' + k xi = f0 + f1 u (xi = x - x_s, u = t - t_s), with
  k = k_d + k_t while the friction spring is loaded (F = F_s + xi) and k = k_d otherwise.

These are the linear contact law's flows (the registry refuses any other law).  The
contact force, its bound and the spring force along a flow are the laws' functions
applied to each part of a signal (constant, harmonic, mode), which is exact for linear
laws.
"""
import math

import numpy as np

from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import plate_motion
from ...laws import contact_force, friction_spring_force
from ...layout import D_AMP, D_EXT_A, D_EXT_V, D_EXT_Z, D_OMEGA, P_G, P_GN, P_GT, P_KD, P_KN, P_M, P_VD, Y_F, Y_VZ, Y_X, Y_Z
from .signals import R_CONTACT, R_DELTA, R_N, R_YDOT, S_M1, mode_value, set_mode, set_signal

# Horizontal regimes: flight, spring loaded, spring held at 0 while N <= 0, and the tail of
# a reset cascade (spring held at 0 while N > 0 falls to its zero).
FREE, ENGAGED, HELD, CASCADE = 0, 1, 2, 3
# Events.
EV_NONE, EV_CONTACT, EV_DETACH, EV_RESET_PLUS, EV_RESET_MINUS, EV_N_RISES, EV_N_ZERO = range(7)


@njit(inline="always")
def contact_constants(prm, drv):
    """(lam_n, k_n/m) of the contact oscillator, the complex amplitude of its steady
    response to the harmonic drive per unit of y's, and y's static offset."""
    m, k_n, gam_n, om = prm[P_M], prm[P_KN], prm[P_GN], drv[D_OMEGA]
    response = m * drv[D_AMP] * om * om / complex(k_n - m * om * om, gam_n * om)
    return -gam_n / (2.0 * m), k_n / m, response, -m * (prm[P_G] + drv[D_EXT_A]) / k_n


@njit(inline="always")
def horizontal_flow(kind, regime, stretch, shear, vx, prm):
    """The horizontal oscillator of a regime from (stretch, F, vx): its stiffness k, the
    particular solution a + b u, (lam, k/m), and the mode xi's value, rate and second
    derivative at the start."""
    m, k_d, gam_t = prm[P_M], prm[P_KD], prm[P_GT]
    lam_t = -gam_t / (2.0 * m)
    loaded = regime == ENGAGED
    # the friction spring's stiffness is its force per unit F (the linear law's)
    k_h = k_d + friction_spring_force(kind, 1.0, prm) if loaded else k_d
    f0 = k_d * stretch - (friction_spring_force(kind, shear, prm) if loaded else 0.0)
    f1 = k_d * prm[P_VD]
    if k_h > 0.0:
        b_lin = f1 / k_h
        a_lin = (f0 - gam_t * b_lin) / k_h
    else:
        b_lin = a_lin = 0.0
    kap_t = k_h / m
    xi0, xi1 = -a_lin, vx - b_lin
    return k_h, a_lin, b_lin, lam_t, kap_t, xi0, xi1, 2.0 * lam_t * xi1 - kap_t * xi0



@njit(inline="always")
def contact_flow(kind, sig, consts, y_s, ydot_s, e_th, om, prm):
    """The contact regime's vertical flow from y = z - Z_p and its rate at the start: the
    signals of delta, N and y' (rows R_DELTA, R_N, R_YDOT), and (h_y, yh0, yh1): y's
    harmonic amplitude (y_R(u) = Re(h_y e^(i om u))) and its mode's value and rate."""
    lam_n, kap_n, response, y_const = consts
    h_y = -1j * response * e_th
    yh0 = y_s - y_const - h_y.real
    yh1 = ydot_s - (1j * om * h_y).real
    yh2 = 2.0 * lam_n * yh1 - kap_n * yh0
    set_signal(sig[R_DELTA], -y_const, 0.0, 0.0, -h_y, om)
    set_mode(sig[R_DELTA], S_M1, -yh0, -yh1, lam_n, kap_n)
    # N = law(delta, u_n) part by part, delta = -y and u_n = y': the constant, the
    # harmonic (the law's response to y = e^(i om u)) and the mode
    h_n = contact_force(kind, -1.0, 1j * om, prm) * h_y
    set_signal(sig[R_N], contact_force(kind, -y_const, 0.0, prm), 0.0, 0.0, h_n, om)
    set_mode(sig[R_N], S_M1, contact_force(kind, -yh0, yh1, prm), contact_force(kind, -yh1, yh2, prm), lam_n, kap_n)
    set_signal(sig[R_YDOT], 0.0, 0.0, 0.0, 1j * om * h_y, om)
    set_mode(sig[R_YDOT], S_M1, yh1, yh2, lam_n, kap_n)
    return h_y, yh0, yh1


@njit(inline="always")
def flight_flow(sig, z, vz, drv, prm, tau_e, e_th):
    """The flight regime's contact signal z - Z_p (row R_CONTACT): ballistic z against the
    plate (its external input's part as a polynomial, the harmonic drive's as a harmonic)."""
    om = drv[D_OMEGA]
    ext_z, ext_v = plate_motion(0.0, om, 0.0, 0.0, drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A], tau_e)
    set_signal(sig[R_CONTACT], z - ext_z, vz - ext_v, -0.5 * (prm[P_G] + drv[D_EXT_A]), 1j * drv[D_AMP] * e_th, om)


@njit(inline="always")
def segment_end(s, prm, drv, flow, vertical, consts, regime, in_contact, u, th, tau_e):
    """The state a time u into the segment: ((x, z, vx, vz, F), (xi, xi'), (theta, plate
    height and velocity)); ``s`` holds the start, ``flow`` the horizontal flow,
    ``vertical`` the contact flow (``contact_flow``)."""
    _, a_lin, b_lin, lam_t, kap_t, xi0, xi1, _ = flow
    xi, xi_rate = mode_value(xi0, xi1, lam_t, kap_t, u)
    x_new = s[Y_X] + a_lin + b_lin * u + xi
    shear_new = s[Y_F] + a_lin + b_lin * u + xi if regime == ENGAGED else 0.0
    amp, om = drv[D_AMP], drv[D_OMEGA]
    th_end = th + om * u
    plate_z, plate_v = plate_motion(amp, om, math.sin(th_end), math.cos(th_end), drv[D_EXT_Z], drv[D_EXT_V],
                                    drv[D_EXT_A], tau_e + u)
    if in_contact:
        h_y, yh0, yh1 = vertical
        lam_n, kap_n, _, y_const = consts
        yh, yh_rate = mode_value(yh0, yh1, lam_n, kap_n, u)
        rot = h_y * complex(math.cos(om * u), math.sin(om * u))
        z_new = (y_const + rot.real + yh) + plate_z
        vz_new = ((1j * om * rot).real + yh_rate) + plate_v
    else:
        grav = prm[P_G]
        z_new = s[Y_Z] + u * (s[Y_VZ] - 0.5 * grav * u)
        vz_new = s[Y_VZ] - grav * u
    return (x_new, z_new, b_lin + xi_rate, vz_new, shear_new), (xi, xi_rate), (th_end, plate_z, plate_v)


@njit(inline="always")
def carry(n_ref, off, dt):
    """The clock (grid index, offset) with the offset's whole grid steps carried into the index."""
    whole = math.floor(off / dt)
    return n_ref + np.int64(whole), off - whole * dt
