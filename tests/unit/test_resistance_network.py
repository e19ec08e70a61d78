"""Beaulieu (2020) resistance network and erfc⁻¹, against the spec's formulas written out here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import erfc
from scipy.special import erfcinv as sp_erfcinv

from thermodem.models import registry
from thermodem.models.thermal import resistance_network as rn
from thermodem.state.materials import Material, resolve_pair

PI = math.pi
SQ2 = math.sqrt(2.0)


# ------------------------------------------------------------------------------ erfc^-1
def test_erfcinv_matches_scipy_over_the_whole_domain():
    x = np.concatenate(
        [
            np.logspace(-300, -1, 3000),  # near 0
            np.linspace(0.0, 2.0, 4001)[1:-1],
            1.0 - np.logspace(-16, -1, 300),  # near 1 (result near 0: relative accuracy kept)
            1.0 + np.logspace(-15.6, -1, 300),
            2.0 - np.logspace(-15.6, -1, 3000),  # near 2 (spacing of doubles below 2: 2.2e-16)
        ]
    )
    ours = np.array([rn.erfcinv(v) for v in x])
    ref = sp_erfcinv(x)
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0.0)


def test_erfcinv_denormals_and_round_trip():
    for x in (1e-320, 1e-310, 2.2e-308):  # scipy itself gives inf at 5e-324
        assert rn.erfcinv(x) == pytest.approx(sp_erfcinv(x), rel=1e-12)
    assert rn.erfcinv(5e-324) == pytest.approx(27.2133, rel=1e-5)
    for x in (1e-200, 1e-9, 0.01, 0.7, 1.3, 1.99):
        assert erfc(rn.erfcinv(x)) == pytest.approx(x, rel=1e-13)


def test_erfcinv_at_the_polynomial_interval_edges():
    """Both sides of each tail interval edge x = exp(-ln 2 · 2^k), and of x = 0.5, 1.5."""
    edges = [math.exp(-math.log(2.0) * 2.0**k) for k in range(11)]
    x = np.array([e + i * math.ulp(e) for e in edges for i in range(-3, 4)])
    x = np.concatenate([x, 2.0 - x[x <= 0.5], [0.5, 0.5 - 2**-54, 1.5, 1.5 + 2**-52]])
    ours = np.array([rn.erfcinv(v) for v in x])
    np.testing.assert_allclose(ours, sp_erfcinv(x), rtol=1e-14, atol=0.0)


def test_erfcinv_from_the_logarithm_and_the_iterative_reference():
    # exp(-L) a normal double (denormals have too few bits to check against)
    big_l = np.concatenate([np.geomspace(math.log(2.0), 708.39, 2000), [math.log(2.0)]])
    ours = np.array([rn.erfcinv_neg_log(v) for v in big_l])
    np.testing.assert_allclose(ours, sp_erfcinv(np.exp(-big_l)), rtol=1e-14, atol=0.0)
    x = np.concatenate([np.logspace(-300, -1, 500), np.linspace(0.0, 2.0, 401)[1:-1]])
    ours = np.array([rn.erfcinv(v) for v in x])
    iterative = np.array([rn.erfcinv_iterative(v) for v in x])
    np.testing.assert_allclose(ours, iterative, rtol=1e-14, atol=0.0)
    for v in (0.0, 2.0, 1.0, -1.0, 3.0, np.nan):
        np.testing.assert_equal(rn.erfcinv_iterative(v), rn.erfcinv(v))


def test_erfcinv_outside_the_domain():
    assert rn.erfcinv(0.0) == np.inf
    assert rn.erfcinv(2.0) == -np.inf
    assert rn.erfcinv(1.0) == 0.0
    for x in (-1e-300, -1.0, 2.0 + 4.5e-16, 3.0, np.nan, np.inf):
        assert np.isnan(rn.erfcinv(x))


# --------------------------------------------------------------------------- resistances
def test_each_resistance_by_hand():
    k_h, r_c = 3.0, 1.0e-4
    assert rn.resistance_contact_surface(k_h, r_c) == pytest.approx(1.0 / 6.0e-4, rel=1e-14)
    sigma, tau, p0, h = 1.4e-6, 0.07, 5.0e7, 5.0e9
    expected = 100.0**0.96 * 1.184 / (PI * 1e-8 * 3.0) * (1.4e-6 / 0.07)
    assert rn.resistance_microcontacts(k_h, r_c, p0, h, sigma, tau) == pytest.approx(expected)
    k_g, a1, a2, m = 0.0263, 1.2, 1.5, 3.4e-7
    expected = (
        2 * SQ2 * sigma * a2 / (PI * k_g * 1e-8 * math.log(1 + a2 / (a1 + m / (2 * SQ2 * sigma))))
    )
    assert rn.resistance_microgap(k_g, r_c, sigma, a1, a2, m) == pytest.approx(expected)
    # solid layer: L/(k A), L = π r/4, A = π (r² - r_c²)
    expected = (PI * 1e-3 / 4) / (2.0 * PI * (1e-6 - 1e-8))
    assert rn.resistance_solid_layer(2.0, 1e-3, r_c) == pytest.approx(expected, rel=1e-14)
    assert rn.resistance_solid_layer(2.0, np.inf, r_c) == 0.0


@pytest.mark.parametrize("b", [0.0, 0.5])
def test_macrogap_by_hand(b):
    k_g, r_h, r_c, m = 0.0263, 1e-3, 1e-4, 3.4e-7
    big_a = 2 * math.sqrt(r_h**2 - r_c**2)
    big_s = 2 * (r_h - r_c**2 / (2 * r_h)) + m
    big_b = b * r_h
    expected = 2 / (
        PI * k_g * (big_s * math.log((big_s - big_b) / (big_s - big_a)) + big_b - big_a)
    )
    assert rn.resistance_macrogap(k_g, r_h, r_c, m, b) == pytest.approx(expected, rel=1e-10)
    assert rn.resistance_macrogap(k_g, r_h, r_c, m, 1.999) == np.inf  # B >= A: no gas region


def test_gas_mean_free_path_and_parameter():
    gas = rn.GasProperties()
    lam = 1.380649e-23 * 300.0 / (SQ2 * PI * (3.66e-10) ** 2 * 101325.0)
    assert gas.mean_free_path_value() == pytest.approx(lam, rel=1e-14)
    assert lam == pytest.approx(6.87e-8, rel=1e-3)  # air at 300 K, 1 atm
    assert rn.GasProperties(mean_free_path=1e-7).mean_free_path_value() == 1e-7
    pr = 1.846e-5 * 1007.0 / 0.0263
    expected = (1.2 / 0.8 + 1.5 / 0.5) * (2 * 1.4 / 2.4) * lam / pr
    assert rn.gas_parameter(0.8, 0.5, gas) == pytest.approx(expected, rel=1e-14)


# ---------------------------------------------------------------------- whole network
def material(**kw) -> Material:
    base = dict(density=2500.0, youngs_modulus=1.0e8, poisson_ratio=0.25, thermal_conductivity=2.0,
                microhardness=5e9, surface_roughness=1e-6, surface_slope=0.05,
                thermal_accommodation=0.8)  # fmt: skip
    base.update(kw)
    return Material(**base)


MAT_I = material()
MAT_J = material(thermal_conductivity=6.0, microhardness=2e9, surface_roughness=2e-6,
                 surface_slope=0.1, thermal_accommodation=0.6, youngs_modulus=2e8)  # fmt: skip


def hand_conductance(r_i, r_j, f, *, h_i=5e9, h_j=2e9, c=1.0, b=0.0):
    """Spec .rst, with the documented choices: P0 = 3F/(2π r_c²) capped at H', a1 >= 0."""
    k_i, k_j = 2.0, 6.0
    e = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    r_eff = r_i if math.isinf(r_j) else r_i * r_j / (r_i + r_j)
    r_c = c * (3 * f * r_eff / (4 * e)) ** (1 / 3)
    k_h = 2 * k_i * k_j / (k_i + k_j)
    h = 2 * h_i * h_j / (h_i + h_j)
    sigma, tau = math.sqrt(1e-12 + 4e-12), math.sqrt(0.05**2 + 0.1**2)
    gas = rn.GasProperties()
    k_g = gas.thermal_conductivity
    m = (1.2 / 0.8 + 1.4 / 0.6) * (2 * 1.4 / 2.4) * gas.mean_free_path_value() / gas.prandtl()
    p0 = min(1.5 * f / (PI * r_c**2), h)
    a1 = float(sp_erfcinv(min(2 * p0 / h, 1.0)))
    a2 = float(sp_erfcinv(0.03 * p0 / h)) - a1
    r_l = 1 / (2 * k_h * r_c)
    r_s = (h / p0) ** 0.96 * 1.184 / (PI * r_c**2 * k_h) * (sigma / tau)
    r_g = (
        2 * SQ2 * sigma * a2 / (PI * k_g * r_c**2 * math.log(1 + a2 / (a1 + m / (2 * SQ2 * sigma))))
    )
    r_cs = (PI * r_i / 4) / (k_i * PI * (r_i**2 - r_c**2))
    if not math.isinf(r_j):
        r_cs += (PI * r_j / 4) / (k_j * PI * (r_j**2 - r_c**2))
    r_h = 2 * r_eff  # = 2 r_i r_j/(r_i + r_j), harmonic mean radius
    big_a = 2 * math.sqrt(r_h**2 - r_c**2)
    big_s = 2 * (r_h - r_c**2 / (2 * r_h)) + m
    big_b = b * r_h
    r_big_g = 2 / (PI * k_g * (big_s * math.log((big_s - big_b) / (big_s - big_a)) + big_b - big_a))
    return 1 / (r_l + 1 / (1 / r_s + 1 / r_g)) + 1 / (r_cs + r_big_g)


