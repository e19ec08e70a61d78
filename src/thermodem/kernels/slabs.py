"""Slab colouring: pair passes that add straight into the particles' arrays without races.

At a rebuild the particles are sorted by cell with one axis (the *slab axis*) major, so every
cell layer along that axis is a contiguous block of particles. A listed pair is closer than
the cut-off, which is at most one cell edge, so its two particles lie in the same layer or in
neighbouring layers (or in the first and last layer across a periodic boundary). Pair *group*
g holds the pairs whose lower layer is g (a pair across the periodic boundary belongs to the
last group), and writes only to layers g and g + 1 (mod the layer count). Groups of equal
parity therefore write to disjoint particles: a pair pass runs the even groups in parallel,
then the odd groups, each group's pairs in list order, and adds forces, torques and heat
directly to the particles, with no per-pair output rows and no second pass.

The order in which a particle receives its contributions depends only on the list and the
groups, never on the number of threads, so results are identical for any thread count. The
groups are a property of the list (saved with it in a checkpoint). With a periodic slab axis
the layer count must be even (or 2 or 1) for the parity rule to hold across the boundary: an
odd count merges its last two cell layers into one layer.

The slab axis is the one over which the particles spread across the most cell layers at the
rebuild, so that the groups share the work evenly between threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from thermodem.kernels.neighbors import _axis_cell


@njit(cache=True, error_model="numpy")
def choose_axis(position, lower, edge, dims):
    """The axis over which the particles occupy the most cell layers (the lowest on ties)."""
    n = position.shape[0]
    best_axis = 0
    best = -1
    for a in range(3):
        lo = dims[a]
        hi = -1
        for i in range(n):
            c = _axis_cell(position[i, a], lower[a], edge[a], dims[a])
            if c < lo:
                lo = c
            if c > hi:
                hi = c
        if hi - lo > best:
            best = hi - lo
            best_axis = a
    return best_axis


def layer_count(cells: int, periodic: bool) -> int:
    """Slab layers for ``cells`` cell layers along the slab axis (see the module docstring)."""
    if periodic and cells > 2 and cells % 2 == 1:
        return cells - 1
    return max(int(cells), 1)


@njit(cache=True, inline="always", error_model="numpy")
def _layer(x, lower, edge, cells, nlayers):
    c = _axis_cell(x, lower, edge, cells)
    return c if c < nlayers else nlayers - 1


@njit(cache=True, inline="always", error_model="numpy")
def _pair_group(li, lj, nlayers):
    lo = min(li, lj)
    hi = max(li, lj)
    if hi - lo > 1:  # across the periodic boundary: layers nlayers - 1 and 0
        return nlayers - 1
    return lo


@njit(cache=True, error_model="numpy")
def group_pairs(position, lower, edge, dims, axis, nlayers, pair_i, pair_j, npairs, group_start):
    """Fill ``group_start`` (nlayers + 1 offsets) when the pairs are already ordered by group.

    Returns False when they are not (pairs across a periodic boundary); then call
    :func:`sort_pairs_by_group`.
    """
    group_start[:] = 0
    last = 0
    for k in range(npairs):
        li = _layer(position[pair_i[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        lj = _layer(position[pair_j[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        g = _pair_group(li, lj, nlayers)
        if g < last:
            return False
        last = g
        group_start[g + 1] += 1
    for g in range(nlayers):
        group_start[g + 1] += group_start[g]
    return True


@njit(cache=True, error_model="numpy")
def sort_pairs_by_group(
    position, lower, edge, dims, axis, nlayers, pair_i, pair_j, npairs, group_start, out_i,
    out_j, where,
):  # fmt: skip
    """Stable counting sort of the pairs by group into ``out_i``/``out_j``; fills
    ``group_start`` and ``where`` (the sorted position of each pair)."""
    group_start[:] = 0
    for k in range(npairs):
        li = _layer(position[pair_i[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        lj = _layer(position[pair_j[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        group_start[_pair_group(li, lj, nlayers) + 1] += 1
    for g in range(nlayers):
        group_start[g + 1] += group_start[g]
    fill = group_start[:nlayers].copy()
    for k in range(npairs):
        li = _layer(position[pair_i[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        lj = _layer(position[pair_j[k], axis], lower[axis], edge[axis], dims[axis], nlayers)
        g = _pair_group(li, lj, nlayers)
        out_i[fill[g]] = pair_i[k]
        out_j[fill[g]] = pair_j[k]
        where[k] = fill[g]
        fill[g] += 1


@njit(cache=True, error_model="numpy")
def order_within_groups(pair_i, pair_j, count, group_start):
    """Sort the pairs of each slab group (in place) by their lower particle index, stably
    (so the pass walks the particle arrays forwards). One group at a time: the scratch is a
    group's size, not the list's (the whole-list NumPy sort took ~40 B per pair at its peak)."""
    for g in range(group_start.shape[0] - 1):
        a = group_start[g]
        b = min(group_start[g + 1], count)
        if b - a < 2:
            continue
        lower = np.minimum(pair_i[a:b], pair_j[a:b])
        order = np.argsort(lower, kind="mergesort")
        sorted_i = pair_i[a:b][order]
        sorted_j = pair_j[a:b][order]
        pair_i[a:b] = sorted_i
        pair_j[a:b] = sorted_j
