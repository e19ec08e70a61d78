"""Indirect conduction models (gas between near particles) against references that are not the
code: scipy.integrate.quad of the spec's integrals written out here in plain numpy, the spec's
own closed forms and limits, and hand computations (spec "Static Contact Models – particles
separated", "Surrounding Layer Models", "Other Conduction Models – Vargas & McCarthy")."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from pydantic import ValidationError
from scipy.integrate import IntegrationWarning, quad

from thermodem.models import registry
from thermodem.models.thermal import indirect_conduction as ic
from thermodem.models.thermal import vargas_mccarthy as vm
from thermodem.models.thermal.batchelor_obrien_contact import bob_complete_rate, pack_bob_complete
from thermodem.models.thermal.contact_radius import geometric_contact_radius
from thermodem.state.gas import GasProperties
from thermodem.state.materials import Material, resolve_pair

PI = math.pi
INF = math.inf
FAMILY = "indirect_conduction"
RANGE_MODELS = ("batchelor_obrien_separated", "rong_horio1999", "musser2011")
ALL_MODELS = (*RANGE_MODELS, "vargas_mccarthy2002")


def material(**kw) -> Material:
    base = dict(density=2500.0, youngs_modulus=1.0e8, poisson_ratio=0.25, specific_heat=800.0,
                thermal_conductivity=2.0, thermal_accommodation=0.8)  # fmt: skip
    base.update(kw)
    return Material(**base)


MAT_A = material(thermal_conductivity=2.0, thermal_accommodation=0.8)
MAT_B = material(thermal_conductivity=6.0, thermal_accommodation=0.5)


def spec_of(model: str) -> registry.ModelSpec:
    return registry.get(FAMILY, model)


def row(model: str, mi=MAT_A, mj=MAT_B, is_wall=False, gas=None, **params) -> np.ndarray:
    spec = spec_of(model)
    pair = resolve_pair(mi, mj, is_wall=is_wall, gas=gas)
    return spec.pack(spec.params(**params), pair)


def conductance(model: str, p, r_i, r_j, dist, r_c=0.0, f_n=0.0) -> float:
    return spec_of(model).kernel(p, r_i, r_j, dist, r_c, f_n)


def layer_row(model: str, k_f=1.0, ratio=0.4, s_min=2.75e-8, contact_term=None) -> np.ndarray:
    values = [k_f, ratio, s_min]
    if model == "rong_horio1999":
        values.append(1.0 if contact_term else 0.0)
    return np.array(values)


def quad_pieces(f, a: float, b: float) -> float:
    """∫_a^b f with breakpoints a + (b - a) 10^-k: the integrands peak sharply at a."""
    if not b > a:
        return 0.0
    edges = [a, *(a + (b - a) * 10.0**-k for k in range(14, 0, -1)), b]
    total = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            total += quad(f, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return total


def bisect(g, lo: float, hi: float) -> float:
    """The root of an increasing g in [lo, hi] to the last bit."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


# ------------------------------------------------------------- references from the spec
def musser_reference(r_i, r_j, d, r_c, ratio, s_min) -> float:
    """Spec (Musser 2011): ∫_{R_c}^{R_f} 2πr / max(S, d - √(R_i² - r²) - √(R_j² - r²)) dr.

    d_f = (d - R_i - R_j) + (R_i - √(R_i² - r²)) + (R_j - √(R_j² - r²)), each R - √(R² - r²)
    written r²/(R + √(R² - r²)) (no cancellation near the axis), from the same gap
    d - (R_i + R_j) the kernel sees.
    """
    r_k, r_l = max(r_i, r_j), min(r_i, r_j)
    gap = d - (r_i + r_j)
    if gap >= ratio * r_k:
        return 0.0
    a = r_k + ratio * r_k
    if d <= math.sqrt(a * a - r_l * r_l):
        r_f = r_l
    else:
        r_f = math.sqrt(a * a - ((a * a - r_l * r_l + d * d) / (2 * d)) ** 2)
    lo = r_c if gap <= 0 else 0.0

    def d_f(r: float) -> float:
        r2 = r * r
        s_i = math.sqrt(max((r_i - r) * (r_i + r), 0.0))
        s_j = math.sqrt(max((r_j - r) * (r_j + r), 0.0))
        return gap + r2 / (r_i + s_i) + r2 / (r_j + s_j)

    return _split_at_s(lambda r: 2 * PI * r / max(s_min, d_f(r)), d_f, lo, r_f, s_min)


def _split_at_s(f, d_f, lo: float, hi: float, s_min: float) -> float:
    """∫_lo^hi f split where d_f = S (the kink of max(S, d_f))."""
    if not hi > lo:
        return 0.0
    if d_f(lo) < s_min < d_f(hi):
        mid = bisect(lambda r: d_f(r) - s_min, lo, hi)
        return quad_pieces(f, lo, mid) + quad_pieces(f, mid, hi)
    return quad_pieces(f, lo, hi)


