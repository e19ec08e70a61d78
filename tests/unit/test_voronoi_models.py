"""Voronoi models A and B (models/thermal/voronoi.py) against checks that are not the code:
scipy.integrate.quad of the spec's integrals (model A, every variant; model B's path
integral), the spec's own closed forms of Chen et al. (2019), the mono-size reductions, the
mirror symmetry of a wall, and the k_f -> 0, k_p -> inf and cut-off limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from thermodem.models import registry
from thermodem.models.thermal import voronoi as v
from thermodem.state.gas import GasProperties
from thermodem.state.materials import Material, resolve_pair

K_F = 0.026


def row_a(k_i: float, k_j: float, sizes: int = v.SIZES_GENERAL, cutoff: float = 10.0):
    return np.array([k_i, k_j, K_F, sizes, cutoff])


def row_b(k_i, k_j, c_i=0.5, c_j=0.5, sizes=v.SIZES_GENERAL, cutoff=10.0):  # noqa: ANN001
    return np.array([k_i, k_j, K_F, c_i, c_j, sizes, cutoff])


def area(a: float) -> np.ndarray:
    return np.array([a])


def quad_gan(r_i, r_j, d, r_c, a_n, k_i, k_j):  # noqa: ANN001
    """The spec's multi-size model A integral (Gan et al. 2016), written for R_i <= R_j."""
    if r_i > r_j:
        r_i, r_j, k_i, k_j = r_j, r_i, k_j, k_i
    r_ij = math.sqrt(a_n / math.pi)
    d_i = math.sqrt(r_i**2 - r_c**2) if r_c > 0 else (r_i**2 - r_j**2 + d**2) / (2 * d)
    d_j = d - d_i
    r_sf = r_i * r_ij / math.sqrt(r_ij**2 + d_i**2)
    r_ij2 = d_j * r_sf / math.sqrt(r_j**2 - r_sf**2)

    def f(r: float) -> float:
        b_i, b_j = math.sqrt(r_i**2 - r**2), math.sqrt(r_j**2 - r**2)
        den = (b_i - d_i * r / r_ij) / k_i + (b_j - d_j * r / r_ij2) / k_j + (d - b_i - b_j) / K_F
        return 2 * math.pi * r / den

    if r_sf <= r_c:
        return 0.0
    pts = [r_c + (r_sf - r_c) * x for x in (1e-6, 1e-4, 1e-2, 0.9, 0.99)]
    return quad(f, r_c, r_sf, epsabs=0, epsrel=1e-13, limit=500, points=pts)[0]


def quad_mono(r_p, d, r_c, a_n, k):  # noqa: ANN001
    """The spec's mono-size model A integral (Cheng et al. 1999) with conductivity k."""
    r_ij = math.sqrt(a_n / math.pi)
    r_sf = r_p * r_ij / math.sqrt(r_ij**2 + d**2 / 4)

    def f(r: float) -> float:
        b = math.sqrt(r_p**2 - r**2)
        return 2 * math.pi * r / ((b - d * r / (2 * r_ij)) / k + (d - 2 * b) / K_F)

    pts = [r_c + (r_sf - r_c) * x for x in (1e-6, 1e-4, 1e-2, 0.9, 0.99)]
    return quad(f, r_c, r_sf, epsabs=0, epsrel=1e-13, limit=500, points=pts)[0]


def quad_wall_a(r_p, d_pw, r_c, a_n, k_p):  # noqa: ANN001
    r_ij = math.sqrt(a_n / math.pi)
    r_sf = r_p * r_ij / math.sqrt(r_ij**2 + d_pw**2)

    def f(r: float) -> float:
        b = math.sqrt(r_p**2 - r**2)
        return 2 * math.pi * r / ((b - d_pw * r / r_ij) / k_p + (d_pw - b) / K_F)

    pts = [r_c + (r_sf - r_c) * x for x in (1e-6, 1e-4, 1e-2, 0.9, 0.99)]
    return quad(f, r_c, r_sf, epsabs=0, epsrel=1e-13, limit=500, points=pts)[0]


