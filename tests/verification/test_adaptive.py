"""Adaptive TR-BDF2 (engine/adaptive.py): its stability function, order, error control against
the matrix exponential, the ledger and temperature-dependent properties."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from thermodem.config.load import case_from_dict
from thermodem.engine.adaptive import GAMMA
from thermodem.engine.simulation import Simulation

R = 1e-3
RHO = 2500.0
K = 1.0
C = 800.0
MASS = RHO * 4.0 / 3.0 * math.pi * R**3
D = 1.95e-3
H = 2.0 * K * math.sqrt(R**2 - (D / 2) ** 2)  # BOB simple with the geometric radius
MATERIAL = {"density": RHO, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
            "thermal_conductivity": K, "specific_heat": C, "restitution": 0.5}  # fmt: skip
FIXED_STEP = {"error_tolerance": 1e9}  # never rejects: every internal step is the engine's


def _write(path: Path, temperatures: list[float]) -> str:
    rows = ["x y z radius temperature"]
    rows += [f"{k * D!r} 0.0 0.0 {R!r} {t!r}" for k, t in enumerate(temperatures)]
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _sim(particles: str, thermal: dict, walls: list | None = None, materials=None) -> Simulation:
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.01, -0.02, -0.02], "upper": [0.5, 0.02, 0.02]},
        "materials": materials or {"glass": dict(MATERIAL)},
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "walls": walls or [],
        "thermal": {"frozen_mechanics": True, "scheme": "tr_bdf2", **thermal},
    }
    return Simulation(case_from_dict(case))


def _by_gid(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[np.argsort(sim.particles.global_id)]


def _growth(z: float) -> float:
    """TR-BDF2's stability function, from its two stages written here: the trapezoid over γh,
    then BDF2 over (t_n, t_n + γh, t_n + h)."""
    d = GAMMA / 2.0
    a = 1.0 / (GAMMA * (2.0 - GAMMA))
    b = (1.0 - GAMMA) ** 2 / (GAMMA * (2.0 - GAMMA))
    stage = (1.0 + d * z) / (1.0 - d * z)
    return (a * stage - b) / (1.0 - d * z)


def test_two_spheres_follow_the_stability_function_at_second_order(tmp_path: Path) -> None:
    """Fixed internal steps (a tolerance that never rejects, the engine's step as the
    internal one): ΔT^n = 100 R(z)^n, z = -2HΔt/(mc), to 1e-9; the error against
    exp(-t/τ) falls at order 2; with Δt = 20 τ one step damps ΔT by |R(-20)| = 0.155
    (L-stable: R → 0 like 1/z) where Crank–Nicolson keeps |(1 - x)/(1 + x)| = 0.82."""
    path = _write(tmp_path / "two.txt", [300.0, 400.0])
    tau = MASS * C / (2.0 * H)
    errors = []
    for dt in (0.4, 0.2, 0.1):
        sim = _sim(path, {"time_step": dt, "implicit": {**FIXED_STEP, "initial_step": dt}})
        steps = int(round(8.0 / dt))
        sim.run(steps=steps)
        t = _by_gid(sim)
        assert sim.thermal.implicit.adaptive.accepted == steps
        assert t[1] - t[0] == pytest.approx(100.0 * _growth(-dt / tau) ** steps, rel=1e-9)
        assert t.sum() == pytest.approx(700.0, rel=1e-13)
        errors.append(abs(t[1] - t[0] - 100.0 * math.exp(-8.0 / tau)))
    order = math.log2(errors[0] / errors[1]), math.log2(errors[1] / errors[2])
    assert order == pytest.approx((2.0, 2.0), abs=0.1)
    stiff = _sim(path, {"time_step": 20.0 * tau,
                        "implicit": {**FIXED_STEP, "initial_step": 20.0 * tau}})  # fmt: skip
    stiff.run(steps=1)
    ratio = np.diff(_by_gid(stiff))[0] / 100.0
    assert ratio == pytest.approx(_growth(-20.0), rel=1e-9)
    assert abs(ratio) < 0.16


def _chain_exact(n: int, times: np.ndarray) -> np.ndarray:
    """Particle 0 at 400 K, the others from 300 K: 400 + e^{-Kt/(mc)} (T₀ - 400), K the
    Laplacian of the chain's equal bonds (written here)."""
    m = n - 1
    k = np.diag(np.r_[np.full(m - 1, 2.0 * H), H]) - H * (np.eye(m, k=1) + np.eye(m, k=-1))
    return np.array([400.0 + expm(-k * t / (MASS * C)) @ np.full(m, -100.0) for t in times])


