"""A doStep and output reads that do not enter Python: the kernels as C functions.

Through pythonfmu every doStep is a Python call (GIL, frames, the numba entry point
unboxing four arrays): about 1.3 us, a tenth of a doStep of a thousand internal steps
of model A (``harness/benchmarks/fmi_boundary.py``).  The FMU's native front end
(``build/python_runtime.c``) can do without it.  A ``Block`` that a front end drives
keeps a ``NativeStep`` record up to date: the C address of its integrator's advance
kernel compiled as a numba ``cfunc`` for the run's model and reading, its state arrays,
its time grid and the checks a doStep makes.  The front end reads the record, makes
the same checks as ``Block.advance_to`` and calls the kernel with the same arguments,
so the state advances bit for bit as through Python.  Everything else -- set-up, inputs,
outputs, FMU state, logging, and any doStep that does not simply succeed -- stays with
the Python slave: the front end then calls the slave's do_step, which finds the state
as the failed kernel call left it (contract rule 4 of ``vibroblock.integrators``) and
says what went wrong.

Reading outputs after each doStep is the other call a master makes all the time; through
pythonfmu a read of five outputs is a Python call that builds the whole observation
(about 7 us).  The record therefore also carries the observe kernel as a cfunc, the
Block's observation array and a table of the outputs that are plain entries of that
observation: (value reference, observation slot) pairs, or one of the two outputs
computed from it (``SURFACE_Z``, ``ZERO``).  pythonfmu numbers the variables of all
types in one sequence, so one table serves fmi2GetReal, fmi2GetInteger and
fmi2GetBoolean; the front end checks a reference's type against the model description
before it looks in the table.  A front end asked for outputs that are all in the table
fills them from one observe call, with the same arithmetic as ``Block._observables``
(an Integer truncated, a Boolean true where the slot is not 0); any other read goes to
the slave.

The record is laid out as ``NativeStep`` in ``build/python_runtime.c``; ``LAYOUT``
names the version both sides check.
"""
from __future__ import annotations

import ctypes
import math

import numpy as np

from . import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import carray, cfunc, types  # noqa: E402

from . import layout as L  # noqa: E402
from .integrators import adaptive, event_driven, fixed_step  # noqa: E402
from . import scenes  # noqa: E402  (after the integrators, which register its scheme)
from .observation import maps_to_point  # noqa: E402

LAYOUT = 3  # bump with any change of NativeStep's fields

# Sources of a native output other than an observation slot (``layout.O_*``): the plate
# surface under the block, z + penetration / cos(alpha); and an output that is 0 in this
# run (energy_residual without the energy balance).
SURFACE_Z, ZERO = -1, -2

# A cfunc whose kernel raised returns 0 (numba zero-fills the result, prints the
# exception and carries on), so the kernel's status is returned shifted: 0 is never a
# status the kernel gave.
STATUS_SHIFT = 1 << 20
RETURNED_OK = STATUS_SHIFT + fixed_step.OK
OBSERVED_OK = STATUS_SHIFT  # what an observe entry returns (a kernel that raised: 0)

_F64, _I64 = types.CPointer(types.float64), types.CPointer(types.int64)
# (kind, flags, y, cnt, drv, prm, n_steps, track_energy) -> status + STATUS_SHIFT
SIGNATURE = types.int64(types.int64, types.int64, _F64, _I64, _F64, _F64, types.int64, types.int64)
# (kind, flags, y, cnt, drv, prm, h, track_energy, obs) -> STATUS_SHIFT when obs is filled
OBSERVE_SIGNATURE = types.int64(types.int64, types.int64, _F64, _I64, _F64, _F64, types.float64, types.int64, _F64)