def geometric_rc(r_i: float, r_j: float, d: float) -> float:
    x = (r_i**2 - r_j**2 + d**2) / (2 * d)
    return math.sqrt(max(r_i**2 - x**2, 0.0)) if d < r_i + r_j else 0.0


def random_pair(rng: np.random.Generator):  # noqa: ANN201
    r_i = 1e-3
    r_j = r_i * (1.0 if rng.random() < 0.3 else rng.uniform(0.3, 3.0))
    kind = rng.integers(3)
    if kind == 0:
        gap = 10 ** rng.uniform(-7, -0.4) * r_i
    elif kind == 1:
        gap = 0.0
    else:
        gap = -(10 ** rng.uniform(-6, -1.5)) * min(r_i, r_j)
    d = r_i + r_j + gap
    a_n = 3 * 10 ** rng.uniform(-1.5, 1.5) * min(r_i, r_j) ** 2
    k_i = K_F * 10 ** rng.uniform(0.0, 4.3)
    k_j = k_i if rng.random() < 0.4 else K_F * 10 ** rng.uniform(0.0, 4.3)
    return r_i, r_j, d, geometric_rc(r_i, r_j, d), a_n, k_i, k_j


def test_model_a_quadrature_matches_quad_to_1e_8() -> None:
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(400):
        r_i, r_j, d, r_c, a_n, k_i, k_j = random_pair(rng)
        h = v.voronoi_a_conductance(row_a(k_i, k_j), r_i, r_j, d, r_c, area(a_n))
        ref = quad_gan(r_i, r_j, d, r_c, a_n, k_i, k_j)
        if ref == 0.0:
            assert h == 0.0
            continue
        worst = max(worst, abs(h - ref) / ref)
    assert worst < 1e-8, worst


def test_model_a_mono_and_mean_radius_and_wall_match_quad() -> None:
    rng = np.random.default_rng(4)
    for _ in range(150):
        r_i, r_j, d, r_c, a_n, k_i, k_j = random_pair(rng)
        k_bar = 1.0 / (1.0 / k_i + 1.0 / k_j)
        gap = d - r_i - r_j
        # mono: the spec's formula with k = k̄ (what Gan's reduces to for equal radii)
        d_m = 2 * r_i + gap
        rc_m = geometric_rc(r_i, r_i, d_m)
        h = v.voronoi_a_conductance(row_a(k_i, k_j), r_i, r_i, d_m, rc_m, area(a_n))
        assert h == pytest.approx(quad_mono(r_i, d_m, rc_m, a_n, k_bar), rel=1e-8)
        # mean radius (Norouzi et al. 2016): R_p = (R_i + R_j)/2, R_c of the pair as given
        r_p = 0.5 * (r_i + r_j)
        h = v.voronoi_a_conductance(row_a(k_i, k_j, v.SIZES_MEAN_RADIUS), r_i, r_j, d, r_c,
                                    area(a_n))  # fmt: skip
        rc_p = max(r_c, geometric_rc(r_p, r_p, d))  # no negative fluid path
        assert h == pytest.approx(quad_mono(r_p, d, rc_p, a_n, k_bar), rel=1e-8)
        # a wall at d_pw = R_i + gap
        d_pw = r_i + gap
        rc_w = math.sqrt(max(r_i**2 - d_pw**2, 0.0))
        h = v.voronoi_a_conductance(row_a(k_i, k_i), r_i, math.inf, d_pw, rc_w, area(a_n))
        assert h == pytest.approx(quad_wall_a(r_i, d_pw, rc_w, a_n, k_i), rel=1e-8)


def test_model_a_gan_reduces_to_mono_and_a_wall_is_a_mirror_plane() -> None:
    r, k = 1e-3, 1.3
    for gap in (-1e-5, 0.0, 1e-6, 1e-4):
        d = 2 * r + gap
        rc = geometric_rc(r, r, d)
        for a_n in (0.5e-6, 4e-6, 30e-6):
            mono = v.voronoi_a_conductance(row_a(k, k), r, r, d, rc, area(a_n))
            near = v.voronoi_a_conductance(row_a(k, k), r, r * (1 + 1e-12), d, rc, area(a_n))
            assert near == pytest.approx(mono, rel=1e-9)  # Gan's branch -> the mono formula
            # the pair and its mirror across the wall: the wall conducts twice the pair
            wall = v.voronoi_a_conductance(row_a(k, k), r, math.inf, 0.5 * d, rc, area(a_n))
            assert wall == pytest.approx(2.0 * mono, rel=1e-12)


