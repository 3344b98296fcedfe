"""The chain's cluster catalogue: an event is a set of slipping blocks connected in space
and time, so that events at two places of a long chain are two events.

A block slips from the step its slip speed exceeds v_start until it falls below v_stop.
A slipping block belongs to the cluster it belonged to at the previous step, or else to
its left neighbour's now, or else to its right neighbour's of the previous step; with none
of them it opens a new cluster.  Where a block's cluster and
its left neighbour's differ, they meet and merge into the earlier one.  A cluster closes
when no block belongs to it any more.  Its potency is the sum of its blocks' slips over
the steps they slipped (the step in which a block stops included); ``n_blocks`` counts the
distinct blocks that slipped in it.

The clusters live in ``clu`` (one row per cluster slot, N + 1 slots; a merged or closed
slot is freed at once, so slots never run out), with each block's membership (memory
(N + 1)(N + 6) doubles: 8 MB at N = 1000); each block's cluster is a column of the
chain's per-block scratch.
"""
import math

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..layout import Y_VX, Y_X

# A cluster slot, float64 array (N + 1, N_CLU + N): in use, start time, first block,
# potency, peak slip speed, blocks slipping in it at this step; then one column per block:
# 1.0 if the block has slipped in the cluster (so that n_blocks counts each block once,
# also where clusters merge).
K_OPEN, K_START, K_FIRST, K_POTENCY, K_PEAK, K_CARRIERS = range(6)
N_CLU = 6


@njit(inline="always")
def _open(clu, t, first):
    """A free slot opened for a cluster starting at t at block ``first``."""
    for k in range(clu.shape[0]):
        if clu[k, K_OPEN] == 0.0:
            clu[k, K_OPEN], clu[k, K_START], clu[k, K_FIRST], clu[k, K_POTENCY] = 1.0, t, first, 0.0
            clu[k, K_PEAK], clu[k, K_CARRIERS] = 0.0, 0.0
            for column in range(N_CLU, clu.shape[1]):
                clu[k, column] = 0.0
            return k
    return -1


@njit(inline="always")
def _merge(clu, label, one, other):
    """Clusters ``one`` and ``other`` meet: the later joins the earlier (its blocks, slip,
    peak); its slot is freed.  ``label`` is the blocks' cluster column (slot + 1; 0 for
    none).  Returns the slot kept."""
    keep, gone = one, other
    if clu[other, K_START] < clu[one, K_START]:
        keep, gone = other, one
    for i in range(label.shape[0]):
        if label[i] == gone + 1:
            label[i] = keep + 1
    for column in range(N_CLU, clu.shape[1]):
        clu[keep, column] = max(clu[keep, column], clu[gone, column])
    clu[keep, K_POTENCY] += clu[gone, K_POTENCY]
    clu[keep, K_PEAK] = max(clu[keep, K_PEAK], clu[gone, K_PEAK])
    clu[keep, K_CARRIERS] += clu[gone, K_CARRIERS]
    clu[gone, K_OPEN] = 0.0
    return keep


@njit(inline="always")
def _join(Y, clu, label, i, slot, x_before):
    """Block i slips in cluster ``slot`` at this step: its slip, speed and membership."""
    label[i] = slot + 1
    clu[slot, K_CARRIERS] += 1.0
    clu[slot, K_POTENCY] += Y[i, Y_X] - x_before
    clu[slot, K_PEAK] = max(clu[slot, K_PEAK], abs(Y[i, Y_VX]))
    clu[slot, N_CLU + i] = 1.0


@njit(inline="always")
def follow(Y, clu, label, x_before, thresholds, t, periodic):
    """One step's clusters: each slipping block joins or opens one, meeting clusters
    merge.  ``thresholds`` = (v_start, v_stop); ``x_before``: positions before the step."""
    v_start, v_stop = thresholds
    for k in range(clu.shape[0]):
        clu[k, K_CARRIERS] = 0.0
    left = -1
    for i in range(Y.shape[0]):
        speed, was = abs(Y[i, Y_VX]), int(label[i]) - 1
        if not (speed >= v_stop if was >= 0 else speed > v_start):
            if was >= 0:  # the step in which it stopped is its cluster's slip too
                clu[was, K_POTENCY] += Y[i, Y_X] - x_before[i]
            label[i], left = 0.0, -1
            continue
        slot = was if was >= 0 else left
        if slot < 0 and i + 1 < Y.shape[0] and label[i + 1] != 0.0:  # (its right neighbour slipped a step ago)
            slot = int(label[i + 1]) - 1
        if was >= 0 and left >= 0 and left != was:
            slot = _merge(clu, label, was, left)
        if slot < 0:
            slot = _open(clu, t, i)
        _join(Y, clu, label, i, slot, x_before[i])
        left = slot
    last = Y.shape[0] - 1
    if periodic and last > 0 and label[0] != 0.0 and label[last] != 0.0 and label[0] != label[last]:
        _merge(clu, label, int(label[0]) - 1, int(label[last]) - 1)


@njit(inline="always")
def close(clu, rows, row, t1):
    """Close every cluster no block slips in any more into ``rows`` from ``row`` on (start,
    end, first block, blocks, potency, peak).  Returns the rows filled and the last
    potency closed (NaN if none)."""
    last = math.nan
    for k in range(clu.shape[0]):
        if clu[k, K_OPEN] != 0.0 and clu[k, K_CARRIERS] == 0.0:
            blocks = 0.0
            for column in range(N_CLU, clu.shape[1]):
                blocks += clu[k, column]
            rows[row, 0], rows[row, 1], rows[row, 2] = clu[k, K_START], t1, clu[k, K_FIRST]
            rows[row, 3], rows[row, 4], rows[row, 5] = blocks, clu[k, K_POTENCY], clu[k, K_PEAK]
            last = clu[k, K_POTENCY]
            clu[k, K_OPEN] = 0.0
            row += 1
    return row, last
