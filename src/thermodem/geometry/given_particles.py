"""Particles at given positions: ``file`` and ``list`` insertion entries (the particles a
user writes down or another code settled), read and checked before anything runs: in the
plane z = 0 in 2D, inside the domain, not coincident nor overlapping each other or the
particles of earlier entries by more than ``simulation.max_overlap_ratio`` (each message names
the entry, the row or file line and the particle). Called by
:func:`thermodem.geometry.insertion.insert`."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from thermodem.config.insertion import FileInsertion, ListInsertion
from thermodem.errors import ConfigError
from thermodem.geometry.insertion import InsertedParticles, WallsOk
from thermodem.io.particle_file import _parse_particle_file

#: Two given particles whose centres are closer than this fraction of the larger radius are
#: coincident: refused even with ``overlap_check: false``, since such a pair never interacts
#: (it has no contact normal).
COINCIDENT_DISTANCE = 1e-9


def insert_given(
    entry: FileInsertion | ListInsertion,
    walls_ok: WallsOk | None,
    planar: bool,
    key: str,
    domain: Any,
    max_overlap_ratio: float,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    periodic: Any = None,
) -> InsertedParticles:
    """The particles of a ``file`` or ``list`` entry, checked (see the module docstring).
    ``periodic`` (three booleans, with ``domain``): pairs across a periodic boundary are
    checked by their nearest images, as the run sees them."""
    given = _insert_file(entry, walls_ok, planar) if isinstance(entry, FileInsertion) else None
    if isinstance(entry, ListInsertion):
        given = _insert_list(entry)
    assert given is not None
    if planar:
        _check_planar(given, entry)
    _check_given(entry, given, key, domain, max_overlap_ratio, existing_positions,
                 existing_radii, planar, periodic)  # fmt: skip
    return given.particles


@dataclass
class _Given:
    """Particles at given positions and where each one was given (for messages)."""

    particles: InsertedParticles
    where: Callable[[int], str]
    """index -> 'insertion.0.positions.3' or "insertion.0.path: particle file 'f', line 7"."""


def _check_planar(given: _Given, entry: FileInsertion | ListInsertion) -> None:
    """2D: every given particle in the plane z = 0, moving in it."""
    p = given.particles
    for what, values in (("centre", p.position), ("velocity", p.velocity)):
        bad = np.flatnonzero(values[:, 2] != 0.0)
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"{given.where(i)}: the particle {what} {_vec(values[i])} has a z component; "
                f"in a 2D case particles lie and move in the plane z = 0 ({bad.size} of "
                f"{len(p)} particles have z != 0)"
            )


def _insert_file(entry: FileInsertion, walls_ok: WallsOk | None, planar: bool = False) -> _Given:
    parsed = _parse_particle_file(entry.path, entry.material, planar)
    p = parsed.particles
    n = len(p)
    if not parsed.has_velocity:
        p.velocity = np.tile(np.asarray(entry.velocity, dtype=np.float64), (n, 1))
    elif any(v != 0.0 for v in entry.velocity):
        warnings.warn(
            f"particle file {str(entry.path)!r} has velocity columns, which set every "
            f"particle's velocity: the entry's velocity {list(entry.velocity)} m/s is not used; "
            "leave one of them out",
            RuntimeWarning,
            stacklevel=2,
        )
    if not parsed.has_temperature and entry.temperature is not None:
        p.temperature = np.full(n, float(entry.temperature))
    elif parsed.has_temperature and entry.temperature is not None:
        warnings.warn(
            f"particle file {str(entry.path)!r} has a temperature column, which sets every "
            f"particle's initial temperature: the entry's temperature = {entry.temperature:g} "
            "K is not used; leave one of them out",
            RuntimeWarning,
            stacklevel=2,
        )
    if walls_ok is not None and n:
        ok = np.asarray(walls_ok(p.position, p.radius), dtype=np.bool_)
        bad = np.flatnonzero(~ok)
        if bad.size:
            raise ValueError(
                f"particle file {str(entry.path)!r}: {bad.size} particle(s) cut through or lie "
                f"outside a wall, the first on line {parsed.line_numbers[bad[0]]}"
            )

    def where(i: int) -> str:
        return f"particle file {str(entry.path)!r}, line {parsed.line_numbers[i]}"

    return _Given(p, where)


def _insert_list(entry: ListInsertion) -> _Given:
    n = len(entry.positions)
    if entry.velocities is not None:
        velocity = np.asarray(entry.velocities, dtype=np.float64).reshape(n, 3)
    else:
        velocity = np.tile(np.asarray(entry.velocity, dtype=np.float64), (n, 1))
    temperature = None
    if entry.temperatures is not None:
        temperature = np.asarray(entry.temperatures, dtype=np.float64)
    elif entry.temperature is not None:
        temperature = np.full(n, float(entry.temperature))
    p = InsertedParticles(
        position=np.asarray(entry.positions, dtype=np.float64).reshape(n, 3),
        radius=entry.radius_array(),
        velocity=velocity,
        temperature=temperature,
        material=entry.material,
    )
    return _Given(p, lambda i: f"positions.{i}")


def _vec(x: np.ndarray) -> str:
    return "[" + ", ".join(f"{float(c):.6g}" for c in x) + "]"


def _check_given(
    entry: FileInsertion | ListInsertion,
    given: _Given,
    key: str,
    domain: tuple[np.ndarray, np.ndarray] | None,
    limit: float,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    planar: bool = False,
    periodic: Any = None,
) -> None:
    """Refuse given particles outside the domain, wider than it (a radius in mm read as
    metres), coincident or overlapping too deeply (across a periodic boundary too)."""
    p = given.particles
    sep = "." if isinstance(entry, ListInsertion) else ".path: "

    def at(i: int) -> str:
        return f"{key}{sep}{given.where(i)}"

    if domain is not None and len(p):
        lower = np.asarray(domain[0], dtype=np.float64)
        upper = np.asarray(domain[1], dtype=np.float64)
        outside = np.any((p.position < lower) | (p.position > upper), axis=1)
        bad = np.flatnonzero(outside)
        if bad.size:
            i = int(bad[0])
            raise ConfigError(
                f"{at(i)}: particle centre {_vec(p.position[i])} is outside the domain "
                f"[{_vec(lower)}, {_vec(upper)}] ({bad.size} of {len(p)} particles are); move "
                "the particles or enlarge domain"
            )
        extent = upper - lower
        for a, axis in enumerate("xy" if planar else "xyz"):
            wide = np.flatnonzero(2.0 * p.radius > extent[a])
            if wide.size:
                i = int(wide[np.argmax(p.radius[wide])])
                r = float(p.radius[i])
                raise ConfigError(
                    f"{at(i)}: radius {r:g} m: the particle ({2.0 * r:g} m across) is wider "
                    f"than the domain along {axis} ({lower[a]:g} .. {upper[a]:g} m, "
                    f"{extent[a]:g} m; {wide.size} of {len(p)} particles are); lengths are in "
                    "metres (is the radius in mm?); give radii smaller than half the domain or "
                    "enlarge domain"
                )
    images = _Images(domain, periodic)
    found = _deepest_overlap(
        p.position,
        p.radius,
        limit,
        existing_positions,
        existing_radii,
        coincident_only=not entry.overlap_check,
        images=images,
    )
    if found is None:
        return
    i, j, ratio, other_entry = found
    if other_entry:
        assert existing_positions is not None and existing_radii is not None
        other_pos = np.asarray(existing_positions, dtype=np.float64).reshape(-1, 3)[j]
        other_rad = float(np.asarray(existing_radii).reshape(-1)[j])
        other = f"a particle of an earlier insertion entry at {_vec(other_pos)}"
    else:
        other_pos, other_rad = p.position[j], float(p.radius[j])
        other = f"the particle of {given.where(j)}" if sep != "." else f"{key}.{given.where(j)}"
    gap = images.separation(p.position[[i]], np.reshape(other_pos, (1, 3)))[0]
    distance = float(np.linalg.norm(gap))
    across = not np.allclose(gap, p.position[i] - other_pos, rtol=0.0, atol=0.0)
    if distance <= COINCIDENT_DISTANCE * max(float(p.radius[i]), other_rad):
        what = f"is at the same position as {other} (a duplicate row?)"
    else:
        wrapped = images.axes(gap, p.position[i] - other_pos) if across else ""
        what = (
            f"overlaps {other} by {ratio:.3g} of the smaller radius (centres {distance:.6g} m "
            f"apart{' across the periodic boundary of ' + wrapped if wrapped else ''})"
        )
    rule = (
        f"given particles may overlap by at most simulation.max_overlap_ratio = {limit:g} of the "
        "smaller radius (two coincident particles never interact)"
        if entry.overlap_check
        else "coincident particles are refused even with overlap_check: false (they never interact)"
    )
    raise ConfigError(
        f"{at(i)}: the particle at {_vec(p.position[i])} {what}; {rule}; remove or move one of them"
    )


def _deepest_overlap(
    pos: np.ndarray,
    rad: np.ndarray,
    limit: float,
    existing_positions: np.ndarray | None,
    existing_radii: np.ndarray | None,
    coincident_only: bool = False,
    images: _Images | None = None,
) -> tuple[int, int, float, bool] | None:
    """The first pair (in the order given) whose overlap exceeds ``limit`` × the smaller
    radius (``coincident_only``: whose centres are within :data:`COINCIDENT_DISTANCE` × the
    larger radius): (i, j, overlap ratio, j is an existing particle), or None.

    Pairs come from a k-d tree (scipy.spatial.cKDTree) within ``r_i + r_max``: O(n log n);
    ``images``: the periodic axes of the domain (pairs by their nearest images).
    """
    n = rad.shape[0]
    if n == 0:
        return None
    images = images if images is not None else _Images(None, None)

    def _overlap_ratio(pa, ra, pb, rb):  # noqa: ANN001, ANN202
        return overlap_ratio(pa, ra, pb, rb, images)

    def bad_pairs(pa, ra, pb, rb):  # noqa: ANN001, ANN202
        if coincident_only:
            gap = images.separation(pa, pb)
            d = np.sqrt(np.einsum("ij,ij->i", gap, gap))
            return d <= COINCIDENT_DISTANCE * np.maximum(ra, rb)
        return _overlap_ratio(pa, ra, pb, rb) > limit

    ex_rad0 = np.asarray(existing_radii if existing_radii is not None else [], np.float64)
    reach0 = max(float(rad.max()), float(ex_rad0.max()) if ex_rad0.size else 0.0)
    make_tree = images.tree_maker(2.0 * reach0)
    tree = make_tree(pos)
    candidates: list[tuple[int, int, float, bool]] = []
    reach = float(rad.max())
    if n > 1:
        cut = COINCIDENT_DISTANCE * reach if coincident_only else 2.0 * reach
        pairs = tree.query_pairs(cut, output_type="ndarray")
        if pairs.size:
            a, b = pairs[:, 0], pairs[:, 1]
            bad = np.flatnonzero(bad_pairs(pos[a], rad[a], pos[b], rad[b]))
            if bad.size:
                late = np.maximum(a[bad], b[bad])
                k = bad[np.lexsort((np.minimum(a[bad], b[bad]), late))[0]]
                i, j = max(int(a[k]), int(b[k])), min(int(a[k]), int(b[k]))
                ratio = float(_overlap_ratio(pos[[i]], rad[[i]], pos[[j]], rad[[j]])[0])
                candidates.append((i, j, ratio, False))
    if existing_positions is not None and existing_radii is not None and len(existing_radii):
        ex_pos = np.asarray(existing_positions, dtype=np.float64).reshape(-1, 3)
        ex_rad = np.asarray(existing_radii, dtype=np.float64).reshape(-1)
        reach = max(reach, float(ex_rad.max()))
        cut = COINCIDENT_DISTANCE * reach if coincident_only else float(rad.max() + ex_rad.max())
        m = tree.sparse_distance_matrix(make_tree(ex_pos), cut, output_type="ndarray")
        if m.size:
            a, b = m["i"].astype(np.int64), m["j"].astype(np.int64)
            bad = np.flatnonzero(bad_pairs(pos[a], rad[a], ex_pos[b], ex_rad[b]))
            if bad.size:
                k = bad[np.argmin(a[bad])]
                i, j = int(a[k]), int(b[k])
                ratio = float(_overlap_ratio(pos[[i]], rad[[i]], ex_pos[[j]], ex_rad[[j]])[0])
                candidates.append((i, j, ratio, True))
    if not candidates:
        return None
    return min(candidates, key=lambda c: c[0])


def overlap_ratio(
    pa: np.ndarray,
    ra: np.ndarray,
    pb: np.ndarray,
    rb: np.ndarray,
    images: _Images | None = None,
) -> np.ndarray:
    """(r_a + r_b - |x_a - x_b|) / min(r_a, r_b) for each pair (coincident: >= 2); with
    ``images``, |x_a - x_b| between the nearest images on the periodic axes."""
    gap = pa - pb if images is None else images.separation(pa, pb)
    d = np.sqrt(np.einsum("ij,ij->i", gap, gap))
    return (ra + rb - d) / np.minimum(ra, rb)


class _Images:
    """The periodic axes of the domain for the overlap checks: separations between nearest
    images, and k-d trees with the domain's periodic topology (scipy's ``boxsize``; a
    non-periodic axis gets a box wider than the domain and any search, so nothing wraps)."""

    def __init__(self, domain: Any, periodic: Any) -> None:
        self.period = np.zeros(3)
        self.lower = np.zeros(3)
        self.extent = np.zeros(3)
        if domain is not None and periodic is not None and any(bool(p) for p in periodic):
            self.lower = np.asarray(domain[0], dtype=np.float64)
            self.extent = np.asarray(domain[1], dtype=np.float64) - self.lower
            self.period = np.where(np.asarray(periodic, dtype=bool), self.extent, 0.0)

    def separation(self, pa: np.ndarray, pb: np.ndarray) -> np.ndarray:
        gap = pa - pb
        on = self.period > 0.0
        if on.any():
            gap[:, on] -= self.period[on] * np.round(gap[:, on] / self.period[on])
        return gap

    def axes(self, gap: np.ndarray, direct: np.ndarray) -> str:
        """The axes on which the nearest image is not the direct difference ('x and z')."""
        names = [a for k, a in enumerate("xyz") if gap[k] != direct[k]]
        return " and ".join(names)

    def tree_maker(self, cut: float) -> Callable[[np.ndarray], Any]:
        from scipy.spatial import cKDTree

        if not (self.period > 0.0).any():
            return cKDTree
        period, on = self.period, self.period > 0.0
        pad = self.extent + cut
        box = np.where(on, period, 3.0 * self.extent + 4.0 * cut)

        def make(points: np.ndarray) -> Any:
            shifted = np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.lower
            shifted[:, on] = np.mod(shifted[:, on], period[on])
            shifted[:, on] = np.where(shifted[:, on] >= period[on], 0.0, shifted[:, on])
            shifted[:, ~on] += pad[~on]  # (the domain's extent beyond it on either side)
            return cKDTree(shifted, boxsize=box)

        return make
