"""Convection (models/thermal/convection.py, engine/fields.py).

- Nu of every correlation against its formula, written out here from the spec's table, at a
  table of (Re, Pr, ε) (and μ_f/μ_fs for Whitaker, both Li & Mason regimes), through the
  model kernels and the field columns they read;
- lumped convective cooling of one sphere, T(t) = T_f + (T0 − T_f) e^(−t/τ), τ = ρ c d/(6 h),
  with each correlation's h: within 1e-4 of the closed form, and exactly the explicit Euler
  sequence (1 − Δt/τ)^n;
- the heat ledger (heat_in_convection closes the balance to round-off), the relative velocity,
  the validity-range warning (once, naming the particle and the value), the liquid tables.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.kernels import fields as fk
from thermodem.models import registry
from thermodem.models.thermal import convection as conv
from thermodem.state import heat
from thermodem.state.materials import Material, resolve_pair

R = 1e-3
RHO, C = 7800.0, 500.0
AIR = {"k": 0.0263, "c": 1007.0, "mu": 1.846e-5}
# ideal-gas density of the default air: P M / (R T)
AIR_RHO = 101325.0 * 0.0289647 / (8.314462618 * 300.0)


# ----------------------------------------------------------- the formulas, from the spec
def nu_ranz_marshall(re, pr, eps, ratio):
    return 2 + 0.6 * re**0.5 * pr ** (1 / 3)


def nu_whitaker(re, pr, eps, ratio):
    return 2 + (0.4 * re**0.5 + 0.06 * re ** (2 / 3)) * pr**0.4 * ratio**0.25


def nu_gunn(re, pr, eps, ratio):
    return (7 - 10 * eps + 5 * eps**2) * (1 + 0.7 * re**0.2 * pr ** (1 / 3)) + (
        1.33 - 2.4 * eps + 1.2 * eps**2
    ) * re**0.7 * pr ** (1 / 3)


def nu_li_mason(m):
    def nu(re, pr, eps, ratio):
        if re < 200:
            return 2 + 0.6 * eps**m * re**0.5 * pr ** (1 / 3)
        if re < 1500:
            return 2 + eps**m * (0.5 * re**0.5 + 0.02 * re**0.8) * pr ** (1 / 3)
        return 2 + 0.000045 * eps**m * re**1.8

    return nu


def nu_stagnant(re, pr, eps, ratio):
    return 2.0


FORMULAS = {
    ("ranz_marshall1952", ()): nu_ranz_marshall,
    ("whitaker1972", ()): nu_whitaker,
    ("gunn1978", ()): nu_gunn,
    ("li_mason2000", (("regime", "dense"),)): nu_li_mason(4.75),
    ("li_mason2000", (("regime", "dilute"),)): nu_li_mason(3.50),
    ("stagnant", ()): nu_stagnant,
}

# (Re, Pr, ε, μ_f/μ_fs): both sides of the Li & Mason regime boundaries (200, 1500), Pr of
# gases and liquids, dilute to dense porosities, Whitaker's viscosity ratio range
TABLE = [
    (0.0, 0.71, 1.0, 1.0),
    (0.5, 0.707, 0.4, 1.0),
    (1.0, 1.0, 0.35, 1.5),
    (12.5, 0.7, 0.45, 1.0),
    (150.0, 7.0, 0.6, 2.0),
    (199.999, 0.72, 0.8, 3.2),
    (200.0001, 0.72, 0.8, 1.0),
    (873.0, 0.9, 0.5, 1.2),
    (1499.9, 1.0, 0.37, 1.0),
    (1500.0001, 0.8, 0.9, 2.5),
    (4.2e4, 380.0, 0.95, 1.0),
    (9.9e4, 50.0, 0.42, 3.0),
]


def _fields_row(re: float, pr: float, eps: float, ratio: float) -> np.ndarray:
    """One particle's fields giving these numbers (R = 1 mm, ρ_f = 1, μ_f = 1e-5)."""
    f = np.zeros((fk.NFIELDS, 1))
    mu, k = 1e-5, 0.03
    f[fk.F_FLUID_DENSITY, 0] = 1.0
    f[fk.F_FLUID_VISCOSITY, 0] = mu
    f[fk.F_SURFACE_VISCOSITY, 0] = mu / ratio
    f[fk.F_FLUID_CONDUCTIVITY, 0] = k
    f[fk.F_FLUID_SPECIFIC_HEAT, 0] = pr * k / mu
    f[fk.F_RELATIVE_SPEED, 0] = re * mu / (2 * R)  # Re = ρ v 2R / μ
    f[fk.F_POROSITY, 0] = eps
    f[fk.F_FLUID_TEMPERATURE, 0] = 300.0
    fk.prandtl_columns(f)
    return f


