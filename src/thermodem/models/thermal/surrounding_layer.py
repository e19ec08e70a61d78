"""Surrounding fluid layer models of indirect conduction: Rong & Horio (1999) and Musser (2011)
(family ``indirect_conduction``; kernel signature and conventions in ``indirect_conduction.py``).

Each particle carries a static fluid layer of thickness δ_f; heat crosses the fluid along
paths parallel to the line of centres, each path of length d_f(r) (at distance r from the
axis) conducting k_f 2πr dr / d_f, with the minimum conduction distance S (spec "Surrounding
Layer Models")::

    H = k_f ∫ 2πr / max(S, d_f(r)) dr,   d_f(r) = d - √(R_i² - r²) - √(R_j² - r²)

All integrals here are evaluated in closed form (no quadrature). The change of variable from
r to the path length y = d_f(r) (y grows with r for r <= min(R_i, R_j)) gives, with
s_k = √(R_k² - r²), Σ = s_i + s_j = d - y and D = R_i² - R_j² (so s_i - s_j = D/Σ):

    2πr dr = 2π s_i s_j/(s_i + s_j) dy = (π/2) (Σ - D²/Σ³) dy

    ∫ 2πr dr / y = (π/2) [d ln(y_b/y_a) - (y_b - y_a)] - (π/2) D² J,
    J = [ln(y/Σ)/d³ + 1/(d² Σ) + 1/(2d Σ²)] from y_a to y_b      (partial fractions of
                                                                    1/(y (d - y)³))

For equal radii D = 0 and the first bracket alone is exact (it is Rong & Horio's integral with
u = cos θ: y = d - 2R u). For a wall (R_j = inf) 2πr dr = 2π s dy, s = d - y, and
∫ 2πr dr / y = 2π [d ln(y_b/y_a) - (y_b - y_a)], which is the spec's analytic solution of
Morris et al. (2015), Lattanzi & Hrenya (2017), Lu et al. (2017). Where d_f < S the integrand
is k_f 2πr/S: an annulus π (r_2² - r_1²)/S. Radii of circles (contact, layer, d_f = S) are
computed with Heron-type products that keep their precision when the circle is small.

Symmetry: everything is built from R_i + R_j, |R_i - R_j|, min, max and sums of the two
sides' terms, so H(i, j) == H(j, i) bit for bit; the rows have no side-specific columns.
Choices (regularisation of Rong & Horio's integral, unequal radii, walls, continuity at
contact): ``docs/models/indirect_conduction-rong_horio1999.md`` and ``-musser2011.md``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.kernels.fastmath_log import fast_log
from thermodem.models.registry import register
from thermodem.state.materials import PairContext

FAMILY = "indirect_conduction"

RONG_HORIO1999 = 2
MUSSER2011 = 3

SL_K_F = 0
SL_LAYER = 1
SL_MIN_GAP = 2
RH_CONTACT_TERM = 3
MUSSER_COLUMNS = ("k_f", "layer_thickness_ratio", "min_separation")
RH_COLUMNS = (*MUSSER_COLUMNS, "contact_term")

#: Defaults after Morris et al. (2015, 2016b) and Lattanzi & Hrenya (2016) (Peng et al. 2020)
DEFAULT_LAYER_RATIO = 0.4
DEFAULT_MIN_SEPARATION = 2.75e-8


# ------------------------------------------------------------------ closed-form integrals
@njit(cache=True, error_model="numpy")
def path_integral_spheres(d, y_a, y_b, sum_a, sum_b, d2):
    """∫ 2πr dr / d_f(r) [m] between the radii where d_f = y_a and y_b (0 < y_a < y_b).

    ``sum_a``, ``sum_b``: Σ = s_i + s_j = d - y at both ends; ``d2`` = (R_i² - R_j²)².
    Equal radii (d2 = 0): (π/2)[d ln(y_b/y_a) - (y_b - y_a)]; else minus (π/2) d2 J with the
    partial-fraction antiderivative J of 1/(y Σ³), written without cancellation
    (Σ_a - Σ_b = y_b - y_a).
    """
    log_ratio = math.log(y_b / y_a)
    dy = y_b - y_a
    main = d * log_ratio - dy
    if d2 == 0.0:
        return 0.5 * math.pi * main
    inv_d = 1.0 / d
    j = (
        (log_ratio + math.log1p(dy / sum_b)) * inv_d * inv_d * inv_d
        + dy / (sum_a * sum_b) * inv_d * inv_d
        + dy * (sum_a + sum_b) / (sum_a * sum_a * sum_b * sum_b) * (0.5 * inv_d)
    )
    return 0.5 * math.pi * (main - d2 * j)


@njit(cache=True, error_model="numpy")
def path_integral_wall(d, y_a, y_b):
    """∫ 2πr dr / (d - √(R² - r²)) [m] between the radii where d_f = y_a and y_b:
    2π [d ln(y_b/y_a) - (y_b - y_a)] (spec, "Interaction with walls", analytic solution)."""
    return 2.0 * math.pi * (d * math.log(y_b / y_a) - (y_b - y_a))


@njit(cache=True, error_model="numpy")
def sphere_sides(r, r_i, r_j, gap):
    """(Σ, y) at distance r from the axis: Σ = s_i + s_j, y = d_f(r) written as
    gap + r²/(R_i + s_i) + r²/(R_j + s_j) (no cancellation for r ≪ R), s_k = √(R_k² - r²)."""
    s_i = math.sqrt(max((r_i - r) * (r_i + r), 0.0))
    s_j = math.sqrt(max((r_j - r) * (r_j + r), 0.0))
    r2 = r * r
    return s_i + s_j, gap + (r2 / (r_i + s_i) + r2 / (r_j + s_j))


@njit(cache=True, error_model="numpy")
def layer_radius2_spheres(r_i, r_j, dist, gap, layer):
    """R_f² of Musser (2011): the circle where the fluid layer of the larger sphere (R_k + δ_f)
    meets the smaller sphere R_l, limited to R_l² when d <= √((R_k + δ_f)² - R_l²) (spec)."""
    r_k = max(r_i, r_j)
    r_l = min(r_i, r_j)
    a = r_k + layer
    if dist * dist <= (a - r_l) * (a + r_l):
        return r_l * r_l
    # Heron form of the intersection circle: (A + R_l - d) = δ_f - gap keeps its precision
    rf2 = (dist - (a - r_l)) * (dist + (a - r_l)) * (layer - gap) * (a + r_l + dist)
    return min(rf2 / (4.0 * dist * dist), r_l * r_l)


@njit(cache=True, error_model="numpy")
def sub_gap_annulus(dist, gap, s_min, delta, r_sum, lo2):
    """r_S² - R_lo² [m²] for two spheres: r_S the circle where d_f = S, i.e. the spheres'
    intersection circle at centre distance D' = d - S, r²(D) = (D² - Δ²)(R_s² - D²)/(4D²)
    (Δ = |R_i - R_j|, R_s = R_i + R_j).

    Separated: r²(d - S) with R_s - D' = S - gap. Touching: r²(d - S) - r²(d) = S (2d - S)/4
    (1 - (Δ R_s)²/(d² (d - S)²)) exactly, plus r²(d) - R_lo², which is 0 when R_lo is the
    geometric contact radius: this avoids the difference of two nearly equal squares (and
    d - S, which loses the digits of S ≪ d, only enters a factor close to 1).
    """
    dd = dist - s_min
    if gap > 0.0:
        return (dd - delta) * (dd + delta) * (s_min - gap) * (r_sum + dd) / (4.0 * dd * dd)
    t = delta * r_sum / (dist * dd)
    shift = 0.25 * s_min * (2.0 * dist - s_min) * ((1.0 - t) * (1.0 + t))
    geo2 = (dist - delta) * (dist + delta) * (-gap) * (r_sum + dist) / (4.0 * dist * dist)
    return shift + (geo2 - lo2)


# ------------------------------------------------------------------------- Musser (2011)
@njit(cache=True, error_model="numpy")
def musser_wall_factor(r, dist, r_c, layer, s_min):
    """H/k_f [m] of Musser's integral for a particle and a flat wall (spec, "Interaction with
    walls"): ∫_{R_c}^{R_f} 2πr/max(S, d - √(R² - r²)) dr, R_f = √((R + δ_f)² - d²) <= R."""
    gap = dist - r
    if not (gap < layer):
        return 0.0
    r_lo = max(r_c, 0.0) if gap <= 0.0 else 0.0
    rf2 = min(r * r, (layer - gap) * (r + layer + dist))
    lo2 = r_lo * r_lo
    if not (rf2 > lo2):
        return 0.0
    r_f = math.sqrt(rf2)
    y_b = gap + rf2 / (r + math.sqrt(max((r - r_f) * (r + r_f), 0.0)))
    y_a = gap + lo2 / (r + math.sqrt(max((r - r_lo) * (r + r_lo), 0.0)))
    if y_a >= s_min:
        return path_integral_wall(dist, y_a, y_b)
    if y_b <= s_min:
        return math.pi * (rf2 - lo2) / s_min
    if gap <= 0.0:
        # r_S² - R_c^geo² = S (2d - S) exactly; R_c^geo² = -gap (2R + gap) - R_c² is 0 when
        # r_c is the geometric radius (to round-off): no difference of nearly equal squares
        annulus = s_min * (2.0 * dist - s_min) + (-gap * (2.0 * r + gap) - lo2)
    else:
        annulus = (s_min - gap) * (2.0 * r + gap - s_min)  # r_S² = R² - (d - S)²
    annulus = min(max(annulus, 0.0), rf2 - lo2)
    return math.pi * annulus / s_min + path_integral_wall(dist, s_min, y_b)


