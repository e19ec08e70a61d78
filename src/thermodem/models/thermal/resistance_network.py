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
- P_0 = 3 F_n / (2π r_c²), the maximum Hertz pressure of the force over that circle; without
  correction it equals the spec's 2 E* δ/(π r_c) for a Hertz contact.
- Out of the domain of erfc⁻¹: P_0 is capped at H' (the contact pressure cannot exceed the
  microhardness: fully plastic), so 0.03 P_0/H' stays in (0, 0.03]; and 2P_0/H' is capped at 1,
  i.e. a1 >= 0: the mean planes of the rough surfaces are not allowed to cross (for P_0 > H'/2
  the microgap formula would otherwise reach ln(1 + a2/(a1 + M/(2√2σ))) with a non-positive
  denominator, an unbounded then undefined gas conductance). Both caps are continuous.
- r_h = 2 r_i r_j/(r_i + r_j) = 2R* (a wall: 2R_i, the sphere-plane gap of the paraboloid
  approximation), B = ``packing_constant`` × r_h (0: simple cubic).
- Wall (r_j = inf): R_c,j = L_j/(k_j A_j) -> 0, every other term has its R* = R_i limit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import pad_row, register
from thermodem.models.thermal.contact_radius import (
    effective_radius,
    hertz_radius_from_force,
    require,
)
from thermodem.state.gas import GasProperties
from thermodem.state.materials import PairContext, effective_youngs_modulus

RESISTANCE_NETWORK = 9

BOLTZMANN = 1.380649e-23  # J/K (exact, SI 2019)
_SQRT_PI = math.sqrt(math.pi)


# ----------------------------------------------------------------------------- erfc^-1
@njit(cache=True, error_model="numpy")
def _erfcx(y):
    """exp(y²) erfc(y) for y >= 0 (asymptotic series beyond y = 25, where erfc underflows)."""
    if y < 25.0:
        return math.erfc(y) * math.exp(y * y)
    t = 0.5 / (y * y)
    term = 1.0
    total = 1.0
    for k in range(1, 10):
        term *= -(2.0 * k - 1.0) * t
        total += term
    return total / (y * _SQRT_PI)


@njit(cache=True, error_model="numpy")
def _log_erfc(y):
    """ln erfc(y) for y >= 0, without underflow."""
    if y < 25.0:
        return math.log(math.erfc(y))
    return -y * y + math.log(_erfcx(y))


@njit(cache=True, error_model="numpy")
def _erfinv_central(z):
    """erf⁻¹(z) for |z| <= 0.5: Maclaurin series start, then Halley steps on erf(y) - z."""
    z2 = z * z
    pi = math.pi
    y = (
        0.5
        * _SQRT_PI
        * z
        * (
            1.0
            + z2
            * (
                pi / 12.0
                + z2
                * (
                    7.0 * pi**2 / 480.0
                    + z2 * (127.0 * pi**3 / 40320.0 + z2 * 4369.0 * pi**4 / 5806080.0)
                )
            )
        )
    )
    for _ in range(8):
        f = math.erf(y) - z
        fp = 2.0 / _SQRT_PI * math.exp(-y * y)
        step = f / (fp + y * f)  # Halley: f'' = -2y f'
        y -= step
        # Halley converges cubically: after a step below 1e-10 |y| the error is far below
        # round-off (a tighter test never triggers and runs all iterations)
        if abs(step) <= 1e-10 * abs(y):
            break
    return y


@njit(cache=True, error_model="numpy")
def _erfcinv_tail(x):
    """erfc⁻¹(x) for 0 < x <= 0.5: Newton on ln erfc(y) = ln x from y0 = sqrt(-ln x).

    erfc(y) <= exp(-y²) makes y0 an upper bound of the root, and ln erfc is concave, so the
    Newton iterates decrease monotonically to the root (no overshoot, no bracketing needed).
    """
    target = math.log(x)
    y = math.sqrt(-target)
    for _ in range(60):
        step = 0.5 * _SQRT_PI * _erfcx(y) * (_log_erfc(y) - target)
        y += step
        # quadratic convergence: after a step below 1e-9 y the error is below round-off
        if abs(step) <= 1e-9 * y:
            break
    return y


