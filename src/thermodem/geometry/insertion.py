"""Particle insertion: lattices, random packings, pouring and particle files.

All randomness goes through the :class:`numpy.random.Generator` the caller passes in, so a given
seed reproduces the same particles. The radii come from :mod:`thermodem.geometry.distributions`;
random packings and pouring place them by random sequential addition
(:mod:`thermodem.geometry.random_fill`); the ``file`` and ``list`` entries are read and checked
in :mod:`thermodem.geometry.given_particles`.

Public API: :class:`InsertedParticles`, :func:`sample_radii`, :func:`insert`,
:func:`lattice_sites`, :class:`Pourer` and :func:`load_particle_file`.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermodem.config.insertion import (
    FileInsertion,
    LatticeInsertion,
    ListInsertion,
    PourInsertion,
    RandomBoxInsertion,
    RandomCylinderInsertion,
)
from thermodem.errors import ConfigError
from thermodem.geometry.distributions import _radii_for_volume, mean_sphere_volume, sample_radii
from thermodem.geometry.random_fill import (
    _AXES,
    _Box,
    _Circle,
    _Cylinder,
    _Obstacles,
    _random_fill,
    _Rect,
    _region_of,
)
from thermodem.io.particle_file import (  # noqa: F401 (re-exported)
    FILE_OPTIONAL_COLUMNS,
    FILE_REQUIRED_COLUMNS,
    _parse_particle_file,
    load_particle_file,
    save_particle_file,
)

#: Random sequential addition of equal spheres jams at a solid fraction of about 0.38
#: (Torquato, Uche & Stillinger 2006, Phys. Rev. E 74, 061308; less near walls, somewhat more
#: for polydisperse radii): a ``random_*`` entry whose particles would fill more than this
#: fraction of its region is refused before any attempt (it could only fail, slowly).
RSA_MAX_FRACTION = 0.5

#: Default of ``simulation.max_overlap_ratio``: the deepest overlap accepted between given
#: particles (file, list) when the caller does not pass the case's value.
DEFAULT_MAX_OVERLAP_RATIO = 0.2

WallsOk = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""Predicate ``walls_ok(positions (n, 3), radii (n,)) -> bool (n,)``: True where a sphere is
acceptable (e.g. it does not cut through a wall). Candidates for which it is False are rejected.
"""


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
# Static insertion kinds
# --------------------------------------------------------------------------------------------


def lattice_axis_counts(entry: LatticeInsertion, planar: bool = False) -> tuple[int, int, int]:
    """Number of lattice sites along x, y and z (without allocating them); ``planar`` (2D):
    one layer at z = 0."""
    r_max = entry.distribution.max_radius_bound
    if r_max is None:
        raise ValueError("lattice insertion needs a bounded radius distribution (set max_radius)")
    if entry.count is not None:
        nz = 1 if planar else int(entry.count[2])
        return (int(entry.count[0]), int(entry.count[1]), nz)
    margin = r_max + entry.jitter
    out = []
    for a in range(2 if planar else 3):
        span = entry.upper[a] - entry.lower[a] - 2.0 * margin
        spacing = entry.axis_spacing(a)
        assert spacing is not None
        out.append(int(math.floor(max(span, 0.0) / spacing + 1e-9)) + 1)
    if planar:
        out.append(1)
    return (out[0], out[1], out[2])


