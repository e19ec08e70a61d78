"""The tessellation (engine/tessellation.py) on geometries whose cells are known exactly: simple
cubic (cubes of side 2R, faces (2R)²), FCC (rhombic dodecahedra, faces √2 R²), BCC (truncated
octahedra, hexagons 3√3 a²/16 and squares a²/8), periodic and clipped by walls (mirror
particles), and the radical plane of two unequal spheres."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.engine.tessellation import Plane, tessellate

R = 1e-3
#: Relative accuracy of the cells: freud (plain) computes in single precision, pyvoro2
#: (radical) in double (measured: 6e-7 and 5e-15 on these lattices).
TOLERANCE = {"plain": 1e-6, "radical": 1e-13}


def box_planes(lower: np.ndarray, upper: np.ndarray, axes=(0, 1, 2)) -> list[Plane]:  # noqa: ANN001
    planes = []
    for a in axes:
        for side, value in ((1.0, lower[a]), (-1.0, upper[a])):
            point, normal = np.zeros(3), np.zeros(3)
            point[a], normal[a] = value, side
            planes.append(Plane(point, normal, (), f"face {a} {side}"))
    return planes


def lattice(kind: str, cells: int) -> tuple[np.ndarray, float]:
    """Touching spheres of radius R on a lattice; (positions, cubic lattice constant)."""
    if kind == "sc":
        a, basis = 2 * R, [[0, 0, 0]]
    elif kind == "fcc":
        a, basis = 2 * math.sqrt(2) * R, [[0, 0, 0], [0, 0.5, 0.5], [0.5, 0, 0.5], [0.5, 0.5, 0]]
    else:
        a, basis = 4 * R / math.sqrt(3), [[0, 0, 0], [0.5, 0.5, 0.5]]
    g = np.arange(cells)
    corners = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    pos = (corners[:, None, :] + np.array(basis)[None]).reshape(-1, 3) * a + 0.25 * a
    return pos, a


@pytest.mark.parametrize("method", ["plain", "radical"])
@pytest.mark.parametrize("kind", ["sc", "fcc", "bcc"])
def test_periodic_lattice_cells_and_faces(kind: str, method: str) -> None:
    pos, a = lattice(kind, 3)
    upper = np.full(3, 3 * a)
    f = tessellate(pos, np.full(len(pos), R), np.zeros(3), upper, np.ones(3, bool), [], method)
    n = len(pos)
    # freud (plain) works in single precision; pyvoro2 (radical) in double: exact to round-off
    tol = TOLERANCE[method]
    volume = {"sc": 8 * R**3, "fcc": a**3 / 4, "bcc": a**3 / 2}[kind]
    assert f.volume == pytest.approx(np.full(n, volume), rel=tol)
    faces = np.sort(f.pair_area)
    if kind == "sc":
        assert f.pair_i.size == 3 * n and faces == pytest.approx(np.full(3 * n, 4 * R**2), rel=tol)
    elif kind == "fcc":
        assert f.pair_i.size == 6 * n
        assert faces == pytest.approx(np.full(6 * n, math.sqrt(2) * R**2), rel=tol)
    else:
        assert f.pair_i.size == 7 * n  # 8 hexagons and 6 squares per cell
        want = np.sort([3 * math.sqrt(3) * a**2 / 16] * 4 * n + [a**2 / 8] * 3 * n)
        assert faces == pytest.approx(want, rel=tol)
    assert f.wall_area.size == 0


@pytest.mark.parametrize("method", ["plain", "radical"])
def test_simple_cubic_in_a_closed_box_is_cubes_with_faces_on_the_walls(method: str) -> None:
    pos, a = lattice("sc", 4)
    pos += 0.5 * a - 0.25 * a  # centres at R, 3R, ...: the walls touch the outer spheres
    upper = np.full(3, 4 * a)
    planes = box_planes(np.zeros(3), upper)
    f = tessellate(pos, np.full(len(pos), R), np.zeros(3), upper, np.zeros(3, bool), planes,
                   method)  # fmt: skip
    n = len(pos)
    tol = TOLERANCE[method]
    assert f.volume == pytest.approx(np.full(n, 8 * R**3), rel=tol)
    assert f.pair_i.size == 3 * 4 * 4 * 3
    assert f.pair_area == pytest.approx(np.full(f.pair_i.size, 4 * R**2), rel=tol)
    # every outer cell face lies on a wall: 6 × 16 faces of (2R)²
    assert f.wall_area.size == 96
    assert f.wall_area == pytest.approx(np.full(96, 4 * R**2), rel=tol)
    for q in range(6):  # each wall sees the 16 particles of its side
        sel = f.wall_particle[f.wall_index == q]
        a_ = q // 2
        want = pos[:, a_] < a if q % 2 == 0 else pos[:, a_] > 3 * a
        assert set(sel.tolist()) == set(np.nonzero(want)[0].tolist())


@pytest.mark.parametrize("method", ["plain", "radical"])
def test_two_spheres_in_a_box_meet_at_the_bisector_or_the_radical_plane(method: str) -> None:
    side = 4 * R
    upper = np.array([2 * side, side, side])
    r = np.array([0.8 * R, 1.6 * R])
    pos = np.array([[0.7 * side, 0.5 * side, 0.5 * side], [1.35 * side, 0.5 * side, 0.5 * side]])
    planes = box_planes(np.zeros(3), upper)
    f = tessellate(pos, r, np.zeros(3), upper, np.zeros(3, bool), planes, method)
    d = pos[1, 0] - pos[0, 0]
    # the face: the bisector (plain) or the power plane (|x - c_i|² - R_i² equal on both sides)
    x = 0.5 * d if method == "plain" else (d * d + r[0] ** 2 - r[1] ** 2) / (2 * d)
    plane = pos[0, 0] + x
    tol = TOLERANCE[method]
    assert f.volume == pytest.approx([plane * side**2, (2 * side - plane) * side**2], rel=tol)
    assert f.pair_area == pytest.approx([side**2], rel=tol)
    assert f.wall_area.size == 10  # five walls per cell (the sixth face is the shared one)


def test_a_particle_outside_a_plane_is_a_clear_error() -> None:
    pos = np.array([[1e-3, 1e-3, 1e-3], [3e-3, 1e-3, -1e-4]])
    planes = box_planes(np.zeros(3), np.full(3, 4e-3))
    with pytest.raises(ValueError, match="particle index 1.*domain|not on the particles' side"):
        tessellate(pos, np.full(2, R), np.zeros(3), np.full(3, 4e-3), np.zeros(3, bool), planes,
                   "plain")  # fmt: skip


def test_a_periodic_box_of_two_cells_is_refused() -> None:
    pos, a = lattice("sc", 2)
    with pytest.raises(ValueError, match="share more than one face"):
        tessellate(pos, np.full(len(pos), R), np.zeros(3), np.full(3, 2 * a), np.ones(3, bool),
                   [], "plain")  # fmt: skip
    # named by their global ids when given (as the case and the outputs name them)
    with pytest.raises(ValueError, match=r"^particle 10\d and particle 10\d share more"):
        tessellate(pos, np.full(len(pos), R), np.zeros(3), np.full(3, 2 * a), np.ones(3, bool),
                   [], "plain", np.arange(len(pos)) + 100)  # fmt: skip


@pytest.mark.parametrize("method", ["plain", "radical"])
def test_compiled_cells_and_both_mirror_selections_agree(
    method: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A loose polydisperse heap with a rough free surface between two walls and a floor (the
    nearest centres far from some wall points), three ways: the compiled clipped cells, the
    library with the particles mirrored by their possible reach of a plane (its nodes'
    distances to the nearest centre; passes the checks at the first attempt) and the library
    with the column-layer selection (forced by an empty first selection, which fails its
    checks and falls back; more mirrors): the same faces and volumes."""
    import thermodem.engine.tessellation as tess

    rng = np.random.default_rng(5)
    side, height = 24 * R, 30 * R
    n = 400
    pos = rng.uniform([R, R, R], [side - R, side - R, height], size=(n, 3))
    # a rough surface: keep the points under a wavy height field, thin near the x walls
    top = 10 * R + 6 * R * np.sin(pos[:, 1] / (3 * R)) ** 2 + 8 * R * (pos[:, 0] > 0.3 * side)
    pos = pos[pos[:, 2] < top]
    radius = rng.uniform(0.6, 1.0, pos.shape[0]) * R
    lower, upper = np.zeros(3), np.array([side, side, height])
    planes = box_planes(lower, upper, axes=(0, 1))
    planes.append(Plane(np.zeros(3), np.array([0.0, 0.0, 1.0]), (), "floor"))
    top_plane = np.array([0.0, 0.0, pos[:, 2].max() + 2 * R])
    planes.append(Plane(top_plane, np.array([0.0, 0.0, -1.0]), (), "free surface"))
    upper[2] = top_plane[2]
    periodic = np.zeros(3, bool)
    compiled = tessellate(pos, radius, lower, upper, periodic, planes, method, backend="compiled")
    by_reach = tessellate(pos, radius, lower, upper, periodic, planes, method, backend="library")
    assert by_reach.attempts == 1

    def nothing(x: np.ndarray, normals: np.ndarray, *args: object) -> list[np.ndarray]:
        return [np.zeros(x.shape[0], bool)] * len(normals)

    monkeypatch.setattr(tess, "_reaching", nothing)
    layered = tessellate(pos, radius, lower, upper, periodic, planes, method, backend="library")
    assert layered.attempts >= 2
    assert by_reach.mirrors < layered.mirrors
    tol = 1e-5 if method == "plain" else 1e-12  # freud's single precision
    for other in (by_reach, compiled):
        assert_same_faces(other, layered, tol)
        assert other.volume.sum() == pytest.approx(side * side * top_plane[2], rel=1e-6)
    assert compiled.mirrors == 0


def assert_same_faces(a, b, tol: float) -> None:  # noqa: ANN001
    """The same faces (pairs and walls) with areas within ``tol`` of the largest, apart from
    slivers near AREA_TOLERANCE R̄² that only one of them keeps (single precision), and the
    same cell volumes."""
    for pairs in (("pair_i", "pair_j", "pair_area"), ("wall_particle", "wall_index", "wall_area")):
        fa = {(int(i), int(j)): x for i, j, x in zip(*(getattr(a, k) for k in pairs), strict=True)}
        fb = {(int(i), int(j)): x for i, j, x in zip(*(getattr(b, k) for k in pairs), strict=True)}
        scale = max(max(fa.values(), default=0.0), max(fb.values(), default=0.0))
        for key in set(fa) | set(fb):
            assert abs(fa.get(key, 0.0) - fb.get(key, 0.0)) <= max(tol, 1e-6) * scale, key
        assert len(set(fa) ^ set(fb)) <= 0.002 * len(fb)
    assert np.abs(a.volume - b.volume).max() <= tol * np.abs(b.volume).max()