def reference_conductance(k_i, k_j, r_i, r_j, f, e, c, h, sigma, tau, k_g, m, b):
    """resistance_network_conductance written out term by term (scipy's erfc⁻¹)."""
    r_eff = r_i if math.isinf(r_j) else r_i * r_j / (r_i + r_j)
    r_c = c * (0.75 * f * r_eff / e) ** (1 / 3)
    r_h = 2 * r_eff
    root = math.sqrt(r_h**2 - r_c**2)
    big_s = 2 * (r_h - r_c**2 / (2 * r_h)) + m
    s_minus_a = m + r_c**4 / (r_h * (r_h + root) ** 2)  # S - A without cancellation
    bracket = big_s * math.log((big_s - b * r_h) / s_minus_a) + b * r_h - 2 * root
    r_big_g = 2 / (PI * k_g * bracket)
    r_cs = (PI * r_i / 4) / (k_i * PI * (r_i**2 - r_c**2))
    if not math.isinf(r_j):
        r_cs += (PI * r_j / 4) / (k_j * PI * (r_j**2 - r_c**2))
    k_h = 2 * k_i * k_j / (k_i + k_j)
    p0 = min(1.5 * f / (PI * r_c**2), h)
    a1 = float(sp_erfcinv(min(2 * p0 / h, 1.0)))
    a2 = float(sp_erfcinv(0.03 * p0 / h)) - a1
    r_l = 1 / (2 * k_h * r_c)
    r_s = (h / p0) ** 0.96 * 1.184 / (PI * r_c**2 * k_h) * (sigma / tau)
    r_g = 2 * SQ2 * sigma * a2 / (PI * k_g * r_c**2 * math.log1p(a2 / (a1 + m / (2 * SQ2 * sigma))))
    return 1 / (r_l + 1 / (1 / r_s + 1 / r_g)) + 1 / (r_cs + r_big_g)


