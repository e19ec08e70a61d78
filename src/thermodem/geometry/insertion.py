"""Particle insertion: radius sampling, lattices, random packings, pouring and particle files.

All randomness goes through the :class:`numpy.random.Generator` the caller passes in, so a given
seed reproduces the same particles. Candidate positions are drawn with vectorised numpy; the
sequential accept/reject step (random sequential addition) runs in a Numba kernel that tests
each candidate against a hashed cell grid of the particles already present, so the cost is
O(N) rather than O(N^2).

Overlap grids: particles are binned by centre in cubic cells of edge ``2 r_max`` (``r_max``: the
largest radius being inserted); a candidate can only overlap particles in the 27 cells around
its own. Existing particles larger than ``r_max`` go into a second grid with cells of edge
``r_max + R_max`` (``R_max``: the largest existing radius), so one large obstacle does not
coarsen the grid for everything else. Cells are hashed into a table of about twice the number of
particles, so memory does not depend on the size of the region.

Public API: :class:`InsertedParticles`, :func:`sample_radii`, :func:`insert`,
:func:`lattice_sites`, :class:`Pourer` and :func:`load_particle_file`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit
from scipy.special import ndtr, ndtri

from thermodem.config.insertion import (
    BoxRegion,
    CylinderRegion,
    DiscreteRadius,
    FileInsertion,
    LatticeInsertion,
    LognormalRadius,
    MonoRadius,
    PourInsertion,
    RandomBoxInsertion,
    RandomCylinderInsertion,
    TruncatedNormalRadius,
    UniformRadius,
)
from thermodem.io.particle_file import (  # noqa: F401 (re-exported)
    FILE_OPTIONAL_COLUMNS,
    FILE_REQUIRED_COLUMNS,
    _parse_particle_file,
    load_particle_file,
    save_particle_file,
)

WallsOk = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""Predicate ``walls_ok(positions (n, 3), radii (n,)) -> bool (n,)``: True where a sphere is
acceptable (e.g. it does not cut through a wall). Candidates for which it is False are rejected.
"""

_AXES = ("x", "y", "z")
_CANDIDATE_BATCH = 16384  # candidate positions drawn per round of random sequential addition


@dataclass
class InsertedParticles:
    """Particles produced by one insertion (all arrays float64, SI units)."""

    position: np.ndarray
    """(n, 3) centres [m]."""
    radius: np.ndarray
    """(n,) radii [m]."""
    velocity: np.ndarray
    """(n, 3) initial velocities [m/s]."""
    temperature: np.ndarray | None
    """(n,) initial temperatures [K], or None to use the engine's default."""
    material: str
    """Material name of every particle."""

    def __len__(self) -> int:
        return int(self.radius.shape[0])

    @classmethod
    def empty(cls, material: str, with_temperature: bool = False) -> InsertedParticles:
        """No particles."""
        return cls(
            position=np.zeros((0, 3)),
            radius=np.zeros(0),
            velocity=np.zeros((0, 3)),
            temperature=np.zeros(0) if with_temperature else None,
            material=material,
        )


def _assemble(
    position: np.ndarray,
    radius: np.ndarray,
    velocity: tuple[float, float, float],
    temperature: float | None,
    material: str,
) -> InsertedParticles:
    """Particles with a common velocity and temperature."""
    n = radius.shape[0]
    return InsertedParticles(
        position=np.ascontiguousarray(position, dtype=np.float64).reshape(n, 3),
        radius=np.ascontiguousarray(radius, dtype=np.float64),
        velocity=np.tile(np.asarray(velocity, dtype=np.float64), (n, 1)),
        temperature=None if temperature is None else np.full(n, float(temperature)),
        material=material,
    )


# --------------------------------------------------------------------------------------------
# Radius sampling
# --------------------------------------------------------------------------------------------


def _open_uniform(rng: np.random.Generator, count: int) -> np.ndarray:
    """Uniform samples on the open interval (0, 1) (``rng.random`` may return exactly 0)."""
    k = np.floor(rng.random(count) * 2.0**53)
    return (k + 0.5) / 2.0**53


def _truncated_standard_normal(
    alpha: float, beta: float, count: int, rng: np.random.Generator
) -> np.ndarray:
    """Standard normal samples restricted to ``[alpha, beta]`` by inverse-CDF sampling.

    An interval entirely in the upper tail is mirrored into the lower tail, where the normal CDF
    is represented accurately.
    """
    flip = alpha > 0.0
    if flip:
        alpha, beta = -beta, -alpha
    p_lo = float(ndtr(alpha))
    p_hi = float(ndtr(beta))
    z = ndtri(p_lo + _open_uniform(rng, count) * (p_hi - p_lo))
    z = np.clip(z, alpha, beta)
    return -z if flip else z