class NativeStep(ctypes.Structure):
    """What a front end needs to run a doStep without Python.  ``ready`` is set by the
    Block once a run has started and its kernels are bound; ``held`` by the FMU slave
    while an input waits to be applied (both 0: the next doStep may go native)."""
    _fields_ = [
        ("layout", ctypes.c_int64),
        ("ready", ctypes.c_int64),
        ("held", ctypes.c_int64),
        ("advance", ctypes.c_void_p),  # SIGNATURE
        ("returned_ok", ctypes.c_int64),  # what advance returns when the kernel finished
        ("kind", ctypes.c_int64),  # the run's variant, readings and laws (vibroblock.readings)
        ("flags", ctypes.c_int64),
        ("y", ctypes.c_void_p),
        ("cnt", ctypes.c_void_p),
        ("drv", ctypes.c_void_p),
        ("prm", ctypes.c_void_p),
        ("step_slot", ctypes.c_int64),  # cnt[step_slot] is the grid index
        ("track_energy", ctypes.c_int64),
        ("step_budget", ctypes.c_double),  # grid steps one call may take
        ("t0", ctypes.c_double),
        ("dt", ctypes.c_double),
        ("time", ctypes.c_double),  # the Block's time: read and written by both sides
        ("grid_tolerance", ctypes.c_double),  # Block.advance_to's rounding to the grid
        ("time_tolerance", ctypes.c_double),  # the slave's match of a master's time to its own
        ("observe", ctypes.c_void_p),  # OBSERVE_SIGNATURE, or NULL: every read goes to the slave
        ("observed_ok", ctypes.c_int64),  # what observe returns when it filled obs
        ("obs", ctypes.c_void_p),  # the Block's observation array (layout.N_OBS)
        ("outputs", ctypes.c_void_p),  # int64 pairs (value reference, slot or SURFACE_Z / ZERO)
        ("n_outputs", ctypes.c_int64),
    ]


# The outputs that are plain entries of the observation in every reading: a native front
# end may read them without Python (``Block._observables`` is the reference).  The Boolean
# contact and the Integer coulomb_resets (and its old name slip_count) are stored as 0.0/1.0
# and a whole count; the front end converts them as _observables does (!= 0, truncation).
OBSERVED_OUTPUTS = {"x": L.O_X, "friction_force": L.O_FRICTION, "normal_force": L.O_NORMAL,
                    "phi_integral": L.O_PHI, "penetration": L.O_PENETRATION, "work_input": L.O_WORK,
                    "energy_dissipated": L.O_DISSIPATED, "contact": L.O_CONTACT, "coulomb_resets": L.O_SLIPS,
                    "slip_count": L.O_SLIPS}
# ... and in the model's own reading, where the state is the point itself (in another
# reading in fixed axes, all but the surface, which ``observation.as_point`` forms).
OBSERVED_POINT = {"z": L.O_Z, "vx": L.O_VX, "vz": L.O_VZ, "surface_z": SURFACE_Z}


class NativeLink:
    """A Block's side of the native front end: the ``NativeStep`` record it keeps up to date
    (its time lives there, also when no front end drives it), and the outputs the front
    end may read."""

    def __init__(self, grid_tolerance: float):
        self.record = NativeStep(layout=LAYOUT, returned_ok=RETURNED_OK, observed_ok=OBSERVED_OK,
                                 step_slot=L.C_STEP, grid_tolerance=grid_tolerance, time=math.nan)
        self.driven = False
        self.output_refs: dict[str, int] = {}
        self.outputs = np.zeros((0, 2), dtype=np.int64)  # kept alive while the record points at it

    def attach(self, record: NativeStep, time_tolerance: float, output_refs: dict | None) -> None:
        """Let a front end drive the block through ``record`` (its time moves there), with
        ``time_tolerance`` the front end's match of a master's time to the block's.  The
        record takes over the block's time; a record already driving another block is
        simply re-pointed at this one.  The caller binds its kernels again."""
        record.time, record.time_tolerance = self.record.time, time_tolerance
        self.output_refs = dict(output_refs or {})
        for name in ("layout", "returned_ok", "observed_ok", "step_slot", "grid_tolerance"):
            setattr(record, name, getattr(self.record, name))
        self.record, self.driven = record, True
        record.ready = 0

    def publish(self, block) -> None:
        """Point the record at the block's bound kernel and arrays; ready once the run has
        started."""
        record = self.record
        record.ready = 0
        if not (self.driven and block.started):
            return
        settings, kernel = block.settings, block._kernel
        entry = entry_address(kernel.advance, kernel.id)
        record.advance = entry
        record.kind = settings.kind
        record.flags = settings.scene_flags(block.frozen_released)
        record.y, record.cnt, record.drv, record.prm = (a.ctypes.data for a in (block.y, block.cnt, block.drv,
                                                                                block.prm))
        record.track_energy = int(block._track_energy)
        record.step_budget = block._step_budget
        record.t0, record.dt = block._grid
        record.observe = entry_address(kernel.observe, kernel.id)
        record.obs = block.obs.ctypes.data
        self.outputs = self._observed_outputs(block)
        record.outputs, record.n_outputs = self.outputs.ctypes.data, len(self.outputs)
        record.ready = int(entry is not None)

    def _observed_outputs(self, block) -> np.ndarray:
        """(value reference, observation slot or SURFACE_Z / ZERO) of each output a front
        end may read straight from the observation in this run."""
        sources = dict(OBSERVED_OUTPUTS)
        if not maps_to_point(block.settings):
            sources.update(OBSERVED_POINT)
        elif not block.settings.tangent_frame:  # observation.as_point leaves the fixed axes' z, vx, vz as they are
            sources.update({name: source for name, source in OBSERVED_POINT.items() if source != SURFACE_Z})
        if not block.energy_balance:
            sources["energy_residual"] = ZERO
        pairs = [(self.output_refs[name], source) for name, source in sources.items() if name in self.output_refs]
        return np.array(pairs, dtype=np.int64).reshape(-1, 2)


