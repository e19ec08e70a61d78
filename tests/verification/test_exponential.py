"""The exponential scheme (engine/exponential.py) against the matrix exponential of the chain
written from the formula, its error control, the ledger and the refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from thermodem.config.load import case_from_dict
from thermodem.engine.exponential import phi_integrals
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError

R = 1e-3
RHO = 2500.0
K = 1.0
C = 800.0
MASS = RHO * 4.0 / 3.0 * math.pi * R**3
D = 1.95e-3  # centre distance of touching neighbours
H = 2.0 * K * math.sqrt(R**2 - (D / 2) ** 2)  # BOB simple with the geometric radius
MATERIAL = {"density": RHO, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
            "thermal_conductivity": K, "specific_heat": C, "restitution": 0.5}  # fmt: skip


def _chain(tmp_path: Path, n: int) -> str:
    rows = ["x y z radius temperature"]
    rows += [f"{k * D!r} 0.0 0.0 {R!r} 300.0" for k in range(n)]
    path = tmp_path / f"chain{n}.txt"
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _sim(particles: str, thermal: dict, walls: list | None = None, materials=None) -> Simulation:
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.01, -0.02, -0.02], "upper": [0.5, 0.02, 0.02]},
        "materials": materials or {"glass": dict(MATERIAL)},
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "walls": walls or [],
        "thermal": {"frozen_mechanics": True, "scheme": "exponential", **thermal},
    }
    return Simulation(case_from_dict(case))


def _by_gid(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[np.argsort(sim.particles.global_id)]


def _chain_exact(n: int, times: np.ndarray) -> np.ndarray:
    """Particle 0 held at 400 K, the others from 300 K: T(t) = 400 + e^{-Mt}(T₀ - 400) with
    M = K/(m c), K the tridiagonal Laplacian of the equal bonds H (written here)."""
    m = n - 1  # free particles 1..n-1
    k = np.zeros((m, m))
    for a in range(m):
        k[a, a] = 2.0 * H if a < m - 1 else H
        if a + 1 < m:
            k[a, a + 1] = k[a + 1, a] = -H
    out = []
    for t in times:
        out.append(400.0 + expm(-k * t / (MASS * C)) @ np.full(m, -100.0))
    return np.array(out)


def test_phi_integrals_are_exact_across_the_series_switch() -> None:
    lam = np.array([0.0, 1e-9, 1e-5, 9.99e-4, 1.001e-3, 0.3, 7.0])
    tau = 1.0
    f1, f2 = phi_integrals(lam, tau)
    for value, one, two in zip(lam, f1, f2, strict=True):
        # ∫₀^τ e^{-λs} ds and ∫₀^τ ∫₀^s e^{-λu} du ds, by mpmath-free closed forms
        if value == 0.0:
            assert one == tau and two == tau**2 / 2
            continue
        x = value * tau
        assert one == pytest.approx(-math.expm1(-x) / value, rel=1e-13)
        # φ₂(-x) = Σ_j (-x)^j/(j + 2)! (30 terms, |x| < 1), the closed form above
        if x < 1.0:
            exact2 = tau**2 * sum((-x) ** j / math.factorial(j + 2) for j in range(30))
        else:
            exact2 = (x + math.expm1(-x)) / value**2
        assert two == pytest.approx(exact2, rel=1e-13)


def test_two_spheres_are_exact_at_any_step(tmp_path: Path) -> None:
    """ΔT = 100 exp(-2Ht/(mc)) whatever the step: no time-discretisation error."""
    rows = ["x y z radius temperature", f"0.0 0.0 0.0 {R!r} 300.0", f"{D!r} 0.0 0.0 {R!r} 400.0"]
    path = tmp_path / "two.txt"
    path.write_text("\n".join(rows) + "\n")
    for dt in (0.5, 8.0):
        sim = _sim(str(path), {"time_step": dt})
        sim.run(until=8.0)
        t = _by_gid(sim)
        assert t[1] - t[0] == pytest.approx(100.0 * math.exp(-8.0 * 2.0 * H / (MASS * C)),
                                            rel=1e-12)  # fmt: skip
        assert t.sum() == pytest.approx(700.0, rel=1e-14)


def test_error_control_bounds_the_error_of_a_long_chain(tmp_path: Path) -> None:
    """121 spheres, the first held at 400 K, 1000 s in steps of 100 s (λ_max t ≈ 210, the
    Krylov space is far from exact): the RMS error of the free particles against the
    matrix exponential stays below krylov_tolerance at every step (measured: 0.04-0.11 of
    it), and a looser tolerance uses fewer Lanczos vectors (40 ... 70)."""
    n = 121
    times = np.arange(100.0, 1000.1, 100.0)
    exact = _chain_exact(n, times)
    fixed = [{"select": {"ids": [0]}, "temperature": 400.0}]
    counts, errors = [], []
    for tolerance in (1e-2, 1e-4, 1e-6, 1e-8):
        sim = _sim(_chain(tmp_path, n), {"time_step": 100.0, "fixed_temperature": fixed,
                                         "implicit": {"krylov_tolerance": tolerance}})  # fmt: skip
        worst = 0.0
        for row in exact:
            sim.run(steps=1)
            t = _by_gid(sim)[1:]
            worst = max(worst, float(np.sqrt(np.mean((t - row) ** 2))))
        assert worst <= tolerance
        vectors = sim.thermal.implicit.exponential.vectors
        assert 10 <= vectors < n - 1  # a real approximation, not the invariant subspace
        counts.append(vectors)
        errors.append(worst)
    assert counts == sorted(counts) and counts[0] < counts[-1]
    assert errors[0] > 1e-6  # the loose tolerance is used, not met by accident


def test_small_dimension_restarts_and_divides_steps_within_tolerance(tmp_path: Path) -> None:
    """krylov_dimension 10: one 1000 s step cannot be reached from one basis; the step is
    divided and new bases start, the error stays at the tolerance's order."""
    n = 121
    fixed = [{"select": {"ids": [0]}, "temperature": 400.0}]
    sim = _sim(_chain(tmp_path, n), {"time_step": 1000.0, "fixed_temperature": fixed,
                                     "implicit": {"krylov_tolerance": 1e-6,
                                                  "krylov_dimension": 10}})  # fmt: skip
    sim.run(steps=1)
    exact = _chain_exact(n, np.array([1000.0]))[0]
    err = float(np.sqrt(np.mean((_by_gid(sim)[1:] - exact) ** 2)))
    assert err < 1e-5
    assert sim.thermal.implicit.timings.cg_iterations > 10  # more than one basis