def test_model_a_limits() -> None:
    r, d, a_n = 1e-3, 2.0e-3 + 2e-5, 4e-6
    # k_f -> 0: H -> 0 in proportion to k_f (the fluid path is in every path)
    h = [v.voronoi_a_conductance(np.array([1.0, 1.0, kf, 0, 10.0]), r, r, d, 0.0, area(a_n))
         for kf in (1e-9, 2e-9)]  # fmt: skip
    assert h[1] == pytest.approx(2 * h[0], rel=1e-6) and h[0] < 1e-10
    # k_p -> inf: the closed form 2π ∫ β dβ/(d - 2β) = 2π [-β/2 - (d/4) ln(d - 2β)]
    r_ij = math.sqrt(a_n / math.pi)
    r_sf = r * r_ij / math.sqrt(r_ij**2 + d**2 / 4)
    b0, b1 = math.sqrt(r**2 - r_sf**2), r

    def prim(b: float) -> float:
        return -b / 2 - d / 4 * math.log(d - 2 * b)

    exact = 2 * math.pi * K_F * (prim(b1) - prim(b0))
    h = v.voronoi_a_conductance(row_a(1e13, 1e13), r, r, d, 0.0, area(a_n))
    assert h == pytest.approx(exact, rel=1e-8)
    # touching: finite, and continuous from the separated side
    touch = v.voronoi_a_conductance(row_a(1.0, 1.0), r, r, 2 * r, 0.0, area(a_n))
    near = v.voronoi_a_conductance(row_a(1.0, 1.0), r, r, 2 * r + 1e-12, 0.0, area(a_n))
    assert math.isfinite(touch) and near == pytest.approx(touch, rel=1e-6)
    # the cut-off: zero at and beyond cutoff × (R_i + R_j)/2, positive just before
    row = row_a(1.0, 1.0, cutoff=1.0)
    assert v.voronoi_a_conductance(row, r, r, 3 * r, 0.0, area(a_n)) == 0.0
    assert v.voronoi_a_conductance(row, r, r, 3 * r * (1 - 1e-9), 0.0, area(a_n)) > 0.0
    assert v.voronoi_a_conductance(row, r, math.inf, 2 * r, 0.0, area(a_n)) == 0.0
    assert math.isnan(v.voronoi_a_conductance(row, r, r, 2.1 * r, 0.0, area(np.nan)))


def chen_spec(k_i, k_j, c_i, c_j, r_i, r_j, d, r_c, a_n):  # noqa: ANN001
    """The spec's closed forms of Chen et al. (2019) as printed (Λ > 0: ln; Λ < 0: atan)."""
    g_i, g_j = r_i / d, r_j / d
    dg = g_j - g_i
    a = (k_i + K_F * (1 / c_i - 1)) / (k_i * g_i)
    b = (k_j + K_F * (1 / c_j - 1)) / (k_j * g_j)
    lam = (1 + dg * a) * (1 - dg * b)
    d_max = 0.5 * (math.sqrt(1 + 4 * a_n / (math.pi * d * d * (1 - dg * dg))) - dg)
    d_min = 0.5 * (math.sqrt(1 + 4 * r_c * r_c / (d * d * (1 - dg * dg))) - dg)
    x_max = ((a + b) * d_max + dg * b - 1) / math.sqrt(abs(lam))
    x_min = ((a + b) * d_min + dg * b - 1) / math.sqrt(abs(lam))
    pre = math.pi * K_F * d * (1 - dg * dg) / (2 * math.sqrt(abs(lam)))
    if lam > 0:
        y1 = (x_max - x_min) / (1 - x_max * x_min)
        return pre * math.log(abs((1 - y1) / (1 + y1))), lam
    y2 = (x_max - x_min) / (1 + x_max * x_min)
    return pre * math.atan(y2), lam


