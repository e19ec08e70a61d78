"""The clipped Voronoi (or radical) tessellation of the particles: face areas, cell volumes,
faces on walls. The geometry only: :class:`~thermodem.engine.voronoi.VoronoiProvider`
(``engine/voronoi.py``) runs it on its update policy and fills the external pair set.

**Compiled cells first.** Each particle's cell is clipped from a box by the clipping planes
and by its neighbours' bisectors (``plain``) or power planes (``radical``) in double
precision (``kernels/voronoi_cells.py``; no mirror particles, serial); the
cells are used when every one fit its buffers, none reached its starting box and their
volumes add up to the clipped domain's (to 1e-6; ~1e-15 measured). Otherwise the libraries
below run, with their own checks (the 50k settled bed: 1.2 s against 2-3.6 s for freud with
mirrors).

**Libraries.** ``method: plain``: freud (``freud.locality.Voronoi``, voro++ inside, periodic
boxes, face areas as neighbour-list weights). freud needs coordinates of order 1: in metres
(mm particles) its neighbour list comes back empty without a warning, so every coordinate is
divided by the mean radius R̄ and the areas and volumes are multiplied by R̄² and R̄³. freud
works in single precision (face areas to ~1e-7 relative). freud has no radical tessellation;
``method: radical`` uses pyvoro2 (voro++'s power / Laguerre mode with the particle radii;
an optional dependency). The error of the plain tessellation for a polydisperse bed is
measured in ``docs/models/indirect_conduction-voronoi_a.md``.

**Boundaries without phantom cells.** The clipping planes are the non-periodic faces of the
domain and the plane walls. Each particle whose cell may reach a clipping plane gets a mirror
image across it: the bisector of a particle and its own mirror is the plane itself, and (for a
point on the particles' side) a mirror is never nearer than its original, so the cells of the
real particles are exactly their unbounded cells clipped by the planes, and the face between a
particle and its own mirror is the cell's face on the plane (area A_n of the particle-wall
pair; its double pyramid to the mirror is the spec's cone to the wall). Which particles need a
mirror is not known beforehand. First attempt: those whose cell may reach the plane's face,
found from the distance ρ of the plane's grid nodes to the nearest centre (a point X of the
plane is in P's cell only if |X - P| <= ρ(X); ``_reaching``), which bounds the set from above
without guessing a depth (the 50k settled bed: 11k mirrors instead of 33k, 2.1 s instead of
5 s per tessellation). Should that fail the checks below, the earlier selection takes over:
those within a layer (FIRST_LAYER × R_max) of the most recessed nearest particle of the
columns around their own across the plane. The result is checked: (1) no real cell has a
face with another particle's mirror, (2) no real cell is bounded through the padding of a
non-periodic axis, (3) the real cells' volumes add up to the clipped domain's volume. If a
check fails after the first attempt, the layer of the leaking planes grows fourfold (at most
until every particle is mirrored); a tessellation that still fails, or a particle centre
outside a clipping plane, is a ValueError (the provider's :class:`SimulationError`), never
silent zeros.
Free surfaces: an open domain face is moved in to FREE_SURFACE × R_max beyond the outermost
centres (see :func:`clipping_planes`).

The walls a face lies on are found from the wall rows: a plane wall is its own clipping plane;
a rectangle (the faces of a box wall) lying in a domain face, or with every particle on its
inner side, clips by its plane and takes the faces of the particles whose projection falls on
it. Cylinders and rectangles with particles on both sides do not clip the cells and exchange
no Voronoi heat (a warning says so when such a wall has a fixed temperature).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from thermodem.engine.mirror_selection import column_depth as _column_depth
from thermodem.engine.mirror_selection import reaching as _reaching
from thermodem.errors import ConfigError
from thermodem.geometry import wall_layout as wl

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation

#: Faces smaller than this × R̄² are degenerate (edge or vertex contacts of cells).
AREA_TOLERANCE = 1e-7
#: A face of a real cell with another particle's mirror larger than this × R̄² means the cell
#: is not clipped (a leak; exact geometry gives such faces zero area, single precision gives
#: slivers up to ~2e-3 R̄² along the long edges of free-surface cells).
LEAK_AREA = 1e-2
#: Relative tolerance of the volume check (freud works in single precision).
VOLUME_TOLERANCE = 1e-6
#: Mirror layer beyond the nearest particles of a plane (see ``_column_depth``), in R_max.
FIRST_LAYER = 4.0
#: An open domain face is moved in to this × R_max beyond the outermost centre.
FREE_SURFACE = 2.0


@dataclass
class Plane:
    """A clipping plane: points x with (x - point) · normal >= 0 are on the particles' side."""

    point: np.ndarray
    normal: np.ndarray
    walls: tuple[int, ...]  # wall rows lying in it (a plane wall: itself)
    name: str  # as messages name it: 'domain z lower face', 'plane walls.5 (lid)'
    face: bool = True  # a face of the domain box (else a wall's own plane, which cuts it)


