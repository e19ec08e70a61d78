"""Vargas & McCarthy (2002): conduction through a stagnant gas and a liquid bridge between
contacting particles (family ``indirect_conduction``; kernel conventions in
``indirect_conduction.py``). Spec "Other Conduction Models – Model by Vargas & McCarthy".

    H = k_l A_l / l_l + k_g* A_g / l_g,   k_g* = k_g / (1 + M / l_g)

    A_c = π R_c²,  A_l = 4π R_p² ((π/2 - φ) tan φ - 1 + cos φ) (1 - cos φ)/cos φ - A_c,
    A_g = 2π R_p² - A_l - A_c,  R_cap = R_p sin φ,
    l_l = [R_cap R_p - (φ R_p² + R_cap √(R_p² - R_cap²))/2] / (R_cap - R_c),
    l_g = R_p² (1 - π/4)/(R_p - R_c) - l_l,
    M = ((2 - a_i)/a_i + (2 - a_j)/a_j) ζ/(ζ + 1) ω / Pr

with the filling angle φ, the accommodation coefficients a of both surfaces
(``thermal_accommodation`` of the materials; the wall's material for a wall), ζ =
``thermal.gas.heat_capacity_ratio``, Pr = μ c_p / k_g and ω the gas's mean free path
(``thermal.gas``). The gas term is written k_g A_g / (l_g + M) (the same value, no division by
l_g). The paper's particles are identical, of radius R_p; for unequal radii and walls R_p =
2R̄ = 2 R_i R_j/(R_i + R_j) (= R for equal spheres, 2R_i for a flat wall): the gap between the
surfaces near the contact, r²/(2R̄), is the one of two equal spheres of radius 2R̄.

Outside the geometry the formulas describe, each path is kept finite and >= 0: A_l and A_g are
clipped at 0 (A_g < 0 once the spec's A_l exceeds the hemisphere, φ > 1.1450 rad), the liquid
path needs R_cap > R_c (else the gas-only lengths are used) and the gas path l_g > 0.
Choices and the checks of the spec's limits:
``docs/models/indirect_conduction-vargas_mccarthy2002.md``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field, field_validator, model_validator

from thermodem.config.base import StrictModel
from thermodem.models.registry import register
from thermodem.models.thermal.contact_radius import effective_radius, require
from thermodem.state.gas import GasProperties
from thermodem.state.materials import PairContext

FAMILY = "indirect_conduction"

VARGAS_MCCARTHY2002 = 4

VM_K_G = 0
VM_GAS_PARAMETER = 1
VM_K_L = 2
VM_FILLING_ANGLE = 3
VM_AREA_FACTOR = 4
VM_SIN_PHI = 5
VM_LIQUID_LENGTH = 6
VM_COLUMNS = (
    "k_g",
    "gas_parameter_M",
    "k_l",
    "filling_angle",
    "liquid_area_factor",
    "sin_filling_angle",
    "liquid_length_factor",
)

_ONE_MINUS_PI_4 = 1.0 - 0.25 * math.pi


_HALF_PI_LO = 6.123233995736766e-17  # π/2 - float(π/2)


def liquid_area_factor(phi: float) -> float:
    """f(φ) = ((π/2 - φ) tan φ - 1 + cos φ)(1 - cos φ)/cos φ, so that A_l = 4π R_p² f - A_c
    (spec); f ≈ π φ³/4 for small φ, 1 - 4ε/3 for φ = π/2 - ε.

    φ <= π/4: 1 - cos φ written 2 sin²(φ/2). Above, in ε = π/2 - φ (with the low part of π/2):
    ε cot ε - 1 + sin ε = sin ε - (sin ε - ε cos ε)/sin ε, the bracket by its series below
    ε = 0.25 — the printed form loses all digits to 1 - 1 as φ -> π/2.
    """
    if phi <= 0.25 * math.pi:
        h = 2.0 * math.sin(0.5 * phi) ** 2
        return ((0.5 * math.pi - phi) * math.tan(phi) - h) * h / math.cos(phi)
    eps = (0.5 * math.pi - phi) + _HALF_PI_LO
    s = math.sin(eps)
    if eps < 0.25:
        e2 = eps * eps
        g = eps * e2 / 3.0 * (1.0 - e2 / 10.0 * (1.0 - e2 / 28.0 * (1.0 - e2 / 54.0 * (
            1.0 - e2 / 88.0))))  # fmt: skip
    else:
        g = s - eps * math.cos(eps)
    return (s - g / s) * (1.0 - s) / s


def liquid_length_factor(phi: float) -> float:
    """z(φ) = sin φ - (φ + sin φ cos φ)/2, so that l_l = R_p² z / (R_cap - R_c) (spec: it is
    ∫_0^{R_cap} (R_p - √(R_p² - r²)) dr / R_p²). Written (sin φ (1 - cos φ) - (φ - sin φ))/2
    with a series for φ - sin φ below 0.25 rad (z ≈ φ³/6)."""
    if phi < 0.25:
        x2 = phi * phi
        phi_minus_sin = phi * x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (
            1.0 - x2 / 72.0 * (1.0 - x2 / 110.0))))  # fmt: skip
    else:
        phi_minus_sin = phi - math.sin(phi)
    return 0.5 * (math.sin(phi) * 2.0 * math.sin(0.5 * phi) ** 2 - phi_minus_sin)


def gas_parameter(alpha_i: float, alpha_j: float, gas: GasProperties) -> float:
    """M = ((2 - a_i)/a_i + (2 - a_j)/a_j) ζ/(ζ + 1) ω/Pr [m] (Vargas & McCarthy 2002; spec)."""
    zeta = gas.heat_capacity_ratio
    accommodation = (2.0 - alpha_i) / alpha_i + (2.0 - alpha_j) / alpha_j
    return accommodation * zeta / (zeta + 1.0) * gas.mean_free_path_value() / gas.prandtl()


@njit(cache=True, inline="always", error_model="numpy")
def vargas_mccarthy2002_conductance(p, r_i, r_j, dist, r_c, f_n):
    """H = k_l A_l/l_l + k_g A_g/(l_g + M) of touching pairs (see the module docstring)."""
    if math.isinf(r_j):
        touching = dist <= r_i
    else:
        touching = dist <= r_i + r_j
    if not touching:
        return 0.0
    r_p = 2.0 * effective_radius(r_i, r_j)
    rc = r_c if r_c > 0.0 else 0.0
    if not (rc < r_p):
        return 0.0
    r2 = r_p * r_p
    a_c = math.pi * rc * rc
    l_total = r2 * _ONE_MINUS_PI_4 / (r_p - rc)
    liquid = 0.0
    a_l = 0.0
    l_g = l_total
    if p[VM_FILLING_ANGLE] > 0.0:
        r_cap = r_p * p[VM_SIN_PHI]
        a_l = max(4.0 * math.pi * r2 * p[VM_AREA_FACTOR] - a_c, 0.0)
        if r_cap > rc:
            l_l = r2 * p[VM_LIQUID_LENGTH] / (r_cap - rc)
            liquid = p[VM_K_L] * a_l / l_l
            l_g = l_total - l_l
        else:
            a_l = 0.0  # the bridge lies inside the contact circle: no liquid path
    a_g = 2.0 * math.pi * r2 - a_l - a_c
    gas = 0.0
    if a_g > 0.0 and l_g > 0.0:
        gas = p[VM_K_G] * a_g / (l_g + p[VM_GAS_PARAMETER])
    return liquid + gas


class VargasMcCarthy2002Params(StrictModel):
    """Vargas & McCarthy (2002) Int. J. Heat Mass Transf. 45, 4847-4856: conduction through the
    stagnant gas and a liquid bridge of filling angle φ between contacting particles (spec
    "Other Conduction Models"). H = k_l A_l/l_l + k_g* A_g/l_g, k_g* = k_g/(1 + M/l_g) with
    the Smoluchowski gas parameter M from both surfaces' ``thermal_accommodation`` and the
    case's gas (k_g, ζ, Pr, mean free path ω). R_c comes from the case's contact_radius model
    (the paper: static Hertz, ``hertz_force``). φ = 0: gas only. Unequal radii and walls:
    R_p = 2R̄. Row: [k_g, M, k_l, φ, f(φ), sin φ, z(φ)].
    """

    filling_angle: float = Field(
        default=0.0,
        ge=0.0,
        lt=0.5 * math.pi,
        description="φ [rad], filling angle of the liquid bridge (0: gas only; < π/2)",
    )
    liquid_conductivity: float | None = Field(
        default=None,
        gt=0,
        allow_inf_nan=False,
        description="k_l [W/(m K)] of the bridge liquid; required when filling_angle > 0",
    )

    @field_validator("filling_angle", mode="before")
    @classmethod
    def _radians(cls, v: object) -> object:
        """An angle of π/2 or more is refused here with its unit: 30 is an angle in degrees
        (the Field bound alone said 'less than 1.5707963267948966')."""
        if isinstance(v, int | float) and not isinstance(v, bool) and v >= 0.5 * math.pi:
            if 2.0 <= v < 90.0:  # (from 2 on no radian angle near: degrees)
                hint = f"; {v:g} looks like degrees: {math.radians(v):.4g} rad"
            else:
                hint = ""
            raise ValueError(
                f"must be less than π/2 = {0.5 * math.pi:.6g} (radians{hint}), got {v!r}"
            )
        return v

    @model_validator(mode="after")
    def _liquid_given(self) -> VargasMcCarthy2002Params:
        if self.filling_angle > 0.0 and self.liquid_conductivity is None:
            raise ValueError(
                f"liquid_conductivity is required when filling_angle > 0 (got filling_angle = "
                f"{self.filling_angle!r} rad and no liquid_conductivity)"
            )
        if self.filling_angle == 0.0 and self.liquid_conductivity is not None:
            # (it ran as gas only, the liquid ignored without a word)
            raise ValueError(
                f"liquid_conductivity = {self.liquid_conductivity:g} W/(m K) is given but "
                "filling_angle is 0 (the default: gas only, no liquid bridge), so it would be "
                "ignored; allowed: a filling_angle > 0 and < π/2 rad for a liquid bridge, or "
                "leave liquid_conductivity out for gas only"
            )
        return self


def pack_vargas_mccarthy2002(params: VargasMcCarthy2002Params, pair: PairContext) -> np.ndarray:
    model = f"{FAMILY}.vargas_mccarthy2002"
    a_i = require(pair.mat_i, "thermal_accommodation", model)
    a_j = require(pair.mat_j, "thermal_accommodation", model)
    phi = params.filling_angle
    k_l = params.liquid_conductivity if params.liquid_conductivity is not None else 0.0
    values = [pair.gas.thermal_conductivity, gas_parameter(a_i, a_j, pair.gas), k_l, phi]
    geometry = [liquid_area_factor(phi), math.sin(phi), liquid_length_factor(phi)]
    return np.array([*values, *geometry], dtype=np.float64)


def vargas_mccarthy2002_range(
    params: VargasMcCarthy2002Params, radius_i: float, radius_j: float
) -> float:
    """Touching pairs only: 0."""
    return 0.0


register(
    family=FAMILY,
    name="vargas_mccarthy2002",
    model_id=VARGAS_MCCARTHY2002,
    kernel=vargas_mccarthy2002_conductance,
    params=VargasMcCarthy2002Params,
    pack=pack_vargas_mccarthy2002,
    summary="gas (Smoluchowski k_g*) and liquid-bridge paths between contacting particles",
    reference="Vargas & McCarthy (2002) Int. J. Heat Mass Transf. 45, 4847-4856; Vargas (2002) "
    "PhD thesis, University of Pittsburgh",
    requires=("thermal_accommodation",),
    uses_gas=(
        "thermal_conductivity",
        "specific_heat",
        "dynamic_viscosity",
        "heat_capacity_ratio",
        "mean_free_path",
    ),
    interaction_range=vargas_mccarthy2002_range,
    antisymmetric=False,
    symmetric=True,
    columns=VM_COLUMNS,
    swap_pairs=(),
    target="contacts",
    planar=("sphere",),
)
