"""Input other codes use for the resistance network: γ = 1 for the gas, and the pair's
equivalent roughness and slope given per interaction (Lethe's resistance test gives both)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.models import registry
from thermodem.models.tables import pair_table
from thermodem.models.thermal import resistance_network as rn
from thermodem.state.gas import GasProperties
from thermodem.state.materials import InteractionOverride, Material, resolve_pair

#: Lethe's tests/dem/particle_particle_thermal_resistances.cc: the gas and the pair surface
LETHE_GAS = {"thermal_conductivity": 0.027, "dynamic_viscosity": 1.85e-5, "specific_heat": 1006.0,
             "heat_capacity_ratio": 1.0, "mean_free_path": 68e-9}  # fmt: skip
SIGMA, TAU, ALPHA = 25e-9, 0.078, 0.7
GLASS = {"density": 2521.0, "youngs_modulus": 5e6, "poisson_ratio": 0.22,
         "thermal_conductivity": 1.0, "specific_heat": 840.0, "microhardness": 9e9,
         "thermal_accommodation": ALPHA}  # fmt: skip


def test_gamma_one_is_accepted_and_gives_the_factor_one():
    """M = (2 (2 - α)/α) (2γ/(1 + γ)) Λ/Pr; γ = 1 makes the middle factor exactly 1."""
    gas = GasProperties(**LETHE_GAS)
    pr = 1.85e-5 * 1006.0 / 0.027  # by hand
    expected = 2.0 * (2.0 - ALPHA) / ALPHA * 1.0 * 68e-9 / pr
    assert rn.gas_parameter(ALPHA, ALPHA, gas) == pytest.approx(expected, rel=1e-15)
    assert math.isfinite(expected) and expected > 0
    with pytest.raises(ValueError, match="greater than or equal to 1"):
        GasProperties(**{**LETHE_GAS, "heat_capacity_ratio": 0.999})


def _two_spheres(interactions: list[dict], glass: dict | None = None) -> dict:
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": {"glass": dict(glass or GLASS)},
        "interactions": interactions,
        "insertion": [
            {
                "kind": "list",
                "material": "glass",
                "positions": [[0.0, 0.0, 0.0], [0.0099, 0.0, 0.0]],
                "radius": 0.005,
                "temperatures": [300.0, 100.0],
            }
        ],
        "thermal": {
            "direct_conduction": "resistance_network",
            "gas": LETHE_GAS,
            "frozen_mechanics": True,
            "time_step": 1e-3,
        },
    }


PAIR = {"materials": ["glass", "glass"], "surface_roughness": SIGMA, "surface_slope": TAU}


def test_pair_roughness_and_slope_from_an_interaction_reach_the_network():
    """Materials without σ and τ: the interactions entry's equivalent values are the row's σ, τ
    (not √2 × them, which the material rule would give), and a thermal step conducts."""
    case = case_from_dict(_two_spheres([PAIR]))
    row = pair_table(case.thermal.direct_conduction, case, list(case.materials))[0, 0]
    assert (row[7], row[8]) == (SIGMA, TAU)
    pr = 1.85e-5 * 1006.0 / 0.027
    assert row[10] == pytest.approx(2.0 * (2.0 - ALPHA) / ALPHA * 68e-9 / pr, rel=1e-15)
    sim = Simulation(case)
    sim.run(steps=1)
    q = sim.particles.heat_rate
    assert np.all(np.isfinite(q)) and q.max() > 0 and q.sum() == pytest.approx(0.0, abs=1e-12)


def test_the_interaction_wins_over_the_materials_and_the_rule_stays_otherwise():
    spec = registry.get("direct_conduction", "resistance_network")
    mat = Material(**GLASS, surface_roughness=1e-6, surface_slope=0.05)
    gas = GasProperties(**LETHE_GAS)
    rule = spec.pack(spec.params(), resolve_pair(mat, mat, gas=gas))
    assert rule[7] == pytest.approx(math.sqrt(2) * 1e-6) and rule[8] == pytest.approx(
        math.sqrt(2) * 0.05
    )
    override = InteractionOverride(**PAIR)
    given = spec.pack(spec.params(), resolve_pair(mat, mat, override, gas=gas))
    assert (given[7], given[8]) == (SIGMA, TAU)
    only_sigma = InteractionOverride(materials=("glass", "glass"), surface_roughness=SIGMA)
    mixed = spec.pack(spec.params(), resolve_pair(mat, mat, only_sigma, gas=gas))
    assert mixed[7] == SIGMA and mixed[8] == pytest.approx(math.sqrt(2) * 0.05)


def test_without_either_the_case_names_the_missing_material_property():
    with pytest.raises(ConfigError, match=r"materials.glass.surface_roughness: missing"):
        Simulation(case_from_dict(_two_spheres([])))
    half = {"materials": ["glass", "glass"], "surface_roughness": SIGMA}
    with pytest.raises(ConfigError, match=r"materials.glass.surface_slope: missing"):
        Simulation(case_from_dict(_two_spheres([half])))
    bad = dict(PAIR, surface_slope=-0.1)
    with pytest.raises(ConfigError, match=r"interactions.0.surface_slope: Input should be greater"):
        case_from_dict(_two_spheres([bad]))
