"""Shared set-up of the Beaulieu (2020) heated steel bed (see README.md)."""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent
DIAMETER = 6.4e-3  # m
RADIUS = DIAMETER / 2.0
FOOTPRINT = (0.105, 0.1)  # m, x and y (Lethe's box: x from -0.005 to 0.1, y from 0 to 0.1)
DEPTHS = (0.040, 0.060, 0.073)  # m below the heated wall
T_COLD = 293.15  # K (20 °C)
T_HOT = 326.15  # K (53 °C)
DURATION = 4000.0  # s

STEEL = {
    "density": 7747.0, "youngs_modulus": 50e6, "poisson_ratio": 0.29, "restitution": 0.8,
    "sliding_friction": 0.7, "rolling_friction": 0.02, "youngs_modulus_real": 200e9,
    "thermal_conductivity": 42.0, "specific_heat": 464.0, "microhardness": 3e9,
    "surface_slope": 0.056, "surface_roughness": 19e-9, "thermal_accommodation": 0.7,
}  # fmt: skip
WALL = {
    "density": 2700.0, "youngs_modulus": 50e6, "poisson_ratio": 0.33, "restitution": 0.8,
    "sliding_friction": 0.7, "rolling_friction": 0.02, "youngs_modulus_real": 100e9,
    "thermal_conductivity": 250.0, "microhardness": 1.8e9, "surface_slope": 0.056,
    "surface_roughness": 0.1e-9, "thermal_accommodation": 0.7,
}  # fmt: skip
GAS = {"thermal_conductivity": 0.027, "specific_heat": 1006.0, "dynamic_viscosity": 1.85e-5,
       "heat_capacity_ratio": 1.0, "mean_free_path": 68e-9}  # fmt: skip