def sample_radii(dist: Any, count: int, rng: np.random.Generator) -> np.ndarray:
    """Draw ``count`` radii [m] from a radius distribution model (float64 array)."""
    count = int(count)
    if count < 0:
        raise ValueError(f"count must be >= 0, got {count}")
    if isinstance(dist, MonoRadius):
        return np.full(count, dist.radius, dtype=np.float64)
    if isinstance(dist, UniformRadius):
        return rng.uniform(dist.min_radius, dist.max_radius, count)
    if isinstance(dist, TruncatedNormalRadius):
        alpha = (dist.min_radius - dist.mean) / dist.std
        beta = (dist.max_radius - dist.mean) / dist.std
        r = dist.mean + dist.std * _truncated_standard_normal(alpha, beta, count, rng)
        return np.clip(r, dist.min_radius, dist.max_radius)
    if isinstance(dist, LognormalRadius):
        mu, sigma = dist.mu, dist.sigma
        alpha = -math.inf if dist.min_radius is None else (math.log(dist.min_radius) - mu) / sigma
        beta = math.inf if dist.max_radius is None else (math.log(dist.max_radius) - mu) / sigma
        r = np.exp(mu + sigma * _truncated_standard_normal(alpha, beta, count, rng))
        return np.clip(r, dist.min_radius, dist.max_radius)
    if isinstance(dist, DiscreteRadius):
        radii = np.asarray(dist.radii, dtype=np.float64)
        return radii[rng.choice(radii.size, size=count, p=dist.number_fractions())]
    raise TypeError(f"unknown radius distribution {type(dist).__name__}")


def _radii_for_volume(dist: Any, volume: float, rng: np.random.Generator) -> np.ndarray:
    """Radii drawn one after another until their summed sphere volume reaches ``volume``."""
    chunks: list[np.ndarray] = []
    total = 0.0
    size = 1024
    while total < volume:
        r = sample_radii(dist, size, rng)
        chunks.append(r)
        total += float(np.sum(4.0 / 3.0 * np.pi * r**3))
        size *= 2
    radii = np.concatenate(chunks)
    cumulative = np.cumsum(4.0 / 3.0 * np.pi * radii**3)
    n = int(np.searchsorted(cumulative, volume)) + 1
    return radii[: min(n, radii.size)]


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
                    f"{what}: a particle of radius {r_max!r} m does not fit in the box, which is "
                    f"{extent[a]!r} m wide along {axis}; enlarge the box or use smaller radii"
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
                f"{what}: a particle of radius {r_max!r} m does not fit in the cylinder of "
                f"radius {self.radius!r} m and length {self.length!r} m; enlarge the cylinder "
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


def _region_of(region: BoxRegion | CylinderRegion) -> _Box | _Cylinder:
    if isinstance(region, BoxRegion):
        return _Box(region.lower, region.upper)
    return _Cylinder(region.base_centre, region.axis, region.radius, region.length)


def _random_fill(
    region: _Box | _Cylinder,
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


# --------------------------------------------------------------------------------------------
# Static insertion kinds
# --------------------------------------------------------------------------------------------


def lattice_sites(entry: LatticeInsertion) -> np.ndarray:
    """Unjittered lattice sites (n, 3) of a ``lattice`` entry, x varying fastest, then y, z."""
    r_max = entry.distribution.max_radius_bound
    if r_max is None:
        raise ValueError("lattice insertion needs a bounded radius distribution (set max_radius)")
    margin = r_max + entry.jitter
    coords = []
    for a, axis in enumerate(_AXES):
        lo, hi = entry.lower[a], entry.upper[a]
        span = hi - lo - 2.0 * margin
        if span < 0.0:
            raise ValueError(
                f"lattice insertion: the box is {hi - lo!r} m wide along {axis}, smaller than "
                f"2 (r_max + jitter) = {2.0 * margin!r} m"
            )
        if entry.spacing is not None:
            s = entry.axis_spacing(a)
            assert s is not None
            n = int(math.floor(span / s + 1e-9)) + 1
            first = lo + margin + 0.5 * max(span - (n - 1) * s, 0.0)
            coords.append(first + s * np.arange(n))
        else:
            assert entry.count is not None
            n = entry.count[a]
            if n == 1:
                coords.append(np.array([0.5 * (lo + hi)]))
            else:
                coords.append(np.linspace(lo + margin, hi - margin, n))
    zz, yy, xx = np.meshgrid(coords[2], coords[1], coords[0], indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()])


