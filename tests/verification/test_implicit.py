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
    """CG with multigrid, with the diagonal and with ``auto`` (the default) equal the direct
    solve; ``auto`` takes the diagonal where the capacity term bounds the condition number
    (Δt = 0.3 s, κ ≤ 2 (1 + Δt ΣH/(m c)) ≈ 2) and multigrid where it does not (Δt = 1e5 s,
    ~1e4 × m c/ΣH)."""
    for dt, auto in ((0.3, 0), (1e5, 1)):
        thermal = {"time_step": dt, "scheme": "backward_euler"}
        sims = [
            _sim(
                _column(tmp_path, 10),
                {**thermal, "implicit": {"preconditioner": choice}},
                walls=HOT_FLOOR,
            )
            for choice in ("auto", "amg", "jacobi", "auto")
        ]
        for sim in sims[1:]:
            sim.thermal.implicit.direct_below = 0  # CG even for 10 unknowns
        for sim in sims:
            sim.run(steps=5)
        for sim in sims[1:]:
            np.testing.assert_allclose(_by_gid(sim), _by_gid(sims[0]), rtol=1e-10)
            assert sim.thermal.implicit.timings.cg_iterations
        timings = [sim.thermal.implicit.timings for sim in sims]
        assert timings[0].cg_iterations == 0  # (direct)
        assert timings[1].setups == 1  # one hierarchy for the constant matrix
        assert timings[2].setups == 0
        assert timings[3].setups == auto
        assert isinstance(sims[1].thermal.implicit, ImplicitSolver)


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


def test_a_linear_network_skips_the_passes_while_its_data_hold(tmp_path: Path) -> None:
    """Backward Euler on a chain over a wall equals the recursion
    (C/Δt + K) Tⁿ⁺¹ = C/Δt Tⁿ + b(tⁿ⁺¹) written here (K: the chain's bonds and the wall's
    Batchelor & O'Brien conductance 4 k̄ R_c, k̄ = k/2, geometric R_c): with the wall at
    400 K the data of b do not change and a step reuses K and b (one pass of the engine per
    step, for the ledger); with the wall ramped, 400 + 0.05 t, b changes every step and the
    network's pass runs again (two per step)."""
    n, gap, dt, steps = 9, 1e-5, 50.0, 6
    h_wall = 2.0 * K * math.sqrt(R**2 - (R - gap) ** 2)
    k = np.diag(np.r_[H + h_wall, np.full(n - 2, 2.0 * H), H])
    k -= H * (np.eye(n, k=1) + np.eye(n, k=-1))
    cap = MASS * C / dt
    path = _write(tmp_path / "chain.txt", [(i * D, 0.0, 0.0, R, 300.0) for i in range(n)])
    for wall_t, per_step, first in (("400", 1, 1), ("400 + 0.05 * t", 2, 0)):
        thermal_wall = {"kind": "fixed", "temperature": wall_t}
        wall = [{"kind": "plane", "point": [-R + gap, 0, 0], "normal": [1, 0, 0],
                 "material": "glass", "thermal": thermal_wall}]  # fmt: skip
        sim = _sim(path, {"time_step": dt, "scheme": "backward_euler"}, walls=wall)
        eng = sim.thermal
        passes = [0]
        evaluate = eng.compute_rates

        def counted(time: float, evaluate=evaluate, passes=passes) -> np.ndarray:  # noqa: ANN001
            passes[0] += 1
            return evaluate(time)

        eng.compute_rates = counted
        t = np.full(n, 300.0)
        for step in range(1, steps + 1):
            sim.run(steps=1)
            b = np.zeros(n)
            b[0] = h_wall * (400.0 + (0.05 * step * dt if first == 0 else 0.0))
            t = np.linalg.solve(cap * np.eye(n) + k, cap * t + b)
            np.testing.assert_allclose(_by_gid(sim), t, rtol=1e-12)
        assert passes[0] == per_step * steps + first


