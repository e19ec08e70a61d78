"""Thermal conditions against hand computations, closed forms and the heat ledger.

Initial temperature rules (also for poured particles), wall temperatures in time, the external
source and its profiles, particle selections, and sub-cycling. Where particles must stay in place
while the mechanics runs, their Young's modulus is 1e-200 Pa: contact forces ~1e-208 N move them
by ~1e-213 m per step, below the last bit of coordinates ~1e-3 m, so positions stay bitwise fixed
(asserted) while the geometric contact radius, which does not depend on E, still conducts.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.state import heat

R = 1e-3
RHO = 2500.0
K = 1.0
C = 800.0
K_WALL = 20.0


def mass(r: float = R) -> float:
    return RHO * 4.0 / 3.0 * math.pi * r**3


MATERIAL = {
    "density": RHO,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "thermal_conductivity": K,
    "specific_heat": C,
    "restitution": 0.5,
}
LIMP = dict(MATERIAL, youngs_modulus=1e-200)  # frozen in place under the mechanics
MATERIALS = {
    "glass": dict(MATERIAL),
    "steel": dict(MATERIAL, thermal_conductivity=K_WALL),
    "copper": dict(MATERIAL, thermal_conductivity=400.0),
    "limp": LIMP,
    "limp_wall": dict(LIMP, thermal_conductivity=K_WALL),
}


def _write(path: Path, rows: list[tuple], temperature: bool = False) -> str:
    header = "x y z radius" + (" temperature" if temperature else "")
    path.write_text("\n".join([header] + [" ".join(f"{v!r}" for v in r) for r in rows]) + "\n")
    return str(path)


def _file(path: str, material: str = "glass", **extra) -> dict:
    return {"kind": "file", "material": material, "path": path, **extra}


def _case(insertion: list, thermal: dict, walls: list | None = None, dt: float = 1e-5) -> dict:
    return {
        "simulation": {"time_step": dt, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": {k: dict(v) for k, v in MATERIALS.items()},
        "insertion": insertion,
        "walls": walls or [],
        "thermal": thermal,
    }


def _sim(*args, **kwargs) -> Simulation:
    return Simulation(case_from_dict(_case(*args, **kwargs)))


def _order(sim: Simulation) -> np.ndarray:
    return np.argsort(sim.particles.global_id)


def _temps(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[_order(sim)]


def _source(sim: Simulation) -> np.ndarray:
    """Source column [W] by global id (heat flux, volumetric and external sources)."""
    return sim.particles.heat_rate_by_mechanism[_order(sim), heat.M_SOURCE]


# ------------------------------------------------------------------------ initial temperature
LINE = [(-0.005 + 0.003 * k, 0.001, 0.002, R) for k in range(5)]  # x = -5, -2, 1, 4, 7 mm


def test_initial_temperature_default_and_uniform(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    case = _case([_file(path)], {})
    case["simulation"]["initial_temperature"] = 310.0
    assert np.all(Simulation(case_from_dict(case)).particles.temperature == 310.0)
    case["thermal"] = {"initial_temperature": {"kind": "uniform", "value": 350.0}}
    assert np.all(Simulation(case_from_dict(case)).particles.temperature == 350.0)


def test_initial_temperature_per_material(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE[:2])
    path2 = _write(tmp_path / "q.txt", LINE[2:4])
    path3 = _write(tmp_path / "r.txt", LINE[4:])
    rule = {"kind": "per_material", "values": {"glass": 310.0, "steel": 420.0}, "default": 250.0}
    sim = _sim(
        [_file(path), _file(path2, "steel"), _file(path3, "copper")],
        {"initial_temperature": rule},
    )
    # ids 0-1 glass, 2-3 steel, 4 copper (not listed: the default)
    assert _temps(sim).tolist() == [310.0, 310.0, 420.0, 420.0, 250.0]


def test_initial_temperature_regions_last_wins_default_outside(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    a = {"lower": [-0.01, -0.01, -0.01], "upper": [0.002, 0.01, 0.01]}  # x = -5, -2, 1 mm
    b = {"lower": [0.0, -0.01, -0.01], "upper": [0.005, 0.01, 0.01]}  # x = 1, 4 mm
    rule = {"kind": "regions", "regions": [[a, 330.0], [b, 360.0]], "default": 280.0}
    sim = _sim([_file(path)], {"initial_temperature": rule})
    assert _temps(sim).tolist() == [330.0, 330.0, 360.0, 360.0, 280.0]
    # the same regions in the other order: the overlap (x = 1 mm) takes a's value
    rule["regions"] = [[b, 360.0], [a, 330.0]]
    sim = _sim([_file(path)], {"initial_temperature": rule})
    assert _temps(sim).tolist() == [330.0, 330.0, 330.0, 360.0, 280.0]


def test_initial_temperature_expression_of_position(tmp_path: Path) -> None:
    rows = [(-0.005 + 0.003 * k, 0.001 * (k - 2), 0.002 - 0.0015 * k, R) for k in range(5)]
    path = _write(tmp_path / "p.txt", rows)
    rule = {"kind": "expression", "expression": "300 + 2000*x - 1000*y**2 + 50*exp(z/0.01)"}
    sim = _sim([_file(path)], {"initial_temperature": rule})
    exact = [300 + 2000 * x - 1000 * y**2 + 50 * math.exp(z / 0.01) for x, y, z, _ in rows]
    np.testing.assert_allclose(_temps(sim), exact, rtol=1e-15)


def test_poured_particles_get_the_rule_at_their_position_and_entries_override(
    tmp_path: Path,
) -> None:
    pour = {
        "kind": "pour",
        "material": "glass",
        "distribution": {"kind": "mono", "radius": 5e-4},
        "rate": 1000.0,
        "interval": 1e-3,
        "end_time": 5e-3,
    }
    left = {"kind": "box", "lower": [-0.01, -0.005, 0.0], "upper": [-0.001, 0.005, 0.01]}
    right = {"kind": "box", "lower": [0.001, -0.005, 0.0], "upper": [0.01, 0.005, 0.01]}
    far = [(0.015, 0.015, 0.015, R), (-0.015, 0.015, 0.015, R)]
    insertion = [
        _file(_write(tmp_path / "a.txt", far), temperature=444.0),  # ids 0, 1: entry value
        _file(
            _write(tmp_path / "b.txt", [(0.015, -0.015, 0.015, R, 411.0)], True), temperature=555.0
        ),  # id 2: the file column wins over the entry
        _file(_write(tmp_path / "c.txt", [(-0.015, -0.015, 0.015, R)])),  # id 3: the rule
        dict(pour, region=left),  # by the rule at the insertion position
        dict(pour, region=right, temperature=333.0),  # entry's value
    ]
    rule = {"kind": "expression", "expression": "300 + 1000*z + 500*x"}
    sim = _sim(insertion, {"initial_temperature": rule})
    start = sim.particles.position[_order(sim)].copy()
    sim.run(steps=600)  # batches at 1, 2, ..., 5 ms: five particles per pour
    p = sim.particles
    order = _order(sim)
    pos, temp = p.position[order], p.temperature[order]
    np.testing.assert_array_equal(pos[:4], start)  # no gravity, no velocity: nothing moves
    assert temp[:4].tolist() == [444.0, 444.0, 411.0, 300 + 1000 * 0.015 + 500 * -0.015]
    poured_left = pos[4:, 0] < 0.0
    assert p.count == 14 and poured_left.sum() == 5
    x, z = pos[4:, 0][poured_left], pos[4:, 2][poured_left]
    np.testing.assert_array_equal(temp[4:][poured_left], 300 + 1000 * z + 500 * x)
    assert np.all(temp[4:][~poured_left] == 333.0)


# -------------------------------------------------------------------------- wall temperature
def _plane(z: float, thermal: dict | None = None, material: str = "steel") -> dict:
    w = {"kind": "plane", "point": [0, 0, z], "normal": [0, 0, 1], "material": material}
    if thermal is not None:
        w["thermal"] = thermal
    return w


def test_wall_temperature_constant_table_and_expression(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", [(0.0011, 0.0012, 0.0013, R)])
    table = [[0.5, 300.0], [1.5, 400.0], [3.5, 200.0]]
    walls = [
        _plane(-0.015, {"kind": "fixed", "temperature": 450.0}),
        {
            "kind": "box",
            "lower": [-0.01] * 3,
            "upper": [0.01] * 3,
            "material": "steel",
            "thermal": {"kind": "fixed", "temperature": table},
        },
        _plane(-0.016, {"kind": "fixed", "temperature": "300 + 20*t + 50*(t > 2)"}),
        _plane(-0.017),  # adiabatic
    ]
    sim = _sim([_file(path)], {"frozen_mechanics": True, "time_step": 0.25}, walls=walls)
    rows = sim.wall_rows
    assert rows.shape[0] == 1 + 6 + 1 + 1
    assert rows[:, 17].tolist() == [1.0] * 8 + [0.0]
    # hand values: the table is linear between its nodes and held outside; (t > 2) is 0 or 1
    expected = {
        0.0: (300.0, 300.0),
        0.5: (300.0, 310.0),
        1.0: (350.0, 320.0),
        1.5: (400.0, 330.0),
        2.0: (350.0, 340.0),
        2.5: (300.0, 400.0),
        3.5: (200.0, 420.0),
        10.0: (200.0, 550.0),
    }
    for t, (t_box, t_expr) in expected.items():
        sim.thermal._update_walls(t)
        assert rows[0, 18] == 450.0
        assert rows[1:7, 18] == pytest.approx([t_box] * 6, rel=1e-15)
        assert rows[7, 18] == pytest.approx(t_expr, rel=1e-15)
    # in a run, step k (k = 1, 2, ...) uses the walls at its start, t = (k - 1) dt
    for k, (t_box, t_expr) in ((5, (350.0, 320.0)), (11, (300.0, 400.0))):
        sim.run(steps=k - sim.step_count)
        assert rows[1, 18] == pytest.approx(t_box, rel=1e-15)
        assert rows[7, 18] == pytest.approx(t_expr, rel=1e-15)


def test_sphere_on_wall_follows_piecewise_exponential_of_wall_steps(tmp_path: Path) -> None:
    # T_w = 300 K, 500 K from t = 2 s, 350 K from t = 12 s; the sphere starts at 300 K
    delta = 1e-5
    path = _write(tmp_path / "one.txt", [(0.0011, 0.0012, R - delta, R)])
    wall_t = "where(t < 2.0, 300.0, where(t < 12.0, 500.0, 350.0))"
    dt = 1.0 / 64.0  # a power of two: step times k dt are exact, t = 2 and 12 s are steps
    sim = _sim(
        [_file(path)],
        {
            "frozen_mechanics": True,
            "time_step": dt,
            "initial_temperature": {"kind": "uniform", "value": 300.0},
        },
        walls=[_plane(0.0, {"kind": "fixed", "temperature": wall_t})],
    )
    # BOB simple with a wall: H = 4 k̄ a, k̄ = k_p k_w / (k_p + k_w), a² = 2 R δ - δ²
    h = 4.0 * (K * K_WALL / (K + K_WALL)) * math.sqrt(2 * R * delta - delta**2)
    tau = mass() * C / h
    x = dt / tau

    def discrete(t: float) -> float:  # explicit Euler: T - T_w shrinks by (1 - dt/τ) per step
        if t <= 2.0:
            return 300.0
        if t <= 12.0:
            return 500.0 - 200.0 * (1.0 - x) ** round((t - 2.0) / dt)
        t12 = discrete(12.0)
        return 350.0 + (t12 - 350.0) * (1.0 - x) ** round((t - 12.0) / dt)

    def exact(t: float) -> float:
        if t <= 2.0:
            return 300.0
        if t <= 12.0:
            return 500.0 - 200.0 * math.exp(-(t - 2.0) / tau)
        return 350.0 + (exact(12.0) - 350.0) * math.exp(-(t - 12.0) / tau)

    for t in (1.0, 2.0, 7.0, 12.0, 16.0, 24.0):
        sim.run(until=t)
        got = sim.particles.temperature[0]
        if t <= 2.0:
            assert got == 300.0
            continue
        assert got == pytest.approx(discrete(t), rel=1e-12)
        # Euler's global error on a decay over time s is ≈ (s/τ)(dt/2τ) of the jump; bound it
        # by twice that, summed over both jumps (200 K and ≈ 120 K)
        bound = 2 * 200.0 * (t - 2.0) / tau * x / 2
        assert abs(got - exact(t)) < bound
    assert abs(sim.thermal.balance_error()) < 1e-12 * sim.thermal.thermal_energy()


# ---------------------------------------------------------------------------- external source
# well separated particles (no contacts): ids 0 and 1 inside the region, id 2 outside
SOURCE_ROWS = [
    (0.001, 0.001, 0.003, R),
    (0.004, 0.001, -0.002, 5e-4),
    (0.015, 0.0, 0.0, R),
    (0.001, -0.001, 0.0, 7e-4),
]
REGION = {"lower": [-0.004, -0.002, -0.003], "upper": [0.006, 0.004, 0.005]}  # centre 1,1,1 mm


def test_external_source_uniform_splits_power_by_cross_section(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", SOURCE_ROWS)
    src = {"power": 2.0, "region": REGION, "start_time": 0.5, "end_time": 1.5}
    sim = _sim([_file(path)], {"external_source": [src]})
    r = np.array([row[3] for row in SOURCE_ROWS])
    inside = np.array([True, True, False, True])
    share = 2.0 * r**2 * inside / (r[inside] ** 2).sum()  # P R_i² / Σ R², π cancels
    assert share[0] == pytest.approx(2.0 * 1.0 / (1.0 + 0.25 + 0.49), rel=1e-14)
    for t, on in (
        (0.0, False),
        (0.4999, False),
        (0.5, True),
        (1.0, True),
        (1.4999, True),
        (1.5, False),
        (3.0, False),
    ):
        sim.thermal.compute_rates(t)
        np.testing.assert_allclose(_source(sim), share if on else 0.0, rtol=1e-14, atol=0.0)
        assert sim.particles.heat_rate[_order(sim)] == pytest.approx(_source(sim), rel=1e-14)


@pytest.mark.parametrize("axis", [(0.0, 0.0, 1.0), (1.0, 1.0, 0.0), (0.0, 3.0, 0.0)])
def test_external_source_gaussian_weights_by_distance_from_axis(
    tmp_path: Path, axis: tuple
) -> None:
    path = _write(tmp_path / "p.txt", SOURCE_ROWS)
    sigma = 2e-3
    src = {"power": 3.0, "region": REGION, "profile": "gaussian", "sigma": sigma, "axis": axis}
    sim = _sim([_file(path)], {"external_source": [src]})
    pos = np.array([row[:3] for row in SOURCE_ROWS])
    r = np.array([row[3] for row in SOURCE_ROWS])
    n = np.asarray(axis) / math.sqrt(sum(a * a for a in axis))
    d = pos - np.array([0.001, 0.001, 0.001])  # the axis line passes through the box centre
    dist2 = (d**2).sum(axis=1) - (d @ n) ** 2
    w = r**2 * np.exp(-dist2 / (2 * sigma**2)) * np.array([1, 1, 0, 1])
    np.testing.assert_allclose(_source(sim), 3.0 * w / w.sum(), rtol=1e-13, atol=0.0)
    if axis == (0.0, 0.0, 1.0):  # by hand: r² = 0, 9e-6, 4e-6 m² from the vertical axis
        w0 = [1.0, 0.25 * math.exp(-9e-6 / 8e-6), 0.0, 0.49 * math.exp(-4e-6 / 8e-6)]
        np.testing.assert_allclose(_source(sim), 3.0 * np.array(w0) / sum(w0), rtol=1e-13)


def test_external_source_ledger_integrates_power_over_active_window(tmp_path: Path) -> None:
    # two touching spheres (conduction between them) and one far away, adiabatic
    rows = [
        (0.0011, 0.001, 0.001, R, 300.0),
        (0.0011 + 1.95e-3, 0.001, 0.001, R, 350.0),
        (0.015, 0.0, 0.0, R, 320.0),
    ]
    path = _write(tmp_path / "p.txt", rows, temperature=True)
    power = 0.01
    src = {
        "power": power,
        "region": {"lower": [-0.005] * 3, "upper": [0.006] * 3},
        "start_time": 1.0,
        "end_time": 3.0,
    }
    sim = _sim(
        [_file(path)], {"frozen_mechanics": True, "time_step": 0.25, "external_source": [src]}
    )
    th = sim.thermal
    u0 = th.thermal_energy()
    sim.run(until=1.0)  # steps starting at 0, 0.25, 0.5, 0.75: before the window
    assert th.cumulative["heat_in_source"] == 0.0
    assert th.thermal_energy() == pytest.approx(u0, rel=1e-14)
    assert _temps(sim)[2] == 320.0
    assert _temps(sim)[1] < 350.0  # conduction ran
    sim.run(until=5.0)  # steps starting at 1.0 ... 2.75 are in [1, 3): 2 s of power
    assert th.cumulative["heat_in_source"] == pytest.approx(power * 2.0, rel=1e-14)
    assert th.thermal_energy() - u0 == pytest.approx(power * 2.0, rel=1e-10)
    assert abs(th.balance_error()) < 1e-12 * u0
    assert _temps(sim)[2] == 320.0  # outside the region


# ---------------------------------------------------------------------------------- selection
def test_selection_by_material_region_ids_and_their_intersection(tmp_path: Path) -> None:
    glass = _write(tmp_path / "g.txt", LINE[:3] + [(-0.008, 0.001, 0.002, R)])
    steel = _write(tmp_path / "s.txt", LINE[3:] + [(0.010, 0.001, 0.002, R)])
    # ids: glass 0 (x=-5), 1 (-2), 2 (1), 3 (-8); steel 4 (4), 5 (7), 6 (10) [mm]
    box = {"lower": [-0.003, -0.01, -0.01], "upper": [0.0075, 0.01, 0.01]}  # ids 1, 2, 4, 5
    flux = [  # powers of two: each particle's flux says which selections hold
        ({"material": "steel"}, 1.0),  # 4, 5, 6
        ({"region": box}, 2.0),  # 1, 2, 4, 5
        ({"ids": [0, 2, 4]}, 4.0),  # 0, 2, 4
        ({"material": "steel", "region": box, "ids": [0, 2, 5, 6]}, 8.0),  # 5
        ({"material": "glass", "region": box}, 16.0),  # 1, 2
    ]
    thermal = {
        "heat_flux": [{"select": s, "flux": q} for s, q in flux],
        "fixed_temperature": [
            {"select": {"material": "glass", "ids": [3, 4]}, "temperature": 500.0}
        ],
    }
    sim = _sim([_file(glass), _file(steel, "steel")], thermal)
    bits = np.array([4, 2 + 16, 2 + 4 + 16, 0, 1 + 2 + 4, 1 + 2 + 8, 1], float)
    np.testing.assert_allclose(_source(sim), bits * 4 * math.pi * R**2, rtol=1e-14, atol=0.0)
    fixed = sim.thermal.fixed[_order(sim)]
    assert fixed.tolist() == [False, False, False, True, False, False, False]
    assert _temps(sim)[3] == 500.0


def test_region_selection_follows_current_positions(tmp_path: Path) -> None:
    # a particle moving at 1 m/s along +x leaves the region x <= 0 during the run
    x0 = -0.001055
    path = _write(tmp_path / "p.txt", [(x0, 0.001, 0.002, R, 300.0)], temperature=True)
    region = {"lower": [-0.01, -0.01, -0.01], "upper": [0.0, 0.01, 0.01]}
    q = 5000.0
    sim = _sim([_file(path)], {"heat_flux": [{"select": {"region": region}, "flux": q}]})
    sim.particles.velocity[:] = [1.0, 0.0, 0.0]
    sim.run(steps=300)
    assert sim.particles.position[0, 0] == pytest.approx(x0 + 300 * 1e-5, rel=1e-12)
    assert sim.particles.heat_rate_by_mechanism[0, heat.M_SOURCE] == 0.0
    # thermal steps start at x0 + k dx, k = 0 ... 299: inside for k <= 105 (x <= -5 µm)
    heating = q * 4 * math.pi * R**2 / (mass() * C)
    assert sim.particles.temperature[0] == pytest.approx(300.0 + 106 * 1e-5 * heating, rel=1e-12)


# -------------------------------------------------------------------------------- sub-cycling
CLUSTER = [  # touching limp spheres, coordinates away from zero (see the module docstring)
    (0.0011, 0.0013, R - 1e-5, R, 300.0),
    (0.0011 + 1.95e-3, 0.0013, R - 1e-5, R, 310.0),
    (0.0011 + 1.95e-3, 0.0013 + 1.9e-3, R - 1e-5, R, 320.0),
    (0.0011 + 1.95e-3, 0.0013 + 1.9e-3, R - 1e-5 + 1.96e-3, R, 330.0),
    (0.0011 - 0.02e-3, 0.0013 + 1.9e-3, R - 1e-5 + 1.96e-3, R, 340.0),
]


@pytest.mark.parametrize("wall_temperature", [500.0, "500 + 20*t"])
def test_substeps_equal_frozen_mechanics_with_n_dt(tmp_path: Path, wall_temperature) -> None:
    path = _write(tmp_path / "c.txt", CLUSTER, temperature=True)
    n, dt, k = 4, 0.05, 100
    conditions = {
        "fixed_temperature": [{"select": {"ids": [4]}, "temperature": 250.0}],
        "heat_flux": [{"select": {"ids": [3]}, "flux": 2000.0}],
    }
    walls = [_plane(0.0, {"kind": "fixed", "temperature": wall_temperature}, "limp_wall")]
    sub = _sim([_file(path, "limp")], dict(conditions, substeps=n), walls=walls, dt=dt)
    start = sub.particles.position.copy()
    frozen = _sim(
        [_file(path, "limp")],
        dict(conditions, frozen_mechanics=True, time_step=n * dt),
        walls=walls,
        dt=dt,
    )
    assert sub.contact_count == 7  # four particle contacts, three on the wall
    sub.run(steps=n * k)
    frozen.run(steps=k)
    np.testing.assert_array_equal(sub.particles.position, start)  # frozen in place
    assert sub.thermal.thermal_steps == frozen.thermal.thermal_steps == k
    assert np.ptp(_temps(sub)) > 50.0  # heat moved
    if isinstance(wall_temperature, float):
        # same positions, contacts, temperatures and Δt_th = n dt: the same floating-point
        # operations, so the same bits
        np.testing.assert_array_equal(_temps(sub), _temps(frozen))
        assert sub.thermal.cumulative == frozen.thermal.cumulative
    else:
        # the step times differ in the last bit: (j n) dt against j (n dt)
        np.testing.assert_allclose(_temps(sub), _temps(frozen), rtol=1e-14, atol=0.0)
    for sim in (sub, frozen):
        assert abs(sim.thermal.balance_error()) < 1e-12 * sim.thermal.thermal_energy()


def test_substeps_converge_to_two_sphere_relaxation(tmp_path: Path) -> None:
    d = 1.95e-3
    rows = [(0.0011, 0.0013, 0.0017, R, 300.0), (0.0011 + d, 0.0013, 0.0017, R, 400.0)]
    path = _write(tmp_path / "two.txt", rows, temperature=True)
    # BOB simple, geometric radius: H = 4 (k/2) a, a² = R² - (d/2)²; ΔT = 100 exp(-t/τ)
    h = 2.0 * K * math.sqrt(R**2 - (d / 2) ** 2)
    tau = mass() * C / (2.0 * h)
    dt, steps = 0.01, 500
    exact = 100.0 * math.exp(-dt * steps / tau)
    errors = []
    for n in (1, 5, 25):
        sim = _sim([_file(path, "limp")], {"substeps": n}, dt=dt)
        sim.run(steps=steps)
        got = np.diff(_temps(sim))[0]
        assert got == pytest.approx(100.0 * (1.0 - n * dt / tau) ** (steps // n), rel=1e-12)
        # conduction is antisymmetric: the sum drifts by at most an ulp per particle and step
        assert abs(_temps(sim).sum() - 700.0) <= 2 * (steps // n) * np.spacing(400.0)
        errors.append(abs(got - exact) / exact)
    assert errors[0] < 1e-3
    assert errors[0] / errors[1] == pytest.approx(1 / 5, rel=0.1)  # first order in n dt
    assert errors[1] / errors[2] == pytest.approx(1 / 5, rel=0.1)


# ---------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("key", ["fixed_temperature", "heat_flux", "volumetric_source"])
def test_unknown_material_in_a_selection(tmp_path: Path, key: str) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    value = {
        "fixed_temperature": "temperature",
        "heat_flux": "flux",
        "volumetric_source": "power_density",
    }[key]
    thermal = {key: [{"select": {"material": "glas"}, value: 400.0}]}
    with pytest.raises(
        ConfigError,
        match=rf"thermal\.{key}\.0\.select\.material: unknown "
        r"material 'glas'; allowed: copper, glass",
    ):
        case_from_dict(_case([_file(path)], thermal))


def test_unknown_material_in_per_material_rule(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    rule = {"kind": "per_material", "values": {"glas": 400.0}}
    with pytest.raises(ConfigError, match=r"thermal\.initial_temperature\.values: unknown"):
        case_from_dict(_case([_file(path)], {"initial_temperature": rule}))


def test_model_missing_a_material_property_names_model_and_property(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    case = _case([_file(path)], {"direct_conduction": "resistance_network"})
    case["materials"]["glass"].update(
        surface_roughness=1e-6, surface_slope=0.1, thermal_accommodation=0.9
    )
    with pytest.raises(
        ConfigError,
        match=r"materials\.glass\.microhardness: missing; required by "
        r"thermal\.direct_conduction = 'resistance_network'",
    ):
        Simulation(case_from_dict(case))
    case["materials"]["glass"]["microhardness"] = 1e9
    Simulation(case_from_dict(case))  # complete: builds


def test_missing_specific_heat_names_the_material_key(tmp_path: Path) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    case = _case([_file(path, "steel")], {})
    del case["materials"]["steel"]["specific_heat"]
    with pytest.raises(ConfigError, match=r"materials\.steel\.specific_heat"):
        Simulation(case_from_dict(case))
    # a material no particle uses (a wall's) needs no specific heat
    case["insertion"] = [_file(path)]
    case["walls"] = [_plane(-0.015, {"kind": "fixed", "temperature": 400.0})]
    Simulation(case_from_dict(case))


@pytest.mark.parametrize(
    ("thermal", "walls", "message"),
    [
        (
            {
                "external_source": [
                    {
                        "power": 1.0,
                        "region": REGION,
                        "profile": "gaussian",
                        "sigma": 1e-3,
                        "axis": [0, 0, 0],
                    }
                ]
            },
            [],
            r"external_source\.0: axis must be a non-zero vector",
        ),
        (
            {},
            [_plane(-0.015, {"temperature": 400.0})],
            r"walls\.0\.(plane\.)?thermal: temperature is given but kind is 'adiabatic'",
        ),
        (
            {},
            [_plane(-0.015, {"kind": "fixed", "temperature": -20.0})],
            r"walls\.0\.(plane\.)?thermal: temperature must be > 0 K",
        ),
        (
            {},
            [_plane(-0.015, {"kind": "fixed", "temperature": [[0.0, 300.0], [1.0, 0.0]]})],
            r"walls\.0\.(plane\.)?thermal: temperature table values must be > 0 K",
        ),
        (
            {"initial_temperature": {"kind": "per_material", "values": {"glass": -5.0}}},
            [],
            r"initial_temperature\.(per_material\.)?values: temperature of 'glass' must be > 0 K",
        ),
        (
            {"initial_temperature": {"kind": "regions", "regions": [[REGION, 0.0]]}},
            [],
            r"initial_temperature\.(regions\.)?regions: temperature of region 0 must be > 0 K",
        ),
    ],
)
def test_bad_condition_values_are_refused(
    tmp_path: Path, thermal: dict, walls: list, message: str
) -> None:
    path = _write(tmp_path / "p.txt", LINE)
    with pytest.raises(ConfigError, match=message):
        case_from_dict(_case([_file(path)], thermal, walls=walls))


def test_ledger_closes_when_particles_are_poured(tmp_path: Path) -> None:
    pour = {
        "kind": "pour",
        "material": "glass",
        "distribution": {"kind": "mono", "radius": 5e-4},
        "region": {"kind": "box", "lower": [-0.005, -0.005, 0.0], "upper": [0.005, 0.005, 0.01]},
        "rate": 1000.0,
        "interval": 1e-3,
        "end_time": 3e-3,
    }
    path = _write(tmp_path / "p.txt", [(0.015, 0.015, 0.015, R, 300.0)], temperature=True)
    sim = _sim([_file(path), pour], {"initial_temperature": {"kind": "uniform", "value": 400.0}})
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=400)
    assert sim.particles.count == 4
    # nothing conducts (no contacts, adiabatic): U gained exactly the poured particles' m c T
    brought = 3 * mass(5e-4) * C * 400.0
    assert sim.thermal.thermal_energy() - u0 == pytest.approx(brought, rel=1e-12)
    assert abs(sim.thermal.balance_error()) < 1e-12 * u0


def _brute_force(sim: Simulation) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fixed mask, bath temperatures and source powers of the case's selections evaluated at
    the current positions entry by entry (the rule of docs/thermal-engine.md, written out)."""
    p, th = sim.particles, sim.thermal.settings
    n = p.count
    fixed, bath, source = np.zeros(n, bool), np.zeros(n), np.zeros(n)
    entries = [("fixed", f.temperature, f.select) for f in th.fixed_temperature]
    entries += [("flux", h.flux, h.select) for h in th.heat_flux]
    entries += [("volume", v.power_density, v.select) for v in th.volumetric_source]
    for kind, value, sel in entries:
        holds = np.ones(n, bool)
        if sel.material is not None:
            holds &= p.type_id == sim.material_index[sel.material]
        if sel.ids is not None:
            holds &= np.isin(p.global_id, sel.ids)
        if sel.region is not None:
            lo, hi = np.asarray(sel.region.lower), np.asarray(sel.region.upper)
            holds &= np.all((p.position >= lo) & (p.position <= hi), axis=1)
        if kind == "fixed":
            fixed |= holds
            bath[holds] = value
        elif kind == "flux":
            source[holds] += value * 4 * math.pi * p.radius[holds] ** 2
        else:
            source[holds] += value * 4 / 3 * math.pi * p.radius[holds] ** 3
    return fixed, bath, source