def quad_b_paths(k_i, k_j, c_i, c_j, r_i, r_j, d, r_c, a_n):  # noqa: ANN001
    """Model B from its assumptions: radial cones from each core (radius c R) to the meeting
    surface r_i - r_j = R_i - R_j, in series, integrated over δ = r_i/d by quad."""
    dg = (r_j - r_i) / d
    one = 1 - dg * dg

    def f(delta: float) -> float:
        ri, rj = d * delta, d * (delta + dg)
        res_i = ((1 / (c_i * r_i) - 1 / r_i) / k_i + (1 / r_i - 1 / ri) / K_F) * delta**2
        res_j = ((1 / (c_j * r_j) - 1 / r_j) / k_j + (1 / r_j - 1 / rj) / K_F) * (delta + dg) ** 2
        return math.pi * one / (res_i + res_j)

    d_max = 0.5 * (math.sqrt(1 + 4 * a_n / (math.pi * d * d * one)) - dg)
    d_min = 0.5 * (math.sqrt(1 + 4 * r_c * r_c / (d * d * one)) - dg)
    return quad(f, d_min, d_max, epsabs=0, epsrel=1e-13, limit=200)[0]


def test_model_b_chen_matches_its_paths_and_the_spec_for_positive_lambda() -> None:
    rng = np.random.default_rng(5)
    signs = set()
    for _ in range(300):
        r_i, r_j, d, r_c, a_n, k_i, k_j = random_pair(rng)
        k_i, k_j = max(k_i, 1.01 * K_F), max(k_j, 1.01 * K_F)
        c_i, c_j = rng.uniform(0.3, 0.9, 2)
        h = v.voronoi_b_conductance(row_b(k_i, k_j, c_i, c_j), r_i, r_j, d, r_c, area(a_n))
        if a_n / math.pi <= r_c * r_c:
            assert h == 0.0
            continue
        assert h == pytest.approx(quad_b_paths(k_i, k_j, c_i, c_j, r_i, r_j, d, r_c, a_n),
                                  rel=1e-9)  # fmt: skip
        spec, lam = chen_spec(k_i, k_j, c_i, c_j, r_i, r_j, d, r_c, a_n)
        signs.add(lam > 0)
        if lam > 1e-6:
            assert h == pytest.approx(spec, rel=1e-7)
        elif lam < -1e-6:
            # the spec prints π k_f d (1 - Δγ²)/(2√|Λ|) atan(Y_2): half of the integral, which
            # would jump by a factor 2 at Λ = 0; the integral is (1/√|Λ|) atan(Y_2)
            assert h == pytest.approx(2 * spec, rel=1e-7)
    assert signs == {True, False}


def test_model_b_mono_is_cheng_and_wall_is_a_mirror_plane() -> None:
    r, k = 1e-3, 1.0
    for gap in (-1e-5, 0.0, 1e-5, 5e-4):
        d = 2 * r + gap
        rc = geometric_rc(r, r, d)
        for a_n in (1e-6, 4e-6, 40e-6):
            if a_n / math.pi <= rc * rc:
                continue
            # Cheng et al. (1999) as printed: a, b, cos θ_0, cos θ_c with k̄ = (1/k_i+1/k_j)^-1
            k_bar = 1 / (2 / k)
            a = 1 / (2 * k_bar) * (1 / (0.5 * r) - 1 / r) + 1 / (K_F * r)
            b = 2 / (K_F * d)
            r_ij = math.sqrt(a_n / math.pi)
            cos0 = d / (2 * math.sqrt(r_ij**2 + d**2 / 4))
            cosc = d / (2 * math.sqrt(rc**2 + d**2 / 4))
            cheng = math.pi / b * math.log((a - b * cos0) / (a - b * cosc))
            for sizes in (v.SIZES_GENERAL, v.SIZES_MEAN_RADIUS):
                h = v.voronoi_b_conductance(row_b(k, k, sizes=sizes), r, r, d, rc, area(a_n))
                assert h == pytest.approx(cheng, rel=1e-11)
            wall = v.voronoi_b_conductance(row_b(k, k), r, math.inf, 0.5 * d, rc, area(a_n))
            assert wall == pytest.approx(2 * cheng, rel=1e-12)
    # k_f -> 0: H ∝ k_f
    h = [v.voronoi_b_conductance(np.array([1.0, 1.0, kf, 0.5, 0.5, 0, 10.0]), r, r, 2.1e-3,
                                 0.0, area(4e-6)) for kf in (1e-7, 2e-7)]  # fmt: skip
    assert h[1] == pytest.approx(2 * h[0], rel=1e-5)


