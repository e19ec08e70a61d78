"""Stagnant-gas resistance network of Beaulieu (2020) (family ``direct_conduction``).

Spec: ``thermal-dem-stagnant-gas-resistance-model.rst``. The conductance between two touching
particles is

    1/R = 1/(R_L + (1/R_s + 1/R_g)^-1) + 1/(R_c + R_G)

with R_L the contact surface (Batchelor & O'Brien 1977), R_s the microcontacts (Van Lew 2016),
R_g the microgap and R_G the macrogap gas (Bahrami, Yovanovich & Culham 2006), R_c the solid
layers of the particles (Beaulieu 2020). Each resistance is its own small function below; the
kernel has the family's signature (see ``direct_conduction.py``) and returns H (T_j - T_i).

Kernels are compiled with ``error_model="numpy"``: they never raise (a division by zero gives
inf/NaN, which the NaN flag of the pair loop catches), as the architecture asks of kernels.

Choices (details and their reasons in ``docs/models/direct_conduction-resistance_network.md``):

- r_c = c (3 F_n R*/(4 E*))^{1/3}, c = (E*_sim/E*_real)^{1/5} (Zhou et al. 2010) when a
  material gives ``youngs_modulus_real`` (a material without it is taken as not softened),
  else c = 1. The ``contact_radius`` input of the kernel is not used.
- P_0 (parameter ``maximum_pressure``): ``force`` (default) P_0 = 3 F_n / (2π r_c²), the
  maximum Hertz pressure of the force over that circle; ``overlap`` P_0 = 2 E*_real δ_real /
  (π r_c) with δ_real = δ (E*/E*_real)^{2/3}, Lethe's form. Both equal the spec's
  2 E* δ/(π r_c) for a Hertz contact at rest without softening (E*_real = E*, c = 1); with a
  softened modulus ``overlap`` is (E*_real/E*)^{2/15} times ``force``.
- Out of the domain of erfc⁻¹: P_0 is capped at H' (the contact pressure cannot exceed the
  microhardness: fully plastic), so 0.03 P_0/H' stays in (0, 0.03]; and 2P_0/H' is capped at 1,
  i.e. a1 >= 0: the mean planes of the rough surfaces are not allowed to cross (for P_0 > H'/2
  the microgap formula would otherwise reach ln(1 + a2/(a1 + M/(2√2σ))) with a non-positive
  denominator, an unbounded then undefined gas conductance). Both caps are continuous.
- r_h = 2 r_i r_j/(r_i + r_j) = 2R* (a wall: 2R_i, the sphere-plane gap of the paraboloid
  approximation), B = ``packing_constant`` × r_h (0: simple cubic).
- Wall (r_j = inf): R_c,j = L_j/(k_j A_j) -> 0, every other term has its R* = R_i limit.
- erfc⁻¹ is the non-iterative ``erfcinv`` of ``erfcinv.py`` (piecewise polynomials, within
  3 ulp); the kernel rearranges the formulas so that one logarithm of P0/H' serves both erfc⁻¹
  and (H'/P0)^0.96 (see ``resistance_network_conductance``).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.models.thermal.contact_radius import effective_radius, require
from thermodem.models.thermal.erfcinv import (  # noqa: F401 (the first two: re-exported)
    erfcinv,
    erfcinv_iterative,
    erfcinv_neg_log,
    erfinv_central,
)
from thermodem.state.gas import GasProperties
from thermodem.state.materials import PairContext, effective_youngs_modulus

RESISTANCE_NETWORK = 9

#: Columns of the parameter row: the direct_conduction family's head (k_i, k_j, ρc_i, ρc_j;
#: the k(T) override replaces them), then the network's own.
COLUMNS = (
    "k_i",
    "k_j",
    "rhoc_i",
    "rhoc_j",
    "e_star",  # E* of the simulation [Pa]
    "zhou_correction",  # c = (E*/E*_real)^(1/5) [-]
    "microhardness",  # H' of the pair [Pa]
    "surface_roughness",  # σ of the pair [m]
    "surface_slope",  # τ of the pair [-]
    "k_gas",  # k_g [W/(m K)]
    "gas_parameter",  # M [m]
    "packing_constant",  # B / r_h [-]
    "p0_mode",  # P0_FORCE or P0_OVERLAP
    "p0_overlap_factor",  # (2/π) E*_real (E*/E*_real)^{2/3} [Pa]: P_0 = factor δ / r_c
)
(
    COL_K_I,
    COL_K_J,
    _,
    _,
    COL_E_STAR,
    COL_ZHOU_CORRECTION,
    COL_MICROHARDNESS,
    COL_SIGMA,
    COL_TAU,
    COL_K_GAS,
    COL_GAS_PARAMETER,
    COL_PACKING_CONSTANT,
    COL_P0_MODE,
    COL_P0_OVERLAP_FACTOR,
) = range(len(COLUMNS))
P0_FORCE = 0.0
P0_OVERLAP = 1.0

BOLTZMANN = 1.380649e-23  # J/K (exact, SI 2019)
_LN_2 = math.log(2.0)
_LN_0_03 = math.log(0.03)


# ------------------------------------------------------------------------- resistances
@njit(cache=True, error_model="numpy")
def resistance_contact_surface(k_h, r_c):
    """R_L = 1/(2 k_h r_c) [K/W], contact-surface constriction (Batchelor & O'Brien 1977)."""
    return 1.0 / (2.0 * k_h * r_c)


@njit(cache=True, error_model="numpy")
def resistance_microcontacts(k_h, r_c, p0, h_micro, sigma, tau):
    """R_s = (H'/P_0)^0.96 1.184/(π r_c² k_h) (σ/τ) [K/W], microcontacts (Van Lew 2016)."""
    return (h_micro / p0) ** 0.96 * 1.184 / (math.pi * r_c * r_c * k_h) * (sigma / tau)


@njit(cache=True, error_model="numpy")
def resistance_microgap(k_g, r_c, sigma, a1, a2, m_gas):
    """R_g = 2√2 σ a2 / (π k_g r_c² ln(1 + a2/(a1 + M/(2√2 σ)))) [K/W], microgap gas
    (Bahrami, Yovanovich & Culham 2006); a1 >= 0 and M > 0 keep the logarithm finite."""
    s2 = 2.0 * math.sqrt(2.0) * sigma
    return s2 * a2 / (math.pi * k_g * r_c * r_c * math.log1p(a2 / (a1 + m_gas / s2)))


@njit(cache=True, error_model="numpy")
def resistance_solid_layer(k, r, r_c):
    """R_c,i = L_i/(k_i A_i), L_i = π r_i/4, A_i = π(r_i² - r_c²) [K/W] (Beaulieu 2020).

    Written as 1/(4 k r (1 - (r_c/r)²)) so that a wall (r = inf) gives 0. For r_c >= r (a
    contact circle as large as the particle: far outside the model's validity) the layer has
    no cross-section left: infinite resistance, the limit of the formula as r_c -> r (beyond
    it the printed formula would turn negative and carry heat from cold to hot).
    """
    q = r_c / r
    if q >= 1.0:
        return np.inf
    return 0.25 / (k * r * (1.0 - q * q))


@njit(cache=True, error_model="numpy")
def macrogap_bracket(r_h, r_c, m_gas, b):
    """S ln((S - B)/(S - A)) + B - A [m] of the macrogap (Bahrami 2006); 0 when the gas region
    is empty (r_c >= r_h or B >= A).

    A = 2 sqrt(r_h² - r_c²), S = 2 (r_h - r_c²/(2 r_h)) + M, B = b r_h. S - A is evaluated as
    M + r_c⁴/(r_h (r_h + sqrt(r_h² - r_c²))²) (no cancellation).
    """
    if r_c >= r_h:
        return 0.0
    root = math.sqrt(r_h * r_h - r_c * r_c)
    big_a = 2.0 * root
    big_b = b * r_h
    if big_b >= big_a:
        return 0.0
    big_s = 2.0 * (r_h - r_c * r_c / (2.0 * r_h)) + m_gas
    s_minus_a = m_gas + r_c**4 / (r_h * (r_h + root) ** 2)
    return big_s * math.log((big_s - big_b) / s_minus_a) + big_b - big_a


@njit(cache=True, error_model="numpy")
def resistance_macrogap(k_g, r_h, r_c, m_gas, b):
    """R_G = 2 / (π k_g [S ln((S - B)/(S - A)) + B - A]) [K/W], macrogap gas (Bahrami 2006);
    the bracket by :func:`macrogap_bracket`. Infinite when the gas region is empty."""
    bracket = macrogap_bracket(r_h, r_c, m_gas, b)
    if bracket == 0.0:
        return np.inf
    return 2.0 / (math.pi * k_g * bracket)


@njit(cache=True, error_model="numpy")
def network_conductance(
    k_i, k_j, r_i, r_j, f_n, e_star, c_zhou, h_micro, sigma, tau, k_g, m_gas, b, overlap,
    p0_overlap,
):  # fmt: skip
    """1/R_ij [W/K] of Beaulieu (2020) for two touching particles (r_j = inf: a wall).

    ``p0_overlap`` = 0: P_0 = 3 F_n/(2π r_c²) (``maximum_pressure: force``); > 0: P_0 =
    p0_overlap δ / r_c with p0_overlap = (2/π) E*_real (E*/E*_real)^{2/3}
    (``maximum_pressure: overlap``, needs δ = ``overlap`` > 0).

    The resistance functions above, rearranged so that the costly operations are few and
    independent of each other (equal to them to ~1e-15 relative, tested):

    - with u = 3 F_n R*/(4 E*): r_c = c u^{1/3} = c exp(ln(u)/3) and
      q = P0/H' = 3F_n/(2π r_c² H') = 2E* u^{1/3}/(π R* c² H'), so
      ln q = ln(2E*/(π R* c² H')) + ln(u)/3, capped at 0 (P0 <= H'); the overlap form
      q = p0_overlap δ/(r_c H') gives ln q = ln(p0_overlap δ/(c H')) - ln(u)/3;
    - ln q gives both erfc⁻¹ from their logarithms, -ln(2q) and -ln(0.03q) (no further log),
      and (H'/P0)^0.96 = exp(-0.96 ln q);
    - R_s and R_g are inverted in closed form; the contact-surface branch is
      g_L g/(g_L + g) with g_L = 1/R_L = 2 k_h r_c, g = 1/R_s + 1/R_g;
    - the macrogap branch is x/(1 + x R_c), x = 1/R_G (one division).
    """
    r_eff = effective_radius(r_i, r_j)
    r_c = 0.0
    log_q = 0.0
    if f_n > 0.0:
        log_u = math.log(0.75 * f_n * r_eff / e_star)
        r_c = c_zhou * math.exp(log_u / 3.0)
        if p0_overlap > 0.0:
            log_q = min(math.log(p0_overlap * overlap / (c_zhou * h_micro)) - log_u / 3.0, 0.0)
        else:
            log_scale = math.log(2.0 * e_star / (math.pi * r_eff * c_zhou * c_zhou * h_micro))
            log_q = min(log_scale + log_u / 3.0, 0.0)
    res_solid = resistance_solid_layer(k_i, r_i, r_c) + resistance_solid_layer(k_j, r_j, r_c)
    # macrogap branch 1/(R_c + R_G) = x/(1 + x R_c), x = 1/R_G = π k_g bracket/2 (one division;
    # 0 when the gas region is empty or the solid layers are blocked, R_c = inf)
    conductance = 0.0
    if res_solid < np.inf:
        x = 0.5 * math.pi * k_g * macrogap_bracket(2.0 * r_eff, r_c, m_gas, b)
        conductance = x / (1.0 + x * res_solid)
    if r_c <= 0.0:
        return conductance
    # a1 = erfc⁻¹(min(2q, 1)) (>= 0), a2 = erfc⁻¹(0.03 q) - a1
    if log_q < -2.0 * _LN_2:  # 2q < 1/2
        a1 = erfcinv_neg_log(-_LN_2 - log_q)
    elif log_q < -_LN_2:  # 1/2 <= 2q < 1: erfc⁻¹(x) = erf⁻¹(1 - x)
        a1 = erfinv_central(1.0 - 2.0 * math.exp(log_q))
    else:
        a1 = 0.0
    a1_plus_a2 = erfcinv_neg_log(-_LN_0_03 - log_q)
    k_h = 2.0 * k_i * k_j / (k_i + k_j)
    area = math.pi * r_c * r_c
    g_s = math.exp(0.96 * log_q) * area * k_h * tau / (1.184 * sigma)  # 1/R_s
    s2 = 2.0 * math.sqrt(2.0) * sigma
    m_s = m_gas / s2
    # 1/R_g, with ln(1 + a2/(a1 + M/s2)) = ln(a1 + a2 + M/s2) - ln(a1 + M/s2): two independent
    # logarithms instead of a division followed by log1p (shorter dependency chain)
    g_g = k_g * area * (math.log(a1_plus_a2 + m_s) - math.log(a1 + m_s)) / (s2 * (a1_plus_a2 - a1))
    g = g_s + g_g
    g_l = 2.0 * k_h * r_c  # 1/R_L
    return conductance + g_l * g / (g_l + g)


@njit(cache=True, error_model="numpy")
def resistance_network_conductance(
    k_i, k_j, r_i, r_j, f_n, e_star, c_zhou, h_micro, sigma, tau, k_g, m_gas, b
):
    """:func:`network_conductance` with P_0 from the force (``maximum_pressure: force``)."""
    return network_conductance(
        k_i, k_j, r_i, r_j, f_n, e_star, c_zhou, h_micro, sigma, tau, k_g, m_gas, b, 0.0, 0.0
    )


@njit(cache=True, error_model="numpy")
def resistance_network_rate(
    p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
):
    """Heat rate into i [W]; the row's columns are :data:`COLUMNS`."""
    if overlap <= 0.0:
        return 0.0
    p0_overlap = p[COL_P0_OVERLAP_FACTOR] if p[COL_P0_MODE] == P0_OVERLAP else 0.0
    h = network_conductance(
        p[COL_K_I], p[COL_K_J], r_i, r_j, max(f_n, 0.0), p[COL_E_STAR], p[COL_ZHOU_CORRECTION],
        p[COL_MICROHARDNESS], p[COL_SIGMA], p[COL_TAU], p[COL_K_GAS], p[COL_GAS_PARAMETER],
        p[COL_PACKING_CONSTANT], overlap, p0_overlap,
    )  # fmt: skip
    return h * (t_j - t_i)


# --------------------------------------------------------------------------- parameters
class ResistanceNetworkParams(StrictModel):
    """Beaulieu (2020) PhD thesis, Polytechnique Montréal (https://publications.polymtl.ca/
    4757/): contact, microcontact, micro/macrogap gas and solid-layer resistances (spec .rst).

    ``packing_constant`` is B/r_h (the spec's B is a length; B = 0 for simple cubic packing,
    B/r_h in [0, 2)). The gas is the case's ``thermal.gas`` (``pair.gas``). Materials need
    thermal_conductivity, microhardness, surface_roughness, surface_slope and
    thermal_accommodation; a wall material too. The packed row's columns are :data:`COLUMNS`.

    ``maximum_pressure``: ``force`` P_0 = 3 F_n/(2π r_c²) (default; allows
    thermal.conductance_force_tolerance), ``overlap`` P_0 = 2 E*_real δ (E*/E*_real)^{2/3} /
    (π r_c) as Lethe computes it (docs/models/direct_conduction-resistance_network.md).
    """

    packing_constant: float = Field(
        default=0.0, ge=0, lt=2, description="B / r_h [-] of the macrogap integral (0: cubic)"
    )
    maximum_pressure: Literal["force", "overlap"] = Field(
        default="force",
        description="P_0 from the normal force, 3F/(2π r_c²), or from the overlap, "
        "2 E*_real δ (E*/E*_real)^(2/3)/(π r_c)",
    )


def gas_parameter(alpha_i: float, alpha_j: float, gas: GasProperties) -> float:
    """M = ((2 - α_i)/α_i + (2 - α_j)/α_j) (2γ/(1 + γ)) Λ/Pr [m] (spec .rst)."""
    gamma = gas.heat_capacity_ratio
    accommodation = (2.0 - alpha_i) / alpha_i + (2.0 - alpha_j) / alpha_j
    return (
        accommodation * (2.0 * gamma / (1.0 + gamma)) * gas.mean_free_path_value() / gas.prandtl()
    )


def pack_resistance_network(params: ResistanceNetworkParams, pair: PairContext) -> np.ndarray:
    model = "direct_conduction.resistance_network"
    mi, mj = pair.mat_i, pair.mat_j

    def both(prop: str) -> tuple[float, float]:
        return require(mi, prop, model), require(mj, prop, model)

    k_i, k_j = both("thermal_conductivity")
    h_i, h_j = both("microhardness")
    # equivalent σ, τ of the pair: an interactions entry's, else from the two materials
    sigma = pair.surface_roughness or math.hypot(*both("surface_roughness"))
    tau = pair.surface_slope or math.hypot(*both("surface_slope"))
    a_i, a_j = both("thermal_accommodation")
    e_sim = pair.effective_youngs_modulus
    real = mi.youngs_modulus_real is not None or mj.youngs_modulus_real is not None
    e_real = effective_youngs_modulus(mi, mj, real=True) if real else e_sim
    c = (e_sim / e_real) ** 0.2
    overlap_mode = params.maximum_pressure == "overlap"
    return packed(
        COLUMNS,
        {
            "k_i": k_i,
            "k_j": k_j,
            "rhoc_i": 0.0,
            "rhoc_j": 0.0,
            "e_star": e_sim,
            "zhou_correction": c,
            "microhardness": 2.0 * h_i * h_j / (h_i + h_j),
            "surface_roughness": sigma,
            "surface_slope": tau,
            "k_gas": pair.gas.thermal_conductivity,
            "gas_parameter": gas_parameter(a_i, a_j, pair.gas),
            "packing_constant": params.packing_constant,
            "p0_mode": P0_OVERLAP if overlap_mode else P0_FORCE,
            "p0_overlap_factor": 2.0 / math.pi * e_real * (e_sim / e_real) ** (2.0 / 3.0),
        },
    )


def _refuse_reuse(params: ResistanceNetworkParams) -> str | None:
    """Why thermal.conductance_force_tolerance cannot be used with these parameters."""
    if params.maximum_pressure == "overlap":
        return (
            "needs the conductance to depend on the contact through the normal force only, "
            "but direct_conduction.maximum_pressure = 'overlap' also reads the overlap: use "
            "maximum_pressure: force, or 0"
        )
    return None


register(
    family="direct_conduction",
    name="resistance_network",
    model_id=RESISTANCE_NETWORK,
    kernel=resistance_network_rate,
    params=ResistanceNetworkParams,
    pack=pack_resistance_network,
    columns=COLUMNS,
    summary="Beaulieu (2020) contact/microcontact/gas-gap/solid-layer resistance network",
    reference="Beaulieu (2020) PhD thesis, Polytechnique Montréal; Bahrami, Yovanovich & Culham "
    "(2006) Int. J. Heat Mass Transf. 49, 3691-3701; Batchelor & O'Brien (1977)",
    requires=(
        "thermal_conductivity",
        "microhardness",
        "surface_roughness",
        "surface_slope",
        "thermal_accommodation",
        "youngs_modulus",
        "poisson_ratio",
    ),
    swap_pairs=((0, 1), (2, 3)),
    # H depends on the contact through F_n only: thermal.conductance_force_tolerance allowed
    # (with maximum_pressure: force; _refuse_reuse says why not otherwise)
    conductance_from_force=True,
    conductance_reuse_refusal=_refuse_reuse,
    # thermal.gas read by pack (k_g; M from Λ, Pr = μ c_p / k_g and γ)
    uses_gas=(
        "thermal_conductivity",
        "specific_heat",
        "dynamic_viscosity",
        "heat_capacity_ratio",
        "mean_free_path",
    ),
)
