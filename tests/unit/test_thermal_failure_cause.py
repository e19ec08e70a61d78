"""A temperature that leaves the physical range names its likely cause: the heat of a source
at a stable thermal step, the time step when it is beyond the explicit limit."""

from __future__ import annotations

import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import SimulationError


def _case(flux: float) -> dict:
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {
            "grain": {
                "density": 2500.0,
                "youngs_modulus": 1e7,
                "poisson_ratio": 0.3,
                "thermal_conductivity": 1.0,
                "specific_heat": 800.0,
            }
        },  # fmt: skip
        "insertion": [
            {
                "kind": "list",
                "material": "grain",
                "positions": [[0.005, 0.005, 0.005]],
                "radii": [1e-3],
            }
        ],  # fmt: skip
        "thermal": {
            "direct_conduction": "none",
            "heat_flux": [{"select": {"ids": [0]}, "flux": flux}],
        },
    }


def test_a_huge_negative_flux_is_named_not_the_time_step() -> None:
    sim = Simulation(case_from_dict(_case(-1.0e9)))
    with pytest.raises(SimulationError, match=r"likely cause: its heat rate -1\.2\d*e\+04 W"):
        sim.run(steps=50)