def test_swapping_the_pair_gives_the_same_conductance_bit_for_bit() -> None:
    rng = np.random.default_rng(6)
    for _ in range(200):
        r_i, r_j, d, r_c, a_n, k_i, k_j = random_pair(rng)
        k_i, k_j = max(k_i, 1.01 * K_F), max(k_j, 1.01 * K_F)
        for fn, row, swapped in (
            (v.voronoi_a_conductance, row_a(k_i, k_j), row_a(k_j, k_i)),
            (v.voronoi_b_conductance, row_b(k_i, k_j, 0.5, 0.6), row_b(k_j, k_i, 0.6, 0.5)),
        ):
            assert fn(row, r_i, r_j, d, r_c, area(a_n)) == fn(swapped, r_j, r_i, d, r_c,
                                                              area(a_n))  # fmt: skip


def material(k: float) -> Material:
    return Material(density=2500.0, youngs_modulus=1e7, poisson_ratio=0.3, specific_heat=800.0,
                    thermal_conductivity=k)  # fmt: skip


def test_packing_core_rule_and_validity_limits() -> None:
    spec = registry.get("indirect_conduction", "voronoi_b")
    gas = GasProperties()
    k_f = gas.thermal_conductivity
    pair = resolve_pair(material(3 * k_f), material(100 * k_f))
    pair = type(pair)(**{**pair.__dict__, "gas": gas})
    row = spec.pack(spec.params(), pair)
    assert row[v.B_CORE_I] == 0.6 and row[v.B_CORE_J] == 0.5  # Chen et al. 2019 by k_p/k_f
    bad = resolve_pair(material(0.5 * k_f), material(100 * k_f))
    with pytest.raises(ValueError, match="k_p/k_f <= 1"):
        spec.pack(spec.params(), bad)
    with pytest.raises(ValueError):
        spec.params(core_radius_ratio=1.2)
    assert spec.interaction_range(spec.params(), 1e-3, 2e-3) == pytest.approx(1.5e-3)
    assert spec.interaction_range(spec.params(cutoff_gap_ratio=0.5), 1e-3, math.inf) == 5e-4


def test_closure_face_area() -> None:
    # Zhou et al. (2009): A_n = 0.985 R² (1 - ε)^(-2/3), r_ij = √(A_n/π) = 0.560 R (1 - ε)^(-1/3)
    for radius, eps in ((1e-3, 0.26), (2.5e-4, 0.4), (3e-3, 0.6)):
        expected = 0.985 * radius**2 / (1.0 - eps) ** (2.0 / 3.0)
        assert v.closure_face_area(radius, eps) == pytest.approx(expected, rel=1e-14)
    for eps in (0.26, 0.4, 0.6):
        a_n = v.closure_face_area(1e-3, eps)
        assert math.sqrt(a_n / math.pi) == pytest.approx(0.560e-3 * (1 - eps) ** (-1 / 3), rel=1e-3)