@dataclass
class Faces:
    """One tessellation: particle indices, areas [m²], volumes [m³]."""

    pair_i: np.ndarray
    pair_j: np.ndarray
    pair_area: np.ndarray
    wall_particle: np.ndarray
    wall_index: np.ndarray
    wall_area: np.ndarray
    volume: np.ndarray
    mirrors: int
    attempts: int
    #: the compiled cells were tried and failed their checks (the library made these)
    fallback: bool = False


# ------------------------------------------------------------------------- geometry
def clipping_planes(sim: Simulation) -> tuple[list[Plane], list[int], np.ndarray, np.ndarray]:
    """The clipping planes of the current walls, the fixed-temperature walls that are not in
    any (they exchange no Voronoi heat), and the box the domain faces bound.

    A non-periodic domain face that carries no wall (an open top above a bed) is a free
    surface: it is moved in to FREE_SURFACE × R_max beyond the outermost particle centre (not
    past the domain), so that the cells of the surface particles end in the gas a diameter
    above them rather than at a far domain face (columns tens of radii tall, whose faces would
    make every surface pair conduct over a whole hemisphere, and which voro++ builds slowly).
    """
    from thermodem.engine.start_checks import wall_row_owners

    planes: list[Plane] = []
    kinds, rows = sim.wall_kind, sim.wall_rows
    owners = wall_row_owners(sim.case)
    used: set[int] = set()
    lower = np.array(sim.lower, float)
    upper = np.array(sim.upper, float)
    pos = sim.particles.position
    reach = FREE_SURFACE * float(sim.particles.radius.max()) if pos.shape[0] else 0.0
    for a in range(3):
        if sim.periodic[a]:
            continue
        for side, value in ((1.0, sim.lower[a]), (-1.0, sim.upper[a])):
            point = np.zeros(3)
            point[a] = value
            normal = np.zeros(3)
            normal[a] = side
            on = []
            for w in range(kinds.shape[0]):
                if kinds[w] not in (wl.PLANE, wl.RECTANGLE):
                    continue
                n_w = rows[w, wl.COL_NORMAL : wl.COL_NORMAL + 3]
                p_w = rows[w, wl.COL_POINT : wl.COL_POINT + 3]
                if abs(abs(float(n_w @ normal)) - 1.0) < 1e-9 and abs(p_w[a] - value) <= 1e-9 * (
                    1.0 + abs(value)
                ):
                    on.append(w)
            used.update(on)
            name = f"domain {'xyz'[a]} {'lower' if side > 0 else 'upper'} face"
            if not on and pos.shape[0]:
                name = f"free surface beyond the particles (open {name})"
                if side > 0:
                    value = max(float(value), float(pos[:, a].min()) - reach)
                    lower[a] = point[a] = value
                else:
                    value = min(float(value), float(pos[:, a].max()) + reach)
                    upper[a] = point[a] = value
            planes.append(Plane(point, normal, tuple(on), name))
    for w in range(kinds.shape[0]):
        if w in used or kinds[w] not in (wl.PLANE, wl.RECTANGLE):
            continue
        point = rows[w, wl.COL_POINT : wl.COL_POINT + 3].copy()
        normal = rows[w, wl.COL_NORMAL : wl.COL_NORMAL + 3].copy()
        if kinds[w] == wl.RECTANGLE and (
            pos.shape[0] == 0 or not np.all((pos - point) @ normal > 0.0)
        ):
            continue  # a rectangle with particles on both sides (a baffle): not a clip plane
        same = next((q for q in planes if abs(float(q.normal @ normal) - 1.0) < 1e-9
                     and abs(float((point - q.point) @ normal)) < 1e-12 * (1.0 + float(
                         np.abs(point).max()))), None)  # fmt: skip
        if same is not None:  # coplanar walls share one clipping plane
            same.walls = (*same.walls, w)
        else:
            planes.append(Plane(point, normal, (w,), wall_name(sim, w, owners), face=False))
        used.add(w)
    hot_elsewhere = [
        w for w in range(kinds.shape[0]) if w not in used and rows[w, wl.COL_THERMAL_KIND] != 0.0
    ]
    return planes, hot_elsewhere, lower, upper