@pytest.mark.parametrize(
    ("r_i", "r_j"), [(1e-4, 1e-4), (1e-3, 3e-3), (1e-2, np.inf), (1e-3, np.inf)]
)
@pytest.mark.parametrize("h", [1e5, 1e9])
@pytest.mark.parametrize(("c", "b"), [(1.0, 0.0), (0.3, 0.5)])
def test_conductance_equals_the_term_by_term_formulas(r_i, r_j, h, c, b):
    """From 1e-9 N to r_c = R*/2, both caps of P0 (soft H' = 1e5) and walls, to 1e-13."""
    args = (2.0, 6.0, r_i, r_j)
    rest = (1.4e-6, 0.14, 0.0263, 3.4e-7, b)
    e = 5.5e6
    r_eff = r_i if math.isinf(r_j) else r_i * r_j / (r_i + r_j)
    f_max = (0.5 * r_eff / c) ** 3 * e / (0.75 * r_eff)
    for f in np.geomspace(1e-9, f_max, 60):
        ours = rn.resistance_network_conductance(*args, f, e, c, h, *rest)
        assert ours == pytest.approx(reference_conductance(*args, f, e, c, h, *rest), rel=1e-13)


def network_row(mi=MAT_I, mj=MAT_J, is_wall=False, **params):
    spec = registry.get("direct_conduction", "resistance_network")
    return spec.pack(spec.params(**params), resolve_pair(mi, mj, is_wall=is_wall))


