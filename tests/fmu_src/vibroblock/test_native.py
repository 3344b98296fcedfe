"""The NativeStep record: what a native front end reads to advance a Block and read its
outputs without Python.

The front end itself (build/python_runtime.c) is exercised through the FMUs in
tests/fmu_src/test_block_fmus.py; here the record's contract: its kernel, called with
its own fields, advances the block exactly as ``advance_to`` does; its observe kernel
and output table give the block's outputs bit for bit; and the record follows the
block (not ready before the start, re-pointed when the arrays change).
"""
import ctypes
import math

import numpy as np
import pytest

from vibroblock import Block
from vibroblock import layout as L
from vibroblock.interface import OUTPUTS
from vibroblock.native import RETURNED_OK, STATUS_SHIFT, SURFACE_Z, ZERO, NativeStep

ADVANCE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                           ctypes.c_void_p, ctypes.c_int64, ctypes.c_int64)
OBSERVE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                           ctypes.c_void_p, ctypes.c_double, ctypes.c_int64, ctypes.c_void_p)
# Value references as an FMU would give them (any distinct numbers).
REFS = {name: 100 + i for i, name in enumerate(OUTPUTS)}
REAL_OUTPUTS = [name for name, (kind, *_) in OUTPUTS.items() if kind == "Real"]

CASES = [
    ("A", "symplectic_euler", {"A": 0.6, "omega": 1.3}),
    ("A", "event_driven", {"A": 0.6, "omega": 1.3}),
    ("B", "rk4", {"A": 0.2, "omega": 0.7}),
    ("C", "implicit_contact", {"A": 0.2, "omega": 0.7}),
    ("C", "adaptive", {"A": 0.3, "omega": 0.85, "formulation": 1, "coulomb_normal": 1}),
    ("A", "symplectic_euler", {"A": 0.02, "omega": 0.5, "frozen_vertical": True}),
    ("A", "symplectic_euler", {"A": 0.6, "omega": 1.3, "coulomb_normal": 2}),
    ("B", "rk4", {"A": 0.2, "omega": 0.7, "coulomb_normal": 1}),
]


def driven(model, integrator, options, energy=False, refs=None):
    record = NativeStep()
    block = Block(model, integrator, 2, energy, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, **options)
    block.drive_natively(record, 1e-9, refs)
    return block, record


def as_array(address, ctype, shape):
    return np.ctypeslib.as_array(ctypes.cast(address, ctypes.POINTER(ctype)), shape)


def native_read(record: NativeStep) -> dict:
    """What the front end does for a read of every output in the record's table:
    {value reference: value} from one observe call."""
    assert record.ready and record.observe
    cnt = as_array(record.cnt, ctypes.c_int64, (L.N_CNT,))
    h = record.time - (record.t0 + cnt[record.step_slot] * record.dt)
    if h < record.grid_tolerance * record.dt:
        h = 0.0
    status = OBSERVE(record.observe)(record.kind, record.flags, record.y, record.cnt, record.drv, record.prm, min(h, record.dt),
                                     record.track_energy, record.obs)
    assert status == record.observed_ok
    obs = as_array(record.obs, ctypes.c_double, (L.N_OBS,))
    values = {}
    for vr, source in as_array(record.outputs, ctypes.c_int64, (record.n_outputs, 2)).tolist():
        assert source in (*range(L.N_OBS), SURFACE_Z, ZERO)
        values[vr] = (obs[source] if source >= 0 else 0.0 if source == ZERO
                      else obs[L.O_Z] + obs[L.O_PENETRATION] / obs[L.O_COS])
    return values


def native_advance(record: NativeStep, t_end: float) -> int:
    """What the front end does for a doStep that ends at t_end: the kernel's status."""
    assert record.ready and not record.held
    cnt = np.ctypeslib.as_array(ctypes.cast(record.cnt, ctypes.POINTER(ctypes.c_int64)), (L.N_CNT,))
    target = math.floor((t_end - record.t0) / record.dt + record.grid_tolerance)
    status = ADVANCE(record.advance)(record.kind, record.flags, record.y, record.cnt, record.drv, record.prm,
                                     target - int(cnt[record.step_slot]), record.track_energy)
    if status == RETURNED_OK:
        record.time = t_end
    return status - STATUS_SHIFT


@pytest.mark.parametrize("model, integrator, options", CASES)
def test_the_records_kernel_advances_as_advance_to(model, integrator, options):
    python, _ = driven(model, integrator, options, energy=True)
    native, record = driven(model, integrator, options, energy=True)
    assert not record.ready  # before the start nothing may run
    for block in (python, native):
        block.start()
    assert record.ready and record.advance and record.time == 0.0
    for k in range(1, 40):
        t_end = 0.5 * k
        python.advance_to(t_end)
        assert native_advance(record, t_end) == 0
        assert native.time == t_end  # the block reads its time from the record
        assert native.outputs() == python.outputs()  # and refreshes its outputs with it
    assert native.get_state() == python.get_state()


