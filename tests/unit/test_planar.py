"""2D cases (issue 16): reading a 2D case, walls as lines, insertion in the plane, output."""

from __future__ import annotations

import math
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.geometry import wall_layout as WL
from thermodem.io.vtk import write_particle_frame, write_wall_frame

GLASS = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3, "restitution": 0.5}


def case2d(**extra) -> dict:
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 0.01, "dimension": 2, "thickness": 0.01},
        "domain": {"lower": [0.0, 0.0], "upper": [0.1, 0.1]},
        "materials": {"glass": dict(GLASS)},
        "output": {"vtu": False},
    }
    case.update(extra)
    return case


def test_two_component_vectors_are_read_in_2d_only() -> None:
    case = case_from_dict(case2d())
    assert case.domain.lower == (0.0, 0.0, 0.0)
    assert case.simulation.gravity == (0.0, -9.81, 0.0)  # the 2D default: along -y
    assert case.contact.normal.model == "hertz_2d"  # 2D discs: the line contact
    assert case.contact.tangential.model == "linear"
    three = case2d()
    three["simulation"]["dimension"] = 3
    three["simulation"].pop("thickness")
    with pytest.raises(ConfigError, match=r"domain\.lower: too few values"):
        case_from_dict(three)


def test_spheres_in_a_plane_keep_the_3d_laws() -> None:
    data = case2d()
    data["simulation"] = {"time_step": 1e-5, "end_time": 0.01, "dimension": 2,
                          "particle_shape": "sphere"}  # fmt: skip
    case = case_from_dict(data)
    assert case.contact.normal.model == "hertz"
    assert case.simulation.disc_thickness == 0.0


def test_a_box_wall_is_four_lines_and_open_top_drops_the_upper_y_side() -> None:
    walls = [{"kind": "box", "lower": [0, 0], "upper": [0.1, 0.1], "material": "glass",
              "open_top": True}]  # fmt: skip
    sim = Simulation(case_from_dict(case2d(walls=walls)))
    assert sim.wall_labels == ["box0.x-", "box0.x+", "box0.y-"]
    rows = sim.wall_rows
    assert np.all(rows[:, WL.COL_POINT + 2] == 0.0)
    # each side is unbounded along z (a line in the plane) and bounded along its own axis
    assert np.isinf(rows[:, WL.COL_HALF_U : WL.COL_HALF_V + 1]).sum() == 3
    assert (
        sorted(rows[:, WL.COL_HALF_U : WL.COL_HALF_V + 1][np.isfinite(rows[:, 12:14])])
        == [pytest.approx(0.05)] * 3
    )


def test_a_cylinder_wall_is_a_circle_and_a_rectangle_a_segment() -> None:
    walls = [
        {"kind": "cylinder", "center": [0.05, 0.05, 0.3], "axis": [0, 0, 1], "radius": 0.04,
         "length": 0.001, "material": "glass"},
        {"kind": "rectangle", "center": [0.05, 0.02], "normal": [0, 1], "u_axis": [1, 0],
         "half_extents": [0.01, 0.001], "material": "glass"},
    ]  # fmt: skip
    sim = Simulation(case_from_dict(case2d(walls=walls)))
    cyl, rect = sim.wall_rows
    assert cyl[WL.COL_POINT + 2] == 0.0 and np.isinf(cyl[WL.COL_HALF_LENGTH])
    assert rect[WL.COL_HALF_U] == 0.01 and np.isinf(rect[WL.COL_HALF_V])
    bad = case2d(walls=[dict(walls[1], u_axis=[1, 0, 1])])
    bad["walls"][0]["normal"] = [0, 1, 0]
    with pytest.raises(ConfigError, match=r"walls\.0\.u_axis: .*segment in the x-y plane"):
        case_from_dict(bad)


def test_lattice_of_discs_has_one_layer_at_z_0() -> None:
    entry = {"kind": "lattice", "material": "glass", "lower": [0.0, 0.0], "upper": [0.1, 0.05],
             "spacing": 0.01, "distribution": {"kind": "mono", "radius": 0.004}}  # fmt: skip
    sim = Simulation(case_from_dict(case2d(insertion=[entry])))
    p = sim.particles
    assert p.count == 10 * 5
    assert np.all(p.position[:, 2] == 0.0)
    assert len(np.unique(np.round(p.position[:, 0], 12))) == 10


