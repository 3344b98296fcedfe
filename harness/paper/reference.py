"""Independent reference solutions of models A, B and C: scipy ``solve_ivp`` with events.

Written from ``docs/physics.md`` alone (it shares no code with the compiled core), so
that comparing the two can catch errors in either.  Three options select the reading of
the paper's Eqs. (3)-(6) (docs/physics.md gives every equation):

* ``formulation``: ``"fixed_axes"`` (0) -- Newton's law for the point r = (x, z) in fixed
  axes, the plate moving vertically, penetration delta = (Z_p - z) cos a, velocities
  relative to the plate projected on t = (cos a, sin a), n = (-sin a, cos a); or
  ``"tangent_frame"`` (1) -- the paper's equations as printed: the state is the abscissa
  x of the block's foot on the surface, its normal coordinate zeta and the rates u
  (along the local tangent) and w (along the local normal), dx/dt = u cos a, the plate's
  vibration A sin(omega t) along the local normal, delta = A sin(omega t) - zeta, no
  curvature terms.
* ``coulomb_normal``: the N of the Coulomb bound mu_s N -- ``"contact_force"`` (0),
  N = k_n delta - gamma_n u_n, or ``"applied_load"`` (1), N = -(load + drive spring) . n.
* ``flight``: the terms that act off contact -- ``"surface"`` (0), the contact phase's
  Theta-free terms evaluated on the surface under the block (load, tangential dashpot);
  or ``"free"`` (1), the free particle of Eqs. (1)-(2): load vertical, dashpot
  -gamma_t dx/dt on the absolute horizontal velocity (fixed axes only; the tangent
  frame's flight is its printed equations with Theta = 0).

In fixed axes the block r = (x, z) moves under

* the drive spring (-k_d (x - V_d t), 0), the load (0, -m g) in A, B or -P_l n in C;
* in contact (delta = (Z_p - z) cos a > 0): the normal force N n, N = k_n delta - gamma_n u_n,
  and the tangential spring -k_t F t with dF/dt = u_t;
* always: the tangential dashpot -gamma_t u_t t;

with Z_p(x, t) = A sin(omega t) + A_x sin(omega_x x), t = (cos a, sin a), n = (-sin a, cos a),
a = arctan(dZ_p/dx), and (u_t, u_n) the velocity relative to the plate along t and n.

The smooth pieces between switches are integrated by scipy's solvers (``RK45``,
``DOP853``, ``LSODA``, ``Radau``, ... -- the classes behind ``solve_ivp``) at any
tolerance; the switches are events, after which the integration restarts in the new
regime.  Events are detected on each step's dense output, at ``event_samples`` evenly
spaced points per step, and located by ``brentq`` on that same interpolant.  With one
sample per step this is ``solve_ivp``'s own detection (sign at the step ends), which
misses a switching function that dips below zero and back within one step -- as the
Coulomb bound mu_s N does when it oscillates with the plate -- so the reference samples
densely and caps the step (``Solver.reference``).

In the table N is the Coulomb bound's normal force (``coulomb_normal``).

==========  ==============================  =========================================
regime      events                          after the event
==========  ==============================  =========================================
flight      delta rises through 0           contact: spring loaded if N > 0, else held
loaded      delta falls through 0           flight, F = 0
            mu_s N -/+ k_t F falls to 0     Coulomb reset: F = 0, counted if F != 0
held        delta falls through 0           flight
(F = 0,     N rises through 0               spring loaded again
 N <= 0)
cascade     delta falls through 0           flight
(F = 0)     N falls through 0               held
==========  ==============================  =========================================

Resets that follow one another closer than ``CASCADE_GAP`` (the dashpot pulling the block
out makes them accumulate at the zero of N) end in the ``cascade`` regime: the spring is
held at zero from there until N has crossed zero, which is the limit of the cascade.

Alongside the state the solver integrates phi = int (dx/dt - V_d)^2 dt and the energy
balance (work of the drive's far end, of the plate and of the load -- in the tangent frame
also of the drive spring's normal component; dashpot dissipation plus k_t F^2 / 2
released at each reset; the normal spring's energy int -k_n delta u_n dt).
"""
from __future__ import annotations