@pytest.mark.parametrize("model, integrator, options", CASES)
@pytest.mark.parametrize("energy", [False, True])
def test_the_records_observation_gives_the_outputs(model, integrator, options, energy):
    """Read through the record at grid points and between them, every output the table
    names has the bits of ``Block.outputs`` (the Boolean contact and the Integer
    slip_count converted as the front end does).  It names them all in the model's own
    reading, except the energy residual with the energy balance on (a sum Python forms);
    in the tangent frame not the block's height and velocities nor the surface under it,
    which Python converts from the frame's state; in another reading in fixed axes (a
    Coulomb bound here) all but the surface, which Python forms from the profile."""
    block, record = driven(model, integrator, options, energy, REFS)
    block.start()
    formed_by_python = ({"z", "vx", "vz", "surface_z"} if options.get("formulation") == 1
                        else {"surface_z"} if options.get("coulomb_normal") else set())
    served = {name for name in [*REAL_OUTPUTS, "contact", "coulomb_resets", "slip_count"]
              if name not in formed_by_python and not (energy and name == "energy_residual")}
    convert = {"contact": lambda v: v != 0.0, "coulomb_resets": int, "slip_count": int}
    normal_forces = []
    for t_end in (0.5, 0.7301, 2.0, 7.3105, 12.5):  # dt = 4e-4 (the default): two ends between grid points
        block.advance_to(t_end)
        outputs = block.outputs()
        read = native_read(record)
        assert {vr: convert.get(name, float)(read[vr]) for name, vr in REFS.items() if vr in read} == {
            REFS[name]: outputs[name] for name in served}
        assert type(outputs["contact"]) is bool and type(outputs["slip_count"]) is int
        normal_forces.append(outputs["normal_force"])
    assert max(normal_forces) > 0.0  # some reads in contact


def test_a_record_without_output_references_serves_no_reads():
    block, record = driven("A", "symplectic_euler", {"A": 0.6, "omega": 1.3})
    block.start()
    assert record.ready and record.n_outputs == 0


def test_a_guard_that_stops_the_kernel_is_reported_to_the_front_end():
    """frozen_vertical's guard stops the kernel when the block would detach: not
    RETURNED_OK, so the front end leaves the doStep to Python, which continues from the
    steps taken, hands over, and re-points the record at the full model's kernel."""
    block, record = driven("A", "symplectic_euler", {"A": 0.02, "omega": 0.5, "frozen_vertical": True})
    block.start()
    frozen = record.flags
    block.set_parameter("A", 6.0)  # A omega^2 = 1.5 g: the plate now throws the block
    status = native_advance(record, 40.0)
    assert status == 1  # STOP
    assert record.time == 0.0 < block.grid_step  # steps taken, time left to Python
    block.advance_to(40.0)
    assert block.frozen_released and record.ready and record.flags != frozen and record.time == 40.0


def test_a_failing_kernel_leaves_the_state_and_says_so():
    block, record = driven("B", "adaptive", {"A": 0.2, "omega": 0.7, "rtol": 1e-6, "atol": 1e-8})
    block.start()
    block.advance_to(1.0)
    state = block.get_state()
    block.prm[L.P_KN] = math.nan  # a kernel failure (non-finite state), not a refused request
    assert native_advance(record, 2.0) < 0
    block.prm[L.P_KN] = state["prm"][L.P_KN]
    assert block.get_state() == state


def test_the_record_follows_the_arrays_and_moves_to_a_new_block():
    block, record = driven("C", "symplectic_euler", {"A": 0.2, "omega": 0.7})
    block.start()
    block.advance_to(3.0)
    saved = block.get_state()
    block.advance_to(6.0)
    block.set_state(saved)  # new arrays
    assert record.y == block.y.ctypes.data and record.cnt == block.cnt.ctypes.data and record.time == 3.0
    other = Block("C", A=0.2, omega=0.7)
    other.drive_natively(record, 1e-9)  # as an FMU state restore does
    assert not record.ready and math.isnan(record.time)
    other.set_state(saved)
    assert record.ready and record.y == other.y.ctypes.data and record.time == 3.0


def test_a_block_without_a_front_end_keeps_its_own_time():
    block = Block("A")
    block.start()
    block.advance_to(2.0)
    assert block.time == 2.0 and not block._native.ready
