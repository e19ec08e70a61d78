"""Thermal engine against analytic solutions and conservation laws."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import SimulationError

R = 1e-3
RHO = 2500.0
K = 1.0
C = 800.0
MASS = RHO * 4.0 / 3.0 * math.pi * R**3

MATERIAL = {
    "density": RHO,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "thermal_conductivity": K,
    "specific_heat": C,
    "restitution": 0.5,
}


def _write(path: Path, rows: list[tuple]) -> str:
    lines = ["x y z radius temperature"] + [" ".join(f"{v!r}" for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _case(
    particles: str,
    thermal: dict,
    walls: list | None = None,
    dt: float = 1e-5,
    gravity=(0.0, 0.0, 0.0),
) -> dict:
    return {
        "simulation": {"time_step": dt, "end_time": 1.0, "gravity": list(gravity)},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": {"glass": dict(MATERIAL), "steel": dict(MATERIAL, thermal_conductivity=20.0)},
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "walls": walls or [],
        "thermal": thermal,
    }


def _by_gid(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[np.argsort(sim.particles.global_id)]


def _pair_relaxation(tmp_path: Path, dt_th: float, t_end: float) -> tuple[float, float]:
    d = 1.95e-3
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (d, 0.0, 0.0, R, 400.0)])
    sim = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": dt_th})))
    sim.run(until=t_end)
    t = _by_gid(sim)
    # BOB simple with the geometric radius: H = 4 (k/2) a, a² = R² - (d/2)²
    h = 2.0 * K * math.sqrt(R**2 - (d / 2) ** 2)
    tau = MASS * C / (2.0 * h)
    return t[1] - t[0], 100.0 * math.exp(-t_end / tau)


def test_two_spheres_relax_exponentially_first_order_in_dt(tmp_path: Path) -> None:
    errors = []
    for dt in (0.2, 0.1, 0.05):
        got, exact = _pair_relaxation(tmp_path, dt, 20.0)
        errors.append(abs(got - exact) / exact)
    assert errors[-1] < 1e-2
    # explicit Euler converges at first order: halving dt halves the error
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.1)
    assert errors[1] / errors[2] == pytest.approx(2.0, rel=0.1)


def test_mean_temperature_conserved_and_heat_antisymmetric(tmp_path: Path) -> None:
    d = 1.95e-3
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (d, 0.0, 0.0, R, 400.0)])
    sim = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 0.1})))
    q = sim.particles.heat_rate_by_mechanism[:, 0]
    assert q[0] == -q[1] and q.max() > 0
    sim.run(steps=50)
    assert sim.particles.temperature.sum() == pytest.approx(700.0, rel=1e-15, abs=1e-12)


def _bed(tmp_path: Path, n_side: int = 4, hot: float = 400.0) -> str:
    rng = np.random.default_rng(2)
    rows = []
    spacing = 2.0 * R * (1.0 - 1e-5)  # a resting simple-cubic stack, barely overlapping
    for a in range(n_side):
        for b in range(n_side):
            for c in range(n_side):
                rows.append(
                    (
                        a * spacing - 0.004,
                        b * spacing - 0.004,
                        c * spacing - 0.004 + R * 0.99999,
                        R,
                        float(rng.uniform(290.0, hot)),
                    )
                )
    return _write(tmp_path / "bed.txt", rows)


def test_adiabatic_box_ledger_closes_to_round_off(tmp_path: Path) -> None:
    walls = [
        {
            "kind": "box",
            "lower": [-0.006, -0.006, -0.004],
            "upper": [0.006, 0.006, 0.01],
            "material": "steel",
        }
    ]
    case = _case(_bed(tmp_path), {"substeps": 1}, walls=walls, gravity=(0.0, 0.0, -9.81))
    sim = Simulation(case_from_dict(case))
    sim.particles.velocity[:] = np.random.default_rng(3).normal(0, 0.02, (sim.particles.count, 3))
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=1500)
    assert sim.contact_count > 20  # touching pairs exchanged heat throughout
    assert sim.thermal.thermal_steps == 1500
    assert abs(sim.thermal.balance_error()) < 1e-12 * u0
    assert np.ptp(sim.particles.temperature) < 110.0  # heat moved


def test_hot_wall_ledger_equals_integrated_wall_heat(tmp_path: Path) -> None:
    walls = [
        {
            "kind": "box",
            "lower": [-0.006, -0.006, -0.004],
            "upper": [0.006, 0.006, 0.01],
            "material": "glass",
        },
        {
            "kind": "plane",
            "point": [0, 0, -0.004],
            "normal": [0, 0, 1],
            "material": "steel",
            "thermal": {"kind": "fixed", "temperature": 500.0},
        },
    ]
    case = _case(_bed(tmp_path, hot=300.0), {"substeps": 5}, walls=walls, gravity=(0.0, 0.0, -9.81))
    sim = Simulation(case_from_dict(case))
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=3000)
    wall_heat = sim.thermal.cumulative["heat_in_wall_direct_conduction"]
    assert wall_heat > 1e-6 * u0  # the floor heated the bed
    assert sim.thermal.thermal_energy() - u0 == pytest.approx(wall_heat, rel=1e-10)
    assert sim.thermal.thermal_steps == 600


def test_sphere_on_hot_plate_approaches_wall_temperature(tmp_path: Path) -> None:
    # a sphere pressed 10 µm into a fixed-temperature plane (frozen mechanics)
    delta = 1e-5
    path = _write(tmp_path / "one.txt", [(0.0, 0.0, R - delta, R, 300.0)])
    walls = [
        {
            "kind": "plane",
            "point": [0, 0, 0],
            "normal": [0, 0, 1],
            "material": "steel",
            "thermal": {"kind": "fixed", "temperature": 500.0},
        }
    ]
    sim = Simulation(
        case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 0.01}, walls=walls))
    )
    sim.run(until=5.0)
    # BOB simple with a wall: k̄ = k_p k_w /(k_p + k_w), geometric radius sqrt(2 R δ - δ²)
    a = math.sqrt(2 * R * delta - delta**2)
    h = 4.0 * (K * 20.0 / (K + 20.0)) * a
    tau = MASS * C / h
    exact = 500.0 - 200.0 * math.exp(-5.0 / tau)
    assert sim.particles.temperature[0] == pytest.approx(exact, rel=1e-4)


def test_constant_volumetric_and_surface_sources(tmp_path: Path) -> None:
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (0.01, 0.0, 0.0, R, 300.0)])
    thermal = {
        "frozen_mechanics": True,
        "time_step": 0.5,
        "volumetric_source": [{"select": {"ids": [0]}, "power_density": 1e5}],
        "heat_flux": [{"select": {"ids": [1]}, "flux": 100.0}],
    }
    sim = Simulation(case_from_dict(_case(path, thermal)))
    sim.run(until=10.0)
    t = _by_gid(sim)
    volume = 4.0 / 3.0 * math.pi * R**3
    assert t[0] == pytest.approx(300.0 + 1e5 * volume * 10.0 / (MASS * C), rel=1e-12)
    assert t[1] == pytest.approx(300.0 + 100.0 * 4 * math.pi * R**2 * 10.0 / (MASS * C), rel=1e-12)
    assert sim.thermal.balance_error() == pytest.approx(0.0, abs=1e-12)


def test_chain_between_fixed_ends_reaches_linear_profile(tmp_path: Path) -> None:
    d = 1.95e-3
    rows = [(k * d, 0.0, 0.0, R, 300.0) for k in range(6)]
    path = _write(tmp_path / "chain.txt", rows)
    thermal = {
        "frozen_mechanics": True,
        "time_step": 0.5,
        "fixed_temperature": [
            {"select": {"ids": [0]}, "temperature": 300.0},
            {"select": {"ids": [5]}, "temperature": 400.0},
        ],
    }
    sim = Simulation(case_from_dict(_case(path, thermal)))
    sim.run(until=3000.0)
    np.testing.assert_allclose(_by_gid(sim), np.linspace(300.0, 400.0, 6), rtol=1e-9)
    # in steady state the fixed ends absorb what they give: net zero
    assert sim.thermal.balance_error() == pytest.approx(0.0, abs=1e-9)


def test_unstable_thermal_step_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (1.95e-3, 0, 0, R, 400.0)])
    sim = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 50.0})))
    with pytest.raises(SimulationError, match="exceeds the explicit Euler limit"):
        sim.step()


@pytest.mark.parametrize(
    ("thermal", "remedy"),
    [
        ({"frozen_mechanics": True, "time_step": 50.0}, "reduce thermal.time_step, choose an "
         "implicit thermal.scheme"),
        ({"substeps": 100}, "reduce thermal.substeps, use substeps: auto"),
        # ρ c R²/k below the mechanical step itself: substeps cannot help (it told
        # "use substeps: auto" to a case with substeps: auto)
        ({"substeps": "auto"}, "the thermal step is already one mechanical step "
         "(thermal.substeps: auto): reduce simulation.time_step"),
    ],
)  # fmt: skip
def test_a_refused_thermal_step_names_what_can_change(
    tmp_path: Path, thermal: dict, remedy: str
) -> None:
    from thermodem.engine.checks import check_thermal_time_step
    from thermodem.errors import ConfigError

    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (1.95e-3, 0, 0, R, 400.0)])
    case = _case(path, thermal)
    if not thermal.get("frozen_mechanics"):
        # ρ c R²/k = 2.5e-5 s: above Δt = 1e-5 s, below 100 Δt; 2.5e-6 s: below Δt itself
        case["materials"]["glass"]["specific_heat"] = 0.01 if thermal["substeps"] == 100 else 0.001
    sim = Simulation(case_from_dict(case))
    with pytest.raises(ConfigError, match="thermal time step refused") as refused:
        check_thermal_time_step(sim)
    assert remedy in str(refused.value)
    assert str(refused.value).endswith("or set thermal.stability.allow_unstable: true)")


def test_auto_substeps_follow_the_limit(tmp_path: Path) -> None:
    case = _case(_bed(tmp_path), {"substeps": "auto"})
    sim = Simulation(case_from_dict(case))
    sim.run(steps=10)
    assert sim.thermal.substeps == min(int(0.5 * sim.thermal.limit / sim.dt), 1000)
    assert sim.thermal.substeps > 1


def test_temperature_dependent_specific_heat_integrates_enthalpy_exactly(tmp_path: Path) -> None:
    # one sphere, constant power; c(T) = c0 + b (T - 300) between 300 and 500 K
    c0, b = 800.0, 2.0
    path = _write(tmp_path / "one.txt", [(0.0, 0.0, 0.0, R, 300.0)])
    case = _case(
        path,
        {
            "frozen_mechanics": True,
            "time_step": 0.5,
            "volumetric_source": [{"select": {"ids": [0]}, "power_density": 2e5}],
        },
    )
    del case["materials"]["glass"]["specific_heat"]  # (the table replaces it)
    case["materials"]["glass"]["specific_heat_table"] = [[300.0, c0], [500.0, c0 + b * 200.0]]
    sim = Simulation(case_from_dict(case))
    u0 = sim.thermal.thermal_energy()
    sim.run(until=40.0)
    q = 2e5 * 4.0 / 3.0 * math.pi * R**3
    # m (c0 x + b x²/2) = Q t with x = T - 300
    x = (-c0 + math.sqrt(c0**2 + 2.0 * b * q * 40.0 / MASS)) / b
    assert sim.particles.temperature[0] == pytest.approx(300.0 + x, rel=1e-12)
    assert sim.thermal.thermal_energy() - u0 == pytest.approx(q * 40.0, rel=1e-12)


def test_temperature_dependent_conductivity_uses_each_particles_k(tmp_path: Path) -> None:
    d = 1.95e-3
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (d, 0.0, 0.0, R, 400.0)])
    case = _case(path, {"frozen_mechanics": True, "time_step": 0.1})
    del case["materials"]["glass"]["thermal_conductivity"]  # (the table replaces it)
    case["materials"]["glass"]["thermal_conductivity_table"] = [[300.0, 1.0], [400.0, 3.0]]
    sim = Simulation(case_from_dict(case))
    q = sim.particles.heat_rate_by_mechanism[np.argsort(sim.particles.global_id), 0]
    a = math.sqrt(R**2 - (d / 2) ** 2)
    k_bar = 1.0 * 3.0 / (1.0 + 3.0)  # k(300 K) = 1, k(400 K) = 3
    assert q[0] == pytest.approx(4.0 * k_bar * a * 100.0, rel=1e-12)
    assert q[1] == -q[0]


def test_pre_run_thermal_checks_refuse_and_warn_with_numbers(tmp_path: Path) -> None:
    from thermodem.engine.checks import check_thermal_time_step
    from thermodem.errors import ConfigError

    d = 1.95e-3
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (d, 0.0, 0.0, R, 400.0)])
    h = 2.0 * K * math.sqrt(R**2 - (d / 2) ** 2)
    limit = MASS * C / h  # m c / ΣH for one contact
    spec_limit = RHO * C * R**2 / K  # 2.0 s
    assert spec_limit < limit
    ok = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 0.1})))
    assert check_thermal_time_step(ok) == []
    warn = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 1.5})))
    (msg,) = check_thermal_time_step(warn)
    assert "ρ c R² / k = 2 s" in msg
    bad = Simulation(case_from_dict(_case(path, {"frozen_mechanics": True, "time_step": 20.0})))
    with pytest.raises(ConfigError) as err:
        check_thermal_time_step(bad)
    assert f"m c / ΣH = {limit:.4g} s" in str(err.value)


def test_frozen_mechanics_reuses_conductances_bit_identically(tmp_path: Path) -> None:
    """With frozen mechanics and constant properties the conductances of the first pass are
    reused; the temperatures and the heat ledger equal those of a run that re-evaluates every
    conductance at every thermal step, to the bit (a time-dependent hot wall, a fixed
    particle and a near-contact chain)."""
    d = 1.95e-3
    rows = [(k * d, 0.0, R - 1e-5, R, 300.0 + 10.0 * k) for k in range(5)]
    rows += [(0.0, d, R - 1e-5, R, 350.0), (3 * d, 2.5 * R, R - 1e-5, R, 320.0)]
    path = _write(tmp_path / "bed.txt", rows)
    walls = [
        {
            "kind": "plane",
            "point": [0, 0, 0],
            "normal": [0, 0, 1],
            "material": "steel",
            "thermal": {"kind": "fixed", "temperature": "400 + 50 * t"},
        }
    ]
    thermal = {
        "frozen_mechanics": True,
        "time_step": 0.05,
        "fixed_temperature": [{"select": {"ids": [4]}, "temperature": 330.0}],
    }
    runs = []
    for reuse in (True, False):
        sim = Simulation(case_from_dict(_case(path, dict(thermal), walls=walls)))
        sim.thermal.reuse_conductance = reuse
        sim.run(steps=200)
        runs.append(sim)
    reused, fresh = runs
    assert reused.thermal.conductance_ready and not fresh.thermal.conductance_ready
    np.testing.assert_array_equal(_by_gid(reused), _by_gid(fresh))
    assert reused.thermal.cumulative == fresh.thermal.cumulative
    assert not np.array_equal(_by_gid(reused), np.array([r[4] for r in rows]))  # heat moved