import cmath
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate
from scipy.optimize import brentq

# Resets closer together than this (tau_0) are the accumulation before a zero of N.
CASCADE_GAP = 1e-9
FLIGHT, LOADED, HELD, CASCADE = "flight", "loaded", "held", "cascade"
STATE_NAMES = ("x", "z", "vx", "vz", "F", "phi", "work", "dissipated", "e_normal")
# The tangent frame's state in the same slots: zeta, u, w in place of z, vx, vz.
FRAME_STATE_NAMES = ("x", "zeta", "u", "w", "F", "phi", "work", "dissipated", "e_normal")
IX, IZ, IVX, IVZ, IF, IPHI, IWORK, IDISS, IEN = range(9)

# The three options, in the order of their integer codes.
FORMULATIONS = ("fixed_axes", "tangent_frame")
COULOMB_NORMALS = ("contact_force", "applied_load")
# The contact law in fixed axes: the elastic force -grad(k_n delta^2 / 2), conservative on a
# curved plate (0, the default), or k_n delta along the normal only (1; docs/physics.md, Sec. 3).
CONTACT_LAWS = ("linear", "linear_along_normal")
FLIGHTS = ("surface", "free")

_COMMON = dict(m=1.0, k_n=1.0, k_t=0.28, gamma_n=0.07, gamma_t=2.5e-4, mu_s=0.5, A=0.0, omega=0.0)
DEFAULTS = {  # the paper's values (Sec. II C, III B, III C)
    "A": dict(_COMMON, g=1.0, k_d=5e-4, V_d=2e-5),
    "B": dict(_COMMON, g=1.0, k_d=5e-6, V_d=2e-4, A_x=1e3, omega_x=2e-2),
    "C": dict(_COMMON, P_l=1.0, k_d=5e-6, V_d=2e-4, A_x=1e3, omega_x=2e-2),
}


def option(kind: str, value, choices: tuple) -> str:
    """An option given by name or by its integer code."""
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool) and 0 <= value < len(choices):
        return choices[int(value)]
    if isinstance(value, str) and value in choices:
        return value
    raise ValueError(f"{kind} must be one of {choices} or their codes 0..{len(choices) - 1}, not {value!r}")


@dataclass(frozen=True)
class Solver:
    """How the smooth pieces are integrated and the switches detected.

    ``event_samples`` points of each step's interpolant are checked for a switch (1: the
    step ends only, as ``solve_ivp`` does); ``max_cycle_fraction`` caps the step to that
    fraction of the plate's period (0: no cap)."""
    method: str = "DOP853"
    rtol: float = 1e-12
    atol: float = 1e-12
    event_samples: int = 1
    max_cycle_fraction: float = 0.0

    @classmethod
    def reference(cls, rtol=1e-12):
        return cls("DOP853", rtol, rtol, event_samples=16, max_cycle_fraction=1.0 / 16.0)