def test_selections_are_classified_at_builds_and_equal_a_brute_force_every_step(
    tmp_path: Path,
) -> None:
    """Particles fly through region selections (one at a periodic face, where positions wrap)
    for 400 steps: at every step the fixed particles, their bath temperatures and the sources
    are those of the selections evaluated at the current positions, although the particles
    are classified only at the neighbour-list builds and per step only the held particles
    and those within half a skin of a region face are visited (issue 17 §5)."""
    rng = np.random.default_rng(5)
    n = 300
    rows = [(*map(float, rng.uniform(-0.019, 0.019, 3)), 4e-4, 300.0) for _ in range(n)]
    keep = []  # drop overlapping draws
    for r in rows:
        if all(np.linalg.norm(np.subtract(r[:3], q[:3])) > 1e-3 for q in keep):
            keep.append(r)
    path = _write(tmp_path / "gas.txt", keep, temperature=True)
    slab = {"lower": [-0.03, -0.03, -0.004], "upper": [0.03, 0.03, 0.003]}
    face = {"lower": [0.015, -0.03, -0.03], "upper": [0.03, 0.03, 0.03]}  # at the periodic x face
    corner = {"lower": [-0.02, -0.02, -0.02], "upper": [-0.005, 0.0, 0.01]}
    thermal = {
        "fixed_temperature": [
            {"select": {"region": slab}, "temperature": 400.0},
            {"select": {"region": face, "material": "glass"}, "temperature": 350.0},
            {"select": {"ids": [0, 1, 2]}, "temperature": 250.0},
        ],
        "heat_flux": [{"select": {"region": corner}, "flux": 300.0}],
        "volumetric_source": [{"select": {"region": face}, "power_density": 2e4}],
    }
    case = _case([_file(path)], thermal)
    case["domain"]["periodic"] = [True, True, True]
    case["neighbors"] = {"skin": 4e-4}
    sim = Simulation(case_from_dict(case))
    v = rng.normal(0.0, 0.3, (sim.particles.count, 3))
    v[:, 0] += np.where(rng.random(sim.particles.count) < 0.5, -2.0, 2.0)  # along periodic x
    sim.particles.velocity[:] = v
    listed = []

    def check(s: Simulation) -> None:
        fixed, bath, source = _brute_force(s)
        th = s.thermal
        assert np.array_equal(th.fixed, fixed)
        assert np.array_equal(s.particles.temperature[fixed], bath[fixed])
        np.testing.assert_allclose(th.source, source, rtol=1e-14, atol=0.0)
        listed.append(th.conditions.listed.shape[0])

    x0 = sim.particles.position[_order(sim), 0].copy()
    sim.run(steps=400, callback=check)
    assert len(listed) == 400
    wrapped = np.abs(sim.particles.position[_order(sim), 0] - x0) > 0.02
    assert wrapped.sum() > 10  # particles crossed the periodic face
    assert sim.rebuild_count > 3
    # classified at the builds (and once at the start), not at every step
    assert sim.thermal.conditions.classifications <= sim.rebuild_count + 2
    fixed_now = int(sim.thermal.fixed.sum())
    assert 0 < fixed_now < sim.particles.count
    assert np.mean(listed) < 0.6 * sim.particles.count


