"""The per-particle fields of engine/fields.py in a simulation.

- the fluid temperature and velocity: uniform, a table of time, an expression of (t, x, y, z),
  a grid file (a trilinear field is reproduced exactly at any particle position; outside the
  grid the boundary value holds, with one warning), relative paths from the case file;
- the porosity providers against hand computations and independent quadratures: the cell
  count (with a wall cutting cells), the shell count (a lone particle, two overlapping
  shells, one and two walls cutting the shell).
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

from thermodem.config.load import case_from_dict, load_case
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError, SimulationError
from thermodem.kernels import fields as fk

DATA = Path(__file__).resolve().parents[1] / "data" / "grids"
sys.path.insert(0, str(DATA))
from expected import AXES, temperature, velocity  # noqa: E402

R = 2e-4
MATERIAL = {
    "density": 3000.0,
    "youngs_modulus": 1e8,
    "poisson_ratio": 0.3,
    "thermal_conductivity": 2.0,
    "specific_heat": 900.0,
}


def _write(path: Path, pos: np.ndarray, radius: float = R, temp: float = 350.0) -> str:
    rows = ["x y z radius temperature"]
    rows += [" ".join(repr(float(v)) for v in (*x, radius, temp)) for x in pos]
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _case(path: str, thermal: dict, lower=(-0.01, -0.01, -0.01), upper=(0.02, 0.02, 0.02)) -> dict:  # noqa: ANN001
    base = {"direct_conduction": "none", "frozen_mechanics": True, "time_step": 0.01}
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": list(lower), "upper": list(upper)},
        "materials": {"grain": dict(MATERIAL)},
        "insertion": [{"kind": "file", "material": "grain", "path": path}],
        "thermal": {**base, **thermal},
    }


def _gid(sim: Simulation, values: np.ndarray) -> np.ndarray:
    return values[np.argsort(sim.particles.global_id)]


def _inside_grid(n: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo = np.array([a[0] for a in AXES]) + R
    hi = np.array([a[-1] for a in AXES]) - R
    pos: list[np.ndarray] = []
    while len(pos) < n:
        x = rng.uniform(lo, hi)
        if all(np.linalg.norm(x - p) > 2.01 * R for p in pos):
            pos.append(x)
    return np.array(pos)


@pytest.mark.parametrize("name", ["image_appended_raw_zlib.vti", "legacy_rectilinear_binary.vtk"])
def test_grid_fluid_is_interpolated_trilinearly_at_the_particles(tmp_path: Path, name: str) -> None:
    pos = _inside_grid(30)
    fluid = {
        "temperature": {"file": str(DATA / name), "field": "T"},
        "velocity": {"file": str(DATA / name), "field": "U"},
    }
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim = Simulation(
            case_from_dict(
                _case(_write(tmp_path / "p.txt", pos), {"convection": "stagnant", "fluid": fluid})
            )
        )
    f = sim.thermal.fields
    tf = _gid(sim, f[fk.F_FLUID_TEMPERATURE])
    assert np.allclose(tf, temperature(*pos.T), rtol=1e-13, atol=0)
    # the stagnant model does not read the velocity: check it with a flowing correlation
    case = _case(
        _write(tmp_path / "p.txt", pos), {"convection": "ranz_marshall1952", "fluid": fluid}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # Re < 1 here
        sim = Simulation(case_from_dict(case))
    speed = _gid(sim, sim.thermal.fields[fk.F_RELATIVE_SPEED])
    u = np.stack(velocity(*pos.T), axis=-1)
    assert np.allclose(speed, np.linalg.norm(u, axis=1), rtol=1e-13, atol=0)


def test_outside_the_grid_the_boundary_value_holds_with_one_warning(tmp_path: Path) -> None:
    x_far = AXES[0][-1] + 0.002  # beyond the grid in x
    pos = np.array([[x_far, AXES[1][1], AXES[2][2]], [AXES[0][1], AXES[1][1], AXES[2][2]]])
    fluid = {"temperature": {"file": str(DATA / "image_ascii.vti"), "field": "T"}}
    case = _case(_write(tmp_path / "p.txt", pos), {"convection": "stagnant", "fluid": fluid})
    with pytest.warns(RuntimeWarning, match=r"1 particles outside the grid .* nearest point"):
        sim = Simulation(case_from_dict(case))
    tf = _gid(sim, sim.thermal.fields[fk.F_FLUID_TEMPERATURE])
    assert tf[0] == pytest.approx(temperature(AXES[0][-1], AXES[1][1], AXES[2][2]), rel=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sim.step()


def test_fluid_temperature_table_and_expressions(tmp_path: Path) -> None:
    pos = np.array([[0.001, 0.002, 0.003], [0.004, 0.0, -0.001]])
    fluid = {
        "temperature": [[0.0, 300.0], [0.05, 400.0]],
        "velocity": ["1 + 100 * x", "0.5 * t", "-z * 10"],
    }
    case = _case(
        _write(tmp_path / "p.txt", pos), {"convection": "ranz_marshall1952", "fluid": fluid}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        sim = Simulation(case_from_dict(case))
        for _ in range(3):
            sim.step()
        sim.thermal.compute_rates(sim.time)  # the fields at t = 0.03 s
    t = sim.time
    assert t == pytest.approx(0.03)
    f = sim.thermal.fields
    assert np.allclose(f[fk.F_FLUID_TEMPERATURE], 300.0 + 100.0 * t / 0.05, rtol=1e-14)
    p = sim.particles.position
    u = np.column_stack([1 + 100 * p[:, 0], np.full(2, 0.5 * t), -p[:, 2] * 10])
    assert np.allclose(f[fk.F_RELATIVE_SPEED], np.linalg.norm(u, axis=1), rtol=1e-14)
    # an expression of position; one that turns negative in the domain before the end time is
    # refused when the case is read; met during a run (a restart with a later end time) it
    # stops the run, naming the particle
    text = "300 + 1e5 * x - 1e7 * x * t"
    case = _case(
        _write(tmp_path / "p.txt", pos), {"convection": "stagnant", "fluid": {"temperature": text}}
    )
    with pytest.raises(ConfigError, match=r"thermal.fluid.temperature: expression .* gives -700"):
        case_from_dict(case)
    case["thermal"]["fluid"]["temperature"] = 300.0
    case = case_from_dict(case)
    case.thermal.fluid.temperature = text  # (past the case's checks)
    sim = Simulation(case)
    tf = _gid(sim, sim.thermal.fields[fk.F_FLUID_TEMPERATURE])
    assert tf == pytest.approx(300 + 1e5 * pos[:, 0], rel=1e-14)
    with pytest.raises(SimulationError, match=r"gives -100.0 K at particle 1 .*t = 0.02 s"):
        for _ in range(3):
            sim.step()


def test_grid_path_relative_to_the_case_file(tmp_path: Path) -> None:
    (tmp_path / "flow.vti").write_bytes((DATA / "image_ascii.vti").read_bytes())
    _write(tmp_path / "p.txt", _inside_grid(2))
    text = f"""