@njit(cache=True, inline="always", error_model="numpy")
def musser2011_conductance(p, r_i, r_j, dist, r_c, f_n):
    """H = k_f ∫_{R_c}^{R_f} 2πr / max(S, d_f(r)) dr (Musser 2011; spec), closed form.

    R_c = 0 when separated, the ``r_c`` argument when touching; R_f from the layer of the
    larger particle δ_f = ratio × max(R_i, R_j), limited to min(R_i, R_j).
    """
    k_f = p[SL_K_F]
    s_min = p[SL_MIN_GAP]
    if math.isinf(r_j):
        return k_f * musser_wall_factor(r_i, dist, r_c, p[SL_LAYER] * r_i, s_min)
    r_sum = r_i + r_j
    gap = dist - r_sum
    layer = p[SL_LAYER] * max(r_i, r_j)
    if not (gap < layer):
        return 0.0
    r_lo = max(r_c, 0.0) if gap <= 0.0 else 0.0
    rf2 = layer_radius2_spheres(r_i, r_j, dist, gap, layer)
    lo2 = r_lo * r_lo
    if not (rf2 > lo2):
        return 0.0
    sum_b, y_b = sphere_sides(math.sqrt(rf2), r_i, r_j, gap)
    if r_lo > 0.0:
        sum_a, y_a = sphere_sides(r_lo, r_i, r_j, gap)
    else:
        sum_a, y_a = r_sum, gap
    delta = abs(r_i - r_j)
    d2 = (delta * r_sum) * (delta * r_sum)
    if y_a >= s_min:
        return k_f * path_integral_spheres(dist, y_a, y_b, sum_a, sum_b, d2)
    if y_b <= s_min:
        return k_f * math.pi * (rf2 - lo2) / s_min
    annulus = min(max(sub_gap_annulus(dist, gap, s_min, delta, r_sum, lo2), 0.0), rf2 - lo2)
    inner = math.pi * annulus / s_min
    return k_f * (inner + path_integral_spheres(dist, s_min, y_b, dist - s_min, sum_b, d2))