def test_rates_left_to_the_next_update_give_the_same_run(tmp_path: Path) -> None:
    """step(complete=False) leaves the source column and the total heat rates to the next
    thermal update (one pass less per step): the run is bit-identical to one that forms them
    at every step, and they are formed whenever they are read (complete_rates, run, report,
    callbacks), equal to the sum of the mechanism columns."""
    rows = [(0.0011 + 0.00195 * k, 0.0013, R - 1e-5, R, 300.0 + 10 * k) for k in range(4)]
    path = _write(tmp_path / "p.txt", rows, temperature=True)
    box = {"lower": [-0.01, -0.01, -0.01], "upper": [0.002, 0.01, 0.01]}
    thermal = {
        "fixed_temperature": [{"select": {"ids": [3]}, "temperature": 250.0}],
        "heat_flux": [{"select": {"region": box}, "flux": 2000.0}],
    }
    walls = [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "steel",
              "thermal": {"kind": "fixed", "temperature": 500.0}}]  # fmt: skip
    every, lazy = _sim([_file(path)], thermal, walls), _sim([_file(path)], thermal, walls)
    for sim in (every, lazy):
        sim.particles.velocity[:, 0] = 0.05
    for _ in range(40):
        every.step()
    lazy.step(complete=False)
    assert lazy.thermal.rates_pending
    lazy.complete_rates()
    assert not lazy.thermal.rates_pending
    seen = []

    def check(s: Simulation) -> None:
        p = s.particles
        assert not s.thermal.rates_pending
        columns = p.heat_rate_by_mechanism[:, s.thermal.sum_columns].sum(axis=1)
        np.testing.assert_allclose(p.heat_rate, columns, rtol=1e-13, atol=1e-300)
        seen.append(s.step_count)

    lazy.run(steps=39, callback=check, every=10)
    assert seen == [10, 20, 30, 40]
    for name, arr in every.particles.arrays().items():
        assert np.array_equal(arr, getattr(lazy.particles, name)), name
    assert every.report() == lazy.report()
    assert every.thermal.balance_error() == lazy.thermal.balance_error()