@pytest.mark.parametrize(("model", "params"), list(FORMULAS), ids=lambda v: str(v))
def test_nusselt_of_every_correlation_against_its_formula(model: str, params: tuple) -> None:
    spec = registry.get("convection", model)
    material = Material(density=RHO, youngs_modulus=1e8, poisson_ratio=0.3)
    row = spec.pack(spec.params(**dict(params)), resolve_pair(material, material))
    formula = FORMULAS[(model, params)]
    for re, pr, eps, ratio in TABLE:
        f = _fields_row(re, pr, eps, ratio)
        assert f[fk.F_PRANDTL, 0] == pytest.approx(pr, rel=1e-14)
        q, g = conv.convection_dispatch(spec.model_id, row, 350.0, R, f, 0)
        q_own, g_own = spec.kernel(row, 350.0, R, f, 0)
        assert (q, g) == (q_own, g_own)  # the dispatcher is the model's kernel
        nu = g / (2 * math.pi * R * f[fk.F_FLUID_CONDUCTIVITY, 0])  # G = h A = 2π R k Nu
        expected = formula(re, pr, eps, ratio)
        assert nu == pytest.approx(expected, rel=1e-12), (re, pr, eps, ratio)
        assert q == pytest.approx(g * (300.0 - 350.0), rel=1e-14)  # Q = h A (T_f − T)


def test_hand_evaluated_values() -> None:
    """A few values by hand (4 digits), so that the formulas above are not the only check."""
    assert nu_ranz_marshall(100.0, 0.7, 0, 1) == pytest.approx(2 + 6 * 0.8879, rel=1e-4)
    # Gunn at ε = 0.4: (7 − 4 + 0.8) = 3.8, (1.33 − 0.96 + 0.192) = 0.562; Re^0.2 = 2.5119,
    # Re^0.7 = 25.119 (Re = 100), Pr^⅓ = 0.8879
    expected = 3.8 * (1 + 0.7 * 2.5119 * 0.8879) + 0.562 * 25.119 * 0.8879
    assert nu_gunn(100.0, 0.7, 0.4, 1) == pytest.approx(expected, rel=1e-4)
    # Li & Mason dense at Re = 1000, ε = 0.5: 0.5^4.75 = 0.037163, 0.5 √1000 = 15.811,
    # 0.02 × 1000^0.8 = 5.0238
    expected = 2 + 0.037163 * (15.811 + 5.0238) * 0.8879
    assert nu_li_mason(4.75)(1000.0, 0.7, 0.5, 1) == pytest.approx(expected, rel=1e-4)


def test_superficial_reynolds_uses_the_porosity() -> None:
    spec = registry.get("convection", "gunn1978")
    material = Material(density=RHO, youngs_modulus=1e8, poisson_ratio=0.3)
    row = spec.pack(spec.params(reynolds_velocity="superficial"), resolve_pair(material, material))
    f = _fields_row(100.0, 0.7, 0.4, 1.0)
    g = conv.convection_dispatch(spec.model_id, row, 350.0, R, f, 0)[1]
    nu = g / (2 * math.pi * R * f[fk.F_FLUID_CONDUCTIVITY, 0])
    assert nu == pytest.approx(nu_gunn(40.0, 0.7, 0.4, 1.0), rel=1e-12)  # Re = ε × 100


# ------------------------------------------------------------------- lumped cooling
def _case(tmp_path: Path, model: dict, fluid: dict, dt: float, porosity=None, t0=400.0) -> dict:  # noqa: ANN001
    path = tmp_path / "one.txt"
    path.write_text(f"x y z radius temperature\n0.005 0.005 0.005 {R} {t0}\n")
    thermal = {
        "direct_conduction": "none",
        "convection": model,
        "fluid": fluid,
        "frozen_mechanics": True,
        "time_step": dt,
    }
    if porosity is not None:
        thermal["porosity"] = porosity
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1e3, "gravity": [0, 0, -9.81]},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {
            "steel": {
                "density": RHO,
                "youngs_modulus": 1e8,
                "poisson_ratio": 0.3,
                "thermal_conductivity": 40.0,
                "specific_heat": C,
            }
        },
        "insertion": [{"kind": "file", "material": "steel", "path": str(path)}],
        "thermal": thermal,
    }