simulation: {{time_step: 1.0e-5, end_time: 1.0, gravity: [0, 0, 0]}}
domain: {{lower: [-0.01, -0.01, -0.01], upper: [0.02, 0.02, 0.02]}}
materials:
  grain: {MATERIAL}
insertion: [{{kind: file, material: grain, path: p.txt}}]
thermal:
  direct_conduction: none
  convection: stagnant
  fluid: {{temperature: {{file: flow.vti, field: T}}}}
"""
    (tmp_path / "case.yaml").write_text(text)
    case = load_case(tmp_path / "case.yaml")
    assert case.thermal.fluid.temperature.file == str(tmp_path / "flow.vti")
    Simulation(case)
    (tmp_path / "flow.vti").unlink()

    with pytest.raises(ConfigError, match=r"thermal.fluid.temperature.file: .*does not exist"):
        Simulation(load_case(tmp_path / "case.yaml"))


# ----------------------------------------------------------------------------- porosity
def test_cell_porosity_by_hand(tmp_path: Path) -> None:
    """Domain 8R × 8R × 8R, cells 4R: three particles in the first cell, one in the last; a
    plane wall at x = 2R makes the first-column cells half fluid."""
    s = R
    pos = np.array(
        [
            [2.5 * s, 1.2 * s, 1.2 * s],
            [2.5 * s, 2.9 * s, 1.2 * s],
            [3.0 * s, 2.0 * s, 3.0 * s],
            [6.0 * s, 6.0 * s, 6.0 * s],
        ]
    )
    radiation = {"model": "surroundings", "environment_temperature": 300.0, "exposure": "fraction"}
    thermal = {"radiation": radiation, "porosity": {"kind": "cell", "cell_size": 4 * s}}
    case = _case(
        _write(tmp_path / "p.txt", pos, radius=0.5 * s),
        thermal,
        lower=(0, 0, 0),
        upper=(8 * s, 8 * s, 8 * s),
    )
    case["materials"]["grain"]["emissivity"] = 0.9
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    v = 4 / 3 * math.pi * (0.5 * s) ** 3
    assert eps[:3] == pytest.approx([1 - 3 * v / (4 * s) ** 3] * 3, rel=1e-14)
    assert eps[3] == pytest.approx(1 - v / (4 * s) ** 3, rel=1e-14)
    case["walls"] = [
        {"kind": "plane", "point": [2 * s, 0, 0], "normal": [1, 0, 0], "material": "grain"}
    ]
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    assert eps[:3] == pytest.approx([1 - 3 * v / (0.5 * (4 * s) ** 3)] * 3, rel=1e-14)


def test_cell_porosity_follows_a_particle_into_another_cell(tmp_path: Path) -> None:
    """The porosities are recomputed only when a particle changes cell
    (engine/fields.py): moving the lone particle of the last cell into the first one
    changes both cells' porosity; a move within a cell changes nothing."""
    s = R
    pos = np.array([[2.5 * s, 1.2 * s, 1.2 * s], [2.5 * s, 2.9 * s, 1.2 * s],
                    [3.0 * s, 2.0 * s, 3.0 * s], [6.0 * s, 6.0 * s, 6.0 * s]])  # fmt: skip
    radiation = {"model": "surroundings", "environment_temperature": 300.0, "exposure": "fraction"}
    thermal = {"radiation": radiation, "porosity": {"kind": "cell", "cell_size": 4 * s}}
    case = _case(_write(tmp_path / "p.txt", pos, radius=0.5 * s), thermal, lower=(0, 0, 0),
                 upper=(8 * s, 8 * s, 8 * s))  # fmt: skip
    case["materials"]["grain"]["emissivity"] = 0.9
    sim = Simulation(case_from_dict(case))
    p = sim.particles
    v = 4 / 3 * math.pi * (0.5 * s) ** 3
    cell = (4 * s) ** 3
    last = int(np.flatnonzero(p.global_id == 3)[0])
    p.position[last] = [6.5 * s, 5.5 * s, 6.2 * s]  # within its cell
    sim.thermal.compute_rates(sim.time)
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    assert eps[3] == pytest.approx(1 - v / cell, rel=1e-14)
    p.position[last] = [1.0 * s, 3.0 * s, 2.0 * s]  # into the first cell
    sim.thermal.compute_rates(sim.time)
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    assert eps == pytest.approx([1 - 4 * v / cell] * 4, rel=1e-14)