class Musser2011Params(StrictModel):
    """Musser (2011) PhD thesis, West Virginia University: surrounding fluid layer for
    multi-sized particles (spec "Surrounding Layer Models – Model by Musser (2011)").

    H = k_f ∫_{R_c}^{R_f} 2πr / max(S, d - √(R_i² - r²) - √(R_j² - r²)) dr; R_c = 0 when
    separated, R_c^geo (the contact radius the engine passes) when touching; R_f where the
    layer δ_f = ratio × R_k of the larger particle R_k meets the smaller R_l, R_f <= R_l.
    Conducts for d < R_i + R_j + δ_f. Wall: d_f = d - √(R² - r²), R_f = √((R + δ_f)² - d²)
    <= R. k_f = ``thermal.gas.thermal_conductivity``. Row: [k_f, δ_f/R, S].
    """

    layer_thickness_ratio: float = Field(
        default=DEFAULT_LAYER_RATIO,
        gt=0,
        allow_inf_nan=False,
        description="δ_f / R [-], fluid layer of a particle over its radius (Morris 2015: 0.4)",
    )
    min_separation: float = Field(
        default=DEFAULT_MIN_SEPARATION,
        gt=0,
        allow_inf_nan=False,
        description="S [m], minimum conduction distance (Morris 2015: 2.75e-8, ≈ gas λ)",
    )