def heat(p, r_i, r_j, f, overlap=1e-6):
    kernel = registry.get("direct_conduction", "resistance_network").kernel
    return kernel(p, 300.0, 310.0, r_i, r_j, 0.0, overlap, 0.0, f, 0.0, 0.0, 0.0)


@pytest.mark.parametrize(("r_i", "r_j"), [(1e-3, 2e-3), (1e-3, np.inf), (2e-3, 2e-3)])
@pytest.mark.parametrize("f", [1e-3, 0.1, 1.0, 30.0])
def test_network_by_hand(r_i, r_j, f):
    p = network_row(is_wall=math.isinf(r_j))
    assert heat(p, r_i, r_j, f) == pytest.approx(10.0 * hand_conductance(r_i, r_j, f), rel=1e-10)


def test_packing_constant_and_no_contact():
    p = network_row(packing_constant=0.3)
    assert heat(p, 1e-3, 2e-3, 1.0) == pytest.approx(10 * hand_conductance(1e-3, 2e-3, 1.0, b=0.3))
    assert heat(p, 1e-3, 2e-3, 1.0, overlap=-1e-6) == 0.0
    # touching with no force: only the solid layers and the macrogap remain
    r_eff = 2e-3 / 3
    gas = rn.GasProperties()
    m = (1.2 / 0.8 + 1.4 / 0.6) * (2 * 1.4 / 2.4) * gas.mean_free_path_value() / gas.prandtl()
    r_h = 2 * r_eff
    big_s = 2 * r_h + m  # r_c = 0: A = 2 r_h, S - A = M, B = 0
    r_big_g = 2 / (PI * gas.thermal_conductivity * (big_s * math.log(big_s / m) - 2 * r_h))
    r_cs = 1 / (4 * 2.0 * 1e-3) + 1 / (4 * 6.0 * 2e-3)
    assert heat(network_row(), 1e-3, 2e-3, 0.0) == pytest.approx(10 / (r_cs + r_big_g), rel=1e-10)


def test_zhou_correction_only_with_a_real_modulus():
    assert network_row()[5] == 1.0
    soft = material(youngs_modulus_real=6.3e10)
    p = network_row(soft, soft)
    e_sim = 1 / (2 * (1 - 0.25**2) / 1e8)
    e_real = 1 / (2 * (1 - 0.25**2) / 6.3e10)
    assert p[5] == pytest.approx((e_sim / e_real) ** 0.2, rel=1e-14)
    # one material softened, the other taken as not softened (real = simulation modulus)
    p = network_row(soft, MAT_J)
    e_sim = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    e_real = 1 / ((1 - 0.25**2) / 6.3e10 + (1 - 0.25**2) / 2e8)
    assert p[5] == pytest.approx((e_sim / e_real) ** 0.2, rel=1e-14)


