"""Random sequential addition: non-overlapping random placement of spheres in a region.

Candidate positions are drawn with vectorised numpy; the sequential accept/reject step runs in a
Numba kernel that tests each candidate against a hashed cell grid of the particles already
present, so the cost is O(N) rather than O(N^2). Holds the hash-grid kernels, the grids of
existing particles (:class:`_Obstacles`), the regions (:class:`_Box`, :class:`_Cylinder`) and
:func:`_random_fill`, used by :mod:`thermodem.geometry.insertion`.

Overlap grids: particles are binned by centre in cubic cells of edge ``2 r_max`` (``r_max``: the
largest radius being inserted); a candidate can only overlap particles in the 27 cells around
its own. Existing particles larger than ``r_max`` go into a second grid with cells of edge
``r_max + R_max`` (``R_max``: the largest existing radius), so one large obstacle does not
coarsen the grid for everything else. Cells are hashed into a table of about twice the number of
particles, so memory does not depend on the size of the region.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numba import njit

from thermodem.config.insertion import BoxRegion, CylinderRegion

if TYPE_CHECKING:
    from thermodem.geometry.insertion import WallsOk

_AXES = ("x", "y", "z")
_CANDIDATE_BATCH = 16384  # candidate positions drawn per round of random sequential addition

# --------------------------------------------------------------------------------------------
# Hashed cell grid (Numba)
# --------------------------------------------------------------------------------------------


@njit(cache=True)
def _bucket(x, y, z, origin, inv_cell, mask):
    """Hash-table slot of the cell containing (x, y, z)."""
    ix = np.int64(np.floor((x - origin[0]) * inv_cell))
    iy = np.int64(np.floor((y - origin[1]) * inv_cell))
    iz = np.int64(np.floor((z - origin[2]) * inv_cell))
    return ((ix * 73856093) ^ (iy * 19349663) ^ (iz * 83492791)) & mask


@njit(cache=True)
def _grid_hits(head, nxt, gpos, grad, origin, inv_cell, mask, x, y, z, r):
    """True if the sphere (x, y, z, r) overlaps a sphere stored in the grid.

    Valid when ``r`` plus any stored radius is at most the cell edge.
    """
    ix = np.int64(np.floor((x - origin[0]) * inv_cell))
    iy = np.int64(np.floor((y - origin[1]) * inv_cell))
    iz = np.int64(np.floor((z - origin[2]) * inv_cell))
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            for dz in range(-1, 2):
                h = (
                    ((ix + dx) * 73856093) ^ ((iy + dy) * 19349663) ^ ((iz + dz) * 83492791)
                ) & mask
                j = head[h]
                while j >= 0:
                    ddx = x - gpos[j, 0]
                    ddy = y - gpos[j, 1]
                    ddz = z - gpos[j, 2]
                    s = r + grad[j]
                    if ddx * ddx + ddy * ddy + ddz * ddz < s * s:
                        return True
                    j = nxt[j]
    return False


@njit(cache=True)
def _grid_push(head, nxt, gpos, grad, count, origin, inv_cell, mask, x, y, z, r):
    """Store a sphere in the grid; returns the new number of stored spheres."""
    gpos[count, 0] = x
    gpos[count, 1] = y
    gpos[count, 2] = z
    grad[count] = r
    h = _bucket(x, y, z, origin, inv_cell, mask)
    nxt[count] = head[h]
    head[h] = count
    return count + 1


@njit(cache=True)
def _grid_fill(head, nxt, gpos, grad, count, origin, inv_cell, mask, pos, rad):
    """Store many spheres; returns the new number of stored spheres."""
    for i in range(rad.shape[0]):
        count = _grid_push(
            head, nxt, gpos, grad, count, origin, inv_cell, mask, pos[i, 0], pos[i, 1],
            pos[i, 2], rad[i],
        )  # fmt: skip
    return count


@njit(cache=True)
def _place_candidates(
    cand, ok, radii, chosen,
    a_head, a_nxt, a_pos, a_rad, a_count, a_origin, a_inv, a_mask,
    b_head, b_nxt, b_pos, b_rad, b_origin, b_inv, b_mask,
):  # fmt: skip
    """Random sequential addition: particle i takes its first acceptable candidate.

    ``cand`` (m, k, 3) candidate centres, ``ok`` (m, k) pre-screened candidates, ``radii`` (m,).
    A candidate is accepted if it overlaps nothing in grid A (same-size and newly placed
    particles) or grid B (large existing particles); accepted particles are added to grid A.
    ``chosen[i]`` receives the accepted candidate index (left at -1 if none). Returns the new
    count of grid A.
    """
    for i in range(cand.shape[0]):
        r = radii[i]
        for c in range(cand.shape[1]):
            if not ok[i, c]:
                continue
            x = cand[i, c, 0]
            y = cand[i, c, 1]
            z = cand[i, c, 2]
            if _grid_hits(a_head, a_nxt, a_pos, a_rad, a_origin, a_inv, a_mask, x, y, z, r):
                continue
            if _grid_hits(b_head, b_nxt, b_pos, b_rad, b_origin, b_inv, b_mask, x, y, z, r):
                continue
            a_count = _grid_push(
                a_head, a_nxt, a_pos, a_rad, a_count, a_origin, a_inv, a_mask, x, y, z, r
            )
            chosen[i] = c
            break
    return a_count


@njit(cache=True)
def _overlap_mask(
    pos, radii,
    a_head, a_nxt, a_pos, a_rad, a_origin, a_inv, a_mask,
    b_head, b_nxt, b_pos, b_rad, b_origin, b_inv, b_mask,
):  # fmt: skip
    """For each sphere, whether it overlaps a sphere stored in grid A or grid B."""
    out = np.zeros(radii.shape[0], dtype=np.bool_)
    for i in range(radii.shape[0]):
        x = pos[i, 0]
        y = pos[i, 1]
        z = pos[i, 2]
        r = radii[i]
        out[i] = _grid_hits(
            a_head, a_nxt, a_pos, a_rad, a_origin, a_inv, a_mask, x, y, z, r
        ) or _grid_hits(b_head, b_nxt, b_pos, b_rad, b_origin, b_inv, b_mask, x, y, z, r)
    return out


class _HashGrid:
    """Arrays of one hashed cell grid (linked lists of spheres per hash slot)."""

    def __init__(self, cell: float, capacity: int, origin: np.ndarray) -> None:
        table = 1 << max(10, math.ceil(math.log2(max(2 * capacity, 1))))
        self.head = np.full(table, -1, dtype=np.int64)
        self.mask = np.int64(table - 1)
        self.nxt = np.empty(max(capacity, 1), dtype=np.int64)
        self.pos = np.empty((max(capacity, 1), 3), dtype=np.float64)
        self.rad = np.empty(max(capacity, 1), dtype=np.float64)
        self.count = 0
        self.origin = np.ascontiguousarray(origin, dtype=np.float64)
        self.inv_cell = 1.0 / cell

    def fill(self, pos: np.ndarray, rad: np.ndarray) -> None:
        self.count = int(
            _grid_fill(
                self.head, self.nxt, self.pos, self.rad, self.count, self.origin,
                self.inv_cell, self.mask, np.ascontiguousarray(pos, dtype=np.float64),
                np.ascontiguousarray(rad, dtype=np.float64),
            )
        )  # fmt: skip

    def lookup_args(self) -> tuple[Any, ...]:
        return (self.head, self.nxt, self.pos, self.rad, self.origin, self.inv_cell, self.mask)


def _as_existing(
    positions: np.ndarray | None, radii: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """Existing particles as float64 (n, 3) and (n,) arrays (None means none)."""
    if positions is None or radii is None:
        return np.zeros((0, 3)), np.zeros(0)
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    rad = np.asarray(radii, dtype=np.float64).reshape(-1)
    if pos.shape[0] != rad.shape[0]:
        raise ValueError(
            f"existing_positions has {pos.shape[0]} rows but existing_radii has {rad.shape[0]}"
        )
    return pos, rad


class _Obstacles:
    """The existing particles that could touch a new sphere of radius <= ``r_max`` in a box."""

    def __init__(
        self,
        lower: np.ndarray,
        upper: np.ndarray,
        r_max: float,
        positions: np.ndarray | None,
        radii: np.ndarray | None,
        extra_capacity: int,
    ) -> None:
        pos, rad = _as_existing(positions, radii)
        if rad.size:
            gap = np.maximum(np.maximum(lower - pos, pos - upper), 0.0)
            near = np.sqrt(np.einsum("ij,ij->i", gap, gap)) < rad + r_max
            pos, rad = pos[near], rad[near]
        small = rad <= r_max
        self.small = _HashGrid(2.0 * r_max, int(small.sum()) + extra_capacity, lower)
        self.small.fill(pos[small], rad[small])
        big_rad = rad[~small]
        big_cell = r_max + (float(big_rad.max()) if big_rad.size else r_max)
        self.big = _HashGrid(big_cell, big_rad.size, lower)
        self.big.fill(pos[~small], big_rad)

    def overlapping(self, pos: np.ndarray, rad: np.ndarray) -> np.ndarray:
        """Bool mask of the spheres that overlap an existing particle."""
        return _overlap_mask(
            np.ascontiguousarray(pos, dtype=np.float64),
            np.ascontiguousarray(rad, dtype=np.float64),
            *self.small.lookup_args(),
            *self.big.lookup_args(),
        )


# --------------------------------------------------------------------------------------------
# Regions
# --------------------------------------------------------------------------------------------


def _m(value: float) -> str:
    """A length for a message: ``0.002 m`` (not ``np.float64(0.002) m``)."""
    return f"{float(value):.6g} m"


class _Box:
    """Axis-aligned box: candidate centres keep a distance r from every face."""

    def __init__(self, lower: Any, upper: Any) -> None:
        self.lower = np.asarray(lower, dtype=np.float64)
        self.upper = np.asarray(upper, dtype=np.float64)

    def bbox(self) -> tuple[np.ndarray, np.ndarray]:
        return self.lower, self.upper

    def check_fits(self, r_max: float, what: str) -> None:
        extent = self.upper - self.lower
        for a, axis in enumerate(_AXES):
            if extent[a] < 2.0 * r_max:
                raise ValueError(
                    f"{what}: a particle of radius {_m(r_max)} does not fit in the box, which is "
                    f"{_m(extent[a])} wide along {axis}; enlarge the box or use smaller radii"
                )

    def volume(self) -> float:
        return float(np.prod(self.upper - self.lower))

    def sample(self, radii: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
        r = radii[:, None, None]
        u = rng.random((radii.size, k, 3))
        return self.lower + r + u * (self.upper - self.lower - 2.0 * r)


def _perpendicular_basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing ``axis`` (unit) to a right-handed orthonormal basis."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


class _Cylinder:
    """Solid cylinder: centres keep a distance r from the mantle and both end discs."""

    def __init__(self, base_centre: Any, axis: Any, radius: float, length: float) -> None:
        self.base = np.asarray(base_centre, dtype=np.float64)
        self.axis = np.asarray(axis, dtype=np.float64)
        self.axis = self.axis / np.linalg.norm(self.axis)
        self.radius = float(radius)
        self.length = float(length)
        self.e1, self.e2 = _perpendicular_basis(self.axis)

    def bbox(self) -> tuple[np.ndarray, np.ndarray]:
        top = self.base + self.length * self.axis
        half = self.radius * np.sqrt(np.clip(1.0 - self.axis**2, 0.0, 1.0))
        return np.minimum(self.base, top) - half, np.maximum(self.base, top) + half

    def check_fits(self, r_max: float, what: str) -> None:
        if self.radius < r_max or self.length < 2.0 * r_max:
            raise ValueError(
                f"{what}: a particle of radius {_m(r_max)} does not fit in the cylinder of "
                f"radius {_m(self.radius)} and length {_m(self.length)}; enlarge the cylinder "
                "or use smaller radii"
            )

    def volume(self) -> float:
        return math.pi * self.radius**2 * self.length

    def sample(self, radii: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
        r = radii[:, None]
        u = rng.random((radii.size, k, 3))
        rho = (self.radius - r) * np.sqrt(u[..., 0])
        theta = 2.0 * np.pi * u[..., 1]
        h = r + (self.length - 2.0 * r) * u[..., 2]
        return (
            self.base
            + h[..., None] * self.axis
            + (rho * np.cos(theta))[..., None] * self.e1
            + (rho * np.sin(theta))[..., None] * self.e2
        )


class _Rect(_Box):
    """A box region of a 2D case: the rectangle of its x-y extent in the plane z = 0; its
    "volume" is the area (discs fill areas)."""

    def __init__(self, lower: Any, upper: Any) -> None:
        super().__init__(lower, upper)
        self.lower[2] = 0.0
        self.upper[2] = 0.0

    def check_fits(self, r_max: float, what: str) -> None:
        extent = self.upper - self.lower
        for a, axis in enumerate(_AXES[:2]):
            if extent[a] < 2.0 * r_max:
                raise ValueError(
                    f"{what}: a particle of radius {_m(r_max)} does not fit in the box, which is "
                    f"{_m(extent[a])} wide along {axis}; enlarge the box or use smaller radii"
                )

    def volume(self) -> float:
        return float((self.upper[0] - self.lower[0]) * (self.upper[1] - self.lower[1]))

    def sample(self, radii: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
        r = radii[:, None, None]
        u = rng.random((radii.size, k, 2))
        out = np.zeros((radii.size, k, 3))
        out[..., :2] = self.lower[:2] + r + u * (self.upper[:2] - self.lower[:2] - 2.0 * r)
        return out


class _Circle:
    """A cylinder region along z of a 2D case: the circle of its radius around the axis in
    the plane z = 0; its "volume" is the area. Centres keep a distance r from the circle."""

    def __init__(self, base_centre: Any, radius: float) -> None:
        self.centre = np.asarray(base_centre, dtype=np.float64).copy()
        self.centre[2] = 0.0
        self.radius = float(radius)

    def bbox(self) -> tuple[np.ndarray, np.ndarray]:
        half = np.array([self.radius, self.radius, 0.0])
        return self.centre - half, self.centre + half

    def check_fits(self, r_max: float, what: str) -> None:
        if self.radius < r_max:
            raise ValueError(
                f"{what}: a particle of radius {_m(r_max)} does not fit in the circle of "
                f"radius {_m(self.radius)}; enlarge the region or use smaller radii"
            )

    def volume(self) -> float:
        return math.pi * self.radius**2

    def sample(self, radii: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
        r = radii[:, None]
        u = rng.random((radii.size, k, 2))
        rho = (self.radius - r) * np.sqrt(u[..., 0])
        theta = 2.0 * np.pi * u[..., 1]
        out = np.zeros((radii.size, k, 3))
        out[..., 0] = self.centre[0] + rho * np.cos(theta)
        out[..., 1] = self.centre[1] + rho * np.sin(theta)
        return out


def _region_of(
    region: BoxRegion | CylinderRegion, planar: bool = False
) -> _Box | _Cylinder | _Circle:
    """The sampler of a region; ``planar`` (2D case): its x-y section in the plane z = 0."""
    if isinstance(region, BoxRegion):
        return _Rect(region.lower, region.upper) if planar else _Box(region.lower, region.upper)
    if planar:  # (the axis is along z: checked with the case)
        return _Circle(region.base_centre, region.radius)
    return _Cylinder(region.base_centre, region.axis, region.radius, region.length)


def _random_fill(
    region: _Box | _Cylinder | _Circle,
    radii: np.ndarray,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None,
    max_attempts: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Random sequential addition of spheres with the given radii into ``region``.

    Particles are placed largest first; each round draws a batch of candidates for every
    unplaced particle. A particle that has used ``max_attempts`` candidates is abandoned.
    Returns (positions (n, 3), placed (n,) bool), in the order of ``radii``; positions of
    abandoned particles are NaN.
    """
    n = radii.size
    positions = np.full((n, 3), np.nan)
    placed = np.zeros(n, dtype=np.bool_)
    if n == 0:
        return positions, placed
    order = np.argsort(-radii, kind="stable")
    r_sorted = np.ascontiguousarray(radii[order])
    r_max = float(r_sorted[0])
    lower, upper = region.bbox()
    obstacles = _Obstacles(lower, upper, r_max, existing_positions, existing_radii, n)
    grid_a, grid_b = obstacles.small, obstacles.big
    sorted_pos = np.full((n, 3), np.nan)
    remaining = np.arange(n)
    used = 0
    while remaining.size and used < max_attempts:
        k = min(max(1, _CANDIDATE_BATCH // remaining.size), max_attempts - used)
        rr = r_sorted[remaining]
        cand = np.ascontiguousarray(region.sample(rr, k, rng))
        if walls_ok is None:
            ok = np.ones((rr.size, k), dtype=np.bool_)
        else:
            ok = np.asarray(walls_ok(cand.reshape(-1, 3), np.repeat(rr, k)), dtype=np.bool_)
            ok = np.ascontiguousarray(ok.reshape(rr.size, k))
        chosen = np.full(rr.size, -1, dtype=np.int64)
        grid_a.count = int(
            _place_candidates(
                cand, ok, rr, chosen,
                grid_a.head, grid_a.nxt, grid_a.pos, grid_a.rad, grid_a.count, grid_a.origin,
                grid_a.inv_cell, grid_a.mask,
                *grid_b.lookup_args(),
            )
        )  # fmt: skip
        hit = chosen >= 0
        sorted_pos[remaining[hit]] = cand[np.flatnonzero(hit), chosen[hit]]
        remaining = remaining[~hit]
        used += k
    positions[order] = sorted_pos
    placed[order] = ~np.isnan(sorted_pos[:, 0])
    return positions, placed