def wall_name(sim: Simulation, w: int, owners: list[int] | None = None) -> str:
    """Wall row ``w`` as messages name it: its kind, its case key and its label
    (``plane walls.5 (plane5)``, ``rectangle walls.0 (box0.z-)``, a ``name`` given: ``plane
    walls.5 (lid)``). ``owners``: engine/start_checks.py's wall_row_owners of the case."""
    from thermodem.engine.start_checks import wall_row_owners

    if owners is None:
        owners = wall_row_owners(sim.case)
    k = owners[w] if w < len(owners) else w
    kind = wl.KIND_NAMES[int(sim.wall_kind[w])]
    return f"{kind} walls.{k} ({sim.wall_labels[w]})"


def clipped_volume(lower: np.ndarray, upper: np.ndarray, planes: list[Plane],
                   inside: np.ndarray) -> float:  # fmt: skip
    """Volume of the domain box cut by the planes (``inside``: a point strictly inside)."""
    box = float(np.prod(upper - lower))
    extra = [p for p in planes if not p.face]
    if not extra:
        return box
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    halfspaces = []
    for a in range(3):
        n = np.zeros(3)
        n[a] = -1.0
        halfspaces.append([*n, lower[a]])  # -x + lower <= 0
        n = np.zeros(3)
        n[a] = 1.0
        halfspaces.append([*n, -upper[a]])
    for p in extra:  # (x - point)·n >= 0  <=>  -n·x + n·point <= 0
        halfspaces.append([*(-p.normal), float(p.normal @ p.point)])
    hs = HalfspaceIntersection(np.array(halfspaces), inside)
    return float(ConvexHull(hs.intersections).volume)


@njit(cache=True, error_model="numpy")
def polygon_areas(vertices, vertex_start, face_vertices, face_start, face_cell, out):
    """Areas of planar polygons (Newell's formula): face f of cell face_cell[f] has the vertex
    indices face_vertices[face_start[f]:face_start[f + 1]] into that cell's vertices."""
    for f in range(face_start.shape[0] - 1):
        base = vertex_start[face_cell[f]]
        nx = ny = nz = 0.0
        a = face_start[f]
        b = face_start[f + 1]
        for k in range(a, b):
            p = vertices[base + face_vertices[k]]
            q = vertices[base + face_vertices[a + (k - a + 1) % (b - a)]]
            nx += (p[1] - q[1]) * (p[2] + q[2])
            ny += (p[2] - q[2]) * (p[0] + q[0])
            nz += (p[0] - q[0]) * (p[1] + q[1])
        out[f] = 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz)