def musser_wall_reference(r, d, r_c, ratio, s_min) -> float:
    """Spec ("Interaction with walls"): ∫_{R_c}^{R_f} 2πr / max(S, d - √(R² - r²)) dr,
    R_f = √((R + δ_f)² - d²) limited to R."""
    gap = d - r
    if gap >= ratio * r:
        return 0.0
    r_f = min(r, math.sqrt((r + ratio * r) ** 2 - d * d))
    lo = r_c if gap <= 0 else 0.0

    def d_f(x: float) -> float:
        return gap + x * x / (r + math.sqrt(max((r - x) * (r + x), 0.0)))

    return _split_at_s(lambda x: 2 * PI * x / max(s_min, d_f(x)), d_f, lo, r_f, s_min)


def rong_horio_reference(r_p, d, ratio, s_min, contact_term, regularised=True) -> float:
    """Spec (Rong & Horio 1999), the θ form: ∫_{θ1}^{θ2} 2πR sinθ / (d - 2R cosθ) d(R sinθ)
    [+ π (R sin θ1)²/S touching], the denominator max(S, ·) when ``regularised``."""
    delta = ratio * r_p
    if d >= 2 * r_p + delta:
        return 0.0
    cos2 = (d * d + r_p * r_p - (r_p + delta) ** 2) / (2 * r_p * d)
    theta2 = math.acos(min(max(cos2, 0.0), 1.0))
    touching = d <= 2 * r_p
    if touching:  # acos(1 - x) written 2 asin(√(x/2)), exact near x = 0
        theta_c = 2 * math.asin(math.sqrt(max(2 * r_p - d, 0.0) / (4 * r_p)))
        theta1 = max(theta_c, 2 * math.asin(math.sqrt(s_min / (4 * r_p))))
    else:
        theta1 = 0.0
    gap = d - 2 * r_p

    def path(t: float) -> float:  # d - 2R cos θ = gap + 2R (1 - cos θ) = gap + 4R sin²(θ/2)
        return gap + 4 * r_p * math.sin(0.5 * t) ** 2

    def f(t: float) -> float:
        y = max(s_min, path(t)) if regularised else path(t)
        return 2 * PI * r_p * math.sin(t) / y * r_p * math.cos(t)

    total = _split_at_s(f, path, theta1, theta2, s_min)
    if touching and contact_term:
        total += PI * (r_p * math.sin(theta1)) ** 2 / s_min
    return total


def spec_wall_analytic(r_p, d_pw, ratio, s_min) -> float:
    """The spec's particle-wall solution, written as printed (Morris 2015; Lattanzi & Hrenya
    2017; Lu et al. 2017): 2π R ((a + 1) ln(|b - a - 1|/|a - c + 1|) + b - c) [per k_f]."""
    delta = ratio * r_p
    a = (d_pw - r_p) / r_p
    r_in = 0.0 if d_pw > r_p + s_min else math.sqrt(1 - (s_min / r_p - a - 1) ** 2)
    limit = math.sqrt(((r_p + delta) / r_p) ** 2 - 1) - 1
    r_out = math.sqrt(((r_p + delta) / r_p) ** 2 - (a + 1) ** 2) if a > limit else 1.0
    b = math.sqrt(1 - r_out**2)
    c = math.sqrt(1 - r_in**2)
    return 2 * PI * r_p * ((a + 1) * math.log(abs(b - a - 1) / abs(a - c + 1)) + b - c)


def wall_analytic_reference(r, d, ratio, s_min) -> float:
    """quad of the integral the spec's analytic wall form solves: ∫_{r_in}^{r_out} 2πr/d_f."""
    gap = d - r
    r_out = min(r, math.sqrt((r + ratio * r) ** 2 - d * d))
    r_in = 0.0 if gap > s_min else math.sqrt((r - d + s_min) * (r + d - s_min))

    def d_f(x: float) -> float:
        return gap + x * x / (r + math.sqrt(max((r - x) * (r + x), 0.0)))

    return quad_pieces(lambda x: 2 * PI * x / d_f(x), r_in, r_out)


# ------------------------------------------------------------------- random parameter sets
def random_pair(rng, equal: bool, wall: bool = False):
    """Radii 0.1-10 mm (ratio 1-5), layer ratio 0.05-1, S 1e-10-1e-5 m, and a gap from deep
    overlap through touching to the end of the range (uniform or log-spaced near 0)."""
    r_i = 10 ** rng.uniform(-4, -2)
    r_j = INF if wall else (r_i if equal else r_i * rng.uniform(1, 5))
    if not wall and rng.random() < 0.5:
        r_i, r_j = r_j, r_i
    ratio = rng.uniform(0.05, 1.0)
    s_min = 10 ** rng.uniform(-10, -5)
    r_small = min(r_i, r_j)
    reach = ratio * (r_i if wall else max(r_i, r_j))
    mode = rng.integers(4)
    if mode == 0:
        gap = rng.uniform(0, reach)
    elif mode == 1:
        gap = 10 ** rng.uniform(-13, math.log10(reach))
    elif mode == 2:
        gap = -(10 ** rng.uniform(-12, math.log10(0.05 * r_small)))
    else:
        gap = s_min * rng.uniform(-2, 2)  # around the minimum separation
    d = r_i + gap if wall else r_i + r_j + gap
    overlap = (r_i - d) if wall else (r_i + r_j) - d
    r_c = geometric_contact_radius(r_i, r_j, overlap) if overlap > 0 else 0.0
    if rng.random() < 0.2:  # another contact radius model (a contacts pair set)
        r_c *= rng.uniform(0.5, 1.5)
    return r_i, r_j, d, r_c, ratio, s_min


