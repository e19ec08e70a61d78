"""Neighbour search: cell list, Verlet skin, half pair list, history carried by identity.

At each rebuild the particles are sorted by cell (a counting sort, so particles that are close
in space are close in memory), then every pair closer than ``R_i + R_j + extra + skin`` is
listed once. A pair is stored oriented so that ``global_id[i] < global_id[j]``; its history row
is carried to the new list by particle identity (old index -> index after the sort), so a run
that rebuilds every step and a run with a skin carry identical history. ``extra`` is the
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


@njit(cache=True, error_model="numpy")
def sort_by_cell(position, lower, edge, dims, order, cell_start):
    """Counting sort of particles by linear cell index.

    Writes ``order`` (new position -> old index) and ``cell_start`` (ncell + 1 offsets).
    """
    n = position.shape[0]
    ncell = dims[0] * dims[1] * dims[2]
    cell_start[:] = 0
    cell_id = np.empty(n, dtype=np.int64)
    for i in range(n):
        c = cell_of(position[i], lower, edge, dims)
        cid = (c[2] * dims[1] + c[1]) * dims[0] + c[0]
        cell_id[i] = cid
        cell_start[cid + 1] += 1
    for c in range(ncell):
        cell_start[c + 1] += cell_start[c]
    fill = cell_start[:ncell].copy()
    for i in range(n):
        cid = cell_id[i]
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
    cell_start,
    extra,
    skin,
    pair_i,
    pair_j,
):
    """List every pair (i, j) with distance < R_i + R_j + extra + skin, each pair once.

    Particles must already be sorted by cell (``cell_start`` from :func:`sort_by_cell` applied
    to the sorted positions). Pairs are oriented so that global_id[i] < global_id[j].
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
                    cid = (sz[a] * dims[1] + sy[b]) * dims[0] + sx[q]
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
def carry_pair_history(
    old_i, old_j, old_count, old_history, new_index, row_start, entries, new_j, new_history,
    new_count,
):  # fmt: skip
    """Copy each old pair's history row to the new pair of the same two particles.

    ``new_index[old particle index]`` is its index after the rebuild's sort. Pairs keep their
    orientation (the smaller global id is i), so the new pair of an old pair (a, b) is the entry
    of row a of the new per-particle list (``row_start``/``entries``, see
    :func:`particle_pair_csr`) that has a as i and b as j. Rows of new pairs without an old
    pair are zero; an all-zero old row (a pair that does not touch) needs no copy.
    """
    new_history[:new_count] = 0.0
    for k in range(old_count):
        if _row_is_zero(old_history, k):
            continue
        a = new_index[old_i[k]]
        b = new_index[old_j[k]]
        for q in range(row_start[a], row_start[a + 1]):
            e = entries[q]
            if e >= 0 and new_j[e] == b:
                _copy_row(old_history, k, new_history, e)
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
def particle_pair_csr(pair_i, pair_j, npairs, global_id, n, row_start, entries):
    """Per-particle list of its pairs, each row ordered by the neighbour's global id.

    Entry e >= 0 means pair e with the particle as i; e < 0 means pair ~e (= -e-1) as j.
    A fixed order per particle makes the reduction independent of list order and threads.
    """
    row_start[:] = 0
    for k in range(npairs):
        row_start[pair_i[k] + 1] += 1
        row_start[pair_j[k] + 1] += 1
    for i in range(n):
        row_start[i + 1] += row_start[i]
    fill = row_start[:n].copy()
    for k in range(npairs):
        i = pair_i[k]
        j = pair_j[k]
        entries[fill[i]] = k
        fill[i] += 1
        entries[fill[j]] = -k - 1
        fill[j] += 1
    # insertion sort of each (short) row by the neighbour's global id
    for i in range(n):
        lo = row_start[i]
        hi = row_start[i + 1]
        for a in range(lo + 1, hi):
            e = entries[a]
            ke = e if e >= 0 else -e - 1
            ge = global_id[pair_j[ke]] if e >= 0 else global_id[pair_i[ke]]
            b = a - 1
            while b >= lo:
                f = entries[b]
                kf = f if f >= 0 else -f - 1
                gf = global_id[pair_j[kf]] if f >= 0 else global_id[pair_i[kf]]
                if gf <= ge:
                    break
                entries[b + 1] = f
                b -= 1
            entries[b + 1] = e


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