def _freud_faces(points: np.ndarray, lengths: np.ndarray, n_real: int) -> tuple:
    """(cell, neighbour, area, vector, volumes of the real cells) from freud, coordinates
    centred on 0 in a periodic box of ``lengths`` (units of R̄)."""
    try:
        import freud
    except ImportError as exc:  # pragma: no cover - a dependency
        raise ConfigError(
            "thermal.tessellation.method = 'plain' needs the freud-analysis package "
            f"(pip install freud-analysis): {exc}"
        ) from None
    box = freud.box.Box(float(lengths[0]), float(lengths[1]), float(lengths[2]))
    voro = freud.locality.Voronoi()
    voro.compute((box, points))
    nl = voro.nlist
    cell = np.asarray(nl.query_point_indices, np.int64)
    keep = cell < n_real
    return (cell[keep], np.asarray(nl.point_indices, np.int64)[keep],
            np.asarray(nl.weights, np.float64)[keep],
            np.asarray(nl.vectors, np.float64)[keep],
            np.asarray(voro.volumes, np.float64)[:n_real].copy())  # fmt: skip


def _pyvoro2_faces(points: np.ndarray, radii: np.ndarray, lengths: np.ndarray,
                   periodic: np.ndarray, n_real: int) -> tuple:  # fmt: skip
    """The same as _freud_faces from pyvoro2's power (radical) tessellation; non-periodic
    axes are container walls (the padding keeps the real cells away from them)."""
    try:
        import pyvoro2 as pv
    except ImportError as exc:
        raise ConfigError(
            "thermal.tessellation.method = 'radical' needs the pyvoro2 package (pip install "
            f"pyvoro2; the radical / Laguerre tessellation of voro++): {exc}"
        ) from None
    half = 0.5 * lengths
    bounds = tuple((-float(h), float(h)) for h in half)
    domain = pv.OrthorhombicCell(bounds, periodic=tuple(bool(x) for x in periodic))
    pts = points.copy()
    for a in range(3):
        if periodic[a]:
            pts[:, a] = np.mod(pts[:, a] + half[a], lengths[a]) - half[a]
    cells = pv.compute(pts, domain=domain, mode="power", radii=radii, return_vertices=True,
                       return_adjacency=False, return_faces=True, output="cells")  # fmt: skip
    cells = [c for c in cells if c["id"] < n_real]
    volumes = np.zeros(n_real)
    ids, vert_blocks, vertex_start = [], [], [0]
    face_cell, neighbour, face_start, face_vertices = [], [], [0], []
    for k, c in enumerate(cells):
        volumes[c["id"]] = c["volume"]
        vert_blocks.append(np.asarray(c["vertices"], np.float64).reshape(-1, 3))
        vertex_start.append(vertex_start[-1] + vert_blocks[-1].shape[0])
        for f in c["faces"]:
            ids.append(c["id"])
            face_cell.append(k)
            neighbour.append(f["adjacent_cell"])
            face_vertices.extend(f["vertices"])
            face_start.append(len(face_vertices))
    area = np.zeros(len(ids))
    polygon_areas(np.concatenate(vert_blocks), np.array(vertex_start, np.int64),
                  np.array(face_vertices, np.int64), np.array(face_start, np.int64),
                  np.array(face_cell, np.int64), area)  # fmt: skip
    cell = np.array(ids, np.int64)
    nbr = np.array(neighbour, np.int64)
    # the neighbour's displacement (no wrap on non-periodic axes: walls of the container)
    vector = np.full((cell.size, 3), np.nan)
    ok = nbr >= 0
    vector[ok] = pts[nbr[ok]] - pts[cell[ok]]
    for a in range(3):
        if periodic[a]:
            vector[ok, a] -= lengths[a] * np.round(vector[ok, a] / lengths[a])
    return cell, nbr, area, vector, volumes


