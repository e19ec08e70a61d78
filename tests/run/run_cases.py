"""The small case the input tests of tests/run start from (a 2 × 2 × 2 lattice of glass
spheres on a floor, 100 steps): test_input_mistakes.py, test_input_at_build.py and
test_ignored_settings.py change a section or two of a copy."""

from __future__ import annotations

import copy
from typing import Any

BASE_CASE: dict[str, Any] = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.001},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {
        "glass": {
            "density": 2500,
            "youngs_modulus": 1.0e7,
            "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0,
            "specific_heat": 800,
        }
    },
    "walls": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "glass"}],
    "insertion": [
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.001},
            "lower": [0, 0, 0],
            "upper": [0.006, 0.006, 0.006],
            "count": [2, 2, 2],
        }
    ],
}


def base_case(**sections: Any) -> dict[str, Any]:
    """A deep copy of BASE_CASE with ``sections`` replaced."""
    return {**copy.deepcopy(BASE_CASE), **copy.deepcopy(sections)}
