"""Porosity kernels of the per-particle field F_POROSITY (``kernels/fields.py``), run by the
porosity providers of ``engine/fields.py``: by a cell count (``thermal.porosity: {kind:
cell}``) and in a shell around each particle (``kind: shell``).

Kernels of this module (compiled, no Python loops over particles; every particle writes only
its own row, or a pair pass adds by slab groups, so the results do not depend on the thread
count):

- :func:`cell_fluid_volume`, :func:`cell_moves`, :func:`cell_porosity`: porosity by a cell
  count (the cells' volume on the particles' side of the walls, :func:`point_in_fluid`);
- :func:`shell_pass`: the solid volume of the neighbours within a shell (exact lens
  volumes), :func:`zero_rows` clears its sums;
- :func:`shell_porosity`: 1 - solid volume / shell volume inside the walls (wall caps,
  their pairwise overlaps :func:`cap_overlap`, corners from :func:`unit_ball_points`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

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
from thermodem.kernels.fields import CHUNK, F_POROSITY
from thermodem.kernels.neighbors import pair_separation, wall_distance
from thermodem.kernels.variants import parallel_kernel


@njit(cache=True, inline="always", error_model="numpy")
def point_in_fluid(kind, row, x0, x1, x2):
    """Whether a point is on the particles' side of a wall: in front of a plane, not behind a
    rectangle within its extent (box faces), inside (side +1) or outside (side -1) of a
    cylinder's mantle within its length."""
    rx = x0 - row[COL_POINT]
    ry = x1 - row[COL_POINT + 1]
    rz = x2 - row[COL_POINT + 2]
    if kind == PLANE:
        return rx * row[COL_NORMAL] + ry * row[COL_NORMAL + 1] + rz * row[COL_NORMAL + 2] >= 0.0
    if kind == RECTANGLE:
        nx = row[COL_NORMAL]
        ny = row[COL_NORMAL + 1]
        nz = row[COL_NORMAL + 2]
        s = rx * nx + ry * ny + rz * nz
        if s >= 0.0:
            return True
        ux = row[COL_U]
        uy = row[COL_U + 1]
        uz = row[COL_U + 2]
        vx = ny * uz - nz * uy
        vy = nz * ux - nx * uz
        vz = nx * uy - ny * ux
        a = rx * ux + ry * uy + rz * uz
        b = rx * vx + ry * vy + rz * vz
        return abs(a) > row[COL_HALF_U] or abs(b) > row[COL_HALF_V]
    if kind == CYLINDER:
        ax = row[COL_AXIS]
        ay = row[COL_AXIS + 1]
        az = row[COL_AXIS + 2]
        h = rx * ax + ry * ay + rz * az
        if abs(h) > row[COL_HALF_LENGTH]:
            return True
        ox = rx - h * ax
        oy = ry - h * ay
        oz = rz - h * az
        rho2 = ox * ox + oy * oy + oz * oz
        r2 = row[COL_RADIUS] * row[COL_RADIUS]
        if row[COL_SIDE] > 0.0:
            return rho2 <= r2
        return rho2 >= r2
    return True