def test_missing_surface_property_is_named():
    with pytest.raises(ValueError, match="microhardness"):
        network_row(MAT_I, material(microhardness=None))
    with pytest.raises(ValueError, match="thermal_accommodation"):
        network_row(MAT_I, material(thermal_accommodation=None), is_wall=True)


def test_plastic_limit_caps_are_continuous_and_finite():
    """2P0/H' >= 1 (a1 capped at 0) and P0 >= H' (P0 capped): finite, continuous, hand value."""
    h = 5e5  # soft surfaces: the caps are reached at moderate forces
    mi, mj = material(microhardness=h), material(
        microhardness=h, thermal_conductivity=6.0, surface_roughness=2e-6, surface_slope=0.1,
        thermal_accommodation=0.6, youngs_modulus=2e8,
    )  # fmt: skip
    p = network_row(mi, mj)
    r_i, r_j = 1e-3, 2e-3
    r_eff = r_i * r_j / (r_i + r_j)
    e = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    # P0 = 1.5 F / (π r_c²) = 1.5 F^{1/3} / (π (3 R*/(4E*))^{2/3})  ->  F where P0 = target
    force_at = lambda target: (target * PI * (0.75 * r_eff / e) ** (2 / 3) / 1.5) ** 3  # noqa: E731
    for f_cap in (force_at(h / 2), force_at(h)):
        lo, hi = heat(p, r_i, r_j, f_cap * (1 - 1e-9)), heat(p, r_i, r_j, f_cap * (1 + 1e-9))
        assert np.isfinite(lo) and np.isfinite(hi)
        assert hi == pytest.approx(lo, rel=1e-6)
    for f in (force_at(0.3 * h), force_at(0.7 * h), force_at(2.0 * h), force_at(5.0 * h)):
        expected = 10 * hand_conductance(r_i, r_j, f, h_i=h, h_j=h)
        assert heat(p, r_i, r_j, f) == pytest.approx(expected, rel=1e-10)


def test_conductance_increases_with_force_for_glass_beads_in_air():
    p = network_row()
    q = [heat(p, 1e-3, 2e-3, f) for f in np.logspace(-4, 3, 200)]
    assert np.all(np.diff(q) > 0)


def test_solid_layer_beyond_validity_blocks_instead_of_reversing() -> None:
    """r_c >= r: no cross-section left (infinite resistance, the limit r_c -> r), so the
    conductance stays positive; the case Hypothesis found: a 0.2 mm sphere on a wall, 3 N."""
    assert rn.resistance_solid_layer(1.0, 1e-3, 1e-3) == np.inf
    assert rn.resistance_solid_layer(1.0, 1e-3, 2e-3) == np.inf
    assert rn.resistance_solid_layer(1.0, 1e-3, 0.999e-3) > 0.0
    # k_i, k_j, r_i, r_j, F_n, E*, c, H', sigma, tau, k_g, M, B/r_h
    h = rn.resistance_network_conductance(
        1.0, 20.0, 2e-4, np.inf, 3.0625, 5e6, 1.0, 3e9, 1e-6, 0.1, 0.0263, 3e-7, 0.0
    )
    assert h > 0.0 and np.isfinite(h)