def pack_musser2011(params: Musser2011Params, pair: PairContext) -> np.ndarray:
    k_f = pair.gas.thermal_conductivity
    return np.array([k_f, params.layer_thickness_ratio, params.min_separation], dtype=np.float64)


def musser2011_range(params: Musser2011Params, radius_i: float, radius_j: float) -> float:
    """Largest surface gap [m] with H > 0: δ_f of the larger particle (wall: ratio × R_i)."""
    r = radius_i if math.isinf(radius_j) else max(radius_i, radius_j)
    return params.layer_thickness_ratio * r


# ---------------------------------------------------------------------- Rong & Horio (1999)
@njit(cache=True, error_model="numpy")
def rong_horio_wall_factor(r, dist, layer, s_min, contact_term):
    """H/k_f [m] for a particle and a flat wall: the spec's analytic solution (Morris et al.
    2015; Lattanzi & Hrenya 2017; Lu et al. 2017) 2π [d ln(y_out/y_in) - (y_out - y_in)],
    y_in = max(S, d - R) (the path at r_in), y_out the path at r_out; plus, with
    ``contact_term``, π r_in²/S for the disk r < r_in where the surfaces are closer than S."""
    gap = dist - r
    if not (gap < layer):
        return 0.0
    q = layer * (2.0 * r + layer)  # (R + δ_f)² - R²
    if dist * dist > q:
        y_out = q / (dist + math.sqrt(dist * dist - q))  # d - √(R² - r_out²)
    else:
        y_out = dist  # r_out = R
    y_in = max(s_min, gap)
    h = path_integral_wall(dist, y_in, y_out) if y_out > y_in else 0.0
    if contact_term != 0.0 and gap < s_min:
        rf2 = min(r * r, (layer - gap) * (r + layer + dist))
        h += math.pi * min(max((s_min - gap) * (2.0 * r + gap - s_min), 0.0), rf2) / s_min
    return h


@njit(cache=True, inline="always", error_model="numpy")
def rong_horio1999_conductance(p, r_i, r_j, dist, r_c, f_n):
    """H = k_f ∫_{θ1}^{θ2} 2π R_p² sinθ cosθ / max(S, d - 2R_p cosθ) dθ
    [+ k_f π (R_p sin θ1)²/S touching, with ``contact_term``] (Rong & Horio 1999; spec).

    Two spheres: :func:`rong_horio1999_spheres`; a wall (``r_j`` = inf): the spec's analytic
    particle-wall solution (:func:`rong_horio_wall_factor`).
    """
    if math.isinf(r_j):
        layer = p[SL_LAYER] * r_i
        return p[SL_K_F] * rong_horio_wall_factor(r_i, dist, layer, p[SL_MIN_GAP],
                                                  p[RH_CONTACT_TERM])  # fmt: skip
    return rong_horio1999_spheres(p, r_i, r_j, dist, r_c, f_n)