def test_held_particles_stay_at_their_bath_and_only_candidates_are_visited(
    tmp_path: Path,
) -> None:
    # a touching line of limp spheres (frozen in place by the mechanics), the first two held
    # at 500 K by a region far from their centres: they are held, not candidates, so after
    # the classification's first evaluation the per-step pass visits no particle; they stay
    # at exactly 500 K while conducting into the rest, and the ledger closes
    rows = [(0.0011 + 1.95e-3 * k, 0.0013, 0.0017, R, 300.0) for k in range(5)]
    path = _write(tmp_path / "line.txt", rows, temperature=True)
    region = {"lower": [-0.01, -0.01, -0.01], "upper": [0.0011 + 1.95e-3 * 1.5, 0.01, 0.01]}
    thermal = {
        "direct_conduction": "batchelor_obrien_simple",
        "contact_radius": "geometric",
        "fixed_temperature": [{"select": {"region": region}, "temperature": 500.0}],
    }
    sim = _sim([_file(path, "limp")], thermal)
    conditions = sim.thermal.conditions
    assert conditions.listed.shape[0] == 2 and conditions.candidates.shape[0] == 0
    assert not conditions.hold_pending  # the start's evaluation set them
    sim.run(steps=400)
    t = _temps(sim)
    assert t[:2].tolist() == [500.0, 500.0]
    assert 300.0 < t[2] < 500.0  # the heat reached the first free particle
    assert abs(sim.thermal.balance_error()) < 1e-9
    # a temperature written from outside, then invalidate(): the next evaluation holds it again
    sim.particles.temperature[_order(sim)[0]] = 321.0
    conditions.invalidate()
    sim.run(steps=1)
    assert _temps(sim)[0] == 500.0
    assert sim.thermal.cumulative["fixed_reset"] > 0.0  # m c (500 - 321) went in