@dataclass
class Trajectory:
    """Samples of a reference run and what it cost.

    ``states`` always holds x, z, vx, vz (the block's horizontal position, its height, and
    their rates; in the tangent frame z and vz are derived, docs/physics.md), F, phi, the
    energy terms, ``contact``, ``slips``, ``delta`` (penetration), ``normal`` (contact
    force, 0 off contact) and ``bound`` (the Coulomb bound's N, 0 off contact); in the
    tangent frame also its own zeta, u, w."""
    model: str
    parameters: dict
    times: np.ndarray
    states: dict  # name -> array over times
    slips: int = 0
    events: int = 0
    rhs_evaluations: int = 0
    wall_time: float = 0.0
    initial: np.ndarray | None = None  # state at t = 0
    event_log: list = field(default_factory=list)  # (time, kind)
    formulation: str = "fixed_axes"
    coulomb_normal: str = "contact_force"
    flight: str = "surface"
    contact_law: str = "linear"

    def __getitem__(self, name):
        return self.states[name]

    def final(self, name):
        return float(self.states[name][-1])

    def energy_residual(self):
        """Stored energy change - work + dissipated at each sample.

        Stored: kinetic (m (vx^2 + vz^2) / 2 in fixed axes, m (u^2 + w^2) / 2 in the tangent
        frame), drive spring k_d (x - V_d t)^2 / 2, tangential spring k_t F^2 / 2, and the
        normal spring's energy (int -k_n delta u_n dt over contacts)."""
        s, p = self.states, self.parameters
        names = STATE_NAMES if self.formulation == "fixed_axes" else FRAME_STATE_NAMES
        v1, v2 = names[IVX], names[IVZ]

        def stored(x, vx, vz, shear, e_normal, t):
            return (0.5 * p["m"] * (vx ** 2 + vz ** 2) + 0.5 * p["k_d"] * (x - p["V_d"] * t) ** 2
                    + 0.5 * p["k_t"] * shear ** 2 + e_normal)

        s0 = self.initial
        start = stored(s0[IX], s0[IVX], s0[IVZ], s0[IF], s0[IEN], 0.0)
        return stored(s["x"], s[v1], s[v2], s["F"], s["e_normal"], self.times) - start - s["work"] + s["dissipated"]


