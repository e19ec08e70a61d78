"""ParaView writers: particle and wall VTU files, wall surface meshes and the PVD index."""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from thermodem.geometry.wall_layout import (
    COL_AXIS,
    COL_HALF_LENGTH,
    COL_HALF_U,
    COL_HALF_V,
    COL_NORMAL,
    COL_POINT,
    COL_RADIUS,
    COL_SIDE,
    COL_TEMPERATURE,
    COL_U,
    CYLINDER,
    PLANE,
    RECTANGLE,
    WALL_WIDTH,
)
from thermodem.io.vtk import (
    PART_PARTICLES,
    PART_WALLS,
    PVDWriter,
    write_particles_vtu,
    write_walls_vtu,
)
from thermodem.io.wall_mesh import wall_surface_mesh

# ---------------------------------------------------------------------------- helpers


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def plane_row(point, normal) -> np.ndarray:
    r = np.zeros(WALL_WIDTH)
    r[COL_POINT : COL_POINT + 3] = point
    r[COL_NORMAL : COL_NORMAL + 3] = _unit(normal)
    return r


def rectangle_row(centre, normal, u, hu, hv) -> np.ndarray:
    r = plane_row(centre, normal)
    r[COL_U : COL_U + 3] = _unit(u)
    r[COL_HALF_U] = hu
    r[COL_HALF_V] = hv
    return r


def cylinder_row(point, axis, radius, half_length, side) -> np.ndarray:
    r = np.zeros(WALL_WIDTH)
    r[COL_POINT : COL_POINT + 3] = point
    r[COL_AXIS : COL_AXIS + 3] = _unit(axis)
    r[COL_RADIUS] = radius
    r[COL_HALF_LENGTH] = half_length
    r[COL_SIDE] = side
    return r