def test_random_box_fills_an_area_fraction_and_random_cylinder_a_circle() -> None:
    entries = [
        {"kind": "random_box", "material": "glass", "lower": [0.0, 0.0], "upper": [0.1, 0.05],
         "volume_fraction": 0.3, "distribution": {"kind": "uniform", "min_radius": 0.001,
                                                  "max_radius": 0.002}},
        {"kind": "random_cylinder", "material": "glass", "base_centre": [0.05, 0.075],
         "axis": [0, 0, 1], "radius": 0.02, "length": 1.0, "count": 40,
         "distribution": {"kind": "mono", "radius": 0.0015}},
    ]  # fmt: skip
    sim = Simulation(case_from_dict(case2d(insertion=entries)))
    p = sim.particles
    assert np.all(p.position[:, 2] == 0.0)
    box = p.position[:, 1] < 0.05
    area = float(np.sum(math.pi * p.radius[box] ** 2))
    assert 0.3 * 0.005 <= area < 0.3 * 0.005 + math.pi * 0.002**2  # drawn until it reaches it
    r = np.hypot(p.position[~box, 0] - 0.05, p.position[~box, 1] - 0.075)
    assert (~box).sum() == 40 and np.all(r <= 0.02 - 0.0015 + 1e-12)
    d = np.hypot(*(p.position[:, None, :2] - p.position[None, :, :2]).transpose(2, 0, 1))
    np.fill_diagonal(d, np.inf)
    assert np.all(d >= p.radius[:, None] + p.radius[None, :] - 1e-12)  # no overlaps


def test_pour_into_a_2d_region(tmp_path: Path) -> None:
    entry = {"kind": "pour", "material": "glass", "rate": 1e4, "interval": 1e-3,
             "distribution": {"kind": "mono", "radius": 0.002}, "velocity": [0.0, -0.5],
             "region": {"kind": "box", "lower": [0.0, 0.05], "upper": [0.1, 0.1]}}  # fmt: skip
    sim = Simulation(case_from_dict(case2d(insertion=[entry])))
    sim.run(steps=250)
    p = sim.particles
    assert p.count == 20
    assert np.all(p.position[:, 2] == 0.0) and np.all(p.velocity[:, 2] == 0.0)


@pytest.mark.parametrize("header", ["x y r", "x y radius vx vy", "x y z r vx vy vz"])
def test_particle_file_with_x_y_r_columns(tmp_path: Path, header: str) -> None:
    names = header.split()
    rows = []
    for k in range(3):
        values = {"x": 0.01 + 0.02 * k, "y": 0.05, "z": 0.0, "r": 0.005, "radius": 0.005,
                  "vx": 0.1 * k, "vy": -0.1, "vz": 0.0}  # fmt: skip
        rows.append([values[n] for n in names])
    path = tmp_path / "discs.txt"
    np.savetxt(path, rows, header=header, comments="")
    entry = {"kind": "file", "material": "glass", "path": str(path)}
    sim = Simulation(case_from_dict(case2d(insertion=[entry])))
    p = sim.particles
    assert p.count == 3 and np.all(p.position[:, 2] == 0.0)
    np.testing.assert_allclose(p.position[:, 0], [0.01, 0.03, 0.05])
    if "vx" in names:
        np.testing.assert_allclose(p.velocity[:, :2], [[0.0, -0.1], [0.1, -0.1], [0.2, -0.1]])


def test_given_particles_off_the_plane_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "off.txt"
    np.savetxt(path, [[0.05, 0.05, 0.001, 0.005]], header="x y z r", comments="")
    entry = {"kind": "file", "material": "glass", "path": str(path)}
    with pytest.raises(ConfigError, match=r"insertion\.0\.path: .*line 2.*has a z component"):
        Simulation(case_from_dict(case2d(insertion=[entry])))
    entry = {"kind": "list", "material": "glass", "positions": [[0.05, 0.05, 0.002]],
             "radius": 0.005}  # fmt: skip
    with pytest.raises(ConfigError, match=r"insertion\.0\.positions\.0: .*plane z = 0"):
        case_from_dict(case2d(insertion=[entry]))


def test_vtu_frames_of_a_2d_case_are_discs(tmp_path: Path) -> None:
    entry = {"kind": "list", "material": "glass", "positions": [[0.02, 0.02], [0.05, 0.02]],
             "radius": 0.005}  # fmt: skip
    walls = [{"kind": "box", "lower": [0, 0], "upper": [0.1, 0.1], "material": "glass"}]
    sim = Simulation(case_from_dict(case2d(insertion=[entry], walls=walls)))
    write_particle_frame(tmp_path / "p.vtu", sim)
    mesh = meshio.read(tmp_path / "p.vtu")
    np.testing.assert_array_equal(mesh.point_data["normal"], [[0, 0, 1], [0, 0, 1]])
    np.testing.assert_array_equal(mesh.point_data["thickness"], [0.01, 0.01])
    write_wall_frame(tmp_path / "w.vtu", sim, extent=0.1)
    walls_mesh = meshio.read(tmp_path / "w.vtu")
    assert np.all(np.isfinite(walls_mesh.points))
    assert np.abs(walls_mesh.points[:, 2]).max() == pytest.approx(0.005)  # the disc slab


def test_models_command_says_which_models_run_in_2d() -> None:
    result = CliRunner().invoke(app, ["models", "normal"])
    assert result.exit_code == 0
    text = result.output
    assert "normal.hertz_2d:" in text
    assert "2D (simulation.dimension: 2): discs only (a 2D law: refused in 3D)" in text
    assert "2D (simulation.dimension: 2): spheres in a plane only (3D form)" in text
    assert "2D (simulation.dimension: 2): discs and spheres in a plane" in text