def lattice_sites(entry: LatticeInsertion, planar: bool = False) -> np.ndarray:
    """Unjittered lattice sites (n, 3) of a ``lattice`` entry, x varying fastest, then y, z;
    ``planar`` (2D): one layer at z = 0."""
    r_max = entry.distribution.max_radius_bound
    if r_max is None:
        raise ValueError("lattice insertion needs a bounded radius distribution (set max_radius)")
    margin = r_max + entry.jitter
    coords = []
    for a, axis in enumerate(_AXES):
        if planar and a == 2:
            coords.append(np.zeros(1))
            continue
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
    planar: bool = False,
    key: str = "insertion",
) -> InsertedParticles:
    sites = lattice_sites(entry, planar)
    radii = sample_radii(entry.distribution, sites.shape[0], rng)
    if entry.jitter > 0.0:
        jitter = rng.uniform(-entry.jitter, entry.jitter, sites.shape)
        if planar:
            jitter[:, 2] = 0.0
        sites = sites + jitter
    keep = np.ones(radii.size, dtype=np.bool_)
    if radii.size:
        lower = np.array(entry.lower, dtype=np.float64)
        upper = np.array(entry.upper, dtype=np.float64)
        if planar:
            lower[2] = upper[2] = 0.0
        obstacles = _Obstacles(
            lower, upper, float(radii.max()), existing_positions, existing_radii, 0
        )
        keep &= ~obstacles.overlapping(sites, radii)
        overlapped = int(radii.size - np.count_nonzero(keep))
        if overlapped and existing_radii is not None and len(existing_radii):
            # (an entry repeated, or a box over an earlier entry's: its sites were skipped
            # and the entry inserted fewer particles, or none, without a word)
            warnings.warn(
                f"{key}: {overlapped} of {radii.size} lattice sites overlap particles of earlier "
                f"insertion entries and are skipped (the entry inserts "
                f"{radii.size - overlapped}); move its box, or remove the entry if it repeats "
                "another",
                RuntimeWarning,
                stacklevel=2,
            )
        if walls_ok is not None:
            keep &= np.asarray(walls_ok(sites, radii), dtype=np.bool_)
    return _assemble(sites[keep], radii[keep], entry.velocity, entry.temperature, entry.material)