def _insert_lattice(
    entry: LatticeInsertion,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None,
) -> InsertedParticles:
    sites = lattice_sites(entry)
    radii = sample_radii(entry.distribution, sites.shape[0], rng)
    if entry.jitter > 0.0:
        sites = sites + rng.uniform(-entry.jitter, entry.jitter, sites.shape)
    keep = np.ones(radii.size, dtype=np.bool_)
    if radii.size:
        lower = np.asarray(entry.lower, dtype=np.float64)
        upper = np.asarray(entry.upper, dtype=np.float64)
        obstacles = _Obstacles(
            lower, upper, float(radii.max()), existing_positions, existing_radii, 0
        )
        keep &= ~obstacles.overlapping(sites, radii)
        if walls_ok is not None:
            keep &= np.asarray(walls_ok(sites, radii), dtype=np.bool_)
    return _assemble(sites[keep], radii[keep], entry.velocity, entry.temperature, entry.material)


def _insert_random(
    entry: RandomBoxInsertion | RandomCylinderInsertion,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None,
) -> InsertedParticles:
    if isinstance(entry, RandomBoxInsertion):
        region: _Box | _Cylinder = _Box(entry.lower, entry.upper)
    else:
        region = _Cylinder(entry.base_centre, entry.axis, entry.radius, entry.length)
    if entry.count is not None:
        radii = sample_radii(entry.distribution, entry.count, rng)
    else:
        assert isinstance(entry, RandomBoxInsertion) and entry.volume_fraction is not None
        radii = _radii_for_volume(entry.distribution, entry.volume_fraction * region.volume(), rng)
    region.check_fits(float(radii.max()), f"{entry.kind} insertion")
    positions, placed = _random_fill(
        region, radii, rng, existing_positions, existing_radii, walls_ok, entry.max_attempts
    )
    n_placed = int(placed.sum())
    if n_placed < radii.size:
        raise ValueError(
            f"{entry.kind} insertion placed only {n_placed} of {radii.size} particles after "
            f"max_attempts={entry.max_attempts} candidate positions per particle; use a larger "
            "region, a lower count/volume_fraction, or a larger max_attempts"
        )
    return _assemble(positions, radii, entry.velocity, entry.temperature, entry.material)


def insert(
    entry: LatticeInsertion | RandomBoxInsertion | RandomCylinderInsertion | FileInsertion,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None = None,
) -> InsertedParticles:
    """Insert the particles of one static entry (``lattice``, ``random_*`` or ``file``).

    ``existing_positions`` (n, 3) and ``existing_radii`` (n,) are the particles already present
    (None or empty arrays for none). ``walls_ok`` optionally screens spheres against the walls.

    * ``lattice``: sites overlapping an existing particle or rejected by ``walls_ok`` are skipped.
    * ``random_box``/``random_cylinder``: random sequential addition; no particle overlaps an
      existing one or another new one, every particle lies fully inside the region. Raises
      ValueError if not every particle can be placed.
    * ``file``: positions are used as given (no overlap check); raises ValueError if
      ``walls_ok`` rejects any particle.

    ``pour`` entries are time dependent: use :class:`Pourer`.
    """
    if isinstance(entry, LatticeInsertion):
        return _insert_lattice(entry, rng, existing_positions, existing_radii, walls_ok)
    if isinstance(entry, RandomBoxInsertion | RandomCylinderInsertion):
        return _insert_random(entry, rng, existing_positions, existing_radii, walls_ok)
    if isinstance(entry, FileInsertion):
        return _insert_file(entry, walls_ok)
    if isinstance(entry, PourInsertion):
        raise TypeError("'pour' insertion entries are time dependent: use Pourer(entry, rng)")
    raise TypeError(f"unknown insertion entry {type(entry).__name__}")


# --------------------------------------------------------------------------------------------
# Pouring
# --------------------------------------------------------------------------------------------