def test_ledger_closes_with_a_wall_a_source_and_a_fixed_particle(tmp_path: Path) -> None:
    wall = [{"kind": "plane", "point": [-R + 1e-5, 0, 0], "normal": [1, 0, 0],
             "material": "glass", "thermal": {"kind": "fixed", "temperature": 500.0}}]  # fmt: skip
    thermal = {
        "time_step": 50.0,
        "fixed_temperature": [{"select": {"ids": [20]}, "temperature": 310.0}],
        "heat_flux": [{"select": {"ids": [40]}, "flux": 500.0}],
        "implicit": {"krylov_tolerance": 1e-10},
    }
    sim = _sim(_chain(tmp_path, 41), thermal, walls=wall)
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=20)
    th = sim.thermal
    assert th.cumulative["heat_in_wall_direct_conduction"] > 1e-3 * u0
    # q 4πR² over 1000 s
    assert th.cumulative["heat_in_source"] == pytest.approx(500.0 * 4 * math.pi * R**2 * 1000.0,
                                                            rel=1e-12)  # fmt: skip
    assert abs(th.cumulative["fixed_absorbed"]) > 1e-4 * u0
    assert abs(th.balance_error()) < 1e-11 * u0


def test_a_wall_temperature_that_changes_starts_a_new_basis(tmp_path: Path) -> None:
    """A wall at 400 K raised to 450 K at t = 300 s under the first sphere of a chain: the
    steps after the change start from the state at the change (the data of the end of a
    step are held over it) and equal the matrix exponential with the new wall. The wall
    conductance is Batchelor & O'Brien's 4 k̄ R_c with k̄ = k/2 and the geometric radius of
    the sphere–plane intersection (written here)."""
    n = 21
    gap = 1e-5
    h_wall = 2.0 * K * math.sqrt(R**2 - (R - gap) ** 2)
    wall = [{"kind": "plane", "point": [-R + gap, 0, 0], "normal": [1, 0, 0],
             "material": "glass",
             "thermal": {"kind": "fixed", "temperature": "400 + 50 * (t > 300)"}}]  # fmt: skip
    thermal = {"time_step": 100.0, "implicit": {"krylov_tolerance": 1e-10}}
    sim = _sim(_chain(tmp_path, n), thermal, walls=wall)
    k = np.diag(np.r_[H + h_wall, np.full(n - 2, 2.0 * H), H])
    k -= H * (np.eye(n, k=1) + np.eye(n, k=-1))

    def exact(start: np.ndarray, wall_t: float, t: float) -> np.ndarray:
        return wall_t + expm(-k * t / (MASS * C)) @ (start - wall_t)

    sim.run(steps=3)
    before = _by_gid(sim).copy()
    assert before == pytest.approx(exact(np.full(n, 300.0), 400.0, 300.0), abs=1e-8)
    sim.run(steps=2)
    assert _by_gid(sim) == pytest.approx(exact(before, 450.0, 200.0), abs=1e-8)
    assert sim.thermal.implicit.exponential.origin_time == 300.0


def test_exponential_refuses_temperature_dependent_properties(tmp_path: Path) -> None:
    glass = {k: v for k, v in MATERIAL.items() if k != "thermal_conductivity"}
    mats = {"glass": dict(glass, thermal_conductivity_table=[[300.0, 1.0], [400.0, 3.0]])}
    with pytest.raises(ConfigError, match="thermal.scheme = 'exponential'.*table"):
        _sim(_chain(tmp_path, 3), {"time_step": 1.0}, materials=mats)
