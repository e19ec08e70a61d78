"""Convection models (family ``convection``): particle–fluid heat transfer, per-particle terms.

Spec: dem-heat-transfer-models.md, section 3 ("Heat Convection Mechanisms", "Dimensionless
Numbers", "Convection Correlations", "Calculation Procedure"). Newton's law of cooling with
the Nusselt number of a correlation, the characteristic length of a sphere l = 2R:

    Re = ρ_f |u_f - v_p| 2R / μ_f,   Pr = c_f μ_f / k_f,
    h = Nu k_f / (2R),   Q_f = h A_s (T_f - T_p) = 2π R k_f Nu (T_f - T_p).

The particle rotation is neglected (spec), the coupling is one-way (the fluid temperature is
imposed: the heat the particles exchange does not change it). Every fluid quantity is a
per-particle field (``kernels/fields.py``) filled by the providers of ``engine/fields.py``
from ``thermal.fluid`` and ``thermal.porosity``; the kernels only read them.

Kernel signature of a per-particle term: ``kernel(p, t_i, r_i, fields, i) -> (Q, G)`` with Q
[W] into particle i and G = h A [W/K], the conductance of the stability limit (the dependence
of h on T_p through μ_fs is neglected there).

The Nusselt functions below are the spec's table (Peng 2020), each citing its paper:

- Ranz & Marshall (1952): Nu = 2 + 0.6 Re^½ Pr^⅓; Re 1–10⁴, Pr 0.6–380.
- Whitaker (1972): Nu = 2 + (0.4 Re^½ + 0.06 Re^⅔) Pr^0.4 (μ_f/μ_fs)^¼; Re 3.5–7.6 × 10⁴,
  Pr 0.71–380, μ_f/μ_fs 1.0–3.2.
- Gunn (1978): Nu = (7 - 10ε + 5ε²)(1 + 0.7 Re^0.2 Pr^⅓) + (1.33 - 2.4ε + 1.2ε²) Re^0.7 Pr^⅓;
  Re < 10⁵, Ra < 10⁹, all Pr.
- Li & Mason (2000): Nu = 2 + 0.6 ε^m Re^½ Pr^⅓ (Re < 200), 2 + ε^m (0.5 Re^½ + 0.02 Re^0.8)
  Pr^⅓ (200 ≤ Re < 1500), 2 + 4.5 × 10⁻⁵ ε^m Re^1.8 (Re ≥ 1500); m = 3.50 dilute, 4.75 dense;
  Pr 0.7–1.0, ε 0.35–1.0.
- Stagnant fluid: Nu = 2 (h = k_f / R, Q = 4π R k_f ΔT).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit, prange
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.kernels.fastmath_exp import fast_power
from thermodem.kernels.fields import (
    F_FLUID_CONDUCTIVITY,
    F_FLUID_DENSITY,
    F_FLUID_SPECIFIC_HEAT,
    F_FLUID_TEMPERATURE,
    F_FLUID_VISCOSITY,
    F_POROSITY,
    F_PRANDTL,
    F_PRANDTL_CBRT,
    F_RELATIVE_SPEED,
    F_SURFACE_VISCOSITY,
)
from thermodem.kernels.variants import parallel_kernel
from thermodem.models.registry import packed, register
from thermodem.state.materials import PairContext

FAMILY = "convection"

NONE = 0
STAGNANT = 1
RANZ_MARSHALL = 2
WHITAKER = 3
GUNN = 4
LI_MASON = 5

#: Parameter row columns (named; ``register(columns=...)`` sets the row width).
STAGNANT_COLUMNS = ("nusselt",)
COL_NUSSELT = 0
REYNOLDS_COLUMNS = ("superficial",)  # Ranz–Marshall, Whitaker, Gunn
COL_SUPERFICIAL = 0  # 1: Re from the superficial velocity ε |u_f - v_p|
LI_MASON_COLUMNS = ("superficial", "exponent")
COL_EXPONENT = 1

#: Li & Mason (2000): the porosity exponent m of each regime.
LI_MASON_EXPONENT = {"dilute": 3.50, "dense": 4.75}

#: The gas properties a convection model reads when ``thermal.fluid.properties`` is ``gas``.
GAS_PROPERTIES = ("thermal_conductivity", "specific_heat", "dynamic_viscosity", "density")

#: Columns of the dimensionless numbers (``convection_numbers``).
N_RE, N_PR, N_NU, N_VISCOSITY_RATIO, N_POROSITY, N_RA = range(6)
NUMBER_NAMES = ("Re", "Pr", "Nu", "viscosity_ratio", "porosity", "Ra")

#: Validity ranges of each correlation (spec, "Convection Correlations", conditions column):
#: (number, lowest, highest); a run that leaves one is warned once.
VALIDITY: dict[str, tuple[tuple[str, float, float], ...]] = {
    "none": (),
    "stagnant": (),
    "ranz_marshall1952": (("Re", 1.0, 1.0e4), ("Pr", 0.6, 380.0)),
    "whitaker1972": (
        ("Re", 3.5, 7.6e4),
        ("Pr", 0.71, 380.0),
        ("viscosity_ratio", 1.0, 3.2),
    ),
    "gunn1978": (("Re", 0.0, 1.0e5), ("Ra", 0.0, 1.0e9)),
    "li_mason2000": (("Pr", 0.7, 1.0), ("porosity", 0.35, 1.0)),
}

#: Whether a model reads the local porosity (needs ``thermal.porosity``).
USES_POROSITY = {"gunn1978", "li_mason2000"}

RE_VELOCITY = {"relative": 0.0, "superficial": 1.0}


class FlowParams(StrictModel):
    """Common parameter of the correlations of a flowing fluid."""

    reynolds_velocity: Literal["relative", "superficial"] = Field(
        default="relative",
        description="velocity of Re: the relative velocity |u_f - v_p| (spec), or the "
        "superficial slip velocity ε |u_f - v_p| (some CFD-DEM codes, for the porosity-based "
        "correlations)",
    )


class NoneParams(StrictModel):
    """No convection."""


class StagnantParams(StrictModel):
    """Stagnant fluid around nearly stationary particles (spec, "Stagnant fluid around DEM
    particles"): Re vanishes and Nu = 2, h = k_f / R, Q = 4π R k_f (T_f - T_p)."""

    nusselt: float = Field(default=2.0, gt=0, description="Nu [-] (2 in most correlations)")


class RanzMarshallParams(FlowParams):
    """Ranz & Marshall (1952), Evaporation from drops, Chem. Eng. Prog. 48:141-146, 173-180:
    Nu = 2 + 0.6 Re^½ Pr^⅓ (flow past a single sphere; Re 1–10⁴, Pr 0.6–380)."""


class WhitakerParams(FlowParams):
    """Whitaker (1972), Forced convection heat transfer correlations for flow in pipes, past
    flat plates, single cylinders, single spheres, and for flow in packed beds and tube
    bundles, AIChE J. 18:361-371: Nu = 2 + (0.4 Re^½ + 0.06 Re^⅔) Pr^0.4 (μ_f/μ_fs)^¼, μ_fs
    the fluid's viscosity at the particle's (surface) temperature (Re 3.5–7.6 × 10⁴,
    Pr 0.71–380, μ_f/μ_fs 1.0–3.2)."""


class GunnParams(FlowParams):
    """Gunn (1978), Transfer of heat or mass to particles in fixed and fluidised beds, Int. J.
    Heat Mass Transfer 21:467-476: Nu = (7 - 10ε + 5ε²)(1 + 0.7 Re^0.2 Pr^⅓)
    + (1.33 - 2.4ε + 1.2ε²) Re^0.7 Pr^⅓ with ε the local porosity (Re < 10⁵, Ra < 10⁹)."""


class LiMasonParams(FlowParams):
    """Li & Mason (2000), A computational investigation of transient heat transfer in
    pneumatic transport of granular particles, Powder Technol. 112:273-282: three Re regimes
    with the porosity factor ε^m (Pr 0.7–1.0, ε 0.35–1.0)."""

    regime: Literal["dense", "dilute"] = Field(
        default="dense", description="m = 4.75 (dense) or 3.50 (dilute)"
    )


def _flow_row(params: FlowParams) -> np.ndarray:
    return packed(REYNOLDS_COLUMNS, {"superficial": RE_VELOCITY[params.reynolds_velocity]})


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


def pack_stagnant(params: StagnantParams, pair: PairContext) -> np.ndarray:
    return packed(STAGNANT_COLUMNS, {"nusselt": params.nusselt})


def pack_flow(params: FlowParams, pair: PairContext) -> np.ndarray:
    return _flow_row(params)


def pack_li_mason(params: LiMasonParams, pair: PairContext) -> np.ndarray:
    values = {
        "superficial": RE_VELOCITY[params.reynolds_velocity],
        "exponent": LI_MASON_EXPONENT[params.regime],
    }
    return packed(LI_MASON_COLUMNS, values)


# ---------------------------------------------------------------------- Nusselt numbers
@njit(cache=True, inline="always", error_model="numpy")
def power(x, a):
    """x^a for x >= 0, a > 0 as exp(a ln x): the same to a few ulp as x**a, and about a
    third faster in these kernels (numba's pow); 0 for x = 0."""
    return math.exp(a * math.log(x)) if x > 0.0 else 0.0


@njit(cache=True, inline="always", error_model="numpy")
def nusselt_ranz_marshall(re, pr_cbrt):
    """Ranz & Marshall (1952): 2 + 0.6 Re^½ Pr^⅓."""
    return 2.0 + 0.6 * math.sqrt(re) * pr_cbrt


@njit(cache=True, inline="always", error_model="numpy")
def nusselt_whitaker(re, pr, viscosity_ratio):
    """Whitaker (1972): 2 + (0.4 Re^½ + 0.06 Re^⅔) Pr^0.4 (μ_f/μ_fs)^¼."""
    return 2.0 + (0.4 * math.sqrt(re) + 0.06 * power(re, 2.0 / 3.0)) * power(pr, 0.4) * math.sqrt(
        math.sqrt(viscosity_ratio)
    )


@njit(cache=True, inline="always", error_model="numpy")
def gunn_from_power(re02, re, pr_cbrt, eps):
    """Gunn's Nu from Re^0.2 (``re02``) and Re (see :func:`nusselt_gunn`)."""
    re07 = re02 * math.sqrt(re)  # Re^0.7 = Re^0.2 Re^0.5
    a = 7.0 - 10.0 * eps + 5.0 * eps * eps
    b = 1.33 - 2.4 * eps + 1.2 * eps * eps
    return a * (1.0 + 0.7 * re02 * pr_cbrt) + b * re07 * pr_cbrt


@njit(cache=True, error_model="numpy")
def gunn_power(re):
    """Re^0.2 by :func:`fast_power`, compiled once and called (not inlined) from the
    particle-by-particle paths (the model's kernel, the dispatchers, the validity check):
    :func:`gunn_chunk` inlines the same operations where they vectorise."""
    return fast_power(re, 0.2)


@njit(cache=True, inline="always", error_model="numpy")
def nusselt_gunn(re, pr_cbrt, eps):
    """Gunn (1978): (7 - 10ε + 5ε²)(1 + 0.7 Re^0.2 Pr^⅓) + (1.33 - 2.4ε + 1.2ε²) Re^0.7 Pr^⅓.
    Re^0.2 from the compiled exp and log (``kernels/fastmath_exp.py``: branch-free, so the
    particle pass's loop over a chunk of particles vectorises, :func:`gunn_chunk`; IEEE
    operations only, so the same bits there and here)."""
    return gunn_from_power(gunn_power(re), re, pr_cbrt, eps)


@njit(cache=True, inline="always", error_model="numpy")
def nusselt_li_mason(re, pr_cbrt, eps, m):
    """Li & Mason (2000): 2 + 0.6 ε^m Re^½ Pr^⅓ (Re < 200); 2 + ε^m (0.5 Re^½ + 0.02 Re^0.8)
    Pr^⅓ (Re < 1500); 2 + 4.5e-5 ε^m Re^1.8 (otherwise)."""
    em = power(eps, m)
    if re < 200.0:
        return 2.0 + 0.6 * em * math.sqrt(re) * pr_cbrt
    if re < 1500.0:
        return 2.0 + em * (0.5 * math.sqrt(re) + 0.02 * power(re, 0.8)) * pr_cbrt
    return 2.0 + 0.000045 * em * power(re, 1.8)


@njit(cache=True, inline="always", error_model="numpy")
def reynolds(p, r_i, fields, i):
    """Re = ρ_f v 2R / μ_f, v = |u_f - v_p| (times ε with the column ``superficial`` = 1)."""
    speed = fields[F_RELATIVE_SPEED, i]
    if p[COL_SUPERFICIAL] != 0.0:
        speed *= fields[F_POROSITY, i]
    return fields[F_FLUID_DENSITY, i] * speed * 2.0 * r_i / fields[F_FLUID_VISCOSITY, i]


@njit(cache=True, inline="always", error_model="numpy")
def convection_nusselt(model_id, p, r_i, fields, i):
    """Nu of model ``model_id`` for particle i (NaN for an unknown id)."""
    if model_id == GUNN:
        re = reynolds(p, r_i, fields, i)
        return nusselt_gunn(re, fields[F_PRANDTL_CBRT, i], fields[F_POROSITY, i])
    if model_id == RANZ_MARSHALL:
        return nusselt_ranz_marshall(reynolds(p, r_i, fields, i), fields[F_PRANDTL_CBRT, i])
    if model_id == WHITAKER:
        ratio = fields[F_FLUID_VISCOSITY, i] / fields[F_SURFACE_VISCOSITY, i]
        return nusselt_whitaker(reynolds(p, r_i, fields, i), fields[F_PRANDTL, i], ratio)
    if model_id == LI_MASON:
        re = reynolds(p, r_i, fields, i)
        return nusselt_li_mason(
            re, fields[F_PRANDTL_CBRT, i], fields[F_POROSITY, i], p[COL_EXPONENT]
        )
    if model_id == STAGNANT:
        return p[COL_NUSSELT]
    if model_id == NONE:
        return 0.0
    return np.nan


@njit(cache=True, inline="always", error_model="numpy")
def _newton(nu, t_i, r_i, fields, i):
    """(Q, G) = (h A (T_f - T), h A), h A = 2π R k_f Nu."""
    ha = 2.0 * math.pi * r_i * fields[F_FLUID_CONDUCTIVITY, i] * nu
    return ha * (fields[F_FLUID_TEMPERATURE, i] - t_i), ha


@njit(cache=True, error_model="numpy")
def gunn_chunk(table, type_id, radius, temperature, fields, lo, hi, heat, conductance):
    """Gunn's (Q, G) of particles lo .. hi - 1 into ``heat[i - lo]``, ``conductance[i - lo]``
    (the particle pass's scratch rows): the operations of :func:`gunn_convection`, particle by
    particle the same bits, in four loops over the chunk: Re (the particle's row), Nu in place,
    G = 2π R k_f Nu, Q = G (T_f - T). The last three read contiguous rows and call no library
    function, so LLVM vectorises them (the power is :func:`fast_power`); as one scalar loop
    with the C library's exp and log the term took ~1.2 ms of a step on the 50k bed."""
    m = hi - lo
    for t in range(m):
        i = np.uint64(lo + t)  # (unsigned: no negative-index wrap-around on the loads)
        heat[t] = reynolds(table[np.uint32(type_id[i])], radius[i], fields, i)
    eps = fields[F_POROSITY, lo:hi]
    pr_cbrt = fields[F_PRANDTL_CBRT, lo:hi]
    for t in range(m):
        re = heat[t]
        heat[t] = gunn_from_power(fast_power(re, 0.2), re, pr_cbrt[t], eps[t])
    r = radius[lo:hi]
    k_f = fields[F_FLUID_CONDUCTIVITY, lo:hi]
    for t in range(m):
        conductance[t] = 2.0 * math.pi * r[t] * k_f[t] * heat[t]  # as _newton
    t_f = fields[F_FLUID_TEMPERATURE, lo:hi]
    t_p = temperature[lo:hi]
    for t in range(m):
        heat[t] = conductance[t] * (t_f[t] - t_p[t])


@njit(cache=True, error_model="numpy")
def none_convection(p, t_i, r_i, fields, i):
    return 0.0, 0.0


@njit(cache=True, error_model="numpy")
def stagnant_convection(p, t_i, r_i, fields, i):
    return _newton(convection_nusselt(STAGNANT, p, r_i, fields, i), t_i, r_i, fields, i)


@njit(cache=True, error_model="numpy")
def ranz_marshall_convection(p, t_i, r_i, fields, i):
    return _newton(convection_nusselt(RANZ_MARSHALL, p, r_i, fields, i), t_i, r_i, fields, i)


@njit(cache=True, error_model="numpy")
def whitaker_convection(p, t_i, r_i, fields, i):
    return _newton(convection_nusselt(WHITAKER, p, r_i, fields, i), t_i, r_i, fields, i)


@njit(cache=True, error_model="numpy")
def gunn_convection(p, t_i, r_i, fields, i):
    return _newton(convection_nusselt(GUNN, p, r_i, fields, i), t_i, r_i, fields, i)


@njit(cache=True, error_model="numpy")
def li_mason_convection(p, t_i, r_i, fields, i):
    return _newton(convection_nusselt(LI_MASON, p, r_i, fields, i), t_i, r_i, fields, i)


@njit(cache=True, inline="always", error_model="numpy")
def convection_dispatch(model_id, p, t_i, r_i, fields, i):
    """(Q, G) of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    if model_id == NONE:
        return 0.0, 0.0
    nu = convection_nusselt(model_id, p, r_i, fields, i)
    return _newton(nu, t_i, r_i, fields, i)


# ------------------------------------------------------------ dimensionless numbers, ranges
@parallel_kernel(error_model="numpy")
def convection_numbers(
    fields, radius, temperature, type_id, model_id, table, gravity, beta_mode, beta,
    with_nusselt, out,
):  # fmt: skip
    """Re, Pr, Nu (``with_nusselt``, else 0), μ_f/μ_fs, ε and Ra of every particle into
    ``out`` (n, 6). Ra = g β |T_p - T_f| d³ ρ² c / (μ k), β = 1/T_f (``beta_mode`` 1, an ideal
    gas), ``beta`` (mode 2) or not evaluated (mode 0: NaN)."""
    n = radius.shape[0]
    for i in prange(n):
        p = table[type_id[i]]
        r = radius[i]
        out[i, N_RE] = reynolds(p, r, fields, i)
        out[i, N_PR] = fields[F_PRANDTL, i]
        out[i, N_NU] = convection_nusselt(model_id, p, r, fields, i) if with_nusselt else 0.0
        out[i, N_VISCOSITY_RATIO] = fields[F_FLUID_VISCOSITY, i] / fields[F_SURFACE_VISCOSITY, i]
        out[i, N_POROSITY] = fields[F_POROSITY, i]
        if beta_mode == 0:
            out[i, N_RA] = np.nan
        else:
            tf = fields[F_FLUID_TEMPERATURE, i]
            b = 1.0 / tf if beta_mode == 1 else beta
            d = 2.0 * r
            rho = fields[F_FLUID_DENSITY, i]
            out[i, N_RA] = (
                gravity * b * abs(temperature[i] - tf) * d * d * d * rho * rho
                * fields[F_FLUID_SPECIFIC_HEAT, i]
                / (fields[F_FLUID_VISCOSITY, i] * fields[F_FLUID_CONDUCTIVITY, i])
            )  # fmt: skip


@njit(cache=True, error_model="numpy")
def first_outside(values, column, lowest, highest):
    """The first row whose ``values[row, column]`` is below ``lowest`` or above ``highest``
    (NaN: not evaluated, never outside), or -1."""
    for i in range(values.shape[0]):
        v = values[i, column]
        if v < lowest or v > highest:
            return i
    return -1


# --------------------------------------------------------------------------- registration
_COMMON = dict(family=FAMILY, target="particles", uses_gas=GAS_PROPERTIES)

register(
    family=FAMILY,
    name="none",
    model_id=NONE,
    kernel=none_convection,
    params=NoneParams,
    pack=pack_none,
    summary="no convection",
    reference="-",
    columns=(),
    target="particles",
    planar=("disc", "sphere"),
)
register(
    **_COMMON,
    name="stagnant",
    model_id=STAGNANT,
    kernel=stagnant_convection,
    params=StagnantParams,
    pack=pack_stagnant,
    summary="stagnant fluid: Nu = 2, Q = 4π R k_f (T_f − T)",
    reference="spec 'Stagnant fluid around DEM particles'",
    columns=STAGNANT_COLUMNS,
)
register(
    **_COMMON,
    name="ranz_marshall1952",
    model_id=RANZ_MARSHALL,
    kernel=ranz_marshall_convection,
    params=RanzMarshallParams,
    pack=pack_flow,
    summary="Nu = 2 + 0.6 Re^½ Pr^⅓ (single sphere; Re 1–1e4, Pr 0.6–380)",
    reference="Ranz & Marshall (1952) Chem. Eng. Prog. 48:141-146, 173-180",
    columns=REYNOLDS_COLUMNS,
)
register(
    **_COMMON,
    name="whitaker1972",
    model_id=WHITAKER,
    kernel=whitaker_convection,
    params=WhitakerParams,
    pack=pack_flow,
    summary="Nu = 2 + (0.4 Re^½ + 0.06 Re^⅔) Pr^0.4 (μ_f/μ_fs)^¼ (Re 3.5–7.6e4, Pr 0.71–380)",
    reference="Whitaker (1972) AIChE J. 18:361-371",
    columns=REYNOLDS_COLUMNS,
)
register(
    **_COMMON,
    name="gunn1978",
    model_id=GUNN,
    kernel=gunn_convection,
    params=GunnParams,
    pack=pack_flow,
    summary="Nu = (7 − 10ε + 5ε²)(1 + 0.7 Re^0.2 Pr^⅓) + (1.33 − 2.4ε + 1.2ε²) Re^0.7 Pr^⅓ "
    "(local porosity ε; Re < 1e5, Ra < 1e9)",
    reference="Gunn (1978) Int. J. Heat Mass Transfer 21:467-476",
    columns=REYNOLDS_COLUMNS,
)
register(
    **_COMMON,
    name="li_mason2000",
    model_id=LI_MASON,
    kernel=li_mason_convection,
    params=LiMasonParams,
    pack=pack_li_mason,
    summary="Nu = 2 + ε^m (...) by Re regime (< 200, < 1500, ≥ 1500); m = 4.75 dense, 3.50 "
    "dilute (Pr 0.7–1, ε 0.35–1)",
    reference="Li & Mason (2000) Powder Technol. 112:273-282",
    columns=LI_MASON_COLUMNS,
)