@njit(cache=True, error_model="numpy")
def erfcinv(x):
    """Inverse complementary error function on (0, 2), relative accuracy ~1e-15.

    erfc⁻¹(0) = inf, erfc⁻¹(2) = -inf, NaN outside [0, 2] (as scipy.special.erfcinv).
    Central part (0.5 <= x <= 1.5) through erf⁻¹(1 - x) (1 - x is exact there, so y near 0 keeps
    its relative accuracy); x > 1.5 by erfc⁻¹(x) = -erfc⁻¹(2 - x) (2 - x exact).
    """
    if not (x >= 0.0 and x <= 2.0):
        return np.nan
    if x == 0.0:
        return np.inf
    if x == 2.0:
        return -np.inf
    if x > 1.5:
        return -_erfcinv_tail(2.0 - x)
    if x >= 0.5:
        return _erfinv_central(1.0 - x)
    return _erfcinv_tail(x)


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

    Written as 1/(4 k r (1 - (r_c/r)²)) so that a wall (r = inf) gives 0.
    """
    q = r_c / r
    return 0.25 / (k * r * (1.0 - q * q))


@njit(cache=True, error_model="numpy")
def resistance_macrogap(k_g, r_h, r_c, m_gas, b):
    """R_G = 2 / (π k_g [S ln((S - B)/(S - A)) + B - A]) [K/W], macrogap gas (Bahrami 2006).

    A = 2 sqrt(r_h² - r_c²), S = 2 (r_h - r_c²/(2 r_h)) + M, B = b r_h. S - A is evaluated as
    M + r_c⁴/(r_h (r_h + sqrt(r_h² - r_c²))²) (no cancellation). Infinite when the gas region
    is empty (B >= A).
    """
    if r_c >= r_h:
        return np.inf
    root = math.sqrt(r_h * r_h - r_c * r_c)
    big_a = 2.0 * root
    big_b = b * r_h
    if big_b >= big_a:
        return np.inf
    big_s = 2.0 * (r_h - r_c * r_c / (2.0 * r_h)) + m_gas
    s_minus_a = m_gas + r_c**4 / (r_h * (r_h + root) ** 2)
    bracket = big_s * math.log((big_s - big_b) / s_minus_a) + big_b - big_a
    return 2.0 / (math.pi * k_g * bracket)


@njit(cache=True, error_model="numpy")
def resistance_network_conductance(
    k_i, k_j, r_i, r_j, f_n, e_star, c_zhou, h_micro, sigma, tau, k_g, m_gas, b
):
    """1/R_ij [W/K] of Beaulieu (2020) for two touching particles (r_j = inf: a wall)."""
    r_eff = effective_radius(r_i, r_j)
    r_c = c_zhou * hertz_radius_from_force(f_n, r_eff, e_star)
    res_solid = resistance_solid_layer(k_i, r_i, r_c) + resistance_solid_layer(k_j, r_j, r_c)
    conductance = 1.0 / (res_solid + resistance_macrogap(k_g, 2.0 * r_eff, r_c, m_gas, b))
    if r_c <= 0.0:
        return conductance
    k_h = 2.0 * k_i * k_j / (k_i + k_j)
    p0 = min(1.5 * f_n / (math.pi * r_c * r_c), h_micro)
    a1 = erfcinv(min(2.0 * p0 / h_micro, 1.0))
    a2 = erfcinv(0.03 * p0 / h_micro) - a1
    g_s = 1.0 / resistance_microcontacts(k_h, r_c, p0, h_micro, sigma, tau)
    g_g = 1.0 / resistance_microgap(k_g, r_c, sigma, a1, a2, m_gas)
    return conductance + 1.0 / (resistance_contact_surface(k_h, r_c) + 1.0 / (g_s + g_g))


@njit(cache=True, error_model="numpy")
def resistance_network_rate(
    p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
):
    """Heat rate into i [W]. Row: [k_i, k_j, 0, 0, E*, c, H', σ, τ, k_g, M, B/r_h]."""
    if overlap <= 0.0:
        return 0.0
    h = resistance_network_conductance(
        p[0], p[1], r_i, r_j, max(f_n, 0.0), p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11]
    )
    return h * (t_j - t_i)


# --------------------------------------------------------------------------- parameters
class ResistanceNetworkParams(StrictModel):
    """Beaulieu (2020) PhD thesis, Polytechnique Montréal (https://publications.polymtl.ca/
    4757/): contact, microcontact, micro/macrogap gas and solid-layer resistances (spec .rst).

    ``packing_constant`` is B/r_h (the spec's B is a length; B = 0 for simple cubic packing,
    B/r_h in [0, 2)). The gas is the case's ``thermal.gas`` (``pair.gas``). Materials need
    thermal_conductivity, microhardness, surface_roughness, surface_slope and
    thermal_accommodation; a wall material too. Row: [k_i, k_j, 0, 0, E*, c, H', σ, τ, k_g, M,
    B/r_h].
    """

    packing_constant: float = Field(
        default=0.0, ge=0, lt=2, description="B / r_h [-] of the macrogap integral (0: cubic)"
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
    s_i, s_j = both("surface_roughness")
    t_i, t_j = both("surface_slope")
    a_i, a_j = both("thermal_accommodation")
    e_sim = pair.effective_youngs_modulus
    real = mi.youngs_modulus_real is not None or mj.youngs_modulus_real is not None
    c = (e_sim / effective_youngs_modulus(mi, mj, real=True)) ** 0.2 if real else 1.0
    return pad_row(
        [
            k_i,
            k_j,
            0.0,
            0.0,
            e_sim,
            c,
            2.0 * h_i * h_j / (h_i + h_j),
            math.hypot(s_i, s_j),
            math.hypot(t_i, t_j),
            pair.gas.thermal_conductivity,
            gas_parameter(a_i, a_j, pair.gas),
            params.packing_constant,
        ]
    )


register(
    family="direct_conduction",
    name="resistance_network",
    model_id=RESISTANCE_NETWORK,
    kernel=resistance_network_rate,
    params=ResistanceNetworkParams,
    pack=pack_resistance_network,
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
    # thermal.gas read by pack (k_g; M from Λ, Pr = μ c_p / k_g and γ)
    uses_gas=(
        "thermal_conductivity",
        "specific_heat",
        "dynamic_viscosity",
        "heat_capacity_ratio",
        "mean_free_path",
    ),
)
