"""The heat_generation family: partition coefficients against the spec's formulas, the rows
the models pack, a docs page per model, bad input named by key.

Partition formulas (spec 5, "Partition coefficient"; ψ_i the share of body i):
Váradi et al. (1996) k_i/(k_i + k_j); Vernotte (1956), Rojek (2014) e_i/(e_i + e_j),
e = sqrt(ρ c k); Mokrani & Bourouga (2005) ½ (k_i/(k_i + k_j) + ρ̂_i/(ρ̂_i + ρ̂_j)); same material:
½. Computed here by hand from the materials' values.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.validation import check_completeness
from thermodem.errors import ConfigError
from thermodem.models import registry
from thermodem.models.thermal import heat_generation as HG
from thermodem.state.heat import GENERATION
from thermodem.state.materials import Material, resolve_pair

DOCS = Path(__file__).resolve().parents[2] / "docs" / "models"
SPECS = [registry.get("heat_generation", n) for n in registry.names("heat_generation")]


def mat(k: float, rho: float, c: float, resistivity: float | None = None) -> Material:
    return Material(density=rho, youngs_modulus=1e7, poisson_ratio=0.3, thermal_conductivity=k,
                    specific_heat=c, electrical_resistivity=resistivity)  # fmt: skip


STEEL = mat(45.0, 7800.0, 470.0, 1.7e-7)
GLASS = mat(1.1, 2500.0, 800.0, 1.0e10)
COPPER = mat(400.0, 8900.0, 385.0, 1.7e-8)


def hand(partition: str, a: Material, b: Material) -> float:
    if partition == "equal":
        return 0.5
    kk = a.thermal_conductivity / (a.thermal_conductivity + b.thermal_conductivity)
    if partition == "conductivity":
        return kk
    if partition == "effusivity":
        ea = math.sqrt(a.density * a.specific_heat * a.thermal_conductivity)
        eb = math.sqrt(b.density * b.specific_heat * b.thermal_conductivity)
        return ea / (ea + eb)
    ra, rb = a.electrical_resistivity, b.electrical_resistivity
    return 0.5 * (kk + ra / (ra + rb))


@pytest.mark.parametrize("partition", HG.PARTITIONS)
@pytest.mark.parametrize("pair", [(STEEL, GLASS), (GLASS, COPPER), (COPPER, STEEL)])
def test_partition_coefficients_against_their_formulas(partition, pair):
    a, b = pair
    psi_ab = HG.pair_partition(partition, resolve_pair(a, b))
    psi_ba = HG.pair_partition(partition, resolve_pair(b, a))
    assert psi_ab == pytest.approx(hand(partition, a, b), rel=1e-14)
    assert psi_ab + psi_ba == pytest.approx(1.0, rel=1e-15)  # all the heat, once
    assert HG.pair_partition(partition, resolve_pair(a, a)) == 0.5  # same material: half


def test_effusivity_partition_of_the_spec_materials_by_number():
    """Steel on glass: e = sqrt(ρ c k) = 12,844 and 1,483 W s^½/(m² K): ψ_steel = 0.89647."""
    psi = HG.pair_partition("effusivity", resolve_pair(STEEL, GLASS))
    assert psi == pytest.approx(0.89647, abs=1e-5)


def row_of(name: str, **params) -> np.ndarray:
    spec = registry.get("heat_generation", name)
    return spec.pack(spec.params(**params), resolve_pair(STEEL, GLASS))


def selected(row: np.ndarray) -> set[str]:
    return {g for k, g in enumerate(GENERATION) if row[HG.C_SELECT + k] != 0.0}


def test_model_rows():
    psi = HG.pair_partition("conductivity", resolve_pair(STEEL, GLASS))
    row = row_of("mechanical_dissipation", partition="conductivity", partition_scope="friction",
                 conversion_fraction=0.9)  # fmt: skip
    assert selected(row) == set(HG.FORCE_MECHANISMS)
    assert row[HG.C_CHI] == 0.9
    assert row[HG.C_PSI_FRICTION] == psi and row[HG.C_PSI_OTHER] == 0.5
    # the kernel: i's share per mechanism, 0 when not selected
    for g, name in enumerate(GENERATION):
        share = HG.partition_share(row, g)
        expected = 0.0 if name == "collision" else (psi if name.endswith("friction") else 0.5)
        assert share == expected, name
    rojek = row_of("rojek2014")
    assert selected(rojek) == {"sliding_friction"} and rojek[HG.C_CHI] == 0.85
    assert rojek[HG.C_PSI_FRICTION] == HG.pair_partition("effusivity", resolve_pair(STEEL, GLASS))
    richard = row_of("richard2008")
    assert selected(richard) == {"normal_damping"} and richard[HG.C_CHI] == 1.0
    assert richard[HG.C_PSI_OTHER] == 0.5
    arkawazi = row_of("al_arkawazi2017")
    assert selected(arkawazi) == {"collision"}
    assert registry.get("heat_generation", "al_arkawazi2017").history_width == 1
    assert selected(row_of("none")) == set()


@pytest.mark.parametrize("spec", SPECS, ids=[s.name for s in SPECS])
def test_docs_page_exists(spec):
    page = DOCS / f"{spec.family}-{spec.name}.md"
    assert page.is_file(), page
    assert len(page.read_text()) > 400


def case(generation, **steel) -> dict:
    glass = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
             "thermal_conductivity": 1.0, "specific_heat": 800.0}  # fmt: skip
    wall = {"density": 7800.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3, **steel}
    return {
        "simulation": {"time_step": 1e-5, "end_time": 0.01},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {"glass": glass, "steel": wall},
        "walls": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "steel",
                   "thermal": {"kind": "fixed", "temperature": 300.0}}],
        "insertion": [{"kind": "list", "material": "glass", "positions": [[0.005, 0.005, 0.002]],
                       "radii": [0.001]}],
        "thermal": {"direct_conduction": "none", "heat_generation": generation},
    }  # fmt: skip


@pytest.mark.parametrize(
    "generation, key",
    [
        ({"model": "mechanical_dissipation", "mechanisms": []}, "at least one mechanism"),
        ({"model": "mechanical_dissipation", "mechanisms": ["sliding_friction"] * 2}, "twice"),
        ({"model": "mechanical_dissipation", "mechanisms": ["collision"]}, "mechanisms.0"),
        ({"model": "mechanical_dissipation", "conversion_fraction": 1.5}, "conversion_fraction"),
        ({"model": "rojek2014", "partition": "thermal"}, "partition"),
        ({"model": "mechanical_dissipaton"}, "did you mean 'mechanical_dissipation'"),
    ],
)
def test_bad_parameters_are_named(generation, key):
    with pytest.raises(ConfigError) as err:
        case_from_dict(case(generation))
    assert "thermal.heat_generation" in str(err.value)
    assert key in str(err.value)


@pytest.mark.parametrize(
    "generation, missing",
    [
        ({"model": "mechanical_dissipation", "partition": "conductivity"}, "thermal_conductivity"),
        ({"model": "rojek2014"}, "specific_heat"),
        ({"model": "mechanical_dissipation", "partition": "mokrani_bourouga2005"},
         "electrical_resistivity"),
    ],
)  # fmt: skip
def test_partition_inputs_of_a_hot_wall_are_required(generation, missing):
    """The wall has a fixed temperature, so it takes a share: its material needs what the
    partition formula reads (an adiabatic wall takes none and needs nothing)."""
    steel = {"thermal_conductivity": 45.0} if missing != "thermal_conductivity" else {}
    c = case_from_dict(case(generation, **steel))
    with pytest.raises(ConfigError, match=rf"materials\.steel\.{missing}: missing; required by "
                                          r"thermal\.heat_generation"):  # fmt: skip
        check_completeness(c)
