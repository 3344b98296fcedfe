"""A kernel's view of its run arrays without numba's reference counting.

numba counts references to an array each time it is passed on, and inside a loop that
branches on the run's laws (``dispatch``) it cannot always drop the counting: every
step then pays atomic increments and decrements, which cost the fixed-step kernels up
to 3x their speed.  An entry kernel therefore reads its parameter, drive and counter
arrays through a raw pointer to their data, which numba indexes like the array and
does not count.  The arrays stay owned by the caller (``Block``, the FMU), which keeps
them alive for the whole call.
"""
from __future__ import annotations

from . import jitcache  # noqa: F401  (before numba: the kernel cache's folder and locator)
from numba import carray, njit, types  # noqa: E402
from numba.extending import intrinsic, overload  # noqa: E402


@intrinsic
def data_pointer(typingctx, array):
    """``array``'s data as a ``CPointer`` of its element type (1-D C-contiguous arrays):
    ``p[i]`` reads and writes ``array[i]``, with no bounds check and no reference count."""
    if not (isinstance(array, types.Array) and array.ndim == 1 and array.layout == "C"):
        return None

    def codegen(context, builder, signature, args):
        return context.make_array(array)(context, builder, value=args[0]).data

    return types.CPointer(array.dtype)(array), codegen


@intrinsic
def row_pointer(typingctx, array, row):
    """Row ``row`` of a 2-D C-contiguous ``array`` as a ``CPointer`` (``p[j]`` is
    ``array[row, j]``): one block's slots of a chain's per-block arrays, handed to the
    single block's functions as if they were that block's own 1-D arrays."""
    if not (isinstance(array, types.Array) and array.ndim == 2 and array.layout == "C"
            and isinstance(row, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(array)(context, builder, value=args[0])
        columns = builder.extract_value(data.shape, 1)
        index = context.cast(builder, args[1], row, types.intp)
        return builder.gep(data.data, [builder.mul(index, columns)])

    return types.CPointer(array.dtype)(array, row), codegen


@intrinsic
def _data_of(typingctx, array):
    """The data of a C-contiguous array of any rank as a ``CPointer`` of its element type."""
    if not (isinstance(array, types.Array) and array.layout == "C"):
        return None

    def codegen(context, builder, signature, args):
        return context.make_array(array)(context, builder, value=args[0]).data

    return types.CPointer(array.dtype)(array), codegen


@njit(inline="always")
def unowned(array):
    """A view of ``array`` (C-contiguous, any rank) that numba does not count: its views and
    the calls it is passed to take no atomic reference counts.  The caller keeps ``array``
    alive (``keep_alive``) for as long as the view is used."""
    return carray(_data_of(array), array.shape)


def unowned_each(values):
    """``values`` (a tuple) with each C-contiguous array in it replaced by its ``unowned``
    view and every other item passed through (compiled code only)."""


def _unowned_or_same(value):
    """``unowned(value)`` for an array, ``value`` itself for anything else."""


@overload(_unowned_or_same, inline="always")
def _unowned_or_same_of(value):
    if isinstance(value, types.Array):
        return lambda value: unowned(value)
    return lambda value: value


@overload(unowned_each, inline="always")
def _unowned_each_of(values):
    if not isinstance(values, types.BaseTuple):
        return lambda values: values
    # One expression per item: numba builds the tuple from the items' own types.
    items = ", ".join(f"_unowned_or_same(values[{i}])" for i in range(len(values))) + ","
    scope = {"_unowned_or_same": _unowned_or_same}
    exec(f"def each(values):\n    return ({items})", scope)
    return scope["each"]


@intrinsic
def keep_alive(typingctx, owner):
    """A use of ``owner`` that emits no code: numba frees an array after its last use, so an
    array read through an ``unowned`` view must be used again after the view's last read."""
    def codegen(context, builder, signature, args):
        return context.get_dummy_value()

    return types.none(owner), codegen
