"""The NativeStep record: what a native front end reads to advance a Block without Python.

The front end itself (build/python_runtime.c) is exercised through the FMUs in
tests/fmu_src/test_block_fmus.py; here the record's contract: its kernel, called with
its own fields, advances the block exactly as ``advance_to`` does, and the record
follows the block (not ready before the start, re-pointed when the arrays change).
"""
import ctypes
import math

import numpy as np
import pytest

from vibroblock import Block
from vibroblock import layout as L
from vibroblock.native import RETURNED_OK, STATUS_SHIFT, NativeStep

ADVANCE = ctypes.CFUNCTYPE(ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                           ctypes.c_void_p, ctypes.c_int64, ctypes.c_int64)

CASES = [
    ("A", "symplectic_euler", {"A": 0.6, "omega": 1.3}),
    ("A", "event_driven", {"A": 0.6, "omega": 1.3}),
    ("B", "rk4", {"A": 0.2, "omega": 0.7}),
    ("C", "implicit_contact", {"A": 0.2, "omega": 0.7}),
    ("C", "adaptive", {"A": 0.3, "omega": 0.85, "formulation": 1, "coulomb_normal": 1}),
    ("A", "symplectic_euler", {"A": 0.02, "omega": 0.5, "frozen_vertical": True}),
]


def driven(model, integrator, options, energy=False):
    record = NativeStep()
    block = Block(model, integrator, 2, energy, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, **options)
    block.drive_natively(record, 1e-9)
    return block, record


def native_advance(record: NativeStep, t_end: float) -> int:
    """What the front end does for a doStep that ends at t_end: the kernel's status."""
    assert record.ready and not record.held
    cnt = np.ctypeslib.as_array(ctypes.cast(record.cnt, ctypes.POINTER(ctypes.c_int64)), (L.N_CNT,))
    target = math.floor((t_end - record.t0) / record.dt + record.grid_tolerance)
    status = ADVANCE(record.advance)(record.flags, record.y, record.cnt, record.drv, record.prm,
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