def _insert_random(
    entry: RandomBoxInsertion | RandomCylinderInsertion,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None,
    planar: bool = False,
) -> InsertedParticles:
    region: _Box | _Cylinder | _Circle
    if isinstance(entry, RandomBoxInsertion):
        region = _Rect(entry.lower, entry.upper) if planar else _Box(entry.lower, entry.upper)
    elif planar:  # a circle in the plane (the axis is along z: checked with the case)
        region = _Circle(entry.base_centre, entry.radius)
    else:
        region = _Cylinder(entry.base_centre, entry.axis, entry.radius, entry.length)
    bound = entry.distribution.max_radius_bound
    if bound is not None:
        region.check_fits(float(bound), f"{entry.kind} insertion")
    if entry.count is not None:
        mean = mean_sphere_volume(entry.distribution, planar=planar)
        fraction = entry.count * mean / region.volume()
        if fraction > RSA_MAX_FRACTION:
            what, unit = ("disc area", "m²") if planar else ("sphere volume", "m³")
            jam = "0.55 for equal discs" if planar else "0.38 for equal spheres"
            raise ValueError(
                f"count: {entry.count} particles (mean {what} {mean:.3g} {unit}) would fill "
                f"{fraction:.3g} of the region's {'area' if planar else 'volume'} "
                f"{region.volume():.3g} {unit}; random sequential addition jams near {jam}, "
                f"so more than {RSA_MAX_FRACTION} is refused: lower count, enlarge the region, "
                "or use a lattice (and let the particles settle)"
            )
        radii = sample_radii(entry.distribution, entry.count, rng)
    else:
        assert isinstance(entry, RandomBoxInsertion) and entry.volume_fraction is not None
        target = entry.volume_fraction * region.volume()
        radii = _radii_for_volume(entry.distribution, target, rng, planar)
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
    entry: LatticeInsertion
    | RandomBoxInsertion
    | RandomCylinderInsertion
    | FileInsertion
    | ListInsertion,
    rng: np.random.Generator,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    walls_ok: WallsOk | None = None,
    *,
    key: str = "insertion",
    domain: tuple[np.ndarray, np.ndarray] | None = None,
    max_overlap_ratio: float = DEFAULT_MAX_OVERLAP_RATIO,
    planar: bool = False,
    periodic: tuple[bool, bool, bool] | None = None,
) -> InsertedParticles:
    """Insert the particles of one static entry (``lattice``, ``random_*``, ``file``, ``list``).

    ``planar`` (a 2D case): the particles lie in the plane z = 0: a lattice has one layer, a
    random box fills its x-y rectangle and a random cylinder (along z) its circle, with
    ``volume_fraction`` an area fraction; a file may give ``x y r`` (z = 0), and given
    particles with z != 0 are refused.

    ``existing_positions`` (n, 3) and ``existing_radii`` (n,) are the particles already present
    (None or empty arrays for none). ``walls_ok`` optionally screens spheres against the walls.

    * ``lattice``: sites overlapping an existing particle or rejected by ``walls_ok`` are skipped.
    * ``random_box``/``random_cylinder``: random sequential addition; no particle overlaps an
      existing one or another new one, every particle lies fully inside the region. A count
      that would fill more than :data:`RSA_MAX_FRACTION` of the region is refused at once;
      otherwise an error if not every particle can be placed.
    * ``file``/``list``: positions are used as given, after checks: every centre inside
      ``domain`` (``(lower, upper)``, if given), no two particles (given, or given and
      existing) coincident or overlapping by more than ``max_overlap_ratio`` of the smaller
      radius (by the nearest images across the ``periodic`` axes of ``domain``), and
      ``walls_ok`` accepting every particle.

    Errors are :class:`~thermodem.errors.ConfigError` (a ValueError) whose message starts with
    ``key`` (the entry's key path, e.g. ``insertion.0``).

    ``pour`` entries are time dependent: use :class:`Pourer`.
    """
    if isinstance(entry, PourInsertion):
        raise TypeError("'pour' insertion entries are time dependent: use Pourer(entry, rng)")
    try:
        existing = (existing_positions, existing_radii, walls_ok, planar)
        if isinstance(entry, LatticeInsertion):
            return _insert_lattice(entry, rng, *existing, key=key)
        if isinstance(entry, RandomBoxInsertion | RandomCylinderInsertion):
            return _insert_random(entry, rng, *existing)
        if isinstance(entry, FileInsertion | ListInsertion):
            from thermodem.geometry.given_particles import insert_given  # (imports this module)

            return insert_given(entry, walls_ok, planar, key, domain, max_overlap_ratio,
                                existing_positions, existing_radii, periodic)  # fmt: skip
    except ConfigError:
        raise
    except ValueError as exc:
        text = str(exc)
        if isinstance(entry, FileInsertion):
            sep = ".path: "
        else:
            sep = "." if re.match(r"^[a-z_]+: ", text) else ": "
        raise ConfigError(f"{key}{sep}{text}") from None
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

    def __init__(
        self, entry: PourInsertion, rng: np.random.Generator, planar: bool = False
    ) -> None:
        self.entry = entry
        self.rng = rng
        self.planar = planar
        self._region = _region_of(entry.region, planar)
        self.inserted = 0
        """Particles inserted so far."""
        self.skipped = 0
        """Particles requested but not placed (the region was too full)."""
        self.last_time = float(entry.start_time)
        """Time up to which particles have been requested [s]."""
        self.batch_cap = max(
            1,
            int(
                RSA_MAX_FRACTION
                * self._region.volume()
                / mean_sphere_volume(entry.distribution, planar=planar)
            ),
        )
        """Most particles one batch tries to place: more than :data:`RSA_MAX_FRACTION` of the
        region could not be placed anyway (the rest of the batch is skipped at once, which
        bounds the work of a batch whatever the rate)."""

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

    def region_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounding box (lower, upper) of the pour region [m]."""
        return self._region.bbox()

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
        requested = n
        n = min(n, self.batch_cap)
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
        n = requested
        if n_placed < n:
            self.skipped += n - n_placed
            warnings.warn(
                f"pour insertion at t={time:.6g} s placed {n_placed} of {n} particles (the region "
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
