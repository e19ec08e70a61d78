"""Implicit heat (engine/implicit.py) against closed forms, the explicit engine and the ledger."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.implicit import ImplicitSolver, steady_state
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError

R = 1e-3
RHO = 2500.0
K = 1.0
C = 800.0
MASS = RHO * 4.0 / 3.0 * math.pi * R**3
D = 1.95e-3  # centre distance of touching neighbours
H = 2.0 * K * math.sqrt(R**2 - (D / 2) ** 2)  # BOB simple, geometric radius

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


def _sim(particles: str, thermal: dict, walls: list | None = None, materials=None) -> Simulation:
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": materials
        or {"glass": dict(MATERIAL), "steel": dict(MATERIAL, thermal_conductivity=20.0)},
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "walls": walls or [],
        "thermal": {"frozen_mechanics": True, **thermal},
    }
    return Simulation(case_from_dict(case))


def _by_gid(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[np.argsort(sim.particles.global_id)]


def _two(tmp_path: Path) -> str:
    return _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (D, 0.0, 0.0, R, 400.0)])


HOT_FLOOR = [
    {"kind": "plane", "point": [0, 0, -R + 1e-5], "normal": [0, 0, 1], "material": "steel",
     "thermal": {"kind": "fixed", "temperature": 500.0}},
]  # fmt: skip


def _column(tmp_path: Path, n: int = 6) -> str:
    """A vertical chain of n touching spheres standing 10 µm deep in the hot floor."""
    rows = [(0.0, 0.0, k * D, R, 300.0 + 5.0 * k) for k in range(n)]
    return _write(tmp_path / "column.txt", rows)


@pytest.mark.parametrize("scheme", ["backward_euler", "crank_nicolson"])
def test_two_spheres_follow_the_schemes_amplification_factor(tmp_path: Path, scheme: str) -> None:
    """ΔT^{n+1} = g ΔT^n with g = 1/(1+2x) (BE) or (1-x)/(1+x) (CN), x = H Δt/(m c); the
    schemes converge to exp(-t/τ), τ = m c/(2H), at first and second order."""
    x_tau = MASS * C / (2.0 * H)
    errors = []
    for dt in (0.4, 0.2, 0.1):
        sim = _sim(_two(tmp_path), {"time_step": dt, "scheme": scheme})
        steps = int(round(8.0 / dt))
        sim.run(steps=steps)
        t = _by_gid(sim)
        x = H * dt / (MASS * C)
        g = 1.0 / (1.0 + 2.0 * x) if scheme == "backward_euler" else (1.0 - x) / (1.0 + x)
        assert t[1] - t[0] == pytest.approx(100.0 * g**steps, rel=1e-9)
        assert t.sum() == pytest.approx(700.0, rel=1e-13)  # the pair exchange is antisymmetric
        errors.append(abs(t[1] - t[0] - 100.0 * math.exp(-8.0 / x_tau)))
    order = math.log2(errors[0] / errors[1]), math.log2(errors[1] / errors[2])
    expected = 1.0 if scheme == "backward_euler" else 2.0
    assert order == pytest.approx((expected, expected), abs=0.1)


def test_network_reproduces_the_engines_heat_rates(tmp_path: Path) -> None:
    """b - K T of the assembled network equals the heat rates the engine computes itself, for
    temperatures other than those of the assembly (the network is linear in T)."""
    thermal = {
        "time_step": 0.1,
        "scheme": "backward_euler",
        "indirect_conduction": {"model": "rong_horio1999"},
        "fixed_temperature": [{"select": {"ids": [5]}, "temperature": 280.0}],
        "heat_flux": [{"select": {"ids": [2]}, "flux": 50.0}],
    }
    sim = _sim(_column(tmp_path), thermal, walls=HOT_FLOOR)
    solver = sim.thermal.implicit
    net = solver.network(0.0)
    rng = np.random.default_rng(1)
    p = sim.particles
    p.temperature[:] = rng.uniform(290.0, 450.0, p.count)
    fixed = sim.thermal.compute_rates(0.0)
    expected = net.rhs - net.conductance @ p.temperature
    assert fixed.sum() == 1
    np.testing.assert_allclose(expected[~fixed], p.heat_rate[~fixed], rtol=1e-12, atol=1e-15)
    # more than the contact conduction entered the matrix: the gas gaps of the range set
    k = net.conductance
    off_diagonal = -(k.sum() - k.diagonal().sum()) / 2.0
    contact = sim.thermal.pair_conductance[: sim.pairs.count].sum()
    assert sim.thermal.range_set.count > 0 and off_diagonal > 1.01 * contact


@pytest.mark.parametrize("scheme", ["backward_euler", "crank_nicolson"])
def test_implicit_converges_to_the_explicit_reference_at_its_order(
    tmp_path: Path, scheme: str
) -> None:
    """A column heated from a fixed floor with a heat flux on top: the implicit results at
    Δt = 0.2, 0.1, 0.05 s approach an explicit reference at order 1 (BE) and 2 (CN). The
    reference is explicit Euler at 1e-3 s and 5e-4 s, Richardson-extrapolated (2 T_½ - T_1:
    second order; the two differ by 9e-4 K, the extrapolation by ~1e-6 K against CN errors
    of 1e-4 K and more)."""
    thermal = {"heat_flux": [{"select": {"ids": [5]}, "flux": 2000.0}]}
    refs = []
    for dt in (1e-3, 5e-4):
        ref = _sim(_column(tmp_path), {"time_step": dt, **thermal}, walls=HOT_FLOOR)
        ref.run(until=4.0)
        refs.append(_by_gid(ref))
    t_ref = 2.0 * refs[1] - refs[0]
    errors = []
    for dt in (0.2, 0.1, 0.05):
        sim = _sim(_column(tmp_path), {"time_step": dt, "scheme": scheme, **thermal},
                   walls=HOT_FLOOR)  # fmt: skip
        sim.run(until=4.0)
        errors.append(float(np.max(np.abs(_by_gid(sim) - t_ref))))
    order = [math.log2(errors[0] / errors[1]), math.log2(errors[1] / errors[2])]
    expected = 1.0 if scheme == "backward_euler" else 2.0
    assert order == pytest.approx([expected, expected], abs=0.05)


def test_ledger_closes_with_walls_sources_and_fixed_particles(tmp_path: Path) -> None:
    thermal = {
        "time_step": 0.5,
        "scheme": "crank_nicolson",
        "fixed_temperature": [{"select": {"ids": [3]}, "temperature": 310.0}],
        "heat_flux": [{"select": {"ids": [5]}, "flux": 3000.0}],
    }
    sim = _sim(_column(tmp_path), thermal, walls=HOT_FLOOR)
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=40)
    th = sim.thermal
    assert th.cumulative["heat_in_wall_direct_conduction"] > 1e-4 * u0
    assert abs(th.cumulative["fixed_absorbed"]) > 1e-5 * u0
    assert abs(th.balance_error()) < 1e-11 * u0


def test_steady_chain_between_two_temperatures_is_linear(tmp_path: Path) -> None:
    """Fixed ends 300 K and 400 K: equal conductances in series give a linear profile and
    the heat H ΔT/(n-1)."""
    rows = [(k * D, 0.0, 0.0, R, 350.0) for k in range(7)]
    thermal = {
        "time_step": 1.0,
        "fixed_temperature": [
            {"select": {"ids": [0]}, "temperature": 300.0},
            {"select": {"ids": [6]}, "temperature": 400.0},
        ],
    }
    sim = _sim(_write(tmp_path / "chain.txt", rows), thermal)
    net = steady_state(sim)
    t = _by_gid(sim)
    np.testing.assert_allclose(t, 300.0 + 100.0 / 6.0 * np.arange(7), rtol=1e-12)
    q = net.rhs - net.conductance @ sim.particles.temperature
    gid = sim.particles.global_id
    assert q[gid == 6][0] == pytest.approx(-H * 100.0 / 6.0, rel=1e-10)


def test_steady_state_of_a_floating_cluster_is_refused(tmp_path: Path) -> None:
    sim = _sim(_two(tmp_path), {"time_step": 1.0})
    with pytest.raises(ConfigError, match="no fixed temperature"):
        steady_state(sim)


def test_temperature_dependent_properties_picard(tmp_path: Path) -> None:
    """k(T) and c(T) tables: the converged implicit step conserves Σ m h(T) (the pair
    exchange cancels) and the Picard iteration takes more than one pass."""
    constants = ("thermal_conductivity", "specific_heat")  # (a table replaces its constant)
    glass = {k: v for k, v in MATERIAL.items() if k not in constants}
    mats = {
        "glass": dict(glass, thermal_conductivity_table=[[300.0, 1.0], [400.0, 3.0]],
                      specific_heat_table=[[300.0, 700.0], [400.0, 1100.0]]),
    }  # fmt: skip
    sim = _sim(_two(tmp_path), {"time_step": 0.5, "scheme": "backward_euler"}, materials=mats)
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=10)
    t = _by_gid(sim)
    assert 0.0 < t[1] - t[0] < 100.0
    assert sim.thermal.thermal_energy() == pytest.approx(u0, rel=1e-12)
    assert sim.thermal.implicit.timings.picard_iterations > 10


def test_implicit_scheme_needs_frozen_mechanics(tmp_path: Path) -> None:
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": {"glass": dict(MATERIAL)},
        "insertion": [{"kind": "file", "material": "glass", "path": _two(tmp_path)}],
        "thermal": {"scheme": "backward_euler"},
    }
    with pytest.raises(ConfigError, match="frozen_mechanics"):
        case_from_dict(case)


def test_multigrid_and_jacobi_paths_match_direct_solve(tmp_path: Path) -> None:
    thermal = {"time_step": 0.3, "scheme": "backward_euler"}
    a = _sim(_column(tmp_path, 10), thermal, walls=HOT_FLOOR)
    b = _sim(_column(tmp_path, 10), thermal, walls=HOT_FLOOR)
    c = _sim(_column(tmp_path, 10), {**thermal, "implicit": {"preconditioner": "jacobi"}},
             walls=HOT_FLOOR)  # fmt: skip
    b.thermal.implicit.direct_below = 0  # CG + smoothed aggregation even for 10 unknowns
    c.thermal.implicit.direct_below = 0
    for sim in (a, b, c):
        sim.run(steps=5)
    np.testing.assert_allclose(_by_gid(b), _by_gid(a), rtol=1e-10)
    np.testing.assert_allclose(_by_gid(c), _by_gid(a), rtol=1e-10)
    assert c.thermal.implicit.timings.setups == 0 and c.thermal.implicit.timings.cg_iterations
    assert b.thermal.implicit.timings.setups == 1  # one hierarchy for the constant matrix
    assert isinstance(b.thermal.implicit, ImplicitSolver)


def test_rannacher_start_keeps_second_order_and_damps_the_stiff_start(tmp_path: Path) -> None:
    """Crank–Nicolson with startup_steps: 2 (the first two steps as backward-Euler half
    steps) stays second order on the two spheres; with Δt ≫ τ plain CN flips the sign of
    ΔT every step (factor (1-x)/(1+x) → -1), the started run decays monotonically."""
    tau = MASS * C / (2.0 * H)
    errors = []
    for dt in (0.4, 0.2, 0.1):
        sim = _sim(_two(tmp_path), {"time_step": dt, "scheme": "crank_nicolson",
                                    "implicit": {"startup_steps": 2}})  # fmt: skip
        sim.run(until=8.0)
        t = _by_gid(sim)
        errors.append(abs(t[1] - t[0] - 100.0 * math.exp(-8.0 / tau)))
    assert math.log2(errors[1] / errors[2]) == pytest.approx(2.0, abs=0.1)
    stiff = {"time_step": 20.0 * tau, "scheme": "crank_nicolson"}
    plain = _sim(_two(tmp_path), stiff)
    started = _sim(_two(tmp_path), {**stiff, "implicit": {"startup_steps": 2}})
    plain.run(steps=2)
    started.run(steps=2)
    # x = H Δt/(m c) = 10: two steps of (1 - x)/(1 + x) = -9/11, two sign flips
    assert np.diff(_by_gid(plain))[0] == pytest.approx(100.0 * (9.0 / 11.0) ** 2, rel=1e-9)
    # four backward-Euler half steps of 1/(1 + x): monotone decay
    assert np.diff(_by_gid(started))[0] == pytest.approx(100.0 / 11.0**4, rel=1e-9)


def test_a_failed_solve_names_the_step_being_computed(tmp_path: Path) -> None:
    """Conjugate gradients stopped after one iteration fail in the first heat step, from the
    state at t = 0 to t = 0.3 s: the message names step 1 and its end (as the explicit update
    and the mechanics do), not step 0, the state it starts from, which the last checkpoint
    holds."""
    from thermodem.errors import SimulationError

    thermal = {"time_step": 0.3, "scheme": "backward_euler",
               "implicit": {"preconditioner": "jacobi", "max_iterations": 1}}  # fmt: skip
    sim = _sim(_column(tmp_path, 10), thermal, walls=HOT_FLOOR)
    sim.thermal.implicit.direct_below = 0
    with pytest.raises(SimulationError, match="conjugate gradients did not reach") as failed:
        sim.run(steps=5)
    assert "at step 1 (t = 0.3 s)" in str(failed.value), str(failed.value)
    assert failed.value.step == 1