def triangle_vectors(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Cross products (right-hand rule): direction = normal, length = twice the area."""
    p0, p1, p2 = (points[triangles[:, i]] for i in range(3))
    return np.cross(p1 - p0, p2 - p0)


def total_area(points: np.ndarray, triangles: np.ndarray) -> float:
    return 0.5 * float(np.linalg.norm(triangle_vectors(points, triangles), axis=1).sum())


# A tilted rectangle: normal and in-plane axis not aligned with the Cartesian axes.
TILTED_NORMAL = _unit([1.0, 2.0, 2.0])
TILTED_U = _unit(np.cross(TILTED_NORMAL, [0.0, 0.0, 1.0]))


# ---------------------------------------------------------------------------- particles


def test_particles_round_trip_exact(tmp_path):
    rng = np.random.default_rng(1)
    n = 11
    positions = rng.normal(size=(n, 3))
    fields = {
        "radius": rng.uniform(1e-3, 2e-3, n),
        "temperature": rng.uniform(290.0, 400.0, n),
        "velocity": rng.normal(size=(n, 3)),
        "omega": rng.normal(size=(n, 3)).astype(np.float32),
        "id": np.arange(n, dtype=np.int64) * 1_000_000_007,
        "material": rng.integers(0, 3, n).astype(np.int32),
    }
    path = tmp_path / "p.vtu"
    write_particles_vtu(path, positions, fields)

    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, positions)
    assert len(mesh.cells) == 1
    assert mesh.cells[0].type == "vertex"
    np.testing.assert_array_equal(mesh.cells[0].data.ravel(), np.arange(n))
    assert set(mesh.point_data) == set(fields)
    for name, value in fields.items():
        back = mesh.point_data[name]
        assert back.dtype == value.dtype, name
        assert back.shape == value.shape, name
        np.testing.assert_array_equal(back, value, err_msg=name)


def test_particles_bool_tensor_and_column_fields(tmp_path):
    n = 4
    positions = np.arange(3 * n, dtype=np.float64).reshape(n, 3)
    tensor = np.arange(9 * n, dtype=np.float64).reshape(n, 3, 3)
    fields = {
        "in_contact": np.array([True, False, True, True]),
        "stress": tensor,
        "column": np.arange(n, dtype=np.float64).reshape(n, 1),
    }
    path = tmp_path / "sub" / "p.vtu"  # the directory is created
    write_particles_vtu(path, positions, fields)
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.point_data["in_contact"], [1, 0, 1, 1])
    assert mesh.point_data["in_contact"].dtype == np.uint8
    np.testing.assert_array_equal(mesh.point_data["stress"], tensor.reshape(n, 9))
    np.testing.assert_array_equal(mesh.point_data["column"], np.arange(n))


def test_particles_header_is_vtk_xml(tmp_path):
    path = tmp_path / "p.vtu"
    write_particles_vtu(path, np.zeros((2, 3)), {"t": np.ones(2)})
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile"
    assert root.get("type") == "UnstructuredGrid"
    assert root.get("header_type") == "UInt64"
    assert root.get("compressor") is None
    piece = root.find("UnstructuredGrid/Piece")
    assert piece.get("NumberOfPoints") == "2"
    assert piece.get("NumberOfCells") == "2"


def test_particles_zlib_compression_round_trip(tmp_path):
    positions = np.random.default_rng(2).normal(size=(50, 3))
    path = tmp_path / "p.vtu"
    write_particles_vtu(path, positions, {"x": positions[:, 0].copy()}, compression="zlib")
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points, positions)
    np.testing.assert_array_equal(mesh.point_data["x"], positions[:, 0])


def test_particles_bad_shapes(tmp_path):
    with pytest.raises(ValueError):
        write_particles_vtu(tmp_path / "p.vtu", np.zeros((3, 2)), {})
    with pytest.raises(ValueError):
        write_particles_vtu(tmp_path / "p.vtu", np.zeros((3, 3)), {"t": np.zeros(4)})
    with pytest.raises(TypeError):
        write_particles_vtu(tmp_path / "p.vtu", np.zeros((3, 3)), {"s": np.array(["a"] * 3)})


# ---------------------------------------------------------------------------- wall meshes


def test_rectangle_mesh_area_extents_and_orientation():
    centre = np.array([0.3, -0.2, 1.5])
    hu, hv = 0.25, 0.1
    row = rectangle_row(centre, TILTED_NORMAL, TILTED_U, hu, hv)
    points, triangles = wall_surface_mesh(RECTANGLE, row)

    assert points.shape == (4, 3)
    assert triangles.shape == (2, 3)
    assert total_area(points, triangles) == pytest.approx(4.0 * hu * hv, rel=1e-12)
    # Every triangle's normal is the wall normal (towards the particles).
    normals = triangle_vectors(points, triangles)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    np.testing.assert_allclose(normals, np.tile(TILTED_NORMAL, (2, 1)), atol=1e-12)
    # Corners are at +-hu along u and +-hv along v = normal x u, in the plane.
    v = np.cross(TILTED_NORMAL, TILTED_U)
    rel = points - centre
    np.testing.assert_allclose(np.abs(rel @ TILTED_U), hu, rtol=1e-12)
    np.testing.assert_allclose(np.abs(rel @ v), hv, rtol=1e-12)
    np.testing.assert_allclose(rel @ TILTED_NORMAL, 0.0, atol=1e-15)
    np.testing.assert_allclose(points.mean(axis=0), centre, atol=1e-15)


def test_rectangle_mesh_u_and_v_are_not_swapped():
    # Normal +z, u = +x: the long side (hu) must lie along x, the short one (hv) along y.
    row = rectangle_row([0, 0, 0], [0, 0, 1], [1, 0, 0], 2.0, 0.5)
    points, _ = wall_surface_mesh(RECTANGLE, row)
    np.testing.assert_allclose(points.max(axis=0), [2.0, 0.5, 0.0])
    np.testing.assert_allclose(points.min(axis=0), [-2.0, -0.5, 0.0])


@pytest.mark.parametrize("normal", [[0, 0, 1], [0, -1, 0], [1, 0, 0], TILTED_NORMAL])
def test_plane_mesh_square_in_the_plane(normal):
    normal = _unit(normal)
    point = np.array([1.0, 2.0, 3.0])
    extent = 0.7
    points, triangles = wall_surface_mesh(PLANE, plane_row(point, normal), infinite_extent=extent)
    assert total_area(points, triangles) == pytest.approx((2 * extent) ** 2, rel=1e-12)
    np.testing.assert_allclose((points - point) @ normal, 0.0, atol=1e-14)
    np.testing.assert_allclose(points.mean(axis=0), point, atol=1e-14)
    # Square: all corners at the same distance (half diagonal) from the centre.
    np.testing.assert_allclose(np.linalg.norm(points - point, axis=1), extent * math.sqrt(2))
    normals = triangle_vectors(points, triangles)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    np.testing.assert_allclose(normals, np.tile(normal, (2, 1)), atol=1e-12)


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("resolution", [3, 12, 48])
def test_cylinder_mesh_area_and_orientation(side, resolution):
    point = np.array([0.1, 0.2, -0.3])
    axis = _unit([0.0, 1.0, 1.0])
    radius, half_length = 0.4, 0.9
    row = cylinder_row(point, axis, radius, half_length, side)
    points, triangles = wall_surface_mesh(CYLINDER, row, resolution=resolution)

    assert points.shape == (2 * resolution, 3)
    assert triangles.shape == (2 * resolution, 3)
    assert triangles.min() == 0 and triangles.max() == 2 * resolution - 1
    # Vertices on the circle of the given radius, at both ends of the tube.
    rel = points - point
    axial = rel @ axis
    radial = rel - axial[:, None] * axis
    np.testing.assert_allclose(np.abs(axial), half_length, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(radial, axis=1), radius, rtol=1e-12)

    # Area: exactly the inscribed polygonal prism, below and close to the exact 2 pi R L.
    length = 2.0 * half_length
    polygon = resolution * 2.0 * radius * math.sin(math.pi / resolution) * length
    exact = 2.0 * math.pi * radius * length
    area = total_area(points, triangles)
    assert area == pytest.approx(polygon, rel=1e-12)
    assert area < exact
    # sin(x)/x >= 1 - x^2/6: the relative error is bounded by (pi/n)^2 / 6.
    assert (exact - area) / exact <= (math.pi / resolution) ** 2 / 6.0

    # Orientation: towards the axis when the particles are inside, away from it otherwise.
    normals = triangle_vectors(points, triangles)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    # Each triangle is half of a flat facet spanning one segment: its normal is radial at the
    # mid angle, so it makes the angle pi/n with the radial direction at each of its vertices.
    radial_unit = radial / np.linalg.norm(radial, axis=1)[:, None]
    cosines = np.einsum("tj,tkj->tk", normals, radial_unit[triangles])
    expected = -side * math.cos(math.pi / resolution)
    np.testing.assert_allclose(cosines, np.full((2 * resolution, 3), expected), atol=1e-12)
    np.testing.assert_allclose(normals @ axis, 0.0, atol=1e-12)


def test_cylinder_infinite_length_uses_infinite_extent():
    row = cylinder_row([0, 0, 0], [0, 0, 1], 1.0, math.inf, 1.0)
    points, _ = wall_surface_mesh(CYLINDER, row, resolution=8, infinite_extent=2.5)
    np.testing.assert_allclose(np.sort(np.unique(points[:, 2])), [-2.5, 2.5])


def test_wall_mesh_rejects_bad_input():
    with pytest.raises(ValueError):
        wall_surface_mesh(7, plane_row([0, 0, 0], [0, 0, 1]))
    with pytest.raises(ValueError):
        wall_surface_mesh(PLANE, np.zeros(WALL_WIDTH))  # zero normal
    with pytest.raises(ValueError):
        wall_surface_mesh(CYLINDER, cylinder_row([0, 0, 0], [0, 0, 1], 1.0, 1.0, 1), resolution=2)
    with pytest.raises(ValueError):
        wall_surface_mesh(RECTANGLE, rectangle_row([0, 0, 0], [0, 0, 1], [1, 0, 0], 0.0, 1.0))


# ---------------------------------------------------------------------------- wall VTU


def test_write_walls_vtu_cell_data(tmp_path):
    resolution = 16
    rows = np.stack(
        [
            plane_row([0, 0, 0], [0, 0, 1]),
            rectangle_row([0, 0, 1], [0, 0, -1], [1, 0, 0], 0.5, 0.25),
            cylinder_row([0, 0, 0.5], [0, 0, 1], 0.5, math.inf, 1.0),
        ]
    )
    rows[:, COL_TEMPERATURE] = [300.0, 350.0, 400.0]
    kinds = np.array([PLANE, RECTANGLE, CYLINDER])
    force = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -2.0], [0.0, 0.0, 0.0]])
    fields = {
        "temperature": rows[:, COL_TEMPERATURE],
        "force": force,
        "force_magnitude": np.linalg.norm(force, axis=1),
    }
    path = tmp_path / "walls.vtu"
    write_walls_vtu(path, kinds, rows, fields, infinite_extent=2.0, resolution=resolution)

    mesh = meshio.read(path)
    assert [c.type for c in mesh.cells] == ["triangle"]
    counts = [2, 2, 2 * resolution]
    wall_id = mesh.cell_data["wall_id"][0]
    np.testing.assert_array_equal(wall_id, np.repeat([0, 1, 2], counts))
    np.testing.assert_array_equal(
        mesh.cell_data["temperature"][0], np.repeat([300.0, 350.0, 400.0], counts)
    )
    np.testing.assert_array_equal(mesh.cell_data["force"][0], np.repeat(force, counts, axis=0))
    # Same geometry as the per-wall meshes, with the triangles offset into one point array.
    pts, tri = mesh.points, mesh.cells[0].data
    for i in range(3):
        p_i, t_i = wall_surface_mesh(int(kinds[i]), rows[i], resolution, 2.0)
        np.testing.assert_allclose(pts[tri[wall_id == i]], p_i[t_i])


def test_write_walls_vtu_without_walls_or_fields(tmp_path):
    path = tmp_path / "walls.vtu"
    write_walls_vtu(path, np.zeros(0, dtype=np.int64), np.zeros((0, WALL_WIDTH)), None, 1.0)
    root = ET.parse(path).getroot()
    assert root.find("UnstructuredGrid/Piece").get("NumberOfCells") == "0"

    rows = plane_row([0, 0, 0], [1, 0, 0])[None, :]
    write_walls_vtu(path, np.array([PLANE]), rows, None, 1.0)
    mesh = meshio.read(path)
    assert set(mesh.cell_data) == {"wall_id"}
    with pytest.raises(ValueError):
        write_walls_vtu(path, np.array([PLANE]), rows, {"wall_id": np.zeros(1)}, 1.0)
    with pytest.raises(ValueError):
        write_walls_vtu(path, np.array([PLANE]), rows, {"t": np.zeros(2)}, 1.0)


# ---------------------------------------------------------------------------- PVD


def _datasets(path) -> list[dict[str, str]]:
    root = ET.parse(path).getroot()  # raises if the XML is not well formed
    assert root.tag == "VTKFile"
    assert root.get("type") == "Collection"
    return [ds.attrib for ds in root.find("Collection").findall("DataSet")]


def test_pvd_entries_in_order_and_valid_after_every_add(tmp_path):
    pvd_path = tmp_path / "out" / "particles.pvd"
    pvd = PVDWriter(pvd_path)
    assert _datasets(pvd_path) == []  # valid (empty) index from the start
    times = [0.0, 1e-5, 0.1, 0.30000000000000004]
    for k, t in enumerate(times):
        pvd.add(t, f"vtk/particles_{k:06d}.vtu")
        entries = _datasets(pvd_path)
        assert len(entries) == k + 1
    assert [float(e["timestep"]) for e in entries] == times  # exact round trip
    assert [e["file"] for e in entries] == [f"vtk/particles_{k:06d}.vtu" for k in range(4)]
    assert all(e["part"] == "0" for e in entries)
    assert PVDWriter.read(pvd_path) == pvd.entries
    assert sorted(os.listdir(pvd_path.parent)) == ["particles.pvd"]  # no temporary left over


def test_pvd_parts_replacement_and_paths(tmp_path):
    pvd_path = tmp_path / "all.pvd"
    pvd = PVDWriter(pvd_path)
    pvd.add(0.0, "p0.vtu", part=PART_PARTICLES)
    pvd.add(0.0, "w0.vtu", part=PART_WALLS)
    pvd.add(0.5, tmp_path / "vtk" / "p1.vtu", part=PART_PARTICLES)  # absolute -> relative
    pvd.add(0.5, "w1 & <old>.vtu", part=PART_WALLS)
    pvd.add(0.5, "w1.vtu", part=PART_WALLS)  # same time and part: replaced
    entries = _datasets(pvd_path)
    assert [(e["timestep"], e["part"], e["file"]) for e in entries] == [
        ("0.0", "0", "p0.vtu"),
        ("0.0", "1", "w0.vtu"),
        ("0.5", "0", "vtk/p1.vtu"),
        ("0.5", "1", "w1.vtu"),
    ]
    with pytest.raises(ValueError):
        pvd.add(0.25, "late.vtu", part=PART_WALLS)
    with pytest.raises(ValueError):
        pvd.add(math.nan, "nan.vtu")
    assert len(_datasets(pvd_path)) == 4  # failed adds leave the file alone


def test_pvd_escapes_file_names(tmp_path):
    pvd_path = tmp_path / "x.pvd"
    PVDWriter(pvd_path).add(1.0, 'a&b<"c">.vtu')
    assert _datasets(pvd_path)[0]["file"] == 'a&b<"c">.vtu'


def test_pvd_resume_keeps_entries_up_to_time(tmp_path):
    pvd_path = tmp_path / "particles.pvd"
    pvd = PVDWriter(pvd_path)
    for k in range(6):
        pvd.add(0.1 * k, f"p{k}.vtu")
    restart_time = 0.1 * 3

    resumed = PVDWriter.resume(pvd_path, restart_time)
    assert [f for _, _, f in resumed.entries] == ["p0.vtu", "p1.vtu", "p2.vtu", "p3.vtu"]
    assert [e["file"] for e in _datasets(pvd_path)] == ["p0.vtu", "p1.vtu", "p2.vtu", "p3.vtu"]
    # The restarted run writes its first frame at the restart time again, then continues.
    resumed.add(restart_time, "p3_restart.vtu")
    resumed.add(0.4, "p4_restart.vtu")
    files = [e["file"] for e in _datasets(pvd_path)]
    assert files == ["p0.vtu", "p1.vtu", "p2.vtu", "p3_restart.vtu", "p4_restart.vtu"]

    fresh = PVDWriter.resume(tmp_path / "missing.pvd", 1.0)
    assert len(fresh) == 0
    assert _datasets(tmp_path / "missing.pvd") == []


def test_pvd_kill_during_rewrite_keeps_previous_index(tmp_path, monkeypatch):
    pvd_path = tmp_path / "particles.pvd"
    pvd = PVDWriter(pvd_path)
    pvd.add(0.0, "p0.vtu")
    before = pvd_path.read_bytes()

    def interrupted(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        pvd.add(1.0, "p1.vtu")
    monkeypatch.undo()
    assert pvd_path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["particles.pvd"]


def test_pvd_with_real_frames_reads_back(tmp_path):
    """End to end: frames written next to the index open through the relative paths."""
    pvd_path = tmp_path / "particles.pvd"
    pvd = PVDWriter(pvd_path)
    rng = np.random.default_rng(3)
    for k in range(3):
        rel = f"vtk/particles_{k:06d}.vtu"
        write_particles_vtu(tmp_path / rel, rng.normal(size=(5, 3)), {"k": np.full(5, k)})
        pvd.add(0.01 * k, rel)
    for k, e in enumerate(_datasets(pvd_path)):
        mesh = meshio.read(pvd_path.parent / e["file"])
        np.testing.assert_array_equal(mesh.point_data["k"], k)


# ---------------------------------------------------------------------------- name tables

NAMES = ["glass", "steel beads", 'a = b <&> "q"', "Kupfer-Ø"]  # spaces, '=', XML, UTF-8


def test_particle_material_names_in_field_data(tmp_path):
    from thermodem.io.vtk_read import read_name_table

    n = 6
    ids = np.array([0, 1, 2, 3, 1, 0], dtype=np.int32)
    path = tmp_path / "p.vtu"
    write_particles_vtu(path, np.zeros((n, 3)), {"material_id": ids}, names={"material_id": NAMES})
    mesh = meshio.read(path)  # a strict reader still opens the file
    np.testing.assert_array_equal(mesh.point_data["material_id"], ids)
    assert read_name_table(mesh.field_data, "material_id") == NAMES
    assert mesh.field_data["material_id 1 = steel beads"].tolist() == [1]
    assert read_name_table(mesh.field_data, "wall_id") == []
    # VTK's reader (ParaView's) sees the same arrays, if VTK is installed
    vtk = pytest.importorskip("vtk")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    fd = reader.GetOutput().GetFieldData()
    labels = [fd.GetArrayName(i) for i in range(fd.GetNumberOfArrays())]
    assert labels == [f"material_id {k} = {name}" for k, name in enumerate(NAMES)]
    assert reader.GetOutput().GetNumberOfPoints() == n


def test_wall_names_and_temperature_in_the_walls_vtu(tmp_path):
    from thermodem.io.vtk_read import read_name_table

    rows = np.stack([plane_row([0, 0, 0], [0, 0, 1]), plane_row([0, 0, 1], [0, 0, -1])])
    fields = {"temperature": np.array([600.0, np.nan]), "material_id": np.array([1, 0])}
    path = tmp_path / "w.vtu"
    write_walls_vtu(
        path, np.array([PLANE, PLANE]), rows, fields, names=["hot plate", "lid"],
        tables={"material_id": ["glass", "steel"]},
    )  # fmt: skip
    mesh = meshio.read(path)
    assert read_name_table(mesh.field_data, "wall_id") == ["hot plate", "lid"]
    assert read_name_table(mesh.field_data, "material_id") == ["glass", "steel"]
    t = mesh.cell_data["temperature"][0]
    np.testing.assert_array_equal(t[:2], [600.0, 600.0])
    assert np.isnan(t[2:]).all()
    with pytest.raises(ValueError, match="2 walls but 1 wall names"):
        write_walls_vtu(path, np.array([PLANE, PLANE]), rows, None, names=["one"])


def test_simulation_frames_carry_names_and_wall_temperatures(tmp_path):
    """A run's frames: particle material names, wall names, the fixed wall's temperature
    (from the case), NaN for adiabatic walls."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.io.vtk import write_particle_frame, write_wall_frame
    from thermodem.io.vtk_read import read_name_table

    props = {"density": 2500, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
             "thermal_conductivity": 1.0, "specific_heat": 800.0}  # fmt: skip
    lattice = {"kind": "lattice", "distribution": {"kind": "mono", "radius": 0.001},
               "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.004], "spacing": 0.0025}  # fmt: skip
    case = case_from_dict(
        {
            "simulation": {"time_step": 1e-5, "end_time": 0.001},
            "domain": {"lower": [0, 0, -0.001], "upper": [0.01, 0.01, 0.01]},
            "materials": {"glass": props, "iron": props},
            "walls": [
                {
                    "kind": "plane",
                    "name": "heater",
                    "point": [0, 0, 0],
                    "normal": [0, 0, 1],
                    "material": "iron",
                    "thermal": {"kind": "fixed", "temperature": 450.0},
                },
                {
                    "kind": "box",
                    "lower": [0, 0, 0],
                    "upper": [0.01, 0.01, 0.01],
                    "material": "glass",
                    "open_top": True,
                },
            ],  # fmt: skip
            "insertion": [
                {**lattice, "material": "glass"},
                {
                    **lattice,
                    "material": "iron",
                    "lower": [0, 0, 0.005],
                    "upper": [0.01, 0.01, 0.009],
                },
            ],  # fmt: skip
            "thermal": {"direct_conduction": "batchelor_obrien_simple"},
        }
    )
    sim = Simulation(case)
    write_particle_frame(tmp_path / "p.vtu", sim)
    write_wall_frame(tmp_path / "w.vtu", sim, 0.02)
    p = meshio.read(tmp_path / "p.vtu")
    names = read_name_table(p.field_data, "material_id")
    assert names == ["glass", "iron"]
    got = [names[k] for k in p.point_data["material_id"]]
    want = [sim.material_names[t] for t in sim.particles.type_id]
    assert got == want and set(got) == {"glass", "iron"}
    w = meshio.read(tmp_path / "w.vtu")
    walls = read_name_table(w.field_data, "wall_id")
    assert walls == list(sim.wall_labels) and walls[0] == "heater" and len(walls) == 6
    wid = w.cell_data["wall_id"][0]
    temperature = w.cell_data["temperature"][0]
    assert np.all(temperature[wid == 0] == 450.0)
    assert np.isnan(temperature[wid > 0]).all()
    wall_materials = read_name_table(w.field_data, "material_id")
    assert [wall_materials[k] for k in w.cell_data["material_id"][0][wid == 0]][0] == "iron"
