"""The integrators: one registry, one contract, one fixed-step driver.

Each integrator is one record in ``INTEGRATORS`` (id, name, the models it supports,
its cost and stability limit, its advance and observe kernels, its status messages).
``Block``, the FMU's ``integrator`` parameter, the README table and the benchmarks read
this registry; adding an integrator is one module and one record here.  A fixed-step
scheme is a ``prepare``/``step`` pair run by the shared driver (``fixed_step``); an
integrator that is not fixed-step brings its own ``advance``/``observe`` kernels
(``event_driven``).

The contract every integrator keeps (``tests/fmu_src/vibroblock/integrators/test_contract.py``
checks every registered one against the rules a test can check):

1. Grid.  The state is stored on the grid t_n = t0 + n dt, n = cnt[C_STEP]; time is
   never accumulated.  ``advance(kind, method, flags, y, cnt, drv, prm, n_steps,
   track_energy)`` moves it by whole grid steps; between grid points outputs come from
   ``observe(..., h, track_energy, obs)``, which fills ``obs`` (``layout.O_*``) with the
   state at t_n + h without touching the stored state.
2. Friction rule.  The stored state satisfies the paper's rule: F = 0 out of contact,
   |k_t F| < mu_s N in contact.  The rule is applied at the end of every step, at the
   new state; a reset of a loaded spring increments cnt[C_SLIPS] and releases
   k_t F^2 / 2 into the dissipated energy.
3. Splits.  The plate drive is a function of the grid index alone, so advancing n1 + n2
   steps in two calls gives the same bits as n1 + n2 in one (an integrator whose
   ``splits_bitwise`` is False -- exact flows with located events -- agrees to its
   event tolerance instead).  Its phase comes from ``plate.drive_phase`` (off the grid:
   ``plate.phase_after``), reduced modulo 2 pi without rounding the product omega t,
   so the plate is the same to ~1e-15 at t ~ 1e12 as near t = 0.
4. Failure.  ``advance`` returns 0 (OK), 1 (STOP: a guard stopped it early, the steps
   taken are stored) or a negative status from ``statuses``; on a negative status the
   arrays are exactly as they were on entry (the last good state).
5. Energy.  With ``track_energy`` the work done on the block and the energy dissipated
   are accumulated (``dynamics.energy_rates``) to the scheme's own order, so that
   stored - start - work + dissipated measures its error; the stored energies are booked
   as their potentials when observed (``observation.stored_energy``), so the normal
   spring's accumulated energy (``Y_E_NORMAL``) is read by nothing and a kernel may leave
   it as it is (``event_driven``, ``implicit_contact`` do).
6. Costs.  Located events and rejected steps are counted in cnt[C_EVENTS] and
   cnt[C_REJECTED] by the integrators that locate or reject.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Callable

import numpy as np

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import typeof, types  # noqa: E402

from . import adaptive, event_driven, fixed_step, implicit_contact, rk4, symplectic_euler
from ..laws import AXES, law
from ..orbits import orbit_response
from .fixed_step import NON_FINITE, OK, STOP


def _spring_dashpot_limit(limit: float):
    """Stability check of an explicit scheme: dt^2 k/m + 2 dt gamma/m <= limit for the
    normal and the tangential contact."""
    def check(p: dict, model: str, name: str) -> str | None:
        dt = p["dt"]
        for what, k, gamma in (("normal contact", p["k_n"], p["gamma_n"]),
                               ("tangential contact", p["k_t"], p["gamma_t"])):
            k_m, c_m = k / p["m"], gamma / p["m"]
            if dt * dt * k_m + 2.0 * dt * c_m > limit:
                dt_max = (limit / (2.0 * c_m) if k_m == 0.0
                          else (-c_m + math.sqrt(c_m * c_m + limit * k_m)) / k_m)
                return (f"dt = {dt:g} is too large for the {what} (k/m = {k_m:g}, gamma/m = {c_m:g}) with "
                        f"{name}: dt^2 k/m + 2 dt gamma/m must stay <= {limit:g}; use dt <= {dt_max:.3g}")
        return None
    return check


def _implicit_contact_limit(p: dict, model: str, name: str) -> str | None:
    """implicit_contact integrates the contact spring-dashpots, and the drive spring's
    pull along the tangent, exactly: on a flat plate nothing limits dt but the search
    for a release inside a step (at most MAX_PIECES half contact periods).  On a
    corrugated plate the frame is frozen over a step and what couples through it stays
    explicit - the drive's pull across the slope and the load's pull along the curved
    surface (stiffness up to load x A_x omega_x^2): dt^2 (k_d + load A_x omega_x^2)/m <= 1."""
    dt = p["dt"]
    curvature = p.get("A_x", 0.0) * p.get("omega_x", 0.0) ** 2  # largest |Z_p''| of the corrugation
    if curvature > 0.0:
        confining = p["P_l"] if "P_l" in p else p["m"] * p["g"]
        k_m = (p["k_d"] + confining * curvature) / p["m"]
        if dt * dt * k_m > 1.0:
            return (f"dt = {dt:g} is too large for the corrugated plate with implicit_contact: the drive spring and "
                    f"the load's pull along the curved surface (k_d + load A_x omega_x^2)/m = {k_m:g} stay explicit, "
                    f"dt^2 times it must stay <= 1; use dt <= {1.0 / math.sqrt(k_m):.3g}")
    half_periods = dt * math.sqrt(p["k_n"] / p["m"]) / math.pi
    if half_periods >= implicit_contact.MAX_PIECES:
        return (f"dt = {dt:g} spans {half_periods:.3g} half periods of the normal contact (k_n/m = "
                f"{p['k_n'] / p['m']:g}); implicit_contact searches at most {implicit_contact.MAX_PIECES} per step "
                f"for a release; use dt <= {implicit_contact.MAX_PIECES * math.pi / math.sqrt(p['k_n'] / p['m']):.3g}")
    return None


def _no_limit(p: dict, model: str, name: str) -> str | None:
    return None


def _undamped_resonance(p: dict, model: str, name: str) -> str | None:
    """event_driven's contact flow is the driven oscillator's closed form, whose particular
    solution divides by k_n - m omega^2 + i gamma_n omega: an undamped contact driven at its
    own resonance has none (the secular solution grows like t), so it is refused up front
    (the condition is ``orbits.orbit_response``'s)."""
    try:
        orbit_response(p["m"], p["k_n"], p["gamma_n"], p["A"], p["omega"])
    except ValueError:
        return (f"{name} cannot drive an undamped contact (gamma_n = 0) at its own resonance omega = sqrt(k_n / m) "
                f"= {p['omega']:g}: its closed-form contact flow has no steady part there (the oscillation grows "
                f"without bound); give gamma_n > 0, another omega, or use adaptive")
    return None


def _event_driven_refuses(readings: dict) -> str | None:
    """event_driven's flows are closed forms of linear oscillators and its Coulomb resets are
    zeros of the oscillating contact force: it runs a contact law only if the law says it is
    linear (a module constant ``LINEAR``), and the contact force's bound only."""
    if readings["coulomb_normal"] != 0:
        bound = law("bound", readings["coulomb_normal"])
        return (f"locates Coulomb resets on the oscillating contact force only, not coulomb_normal = {bound.id} "
                f"({bound.name})")
    contact = law("contact", readings.get("contact_law", 0))
    if not getattr(contact.module, "LINEAR", False):
        return (f"integrates the closed-form flows of a linear contact law only, not contact_law = {contact.id} "
                f"({contact.name}): its force is not linear in the penetration and its rate")
    return None


# Tolerances the adaptive integrator accepts: below RTOL_MIN the local error cannot be
# told from rounding; above RTOL_MAX the error estimate no longer bounds anything.
RTOL_MIN, RTOL_MAX = 1e-13, 1e-2


def _tolerances(p: dict, model: str, name: str) -> str | None:
    """The adaptive integrator's dt is only its storage grid; its accuracy is rtol, atol."""
    rtol, atol = p["rtol"], p["atol"]
    if not RTOL_MIN <= rtol <= RTOL_MAX:
        return (f"rtol = {rtol:g} is not admissible with {name}: the relative tolerance must lie in "
                f"[{RTOL_MIN:g}, {RTOL_MAX:g}] (below, rounding dominates the local error; above, the error "
                "estimate bounds nothing)")
    if not 1e-300 < atol <= 1.0:
        return (f"atol = {atol:g} is not admissible with {name}: the absolute tolerance must lie in (1e-300, 1] "
                "(lengths in delta_0 and velocities in delta_0/tau_0, whose natural scale is 1)")
    return None


# Messages of the failure statuses; {t}, {t_end}, {dt}, {integrator} are filled in.
NON_FINITE_MESSAGE = ("the state became non-finite while integrating from t = {t:g} to t = {t_end:g} (dt = {dt:g}, "
                      "{integrator}); the state at t = {t:g} is kept. Reduce dt or check the parameters for extreme "
                      "values.")


@dataclass(frozen=True)
class Integrator:
    id: int  # the FMU's ``integrator`` value: stable, never reused
    name: str
    summary: str  # one line for the FMU's description and the README
    models: str  # "*" for every variant, else the variant names it supports
    force_evaluations: int  # per internal step (0: the cost is per event, not per step)
    check_step: Callable[[dict, str, str], str | None]  # why dt is not admissible, or None
    advance: Callable
    observe: Callable
    statuses: dict[int, str] = field(default_factory=dict)  # failure status -> message
    splits_bitwise: bool = True  # contract rule 3 holds bit for bit
    public: bool = True  # offered through the FMU's ``integrator`` parameter
    scheme: tuple | None = None  # (prepare, step) of a fixed-step scheme
    # Why the integrator cannot run a reading (formulation, coulomb_normal, flight), or None.
    unsupported_reading: Callable[[dict], str | None] = lambda readings: None
    # The record that runs in its place for (model, readings, parameters), or None: how an
    # integrator hands a structure it does not need to discover over to exact flows.
    hand_over: Callable[[str, dict, dict], "Integrator | None"] = lambda model, readings, parameters: None

    def run_advance(self, kind: int, flags: int, y, cnt, drv, prm, n_steps: int, track_energy: bool) -> int:
        return self.bind_advance(kind, flags, y, cnt, drv, prm)(n_steps, bool(track_energy))

    def run_observe(self, kind: int, flags: int, y, cnt, drv, prm, h: float, track_energy: bool, obs) -> None:
        self.bind_observe(kind, flags, y, cnt, drv, prm)(float(h), bool(track_energy), obs)

    def bind_advance(self, kind: int, flags: int, y, cnt, drv, prm) -> Callable:
        """The advance kernel's compiled entry point with the run's arrays bound:
        ``(n_steps, track_energy) -> status``.  Resolved once, it is called without any
        lookup or type resolution (a doStep's overhead, harness/benchmarks/fmi_boundary.py)."""
        args = (flags, y, cnt, drv, prm)
        return partial(_entry_point(self.advance, kind, self.id, (*args, 0, False)), kind, self.id, *args)

    def bind_observe(self, kind: int, flags: int, y, cnt, drv, prm) -> Callable:
        """The observe kernel bound likewise: ``(h, track_energy, obs)``."""
        args = (flags, y, cnt, drv, prm)
        return partial(_entry_point(self.observe, kind, self.id, (*args, 0.0, False, np.zeros(0))), kind, self.id,
                       *args)

    def supports(self, model: str) -> bool:
        return self.models == "*" or model in self.models

    def message(self, status: int, **where) -> str:
        text = self.statuses.get(status) or (NON_FINITE_MESSAGE if status == NON_FINITE
                                             else f"integrator {self.name} failed with status {status}")
        return text.format(integrator=self.name, **where)

    def budget_message(self, t: float, t_end: float, todo: int, dt: float, budget: int) -> str:
        """Why one call does not take ``todo`` > ``budget`` grid steps: an FMI master cannot
        interrupt a doStep, so a request of hours is refused with its cost and the ways round."""
        return (f"advancing from t = {t:g} to t = {t_end:g} takes {todo:.3g} internal steps of dt = {dt:g} with "
                f"{self.name} (hours: ~{todo / 1e8 / 3600:.2g} h or more at 1e8 steps/s); one call may take at most "
                f"{budget:.3g} steps so that a master is never held. Use shorter communication steps, or a larger "
                "dt with implicit_contact (no contact stiffness limit), or event_driven (model A); the state is kept.")


# (kernel, method) -> compiled entry point.  The kernels take ``method`` as a literal (a
# fixed-step scheme is inlined into its driver's loop) and ``kind`` -- the variant, the
# readings and the laws of the run -- as a plain integer: a run constant the kernels
# branch on, so one compilation serves every variant and reading.  Calling the
# dispatcher with a plain int for ``method`` would make numba retry the non-literal
# typing on every call (~0.1 s), so the specialization is compiled (or loaded from the
# cache) once and its entry point called directly.
_ENTRY_POINTS: dict = {}


def _entry_point(kernel, kind: int, method: int, args: tuple):
    """The compiled entry point of ``kernel`` for ``method`` and arguments typed like ``args``."""
    key = (kernel, method)
    entry = _ENTRY_POINTS.get(key)
    if entry is None:
        signature = (types.int64, types.literal(method), *(typeof(a) for a in args))
        kernel.compile(signature)
        entry = _ENTRY_POINTS[key] = kernel.overloads[signature].entry_point
    return entry


def _fixed_step(id, name, module, **record):
    fixed_step.register(id, module.prepare, module.step, getattr(module, "INLINE_STEP", True))
    return Integrator(id=id, name=name, advance=fixed_step.advance, observe=fixed_step.observe,
                      scheme=(module.prepare, module.step), **record)


_IMPLICIT_STATUSES = {
    implicit_contact.TOO_MANY_SWITCHES: (
        f"more than {implicit_contact.MAX_SEGMENTS} contact switches within one step of dt = {{dt:g}} between t = "
        "{t:g} and t = {t_end:g} ({integrator}): the contact chatters faster than the step resolves; the state at "
        "t = {t:g} is kept. Reduce dt."),
    implicit_contact.TOO_FAST_FOR_CORRUGATION: (
        "the block crosses the corrugation too fast for dt = {dt:g} between t = {t:g} and t = {t_end:g}: the "
        f"surface under it turns by more than {implicit_contact.MAX_TURN_PER_STEP} rad in one step "
        "({integrator}); the state at t = {t:g} is kept. Reduce dt."),
}

_ADAPTIVE_STATUSES = {
    adaptive.STEP_TOO_SMALL: (
        "the error-controlled step fell to rounding level between t = {t:g} and t = {t_end:g} ({integrator}): "
        "the tolerances cannot be met there; the state at t = {t:g} is kept. Loosen rtol/atol or check the "
        "parameters for extreme values. Under rate-and-state friction this is where the interface's slip runs "
        "away in finite time, k_t < (b - a) N_b / D_c (docs/physics.md, Sec. 5)."),
    adaptive.TOO_MANY_STEPS: (
        f"more than {adaptive.MAX_STEPS} internal steps between t = {{t:g}} and t = {{t_end:g}} ({{integrator}}; "
        "some 20 s of work): a master must not be held that long; the state at t = {t:g} is kept. Use "
        "shorter communication steps or looser rtol/atol (resolving each plate period over a long stick is "
        "what costs)."),
    adaptive.TOO_MANY_EVENTS: (
        f"more than {adaptive.MAX_IMMEDIATE} contact or friction switches in a row at one instant near t = "
        "{t:g} ({integrator}): the contact chatters; the state at t = {t:g} is kept."),
}

_RECORDS = (
    _fixed_step(0, "symplectic_euler", symplectic_euler,
                summary="the paper's first-order scheme (semi-implicit Euler)", models="*", force_evaluations=1,
                check_step=_spring_dashpot_limit(1.0)),
    _fixed_step(1, "rk4", rk4, summary="classical fourth-order Runge-Kutta", models="*", force_evaluations=4,
                check_step=_spring_dashpot_limit(4.0)),
    Integrator(2, "event_driven", "exact flows with located events (model A only)", models="A",
               force_evaluations=0, check_step=_undamped_resonance, advance=event_driven.advance,
               observe=event_driven.observe, splits_bitwise=False, unsupported_reading=lambda r: _event_driven_refuses(r)),
    _fixed_step(3, "implicit_contact", implicit_contact,
                summary="contact spring-dashpots in closed form, stiff-stable", models="*", force_evaluations=2,
                check_step=_implicit_contact_limit, statuses=_IMPLICIT_STATUSES,
                unsupported_reading=lambda r: (
                    "integrates the fixed-axes reading only (its closed-form contact flows, the frame's turning "
                    "terms and their energy accounting are written for a point in fixed axes), not formulation = 1 "
                    "(tangent_frame)" if r["formulation"] == 1 else
                    "follows the surface's frame in flight too (its flight segments are exact flows along the "
                    "frozen tangent), not flight = 1 (free)" if r["flight"] == 1 else None)),
    Integrator(4, "adaptive", "error-controlled steps with located events: explicit DOP853 where the motion is "
               "not stiff, stiff-stable RODAS4 where it is; on model A exact flows (option exact_flows)",
               models="*", force_evaluations=0, check_step=_tolerances, advance=adaptive.advance,
               observe=adaptive.observe, statuses=_ADAPTIVE_STATUSES, splits_bitwise=False,
               # (_exact_flows reads the finished registry: looked up when called)
               hand_over=lambda model, readings, parameters: _exact_flows(model, readings, parameters)),
    # adaptive runs every reading: the tangent frame through position_rates, the applied-load
    # bound through coulomb_bound in its event values, free flight with one frame per regime
    # (its module doc); tangent_frame + free flight is refused for every integrator (Settings).
)
INTEGRATOR_RECORDS: dict[str, Integrator] = {r.name: r for r in _RECORDS}
# adaptive where it hands over to exact flows: event_driven's kernels under adaptive's name
# (its messages name the integrator the user chose).
_ADAPTIVE_EXACT = replace(INTEGRATOR_RECORDS["event_driven"], name="adaptive", public=False,
                          summary="adaptive on model A: exact flows with located events")


def _exact_flows(model: str, readings: dict, parameters: dict) -> Integrator | None:
    """adaptive's hand-over on model A (its option ``exact_flows``).  Every regime of model A
    is linear with polynomial and harmonic forcing, so its exact flow is known in closed
    form; taking it costs per event, where error-controlled steps must resolve the friction
    spring's ringing and the plate's period in between (69x event_driven's time on a
    stick-slip run at equal accuracy 1e-6, README "adaptive, measured").  Where event_driven cannot run
    the reading (the applied-load bound) or the parameters (an undamped contact driven at
    resonance), adaptive keeps its own steps."""
    exact = INTEGRATOR_RECORDS["event_driven"]
    if (not exact.supports(model) or exact.unsupported_reading(readings) or _refused_by_a_law(exact, readings)
            or exact.check_step(parameters, model, exact.name)):
        return None
    return _ADAPTIVE_EXACT


def _refused_by_a_law(record: Integrator, readings: dict) -> bool:
    """Whether one of the run's laws refuses ``record`` (e.g. rate-and-state friction, whose
    interface event_driven's closed forms do not follow: adaptive keeps its own steps)."""
    return any(record.name in law(axis.name, readings.get(axis.parameter, 0)).refused_by for axis in AXES.values())


BY_ID: dict[int, Integrator] = {r.id: r for r in _RECORDS}
# name -> FMU id of the integrators users choose from
INTEGRATORS: dict[str, int] = {r.name: r.id for r in _RECORDS if r.public}


def _register_reduced_scene() -> Integrator:
    """The scheme that runs a scene with reductions (``vibroblock.scenes``): internal,
    chosen by the scene options, not by ``integrator``."""
    from .. import scenes  # imports fixed_step, so it comes after this package's own modules
    record = Integrator(scenes.SCHEME_ID, "reduced_scene", "scene reductions, first order", models="*",
                        force_evaluations=1, check_step=_no_limit, advance=fixed_step.advance,
                        observe=scenes.observe, public=False, scheme=(scenes.prepare, scenes.step))
    fixed_step.register(scenes.SCHEME_ID, scenes.prepare, scenes.step, scenes.INLINE_STEP)
    BY_ID[scenes.SCHEME_ID] = record
    return record


REDUCED_SCENE = _register_reduced_scene()


def integrator(name_or_id) -> Integrator:
    """The record of a public integrator, by name or FMU id."""
    if isinstance(name_or_id, str):
        record = INTEGRATOR_RECORDS.get(name_or_id)
    else:
        record = BY_ID.get(int(name_or_id))
    if record is None or not record.public:
        raise KeyError(name_or_id)
    return record


__all__ = ["INTEGRATORS", "INTEGRATOR_RECORDS", "BY_ID", "Integrator", "integrator", "REDUCED_SCENE", "OK", "STOP",
           "NON_FINITE"]