def relative_error(h: float, ref: float) -> float:
    return abs(h - ref) / ref if ref > 0 else abs(h)


@pytest.mark.parametrize(("equal", "n"), [(True, 600), (False, 2400)])
def test_musser_closed_form_matches_quad_of_the_spec_integral(equal, n):
    rng = np.random.default_rng(2011 + equal)
    worst = 0.0
    for _ in range(n):
        r_i, r_j, d, r_c, ratio, s_min = random_pair(rng, equal)
        h = conductance("musser2011", layer_row("musser2011", 1.0, ratio, s_min), r_i, r_j, d, r_c)
        ref = musser_reference(r_i, r_j, d, r_c, ratio, s_min)
        err = relative_error(h, ref)
        worst = max(worst, err)
        assert err < 1e-8, (r_i, r_j, d, r_c, ratio, s_min, h, ref)
    print(f"musser2011 {'equal' if equal else 'unequal'} radii: max rel. error {worst:.2e}")


def test_musser_wall_matches_quad_of_the_spec_integral():
    rng = np.random.default_rng(2015)
    worst = 0.0
    for _ in range(800):
        r, _, d, r_c, ratio, s_min = random_pair(rng, False, wall=True)
        p = layer_row("musser2011", 1.0, ratio, s_min)
        ref = musser_wall_reference(r, d, r_c, ratio, s_min)
        err = relative_error(conductance("musser2011", p, r, INF, d, r_c), ref)
        worst = max(worst, err)
        assert err < 1e-8, (r, d, r_c, ratio, s_min, ref)
    print(f"musser2011 wall: max rel. error {worst:.2e}")


def test_rong_horio_matches_quad_of_the_spec_integrand():
    """The θ form of the spec, with θ1, θ2 and the contact term as printed; the denominator is
    max(S, ·) (Musser's remedy). Where every path is at least S long (separated by >= S) the
    kernel equals the spec's literal integrand."""
    rng = np.random.default_rng(1999)
    worst = 0.0
    literal = 0
    for k in range(1500):
        r_i, r_j, d, _, ratio, s_min = random_pair(rng, equal=k % 3 == 0)
        r_p = 0.5 * (r_i + r_j)
        d = 2 * r_p + (d - (r_i + r_j))  # the same surface gap for the mean-radius pair
        contact = bool(rng.integers(2))
        p = layer_row("rong_horio1999", 1.0, ratio, s_min, contact)
        h = conductance("rong_horio1999", p, r_i, r_j, d)
        ref = rong_horio_reference(r_p, d, ratio, s_min, contact)
        worst = max(worst, relative_error(h, ref))
        assert relative_error(h, ref) < 1e-8, (r_i, r_j, d, ratio, s_min, contact, h, ref)
        if d - 2 * r_p >= s_min and ref > 0:
            literal += 1
            plain = rong_horio_reference(r_p, d, ratio, s_min, contact, regularised=False)
            assert relative_error(h, plain) < 1e-8
    assert literal > 300
    print(f"rong_horio1999: max rel. error {worst:.2e} ({literal} sets with the literal form)")


def test_rong_horio_closed_form_by_hand():
    """u = cos θ: ∫ 2π R² u/(d - 2R u) du = π R [a ln((a - u2)/(a - u1)) - (u1 - u2)],
    a = d/(2R) (docstring of rong_horio1999_conductance), for a separated pair."""
    r, gap, ratio = 1e-3, 2e-5, 0.4
    d = 2 * r + gap
    a = d / (2 * r)
    u2 = (d * d + r * r - (r + ratio * r) ** 2) / (2 * r * d)
    by_hand = PI * r * (a * math.log((a - u2) / (a - 1.0)) - (1.0 - u2))
    p = layer_row("rong_horio1999", 1.0, ratio, 1e-9)
    assert conductance("rong_horio1999", p, r, r, d) == pytest.approx(by_hand, rel=1e-13)


def test_rong_horio_wall_is_the_spec_analytic_solution():
    rng = np.random.default_rng(2017)
    worst = 0.0
    for _ in range(600):
        r, _, d, r_c, ratio, s_min = random_pair(rng, False, wall=True)
        if d - s_min <= 0:
            continue
        p = layer_row("rong_horio1999", 1.0, ratio, s_min, False)
        h = conductance("rong_horio1999", p, r, INF, d, r_c)
        ref = wall_analytic_reference(r, d, ratio, s_min)
        worst = max(worst, relative_error(h, ref))
        assert relative_error(h, ref) < 1e-8, (r, d, ratio, s_min, h, ref)
        printed = spec_wall_analytic(r, d, ratio, s_min)
        # the printed form loses digits to b - a - 1 for small gaps: 1e-6 of its own
        assert h == pytest.approx(printed, rel=1e-6, abs=1e-6 * r)
        # with the contact term: the sub-S disk conducts through S = Musser's integral from 0
        p1 = layer_row("rong_horio1999", 1.0, ratio, s_min, True)
        h1 = conductance("rong_horio1999", p1, r, INF, d, r_c)
        assert relative_error(h1, musser_wall_reference(r, d, 0.0, ratio, s_min)) < 1e-8
    print(f"rong_horio1999 wall: max rel. error {worst:.2e}")