def _sphere_volume_beyond_planes(rs: float, cuts: list[float]) -> float:
    """Volume of a sphere (radius rs, centre 0) with x >= -cuts[0] and z >= -cuts[1] (an
    independent quadrature: slices in z of a disc cut by the line x = -cuts[0])."""
    dx = cuts[0]
    dz = cuts[1] if len(cuts) > 1 else rs

    def area(z: float) -> float:
        rho2 = rs * rs - z * z
        if rho2 <= 0:
            return 0.0
        rho = math.sqrt(rho2)
        if dx >= rho:
            return math.pi * rho2
        segment = rho2 * math.acos(dx / rho) - dx * math.sqrt(rho2 - dx * dx)
        return math.pi * rho2 - segment

    return integrate.quad(area, -min(dz, rs), rs, epsabs=0, epsrel=1e-12, limit=200)[0]


def _lens(a: float, b: float, d: float) -> float:
    """Intersection volume of two spheres by quadrature of the common disc areas along the
    axis (an independent check of the closed form in kernels/fields.py)."""

    def area(x: float) -> float:
        r1 = a * a - x * x
        r2 = b * b - (d - x) ** 2
        return math.pi * max(min(r1, r2), 0.0)

    x_cut = (d * d + a * a - b * b) / (2 * d)
    return (
        integrate.quad(area, d - b, x_cut, epsrel=1e-12)[0]
        + integrate.quad(area, x_cut, a, epsrel=1e-12)[0]
    )


