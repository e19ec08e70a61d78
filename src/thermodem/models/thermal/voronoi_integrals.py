"""The integrals of Voronoi model A (Cheng, Yu & Zulli 1999; Gan et al. 2016 for unequal
radii) and the inverse-quadratic integral shared with model B (``voronoi.py`` holds the
models, their parameters and their choices).

- ``cone_integral``: the closed form of model A for a path through one sphere and the fluid
  (a mono-size pair, the mean-radius rule, a flat wall), where the spec calls for a
  quadrature: its integrand is a rational function of sin φ and cos φ (r = R sin φ), whose
  integral is elementary.
- ``model_a_integral``: the graded Gauss-Legendre quadrature of the general (Gan et al. 2016)
  path through two spheres of different radii, which has two square roots √(R_i² - r²),
  √(R_j² - r²) and no elementary integral.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Gauss-Legendre rule of model A's quadrature on [0, 1], used on each half interval (see
#: ``model_a_integral``).
QUAD_NODES = 20
_x, _w = np.polynomial.legendre.leggauss(QUAD_NODES)
GL_U = np.ascontiguousarray(0.5 * (_x + 1.0))
GL_W = np.ascontiguousarray(0.5 * _w)
del _x, _w


@njit(cache=True, inline="always", error_model="numpy")
def arctan_ratio(z2):
    """atanh(z)/z for z² = ``z2`` > 0, atan(|z|)/|z| for z2 < 0 (series near 0)."""
    if abs(z2) < 1e-4:
        return 1.0 + z2 * (1.0 / 3.0 + z2 * (0.2 + z2 * (1.0 / 7.0 + z2 / 9.0)))
    if z2 > 0.0:
        z = math.sqrt(z2)
        return math.atanh(z) / z
    z = math.sqrt(-z2)
    return math.atan(z) / z


@njit(cache=True, error_model="numpy")
def _inverse_quadratic_integral(t1, t2, p, q):
    """∫_{t1}^{t2} dt/(p + q t²) where p + q t² > 0 on [t1, t2]: (t2 - t1)/(p + q t1 t2) ×
    f(-p q x²) (the addition formula of atan/atanh, no cancellation as p q -> 0). p <= 0 needs
    t1 t2 > 0 and is integrated in 1/t; across a half turn of atan, the two angles."""
    if not p > 0.0:
        t1, t2, p, q = 1.0 / t2, 1.0 / t1, q, p  # dt/(p + q t²) = -ds/(q + p s²), s = 1/t
    den = p + q * t1 * t2
    if den > 0.0:
        x = (t2 - t1) / den
        return x * arctan_ratio(-p * q * x * x)
    s = math.sqrt(q / p)
    return (math.atan(s * t2) - math.atan(s * t1)) / math.sqrt(p * q)


@njit(cache=True, error_model="numpy")
def cone_integral(solid, fluid, axial, r_ij, radius, r_lo, r_hi):
    """2π ∫_{r_lo}^{r_hi} r dr / Σ(r) in closed form, for the one-sphere path of model A:
    Σ = solid (β - axial r/r_ij) + fluid (axial - β), β = √(R² - r²), R = ``radius``.
    Mono-size pair (half of it): solid = 1/k_i + 1/k_j, fluid = 2/k_f, axial = d/2; flat
    wall: solid = 1/k_p, fluid = 1/k_f, axial = d_pw.

    With Σ = A β + B - C r (A = solid - fluid, B = fluid axial, C = solid axial/r_ij) and
    r = R sin φ, Σ = B + ρ cos χ, ρ = R √(A² + C²), χ = φ + ψ, tan ψ = C/A, and the
    numerator sin φ cos φ = ½ (sin 2χ cos 2ψ - cos 2χ sin 2ψ), the integral is elementary
    (m = A² + C²)::

        H = 2π/m² [ -(A² - C²)(ΔΣ - B Δln Σ) - 2AC (Δ(A r + C β) - B Δφ)
                    - AC (2B² - R² m) ΔK ],   K = ∫ dχ/(B + ρ cos χ)

    K by the half-angle substitution about χ = 0 (A > 0: χ in (0, π)) or χ = π (A <= 0: χ
    in [π/2, 3π/2]), so that the tangent stays finite. Checked against scipy.integrate.quad
    and the Gauss-Legendre integration of the general form (tests/unit/test_voronoi_models.py).
    """
    if not r_hi > r_lo:
        return 0.0
    big_a = solid - fluid
    big_b = fluid * axial
    big_c = solid * axial / r_ij
    m = big_a * big_a + big_c * big_c
    rho = radius * math.sqrt(m)
    beta_1 = math.sqrt(max(radius * radius - r_lo * r_lo, 0.0))
    beta_2 = math.sqrt(max(radius * radius - r_hi * r_hi, 0.0))
    # Σ with the fluid path written without cancellation where it closes (axial ~ β)
    gap_1 = ((axial - radius) * (axial + radius) + r_lo * r_lo) / (axial + beta_1)
    gap_2 = ((axial - radius) * (axial + radius) + r_hi * r_hi) / (axial + beta_2)
    sum_1 = solid * (beta_1 - axial * r_lo / r_ij) + fluid * gap_1
    sum_2 = solid * (beta_2 - axial * r_hi / r_ij) + fluid * gap_2
    d_sum = sum_2 - sum_1
    e1 = d_sum - big_b * math.log1p(d_sum / sum_1)
    d_beta = (r_lo - r_hi) * (r_lo + r_hi) / (beta_1 + beta_2)
    d_phi = math.asin(min(r_hi / radius, 1.0)) - math.asin(min(r_lo / radius, 1.0))
    e2 = big_a * (r_hi - r_lo) + big_c * d_beta - big_b * d_phi
    # ρ sin χ = A r + C β, ρ cos χ = A β - C r
    sin_1 = big_a * r_lo + big_c * beta_1
    sin_2 = big_a * r_hi + big_c * beta_2
    cos_1 = big_a * beta_1 - big_c * r_lo
    cos_2 = big_a * beta_2 - big_c * r_hi
    if big_a > 0.0:  # t = tan(χ/2)
        d_k = 2.0 * _inverse_quadratic_integral(
            sin_1 / (rho + cos_1), sin_2 / (rho + cos_2), big_b + rho, big_b - rho
        )
    else:  # t = tan((χ - π)/2)
        d_k = 2.0 * _inverse_quadratic_integral(
            -sin_1 / (rho - cos_1), -sin_2 / (rho - cos_2), big_b - rho, big_b + rho
        )
    ac = big_a * big_c
    return (2.0 * math.pi / (m * m)) * (
        -(big_a - big_c) * (big_a + big_c) * e1
        - 2.0 * ac * e2
        - ac * (2.0 * big_b * big_b - radius * radius * m) * d_k
    )


@njit(cache=True, inline="always", error_model="numpy")
def _path_denominator(r, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall):
    """Σ (path length / conductivity) of the path at radius r (model A): in the smaller
    particle, in the larger one (absent at a wall) and in the fluid."""
    beta_s = math.sqrt(max(r_s * r_s - r * r, 0.0))
    den = (beta_s - d_s * r / c_s) * ik_s
    if wall:
        return den + (dist - beta_s) * ik_f
    beta_l = math.sqrt(max(r_l * r_l - r * r, 0.0))
    return den + (beta_l - d_l * r / c_l) * ik_l + (dist - beta_s - beta_l) * ik_f


@njit(cache=True, inline="always", error_model="numpy")
def _path_slope(r, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, ik_f, wall):
    """d/dr of ``_path_denominator``."""
    beta_s = math.sqrt(max(r_s * r_s - r * r, 0.0))
    slope = (-r / beta_s - d_s / c_s) * ik_s + r / beta_s * ik_f
    if wall:
        return slope
    beta_l = math.sqrt(max(r_l * r_l - r * r, 0.0))
    return slope + (-r / beta_l - d_l / c_l) * ik_l + r / beta_l * ik_f


@njit(cache=True, inline="always", error_model="numpy")
def _graded_half(phi_end, direction, lam, half, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l,
                 dist, ik_f, wall):  # fmt: skip
    """∫ over the half interval [phi_end, phi_end + direction × half] of 2πr dr/Σ(path/k),
    with the nodes graded geometrically away from phi_end on the scale ``lam``."""
    lam = max(min(lam, half), 1e-14 * half)
    alpha = math.log1p(half / lam)
    total = 0.0
    for q in range(GL_U.shape[0]):
        e = math.expm1(alpha * GL_U[q])
        phi = phi_end + direction * lam * e
        r = r_s * math.sin(phi)
        jac = alpha * lam * (e + 1.0) * r_s * math.cos(phi)  # |dr/du|
        den = _path_denominator(r, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall)
        total += GL_W[q] * r / den * jac
    return total


@njit(cache=True, error_model="numpy")
def model_a_integral(r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall, r_lo, r_hi):
    """∫_{r_lo}^{r_hi} 2πr dr / Σ(path/k) of model A (``_path_denominator``; ``r_s`` is the
    smaller radius, ``ik_*`` reciprocal conductivities).

    The integrand is smooth in φ with r = R_s sin φ (β_s = R_s cos φ has no square-root end
    point even when r_hi is close to R_s), but it can vary on scales much smaller than the
    interval at either end: at r_lo where the fluid gap d - β_s - β_l is small (its
    resistance grows from ~0 to that of the solid path over a length λ_lo, estimated from the
    gap's Taylor expansion: gap'·s + gap''·s²/2 = k_f × the path resistance at r_lo), and at
    r_hi when k_p ~ k_f (the resistance falls towards the small fluid path at r_sf, like a
    pole at λ_hi = Σ/|dΣ/dr| beyond the end). Each half of the φ interval is integrated by
    Gauss-Legendre with its nodes graded geometrically from its end on that scale,
    φ - φ_end = λ (exp(α u) - 1), α = ln(1 + (Φ/2)/λ), u in [0, 1].
    Checked against scipy.integrate.quad to 1e-8 (tests/unit/test_voronoi_models.py).
    """
    if not r_hi > r_lo:
        return 0.0
    phi_lo = math.asin(min(r_lo / r_s, 1.0))
    phi_hi = math.asin(min(r_hi / r_s, 1.0))
    half = 0.5 * (phi_hi - phi_lo)
    # the lower end: the scale of the fluid gap's growth
    beta_s = math.sqrt(max(r_s * r_s - r_lo * r_lo, 0.0))
    c1 = r_lo / beta_s
    c2 = 0.5 * (1.0 / beta_s + r_lo * r_lo / (beta_s * beta_s * beta_s))
    if not wall:
        beta_l = math.sqrt(max(r_l * r_l - r_lo * r_lo, 0.0))
        c1 += r_lo / beta_l
        c2 += 0.5 * (1.0 / beta_l + r_lo * r_lo / (beta_l * beta_l * beta_l))
    delta = (
        _path_denominator(r_lo, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall) / ik_f
    )
    scale = 2.0 * delta / (c1 + math.sqrt(c1 * c1 + 4.0 * c2 * delta))
    lam_lo = scale / beta_s
    # the upper end: distance to the pole of 1/Σ when Σ falls towards r_hi
    den_hi = _path_denominator(r_hi, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall)
    slope_hi = _path_slope(r_hi, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, ik_f, wall)
    lam_hi = half
    if slope_hi < 0.0:
        lam_hi = den_hi / (-slope_hi) / (r_s * math.cos(phi_hi))
    total = _graded_half(
        phi_lo, 1.0, lam_lo, half, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall
    )
    total += _graded_half(
        phi_hi, -1.0, lam_hi, half, r_s, d_s, c_s, ik_s, r_l, d_l, c_l, ik_l, dist, ik_f, wall
    )
    return 2.0 * math.pi * total