def test_conjugate_gradients_error_bound_holds_against_the_direct_solve() -> None:
    """a = C' + L (L the Laplacian of a random graph with random conductances and a few
    links to fixed nodes, C' a random capacity term): stopped by Σ rᵢ²/C'ᵢ ≤ ε² ΣC', the
    capacity-weighted RMS error against the direct solve is ≤ ε (the bound
    eᵀC'e ≤ rᵀC'⁻¹r; a conservative one: measured 6e-5 to 0.04 ε), and the stop comes before
    the relative residual 1e-10."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from thermodem.engine.implicit_solve import conjugate_gradients

    rng = np.random.default_rng(7)
    n, pairs = 2000, 8000
    i, j = rng.integers(0, n, pairs), rng.integers(0, n, pairs)
    keep = i != j
    h = rng.uniform(0.1, 10.0, keep.sum())
    lap = sp.coo_matrix((np.r_[-h, -h], (np.r_[i[keep], j[keep]], np.r_[j[keep], i[keep]])),
                        shape=(n, n)).tocsr()  # fmt: skip
    lap -= sp.diags(np.asarray(lap.sum(axis=1)).ravel())
    to_fixed = np.where(rng.random(n) < 0.05, rng.uniform(0.1, 10.0, n), 0.0)
    for scale in (1e-3, 1.0):  # stiff (capacity ≪ conductances) and mild
        c = scale * rng.uniform(0.5, 2.0, n)
        a = (lap + sp.diags(c + to_fixed)).tocsr()
        r = rng.normal(size=n)
        exact = spla.spsolve(a.tocsc(), r)
        for eps in (1e-2, 1e-5):
            stop = 1e-10 * np.linalg.norm(r)
            x, count, ok = conjugate_gradients(a, r, 1.0 / a.diagonal(), stop, 5000, 1.0 / c,
                                               eps**2 * c.sum())  # fmt: skip
            assert ok
            error = np.sqrt(np.sum(c * (x - exact) ** 2) / c.sum())
            assert error <= eps
            _, full, _ = conjugate_gradients(a, r, 1.0 / a.diagonal(), stop, 5000)
            assert count < full


@pytest.mark.parametrize("scheme", ["backward_euler", "crank_nicolson", "tr_bdf2"])
def test_restart_over_a_hot_wall_is_bit_identical(tmp_path: Path, scheme: str) -> None:
    """A chain over a wall at 400 K (b ≠ 0: the wall's conductance) with conjugate gradients:
    the restarted run reuses b from its first pass, the uninterrupted one from its last
    pass at the same state, so the two agree bit for bit."""
    from thermodem.io.checkpoint import checkpoint_name, write_checkpoint

    n, gap = 9, 1e-5
    path = _write(tmp_path / "chain.txt", [(i * D, 0.0, 0.0, R, 300.0) for i in range(n)])
    wall = [{"kind": "plane", "point": [-R + gap, 0, 0], "normal": [1, 0, 0],
             "material": "glass", "thermal": {"kind": "fixed", "temperature": 400.0}}]  # fmt: skip
    thermal = {"time_step": 20.0, "scheme": scheme, "implicit": {"preconditioner": "jacobi"}}

    def sim() -> Simulation:
        s = _sim(path, thermal, walls=wall)
        s.thermal.implicit.direct_below = 0
        return s

    reference = sim()
    reference.run(steps=6)
    first = sim()
    first.run(steps=3)
    saved = write_checkpoint(first, tmp_path / checkpoint_name(first.step_count))
    second = Simulation.from_checkpoint(saved)
    second.thermal.implicit.direct_below = 0
    second.run(steps=3)
    assert np.array_equal(second.particles.temperature, reference.particles.temperature)
    assert second.thermal.cumulative == reference.thermal.cumulative
    assert reference.thermal.implicit.timings.cg_iterations > 0
