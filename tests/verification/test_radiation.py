"""Per-particle terms: radiation with the surroundings (models/thermal/radiation.py).

Against the closed-form cooling time of a lumped sphere in a large enclosure, the explicit
stability limit with the linearised radiative conductance 4 ε σ A T³ at 1500 K, and the heat
ledger.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import SimulationError
from thermodem.models.thermal.radiation import STEFAN_BOLTZMANN
from thermodem.state import heat

R = 1e-3
RHO, C, EPS = 7800.0, 500.0, 0.8


def _case(t0: float, t_env: float, time_step: float, tmp_path) -> dict:  # noqa: ANN001
    path = tmp_path / "one.txt"
    path.write_text(f"x y z radius temperature\n0.005 0.005 0.005 {R} {t0}\n")
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1e3, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {
            "steel": {
                "density": RHO,
                "youngs_modulus": 1e8,
                "poisson_ratio": 0.3,
                "thermal_conductivity": 40.0,
                "specific_heat": C,
                "emissivity": EPS,
            }
        },
        "insertion": [{"kind": "file", "material": "steel", "path": str(path)}],
        "thermal": {
            "direct_conduction": "none",
            "radiation": {"model": "surroundings", "environment_temperature": t_env},
            "frozen_mechanics": True,
            "time_step": time_step,
        },
    }


def _rate_constant() -> float:
    """a of dT/dt = -a (T⁴ - T_e⁴): ε A σ / (m c)."""
    area = 4 * math.pi * R**2
    mass = RHO * 4 / 3 * math.pi * R**3
    return EPS * area * STEFAN_BOLTZMANN / (mass * C)


def _cooling_time(t0: float, t: float, t_env: float) -> float:
    """Time for T0 -> T: ∫ dT/(T⁴ - T_e⁴) = (ln((T - T_e)/(T + T_e)) - 2 atan(T/T_e))/(4 T_e³)."""

    def f(x: float) -> float:
        return (math.log((x - t_env) / (x + t_env)) - 2 * math.atan(x / t_env)) / (4 * t_env**3)

    return (f(t0) - f(t)) / _rate_constant()


def test_radiative_cooling_time_matches_the_closed_form(tmp_path) -> None:  # noqa: ANN001
    t0, t_env, target = 1500.0, 300.0, 800.0
    limit = 1.0 / (4 * _rate_constant() * t0**3)  # m c / (4 ε σ A T³)
    errors = []
    for fraction in (0.004, 0.002):
        dt = fraction * limit
        sim = Simulation(case_from_dict(_case(t0, t_env, dt, tmp_path)))
        temps = [t0]
        while temps[-1] > target:
            sim.step()
            temps.append(float(sim.particles.temperature[0]))
        # the crossing time, linear between the two steps around it
        k = len(temps) - 1
        crossing = (k - 1 + (temps[k - 1] - target) / (temps[k - 1] - temps[k])) * dt
        errors.append(abs(crossing / _cooling_time(t0, target, t_env) - 1.0))
        th = sim.thermal
        assert abs(th.balance_error()) <= 1e-12 * th.initial_energy
        assert th.cumulative["heat_in_radiation"] < 0.0
        assert sim.particles.heat_rate_by_mechanism[0, heat.M_RADIATION] < 0.0
    assert errors[1] < 1e-3
    assert 1.8 < errors[0] / errors[1] < 2.2  # explicit Euler: first order in the step


def test_explicit_limit_uses_the_linearised_radiative_conductance_at_1500_k(tmp_path) -> None:  # noqa: ANN001
    t0 = 1500.0
    limit = 1.0 / (4 * _rate_constant() * t0**3)
    sim = Simulation(case_from_dict(_case(t0, 300.0, 1.05 * limit, tmp_path)))
    assert sim.thermal.conductance_sum[0] == pytest.approx(
        4 * EPS * 4 * math.pi * R**2 * STEFAN_BOLTZMANN * t0**3, rel=1e-12
    )
    with pytest.raises(SimulationError, match="explicit Euler limit"):
        sim.step()
    ok = Simulation(case_from_dict(_case(t0, 300.0, 0.95 * limit, tmp_path)))
    temps = []
    for _ in range(50):
        ok.step()
        temps.append(float(ok.particles.temperature[0]))
    assert np.all(np.diff(temps) < 0.0) and temps[-1] > 300.0  # monotonic, no overshoot