# (model parameters, fluid speed [m/s], porosity, Nu formula, gas c_p): each inside its
# range (Whitaker's Pr starts at 0.71: air's 0.707 with a c_p of 1015 J/(kg K) is 0.712)
COOLING = [
    ({"model": "stagnant"}, 0.0, None, nu_stagnant, AIR["c"]),
    ({"model": "ranz_marshall1952"}, 2.0, None, nu_ranz_marshall, AIR["c"]),
    ({"model": "whitaker1972"}, 2.0, None, nu_whitaker, 1015.0),
    ({"model": "gunn1978"}, 2.0, 0.45, nu_gunn, AIR["c"]),
    ({"model": "li_mason2000", "regime": "dense"}, 2.0, 0.45, nu_li_mason(4.75), AIR["c"]),
    ({"model": "li_mason2000", "regime": "dilute"}, 30.0, 0.9, nu_li_mason(3.5), AIR["c"]),
]


@pytest.mark.parametrize(
    ("model", "speed", "eps", "formula", "c_gas"),
    COOLING,
    ids=[f"{m['model']}-{m.get('regime', '')}" for m, *_ in COOLING],
)
def test_lumped_convective_cooling_matches_the_closed_form(
    tmp_path: Path, model: dict, speed: float, eps: float | None, formula, c_gas: float
) -> None:  # noqa: ANN001
    re = AIR_RHO * speed * 2 * R / AIR["mu"]
    pr = c_gas * AIR["mu"] / AIR["k"]
    h = formula(re, pr, eps or 1.0, 1.0) * AIR["k"] / (2 * R)
    tau = RHO * C * 2 * R / (6 * h)
    dt = tau / 4000.0
    t0, tf = 400.0, 300.0
    case = _case(tmp_path, model, {"temperature": tf, "velocity": [0.0, speed, 0.0]}, dt, eps)
    case["thermal"]["gas"] = {"specific_heat": c_gas}
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # inside the validity range: no warning
        sim = Simulation(case_from_dict(case))
        worst_closed = worst_euler = 0.0
        for n in range(1, 8001):  # to t = 2 τ
            sim.step()
            theta = (sim.particles.temperature[0] - tf) / (t0 - tf)
            if n % 400 == 0:
                worst_closed = max(worst_closed, abs(theta - math.exp(-n * dt / tau)))
                worst_euler = max(worst_euler, abs(theta / (1 - dt / tau) ** n - 1))
    assert worst_closed < 1e-4
    assert worst_euler < 1e-10  # exactly the explicit Euler sequence of this h
    th = sim.thermal
    assert th.conductance_sum[0] == pytest.approx(h * 4 * math.pi * R**2, rel=1e-12)
    # the ledger: the heat from the fluid is the change of the particle's energy
    u = th.thermal_energy() - th.initial_energy
    assert th.cumulative["heat_in_convection"] == pytest.approx(u, rel=1e-12)
    assert abs(th.balance_error()) <= 1e-12 * th.initial_energy
    assert th.summary()["heat_rate_convection"] < 0.0


def test_relative_velocity_and_a_moving_particle(tmp_path: Path) -> None:
    case = _case(tmp_path, "ranz_marshall1952", {"temperature": 300.0, "velocity": [1, 2, 3]}, 1e-3)
    sim = Simulation(case_from_dict(case))
    th = sim.thermal
    assert th.fields[fk.F_RELATIVE_SPEED, 0] == pytest.approx(math.sqrt(14.0), rel=1e-14)
    sim.particles.velocity[0] = [1.0, 0.0, -1.0]
    th.compute_rates(sim.time)
    assert th.fields[fk.F_RELATIVE_SPEED, 0] == pytest.approx(math.sqrt(0 + 4 + 16), rel=1e-14)
    numbers = th.field_provider.numbers(th.fields)
    re = AIR_RHO * math.sqrt(20.0) * 2 * R / AIR["mu"]
    assert numbers["Re"][0] == pytest.approx(re, rel=1e-12)
    assert numbers["Nu"][0] == pytest.approx(
        nu_ranz_marshall(re, AIR["c"] * AIR["mu"] / AIR["k"], 1, 1), rel=1e-12
    )


def test_leaving_the_validity_range_warns_once_with_the_particle(tmp_path: Path) -> None:
    # Ranz & Marshall below Re = 1: a fluid at rest
    case = _case(tmp_path, "ranz_marshall1952", {"temperature": 300.0}, 1e-3)
    with pytest.warns(RuntimeWarning, match=r"Re = 0 of particle 0 at step 0 .*range 1–10000"):
        sim = Simulation(case_from_dict(case))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for _ in range(3):
            sim.step()  # no second warning
    assert sim.thermal.field_provider.warned == ["Re"]