class Model:
    """Forces and switching functions of one variant in one formulation."""

    def __init__(self, model: str, parameters: dict, formulation="fixed_axes", coulomb_normal="contact_force",
                 flight="surface", contact_law="linear"):
        if model not in DEFAULTS:
            raise ValueError(f"unknown model {model!r}")
        unknown = set(parameters) - set(DEFAULTS[model])
        if unknown:
            raise ValueError(f"model {model} has no parameters {sorted(unknown)}")
        self.model = model
        self.p = {"A_x": 0.0, "omega_x": 0.0, "g": 0.0, "P_l": 0.0, **DEFAULTS[model], **parameters}
        self.formulation = option("formulation", formulation, FORMULATIONS)
        self.coulomb_normal = option("coulomb_normal", coulomb_normal, COULOMB_NORMALS)
        self.flight = option("flight", flight, FLIGHTS)
        self.contact_law = option("contact_law", contact_law, CONTACT_LAWS)
        self.tangent = self.formulation == "tangent_frame"
        self.applied = self.coulomb_normal == "applied_load"
        self.free_flight = self.flight == "free"
        if self.tangent and self.free_flight:
            raise ValueError("flight = 'free' applies to the fixed-axes formulation only: the tangent frame's "
                             "flight is its printed equations with Theta = 0 (docs/physics.md)")
        self.names = FRAME_STATE_NAMES if self.tangent else STATE_NAMES

    # -- geometry and plate
    def surface(self, x):
        p = self.p
        if p["A_x"] == 0.0:
            return 0.0, 0.0
        return p["A_x"] * math.sin(p["omega_x"] * x), p["A_x"] * p["omega_x"] * math.cos(p["omega_x"] * x)

    def curvature(self, x):
        """d^2 Z_p / dx^2 of the static profile."""
        p = self.p
        return -p["A_x"] * p["omega_x"] ** 2 * math.sin(p["omega_x"] * x) if p["A_x"] != 0.0 else 0.0

    def plate(self, t):
        p = self.p
        w = p["omega"]
        return p["A"] * math.sin(w * t), p["A"] * w * math.cos(w * t), -p["A"] * w * w * math.sin(w * t)

    def tilt(self, x):
        """cos a, sin a of the surface at abscissa x."""
        _, slope = self.surface(x)
        cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
        return cos_a, slope * cos_a

    def normal_load(self, cos_a):
        """The confining load's component into the plate, -load . n: m g cos a (A, B), P_l (C)."""
        return self.p["P_l"] if self.model == "C" else self.p["m"] * self.p["g"] * cos_a

    def kinematics(self, t, s):
        """Penetration, u_n, u_t, cos a, sin a, and the plate's velocity (vertical in fixed
        axes, along the normal in the tangent frame)."""
        if self.tangent:
            cos_a, sin_a = self.tilt(s[IX])
            plate_z, plate_v, _ = self.plate(t)
            return plate_z - s[IZ], s[IVZ] - plate_v, s[IVX], cos_a, sin_a, plate_v
        x, z, vx, vz = s[IX], s[IZ], s[IVX], s[IVZ]
        height, slope = self.surface(x)
        cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
        sin_a = slope * cos_a
        plate_z, plate_v, _ = self.plate(t)
        delta = (plate_z + height - z) * cos_a
        rel_vz = vz - plate_v
        return delta, -vx * sin_a + rel_vz * cos_a, vx * cos_a + rel_vz * sin_a, cos_a, sin_a, plate_v

    def normal_force(self, t, s):
        delta, u_n, *_ = self.kinematics(t, s)
        return self.p["k_n"] * delta - self.p["gamma_n"] * u_n

    def applied_normal(self, t, s):
        """-(load + drive spring) . n = W_n - k_d (x - V_d t) sin a (docs/physics.md)."""
        cos_a, sin_a = self.tilt(s[IX])
        return self.normal_load(cos_a) - self.p["k_d"] * (s[IX] - self.p["V_d"] * t) * sin_a

    def bound_normal(self, t, s):
        """The N of the Coulomb bound mu_s N."""
        return self.applied_normal(t, s) if self.applied else self.normal_force(t, s)

    def rhs(self, t, s, regime):
        if self.tangent:
            return self._rhs_tangent_frame(t, s, regime)
        if regime == FLIGHT and self.free_flight:
            return self._rhs_free_flight(t, s)
        p = self.p
        delta, u_n, u_t, cos_a, sin_a, plate_v = self.kinematics(t, s)
        touching = regime != FLIGHT
        normal = p["k_n"] * delta - p["gamma_n"] * u_n if touching else 0.0
        tangential = -p["gamma_t"] * u_t - (p["k_t"] * s[IF] if regime == LOADED else 0.0)
        if self.model == "C":
            load_x, load_z = p["P_l"] * sin_a, -p["P_l"] * cos_a
        else:
            load_x, load_z = 0.0, -p["m"] * p["g"]
        # The conservative contact's x-force k_n delta^2 tan(a) da/dx, da/dx = h'' cos^2(a).
        curving = (p["k_n"] * delta * delta * sin_a * cos_a * self.curvature(s[IX])
                   if touching and self.contact_law == "linear" else 0.0)
        fx = -p["k_d"] * (s[IX] - p["V_d"] * t) - normal * sin_a + tangential * cos_a + load_x + curving
        fz = normal * cos_a + tangential * sin_a + load_z
        power_in = (p["k_d"] * (p["V_d"] * t - s[IX]) * p["V_d"] + plate_v * (normal * cos_a + tangential * sin_a)
                    + load_x * s[IVX] + load_z * s[IVZ])
        loss = p["gamma_t"] * u_t * u_t + (p["gamma_n"] * u_n * u_n if touching else 0.0)
        # The contact's stored energy: d(k_n delta^2 / 2)/dt = -k_n delta u_n - curving vx for the
        # conservative law; the old force's storage is booked as its power -k_n delta u_n.
        storage = -p["k_n"] * delta * u_n - curving * s[IVX] if touching else 0.0
        return [s[IVX], s[IVZ], fx / p["m"], fz / p["m"], u_t if regime == LOADED else 0.0,
                (s[IVX] - p["V_d"]) ** 2, power_in, loss, storage]

    def _rhs_free_flight(self, t, s):
        """Fixed axes off contact with flight = 'free': m x'' = -k_d (x - V_d t) - gamma_t x',
        m z'' = -W, W = m g (A, B) or P_l (C)."""
        p = self.p
        weight = p["P_l"] if self.model == "C" else p["m"] * p["g"]
        vx, vz = s[IVX], s[IVZ]
        fx = -p["k_d"] * (s[IX] - p["V_d"] * t) - p["gamma_t"] * vx
        power_in = p["k_d"] * (p["V_d"] * t - s[IX]) * p["V_d"] - weight * vz
        return [vx, vz, fx / p["m"], -weight / p["m"], 0.0, (vx - p["V_d"]) ** 2, power_in,
                p["gamma_t"] * vx * vx, 0.0]

    def _rhs_tangent_frame(self, t, s, regime):
        """The paper's Eqs. (3)-(6) as printed, state (x, zeta, u, w, F, ...):
        dx/dt = u cos a, dzeta/dt = w,
        m du/dt = -k_d (x - V_d t) cos a - gamma_t u - k_t F Theta + L_t,
        m dw/dt = N Theta + k_d (x - V_d t) sin a + L_n,
        (L_t, L_n) = (0, -m g) in A, (-m g sin a, -m g cos a) in B, (0, -P_l) in C."""
        p = self.p
        x, u, w = s[IX], s[IVX], s[IVZ]
        cos_a, sin_a = self.tilt(x)
        plate_z, plate_v, _ = self.plate(t)
        delta = plate_z - s[IZ]
        u_n = w - plate_v
        touching = regime != FLIGHT
        normal = p["k_n"] * delta - p["gamma_n"] * u_n if touching else 0.0
        if self.model == "C":
            load_t, load_n = 0.0, -p["P_l"]
        else:
            load_t, load_n = -p["m"] * p["g"] * sin_a, -p["m"] * p["g"] * cos_a
        stretch = x - p["V_d"] * t
        f_t = -p["k_d"] * stretch * cos_a - p["gamma_t"] * u - (p["k_t"] * s[IF] if regime == LOADED else 0.0) + load_t
        f_n = normal + p["k_d"] * stretch * sin_a + load_n
        vx = u * cos_a
        power_in = (p["k_d"] * (p["V_d"] * t - x) * p["V_d"] + normal * plate_v + load_t * u
                    + (load_n + p["k_d"] * stretch * sin_a) * w)
        loss = p["gamma_t"] * u * u + (p["gamma_n"] * u_n * u_n if touching else 0.0)
        return [vx, w, f_t / p["m"], f_n / p["m"], u if regime == LOADED else 0.0,
                (vx - p["V_d"]) ** 2, power_in, loss, -p["k_n"] * delta * u_n if touching else 0.0]

    def loaded_after_switch(self, t, s):
        """Whether the spring loads right after contact or a reset (mu_s N > 0, or N = 0 rising)."""
        normal = self.bound_normal(t, s)
        if self.p["mu_s"] <= 0.0:
            return False
        if normal != 0.0:
            return normal > 0.0
        ds = self.rhs(t, s, HELD)
        eps = 1e-9
        return self.bound_normal(t + eps, np.asarray(s) + eps * np.asarray(ds)) > 0.0

    def _signals(self, t, y):
        """Penetration and the Coulomb bound's N at times t (array) and states y (columns)."""
        p = self.p
        x = y[IX]
        if p["A_x"] == 0.0:
            height = slope = np.zeros_like(x)
        else:
            height = p["A_x"] * np.sin(p["omega_x"] * x)
            slope = p["A_x"] * p["omega_x"] * np.cos(p["omega_x"] * x)
        cos_a = 1.0 / np.sqrt(1.0 + slope * slope)
        sin_a = slope * cos_a
        w = p["omega"]
        if self.tangent:
            delta = p["A"] * np.sin(w * t) - y[IZ]
            u_n = y[IVZ] - p["A"] * w * np.cos(w * t)
        else:
            z, vx, vz = y[IZ], y[IVX], y[IVZ]
            delta = (p["A"] * np.sin(w * t) + height - z) * cos_a
            u_n = -vx * sin_a + (vz - p["A"] * w * np.cos(w * t)) * cos_a
        if self.applied:
            load = p["P_l"] if self.model == "C" else p["m"] * p["g"] * cos_a
            normal = load - p["k_d"] * (x - p["V_d"] * t) * sin_a
        else:
            normal = p["k_n"] * delta - p["gamma_n"] * u_n
        return delta, normal

    def switching(self, regime, t, y):
        """Switching functions of a regime at times t (array) and states y (columns), with
        the direction that triggers each (+1 rising through 0, -1 falling) and its name."""
        p = self.p
        delta, normal = self._signals(t, y)
        if regime == FLIGHT:
            return [(delta, +1, "contact")]
        if regime == LOADED:
            return [(delta, -1, "detach"), (p["mu_s"] * normal - p["k_t"] * y[IF], -1, "reset"),
                    (p["mu_s"] * normal + p["k_t"] * y[IF], -1, "reset")]
        if regime == HELD:
            return [(delta, -1, "detach"), (normal, +1, "rearm")]
        return [(delta, -1, "detach"), (normal, -1, "held")]

    # -- the tangent frame's state seen as a point (x, z): docs/physics.md, "Outputs"
    def frame_to_point(self, s):
        """x, z, vx, vz of a tangent-frame state: z = h(x) + zeta / cos a, vx = u cos a,
        vz = dz/dt = u sin a + w / cos a + zeta h''(x) u sin a cos a."""
        x, zeta, u, w = s[IX], s[IZ], s[IVX], s[IVZ]
        height, _ = self.surface(x)
        cos_a, sin_a = self.tilt(x)
        return (x, height + zeta / cos_a, u * cos_a,
                u * sin_a + w / cos_a + zeta * self.curvature(x) * u * sin_a * cos_a)

    def point_to_frame(self, x, z, vx, vz):
        """The inverse of ``frame_to_point``: zeta, u, w."""
        height, _ = self.surface(x)
        cos_a, sin_a = self.tilt(x)
        zeta = (z - height) * cos_a
        u = vx / cos_a
        return zeta, u, cos_a * (vz - u * sin_a - zeta * self.curvature(x) * u * sin_a * cos_a)