def test_error_control_on_a_chain(tmp_path: Path) -> None:
    """61 spheres, the first held at 400 K, output every 50 s up to 1000 s: the RMS error of
    the free particles against the matrix exponential shrinks with error_tolerance, at more
    internal steps. The tolerance bounds the local error of a step; the global error is the
    sum of ~N of them, N ∝ tol^(-1/3), so it goes as tol^(2/3): measured 0.81, 2.0, 4.9
    (and 11 at 1e-5) × tol at tol = 1e-2, 1e-3, 1e-4, with 35, 57, 110 internal steps."""
    n = 61
    times = np.arange(50.0, 1000.1, 50.0)
    exact = _chain_exact(n, times)
    path = _write(tmp_path / "chain.txt", [300.0] * n)
    fixed = [{"select": {"ids": [0]}, "temperature": 400.0}]
    steps, worst_errors = [], []
    for tol in (1e-2, 1e-3, 1e-4):
        sim = _sim(path, {"time_step": 50.0, "fixed_temperature": fixed,
                          "implicit": {"error_tolerance": tol}})  # fmt: skip
        worst = 0.0
        for row in exact:
            sim.run(steps=1)
            worst = max(worst, float(np.sqrt(np.mean((_by_gid(sim)[1:] - row) ** 2))))
        assert worst <= 1.5 * tol * (1e-2 / tol) ** (1.0 / 3.0)  # 1.5e-2, 3.2e-3, 7.0e-4
        worst_errors.append(worst)
        steps.append(sim.thermal.implicit.adaptive.accepted)
    assert worst_errors[0] > worst_errors[1] > worst_errors[2]
    assert steps[0] < steps[1] < steps[2]


def test_iterative_solves_stop_at_their_error_bound(tmp_path: Path) -> None:
    """The chain of test_error_control_on_a_chain at tol = 1e-3 with conjugate gradients
    (Jacobi) instead of the direct solve: the solves stop when their error is bounded by
    1 % of tol, so the run stays within its error bound against the matrix exponential and
    within a small fraction of tol of the direct run, at fewer iterations than the relative
    residual 1e-10 needs."""
    n, tol = 61, 1e-3
    times = np.arange(50.0, 1000.1, 50.0)
    exact = _chain_exact(n, times)
    path = _write(tmp_path / "chain.txt", [300.0] * n)
    fixed = [{"select": {"ids": [0]}, "temperature": 400.0}]
    thermal = {"time_step": 50.0, "fixed_temperature": fixed,
               "implicit": {"error_tolerance": tol, "preconditioner": "jacobi"}}  # fmt: skip
    direct, iterative = _sim(path, thermal), _sim(path, thermal)
    iterative.thermal.implicit.direct_below = 0
    u0 = iterative.thermal.thermal_energy()
    worst = np.zeros(3)  # iterative and direct against the exact, iterative against direct
    for row in exact:
        direct.run(steps=1)
        iterative.run(steps=1)
        t, t_direct = _by_gid(iterative), _by_gid(direct)
        errors = [t[1:] - row, t_direct[1:] - row, t - t_direct]
        worst = np.maximum(worst, [np.sqrt(np.mean(e**2)) for e in errors])
    # measured: 1.983e-3, 1.979e-3 and 4.5e-5 K (the solves' errors, each ≤ 1e-5 K, over
    # 57 steps of two stages)
    assert worst[2] <= 0.1 * tol
    assert worst[0] <= worst[1] + 0.1 * tol <= 3.2e-3  # the direct run's bound
    timings = iterative.thermal.implicit.timings
    assert 0 < timings.cg_iterations < 5 * timings.solves  # (~19 per solve to 1e-10)
    assert abs(iterative.thermal.balance_error()) < 1e-11 * u0


@pytest.mark.parametrize("direct_below", [200, 0])
def test_ledger_closes_with_a_wall_a_source_and_a_fixed_particle(
    tmp_path: Path, direct_below: int
) -> None:
    """Over internal steps that do not coincide with the engine's, with the direct solve and
    with conjugate gradients stopped at their error bound (the conservative correction)."""
    wall = [{"kind": "plane", "point": [-R + 1e-5, 0, 0], "normal": [1, 0, 0],
             "material": "glass", "thermal": {"kind": "fixed", "temperature": 500.0}}]  # fmt: skip
    thermal = {
        "time_step": 20.0,
        "fixed_temperature": [{"select": {"ids": [10]}, "temperature": 310.0}],
        "heat_flux": [{"select": {"ids": [20]}, "flux": 500.0}],
        "implicit": {"error_tolerance": 1e-3},
    }
    sim = _sim(_write(tmp_path / "c.txt", [300.0] * 21), thermal, walls=wall)
    sim.thermal.implicit.direct_below = direct_below
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=10)
    th = sim.thermal
    assert th.implicit.adaptive.accepted > 10  # more internal steps than engine steps
    assert th.cumulative["heat_in_wall_direct_conduction"] > 1e-3 * u0
    assert abs(th.cumulative["fixed_absorbed"]) > 1e-4 * u0
    assert abs(th.balance_error()) < 1e-11 * u0


