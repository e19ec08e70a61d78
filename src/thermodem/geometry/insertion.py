"""Particle insertion: lattices, random packings, pouring and particle files.

All randomness goes through the :class:`numpy.random.Generator` the caller passes in, so a given
seed reproduces the same particles. The radii come from :mod:`thermodem.geometry.distributions`;
random packings and pouring place them by random sequential addition
(:mod:`thermodem.geometry.random_fill`).

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

from thermodem.config.insertion import (
    FileInsertion,
    LatticeInsertion,
    PourInsertion,
    RandomBoxInsertion,
    RandomCylinderInsertion,
)
from thermodem.geometry.distributions import _radii_for_volume, sample_radii
from thermodem.geometry.random_fill import (
    _AXES,
    _Box,
    _Cylinder,
    _Obstacles,
    _random_fill,
    _region_of,
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