def test_shell_porosity_against_quadratures(tmp_path: Path) -> None:
    ratio = 3.0
    rs = ratio * R
    # a lone particle far from everything, and a pair 3.5 R apart (shells overlap them)
    pos = np.array([[0.0, 0.0, 0.0], [0.01, 0.01, 0.01], [0.01 + 3.5 * R, 0.01, 0.01]])
    case = _case(
        _write(tmp_path / "p.txt", pos),
        {
            "radiation": {
                "model": "surroundings",
                "environment_temperature": 300.0,
                "exposure": "fraction",
            },
            "porosity": {"kind": "shell", "radius_ratio": ratio},
        },
    )
    case["materials"]["grain"]["emissivity"] = 0.9
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    vs = 4 / 3 * math.pi * rs**3
    vp = 4 / 3 * math.pi * R**3
    assert eps[0] == pytest.approx(1 - 1 / 27, rel=1e-14)
    lens = _lens(rs, R, 3.5 * R)
    assert eps[1] == pytest.approx(1 - (vp + lens) / vs, rel=1e-10)
    # walls: one plane 1.5 R below particle 0 (exact cap), then a second at 1.2 R in x (the
    # overlap of the two caps from the lattice)
    walls = [{"kind": "plane", "point": [0, 0, -1.5 * R], "normal": [0, 0, 1], "material": "grain"}]
    case["walls"] = walls
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    v_avail = _sphere_volume_beyond_planes(rs, [rs, 1.5 * R])
    assert eps[0] == pytest.approx(1 - vp / v_avail, rel=1e-10)
    # a second wall 1.2 R away in x: the overlap of the two caps (a quadrature in the kernel)
    second = {"kind": "plane", "point": [-1.2 * R, 0, 0], "normal": [1, 0, 0], "material": "grain"}
    case["walls"] = walls + [second]
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    v_avail = _sphere_volume_beyond_planes(rs, [1.2 * R, 1.5 * R])
    assert 1 - eps[0] == pytest.approx(vp / v_avail, rel=1e-6)
    # a box corner, a third wall 1.0 R away in y: the triple overlap from quasi-random points
    third = {"kind": "plane", "point": [0, -1.0 * R, 0], "normal": [0, 1, 0], "material": "grain"}
    case["walls"] = walls + [second, third]
    sim = Simulation(case_from_dict(case))
    eps = _gid(sim, sim.thermal.fields[fk.F_POROSITY])
    v_avail = _corner_volume(rs, 1.2 * R, 1.0 * R, 1.5 * R)
    assert 1 - eps[0] == pytest.approx(vp / v_avail, rel=2e-3)


def _corner_volume(rs: float, a: float, b: float, c: float) -> float:
    """Volume of a sphere (radius rs, centre 0) with x >= -a, y >= -b, z >= -c (nested
    quadratures)."""

    def area(z: float) -> float:
        rho2 = rs * rs - z * z
        if rho2 <= 0:
            return 0.0
        rho = math.sqrt(rho2)

        def height(x: float) -> float:
            top = math.sqrt(max(rho2 - x * x, 0.0))
            return max(top - max(-b, -top), 0.0)

        lo = max(-a, -rho)
        return integrate.quad(height, lo, rho, epsrel=1e-11, limit=200)[0] if lo < rho else 0.0

    return integrate.quad(area, max(-c, -rs), rs, epsrel=1e-11, limit=200)[0]