@pytest.mark.parametrize("direct_below", [200, 0])
def test_temperature_dependent_properties_conserve_enthalpy(
    tmp_path: Path, direct_below: int
) -> None:
    """k(T) and c(T) tables: Picard in each stage; the pair exchange conserves Σ m h(T), with
    the direct solve and with conjugate gradients stopped at their error bound."""
    constants = ("thermal_conductivity", "specific_heat")  # (a table replaces its constant)
    glass = {k: v for k, v in MATERIAL.items() if k not in constants}
    mats = {"glass": dict(glass, thermal_conductivity_table=[[300.0, 1.0], [400.0, 3.0]],
                          specific_heat_table=[[300.0, 700.0], [400.0, 1100.0]])}  # fmt: skip
    thermal = {"time_step": 2.0, "implicit": {"error_tolerance": 1e-3}}
    chain = [300.0, 400.0] * 6  # (12 unknowns: the CG takes several iterations)
    sim = _sim(_write(tmp_path / "chain.txt", chain), thermal, materials=mats)
    sim.thermal.implicit.direct_below = direct_below
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=5)
    t = _by_gid(sim)
    assert 0.0 < t[1] - t[0] < 100.0
    assert sim.thermal.thermal_energy() == pytest.approx(u0, rel=1e-12)
    adaptive = sim.thermal.implicit.adaptive
    stages = 2 * (adaptive.accepted + adaptive.rejected)
    assert sim.thermal.implicit.timings.picard_iterations > stages  # more than one per stage


def _radiating_sphere_temperature(t: float, t0: float, t_env: float, a: float) -> float:
    """dT/dt = a (T_e⁴ - T⁴): t(T) = [ln((T_e + T)/(T_e - T)) + 2 atan(T/T_e)]/(4 a T_e³)
    from T₀ (closed form), inverted by bisection."""
    from scipy.optimize import brentq

    def elapsed(temp: float) -> float:
        return (math.log((t_env + temp) / (t_env - temp)) + 2.0 * math.atan(temp / t_env)) / (
            4.0 * a * t_env**3
        )

    return brentq(lambda temp: elapsed(temp) - elapsed(t0) - t, t0, t_env * (1 - 1e-15),
                  xtol=1e-13, rtol=1e-15)  # fmt: skip


ORDERS = [("backward_euler", 1.0), ("crank_nicolson", 2.0), ("tr_bdf2", 2.0)]


@pytest.mark.parametrize(("scheme", "order"), ORDERS)
def test_t4_radiation_converges_at_the_schemes_order(
    tmp_path: Path, scheme: str, order: float
) -> None:
    """One sphere radiating with surroundings at 1000 K from 300 K (T⁴: the Picard iteration
    on the linearised term, Newton's method since G = dQ/dT): the temperature at 4 s against
    the closed form of dT/dt = εσA(T_e⁴ - T⁴)/(mc) converges at the scheme's order (TR-BDF2
    at fixed internal steps), and the ledger's heat_in_radiation is the energy gained."""
    mats = {"glass": dict(MATERIAL, emissivity=0.9)}
    path = _write(tmp_path / "one.txt", [300.0])
    a = 0.9 * 5.670374419e-8 * 4.0 * math.pi * R**2 / (MASS * C)
    exact = _radiating_sphere_temperature(4.0, 300.0, 1000.0, a)
    errors = []
    for dt in (0.4, 0.2, 0.1):
        implicit = {**FIXED_STEP, "initial_step": dt} if scheme == "tr_bdf2" else {}
        radiation = {"model": "surroundings", "environment_temperature": 1000.0}
        thermal = {"time_step": dt, "scheme": scheme, "implicit": implicit, "radiation": radiation}
        sim = _sim(path, thermal, materials=mats)
        u0 = sim.thermal.thermal_energy()
        sim.run(until=4.0)
        errors.append(abs(float(sim.particles.temperature[0]) - exact))
        gained = sim.thermal.thermal_energy() - u0
        assert sim.thermal.cumulative["heat_in_radiation"] == pytest.approx(gained, rel=1e-9)
        assert sim.thermal.implicit.timings.picard_iterations > sim.step_count
    assert 450.0 < exact < 900.0  # a real non-linear transient
    observed = math.log2(errors[0] / errors[1]), math.log2(errors[1] / errors[2])
    assert observed == pytest.approx((order, order), abs=0.1)
