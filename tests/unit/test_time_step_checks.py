"""Time step criteria: Rayleigh (Li et al. 2005) and Hertz collision time (spec appendix A)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.checks import check_time_step, critical_times, rayleigh_time
from thermodem.errors import ConfigError


def _case(dt: float, allow: bool = False, speed: float = 1.0) -> dict:
    return {
        "simulation": {
            "time_step": dt,
            "end_time": 1.0,
            "gravity": [0, 0, 0],
            "time_step_check": {"impact_velocity": speed, "allow_unstable": allow},
        },
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {"glass": {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3}},
    }


def test_rayleigh_time_by_hand() -> None:
    # R = 1 mm glass: G = E / (2 (1 + nu)) = 3.846e6 Pa
    g = 1e7 / 2.6
    expected = math.pi * 1e-3 * math.sqrt(2500.0 / g) / (0.8766 + 0.163 * 0.3)
    assert rayleigh_time(1e-3, 2500.0, g, 0.3) == pytest.approx(expected, rel=1e-15)
    assert expected == pytest.approx(8.65e-5, rel=2e-3)


def test_collision_time_by_hand() -> None:
    case = case_from_dict(_case(1e-6))
    t = critical_times(case, np.array([1e-3]), np.array([0]), ["glass"])
    m = 2500.0 * 4.0 / 3.0 * math.pi * 1e-9
    e_star = 1e7 / (2.0 * (1.0 - 0.09))
    tc = 2.87 * ((m / 2) ** 2 / (0.5e-3 * e_star**2 * 1.0)) ** 0.2
    assert t["collision"] == pytest.approx(tc, rel=1e-12)


def test_small_step_passes_large_warns_too_large_refused() -> None:
    radius, types = np.array([1e-3]), np.array([0])
    assert check_time_step(case_from_dict(_case(1e-6)), radius, types, ["glass"]) == []
    # 3e-5 s: 0.35 of the Rayleigh time (warn above 0.3); at 0.01 m/s the collision lasts
    # ~5.1e-4 s, i.e. ~17 steps (warn below 30, refuse below 10)
    warnings = check_time_step(case_from_dict(_case(3e-5, speed=0.01)), radius, types, ["glass"])
    assert len(warnings) == 2
    assert any("Rayleigh" in w for w in warnings)
    assert any("collision" in w for w in warnings)
    with pytest.raises(ConfigError, match="at least 10 are required"):
        check_time_step(case_from_dict(_case(3e-5)), radius, types, ["glass"])
    with pytest.raises(ConfigError) as err:
        check_time_step(case_from_dict(_case(1e-4)), radius, types, ["glass"])
    assert "simulation.time_step = 0.0001 s is 1.16 × the Rayleigh time" in str(err.value)
    # explicit permission turns the refusal into a warning
    warnings = check_time_step(case_from_dict(_case(1e-4, allow=True)), radius, types, ["glass"])
    assert any("Rayleigh" in w for w in warnings)