class Pourer:
    """Time-dependent insertion for a ``pour`` entry.

    Call :meth:`due` every step; when it is True call :meth:`emit`, which inserts the particles
    requested since the previous emission. After time ``t`` a total of
    ``floor(rate (min(t, end_time) - start_time))`` particles has been requested. Particles that
    cannot be placed without overlap are skipped with a :class:`RuntimeWarning` and counted in
    ``skipped``; they are not requested again.
    """

    def __init__(self, entry: PourInsertion, rng: np.random.Generator) -> None:
        self.entry = entry
        self.rng = rng
        self._region = _region_of(entry.region)
        self.inserted = 0
        """Particles inserted so far."""
        self.skipped = 0
        """Particles requested but not placed (the region was too full)."""
        self.last_time = float(entry.start_time)
        """Time up to which particles have been requested [s]."""

    @property
    def finished(self) -> bool:
        """True once the final batch (at ``end_time``) has been emitted."""
        return self.entry.end_time is not None and self.last_time >= self.entry.end_time

    def _requested(self, time: float) -> int:
        """Total number of particles requested by ``time``."""
        t = time if self.entry.end_time is None else min(time, self.entry.end_time)
        if t <= self.entry.start_time:
            return 0
        return int(math.floor(self.entry.rate * (t - self.entry.start_time) + 1e-9))

    def next_time(self) -> float:
        """Time of the next scheduled batch [s]."""
        t = self.last_time + self.entry.interval
        return t if self.entry.end_time is None else min(t, self.entry.end_time)

    def due(self, time: float, dt: float) -> bool:
        """Whether a batch should be emitted in the step at ``time`` of length ``dt``.

        A batch is due from half a step before its scheduled time, so round-off in the
        accumulated time does not delay it by a whole step.
        """
        if self.finished:
            return False
        return time >= self.next_time() - 0.5 * dt

    def emit(
        self,
        time: float,
        existing_positions: np.ndarray | None,
        existing_radii: np.ndarray | None,
        walls_ok: WallsOk | None = None,
    ) -> InsertedParticles:
        """Insert the particles requested since the last emission (none before ``start_time``).

        New particles overlap neither the existing particles nor each other, and lie fully
        inside the region.
        """
        entry = self.entry
        t = time if entry.end_time is None else min(time, entry.end_time)
        n = self._requested(t) - (self.inserted + self.skipped)
        self.last_time = max(self.last_time, t)
        if n <= 0:
            return InsertedParticles.empty(entry.material, entry.temperature is not None)
        radii = sample_radii(entry.distribution, n, self.rng)
        self._region.check_fits(float(radii.max()), "pour insertion")
        positions, placed = _random_fill(
            self._region,
            radii,
            self.rng,
            existing_positions,
            existing_radii,
            walls_ok,
            entry.max_attempts,
        )
        n_placed = int(placed.sum())
        self.inserted += n_placed
        if n_placed < n:
            self.skipped += n - n_placed
            warnings.warn(
                f"pour insertion at t={time!r} s placed {n_placed} of {n} particles (the region "
                f"is too full; {self.skipped} skipped so far); use a larger region or a lower rate",
                RuntimeWarning,
                stacklevel=2,
            )
        return _assemble(
            positions[placed], radii[placed], entry.velocity, entry.temperature, entry.material
        )

    def state_dict(self) -> dict[str, Any]:
        """Restart state: counts so far and the time up to which particles were requested.

        The random generator belongs to the caller and is not included.
        """
        return {"inserted": self.inserted, "skipped": self.skipped, "last_time": self.last_time}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore the state saved by :meth:`state_dict`."""
        expected = {"inserted", "skipped", "last_time"}
        if set(state) != expected:
            raise ValueError(
                f"pour state must have exactly the keys {sorted(expected)}, got {sorted(state)}"
            )
        inserted, skipped = int(state["inserted"]), int(state["skipped"])
        last_time = float(state["last_time"])
        if inserted < 0 or skipped < 0 or not math.isfinite(last_time):
            raise ValueError(f"invalid pour state {state!r}")
        self.inserted, self.skipped, self.last_time = inserted, skipped, last_time


# --------------------------------------------------------------------------------------------
# Particle files
# --------------------------------------------------------------------------------------------


def _insert_file(entry: FileInsertion, walls_ok: WallsOk | None) -> InsertedParticles:
    parsed = _parse_particle_file(entry.path, entry.material)
    p = parsed.particles
    n = len(p)
    if not parsed.has_velocity:
        p.velocity = np.tile(np.asarray(entry.velocity, dtype=np.float64), (n, 1))
    if not parsed.has_temperature and entry.temperature is not None:
        p.temperature = np.full(n, float(entry.temperature))
    if walls_ok is not None and n:
        ok = np.asarray(walls_ok(p.position, p.radius), dtype=np.bool_)
        bad = np.flatnonzero(~ok)
        if bad.size:
            raise ValueError(
                f"particle file {str(entry.path)!r}: {bad.size} particle(s) cut through or lie "
                f"outside a wall, the first on line {parsed.line_numbers[bad[0]]}"
            )
    return p