def initial_state(model: Model, mode: int = 0, x_start=0.0, z_start=0.0, vx_start=0.0, vz_start=0.0):
    """The core's three starts, recomputed here: 0 rest penetration under the plate,
    1 as given, 2 on the steady in-contact orbit of the vertical (tangent frame: normal)
    oscillator.  The rest penetration is the load's alone, W_n / k_n (the drive spring's
    normal component is left out).  In the tangent frame x_start, z_start, vx_start,
    vz_start are the point's coordinates, mapped by ``Model.point_to_frame``."""
    p = model.p
    height, slope = model.surface(x_start)
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    sin_a = slope * cos_a
    plate_z, plate_v, _ = model.plate(0.0)
    if model.model == "C":
        weight = p["P_l"]
    else:
        weight = p["m"] * p["g"] * cos_a
    w = p["omega"]
    if mode == 2:
        # steady in-contact response: y'' m + gamma_n y' + k_n y = -weight + m A w^2 sin(w t),
        # y = -weight / k_n + Im(c e^(i w t)) (none for an undamped contact driven at resonance:
        # only this start needs it)
        c = p["m"] * p["A"] * w * w / (p["k_n"] - p["m"] * w * w + 1j * p["gamma_n"] * w)
    s = np.zeros(len(STATE_NAMES))
    s[IX], s[IVX] = x_start, vx_start
    if model.tangent:
        zeta, u, w_n = model.point_to_frame(x_start, z_start, vx_start, vz_start)
        if mode == 0:
            zeta = plate_z - weight / p["k_n"]
            _, u, w_n = model.point_to_frame(x_start, height + zeta / cos_a, vx_start, vz_start)
        elif mode == 2:
            zeta = plate_z - weight / p["k_n"] + c.imag
            w_n = plate_v + (1j * w * c).imag
        s[IZ], s[IVX], s[IVZ] = zeta, u, w_n
    elif mode == 0:
        s[IZ], s[IVZ] = plate_z + height - weight / (p["k_n"] * cos_a), vz_start
    elif mode == 1:
        s[IZ], s[IVZ] = z_start, vz_start
    else:
        s[IZ] = plate_z + height - weight / p["k_n"] + c.imag
        s[IVZ] = plate_v + (1j * w * c).imag
    delta = model.kinematics(0.0, s)[0]
    s[IEN] = 0.5 * p["k_n"] * delta * delta if delta > 0.0 else 0.0
    return s