@parallel_kernel(error_model="numpy")
def cell_fluid_volume(lower, edge, dims, wall_kind, wall_rows, samples, out):
    """Volume of every cell on the particles' side of all walls, by a midpoint rule of
    ``samples``³ points per cell (``out``: one value per cell, x fastest)."""
    ncell = dims[0] * dims[1] * dims[2]
    nw = wall_kind.shape[0]
    cell_volume = edge[0] * edge[1] * edge[2]
    total = samples * samples * samples
    for c in prange(ncell):
        cx = c % dims[0]
        cy = (c // dims[0]) % dims[1]
        cz = c // (dims[0] * dims[1])
        inside = 0
        for a in range(samples):
            x0 = lower[0] + (cx + (a + 0.5) / samples) * edge[0]
            for b in range(samples):
                x1 = lower[1] + (cy + (b + 0.5) / samples) * edge[1]
                for d in range(samples):
                    x2 = lower[2] + (cz + (d + 0.5) / samples) * edge[2]
                    ok = True
                    for w in range(nw):
                        if not point_in_fluid(wall_kind[w], wall_rows[w], x0, x1, x2):
                            ok = False
                            break
                    if ok:
                        inside += 1
        out[c] = cell_volume * inside / total


@njit(cache=True, inline="always", error_model="numpy")
def _cell_index(x, lower, edge, dims):
    c = 0
    stride = 1
    for a in range(3):
        k = int(math.floor((x[a] - lower[a]) / edge[a]))
        if k < 0:
            k = 0
        if k >= dims[a]:
            k = dims[a] - 1
        c += k * stride
        stride *= dims[a]
    return c


# inlined into cell_porosity (its prange is the caller's: kernels/variants.py)
@njit(cache=True, inline="always", error_model="numpy")
def _bin_solid(position, radius, lower, edge, dims, solid, cell):
    """Solid volume of the particles by the cell of their centre: the cells in parallel,
    the sums serially (a fixed order)."""
    n = position.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            cell[i] = _cell_index(position[i], lower, edge, dims)
    for c in range(solid.shape[0]):
        solid[c] = 0.0
    for i in range(n):
        r = radius[i]
        solid[cell[i]] += 4.0 / 3.0 * math.pi * r * r * r


@parallel_kernel(error_model="numpy")
def cell_moves(position, lower, edge, dims, cell, part):
    """How many particles have their centre in another cell than ``cell[i]`` (the cells of
    the last :func:`cell_porosity`); ``part``: scratch of at least n // CHUNK + 1 entries."""
    n = position.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        moves = 0
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            if _cell_index(position[i], lower, edge, dims) != cell[i]:
                moves += 1
        part[c] = moves
    total = 0
    for c in range(nchunks):
        total += int(part[c])
    return total


@parallel_kernel(error_model="numpy")
def cell_porosity(position, radius, lower, edge, dims, fluid_volume, solid, cell, fields):
    """Porosity of the cell of each particle's centre, 1 - V_solid / V_cell, clipped to
    [0, 1]: V_solid the volume of the particles whose centre is in the cell, V_cell the
    cell's volume on the particles' side of the walls (:func:`cell_fluid_volume`). Every
    particle given is binned; the first ``fields.shape[1]`` take their cell's porosity (on
    several MPI ranks the owned ones: the ghosts are binned, their owners take theirs)."""
    _bin_solid(position, radius, lower, edge, dims, solid, cell)
    n = fields.shape[1]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            k = cell[i]
            v = fluid_volume[k]
            eps = 1.0 - solid[k] / v if v > 0.0 else 0.0
            fields[F_POROSITY, i] = min(max(eps, 0.0), 1.0)


@njit(cache=True, inline="always", error_model="numpy")
def lens_volume(a, b, d):
    """Volume of the intersection of two spheres of radii a and b whose centres are d apart."""
    if d >= a + b:
        return 0.0
    if d <= abs(a - b):
        r = min(a, b)
        return 4.0 / 3.0 * math.pi * r * r * r
    s = a + b - d
    return math.pi * s * s * (d * d + 2.0 * d * (a + b) - 3.0 * (a - b) * (a - b)) / (12.0 * d)


@parallel_kernel(error_model="numpy")
def shell_pass(position, radius, pair_i, pair_j, group_start, lower, upper, periodic,
               shell_ratio, sums):  # fmt: skip
    """Shell porosity: sums[i, 0] += the volume of the neighbours inside the sphere of radius
    shell_ratio × R_i (exact lens volumes), over the pairs of a range set, by slab groups
    (race-free, fixed order; ``sums`` zeroed by the caller)."""
    length = upper - lower
    ngroups = group_start.shape[0] - 1
    for parity in range(2):
        for half in prange((ngroups + 1 - parity) // 2):
            g = 2 * half + parity
            for k in range(group_start[g], group_start[g + 1]):
                i = pair_i[k]
                j = pair_j[k]
                d = pair_separation(position, i, j, length, periodic)[3]
                ri = radius[i]
                rj = radius[j]
                sums[i, 0] += lens_volume(shell_ratio * ri, rj, d)
                sums[j, 0] += lens_volume(shell_ratio * rj, ri, d)


@parallel_kernel(error_model="numpy")
def zero_rows(values):
    """values[:, :] = 0 (parallel)."""
    n = values.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            for q in range(values.shape[1]):
                values[i, q] = 0.0


@njit(cache=True, inline="always", error_model="numpy")
def cap_volume(r, d):
    """Volume of the part of a sphere of radius r beyond a plane at distance d from its centre
    (0 for d >= r; the whole sphere for d <= -r)."""
    if d >= r:
        return 0.0
    if d <= -r:
        return 4.0 / 3.0 * math.pi * r * r * r
    h = r - d
    return math.pi * h * h * (3.0 * r - h) / 3.0


def _halton(count: int, base: int) -> np.ndarray:
    out = np.zeros(count)
    for i in range(count):
        f, r, k = 1.0, 0.0, i + 1
        while k > 0:
            f /= base
            r += f * (k % base)
            k //= base
        out[i] = r
    return out


def unit_ball_points(count: int = 8000) -> np.ndarray:
    """Quasi-random points in the unit ball (m, 3): the Halton points (bases 2, 3, 5) of the
    cube [-1, 1]³ that fall in the ball (m ≈ 0.52 count). Not a lattice, so that planes
    aligned with the axes (box walls) do not meet rows of points (no staircase bias)."""
    cube = np.column_stack([_halton(count, b) for b in (2, 3, 5)]) * 2.0 - 1.0
    return np.ascontiguousarray(cube[(cube**2).sum(axis=1) <= 1.0])


_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
GL_X = np.ascontiguousarray(_GL_X)
GL_W = np.ascontiguousarray(_GL_W)


@njit(cache=True, inline="always", error_model="numpy")
def _segment(rho, e):
    """Area of the part of a disc of radius rho beyond a chord at signed distance e."""
    if e >= rho:
        return 0.0
    if e <= -rho:
        return math.pi * rho * rho
    return rho * rho * math.acos(e / rho) - e * math.sqrt(rho * rho - e * e)


@njit(cache=True, inline="always", error_model="numpy")
def _overlap_slices(r, d2, c, q, a, b):
    """∫_a^b of the slice areas of the sphere beyond the second plane, 16-point Gauss."""
    if b <= a:
        return 0.0
    half = 0.5 * (b - a)
    mid = 0.5 * (b + a)
    total = 0.0
    for k in range(GL_X.shape[0]):
        s = mid + half * GL_X[k]
        rho2 = r * r - s * s
        if rho2 > 0.0:
            total += GL_W[k] * _segment(math.sqrt(rho2), (d2 + s * c) / q)
    return total * half


@njit(cache=True, error_model="numpy")
def cap_overlap(r, d1, n1x, n1y, n1z, d2, n2x, n2y, n2z):
    """Volume of the part of a sphere (radius r, centre 0) behind two planes at distances d1,
    d2 from the centre with unit normals n1, n2 pointing to the centre (points u with
    u·n < −d): slices along n1, each a disc cut by the second plane's chord (circular
    segments), integrated piecewise between the slices where the chord touches the disc."""
    c = n1x * n2x + n1y * n2y + n1z * n2z
    q2 = 1.0 - c * c
    lo = -r
    hi = -d1
    if hi <= lo:
        return 0.0
    if q2 < 1e-24:  # parallel planes: behind both is a slab of the sphere
        if c > 0.0:
            return cap_volume(r, max(d1, d2))
        a = max(lo, d2)
        if hi <= a:
            return 0.0
        return math.pi * (r * r * (hi - a) - (hi**3 - a**3) / 3.0)
    q = math.sqrt(q2)
    breaks = np.empty(4)
    breaks[0] = lo
    m = 1
    if d2 < r:
        root = q * math.sqrt(r * r - d2 * d2)
        for s in (-d2 * c - root, -d2 * c + root):
            if lo < s < hi:
                breaks[m] = s
                m += 1
    breaks[m] = hi
    m += 1
    if m == 4 and breaks[1] > breaks[2]:
        breaks[1], breaks[2] = breaks[2], breaks[1]
    total = 0.0
    for k in range(m - 1):
        total += _overlap_slices(r, d2, c, q, breaks[k], breaks[k + 1])
    return total


@parallel_kernel(error_model="numpy")
def shell_porosity(
    position, radius, wall_kind, wall_rows, shell_ratio, lattice, solid, scratch, fields
):  # solid: (n, 4), the neighbours' volume in column 0
    """ε_i = 1 - (V_i + solid_i) / V_shell,i, clipped to [0, 1]: V_i the particle's own
    volume, solid_i the neighbours' volume inside the shell (:func:`shell_pass`),
    V_shell,i the volume of the sphere of radius shell_ratio × R_i on the particles' side of
    the walls. Each wall closer than the shell radius cuts a cap (the wall taken as its
    tangent plane at the closest point: exact for planes and box faces). Inclusion and
    exclusion: the caps are removed, the overlaps of each two caps added back
    (:func:`cap_overlap`, a quadrature), and where three or more caps overlap (a corner) the
    remainder is estimated from quasi-random points in the shell (``lattice``:
    :func:`unit_ball_points`; a point in k caps was removed 1 - k + k(k - 1)/2 times too
    few). ``scratch``: a row of 4 × (number of walls) values per
    chunk of particles."""
    n = position.shape[0]
    nw = wall_kind.shape[0]
    npts = lattice.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        row = scratch[c]
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            ri = radius[i]
            rs = shell_ratio * ri
            full = 4.0 / 3.0 * math.pi * rs * rs * rs
            volume = full
            cuts = 0
            for w in range(nw):
                res = wall_distance(wall_kind[w], wall_rows[w], position[i])
                d = res[0]
                if d < rs:
                    volume -= cap_volume(rs, d)
                    row[4 * cuts] = d
                    row[4 * cuts + 1] = res[1]
                    row[4 * cuts + 2] = res[2]
                    row[4 * cuts + 3] = res[3]
                    cuts += 1
            for a in range(cuts):
                for b in range(a + 1, cuts):
                    volume += cap_overlap(
                        rs, row[4 * a], row[4 * a + 1], row[4 * a + 2], row[4 * a + 3],
                        row[4 * b], row[4 * b + 1], row[4 * b + 2], row[4 * b + 3],
                    )  # fmt: skip
            if cuts > 2:
                extra = 0
                for q in range(npts):
                    inside = 0
                    for w in range(cuts):
                        s = rs * (
                            lattice[q, 0] * row[4 * w + 1]
                            + lattice[q, 1] * row[4 * w + 2]
                            + lattice[q, 2] * row[4 * w + 3]
                        )
                        if s < -row[4 * w]:  # behind the wall's plane
                            inside += 1
                    if inside > 2:
                        extra += (inside - 1) * (inside - 2) // 2
                volume -= extra * full / npts
            own = 4.0 / 3.0 * math.pi * ri * ri * ri
            eps = 1.0 - (own + solid[i, 0]) / volume if volume > 0.0 else 0.0
            fields[F_POROSITY, i] = min(max(eps, 0.0), 1.0)