def tessellate(position: np.ndarray, radius: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               periodic: np.ndarray, planes: list[Plane], method: str,
               global_id: np.ndarray | None = None, backend: str = "auto") -> Faces:  # fmt: skip
    """The clipped Voronoi (or radical) tessellation of the spheres (see the module
    docstring). Raises ValueError with the reason if it cannot be made, naming particles by
    ``global_id`` (as the case and the outputs do; without it by their index here).
    ``backend``: "auto" (the compiled cells, the libraries if their check fails; the result
    says so in ``fallback``), "compiled" (no fallback: a ValueError instead), "library"
    (freud or pyvoro2 with mirrors)."""

    def particle(k: int) -> str:
        if global_id is None:
            return f"particle index {k}"
        return f"particle {int(global_id[k])}"

    n = position.shape[0]
    unit = float(radius.mean())
    r_max = float(radius.max()) / unit
    lo = np.asarray(lower, float) / unit
    hi = np.asarray(upper, float) / unit
    centre = 0.5 * (lo + hi)
    x = position / unit - centre
    lo, hi = lo - centre, hi - centre
    periodic = np.asarray(periodic, bool)
    normals = np.array([p.normal for p in planes]).reshape(-1, 3)
    points = np.array([p.point / unit - centre for p in planes]).reshape(-1, 3)
    signed = np.einsum("ika,ka->ik", x[:, None, :] - points[None], normals)
    if planes:
        bad = np.argwhere(signed <= 0.0)
        if bad.size:
            k, q = bad[0]
            raise ValueError(
                f"{particle(k)} (centre {position[k].tolist()} m) is not on the particles' side "
                f"of the {planes[q].name}: its cell cannot be clipped by it"
            )
    span = hi - lo
    inside = position.mean(axis=0)
    expected = clipped_volume(np.asarray(lower, float), np.asarray(upper, float), planes,
                              inside) / unit**3  # fmt: skip
    if backend != "library":
        cells = _clipped_cells(x, radius / unit, lo, hi, periodic, normals, points, method,
                               expected)  # fmt: skip
        if cells is not None:
            return _collect(*cells, unit, particle, 0, 0)
        if backend == "compiled":
            raise ValueError("the compiled cells did not pass their checks")
        fallback = True
    else:
        fallback = False
    spread = r_max**2 - (float(radius.min()) / unit) ** 2 if method == "radical" else 0.0
    reaching = _reaching(x, normals, points, spread, (FREE_SURFACE + 2.0) * r_max)
    depth: list[np.ndarray] = []
    layers = np.full(len(planes), FIRST_LAYER * r_max)
    reason = ""
    attempt = 0
    for _ in range(30):
        attempt += 1
        # mirrors
        idx, plane_of = [], []
        everything = (attempt > 1 and bool(layers.size)
                      and bool(np.all(layers > float(span.max()) + 2 * r_max)))  # fmt: skip
        if attempt == 2:  # the exact-reach selection leaked: the column layers below
            depth = [_column_depth(x, signed[:, q], normals[q], r_max) for q in range(len(planes))]
        for q in range(len(planes)):
            if attempt == 1:
                sel = np.nonzero(reaching[q])[0]
            else:
                sel = np.nonzero(signed[:, q] < depth[q] + layers[q])[0]
            idx.append(sel)
            plane_of.append(np.full(sel.size, q, np.int64))
        origin = np.concatenate(idx) if idx else np.zeros(0, np.int64)
        plane_of = np.concatenate(plane_of) if plane_of else np.zeros(0, np.int64)
        mirror = x[origin] - 2.0 * signed[origin, plane_of][:, None] * normals[plane_of]
        gen = np.concatenate([x, mirror])
        # a tight box: the mirror cells at its ends meet their periodic images (cheap, and
        # never a real cell's neighbour: the checks below)
        lengths = span.copy()
        shift = np.zeros(3)
        for a in range(3):
            if not periodic[a]:
                top, bottom = float(gen[:, a].max()), float(gen[:, a].min())
                lengths[a] = top - bottom + 4.0 * r_max
                shift[a] = -0.5 * (top + bottom)
        gen = gen + shift
        if method == "radical":
            rad = np.concatenate([radius, radius[origin]]) / unit
            cell, nbr, area, vector, volume = _pyvoro2_faces(gen, rad, lengths, periodic, n)
        else:
            cell, nbr, area, vector, volume = _freud_faces(gen, lengths, n)
        big = area > AREA_TOLERANCE
        real = nbr < n
        own = np.zeros(cell.size, bool)
        m = ~real
        own[m] = origin[nbr[m] - n] == cell[m]
        foreign = m & ~own & (area > LEAK_AREA)
        wrapped = np.zeros(cell.size, bool)
        r = real & big
        direct = gen[nbr[r]] - gen[cell[r]]
        for a in range(3):
            if not periodic[a]:
                wrapped[np.nonzero(r)[0]] |= np.abs(vector[r, a] - direct[:, a]) > 1e-3
        volume_error = abs(float(volume.sum()) - expected) / expected
        missing = np.nonzero(volume <= 0.0)[0]
        if (
            not foreign.any()
            and not wrapped.any()
            and volume_error <= VOLUME_TOLERANCE
            and (missing.size == 0)
        ):
            break
        reason = (
            f"{int(foreign.sum())} faces with other particles' mirrors, {int(wrapped.sum())} "
            f"faces through the padding, {missing.size} empty cells, cell volumes add up to "
            f"{volume_error:.3g} relative off the clipped domain's"
        )
        if everything:
            raise ValueError(f"the tessellation failed with every particle mirrored: {reason}")
        # grow the layers of the planes whose mirrors bound real cells, else all of them
        leaking = np.unique(plane_of[nbr[foreign] - n])
        if attempt == 1:
            continue
        if leaking.size and not wrapped.any():
            layers[leaking] *= 4.0
        else:
            layers *= 4.0
    else:  # pragma: no cover - the layer reaches the domain size long before
        raise ValueError(f"the tessellation failed: {reason}")
    sel = real & big
    w = m & own & big
    faces = _collect(cell[sel], nbr[sel], area[sel], cell[w], plane_of[nbr[w] - n], area[w],
                     volume, unit, particle, int(origin.size), attempt)  # fmt: skip
    faces.fallback = fallback
    return faces


