"""Neighbour search: cell list, Verlet skin, half pair list, history carried by identity.

At each rebuild the particles are sorted by cell (a counting sort, so particles that are close
in space are close in memory), then every pair closer than ``R_i + R_j + extra + skin`` is
listed once. A pair is stored oriented so that ``global_id[i] < global_id[j]``; its history row
is carried to the new list by particle identity (old index -> index after the sort), in place
(:func:`move_rows`), so a run that rebuilds every step and a run with a skin carry identical
history. ``extra`` is the
interaction distance beyond contact needed by gap models (near, non-touching pairs).

All kernels write into preallocated buffers and report the count they needed; when a buffer is
too small they return the needed size and the caller grows it and calls again.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from thermodem.geometry.wall_layout import (
    COL_AXIS,
    COL_HALF_LENGTH,
    COL_HALF_U,
    COL_HALF_V,
    COL_NORMAL,
    COL_POINT,
    COL_RADIUS,
    COL_SIDE,
    COL_U,
    CYLINDER,
    PLANE,
    RECTANGLE,
)


@njit(cache=True, error_model="numpy")
def minimum_image(dx, length, periodic):
    """dx folded into [-L/2, L/2] on a periodic axis."""
    if periodic:
        dx -= length * math.floor(dx / length + 0.5)
    return dx


@njit(cache=True, inline="always", error_model="numpy")
def pair_separation(position, i, j, length, periodic):
    """(dx, dy, dz, distance) from particle i to particle j, minimum image on periodic axes."""
    dx = minimum_image(position[j, 0] - position[i, 0], length[0], periodic[0])
    dy = minimum_image(position[j, 1] - position[i, 1], length[1], periodic[1])
    dz = minimum_image(position[j, 2] - position[i, 2], length[2], periodic[2])
    return dx, dy, dz, math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, error_model="numpy")
def cell_grid(lower, upper, cell_size, periodic):
    """Number of cells per axis (at least 1) and the actual cell edge per axis."""
    dims = np.empty(3, dtype=np.int64)
    edge = np.empty(3, dtype=np.float64)
    for a in range(3):
        length = upper[a] - lower[a]
        n = int(math.floor(length / cell_size))
        if n < 1:
            n = 1
        dims[a] = n
        edge[a] = length / n
    return dims, edge


@njit(cache=True, error_model="numpy")
def cell_of(x, lower, edge, dims):
    """Cell coordinates (cx, cy, cz) of a position, clamped into the grid on every axis."""
    return (
        _axis_cell(x[0], lower[0], edge[0], dims[0]),
        _axis_cell(x[1], lower[1], edge[1], dims[1]),
        _axis_cell(x[2], lower[2], edge[2], dims[2]),
    )


@njit(cache=True, error_model="numpy")
def _axis_cell(x, lower, edge, n):
    k = int(math.floor((x - lower) / edge))
    if k < 0:
        return 0
    if k >= n:
        return n - 1
    return k


@njit(cache=True, inline="always", error_model="numpy")
def linear_cell(cx, cy, cz, dims, axes):
    """Linear index of cell (cx, cy, cz) with ``axes[0]`` the major (slowest) axis and
    ``axes[2]`` the minor one, so that the cells of one layer along ``axes[0]`` are
    contiguous (the slab layers of :mod:`thermodem.kernels.slabs`)."""
    c = (cx, cy, cz)
    return (c[axes[0]] * dims[axes[1]] + c[axes[1]]) * dims[axes[2]] + c[axes[2]]


@njit(cache=True, error_model="numpy")
def sort_by_cell(position, lower, edge, dims, axes, order, cell_start):
    """Counting sort of particles by linear cell index (see :func:`linear_cell`).

    Writes ``order`` (new position -> old index, int32) and ``cell_start`` (ncell + 1 offsets).
    ``order`` first holds each particle's cell index (no extra per-particle buffer).
    """
    n = position.shape[0]
    ncell = dims[0] * dims[1] * dims[2]
    cell_start[:] = 0
    for i in range(n):
        c = cell_of(position[i], lower, edge, dims)
        cid = linear_cell(c[0], c[1], c[2], dims, axes)
        cell_start[cid + 1] += 1
    for c in range(ncell):
        cell_start[c + 1] += cell_start[c]
    fill = cell_start[:ncell].copy()
    for i in range(n):
        c = cell_of(position[i], lower, edge, dims)
        cid = linear_cell(c[0], c[1], c[2], dims, axes)
        order[fill[cid]] = i
        fill[cid] += 1


@njit(cache=True, error_model="numpy")
def _stencil_axis(k, n, periodic, out):
    """Unique neighbour cell coordinates along one axis; returns their count."""
    m = 0
    for d in (-1, 0, 1):
        c = k + d
        if periodic:
            c = c % n
        elif c < 0 or c >= n:
            continue
        dup = False
        for q in range(m):
            if out[q] == c:
                dup = True
        if not dup:
            out[m] = c
            m += 1
    return m


@njit(cache=True, error_model="numpy")
def build_pairs(
    position,
    radius,
    global_id,
    lower,
    upper,
    periodic,
    dims,
    edge,
    axes,
    cell_start,
    extra,
    skin,
    pair_i,
    pair_j,
):
    """List every pair (i, j) with distance < R_i + R_j + extra + skin, each pair once.

    Particles must already be sorted by cell (``cell_start`` from :func:`sort_by_cell` applied
    to the sorted positions). Pairs are oriented so that global_id[i] < global_id[j]; they are
    listed in the order of the lower particle index, so the lower index's slab layer never
    decreases along the list (what :func:`thermodem.kernels.slabs.group_pairs` relies on).
    Returns the number of pairs found; if it exceeds the buffers' length, nothing beyond the
    capacity is written and the caller must grow the buffers and call again.
    """
    n = position.shape[0]
    cap = pair_i.shape[0]
    count = 0
    length = upper - lower
    sx = np.empty(3, dtype=np.int64)
    sy = np.empty(3, dtype=np.int64)
    sz = np.empty(3, dtype=np.int64)
    for i in range(n):
        c = cell_of(position[i], lower, edge, dims)
        mx = _stencil_axis(c[0], dims[0], periodic[0], sx)
        my = _stencil_axis(c[1], dims[1], periodic[1], sy)
        mz = _stencil_axis(c[2], dims[2], periodic[2], sz)
        xi = position[i, 0]
        yi = position[i, 1]
        zi = position[i, 2]
        ri = radius[i] + extra + skin
        for a in range(mz):
            for b in range(my):
                for q in range(mx):
                    cid = linear_cell(sx[q], sy[b], sz[a], dims, axes)
                    for j in range(cell_start[cid], cell_start[cid + 1]):
                        if j <= i:
                            continue
                        dx = minimum_image(position[j, 0] - xi, length[0], periodic[0])
                        dy = minimum_image(position[j, 1] - yi, length[1], periodic[1])
                        dz = minimum_image(position[j, 2] - zi, length[2], periodic[2])
                        cut = ri + radius[j]
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if count < cap:
                                if global_id[i] < global_id[j]:
                                    pair_i[count] = i
                                    pair_j[count] = j
                                else:
                                    pair_i[count] = j
                                    pair_j[count] = i
                            count += 1
    return count


@njit(cache=True, error_model="numpy")
def wall_distance(kind, row, x):
    """Distance from a sphere centre to a wall surface and the unit normal wall -> centre.

    Returns (distance, nx, ny, nz, qx, qy, qz) where q is the closest point of the wall.
    A plane is one-sided (distance is signed along its normal); a rectangle is two-sided and
    includes its edges; a cylinder acts on the inside (side +1) or outside (side -1) of its
    mantle, within its half length (no end caps: add planes for those). Beyond the ends of a
    finite cylinder the distance is +inf.
    """
    px = row[COL_POINT]
    py = row[COL_POINT + 1]
    pz = row[COL_POINT + 2]
    rx = x[0] - px
    ry = x[1] - py
    rz = x[2] - pz
    if kind == PLANE:
        nx = row[COL_NORMAL]
        ny = row[COL_NORMAL + 1]
        nz = row[COL_NORMAL + 2]
        s = rx * nx + ry * ny + rz * nz
        return s, nx, ny, nz, x[0] - s * nx, x[1] - s * ny, x[2] - s * nz
    if kind == RECTANGLE:
        nx = row[COL_NORMAL]
        ny = row[COL_NORMAL + 1]
        nz = row[COL_NORMAL + 2]
        ux = row[COL_U]
        uy = row[COL_U + 1]
        uz = row[COL_U + 2]
        vx = ny * uz - nz * uy
        vy = nz * ux - nx * uz
        vz = nx * uy - ny * ux
        a = rx * ux + ry * uy + rz * uz
        b = rx * vx + ry * vy + rz * vz
        hu = row[COL_HALF_U]
        hv = row[COL_HALF_V]
        a = min(max(a, -hu), hu)
        b = min(max(b, -hv), hv)
        qx = px + a * ux + b * vx
        qy = py + a * uy + b * vy
        qz = pz + a * uz + b * vz
        dx = x[0] - qx
        dy = x[1] - qy
        dz = x[2] - qz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        if d > 0.0:
            return d, dx / d, dy / d, dz / d, qx, qy, qz
        return 0.0, nx, ny, nz, qx, qy, qz
    if kind == CYLINDER:
        ax = row[COL_AXIS]
        ay = row[COL_AXIS + 1]
        az = row[COL_AXIS + 2]
        h = rx * ax + ry * ay + rz * az
        if abs(h) > row[COL_HALF_LENGTH]:
            return np.inf, 0.0, 0.0, 1.0, x[0], x[1], x[2]
        ox = rx - h * ax
        oy = ry - h * ay
        oz = rz - h * az
        rho = math.sqrt(ox * ox + oy * oy + oz * oz)
        if rho > 0.0:
            ox /= rho
            oy /= rho
            oz /= rho
        else:
            ox = 1.0
            oy = 0.0
            oz = 0.0
        big_r = row[COL_RADIUS]
        qx = px + h * ax + big_r * ox
        qy = py + h * ay + big_r * oy
        qz = pz + h * az + big_r * oz
        if row[COL_SIDE] > 0.0:
            return big_r - rho, -ox, -oy, -oz, qx, qy, qz
        return rho - big_r, ox, oy, oz, qx, qy, qz
    return np.inf, 0.0, 0.0, 1.0, x[0], x[1], x[2]


@njit(cache=True, error_model="numpy")
def build_wall_pairs(
    position, radius, wall_kind, wall_rows, extra, skin, wall_pair_i, wall_pair_w, wall_row_start
):
    """List (particle, wall) pairs within R + extra + skin, grouped by particle.

    Writes ``wall_row_start`` (n + 1 offsets into the wall pair arrays). Returns the count;
    when it exceeds the buffers' length the caller grows them and calls again.
    """
    n = position.shape[0]
    cap = wall_pair_i.shape[0]
    count = 0
    for i in range(n):
        wall_row_start[i] = min(count, cap)
        for w in range(wall_kind.shape[0]):
            d = wall_distance(wall_kind[w], wall_rows[w], position[i])[0]
            if d < radius[i] + extra + skin:
                if count < cap:
                    wall_pair_i[count] = i
                    wall_pair_w[count] = w
                count += 1
    wall_row_start[n] = min(count, cap)
    return count


@njit(cache=True, inline="always", error_model="numpy")
def _copy_row(old_history, k, new_history, m):
    for c in range(old_history.shape[1]):
        new_history[m, c] = old_history[k, c]


@njit(cache=True, inline="always", error_model="numpy")
def _row_is_zero(history, k):
    for c in range(history.shape[1]):
        if history[k, c] != 0.0:
            return False
    return True


@njit(cache=True, error_model="numpy")
def lower_index_offsets(pair_i, pair_j, npairs, n, offsets):
    """``offsets[a]``: the first pair whose lower particle index is a (n + 1 offsets).

    :func:`build_pairs` lists pairs in the order of their lower index, so the pairs of each
    lower index are contiguous. Returns False if the list is not in that order.
    """
    a = 0
    offsets[0] = 0
    for k in range(npairs):
        lo = min(pair_i[k], pair_j[k])
        if lo < a:
            return False
        while a < lo:
            a += 1
            offsets[a] = k
    while a < n:
        a += 1
        offsets[a] = npairs
    return True


@njit(cache=True, error_model="numpy")
def carry_destinations(
    old_i, old_j, old_count, history, new_index, offsets, new_i, new_j, dest
):  # fmt: skip
    """``dest[k]``: the new pair of old pair k (same two particles), or -1 when the old pair
    is gone or its history row is zero (a pair that does not touch carries nothing).

    ``new_index[old particle index]`` is its index after the rebuild's sort; ``offsets`` from
    :func:`lower_index_offsets`. Pairs keep their orientation (the smaller global id is i).
    ``dest`` may be ``old_i`` itself (each entry is read before it is written).
    """
    for k in range(old_count):
        if _row_is_zero(history, k):
            dest[k] = -1
            continue
        a = new_index[old_i[k]]
        b = new_index[old_j[k]]
        lo = min(a, b)
        found = -1
        for e in range(offsets[lo], offsets[lo + 1]):
            if new_i[e] == a and new_j[e] == b:
                found = e
                break
        dest[k] = found


@njit(cache=True, error_model="numpy")
def move_rows(history, dest, old_count, new_count, done, carry, spare):
    """Move row k of ``history`` to row ``dest[k]`` in place, for every old row k with
    ``dest[k] >= 0``; every other row of the first ``new_count`` ends zero.

    ``dest`` is one-to-one, so the moves form chains and cycles: each chain is followed from
    its start, carrying one row at a time (``carry`` and ``spare`` hold a row, ``done`` marks
    old rows whose content has left). The history therefore needs no second table.
    """
    width = history.shape[1]
    for k in range(old_count):
        done[k] = 0
        if dest[k] < 0:
            for c in range(width):
                history[k, c] = 0.0
    for k in range(old_count, new_count):
        for c in range(width):
            history[k, c] = 0.0
    for k0 in range(old_count):
        if done[k0] or dest[k0] < 0:
            continue
        done[k0] = 1
        if dest[k0] == k0:
            continue
        for c in range(width):
            carry[c] = history[k0, c]
            history[k0, c] = 0.0  # vacated; a chain may land here later
        e = dest[k0]
        while True:
            if e < old_count and dest[e] >= 0 and not done[e]:
                done[e] = 1  # its own row moves on, ours lands
                for c in range(width):
                    spare[c] = history[e, c]
                    history[e, c] = carry[c]
                    carry[c] = spare[c]
                e = dest[e]
            else:
                for c in range(width):
                    history[e, c] = carry[c]
                break


@njit(cache=True, error_model="numpy")
def carry_wall_history(
    old_i, old_w, old_count, old_history, new_index, wall_row_start, new_w, new_history,
    new_count,
):  # fmt: skip
    """Copy each old particle-wall pair's history to the new pair of the same particle and
    wall (new wall pairs are grouped by particle, ``wall_row_start``); other rows zero."""
    new_history[:new_count] = 0.0
    for k in range(old_count):
        if _row_is_zero(old_history, k):
            continue
        a = new_index[old_i[k]]
        for m in range(wall_row_start[a], wall_row_start[a + 1]):
            if new_w[m] == old_w[k]:
                _copy_row(old_history, k, new_history, m)
                break


@njit(cache=True, error_model="numpy")
def max_displacement(position, reference, lower, upper, periodic):
    """Largest displacement since the reference positions (minimum image on periodic axes)."""
    length = upper - lower
    best = 0.0
    for i in range(position.shape[0]):
        dx = minimum_image(position[i, 0] - reference[i, 0], length[0], periodic[0])
        dy = minimum_image(position[i, 1] - reference[i, 1], length[1], periodic[1])
        dz = minimum_image(position[i, 2] - reference[i, 2], length[2], periodic[2])
        d2 = dx * dx + dy * dy + dz * dz
        if d2 > best:
            best = d2
    return math.sqrt(best)