@njit(cache=True, inline="always", error_model="numpy")
def rong_horio1999_spheres(p, r_i, r_j, dist, r_c, f_n):
    """:func:`rong_horio1999_conductance` of two spheres (``r_j`` finite).

    R_p = (R_i + R_j)/2, δ_f = ratio × R_p; θ1 = 0 separated, the spec's max(acos(d/2R_p),
    acos(1 - S/2R_p)) touching; θ2 = acos((d² + R_p² - (R_p + δ_f)²)/(2R_p d)) <= π/2. In the
    path length y = d - 2R_p cosθ: y1 = gap (separated) or max(0, gap + S) (touching),
    y2 = ((R_p + δ_f)² - R_p²)/d; the part with y < S is an annulus at k_f/S, the rest
    (π/2)[d ln(y2/y_a) - (y2 - y_a)], y_a = max(y1, S).

    Branch-free (selects only) and with the compiled logarithm of ``kernels/fastmath_log.py``
    (within 1 ulp of ``math.log``), so that the range pass's conductance loop vectorises
    (``kernels/range_pass.py``, which calls this form for its sphere pairs).
    """
    # the row read first: the array view then dies in the first block, and Numba's
    # reference-count pruning drops its incref/decref, a call that keeps a loop scalar
    k_f = p[SL_K_F]
    s_min = p[SL_MIN_GAP]
    ratio = p[SL_LAYER]
    contact_term = p[RH_CONTACT_TERM] != 0.0
    r_sum = r_i + r_j
    r_p = 0.5 * r_sum
    gap = dist - r_sum
    layer = ratio * r_p
    # written without data-dependent branches (selects only): in a bed, touching and
    # separated pairs alternate at random and mispredicted branches cost more than the
    # arithmetic (the 50k bed's range pairs, both forms in one process: 37 -> 26 ns per pair
    # on a busy machine, bit-identical); every piece below is exactly 0 where the branchy
    # form skipped it
    q = layer * (2.0 * r_p + layer)  # (R_p + δ_f)² - R_p²
    y2 = q / dist if dist * dist > q else dist  # cos θ2 >= 0, else θ2 = π/2
    touching = gap <= 0.0
    y1 = max(0.0, gap + s_min) if touching else gap
    inside = (gap < layer) & (y2 > y1)
    # paths shorter than S conduct through S (the spec's Musser remedy): an annulus at k_f/S
    y_lo = min(s_min, y2)
    h = math.pi * max(y_lo - y1, 0.0) * (2.0 * dist - y1 - y_lo) / (4.0 * s_min)
    y_a = max(y1, s_min)
    y_b = max(y2, y_a)
    h += 0.5 * math.pi * (dist * fast_log(y_b / y_a) - (y_b - y_a))
    # π (R_p sin θ1)²/S for touching pairs, (R_p sin θ1)² = R_p² - (d - y1)²/4
    contact = math.pi * (y1 - gap) * (r_sum + dist - y1) / (4.0 * s_min)
    h += contact if touching & contact_term else 0.0
    h = h if inside else 0.0
    return k_f * h