# ------------------------------------------------------------ maximum pressure P_0 (issue 17)
def spec_conductance(r_i, r_j, f, overlap, mode, *, e_real_i=None, e_real_j=None):
    """The network of MAT_I and MAT_J written out from the spec (.rst) with scipy's erfc⁻¹;
    P_0 by ``mode``: 'force' 3F/(2π r_c²), 'overlap' 2 E*_real δ (E*/E*_real)^{2/3}/(π r_c)
    (Lethe's form; the spec's 2E*δ/(π r_c) when not softened); both capped as documented."""
    k_i, k_j, nu = 2.0, 6.0, 0.25
    e = 1 / ((1 - nu**2) / 1e8 + (1 - nu**2) / 2e8)
    e_real = 1 / ((1 - nu**2) / (e_real_i or 1e8) + (1 - nu**2) / (e_real_j or 2e8))
    c = (e / e_real) ** 0.2
    r_eff = r_i if math.isinf(r_j) else r_i * r_j / (r_i + r_j)
    r_c = c * (3 * f * r_eff / (4 * e)) ** (1 / 3)
    if mode == "force":
        p0 = 3 * f / (2 * PI * r_c**2)
    else:
        p0 = 2 * e_real * overlap * (e / e_real) ** (2 / 3) / (PI * r_c)
    h = 2 * 5e9 * 2e9 / (5e9 + 2e9)
    p0 = min(p0, h)
    k_h = 2 * k_i * k_j / (k_i + k_j)
    sigma, tau = math.sqrt(1e-12 + 4e-12), math.sqrt(0.05**2 + 0.1**2)
    gas = rn.GasProperties()
    k_g = gas.thermal_conductivity
    m_gas = (1.2 / 0.8 + 1.4 / 0.6) * (2 * 1.4 / 2.4) * gas.mean_free_path_value() / gas.prandtl()
    a1 = float(sp_erfcinv(min(2 * p0 / h, 1.0)))
    a2 = float(sp_erfcinv(0.03 * p0 / h)) - a1
    r_l = 1 / (2 * k_h * r_c)
    r_s = (h / p0) ** 0.96 * 1.184 / (PI * r_c**2 * k_h) * (sigma / tau)
    s2 = 2 * SQ2 * sigma
    r_g = s2 * a2 / (PI * k_g * r_c**2 * math.log(1 + a2 / (a1 + m_gas / s2)))
    r_cs = (PI * r_i / 4) / (k_i * PI * (r_i**2 - r_c**2))
    if not math.isinf(r_j):
        r_cs += (PI * r_j / 4) / (k_j * PI * (r_j**2 - r_c**2))
    r_h = 2 * r_eff
    big_a = 2 * math.sqrt(r_h**2 - r_c**2)
    big_s = 2 * (r_h - r_c**2 / (2 * r_h)) + m_gas
    r_big_g = 2 / (PI * k_g * (big_s * math.log(big_s / (big_s - big_a)) - big_a))
    return 1 / (r_l + 1 / (1 / r_s + 1 / r_g)) + 1 / (r_cs + r_big_g)


def test_pressure_mode_columns():
    p = network_row()
    assert p[rn.COL_P0_MODE] == rn.P0_FORCE  # the default
    e = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    assert p[rn.COL_P0_OVERLAP_FACTOR] == pytest.approx(2 * e / PI, rel=1e-14)
    soft = material(youngs_modulus_real=6.3e10)
    p = network_row(soft, MAT_J, maximum_pressure="overlap")
    assert p[rn.COL_P0_MODE] == rn.P0_OVERLAP
    e_real = 1 / ((1 - 0.25**2) / 6.3e10 + (1 - 0.25**2) / 2e8)
    factor = 2 * e_real * (e / e_real) ** (2 / 3) / PI
    assert p[rn.COL_P0_OVERLAP_FACTOR] == pytest.approx(factor, rel=1e-14)
    assert p.shape == (len(rn.COLUMNS),)
    with pytest.raises(ValueError, match="maximum_pressure"):
        rn.ResistanceNetworkParams(maximum_pressure="hertz")


@pytest.mark.parametrize("mode", ["force", "overlap"])
@pytest.mark.parametrize("softened", [False, True])
@pytest.mark.parametrize(("r_i", "r_j"), [(1e-3, 2e-3), (1e-3, np.inf)])
def test_both_pressures_equal_the_spec_written_out(mode, softened, r_i, r_j):
    """Forces from 1e-4 N to past the plastic caps, overlaps off the Hertz value by ±30 %."""
    real = {"youngs_modulus_real": 6.3e10} if softened else {}
    mi, mj = material(**real), MAT_J
    p = network_row(mi, mj, is_wall=math.isinf(r_j), maximum_pressure=mode)
    r_eff = r_i if math.isinf(r_j) else r_i * r_j / (r_i + r_j)
    e = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    for f in np.geomspace(1e-4, 30.0, 12):
        hertz = (3 * f / (4 * e * math.sqrt(r_eff))) ** (2 / 3)
        for overlap in (0.7 * hertz, hertz, 1.3 * hertz):
            expected = spec_conductance(
                r_i, r_j, f, overlap, mode, e_real_i=real.get("youngs_modulus_real")
            )
            assert heat(p, r_i, r_j, f, overlap) == pytest.approx(10 * expected, rel=1e-11)


