"""Voronoi-based conduction through the interstitial fluid (family ``indirect_conduction``,
``target="external"``): models A and B of Cheng, Yu & Zulli (1999), with the multi-size
extensions of Gan et al. (2016) (model A) and Chen et al. (2019) (model B) and the flat-wall
adaptation of the spec ("Voronoi-Based Models").

Kernel signature (float64 scalars, ``p`` the packed row of the type pair, ``inputs`` the
pair's row of the external pair set)::

    kernel(p, r_i, r_j, dist, r_c, inputs) -> conductance H [W/K] >= 0

``inputs[INPUT_FACE_AREA]`` is A_n [m²], the area of the Voronoi face the two cells share
(or of the cell's face on the wall), from the tessellation (``engine/tessellation.py``) or from
the porosity closure of Zhou et al. (2009). The double pyramid on that face is replaced by the
double tapered cone of the same base area, radius r_ij = √(A_n/π); with the pyramid's volume
V_ij = A_n d_ij / 3 this is the spec's r_ij = √(3 V_ij/(π d_ij)). ``dist`` is the centre
distance (a wall: r_j = inf, dist = d_pw the distance from the centre to the wall plane);
``r_c`` the contact radius where the bodies overlap (the geometric R_c), else 0.

Every kernel returns 0 when the surface gap is at or beyond ``cutoff_gap_ratio`` × R̃ (the
spec's remark after Zhou et al. 2009: model A conducts negligibly once d_ij >= 3 R_p, i.e. a
gap of R_p; "a similar cut-off value should be set" for the others; R̃ = (R_i + R_j)/2, or R_i
at a wall), when the face is smaller than the contact (nothing left to conduct through the
fluid), and NaN for a NaN input (the engine's NaN flag).

Swapping i and j (radii, inputs, the row columns in ``swap_pairs``) gives the same H bit for
bit: each kernel orders the two sides canonically (smaller radius first, then smaller k,
then smaller core) before it evaluates the asymmetric formulas.

Formulas, choices and their checks: ``docs/models/indirect_conduction-voronoi_a.md`` and
``-voronoi_b.md``.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, field_validator

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.models.thermal.contact_radius import require
from thermodem.models.thermal.voronoi_integrals import arctan_ratio, cone_integral, model_a_integral
from thermodem.state.materials import PairContext

FAMILY = "indirect_conduction"

VORONOI_A = 5
VORONOI_B = 6

#: Columns of a pair's input row in the external pair set.
INPUT_FACE_AREA = 0
INPUT_WIDTH = 1

#: Multi-size rules.
SIZES_GENERAL = 0  # model A: Gan et al. (2016); model B: Chen et al. (2019)
SIZES_MEAN_RADIUS = 1  # the mono-size formula with R_p = (R_i + R_j)/2 (Norouzi et al. 2016)

# model A row
A_K_I = 0
A_K_J = 1
A_K_F = 2
A_SIZES = 3
A_CUTOFF = 4
A_COLUMNS = ("k_i", "k_j", "k_f", "multi_size", "cutoff_gap_ratio")
A_SWAP_PAIRS = ((A_K_I, A_K_J),)

# model B row
B_K_I = 0
B_K_J = 1
B_K_F = 2
B_CORE_I = 3
B_CORE_J = 4
B_SIZES = 5
B_CUTOFF = 6
B_COLUMNS = ("k_i", "k_j", "k_f", "core_ratio_i", "core_ratio_j", "multi_size",
             "cutoff_gap_ratio")  # fmt: skip
B_SWAP_PAIRS = ((B_K_I, B_K_J), (B_CORE_I, B_CORE_J))


# ------------------------------------------------------------------------ parameters
class _Common(StrictModel):
    geometry: Literal["tessellation", "porosity"] = Field(
        default="tessellation",
        description="where the face area A_n comes from: the Voronoi tessellation "
        "(thermal.tessellation), or the porosity closure of Zhou et al. (2009), "
        "A_n = 0.985 R² (1 - ε)^(-2/3), with ε from thermal.porosity",
    )
    cutoff_gap_ratio: float = Field(
        default=1.0,
        gt=0,
        description="no conduction once the surface gap is >= this × (R_i + R_j)/2 (a wall: "
        "× R_i); 1.0: Zhou et al. (2009), d_ij >= 3 R_p",
    )


class VoronoiAParams(_Common):
    """Voronoi model A, Cheng, Yu & Zulli (1999) Int. J. Heat Mass Transfer 42, 2847-2856:
    the double tapered cone's surface is isothermal, the region outside it does not conduct
    and the heat paths are parallel to the line of centres; H is an integral over the path
    radius r from R_c to r_sf: elementary when the path crosses one sphere size (mono-size,
    mean radius, a wall; ``voronoi_integrals.cone_integral``), else (Gan et al. 2016 with
    R_i != R_j) by a compiled quadrature (``voronoi_integrals.model_a_integral``).

    Mono-size (R_i = R_j = R_p)::

        H = ∫ 2πr dr / [ (√(R_p² - r²) - d r/(2 r_ij))/k + (d - 2√(R_p² - r²))/k_f ]
        r_sf = R_p r_ij / √(r_ij² + (d/2)²),    k = k̄ = (1/k_i + 1/k_j)^-1

    Multi-size: ``gan2016`` (Gan et al. 2016), the integral with β_i, D_i, r_ij, r'_ij of the
    spec, or ``mean_radius`` (Norouzi et al. 2016), the mono formula with R_p = (R_i + R_j)/2
    (from the larger of R_c and the radius where the two mean spheres part).
    A flat wall: d_p = √(R_p² - r²) - d_pw r/r_ij in the particle (k_p = k_i), d_f = d_pw -
    √(R_p² - r²) in the fluid, r_sf = R_p r_ij/√(r_ij² + d_pw²); conduction in the wall is
    neglected. Row: [k_i, k_j, k_f, multi_size, cutoff_gap_ratio].
    """

    multi_size: Literal["gan2016", "mean_radius"] = Field(
        default="gan2016",
        description="unequal radii: gan2016 (Gan et al. 2016) or mean_radius (Norouzi et al. "
        "2016: the mono-size formula with R_p = (R_i + R_j)/2)",
    )


#: Isothermal core ratio r_c/R_p of Chen et al. (2019) by k_p/k_f: 0.6 for 1 < k_p/k_f <= 5,
#: 0.5 above (their range ends at 10^4; above it the core hardly matters and 0.5 is kept).
def chen2019_core_ratio(k_ratio: float) -> float:
    return 0.6 if k_ratio <= 5.0 else 0.5


class VoronoiBParams(_Common):
    """Voronoi model B, Cheng, Yu & Zulli (1999): each particle has an isothermal core of
    radius r_c at its temperature and the heat paths radiate from the centres (closed form).

    Mono-size (Cheng et al. 1999)::

        H = (π/b) ln[(a - b cos θ_0)/(a - b cos θ_c)]
        a = (1/(2k̄)) (1/r_c - 1/R_p) + 1/(k_f R_p),  b = 2/(k_f d),  k̄ = (1/k_i + 1/k_j)^-1
        cos θ_0 = d / (2√(r_ij² + (d/2)²)),  cos θ_c = d / (2√(R_c² + (d/2)²))

    Multi-size: ``chen2019`` (Chen et al. 2019, Powder Technol. 353, the Λ, Δγ, A, B, δ, X, Y
    formulas of the spec, which reduce to the mono form for equal radii) or ``mean_radius``
    (the mono form with R_p = (R_i + R_j)/2). A flat wall: a = (1/(2k_p))(1/r_c - 1/R_p) +
    1/(2 k_f R_p), b = 1/(2 k_f d_pw), cos θ_0 = d_pw/√(r_ij² + d_pw²). Not valid for
    k_p/k_f < 1 (no isothermal core; refused). Row: [k_i, k_j, k_f, r_c,i/R_i, r_c,j/R_j,
    multi_size, cutoff_gap_ratio].
    """

    core_radius_ratio: float | Literal["chen2019"] = Field(
        default="chen2019",
        description="isothermal core r_c/R_p (0 < . < 1), or chen2019: 0.6 for 1 < k_p/k_f <= "
        "5, 0.5 above (Chen et al. 2019; 0.5: Cheng et al. 1999 for mono-size)",
    )
    multi_size: Literal["chen2019", "mean_radius"] = Field(
        default="chen2019",
        description="unequal radii: chen2019 (Chen et al. 2019) or mean_radius (the mono-size "
        "formula with R_p = (R_i + R_j)/2)",
    )

    @field_validator("core_radius_ratio")
    @classmethod
    def _ratio(cls, v: float | str) -> float | str:
        if not isinstance(v, str) and not (0.0 < v < 1.0):
            raise ValueError(f"core_radius_ratio must be in (0, 1) or 'chen2019', got {v!r}")
        return v


def _conductivities(pair: PairContext, model: str) -> tuple[float, float, float]:
    k_i = require(pair.mat_i, "thermal_conductivity", model)
    # a wall: conduction in the wall is not considered (the spec's flat-wall adaptation)
    k_j = k_i if pair.is_wall else require(pair.mat_j, "thermal_conductivity", model)
    return k_i, k_j, float(pair.gas.thermal_conductivity)


def pack_voronoi_a(params: VoronoiAParams, pair: PairContext) -> np.ndarray:
    k_i, k_j, k_f = _conductivities(pair, f"{FAMILY}.voronoi_a")
    sizes = SIZES_GENERAL if params.multi_size == "gan2016" else SIZES_MEAN_RADIUS
    values = {"k_i": k_i, "k_j": k_j, "k_f": k_f, "multi_size": sizes,
              "cutoff_gap_ratio": params.cutoff_gap_ratio}  # fmt: skip
    return packed(A_COLUMNS, values)


def pack_voronoi_b(params: VoronoiBParams, pair: PairContext) -> np.ndarray:
    model = f"{FAMILY}.voronoi_b"
    k_i, k_j, k_f = _conductivities(pair, model)
    cores = []
    for side, k in (("i", k_i), ("j", k_j)):
        if not k / k_f > 1.0:
            raise ValueError(
                f"{model} is not valid for k_p/k_f <= 1 (no isothermal core, Chen et al. 2019): "
                f"the material of side {side} has k_p = {k:g} W/(m K), "
                f"thermal.gas.thermal_conductivity "
                f"= {k_f:g} W/(m K), k_p/k_f = {k / k_f:.4g}; use voronoi_a"
            )
        ratio = params.core_radius_ratio
        cores.append(chen2019_core_ratio(k / k_f) if isinstance(ratio, str) else float(ratio))
    if pair.is_wall:
        cores[1] = cores[0]
    sizes = SIZES_GENERAL if params.multi_size == "chen2019" else SIZES_MEAN_RADIUS
    values = {"k_i": k_i, "k_j": k_j, "k_f": k_f, "core_ratio_i": cores[0],
              "core_ratio_j": cores[1], "multi_size": sizes,
              "cutoff_gap_ratio": params.cutoff_gap_ratio}  # fmt: skip
    return packed(B_COLUMNS, values)


def voronoi_range(params: _Common, radius_i: float, radius_j: float) -> float:
    """Largest surface gap [m] at which H > 0: cutoff × (R_i + R_j)/2 (a wall: × R_i)."""
    scale = radius_i if math.isinf(radius_j) else 0.5 * (radius_i + radius_j)
    return params.cutoff_gap_ratio * scale


# ------------------------------------------------------------------------- model A
@njit(cache=True, inline="always", error_model="numpy")
def _gap_beyond_cutoff(r_i, r_j, dist, ratio):
    if math.isinf(r_j):
        return dist - r_i >= ratio * r_i
    return dist - (r_i + r_j) >= ratio * 0.5 * (r_i + r_j)


@njit(cache=True, error_model="numpy")
def voronoi_a_conductance(p, r_i, r_j, dist, r_c, inputs):
    """H of Voronoi model A (see VoronoiAParams) for a pair or a flat wall (r_j = inf)."""
    area = inputs[INPUT_FACE_AREA]
    if math.isnan(area) or math.isnan(dist):
        return np.nan
    if not area > 0.0 or _gap_beyond_cutoff(r_i, r_j, dist, p[A_CUTOFF]):
        return 0.0
    r_ij = math.sqrt(area / math.pi)
    ik_f = 1.0 / p[A_K_F]
    if math.isinf(r_j):  # a flat wall: one particle, d_pw = dist
        r_sf = r_i * r_ij / math.sqrt(r_ij * r_ij + dist * dist)
        return cone_integral(1.0 / p[A_K_I], ik_f, dist, r_ij, r_i, r_c, r_sf)
    k_i = p[A_K_I]
    k_j = p[A_K_J]
    if p[A_SIZES] == SIZES_MEAN_RADIUS or r_i == r_j:
        # mono-size: k = k̄ = (1/k_i + 1/k_j)^-1, both halves of the path alike
        r_p = 0.5 * (r_i + r_j)
        half = 0.5 * dist
        r_sf = r_p * r_ij / math.sqrt(r_ij * r_ij + half * half)
        ik = (k_i + k_j) / (k_i * k_j)
        # the paths start where the two mean spheres part (no negative fluid path)
        r_lo = max(r_c, math.sqrt(max(r_p * r_p - half * half, 0.0)))
        return cone_integral(ik, 2.0 * ik_f, half, r_ij, r_p, r_lo, r_sf)
    # Gan et al. (2016), written for R_i <= R_j: s is the smaller particle, l the larger
    if r_i < r_j:
        r_s, r_l, k_s, k_l = r_i, r_j, k_i, k_j
    else:
        r_s, r_l, k_s, k_l = r_j, r_i, k_j, k_i
    if r_c > 0.0:
        d_s = math.sqrt(max(r_s * r_s - r_c * r_c, 0.0))
    else:
        d_s = (r_s * r_s - r_l * r_l + dist * dist) / (2.0 * dist)
    d_l = dist - d_s
    r_sf = r_s * r_ij / math.sqrt(r_ij * r_ij + d_s * d_s)
    c_l = d_l * r_sf / math.sqrt(max(r_l * r_l - r_sf * r_sf, 0.0))
    return model_a_integral(r_s, d_s, r_ij, 1.0 / k_s, r_l, d_l, c_l, 1.0 / k_l, dist, ik_f,
                            False, r_c, r_sf)  # fmt: skip


# ------------------------------------------------------------------------- model B
@njit(cache=True, inline="always", error_model="numpy")
def cheng_b(a, b, cos_0, cos_c):
    """(π/b) ln[(a - b cos θ_0)/(a - b cos θ_c)] of model B (log1p form)."""
    return math.pi / b * math.log1p(b * (cos_c - cos_0) / (a - b * cos_c))


@njit(cache=True, inline="always", error_model="numpy")
def _quadratic_integral(u1, u2, lam):
    """∫_{u1}^{u2} du/(u² - Λ), in a form without cancellation near Λ = 0:
    (u2 - u1)/(u1 u2 - Λ) × f(ζ²), ζ² = Λ (u2 - u1)²/(u1 u2 - Λ)², f = artanh(ζ)/ζ for
    ζ² > 0, atan(|ζ|)/|ζ| for ζ² < 0, 1 + ζ²/3 + ζ⁴/5 + ... near 0."""
    ratio = (u2 - u1) / (u1 * u2 - lam)
    return ratio * arctan_ratio(lam * ratio * ratio)


@njit(cache=True, error_model="numpy")
def chen_b(k_i, k_j, k_f, core_i, core_j, r_i, r_j, dist, r_c, area):
    """H of Chen et al. (2019)'s multi-size model B (i, j as given; see voronoi_b_conductance
    for the canonical order). Their closed forms for Λ > 0, Λ = 0, Λ < 0 are one integral,
    π k_f d (1 - Δγ²) ∫ dδ/P(δ) with P = (A + B) δ² + 2 (B Δγ - 1) δ + Δγ (B Δγ - 1)
    = (u² - Λ)/(A + B), u = (A + B) δ + B Δγ - 1 = √|Λ| X, evaluated by _quadratic_integral."""
    g_i = r_i / dist
    g_j = r_j / dist
    dg = g_j - g_i
    big_a = (k_i + k_f * (1.0 / core_i - 1.0)) / (k_i * g_i)
    big_b = (k_j + k_f * (1.0 / core_j - 1.0)) / (k_j * g_j)
    lam = (1.0 + dg * big_a) * (1.0 - dg * big_b)
    one = 1.0 - dg * dg
    d_max = 0.5 * (math.sqrt(1.0 + 4.0 * area / (math.pi * dist * dist * one)) - dg)
    d_min = 0.5 * (math.sqrt(1.0 + 4.0 * r_c * r_c / (dist * dist * one)) - dg)
    if not d_max > d_min:
        return 0.0
    u_min = (big_a + big_b) * d_min + dg * big_b - 1.0
    u_max = (big_a + big_b) * d_max + dg * big_b - 1.0
    return math.pi * k_f * dist * one * _quadratic_integral(u_min, u_max, lam)


@njit(cache=True, error_model="numpy")
def voronoi_b_conductance(p, r_i, r_j, dist, r_c, inputs):
    """H of Voronoi model B (see VoronoiBParams) for a pair or a flat wall (r_j = inf)."""
    area = inputs[INPUT_FACE_AREA]
    if math.isnan(area) or math.isnan(dist):
        return np.nan
    if not area > 0.0 or _gap_beyond_cutoff(r_i, r_j, dist, p[B_CUTOFF]):
        return 0.0
    k_f = p[B_K_F]
    r_ij2 = area / math.pi
    if r_ij2 <= r_c * r_c:
        return 0.0
    if math.isinf(r_j):  # a flat wall at d_pw = dist
        k_p = p[B_K_I]
        core = p[B_CORE_I] * r_i
        a = 0.5 / k_p * (1.0 / core - 1.0 / r_i) + 0.5 / (k_f * r_i)
        b = 0.5 / (k_f * dist)
        cos_0 = dist / math.sqrt(r_ij2 + dist * dist)
        cos_c = dist / math.sqrt(r_c * r_c + dist * dist)
        return cheng_b(a, b, cos_0, cos_c)
    k_i = p[B_K_I]
    k_j = p[B_K_J]
    c_i = p[B_CORE_I]
    c_j = p[B_CORE_J]
    if p[B_SIZES] == SIZES_MEAN_RADIUS:
        r_p = 0.5 * (r_i + r_j)
        # 1/(2k̄)(1/r_c - 1/R_p) with each side's own core and conductivity
        a = 0.5 * ((1.0 / (c_i * r_p) - 1.0 / r_p) / k_i + (1.0 / (c_j * r_p) - 1.0 / r_p) / k_j)
        a += 1.0 / (k_f * r_p)
        b = 2.0 / (k_f * dist)
        half2 = 0.25 * dist * dist
        cos_0 = 0.5 * dist / math.sqrt(r_ij2 + half2)
        cos_c = 0.5 * dist / math.sqrt(r_c * r_c + half2)
        return cheng_b(a, b, cos_0, cos_c)
    # canonical order: smaller radius first, then smaller k, then smaller core
    if (r_i, k_i, c_i) <= (r_j, k_j, c_j):
        return chen_b(k_i, k_j, k_f, c_i, c_j, r_i, r_j, dist, r_c, area)
    return chen_b(k_j, k_i, k_f, c_j, c_i, r_j, r_i, dist, r_c, area)


# ---------------------------------------------------------------------- dispatcher
@njit(cache=True, inline="always", error_model="numpy")
def voronoi_dispatch(model_id, p, r_i, r_j, dist, r_c, inputs):
    """Conductance H [W/K] of the Voronoi model ``model_id`` (NaN for any other id)."""
    if model_id == VORONOI_A:
        return voronoi_a_conductance(p, r_i, r_j, dist, r_c, inputs)
    elif model_id == VORONOI_B:
        return voronoi_b_conductance(p, r_i, r_j, dist, r_c, inputs)
    return np.nan


@njit(cache=True, inline="always", error_model="numpy")
def voronoi_cutoff_distance(model_id, p, r_i, r_j):
    """The centre distance of the cut-off, R_i + R_j + cutoff_gap_ratio × (R_i + R_j)/2."""
    ratio = p[A_CUTOFF] if model_id == VORONOI_A else p[B_CUTOFF]
    return (r_i + r_j) * (1.0 + 0.5 * ratio)


@njit(cache=True, inline="always", error_model="numpy")
def voronoi_side(model_id, p, r_i, r_j, dist):
    """Where a pair at centre distance ``dist`` is relative to the two places where H(d) is
    not smooth: 0 overlapping (d < R_i + R_j: a contact radius R_c > 0), 1 separated within
    the cut-off, 2 at or beyond the cut-off (H = 0; the same test as the kernels). The
    conductance reuse of ``thermal.tessellation.conductance_gap_tolerance`` never carries a
    conductance across them (``kernels/heat_terms.py``: the external pair pass)."""
    if dist < r_i + r_j:
        return 0
    ratio = p[A_CUTOFF] if model_id == VORONOI_A else p[B_CUTOFF]
    if _gap_beyond_cutoff(r_i, r_j, dist, ratio):
        return 2
    return 1


# -------------------------------------------------------------- the porosity closure
@njit(cache=True, inline="always", error_model="numpy")
def closure_face_area(radius, porosity):
    """A_n = 0.985 R² (1 - ε)^(-2/3) of Zhou et al. (2009) after Yang et al. (2002):
    r_ij = √(A_n/π) = 0.560 R (1 - ε)^(-1/3)."""
    return 0.985 * radius * radius * (1.0 - porosity) ** (-2.0 / 3.0)


# -------------------------------------------------------------------- registration
_CHENG = "Cheng, Yu & Zulli (1999) Int. J. Heat Mass Transfer 42, 2847-2856"
_ZHOU = "Zhou, Yu & Zulli (2009) AIChE J. 55, 868-884 (cut-off, porosity closure)"

register(
    family=FAMILY,
    name="voronoi_a",
    model_id=VORONOI_A,
    kernel=voronoi_a_conductance,
    params=VoronoiAParams,
    pack=pack_voronoi_a,
    summary="Voronoi model A: fluid conduction in the double cone of the shared Voronoi face "
    "(closed form; quadrature for gan2016's unequal radii)",
    reference=f"{_CHENG}; Gan et al. (2016) (multi-size); Norouzi et al. (2016) (mean radius); "
    f"{_ZHOU}",
    requires=("thermal_conductivity",),
    uses_gas=("thermal_conductivity",),
    interaction_range=voronoi_range,
    antisymmetric=False,
    symmetric=True,
    columns=A_COLUMNS,
    swap_pairs=A_SWAP_PAIRS,
    target="external",
)
register(
    family=FAMILY,
    name="voronoi_b",
    model_id=VORONOI_B,
    kernel=voronoi_b_conductance,
    params=VoronoiBParams,
    pack=pack_voronoi_b,
    summary="Voronoi model B: isothermal cores, radial heat paths to the shared Voronoi face "
    "(closed form)",
    reference=f"{_CHENG}; Chen et al. (2019) (multi-size); {_ZHOU}",
    requires=("thermal_conductivity",),
    uses_gas=("thermal_conductivity",),
    interaction_range=voronoi_range,
    antisymmetric=False,
    symmetric=True,
    columns=B_COLUMNS,
    swap_pairs=B_SWAP_PAIRS,
    target="external",
)
