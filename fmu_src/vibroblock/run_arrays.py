"""The arrays of a run (``layout``): made at the start, retuned with the drive, saved and
restored whole (the FMU state), handed to the kernels as they are."""
from __future__ import annotations

import math

import numpy as np

from . import layout as L
from .integrators.plate import reduced_phase
from .laws import initial_friction_state, law
from .settings import ModelError


def fresh(parameters: dict, t0: float, readings: dict):
    """(y, cnt, drv, prm) at the start time t0: the parameters in their slots, the clock
    and the drive (its phase reduced exactly), the counters zero, the state zero but for
    the friction law's own (``readings`` choose the law)."""
    prm = np.zeros(L.N_PRM)
    for name, index in L.prm_slots().items():
        prm[index] = parameters.get(name, 0.0)
    drv = np.zeros(L.N_DRV)
    drv[L.D_T0], drv[L.D_DT] = t0, parameters["dt"]
    drv[L.D_AMP], drv[L.D_AMP_X] = plate_law(readings).amplitudes(parameters["A"], parameters.get("drive_angle", 0.0))
    drv[L.D_OMEGA] = parameters["omega"]
    drv[L.D_PHASE], drv[L.D_EXT_T] = reduced_phase(0.0, parameters["omega"], t0), t0
    y = np.zeros(L.N_Y)
    y[L.Y_FRICTION_STATE] = initial_friction_state(readings, parameters)
    return y, np.zeros(L.N_CNT, dtype=np.int64), drv, prm


def plate_law(readings: dict):
    """The module of the run's plate law (``laws``: plate)."""
    return law("plate", int(readings.get("plate_motion", 0))).module


def retune_drive(cnt, drv, parameters: dict, readings: dict) -> None:
    """Take the parameters' A and omega from the current grid step on, keeping the phase
    continuous: the phase is re-anchored there."""
    n = cnt[L.C_STEP]
    step_rate = drv[L.D_OMEGA] * drv[L.D_DT]  # the kernels' phase per grid step
    phase = reduced_phase(drv[L.D_PHASE], step_rate, n - cnt[L.C_PHASE_STEP])
    drv[L.D_PHASE], cnt[L.C_PHASE_STEP] = phase, n
    drv[L.D_AMP], drv[L.D_AMP_X] = plate_law(readings).amplitudes(parameters["A"], parameters.get("drive_angle", 0.0))
    drv[L.D_OMEGA] = parameters["omega"]


def check_plate_input(values, readings: dict | None = None) -> None:
    """Refuse an input that is not finite, or a horizontal one where the run's plate law
    moves the plate vertically only.  ``values`` = (z, v, a[, x, vx, ax])."""
    values = dict(zip(("plate_z", "plate_v", "plate_a", "plate_x", "plate_vx", "plate_ax"), values))
    for name, value in values.items():
        if not math.isfinite(value):
            raise ModelError(f"input {name} = {value!r} is not finite; the previous input is kept")
    x, vx, ax = (values.get(name, 0.0) for name in ("plate_x", "plate_vx", "plate_ax"))
    if not plate_law(readings or {}).SIDEWAYS and (x, vx, ax) != (0.0, 0.0, 0.0):
        moving = ", ".join(f"{name} = {values[name]:g}" for name in ("plate_x", "plate_vx", "plate_ax")
                           if values[name] != 0.0)
        raise ModelError(f"input {moving}: the plate moves vertically only under plate_motion = 0; set "
                         f"plate_motion = 1 (oblique) before the start to shake it horizontally; the previous "
                         f"input is kept")


def set_plate_input(drv, time: float, z: float, v: float, a: float, x: float = 0.0, vx: float = 0.0,
                    ax: float = 0.0) -> None:
    """External plate motion from ``time`` on: z + v tau + a tau^2 / 2 and, under the
    oblique plate law, x + vx tau + ax tau^2 / 2 (``Block.set_plate_input``)."""
    drv[L.D_EXT_Z], drv[L.D_EXT_V], drv[L.D_EXT_A], drv[L.D_EXT_T] = z, v, a, time
    drv[L.D_EXT_X], drv[L.D_EXT_VX], drv[L.D_EXT_AX] = x, vx, ax


def counters(cnt) -> dict[str, int]:
    """The run's cost counters by name (``Block.counters``)."""
    return {"steps": int(cnt[L.C_STEP]), "resets": int(cnt[L.C_SLIPS]), "events": int(cnt[L.C_EVENTS]),
            "rejected": int(cnt[L.C_REJECTED]), "accepted": int(cnt[L.C_ACCEPTED]),
            "jacobians": int(cnt[L.C_JACOBIANS]), "periods_jumped": int(cnt[L.C_JUMPED])}


def saved(y, cnt, drv, prm) -> dict:
    """The arrays as plain (JSON-able) values."""
    return {"y": y.tolist(), "cnt": cnt.tolist(), "drv": drv.tolist(), "prm": prm.tolist()}


def restored(state: dict):
    """(y, cnt, drv, prm) from ``saved``'s values; ModelError if they are not a run's."""
    try:
        y = np.array(state["y"], dtype=float)
        cnt = np.array(state["cnt"], dtype=np.int64)
        drv = np.array(state["drv"], dtype=float)
        prm = np.array(state["prm"], dtype=float)
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelError(f"not a valid block state: {exc}") from None
    if (y.shape, cnt.shape, drv.shape, prm.shape) != ((L.N_Y,), (L.N_CNT,), (L.N_DRV,), (L.N_PRM,)):
        raise ModelError("not a valid block state: array sizes differ from this model's")
    return y, cnt, drv, prm