def _collect(a: np.ndarray, b: np.ndarray, face: np.ndarray, w_cell: np.ndarray,
             w_plane: np.ndarray, w_area: np.ndarray, volume: np.ndarray, unit: float,
             particle: Callable[[int], str], mirrors: int, attempts: int) -> Faces:  # fmt: skip
    """Faces from the cells' faces in units of R̄: (a, b, face) between particles, each seen
    from one or both cells (the mean of the two areas), and (w_cell, w_plane, w_area) on the
    clipping planes."""
    key_i, key_j = np.minimum(a, b), np.maximum(a, b)
    order = np.lexsort((key_j, key_i))
    key_i, key_j, face = key_i[order], key_j[order], face[order]
    start = np.concatenate([[0], np.nonzero((np.diff(key_i) != 0) | (np.diff(key_j) != 0))[0] + 1])
    if key_i.size == 0:  # a single cell, or cells that only touch walls
        start = np.zeros(0, np.int64)
    counts = np.diff(np.append(start, key_i.size)).astype(np.int64)
    if np.any(counts > 2):
        k = int(start[np.argmax(counts > 2)])
        raise ValueError(
            f"{particle(int(key_i[k]))} and {particle(int(key_j[k]))} share more than one face "
            "(a periodic domain shorter than three cells along an axis): the pair would "
            "conduct twice"
        )
    sums = np.add.reduceat(face, start) if face.size else np.zeros(0)
    order = np.lexsort((w_plane, w_cell))
    return Faces(
        pair_i=key_i[start],
        pair_j=key_j[start],
        pair_area=sums / counts * unit**2,
        wall_particle=w_cell[order],
        wall_index=w_plane[order],
        wall_area=w_area[order] * unit**2,
        volume=volume * unit**3,
        mirrors=mirrors,
        attempts=attempts,
    )


