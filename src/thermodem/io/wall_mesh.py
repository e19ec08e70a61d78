"""Triangulated wall surfaces for display (the wall frames of :mod:`thermodem.io.vtk`):
planes as squares, rectangles as two triangles, cylinders as open tubes, oriented towards the
particles."""

from __future__ import annotations

import math

import numpy as np

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
    WALL_WIDTH,
)


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    if not math.isfinite(norm) or norm == 0.0:
        raise ValueError(f"wall {what} must be a finite non-zero vector, got {v}")
    return v / norm


def _perpendicular_unit(n: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to the unit vector ``n``."""
    # Cross with the Cartesian axis least aligned with n: well conditioned.
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    return _unit(np.cross(n, e), "normal")


def _quad_mesh(
    centre: np.ndarray, u: np.ndarray, v: np.ndarray, hu: float, hv: float
) -> tuple[np.ndarray, np.ndarray]:
    """Two triangles covering centre + [-hu, hu] u + [-hv, hv] v, oriented along u x v."""
    points = np.array(
        [
            centre - hu * u - hv * v,
            centre + hu * u - hv * v,
            centre + hu * u + hv * v,
            centre - hu * u + hv * v,
        ]
    )
    triangles = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    return points, triangles


def wall_surface_mesh(
    kind: int, row: np.ndarray, resolution: int = 48, infinite_extent: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Triangulated surface of one wall, for display.

    Parameters
    ----------
    kind:
        ``PLANE``, ``RECTANGLE`` or ``CYLINDER`` (see :mod:`thermodem.geometry.wall_layout`).
    row:
        The wall's parameter row (``WALL_WIDTH`` float64 values).
    resolution:
        Number of segments around a cylinder (at least 3).
    infinite_extent:
        Half size used for what is unbounded: a plane is drawn as a square of side
        ``2 * infinite_extent`` centred at its point, a cylinder with infinite half length as a
        tube of length ``2 * infinite_extent`` centred at its axis point.

    Returns
    -------
    points, triangles:
        (P, 3) float64 vertices and (T, 3) int64 vertex indices. Triangles are oriented
        (right-hand rule) so that their normal points towards the particles: along the normal
        for planes and rectangles, towards the axis for a cylinder holding the particles inside
        (side +1) and away from it otherwise. A cylinder is an open tube (no end caps) whose
        vertices lie on the circle of the given radius, so its area is that of the inscribed
        polygonal prism, ``resolution * 2 R sin(pi / resolution) * 2 L``. A rotating cylinder is
        axisymmetric: its mesh does not change with time.
    """
    r = np.asarray(row, dtype=np.float64)
    if r.shape != (WALL_WIDTH,):
        raise ValueError(f"wall row must have shape ({WALL_WIDTH},), got {r.shape}")
    if not (infinite_extent > 0.0 and math.isfinite(infinite_extent)):
        raise ValueError(f"infinite_extent must be positive and finite, got {infinite_extent}")
    point = r[COL_POINT : COL_POINT + 3].copy()

    if kind == PLANE:
        n = _unit(r[COL_NORMAL : COL_NORMAL + 3], "normal")
        u = _perpendicular_unit(n)
        v = np.cross(n, u)
        return _quad_mesh(point, u, v, infinite_extent, infinite_extent)

    if kind == RECTANGLE:
        n = _unit(r[COL_NORMAL : COL_NORMAL + 3], "normal")
        u = _unit(r[COL_U : COL_U + 3], "u axis")
        # Keep u exactly in the plane (it should already be perpendicular to n).
        u = _unit(u - np.dot(u, n) * n, "u axis (parallel to the normal)")
        v = np.cross(n, u)
        hu, hv = float(r[COL_HALF_U]), float(r[COL_HALF_V])
        if not (hu > 0.0 and hv > 0.0 and math.isfinite(hu) and math.isfinite(hv)):
            raise ValueError(f"rectangle half extents must be positive and finite: {hu}, {hv}")
        return _quad_mesh(point, u, v, hu, hv)

    if kind == CYLINDER:
        if resolution < 3:
            raise ValueError(f"resolution must be at least 3, got {resolution}")
        a = _unit(r[COL_AXIS : COL_AXIS + 3], "axis")
        radius = float(r[COL_RADIUS])
        if not (radius > 0.0 and math.isfinite(radius)):
            raise ValueError(f"cylinder radius must be positive and finite, got {radius}")
        half_length = float(r[COL_HALF_LENGTH])
        if math.isinf(half_length):
            half_length = infinite_extent
        if not half_length > 0.0:
            raise ValueError(f"cylinder half length must be positive, got {half_length}")
        e1 = _perpendicular_unit(a)
        e2 = np.cross(a, e1)  # (e1, e2, a) right-handed
        theta = 2.0 * np.pi * np.arange(resolution) / resolution
        ring = radius * (np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2)
        bottom = point + ring - half_length * a
        top = point + ring + half_length * a
        points = np.concatenate([bottom, top])  # bottom k -> k, top k -> resolution + k
        k = np.arange(resolution, dtype=np.int64)
        k1 = (k + 1) % resolution
        # (bottom k, bottom k+1, top k+1) turns along e_theta then along a: the normal is
        # e_theta x a = e_r, outwards.
        outward = np.concatenate(
            [
                np.stack([k, k1, resolution + k1], axis=1),
                np.stack([k, resolution + k1, resolution + k], axis=1),
            ]
        )
        # Interleave so the two triangles of each quad are neighbours.
        triangles = outward.reshape(2, resolution, 3).transpose(1, 0, 2).reshape(-1, 3)
        if r[COL_SIDE] > 0.0:  # particles inside: normals towards the axis
            triangles = triangles[:, ::-1]
        return points, np.ascontiguousarray(triangles)

    raise ValueError(f"unknown wall kind {kind}")