def test_rong_horio_equals_musser_for_equal_radii_except_near_contact():
    """Both integrate 2πr/max(S, d_f); for equal radii they differ only where the spec's θ1
    (θ_S for overlaps below S) differs from the contact circle, and by the contact term."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        r_i, _, d, _, ratio, s_min = random_pair(rng, equal=True)
        overlap = 2 * r_i - d
        if 0 < overlap <= s_min:
            continue
        r_c = geometric_contact_radius(r_i, r_i, overlap) if overlap > 0 else 0.0
        rh = conductance(
            "rong_horio1999", layer_row("rong_horio1999", 1, ratio, s_min), r_i, r_i, d
        )
        mu = conductance("musser2011", layer_row("musser2011", 1, ratio, s_min), r_i, r_i, d, r_c)
        assert rh == pytest.approx(mu, rel=1e-9, abs=1e-300)


# ------------------------------------------------------------------ continuity at contact
def _around_contact(model, p, r_i, r_j, eps):
    wall = math.isinf(r_j)
    touch = r_i if wall else r_i + r_j
    out = []
    for d in (touch + eps, touch, touch - eps):
        overlap = touch - d
        r_c = geometric_contact_radius(r_i, r_j, overlap) if overlap > 0 else 0.0
        out.append(conductance(model, p, r_i, r_j, d, r_c))
    return out


@pytest.mark.parametrize(("r_i", "r_j"), [(1e-3, 1e-3), (1e-3, 3e-3), (1e-3, INF)])
def test_surrounding_layer_is_continuous_at_contact(r_i, r_j):
    s_min = 2.75e-8
    eps = 1e-6 * s_min
    for model, contact in (("musser2011", None), ("rong_horio1999", True)):
        h = _around_contact(model, layer_row(model, 1.0, 0.4, s_min, contact), r_i, r_j, eps)
        assert h[0] == pytest.approx(h[1], rel=1e-5) and h[2] == pytest.approx(h[1], rel=1e-5)
    # Rong & Horio without its contact term: the wall form is continuous; two spheres lose,
    # at first contact, the disk of paths shorter than S, π k_f (R_p² sin²θ_S)/S
    p = layer_row("rong_horio1999", 1.0, 0.4, s_min, False)
    above, at, below = _around_contact("rong_horio1999", p, r_i, r_j, eps)
    assert below == pytest.approx(at, rel=1e-5)
    if math.isinf(r_j):
        assert above == pytest.approx(at, rel=1e-5)
    else:
        r_p = 0.5 * (r_i + r_j)
        assert above - at == pytest.approx(PI * (r_p - s_min / 4), rel=1e-4)


# --------------------------------------------------------------- generic model properties
def packed(model, is_wall=False):
    params = {"filling_angle": 0.4, "liquid_conductivity": 0.6} if model.startswith("v") else {}
    return row(model, MAT_A, MAT_B, is_wall=is_wall, **params)


@pytest.mark.parametrize("model", ALL_MODELS)
def test_nonnegative_finite_and_symmetric_bit_for_bit(model):
    spec = spec_of(model)
    p = packed(model)
    swapped = p.copy()
    for a, b in spec.swap_pairs:
        swapped[a], swapped[b] = p[b], p[a]
    assert p.shape == (len(spec.columns),)
    rng = np.random.default_rng(3)
    positive = 0
    for _ in range(3000):
        r_i, r_j, d, r_c, _, _ = random_pair(rng, equal=bool(rng.integers(2)))
        if rng.random() < 0.1:
            r_c = rng.uniform(0, min(r_i, r_j))  # any contact radius: the contacts pair set
        h = conductance(model, p, r_i, r_j, d, r_c)
        assert math.isfinite(h) and h >= 0.0, (r_i, r_j, d, r_c, h)
        assert conductance(model, swapped, r_j, r_i, d, r_c) == h
        positive += h > 0
        hw = conductance(model, packed(model, True), r_i, INF, r_i + (d - r_i - r_j), r_c)
        assert math.isfinite(hw) and hw >= 0.0
    assert positive > 500


@pytest.mark.parametrize("model", RANGE_MODELS)
@pytest.mark.parametrize(("r_i", "r_j"), [(1e-3, 1e-3), (1e-3, 4e-3), (2e-3, INF)])
def test_zero_beyond_the_registered_interaction_range(model, r_i, r_j):
    spec = spec_of(model)
    p = packed(model, math.isinf(r_j))
    reach = spec.interaction_range(spec.params(), r_i, r_j)
    touch = r_i if math.isinf(r_j) else r_i + r_j
    assert conductance(model, p, r_i, r_j, touch + reach * (1 - 1e-6)) > 0.0
    assert conductance(model, p, r_i, r_j, touch + reach * (1 + 1e-9)) == 0.0
    assert conductance(model, p, r_i, r_j, touch + 3 * reach) == 0.0


def test_vargas_mccarthy_range_is_touching_only():
    spec = spec_of("vargas_mccarthy2002")
    assert spec.interaction_range(spec.params(), 1e-3, 1e-3) == 0.0
    p = packed("vargas_mccarthy2002")
    assert conductance("vargas_mccarthy2002", p, 1e-3, 1e-3, 2e-3 + 1e-12, 0.0) == 0.0
    assert conductance("vargas_mccarthy2002", p, 1e-3, 1e-3, 2e-3, 0.0) > 0.0


@pytest.mark.parametrize("model", ALL_MODELS)
@pytest.mark.parametrize("wall", [False, True])
def test_vanishes_with_the_gas_conductivity(model, wall):
    """H(k_f -> 0) -> 0 (gas paths only: V&M with φ = 0)."""
    r_i, r_j = 1e-3, (INF if wall else 2e-3)
    gap = -1e-7 if model == "vargas_mccarthy2002" else 1e-5
    d = r_i + gap if wall else r_i + r_j + gap
    r_c = geometric_contact_radius(r_i, r_j, -gap) if gap < 0 else 0.0
    values = []
    for k_f in (1e-2, 1e-4, 1e-6):
        gas = GasProperties(thermal_conductivity=k_f)
        p = row(model, MAT_A, MAT_B, is_wall=wall, gas=gas)
        values.append(conductance(model, p, r_i, r_j, d, r_c))
    assert values[0] > 0 and values[1] < 0.1 * values[0] and values[2] < 1e-3 * values[0]


# ------------------------------------------------------- Batchelor & O'Brien, separated
K10 = material(thermal_conductivity=10.0)
AIR01 = GasProperties(thermal_conductivity=0.1)  # k_pf = 100, k_pf² = 1e4


def bob_h(gap, r_i=1e-3, r_j=1e-3, **params):
    p = row("batchelor_obrien_separated", K10, K10, is_wall=math.isinf(r_j), gas=AIR01, **params)
    d = r_i + gap if math.isinf(r_j) else r_i + r_j + gap
    return conductance("batchelor_obrien_separated", p, r_i, r_j, d)


R_BAR = 0.5e-3  # two 1 mm spheres; λ = 1e4 d_s / (2 R̄) = 1e7 d_s


@pytest.mark.parametrize(
    ("regime", "gap", "which"),
    [
        ("dai2019", 1e-10, "near"),  # λ = 1e-3
        ("dai2019", 1e-4, "far"),  # λ = 1e3
        ("dai2019", 1e-6, "min"),  # λ = 10
        ("moscardini2018", 5e-9, "near"),  # λ = 0.05
        ("moscardini2018", 5e-8, "far"),  # λ = 0.5
        ("minimum", 1e-10, "min"),
        ("minimum", 1e-4, "min"),
    ],
)
@pytest.mark.parametrize("cylinder", ["kanuparthi2008", "moscardini2018", "dai2019", 0.7])
def test_bob_separated_regimes_by_hand(regime, gap, which, cylinder):
    ratio = {"kanuparthi2008": 1.0, "moscardini2018": 1.42, "dai2019": 2.0}.get(cylinder, cylinder)
    near = math.log(1e4)
    far = math.log(1 + (ratio * R_BAR) ** 2 / (2 * R_BAR * gap))
    x = {"near": near, "far": far, "min": min(near, far)}[which]
    h = bob_h(gap, regime=regime, cylinder_radius=cylinder)
    assert h == pytest.approx(2 * PI * R_BAR * 0.1 * x, rel=1e-13)


def test_bob_separated_dai_thresholds_with_a_thin_cylinder():
    """r̄ = 0.1 R̄: the minimum is the far form already at λ = 0.009, so only the λ < 0.01 rule
    gives the near form there (the thresholds matter, not only the minimum)."""
    near = math.log(1e4)
    for lam, expected in ((0.009, near), (0.015, None), (150.0, None)):
        gap = lam / 1e7
        far = math.log1p(0.01 * R_BAR**2 / (2 * R_BAR * gap))
        x = expected if expected is not None else (far if lam > 100 else min(near, far))
        assert bob_h(gap, cylinder_radius=0.1) == pytest.approx(2 * PI * R_BAR * 0.1 * x, rel=1e-13)
    assert far < near


def test_bob_separated_regime_boundaries():
    """dai2019 is continuous at λ = 0.01 and 100 for 0.2 <= r̄/R̄ < 20 √(1 - 1/k_pf²) (the
    minimum is already the near form below 0.01 and the far form above 100); at 20 it jumps by
    2π R̄ k_f ln(1 + 1/k_pf²). moscardini2018 jumps at λ = 0.1."""
    for c in (0.2, 1.0, 1.42, 2.0, 19.99):
        for lam in (0.01, 100.0):
            below = bob_h(lam * (1 - 1e-9) / 1e7, cylinder_radius=c)
            above = bob_h(lam * (1 + 1e-9) / 1e7, cylinder_radius=c)
            assert above == pytest.approx(below, rel=1e-6)
    below = bob_h(100 * (1 - 1e-9) / 1e7, cylinder_radius=20.0)
    above = bob_h(100 * (1 + 1e-9) / 1e7, cylinder_radius=20.0)
    assert above - below == pytest.approx(2 * PI * R_BAR * 0.1 * math.log1p(1e-4), rel=1e-4)
    below = bob_h(0.1 * (1 - 1e-9) / 1e7, regime="moscardini2018", cylinder_radius=1.42)
    above = bob_h(0.1 * (1 + 1e-9) / 1e7, regime="moscardini2018", cylinder_radius=1.42)
    jump = math.log(1 + 1.42**2 * 1e4 / 0.4) - math.log(1e4)  # far - near at λ = 0.1
    assert (above - below) == pytest.approx(2 * PI * R_BAR * 0.1 * jump, rel=1e-6)
    assert jump > 1.6


def test_bob_separated_touching_cutoff_and_contact_limit():
    assert bob_h(0.0) == 0.0 and bob_h(-1e-6) == 0.0  # contact: the direct model's
    assert bob_h(R_BAR * (1 - 1e-9)) > 0.0 and bob_h(R_BAR) == 0.0  # d_s < 1.00 R̄
    assert bob_h(0.5 * R_BAR * (1 - 1e-9), cutoff_gap_ratio=0.5) > 0.0
    assert bob_h(0.5 * R_BAR, cutoff_gap_ratio=0.5) == 0.0
    # d_s -> 0: 2π R̄ k_f ln k_pf², batchelor_obrien_complete's contact value at η = 0
    limit = 2 * PI * R_BAR * 0.1 * math.log(1e4)
    assert bob_h(1e-16) == pytest.approx(limit, rel=1e-14)
    pair = resolve_pair(K10, K10, gas=AIR01)
    pc = pack_bob_complete(registry.get("direct_conduction", "batchelor_obrien_complete")
                           .params(), pair)  # fmt: skip
    assert bob_complete_rate(pc, 0.0, 1.0, 1e-3, 1e-3, 2e-3, 0.0, 0.0, 0, 0, 0, 0) == (
        pytest.approx(limit, rel=1e-14)
    )


def test_bob_separated_defaults_equal_the_complete_models_separated_branch():
    """Defaults (dai2019, r̄ = 2.00 R̄, cut-off 1.00 R̄) = batchelor_obrien_complete for δ < 0."""
    spec_c = registry.get("direct_conduction", "batchelor_obrien_complete")
    rng = np.random.default_rng(5)
    for _ in range(200):
        r_i, r_j = 10 ** rng.uniform(-4, -2, 2)
        r_eff = r_i * r_j / (r_i + r_j)
        gap = r_eff * 10 ** rng.uniform(-9, 0)
        pair = resolve_pair(MAT_A, MAT_B)
        pc = spec_c.pack(spec_c.params(), pair)
        q = bob_complete_rate(pc, 0.0, 1.0, r_i, r_j, r_i + r_j + gap, -gap, 0.0, 0, 0, 0, 0)
        p = row("batchelor_obrien_separated")
        h = conductance("batchelor_obrien_separated", p, r_i, r_j, r_i + r_j + gap)
        assert h == pytest.approx(q, rel=1e-12, abs=0.0)


def test_bob_separated_wall_uses_the_particle_radius():
    gap = 1e-6
    h = bob_h(gap, r_i=1e-3, r_j=INF, regime="minimum", cylinder_radius=1.0)
    far = math.log(1 + 1e-3**2 / (2 * 1e-3 * gap))
    assert h == pytest.approx(2 * PI * 1e-3 * 0.1 * min(math.log(1e4), far), rel=1e-13)
    # the wall's conductivity enters k_p: a copper wall under a glass particle
    p = row("batchelor_obrien_separated", K10, material(thermal_conductivity=400.0),
            is_wall=True, gas=AIR01)  # fmt: skip
    assert p[ic.BOB_K_J] == 400.0
    k_p = 2 * 10 * 400 / 410
    h = conductance("batchelor_obrien_separated", p, 1e-3, INF, 1e-3 + 1e-12)
    assert h == pytest.approx(2 * PI * 1e-3 * 0.1 * 2 * math.log(k_p / 0.1), rel=1e-12)


def test_bob_separated_bad_parameters():
    params = spec_of("batchelor_obrien_separated").params
    for bad in ({"cylinder_radius": 0.0}, {"cylinder_radius": -1.0},
                {"cylinder_radius": math.inf}, {"cylinder_radius": "dai"},
                {"cutoff_gap_ratio": -0.5}, {"cutoff_gap_ratio": 0.0},
                {"regime": "linear"}):  # fmt: skip
        with pytest.raises(ValidationError, match=next(iter(bad))):
            params(**bad)
    with pytest.raises(ValueError, match=r"k_p/k_f > 1.*thermal.gas.thermal_conductivity = 30"):
        row("batchelor_obrien_separated", K10, K10, gas=GasProperties(thermal_conductivity=30))
    with pytest.raises(ValueError, match="thermal_conductivity"):
        row("batchelor_obrien_separated", material(thermal_conductivity=None), MAT_B)


# ------------------------------------------------------------------ surrounding layer
@pytest.mark.parametrize("model", ["rong_horio1999", "musser2011"])
def test_surrounding_layer_bad_parameters_and_row(model):
    params = spec_of(model).params
    for bad in ({"min_separation": 0.0}, {"min_separation": -1e-9},
                {"min_separation": math.nan}, {"layer_thickness_ratio": 0.0},
                {"layer_thickness_ratio": -0.4}):  # fmt: skip
        with pytest.raises(ValidationError, match=next(iter(bad))):
            params(**bad)
    gas = GasProperties(thermal_conductivity=0.05)
    p = row(model, gas=gas, layer_thickness_ratio=0.3, min_separation=1e-7)
    assert list(p[:3]) == [0.05, 0.3, 1e-7]
    assert p.shape == (len(spec_of(model).columns),)


# ---------------------------------------------------------------- Vargas & McCarthy (2002)
def vm_row(phi=0.0, k_l=None, gas=None, mi=MAT_A, mj=MAT_B, is_wall=False):
    params = {"filling_angle": phi}
    if k_l is not None:
        params["liquid_conductivity"] = k_l
    return row("vargas_mccarthy2002", mi, mj, is_wall=is_wall, gas=gas, **params)


def vm_h(p, r=1e-3, r_c=2e-5, r_j=None):
    r_j = r if r_j is None else r_j
    d = r - 1e-9 if math.isinf(r_j) else r + r_j - 1e-9
    return conductance("vargas_mccarthy2002", p, r, r_j, d, r_c)


def gas_parameter_by_hand(gas: GasProperties, a_i=0.8, a_j=0.5) -> float:
    pr = gas.dynamic_viscosity * gas.specific_heat / gas.thermal_conductivity
    omega = 1.380649e-23 * gas.temperature / (math.sqrt(2) * PI * gas.molecular_diameter**2
                                               * gas.pressure)  # fmt: skip
    zeta = gas.heat_capacity_ratio
    return ((2 - a_i) / a_i + (2 - a_j) / a_j) * zeta / (zeta + 1) * omega / pr


def vm_spec_by_hand(r_p, r_c, phi, k_l, k_g, m_gas) -> float:
    """The spec's areas and lengths as printed; both paths."""
    a_c = PI * r_c**2
    a_l = 4 * PI * r_p**2 * ((PI / 2 - phi) * math.tan(phi) - 1 + math.cos(phi)) * (
        (1 - math.cos(phi)) / math.cos(phi)) - a_c  # fmt: skip
    a_g = 2 * PI * r_p**2 - a_l - a_c
    r_cap = math.sqrt(r_p**2 * (1 - math.cos(phi)) * (1 + math.cos(phi)))
    l_l = (r_cap * r_p - 0.5 * (phi * r_p**2 + r_cap * math.sqrt(r_p**2 - r_cap**2))) / (
        r_cap - r_c)  # fmt: skip
    l_g = r_p**2 * (1 - PI / 4) / (r_p - r_c) - l_l
    k_star = k_g / (1 + m_gas / l_g)
    return k_l * a_l / l_l + k_star * a_g / l_g