def test_gunn_rayleigh_range_is_checked_for_a_gas(tmp_path: Path) -> None:
    # a 2 cm sphere 1000 K above a stagnant gas: Ra = g β ΔT d³ / (ν α) ≈ 1e5 < 1e9; with a
    # 0.3 m sphere (hypothetical) it leaves the range
    case = _case(
        tmp_path, "gunn1978", {"temperature": 300.0, "velocity": [0, 0, 0.1]}, 1e-3, 0.5, t0=1300.0
    )
    sim = Simulation(case_from_dict(case))
    ra = sim.thermal.field_provider.numbers(sim.thermal.fields)["Ra"][0]
    d = 2 * R
    nu_k = AIR["mu"] / AIR_RHO
    alpha = AIR["k"] / (AIR_RHO * AIR["c"])
    assert ra == pytest.approx(9.81 * (1 / 300.0) * 1000.0 * d**3 / (nu_k * alpha), rel=1e-12)


def test_whitaker_viscosity_ratio_from_a_liquid_table(tmp_path: Path) -> None:
    mu = [[280.0, 1.4e-3], [380.0, 0.3e-3]]
    liquid = {
        "kind": "liquid",
        "thermal_conductivity": [[280.0, 0.58], [380.0, 0.68]],
        "density": 1000.0,
        "specific_heat": 4180.0,
        "dynamic_viscosity": mu,
    }
    case = _case(
        tmp_path,
        "whitaker1972",
        {"temperature": 300.0, "velocity": [0, 0, 0.05], "properties": liquid},
        1e-4,
        t0=330.0,
    )
    sim = Simulation(case_from_dict(case))
    f = sim.thermal.fields[:, 0]
    mu_f = 1.4e-3 + (300 - 280) / 100 * (0.3e-3 - 1.4e-3)
    mu_s = 1.4e-3 + (330 - 280) / 100 * (0.3e-3 - 1.4e-3)
    k_f = 0.58 + 0.2 * 0.1
    assert f[fk.F_FLUID_VISCOSITY] == pytest.approx(mu_f, rel=1e-14)
    assert f[fk.F_SURFACE_VISCOSITY] == pytest.approx(mu_s, rel=1e-14)
    assert f[fk.F_FLUID_CONDUCTIVITY] == pytest.approx(k_f, rel=1e-14)
    pr = 4180.0 * mu_f / k_f
    assert f[fk.F_PRANDTL] == pytest.approx(pr, rel=1e-14)
    re = 1000.0 * 0.05 * 2 * R / mu_f
    q = sim.particles.heat_rate_by_mechanism[0, heat.M_CONVECTION]
    nu = nu_whitaker(re, pr, 0, mu_f / mu_s)
    assert q == pytest.approx(2 * math.pi * R * k_f * nu * (300.0 - 330.0), rel=1e-12)


def test_missing_sections_are_named(tmp_path: Path) -> None:
    case = _case(tmp_path, "gunn1978", {"temperature": 300.0}, 1e-3)
    with pytest.raises(
        ConfigError,
        match=r"thermal.porosity: missing; required by "
        r"thermal.convection = 'gunn1978'",
    ):
        Simulation(case_from_dict(case))
    case = _case(tmp_path, "ranz_marshall1952", {"temperature": 300.0}, 1e-3)
    del case["thermal"]["fluid"]
    with pytest.raises(
        ConfigError,
        match=r"thermal.fluid: missing; required by "
        r"thermal.convection = 'ranz_marshall1952'",
    ):
        Simulation(case_from_dict(case))
    # porosity kind voronoi is served by the tessellation (engine/voronoi.py, issue 11)
    case = _case(tmp_path, "gunn1978", {"temperature": 300.0}, 1e-3, {"kind": "voronoi"})
    Simulation(case_from_dict(case))
    case = _case(tmp_path, "stagnant", {"temperature": -3.0}, 1e-3)
    with pytest.raises(ConfigError, match=r"thermal.fluid.temperature"):
        case_from_dict(case)
    case = _case(tmp_path, "stagnant", {"temperature": 300.0}, 1e-3)
    case["thermal"]["gas"] = {"mean_free_path": 1e-7}
    with pytest.raises(ConfigError, match=r"thermal.gas.density: missing"):
        Simulation(case_from_dict(case))


def test_an_unused_fluid_or_porosity_section_is_reported(tmp_path: Path) -> None:
    case = _case(tmp_path, "stagnant", {"temperature": 300.0}, 1e-3, porosity=0.4)
    with pytest.warns(RuntimeWarning, match=r"thermal.porosity is given but no selected model"):
        Simulation(case_from_dict(case))