class RongHorio1999Params(StrictModel):
    """Rong & Horio (1999) Proc. 2nd Int. Conf. CFD in the Minerals and Process Industries,
    65-70: surrounding fluid layer, mono-sized particles (spec "Surrounding Layer Models").

    H = k_f ∫_{θ1}^{θ2} 2π R_p sinθ / max(S, d - 2R_p cosθ) d(R_p sinθ), θ1 = 0 when separated
    and the spec's θ1 when touching, θ2 where the layer δ_f = ratio × R_p meets the other
    sphere; ``contact_term`` adds the spec's k_f π (R_p sin θ1)²/S for touching pairs (off by
    default: the spec counts it as contact conduction, Q_cpp, which a direct_conduction model
    already gives). The max(S, ·) is Musser's remedy: the spec's integrand diverges at θ1 once
    the overlap exceeds S, and as the gap of separated pairs closes. Unequal radii: R_p =
    (R_i + R_j)/2 (same surface gap); prefer musser2011 for polydisperse beds. Wall: the
    spec's analytic particle-wall solution (Morris et al. 2015). k_f =
    ``thermal.gas.thermal_conductivity``. Row: [k_f, δ_f/R_p, S, contact_term].
    """

    layer_thickness_ratio: float = Field(
        default=DEFAULT_LAYER_RATIO,
        gt=0,
        allow_inf_nan=False,
        description="δ_f / R_p [-], fluid layer over the particle radius (Morris 2015: 0.4)",
    )
    min_separation: float = Field(
        default=DEFAULT_MIN_SEPARATION,
        gt=0,
        allow_inf_nan=False,
        description="S [m], minimum conduction distance (Morris 2015: 2.75e-8, ≈ gas λ)",
    )
    contact_term: bool = Field(
        default=False,
        description="add k_f π (R_p sin θ1)²/S for touching pairs (contact conduction: off)",
    )


def pack_rong_horio1999(params: RongHorio1999Params, pair: PairContext) -> np.ndarray:
    k_f = pair.gas.thermal_conductivity
    values = [k_f, params.layer_thickness_ratio, params.min_separation]
    return np.array([*values, 1.0 if params.contact_term else 0.0], dtype=np.float64)


def rong_horio1999_range(params: RongHorio1999Params, radius_i: float, radius_j: float) -> float:
    """Largest surface gap [m] with H > 0: δ_f = ratio × (R_i + R_j)/2 (wall: ratio × R_i)."""
    r_p = radius_i if math.isinf(radius_j) else 0.5 * (radius_i + radius_j)
    return params.layer_thickness_ratio * r_p


# --------------------------------------------------------------------------- registration
_PENG = "; Peng, Doroodchi & Moghtaderi (2020) Prog. Energy Combust. Sci. 79 (δ_f, S values)"
_WALL = (
    "; Morris et al. (2015) Int. J. Heat Mass Transf. 89, 1277-1289; Lattanzi & Hrenya (2017) "
    "AIChE J. 63, 4685-4693 (wall)"
)
_COMMON = dict(
    family=FAMILY,
    requires=(),
    uses_gas=("thermal_conductivity",),
    antisymmetric=False,
    symmetric=True,
    swap_pairs=(),
    target="range",
)

register(
    name="rong_horio1999",
    model_id=RONG_HORIO1999,
    kernel=rong_horio1999_conductance,
    params=RongHorio1999Params,
    pack=pack_rong_horio1999,
    summary="surrounding fluid layer, mono-sized (mean radius), optional contact term",
    reference="Rong & Horio (1999) Proc. 2nd Int. Conf. CFD Miner. Process Ind., Melbourne, "
    "65-70" + _WALL + _PENG,
    interaction_range=rong_horio1999_range,
    range_parameter="layer_thickness_ratio",
    columns=RH_COLUMNS,
    uses_contact_radius=False,
    **_COMMON,
    planar=("sphere",),
)
register(
    name="musser2011",
    model_id=MUSSER2011,
    kernel=musser2011_conductance,
    params=Musser2011Params,
    pack=pack_musser2011,
    summary="surrounding fluid layer, multi-sized: ∫ 2πr k_f / max(S, d_f(r)) dr, closed form",
    reference="Musser (2011) PhD thesis, West Virginia University" + _WALL + _PENG,
    interaction_range=musser2011_range,
    range_parameter="layer_thickness_ratio",
    columns=MUSSER_COLUMNS,
    **_COMMON,
    planar=("sphere",),
)
