"""Cases of the multi-rank tests: the settled 500-sphere beds of tests/data (made by
tools/mpi_test_beds.py) with the mechanics, the contact conduction and the range set."""

from __future__ import annotations

from pathlib import Path
from typing import Any

DATA = Path(__file__).resolve().parents[1] / "data"
SIDE = 14e-3  # [m] floor of the bed
HEIGHT = 0.05  # [m] domain height


def bed_case(
    positions: str | None,
    *,
    periodic: bool = False,
    heat: str | None = "contact",
    time_step: float = 5e-6,
    restitution: float = 0.5,
    end_time: float = 1.0,
) -> dict[str, Any]:
    """The case dict: the bed in ``positions`` (None: 500 spheres inserted at random);
    ``heat``: None, "contact" (Batchelor & O'Brien simple, the fused contact pass) or
    "range" (Batchelor & O'Brien complete: its separated pairs on the range set and a hot
    wall); the bottom layer is held at 400 K."""
    material = {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": restitution,
        "sliding_friction": 0.5,
        "rolling_friction": 0.05,
        "thermal_conductivity": 1.0,
        "specific_heat": 800.0,
    }
    case: dict[str, Any] = {
        "simulation": {"time_step": time_step, "end_time": end_time, "seed": 3},
        "domain": {
            "lower": [0, 0, 0],
            "upper": [SIDE, SIDE, HEIGHT],
            "periodic": [periodic, periodic, False],
        },  # fmt: skip
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        "output": {"vtu": False},
    }
    if periodic:
        case["walls"] = [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1],
                          "material": "glass"}]  # fmt: skip
    else:
        case["walls"] = [{"kind": "box", "lower": [0, 0, 0], "upper": [SIDE, SIDE, HEIGHT],
                          "open_top": True, "material": "glass"}]  # fmt: skip
    if positions is None:
        case["insertion"] = [{"kind": "random_box", "material": "glass", "count": 500,
                              "distribution": {"kind": "mono", "radius": 1e-3},
                              "lower": [0, 0, 0], "upper": [SIDE, SIDE, 0.048]}]  # fmt: skip
    else:
        case["insertion"] = [{"kind": "file", "material": "glass", "path": str(positions)}]
    if heat is not None:
        thermal: dict[str, Any] = {
            "direct_conduction": "batchelor_obrien_simple",
            "initial_temperature": {"kind": "expression", "expression": "300 + 5000 * z"},
            "fixed_temperature": [{"temperature": 400.0, "select": {
                "region": {"lower": [0, 0, 0], "upper": [SIDE, SIDE, 1.5e-3]}}}],
        }  # fmt: skip
        if heat == "range":
            thermal["direct_conduction"] = "batchelor_obrien_complete"
            thermal["gas"] = {"thermal_conductivity": 0.026}
            case["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 420.0}
        case["thermal"] = thermal
    return case


COLUMN_SIDE = 6e-3  # [m] floor of the column
COLUMN_HEIGHT = 12e-3  # [m] 6 layers of 3 x 3 spheres, touching


def column_case(thermal: dict[str, Any] | None, *, steps: int = 140,
                time_step: float = 5e-6) -> dict[str, Any]:  # fmt: skip
    """54 spheres (3 x 3 x 6, R = 1 mm, touching) between a hot floor (400 K) and a cold lid
    (300 K) pressing down at 5 cm/s, side walls adiabatic; the thermal section ``thermal``
    on top of Batchelor & O'Brien simple and a linear initial temperature (None: no heat,
    no wall temperatures). c = 2 J/(kg K), so that the heat changes temperatures by tens of
    kelvin in a hundred steps. On 2 ranks the bisection cuts it across z (27 + 27)."""
    w, h = COLUMN_SIDE, COLUMN_HEIGHT
    material = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
                "restitution": 0.5, "sliding_friction": 0.5, "rolling_friction": 0.05,
                "thermal_conductivity": 50.0, "specific_heat": 2.0}  # fmt: skip
    hot = {"kind": "fixed", "temperature": 400.0}
    cold = {"kind": "fixed", "temperature": 300.0}
    walls = [
        {"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "glass",
         "thermal": hot},
        {"kind": "plane", "point": [0, 0, 0], "normal": [1, 0, 0], "material": "glass"},
        {"kind": "plane", "point": [w, 0, 0], "normal": [-1, 0, 0], "material": "glass"},
        {"kind": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "glass"},
        {"kind": "plane", "point": [0, w, 0], "normal": [0, -1, 0], "material": "glass"},
        {"kind": "plane", "point": [0, 0, h - 2e-5], "normal": [0, 0, -1], "material": "glass",
         "velocity": [0, 0, -0.05], "thermal": cold},
    ]  # fmt: skip
    case: dict[str, Any] = {
        "simulation": {"time_step": time_step, "end_time": steps * time_step, "seed": 3},
        "domain": {"lower": [0, 0, 0], "upper": [w, w, 2 * h]},
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        "walls": walls,
        "insertion": [{"kind": "lattice", "material": "glass",
                       "distribution": {"kind": "mono", "radius": 1e-3},
                       "lower": [0, 0, 0], "upper": [w, w, h], "count": [3, 3, 6]}],
        "output": {"vtu": False},
    }  # fmt: skip
    if thermal is None:
        for wall in walls:
            wall.pop("thermal", None)
        return case
    case["thermal"] = {
        "direct_conduction": "batchelor_obrien_simple",
        "initial_temperature": {"kind": "expression", "expression": "300 + 5000 * z"},
        **thermal,
    }
    return case
