"""The case-level interstitial gas (``thermal.gas``): its values, its validation, and that the
models read it (resistance network: k_g and M; Batchelor & O'Brien complete/modified: k_f)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.models import registry
from thermodem.models.thermal import resistance_network as rn
from thermodem.state.gas import GasProperties
from thermodem.state.materials import Material, resolve_pair

K_B = 1.380649e-23
R = 1e-3
SURFACE = {"microhardness": 5e9, "surface_roughness": 1e-6, "surface_slope": 0.05,
           "thermal_accommodation": 0.8}  # fmt: skip
MATERIAL = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0, "specific_heat": 800.0, **SURFACE}  # fmt: skip
#: a gas unlike air in every property the models read (helium-like, 2 bar, 500 K)
GAS = {"thermal_conductivity": 0.2, "specific_heat": 5193.0, "dynamic_viscosity": 2.8e-5,
       "heat_capacity_ratio": 5.0 / 3.0, "pressure": 2.0e5, "temperature": 500.0,
       "molecular_diameter": 2.6e-10}  # fmt: skip


# ------------------------------------------------------------------------- the section
def test_mean_free_path_from_kinetic_theory_by_hand():
    # Λ = k_B T / (√2 π d² P) = 6.903245e-21 J / (4.442883 × 6.76e-20 m² × 2e5 Pa)
    lam = 1.380649e-23 * 500.0 / (math.sqrt(2.0) * math.pi * 2.6e-10**2 * 2.0e5)
    assert lam == pytest.approx(1.149243e-7, rel=1e-6)
    assert GasProperties(**GAS).mean_free_path_value() == pytest.approx(lam, rel=1e-14)
    # air at 300 K, 1 atm (the defaults): 68.7 nm
    assert GasProperties().mean_free_path_value() == pytest.approx(6.868e-8, rel=1e-3)
    # a missing one of P, T, d takes the air value
    low = GasProperties(pressure=1000.0)
    assert (low.temperature, low.molecular_diameter) == (300.0, 3.66e-10)
    air = GasProperties().mean_free_path_value()
    assert low.mean_free_path_value() == pytest.approx(101.325 * air, rel=1e-14)
    # a given mean free path is used as such (and P, T, d are not set)
    given = GasProperties(mean_free_path=1e-7)
    assert given.mean_free_path_value() == 1e-7 and given.pressure is None
    assert GasProperties(**GAS).prandtl() == pytest.approx(2.8e-5 * 5193.0 / 0.2, rel=1e-14)


def test_physical_constants_are_the_specs_to_its_printed_digits():
    """k_B (Vargas & McCarthy's mean free path) and σ (radiation) are the exact SI values; the
    spec prints 1.3806e-23 J/K (k_B rounded) and 5.6703e-8 W/(m² K⁴) (σ truncated, or an older
    value: 1.3e-5 relative below CODATA)."""
    from thermodem.models.thermal.radiation import STEFAN_BOLTZMANN
    from thermodem.state.gas import BOLTZMANN

    assert BOLTZMANN == 1.380649e-23 and STEFAN_BOLTZMANN == 5.670374419e-8
    assert abs(BOLTZMANN - 1.3806e-23) < 0.5e-27  # half a unit of the last printed digit
    assert 0 < STEFAN_BOLTZMANN / 5.6703e-8 - 1 < 1.5e-5


@pytest.mark.parametrize(
    ("gas", "expected"),
    [
        ({"thermal_conductivity": 0.0}, "thermal.gas.thermal_conductivity: Input should be "
         "greater than 0 (got 0.0)"),
        ({"heat_capacity_ratio": 0.99}, "thermal.gas.heat_capacity_ratio: Input should be "
         "greater than or equal to 1 (got 0.99)"),
        ({"pressure": -1.0}, "thermal.gas.pressure: Input should be greater than 0 (got -1.0)"),
        ({"mean_free_path": 1e-7, "temperature": 400.0}, "thermal.gas: give either "
         "mean_free_path or pressure, temperature and molecular_diameter (from which it is "
         "computed), not both: got mean_free_path = 1e-07 and temperature = 400.0"),
        ({"conductivity": 0.1}, "thermal.gas.conductivity: unknown key (did you mean "
         "'thermal_conductivity'?)"),
    ],
)  # fmt: skip
def test_bad_gas_values_name_the_key_the_value_and_the_bound(gas, expected):
    with pytest.raises(ConfigError) as err:
        case_from_dict(_case("unused", {"gas": gas}))
    assert expected in str(err.value)


@pytest.mark.parametrize(
    ("thermal", "expected"),
    [
        ({"direct_conduction": {"model": "resistance_network", "gas": {"pressure": 1e4}}},
         "thermal.direct_conduction.gas: unknown key (got {'pressure': 10000.0}): the "
         "interstitial gas is no longer a model parameter: give it once for the case in the "
         "section thermal.gas"),
        ({"direct_conduction": {"model": "batchelor_obrien_complete", "fluid_conductivity": 0.1}},
         "thermal.direct_conduction.fluid_conductivity: unknown key (got 0.1): the fluid "
         "conductivity is now that of the case's interstitial gas: give it as "
         "thermal.gas.thermal_conductivity"),
        ({"direct_conduction": {"model": "batchelor_obrien_modified", "fluid_conductivity": 0.1}},
         "give it as thermal.gas.thermal_conductivity"),
    ],
)  # fmt: skip
def test_the_old_model_keys_say_where_the_gas_goes(thermal, expected):
    with pytest.raises(ConfigError) as err:
        case_from_dict(_case("unused", thermal))
    assert expected in str(err.value)
    assert "allowed keys: model," in str(err.value)


def test_a_top_level_gas_section_points_to_thermal_gas():
    data = _case("unused", {})
    data["gas"] = {"thermal_conductivity": 0.1}
    with pytest.raises(ConfigError, match=r"gas: unknown key .*the section thermal\.gas"):
        case_from_dict(data)


def test_the_section_is_always_there_with_air_defaults():
    case = case_from_dict(_case("unused", {}))
    assert case.thermal.gas == GasProperties()
    assert case.thermal.gas.thermal_conductivity == 0.0263
    assert resolve_pair(Material(**MATERIAL), Material(**MATERIAL)).gas == GasProperties()


def test_every_gas_property_a_model_reads_is_a_gas_key():
    users = {f"{s.family}.{s.name}": s.uses_gas for s in registry.all_models() if s.uses_gas}
    convection = {f"convection.{n}" for n in registry.names("convection") if n != "none"}
    assert (
        set(users)
        == {
            "direct_conduction.resistance_network",
            "direct_conduction.batchelor_obrien_complete",
            "direct_conduction.batchelor_obrien_modified",
            "indirect_conduction.batchelor_obrien_separated",
            "indirect_conduction.rong_horio1999",
            "indirect_conduction.musser2011",
            "indirect_conduction.vargas_mccarthy2002",
            "indirect_conduction.voronoi_a",
            "indirect_conduction.voronoi_b",
        }
        | convection
    )  # the convection models read it as thermal.fluid.properties: gas
    for names in users.values():
        assert set(names) <= set(GasProperties.model_fields)
    for spec in registry.all_models():  # no model has the gas among its own parameters
        assert not {"gas", "fluid_conductivity"} & set(spec.params.model_fields)


# ------------------------------------------------------------ the models read the case's gas
def _write(path: Path, rows: list[tuple]) -> str:
    lines = ["x y z radius temperature"] + [" ".join(f"{v!r}" for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _case(particles: str, thermal: dict) -> dict:
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.02, 0.02, 0.02]},
        "materials": {"glass": dict(MATERIAL)},
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "thermal": thermal,
    }


def _two_spheres(tmp_path: Path, thermal: dict, d: float = 1.95e-3) -> Simulation:
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (d, 0.0, 0.0, R, 400.0)])
    thermal = {"frozen_mechanics": True, "time_step": 1e-3, **thermal}
    return Simulation(case_from_dict(_case(path, thermal)))


def test_resistance_network_takes_k_g_and_m_from_the_case_gas(tmp_path):
    sim = _two_spheres(tmp_path, {"direct_conduction": "resistance_network", "gas": GAS})
    row = sim.thermal.conduction_table[0, 0]
    # M = (2 (2 - α)/α) (2γ/(1 + γ)) Λ/Pr by hand from the values of GAS
    lam = K_B * 500.0 / (math.sqrt(2.0) * math.pi * 2.6e-10**2 * 2.0e5)
    pr = 2.8e-5 * 5193.0 / 0.2
    gamma = 5.0 / 3.0
    m_gas = 2 * (2 - 0.8) / 0.8 * (2 * gamma / (1 + gamma)) * lam / pr
    assert row[9] == 0.2
    assert row[10] == pytest.approx(m_gas, rel=1e-14)
    # the same row as packing with the explicit gas
    spec = registry.get("direct_conduction", "resistance_network")
    mat = Material(**MATERIAL)
    explicit = spec.pack(spec.params(), resolve_pair(mat, mat, gas=GasProperties(**GAS)))
    assert list(row) == list(explicit)
    # one thermal step: Q_0 = H (T_1 - T_0) with H from explicit k_g and M, and the Hertz force
    # at rest F = 4/3 E* sqrt(R*) δ^1.5 (no damping without relative velocity)
    sim.run(steps=1)
    e_star = 1e7 / (2 * (1 - 0.3**2))
    f_n = 4.0 / 3.0 * e_star * math.sqrt(R / 2) * (2 * R - 1.95e-3) ** 1.5
    sigma, tau = math.sqrt(2) * 1e-6, math.sqrt(2) * 0.05
    h = rn.resistance_network_conductance(
        1.0, 1.0, R, R, f_n, e_star, 1.0, 5e9, sigma, tau, 0.2, m_gas, 0.0
    )
    q = sim.particles.heat_rate[list(sim.particles.global_id).index(0)]
    assert q == pytest.approx(h * 100.0, rel=1e-9)
    # and air gives a different conductance
    air = _two_spheres(tmp_path, {"direct_conduction": "resistance_network"})
    air.run(steps=1)
    assert air.particles.heat_rate[list(air.particles.global_id).index(0)] != pytest.approx(
        q, rel=1e-3
    )


@pytest.mark.parametrize("model", ["batchelor_obrien_complete", "batchelor_obrien_modified"])
def test_batchelor_obrien_takes_k_f_from_the_case_gas(tmp_path, model):
    sim = _two_spheres(tmp_path, {"direct_conduction": model, "gas": {"thermal_conductivity": 0.1}})
    assert sim.thermal.conduction_table[0, 0][4] == 0.1
    air = _two_spheres(tmp_path, {"direct_conduction": model})
    assert air.thermal.conduction_table[0, 0][4] == 0.0263
    # k_pf = k_p/k_f must exceed 1: the message names the gas key
    with pytest.raises(ConfigError, match=r"thermal\.gas\.thermal_conductivity = 2 W/\(m K\)"):
        _two_spheres(tmp_path, {"direct_conduction": model, "gas": {"thermal_conductivity": 2.0}})


def test_validate_and_models_show_the_gas(tmp_path):
    path = _write(tmp_path / "two.txt", [(0.0, 0.0, 0.0, R, 300.0), (1.95e-3, 0.0, 0.0, R, 400.0)])
    case = tmp_path / "c.yaml"
    data = _case(path, {"direct_conduction": "resistance_network"})
    case.write_text(yaml.safe_dump(data))
    out = CliRunner().invoke(app, ["validate", str(case)])
    assert out.exit_code == 0, out.output
    assert (
        "# thermal.gas (default: air at 300 K, 1 atm; read by thermal.direct_conduction = "
        "'resistance_network'): k_g = 0.0263 W/(m K)" in out.output
    )
    assert "Λ = 6.868e-08 m (from P = 101325 Pa, T = 300 K, d = 3.66e-10 m)" in out.output
    models = CliRunner().invoke(app, ["models", "direct_conduction"])
    assert "reads thermal.gas: thermal_conductivity, specific_heat" in models.output
    assert models.output.count("allows thermal.conductance_force_tolerance") == 1


def test_api_refuses_a_gas_parameter():
    spec = registry.get("direct_conduction", "resistance_network")
    with pytest.raises(ValidationError):
        spec.params(gas={})