def test_vargas_mccarthy_gas_parameter_and_gas_only_formula():
    gas = GasProperties()  # air, 300 K, 1 atm
    p = vm_row(gas=gas)
    m_gas = gas_parameter_by_hand(gas)
    assert p[vm.VM_GAS_PARAMETER] == pytest.approx(m_gas, rel=1e-13)
    # air: Λ = 6.87e-8 m, Pr = 0.707; (1.5 + 3) × 1.4/2.4 × Λ/Pr = 2.55e-7 m
    assert m_gas == pytest.approx(2.55e-7, rel=1e-2)
    r, r_c = 1e-3, 2e-5
    l_g = r * r * (1 - PI / 4) / (r - r_c)
    k_star = gas.thermal_conductivity / (1 + m_gas / l_g)
    spec = k_star * 2 * PI * (1 - 0.5 * (r_c / r) ** 2) * (r - r_c) / (1 - PI / 4)
    assert vm_h(p, r, r_c) == pytest.approx(spec, rel=1e-13)


@pytest.mark.parametrize("phi", [0.05, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("r_c", [0.0, 1e-5, 4e-5])
def test_vargas_mccarthy_general_formula_by_hand(phi, r_c):
    gas = GasProperties()
    p = vm_row(phi, k_l=0.6, gas=gas)
    ref = vm_spec_by_hand(1e-3, r_c, phi, 0.6, gas.thermal_conductivity,
                          gas_parameter_by_hand(gas))  # fmt: skip
    h = vm_h(p, 1e-3, r_c)
    if phi == 0.05 and r_c == 4e-5:
        # the contact circle (0.04 R) is wider than 4 R² f(φ) allows: the printed A_l < 0 and
        # the spec's H is negative; the kernel clips A_l at 0 (gas path only)
        assert ref < 0.0 < h
        l_g = 1e-6 * (1 - PI / 4) / (1e-3 - r_c) - 1e-6 * vm.liquid_length_factor(phi) / (
            1e-3 * math.sin(phi) - r_c)  # fmt: skip
        gas_path = gas.thermal_conductivity * (2 * PI * 1e-6 - PI * r_c**2) / (
            l_g + gas_parameter_by_hand(gas))  # fmt: skip
        assert h == pytest.approx(gas_path, rel=1e-11)
    else:
        assert h == pytest.approx(ref, rel=1e-11)


@pytest.mark.parametrize("r_c", [0.0, 3e-5])
def test_vargas_mccarthy_limits_of_the_filling_angle(r_c):
    gas = GasProperties()
    r, k_l = 1e-3, 0.6
    gas_only = vm_h(vm_row(0.0, gas=gas), r, r_c)
    small = vm_h(vm_row(1e-6, k_l=k_l, gas=gas), r, r_c)
    if r_c == 0.0:  # A_l ≈ π² R² φ³, l_l ≈ R φ²/6: the bridge adds 6π² k_l R φ
        assert small - gas_only == pytest.approx(6 * PI**2 * k_l * r * 1e-6, rel=1e-5)
    else:  # a bridge narrower than the contact circle: no liquid path
        assert small == gas_only
    # φ -> π/2: the spec's liquid-only formula (its gas area 2πR² - A_l - A_c is negative
    # beyond φ* = 1.14498 rad, where f(φ*) = 1/2, and is clipped at 0)
    # the spec's A_l = 4πR² - πR_c², l_l = R²(1 - π/4)/(R - R_c): k_l A_l / l_l; its printed
    # closed form writes 4π (1 - ½ (R_c/R)²) where A_l/R² = 4π (1 - ¼ (R_c/R)²)
    liquid_only = k_l * (4 * PI * r * r - PI * r_c**2) * (r - r_c) / (r * r * (1 - PI / 4))
    printed = k_l * 4 * PI * (1 - 0.5 * (r_c / r) ** 2) * (r - r_c) / (1 - PI / 4)
    near_right = vm_h(vm_row(0.5 * PI - 1e-9, k_l=k_l, gas=gas), r, r_c)
    assert near_right == pytest.approx(liquid_only, rel=1e-8)
    quarter = k_l * PI * r_c**2 * (r - r_c) / (r * r * (1 - PI / 4))
    assert liquid_only - printed == pytest.approx(quarter, rel=1e-9, abs=0)
    phi_star = 1.1449815475453589
    assert vm.liquid_area_factor(phi_star) == pytest.approx(0.5, rel=1e-12)
    below = vm_h(vm_row(phi_star - 1e-9, k_l=k_l, gas=gas), r, r_c)
    above = vm_h(vm_row(phi_star + 1e-9, k_l=k_l, gas=gas), r, r_c)
    assert above == pytest.approx(below, rel=1e-6)


def test_vargas_mccarthy_smoluchowski_limits():
    """k_g* -> k_g as ω -> 0; free molecular (ω ≫ l_g): k_g* ∝ 1/ω, i.e. ∝ the pressure."""
    r, r_c = 1e-3, 2e-5
    l_g = r * r * (1 - PI / 4) / (r - r_c)
    continuum = 0.0263 * (2 * PI * r * r - PI * r_c**2) / l_g
    h0 = vm_h(vm_row(gas=GasProperties(mean_free_path=1e-16)), r, r_c)
    assert h0 == pytest.approx(continuum, rel=1e-10)
    by_pressure = [vm_h(vm_row(gas=GasProperties(pressure=p_g)), r, r_c) for p_g in (1e-3, 5e-4)]
    assert by_pressure[0] / by_pressure[1] == pytest.approx(2.0, rel=1e-5)
    # in between: k_g* = k_g l_g/(l_g + M), M ∝ ω
    m1 = vm_row(gas=GasProperties(mean_free_path=1e-6))[vm.VM_GAS_PARAMETER]
    h1 = vm_h(vm_row(gas=GasProperties(mean_free_path=1e-6)), r, r_c)
    h2 = vm_h(vm_row(gas=GasProperties(mean_free_path=2e-6)), r, r_c)
    assert h1 / h2 == pytest.approx((l_g + 2 * m1) / (l_g + m1), rel=1e-13)


def test_vargas_mccarthy_unequal_radii_and_wall_use_twice_the_effective_radius():
    p = vm_row(0.4, k_l=0.6)
    r_c = 2e-5
    assert vm_h(p, 1e-3, r_c, r_j=3e-3) == pytest.approx(vm_h(p, 1.5e-3, r_c), rel=1e-14)
    pw = vm_row(0.4, k_l=0.6, is_wall=True)
    assert vm_h(pw, 1e-3, r_c, r_j=INF) == pytest.approx(vm_h(pw, 2e-3, r_c), rel=1e-14)
    # the wall's material gives the second accommodation coefficient
    wall = material(thermal_accommodation=0.2)
    m = vm_row(gas=GasProperties(), mj=wall, is_wall=True)[vm.VM_GAS_PARAMETER]
    assert m == pytest.approx(gas_parameter_by_hand(GasProperties(), 0.8, 0.2), rel=1e-13)


def test_vargas_mccarthy_bad_parameters():
    params = spec_of("vargas_mccarthy2002").params
    for bad in ({"filling_angle": -0.1}, {"filling_angle": 0.5 * PI},
                {"filling_angle": 2.0, "liquid_conductivity": 0.6},
                {"filling_angle": 0.3, "liquid_conductivity": -1.0}):  # fmt: skip
        with pytest.raises(ValidationError, match="filling_angle|liquid_conductivity"):
            params(**bad)
    with pytest.raises(ValidationError, match=r"liquid_conductivity is required.*0\.3"):
        params(filling_angle=0.3)
    with pytest.raises(ValueError, match="thermal_accommodation"):
        vm_row(mj=material(thermal_accommodation=None))