def test_curvature_premise_of_the_conductance_reuse() -> None:
    """The bound of thermal.tessellation.conductance_gap_tolerance, 1.5 C tol² H, rests on
    C = max w² |H''(d)| / H over pairs (w = |d - R_i - R_j| the surface gap or overlap, H''
    by central differences at 1e-3 w, on one side of touching and of the cut-off): <= 5 for
    model A and <= 45 for model B (its largest values where the face shrinks to the contact
    and H -> 0); the elasticity w |H'| / H <= 2 and 20 (the bound without a slope)."""
    rng = np.random.default_rng(2)
    limits = {"a": (2.0, 5.0), "b": (20.0, 45.0)}
    for model in ("a", "b"):
        worst_e = worst_c = 0.0
        for _ in range(1500):
            r_i = 1e-3
            r_j = r_i * (1.0 if rng.random() < 0.3 else rng.uniform(0.3, 3.0))
            if rng.integers(2) == 0:
                gap = 10 ** rng.uniform(-6, -0.01) * r_i
            else:
                gap = -(10 ** rng.uniform(-6, -1.5)) * min(r_i, r_j)
            d = r_i + r_j + gap
            a_n = area(3 * 10 ** rng.uniform(-1.5, 1.5) * min(r_i, r_j) ** 2)
            k_i = K_F * 10 ** rng.uniform(0.01, 4.3)
            k_j = k_i if rng.random() < 0.4 else K_F * 10 ** rng.uniform(0.01, 4.3)
            if model == "a":
                row, fn = row_a(k_i, k_j, cutoff=1.0), v.voronoi_a_conductance
            else:
                row, fn = row_b(k_i, k_j, cutoff=1.0), v.voronoi_b_conductance

            def h(x: float) -> float:
                return fn(row, r_i, r_j, x, geometric_rc(r_i, r_j, x), a_n)  # noqa: B023

            h0 = h(d)
            if h0 <= 0.0:
                continue
            w = abs(gap)
            room = min(w, r_i + r_j + 0.5 * (r_i + r_j) - d)
            e = min(1e-3 * w, 0.5 * room)
            hp, hm = h(d + e), h(d - e)
            worst_e = max(worst_e, w * abs(hp - hm) / (2 * e) / h0)
            worst_c = max(worst_c, w * w * abs(hp - 2 * h0 + hm) / e**2 / h0)
        assert worst_e <= limits[model][0] and worst_c <= limits[model][1], (model, worst_e,
                                                                              worst_c)  # fmt: skip
        assert worst_c > 0.2 * limits[model][1]  # the sample reaches the worst region