SOLVERS = {"RK23": integrate.RK23, "RK45": integrate.RK45, "DOP853": integrate.DOP853, "LSODA": integrate.LSODA,
           "Radau": integrate.Radau, "BDF": integrate.BDF}


def _first_switch(m: Model, regime, dense, t_old, t_new, samples):
    """Earliest switch on (t_old, t_new] of the step's interpolant: (time, name) or None."""
    times = np.linspace(t_old, t_new, samples + 1)
    values = m.switching(regime, times, dense(times))
    for k in range(samples):
        best = None
        for row, (g, direction, name) in enumerate(values):
            before, after = g[k], g[k + 1]
            crossed = (before < 0.0 <= after) if direction > 0 else (before > 0.0 >= after)
            if not crossed:
                continue
            if after == 0.0:
                root = times[k + 1]
            else:
                root = brentq(lambda tt: m.switching(regime, tt, dense(tt))[row][0], times[k], times[k + 1],
                              xtol=1e-15, rtol=4.0 * np.finfo(float).eps)
            if best is None or root < best[0]:
                best = (root, name)
        if best is not None:
            return best
    return None


def simulate(model: str, parameters: dict | None = None, t_end: float = 100.0, sample_times=None,
             solver: Solver = Solver(), initial: int = 0, max_events: int = 10_000_000,
             formulation="fixed_axes", coulomb_normal="contact_force", flight="surface", contact_law="linear",
             **start) -> Trajectory:
    """Integrate from t = 0 to t_end; samples at ``sample_times`` (default: t_end only).

    ``formulation``, ``coulomb_normal`` and ``flight`` take the names in FORMULATIONS,
    COULOMB_NORMALS, FLIGHTS or their integer codes (docs/physics.md)."""
    m = Model(model, dict(parameters or {}), formulation, coulomb_normal, flight, contact_law)
    s = initial_state(m, initial, **start)
    start_state = s.copy()
    samples = np.atleast_1d(np.asarray(t_end if sample_times is None else sample_times, dtype=float))
    if np.any(np.diff(samples) <= 0.0) or samples[0] < 0.0 or samples[-1] > t_end:
        raise ValueError("sample_times must increase within [0, t_end]")
    stepper = SOLVERS[solver.method]
    max_step = np.inf
    if solver.max_cycle_fraction > 0.0 and m.p["omega"] > 0.0 and m.p["A"] != 0.0:
        max_step = solver.max_cycle_fraction * 2.0 * math.pi / m.p["omega"]

    delta = m.kinematics(0.0, s)[0]
    regime = (LOADED if m.loaded_after_switch(0.0, s) else HELD) if delta > 0.0 else FLIGHT
    rows, row_regimes, row_slips = [], [], []
    t, slips, events, evaluations = 0.0, 0, 0, 0
    last_reset = -math.inf
    log = []
    next_sample = 0
    started = time.perf_counter()
    while next_sample < len(samples) and samples[next_sample] <= t:  # samples at the start
        rows.append(s.copy())
        row_regimes.append(regime)
        row_slips.append(slips)
        next_sample += 1
    while t < t_end:
        current = regime
        integrator = stepper(lambda tt, ss: m.rhs(tt, ss, current), t, s, t_end, rtol=solver.rtol, atol=solver.atol,
                             max_step=max_step)
        switch = None
        while integrator.status == "running":
            message = integrator.step()
            if integrator.status == "failed":
                raise RuntimeError(f"{solver.method} failed at t = {integrator.t}: {message}")
            dense = integrator.dense_output()
            switch = _first_switch(m, regime, dense, integrator.t_old, integrator.t, solver.event_samples)
            t_stop = switch[0] if switch else integrator.t
            while next_sample < len(samples) and samples[next_sample] <= t_stop:
                rows.append(dense(samples[next_sample]))
                row_regimes.append(regime)
                row_slips.append(slips)
                next_sample += 1
            if switch:
                break
        evaluations += integrator.nfev
        if not switch:
            s, t = np.array(integrator.y), float(integrator.t)
            break
        t, kind = switch
        s = np.array(dense(t))
        events += 1
        if events > max_events:
            raise RuntimeError(f"more than {max_events} events before t = {t}")
        log.append((t, kind))
        if kind == "contact":
            regime = LOADED if m.loaded_after_switch(t, s) else HELD
        elif kind == "detach":
            s[IDISS] += 0.5 * m.p["k_t"] * s[IF] ** 2
            s[IF] = 0.0
            regime = FLIGHT
        elif kind == "reset":
            if s[IF] != 0.0:
                slips += 1
                s[IDISS] += 0.5 * m.p["k_t"] * s[IF] ** 2
            s[IF] = 0.0
            if m.loaded_after_switch(t, s):
                regime = CASCADE if t - last_reset < CASCADE_GAP else LOADED
            else:
                regime = HELD
            last_reset = t
        elif kind == "rearm":
            regime = LOADED
        else:  # the cascade's limit: N reached zero
            regime = HELD
    wall = time.perf_counter() - started
    while next_sample < len(samples):  # t_end itself, reached without an event
        rows.append(s.copy())
        row_regimes.append(regime)
        row_slips.append(slips)
        next_sample += 1
    data = np.array(rows)
    states = {name: data[:, i] for i, name in enumerate(m.names)}
    if m.tangent:
        point = np.array([m.frame_to_point(row) for row in data]).reshape(-1, 4)
        for i, name in enumerate(("x", "z", "vx", "vz")):
            states[name] = point[:, i]
    states["contact"] = np.array([r != FLIGHT for r in row_regimes])
    states["slips"] = np.array(row_slips)
    states["delta"] = np.array([m.kinematics(tk, row)[0] for tk, row in zip(samples, data)])
    states["normal"] = np.array([m.normal_force(tk, row) if c else 0.0
                                 for tk, row, c in zip(samples, data, states["contact"])])
    states["bound"] = np.array([m.bound_normal(tk, row) if c else 0.0
                                for tk, row, c in zip(samples, data, states["contact"])])
    return Trajectory(model, m.p, samples, states, slips=slips, events=events, rhs_evaluations=evaluations,
                      wall_time=wall, event_log=log, initial=start_state, formulation=m.formulation,
                      coulomb_normal=m.coulomb_normal, flight=m.flight, contact_law=m.contact_law)


def stick_slip_cycle(parameters: dict) -> dict:
    """Claim C1 (model A, no vibration): creep velocity, stick time and slip length."""
    p = {**DEFAULTS["A"], **parameters}
    creep = p["V_d"] * p["k_d"] / (p["k_t"] + p["k_d"])
    return {"creep": creep, "stick_time": p["mu_s"] * p["m"] * p["g"] / (p["k_t"] * creep),
            "slip_length": p["mu_s"] * p["m"] * p["g"] / p["k_d"]}


def steady_orbit_height(parameters: dict, t: float) -> float:
    """Height of a model-A block on its steady in-contact orbit (no drive), at time t."""
    p = {**DEFAULTS["A"], **parameters}
    w = p["omega"]
    c = p["m"] * p["A"] * w * w / (p["k_n"] - p["m"] * w * w + 1j * p["gamma_n"] * w)
    return p["A"] * math.sin(w * t) - p["m"] * p["g"] / p["k_n"] + (c * cmath.exp(1j * w * t)).imag
