"""The kernels' raw view of their run arrays (``vibroblock.unowned``)."""
import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from vibroblock.unowned import data_pointer, keep_alive, row_pointer, unowned, unowned_each


@njit
def _sum_and_bump(values, counts):
    """Reads ``values`` and increments ``counts`` through their data pointers."""
    v, c = data_pointer(values), data_pointer(counts)
    total = 0.0
    for i in range(values.size):
        total += v[i]
        c[i] += 1
    return total


def test_the_pointer_reads_and_writes_the_arrays_own_data():
    values = np.array([0.5, 1.25, -3.0, 1e300])
    counts = np.array([7, 0, -2, 5], dtype=np.int64)
    assert _sum_and_bump(values, counts) == values.sum()
    assert counts.tolist() == [8, 1, -1, 6]


@njit
def _first(values):
    return data_pointer(values)[0]


def test_a_strided_array_is_refused_at_compile_time():
    """A pointer to a view's data would read the base array's elements, not the view's."""
    with pytest.raises(TypingError):
        _first(np.arange(6.0)[::2])


@njit
def _bump_row(table, row):
    """Doubles every slot of one row through its row pointer."""
    p = row_pointer(table, row)
    for j in range(table.shape[1]):
        p[j] *= 2.0


def test_a_row_pointer_reaches_that_row_and_no_other():
    table = np.arange(12.0).reshape(3, 4)
    _bump_row(table, 1)
    assert table.tolist() == [[0.0, 1.0, 2.0, 3.0], [8.0, 10.0, 12.0, 14.0], [8.0, 9.0, 10.0, 11.0]]


def test_a_row_pointer_of_a_transposed_table_is_refused():
    with pytest.raises(TypingError):
        _bump_row(np.arange(12.0).reshape(3, 4).T, 0)


@njit
def _fill_through_views(rows, columns):
    """Allocates a table, writes it through an unowned view's row views, returns the owner."""
    owner = np.zeros((rows, columns))
    table = unowned(owner)
    for r in range(rows):
        row = table[r]  # a view of the unowned view: no reference count taken
        for c in range(columns):
            row[c] = 10.0 * r + c
    keep_alive(owner)
    return owner


def test_an_unowned_view_reads_and_writes_its_owners_data():
    assert _fill_through_views(3, 4).tolist() == [[10.0 * r + c for c in range(4)] for r in range(3)]


@njit
def _unowned_first(values):
    return unowned(values)[0, 0]


def test_an_unowned_view_of_a_strided_array_is_refused_at_compile_time():
    """Its data pointer would read the base array's elements, not the view's."""
    with pytest.raises(TypingError):
        _unowned_first(np.arange(12.0).reshape(3, 4)[:, ::2])


@njit
def _bump_each(owned):
    """Writes through ``unowned_each``'s views of a tuple of arrays and a scalar."""
    table, flags, scale = unowned_each(owned)
    table[1, 2] += scale
    flags[0] = not flags[0]
    keep_alive(owned)
    return scale


def test_unowned_each_views_every_array_of_a_tuple_and_passes_the_rest():
    table, flags = np.zeros((2, 3)), np.zeros(2, dtype=np.bool_)
    assert _bump_each((table, flags, 2.5)) == 2.5
    assert table.tolist() == [[0.0, 0.0, 0.0], [0.0, 0.0, 2.5]]
    assert flags.tolist() == [True, False]


@njit
def _each_of_a_scalar(value):
    return unowned_each(value)


def test_unowned_each_passes_a_value_that_is_not_a_tuple():
    """A scheme with no arrays hands its driver a plain number."""
    assert _each_of_a_scalar(7) == 7
