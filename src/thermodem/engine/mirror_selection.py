"""Which particles get a mirror image across a clipping plane, for the tessellation by the
libraries (``engine/tessellation.py``): ``reaching`` (those whose cell may reach the plane,
from the distance of the plane's grid nodes to the nearest centre; the first attempt) and
``column_depth`` (the layers of the earlier selection, the fallback)."""

from __future__ import annotations

import itertools
import math

import numpy as np


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning the plane of ``normal``."""
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.5:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(normal, u)


def reaching(x: np.ndarray, normals: np.ndarray, points: np.ndarray, spread: float,
              pad: float) -> list[np.ndarray]:  # fmt: skip
    """For each plane, the particles whose cell may reach its part on the particles' side of
    the other planes (a superset, exact up to the sampling bound below).

    A point X of the plane belongs to particle P's cell only if |X - P| <= ρ(X), the distance
    from X to the nearest centre (radical cells: |X - P|² <= ρ(X)² + ``spread``, spread =
    R_max² - R_min²). The plane is sampled on a square grid of spacing h = 1 (units of R̄)
    over the particles' projection plus ``pad``, keeping the nodes within h of the face; every
    face point is within h/√2 of a node X_k and ρ is 1-Lipschitz, so P needs a mirror only if
    |X_k - P| <= √((ρ_k + h/√2)² + spread) + h/√2 for some node: a ball query per node."""
    from scipy.spatial import cKDTree

    tree = cKDTree(x)
    step = 1.0
    half_diag = step / math.sqrt(2.0)
    out = []
    for q in range(normals.shape[0]):
        u, v = plane_basis(normals[q])
        rel = x - points[q]
        a, b = rel @ u, rel @ v
        ga = np.arange(a.min() - pad, a.max() + pad + step, step)
        gb = np.arange(b.min() - pad, b.max() + pad + step, step)
        nodes = points[q] + ga[:, None, None] * u + gb[None, :, None] * v
        nodes = nodes.reshape(-1, 3)
        keep = np.ones(nodes.shape[0], bool)
        for o in range(normals.shape[0]):
            if o != q:
                keep &= (nodes - points[o]) @ normals[o] >= -step
        nodes = nodes[keep]
        rho = tree.query(nodes)[0]
        reach = np.sqrt((rho + half_diag) ** 2 + spread) + half_diag
        found = tree.query_ball_point(nodes, reach, return_sorted=False)
        mask = np.zeros(x.shape[0], bool)
        mask[np.fromiter(itertools.chain.from_iterable(found), np.int64)] = True
        out.append(mask)
    return out


def column_depth(x: np.ndarray, signed: np.ndarray, normal: np.ndarray,
                  r_max: float) -> np.ndarray:  # fmt: skip
    """For each particle, the distance to the plane of the most recessed nearest particle of
    the columns (width 2 R_max, across the plane) around its own: a particle whose cell
    reaches the plane is within a few radii of that depth, also under a rough free surface
    or where a free surface meets a wall."""
    u, v = plane_basis(normal)
    cu = np.floor((x @ u) / (2.0 * r_max)).astype(np.int64)
    cv = np.floor((x @ v) / (2.0 * r_max)).astype(np.int64)
    cu -= cu.min() - 1
    cv -= cv.min() - 1
    grid = np.full((int(cu.max()) + 2, int(cv.max()) + 2), -np.inf)
    nearest = np.full(grid.shape, np.inf)
    np.minimum.at(nearest, (cu, cv), signed)
    grid[np.isfinite(nearest)] = nearest[np.isfinite(nearest)]
    around = grid.copy()
    for du in (-1, 0, 1):
        for dv in (-1, 0, 1):
            around[1:-1, 1:-1] = np.maximum(around[1:-1, 1:-1],
                                            grid[1 + du : grid.shape[0] - 1 + du,
                                                 1 + dv : grid.shape[1] - 1 + dv])  # fmt: skip
    return around[cu, cv]