def _clipped_cells(x: np.ndarray, radius: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                   periodic: np.ndarray, normals: np.ndarray, points: np.ndarray, method: str,
                   expected: float) -> tuple | None:  # fmt: skip
    """The cells by the compiled clipping of ``kernels/voronoi_cells.py`` (units of R̄,
    centred coordinates), as the arguments of ``_collect``; None when a cell did not fit its
    buffers, reached the starting box, or the volumes do not add up to the clipped domain's
    (the caller then uses the libraries)."""
    from thermodem.kernels import voronoi_cells as vc

    n = x.shape[0]
    if n == 0:
        return None
    r_max = float(radius.max())
    weight = radius**2 if method == "radical" else np.zeros(n)
    spread = float(weight.max() - weight.min())
    length = hi - lo
    target = 2.0 * r_max
    shape = np.empty(3, np.int64)
    size = np.empty(3)
    for a in range(3):
        shape[a] = max(1, int(length[a] // target)) if periodic[a] else max(
            1, int(math.ceil(length[a] / target)))  # fmt: skip
        size[a] = length[a] / shape[a] if periodic[a] else target
    index = np.clip(np.floor((x - lo) / size).astype(np.int64), 0, shape - 1)
    flat = (index[:, 0] * shape[1] + index[:, 1]) * shape[2] + index[:, 2]
    order = np.argsort(flat, kind="stable")
    start = np.zeros(int(shape.prod()) + 1, np.int64)
    np.cumsum(np.bincount(flat, minlength=int(shape.prod())), out=start[1:])
    label = np.empty((n, vc.MAX_OUT), np.int64)
    area = np.empty((n, vc.MAX_OUT))
    count = np.empty(n, np.int64)
    volume = np.empty(n)
    status = np.empty(n, np.int64)
    vc.voronoi_cells(np.ascontiguousarray(x), weight, spread, lo, hi, periodic,
                     np.ascontiguousarray(normals), np.ascontiguousarray(points),
                     2.0 * target, size, shape, start, order, label, area, count, volume,
                     status)  # fmt: skip
    if np.any(status != vc.OK) or np.any(volume <= 0.0):
        return None
    if abs(float(volume.sum()) - expected) > VOLUME_TOLERANCE * expected:
        return None
    rows = np.arange(vc.MAX_OUT)[None, :] < count[:, None]
    owner = np.broadcast_to(np.arange(n)[:, None], label.shape)[rows]
    label, area = label[rows], area[rows]
    big = area > AREA_TOLERANCE
    pair = big & (label >= 0)
    wall = big & (label < 0) & (label != vc.BOX)
    return (owner[pair], label[pair], area[pair], owner[wall], -1 - label[wall], area[wall],
            volume)  # fmt: skip


def wall_of_face(sim: Simulation, planes: list[Plane], particle: np.ndarray,
                 plane: np.ndarray) -> np.ndarray:  # fmt: skip
    """The wall row each clipped face lies on (-1: a domain face without a wall there)."""
    out = np.full(particle.size, -1, np.int64)
    pos = sim.particles.position
    rows = sim.wall_rows
    for q, pl in enumerate(planes):
        sel = np.nonzero(plane == q)[0]
        for w in pl.walls:
            free = sel[out[sel] < 0]
            if not free.size:
                break
            if sim.wall_kind[w] == wl.PLANE:
                out[free] = w
                continue
            row = rows[w]
            u = row[wl.COL_U : wl.COL_U + 3]
            n = row[wl.COL_NORMAL : wl.COL_NORMAL + 3]
            v = np.cross(n, u)
            rel = pos[particle[free]] - row[wl.COL_POINT : wl.COL_POINT + 3]
            on = (np.abs(rel @ u) <= row[wl.COL_HALF_U] * (1 + 1e-9)) & (
                np.abs(rel @ v) <= row[wl.COL_HALF_V] * (1 + 1e-9)
            )
            out[free[on]] = w
    return out


__all__ = ["Faces", "Plane", "clipping_planes", "tessellate", "wall_name", "wall_of_face"]