# The kernel families with a C entry.  A cfunc names its kernel in the body (a global),
# not captured: numba keys a cached cfunc by its closure's values, which must be plain
# numbers to be found again by the next process.  So one factory per signature holds
# the family and the method (the kernels take it as a literal; kind is an argument, so
# one cfunc serves every variant, reading and law), and the branches of the families not
# taken are pruned when the cfunc is compiled.
FIXED_STEP, EVENT_DRIVEN, ADAPTIVE, SCENES = 0, 1, 2, 3


def _advance_entry(family: int, method: int):
    @cfunc(SIGNATURE, cache=True)
    def advance(kind, flags, y_ptr, cnt_ptr, drv_ptr, prm_ptr, n_steps, track_energy):
        y, cnt = carray(y_ptr, L.N_Y), carray(cnt_ptr, L.N_CNT)
        drv, prm, energy = carray(drv_ptr, L.N_DRV), carray(prm_ptr, L.N_PRM), track_energy != 0
        if family == 0:  # FIXED_STEP
            status = fixed_step.advance(kind, method, flags, y, cnt, drv, prm, n_steps, energy)
        elif family == 1:  # EVENT_DRIVEN
            status = event_driven.advance(kind, method, flags, y, cnt, drv, prm, n_steps, energy)
        else:
            status = adaptive.advance(kind, method, flags, y, cnt, drv, prm, n_steps, energy)
        return STATUS_SHIFT + status
    return advance


def _observe_entry(family: int, method: int):
    @cfunc(OBSERVE_SIGNATURE, cache=True)
    def observe(kind, flags, y_ptr, cnt_ptr, drv_ptr, prm_ptr, h, track_energy, obs_ptr):
        y, cnt, obs = carray(y_ptr, L.N_Y), carray(cnt_ptr, L.N_CNT), carray(obs_ptr, L.N_OBS)
        drv, prm, energy = carray(drv_ptr, L.N_DRV), carray(prm_ptr, L.N_PRM), track_energy != 0
        if family == 0:  # FIXED_STEP
            fixed_step.observe(kind, method, flags, y, cnt, drv, prm, h, energy, obs)
        elif family == 1:  # EVENT_DRIVEN
            event_driven.observe(kind, method, flags, y, cnt, drv, prm, h, energy, obs)
        elif family == 2:  # ADAPTIVE
            adaptive.observe(kind, method, flags, y, cnt, drv, prm, h, energy, obs)
        else:
            scenes.observe(kind, method, flags, y, cnt, drv, prm, h, energy, obs)
        return OBSERVED_OK
    return observe


# kernel -> (factory, family); the family numbers are the branches above
_FACTORIES = {fixed_step.advance: (_advance_entry, FIXED_STEP), event_driven.advance: (_advance_entry, EVENT_DRIVEN),
              adaptive.advance: (_advance_entry, ADAPTIVE), fixed_step.observe: (_observe_entry, FIXED_STEP),
              event_driven.observe: (_observe_entry, EVENT_DRIVEN), adaptive.observe: (_observe_entry, ADAPTIVE),
              scenes.observe: (_observe_entry, SCENES)}
_ENTRIES: dict = {}  # (kernel, method) -> cfunc, kept alive with its code


def entry_address(kernel, method: int) -> int | None:
    """The C address of ``kernel`` (an advance or observe kernel) for ``method``, compiled
    or loaded from the cache once per process; None for a kernel without a C entry."""
    key = (kernel, method)
    if key not in _ENTRIES:
        factory, family = _FACTORIES.get(kernel, (None, None))
        try:
            _ENTRIES[key] = factory(family, method) if factory is not None else None
        except Exception:  # noqa: BLE001 - no C entry is no error: every doStep goes through Python
            _ENTRIES[key] = None
    entry = _ENTRIES[key]
    return entry.address if entry is not None else None