def test_overlap_form_is_the_spec_line_without_softening():
    """No youngs_modulus_real: P_0 = 2E*δ/(π r_c), the spec's line; for a Hertz contact
    (F = (4/3) E* sqrt(R*) δ^{3/2}) both forms give the same conductance."""
    e = 1 / ((1 - 0.25**2) / 1e8 + (1 - 0.25**2) / 2e8)
    r_i, r_j = 1e-3, 2e-3
    r_eff = r_i * r_j / (r_i + r_j)
    by_force = network_row(maximum_pressure="force")
    by_overlap = network_row(maximum_pressure="overlap")
    for overlap in np.geomspace(1e-8, 1e-5, 7):
        f = 4 / 3 * e * math.sqrt(r_eff) * overlap**1.5
        h_overlap = heat(by_overlap, r_i, r_j, f, overlap)
        assert h_overlap == pytest.approx(heat(by_force, r_i, r_j, f, overlap), rel=1e-12)
        assert h_overlap == pytest.approx(10 * spec_conductance(r_i, r_j, f, overlap, "force"))


def test_lethe_unit_test_case():
    """Lethe's particle_particle_thermal_resistances test (chaos-polymtl/lethe, tests/dem):
    two 10 mm spheres, E = 5 MPa, E_real = 65 GPa, ν = 0.22, δ = 0.1 mm, Hertz force; its
    output: total conductance 0.00294375 W/K. The overlap form reproduces it (to 5e-6: Lethe
    prints 6 digits, and its printed microgap resistance 1087.75 differs from the formula with
    the test's gas parameter, 1089.96, by 2e-3, which moves H by 7e-6); the force form gives
    P_0 (E*_real/E*)^{-2/15} = 0.28 times smaller and H 1.3e-3 lower."""
    nu, e_sim, e_real, radius, overlap = 0.22, 5e6, 65e9, 5e-3, 1e-4
    glass = material(
        youngs_modulus=e_sim, poisson_ratio=nu, youngs_modulus_real=e_real,
        thermal_conductivity=1.0, microhardness=9e9, surface_roughness=25e-9 / SQ2,
        surface_slope=0.078 / SQ2, thermal_accommodation=0.7,
    )  # fmt: skip
    gas = rn.GasProperties(
        thermal_conductivity=0.027, dynamic_viscosity=1.85e-5, specific_heat=1006.0,
        mean_free_path=68e-9,
    )  # fmt: skip
    # Lethe's test takes γ = 1 (2γ/(1+γ) = 1): M = 2 (2 - α)/α Λ/Pr
    m_gas = 2 * (2 - 0.7) / 0.7 * 68e-9 / (1.85e-5 * 1006.0 / 0.027)
    e_star = e_sim / (2 * (1 - nu**2))
    force = 4 / 3 * e_star * math.sqrt(radius / 2) * overlap**1.5
    spec = registry.get("direct_conduction", "resistance_network")
    out = {}
    for mode in ("force", "overlap"):
        p = spec.pack(spec.params(maximum_pressure=mode), resolve_pair(glass, glass, gas=gas))
        p[10] = m_gas
        out[mode] = spec.kernel(p, 0.0, 1.0, radius, radius, 0.0, overlap, 0.0, force, 0, 0, 0)
    assert out["overlap"] == pytest.approx(0.00294375, rel=1e-5)
    assert out["force"] / 0.00294375 - 1.0 == pytest.approx(-1.29e-3, abs=0.05e-3)