def test_model_b_cutoff_and_touching_limits() -> None:
    """The spec's cut-off remark ("a similar cut-off value should be set"): model B is zero
    at and beyond cutoff × (R_i + R_j)/2 and at a wall beyond cutoff × R_i, positive just
    before; at touching (R_c = 0, θ_c = 0) it is finite and continuous from both sides."""
    r, a_n = 1e-3, area(4e-6)
    row = row_b(1.0, 1.0, cutoff=1.0)
    assert v.voronoi_b_conductance(row, r, r, 3 * r, 0.0, a_n) == 0.0
    assert v.voronoi_b_conductance(row, r, r, 3 * r * (1 - 1e-9), 0.0, a_n) > 0.0
    assert v.voronoi_b_conductance(row, r, math.inf, 2 * r, 0.0, a_n) == 0.0
    assert v.voronoi_b_conductance(row, r, math.inf, 2 * r * (1 - 1e-9), 0.0, a_n) > 0.0
    assert math.isnan(v.voronoi_b_conductance(row, r, r, 2.1 * r, 0.0, area(np.nan)))
    for sizes in (v.SIZES_GENERAL, v.SIZES_MEAN_RADIUS):
        rw = row_b(1.0, 3.0, sizes=sizes)
        touch = v.voronoi_b_conductance(rw, r, r, 2 * r, 0.0, a_n)
        apart = v.voronoi_b_conductance(rw, r, r, 2 * r * (1 + 1e-10), 0.0, a_n)
        d_in = 2 * r * (1 - 1e-10)
        inside = v.voronoi_b_conductance(rw, r, r, d_in, geometric_rc(r, r, d_in), a_n)
        assert math.isfinite(touch) and touch > 0
        assert apart == pytest.approx(touch, rel=1e-6) and inside == pytest.approx(touch, rel=1e-4)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_model_a_closed_form_matches_quad_and_the_general_quadrature() -> None:
    """cone_integral (the elementary integral of the one-sphere path: mono-size, mean radius,
    wall) against scipy.integrate.quad of Σ = s (β - ℓ r/r_ij) + f (ℓ - β) and against the
    graded Gauss-Legendre integration of the general path (model_a_integral with equal
    spheres), over k_p/k_f = 1e-2 ... 1e6 (both signs of A = s - f, both signs of B - ρ) and
    surface gaps down to 1e-10 R."""
    from thermodem.models.thermal.voronoi_integrals import cone_integral, model_a_integral

    rng = np.random.default_rng(11)
    worst_quad = worst_gl = 0.0
    seen = set()
    for _ in range(600):
        r = 1e-3
        k_p = K_F * 10 ** rng.uniform(-2.0, 6.0)
        wall = rng.random() < 0.3
        if rng.random() < 0.3:
            axial = r * (1.0 + 10 ** rng.uniform(-10.0, -1.0))
        else:
            axial = r * rng.uniform(0.5, 2.0)
        r_ij = r * 10 ** rng.uniform(-0.3, 0.7)
        solid, fluid = (1.0 / k_p, 1.0 / K_F) if wall else (2.0 / k_p, 2.0 / K_F)
        r_sf = r * r_ij / math.sqrt(r_ij**2 + axial**2)
        r_lo = math.sqrt(max(r * r - axial * axial, 0.0))
        if rng.random() < 0.2:
            r_lo = max(r_lo, rng.uniform(0.0, 0.9) * r_sf)
        if not r_sf > r_lo:
            continue
        big_a, big_b = solid - fluid, fluid * axial
        rho = r * math.hypot(big_a, solid * axial / r_ij)
        seen.add((big_a > 0.0, big_b > rho))
        h = cone_integral(solid, fluid, axial, r_ij, r, r_lo, r_sf)

        def f(x: float, r=r, s=solid, fl=fluid, ax=axial, c=r_ij) -> float:  # noqa: ANN001
            b = math.sqrt(r * r - x * x)
            return 2 * math.pi * x / (s * (b - ax * x / c) + fl * (ax - b))

        pts = [r_lo + (r_sf - r_lo) * x for x in (1e-8, 1e-6, 1e-4, 1e-2, 0.5, 0.9, 0.99)]
        ref = quad(f, r_lo, r_sf, epsabs=0, epsrel=1e-13, limit=1000, points=pts)[0]
        worst_quad = max(worst_quad, abs(h - ref) / ref)
        # the same path as two equal halves in the general form (half the solid each side)
        ik = 0.5 * solid if not wall else solid
        if not wall:
            gl = model_a_integral(r, axial, r_ij, ik, r, axial, r_ij, ik, 2 * axial,
                                  1.0 / K_F, False, r_lo, r_sf)  # fmt: skip
        else:
            gl = model_a_integral(r, axial, r_ij, ik, 0.0, 0.0, 1.0, 0.0, axial, 1.0 / K_F,
                                  True, r_lo, r_sf)  # fmt: skip
        worst_gl = max(worst_gl, abs(h - gl) / gl)
    assert seen == {(True, True), (True, False), (False, True), (False, False)}, seen
    assert worst_quad < 1e-9, worst_quad
    assert worst_gl < 1e-8, worst_gl


def test_inverse_quadratic_integral_on_every_branch() -> None:
    """∫ dt/(p + q t²) of model A's closed form against quad: p > 0 with q of both signs, p <= 0
    (integrated in 1/t) and the half turn of atan (p + q t1 t2 <= 0)."""
    from thermodem.models.thermal.voronoi_integrals import _inverse_quadratic_integral as iq

    cases = [(1.0, 2.0, 0.3, 0.7), (1.0, -0.5, -0.9, 1.2), (-0.5, 2.0, 0.6, 1.5),
             (-0.5, 2.0, -1.5, -0.6), (0.0, 3.0, 0.2, 0.9), (1e-3, 1.0, -0.5, 0.6),
             (1e-3, 1.0, -30.0, 40.0), (2.0, 1e-12, -3.0, 5.0),
             (2.0, -1e-12, -3.0, 5.0)]  # fmt: skip
    branches = set()
    for p, q, t1, t2 in cases:
        ref = quad(lambda t: 1.0 / (p + q * t * t), t1, t2, epsabs=0, epsrel=1e-13,  # noqa: B023
                   limit=500, points=[0.0] if t1 < 0 < t2 else None)[0]  # fmt: skip
        assert iq(t1, t2, p, q) == pytest.approx(ref, rel=1e-12), (p, q, t1, t2)
        assert iq(t2, t1, p, q) == pytest.approx(-ref, rel=1e-12)
        branches.add("p<=0" if not p > 0 else ("half turn" if p + q * t1 * t2 <= 0 else "x"))
    assert branches == {"p<=0", "half turn", "x"}
