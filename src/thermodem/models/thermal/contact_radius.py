"""Contact radius models (family ``contact_radius``), including low-stiffness corrections.

Kernel signature (all float64 scalars, ``p`` the packed parameter row of the type pair)::

    kernel(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff) -> contact radius [m]

i.e. (p, radius_i, radius_j, distance, overlap, normal_force, contact_duration,
impact_velocity, mass_eff). ``overlap`` δ > 0 in contact (R_i + R_j - d for two particles,
R_i - d for a particle-wall pair; the kernels use δ, not ``dist``); ``f_n`` the normal contact
force (negative while a damped contact opens: taken as zero); ``t_contact`` the time since
first contact [s]; ``v_impact`` the normal approach speed at first contact [m/s]; ``m_eff`` m*.
A wall is passed as ``radius_j = inf`` (its material is ``mat_j`` in ``pack``); every kernel
then returns the R_j -> inf limit (R* = R_i). Kernels return 0 when the pair does not touch.
The result is symmetric in i and j, so ``antisymmetric=False`` and the rows need no swap.

Kernels are compiled with ``error_model="numpy"``: they never raise (a division by zero gives
inf/NaN, which the NaN flag of the pair loop catches), as the architecture asks of kernels.

Spec: ``dem-heat-transfer-models.md`` appendix A (Hertz, geometry) and section 2.8 (low
stiffness corrections). The derivations and choices are in ``docs/models/contact_radius-*.md``.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.state.materials import Material, PairContext, effective_youngs_modulus

NONE = 0
GEOMETRIC = 1
HERTZ_FORCE = 2
HERTZ_OVERLAP = 3
ZHOU2010 = 4
LU2017 = 5
MORRIS2016_AREA = 6
MORRIS2016_AREA_TIME = 7

FAMILY = "contact_radius"

# Named columns of the packed rows (``register(columns=...)``; kernels index ``p`` by these).
HERTZ_FORCE_COLUMNS = ("e_star",)
HF_E_STAR = 0
ZHOU2010_COLUMNS = ("e_star", "correction_factor", "from_force")
Z10_E_STAR, Z10_FACTOR, Z10_FROM_FORCE = 0, 1, 2
LU2017_COLUMNS = ("normal_stiffness", "e_star_real")
LU_STIFFNESS, LU_E_STAR_REAL = 0, 1
MORRIS_AREA_COLUMNS = ("e_star_real",)
MA_E_STAR_REAL = 0
MORRIS_AREA_TIME_COLUMNS = ("e_star_real", "e_star", "linear_law", "normal_stiffness")
MAT_E_STAR_REAL, MAT_E_STAR, MAT_LINEAR, MAT_STIFFNESS = 0, 1, 2, 3


# ------------------------------------------------------------------ shared scalar helpers
@njit(cache=True, error_model="numpy")
def effective_radius(radius_i, radius_j):
    """R* = (1/R_i + 1/R_j)^-1 (appendix A); R_j = inf (wall) gives R_i. Exactly symmetric."""
    return 1.0 / (1.0 / radius_i + 1.0 / radius_j)


@njit(cache=True, error_model="numpy")
def hertz_radius_from_force(normal_force, eff_radius, e_star):
    """R_c = (3 F_n R* / (4 E*))^{1/3} (appendix A, static Hertz); 0 for F_n <= 0."""
    if normal_force <= 0.0:
        return 0.0
    return (0.75 * normal_force * eff_radius / e_star) ** (1.0 / 3.0)


@njit(cache=True, error_model="numpy")
def hertz_max_contact_radius(mass_eff, eff_radius, e_star, impact_velocity):
    """R_c^max = (15/16 m* R*² v² / E*)^{1/5} of an elastic Hertz impact (appendix A)."""
    return (15.0 / 16.0 * mass_eff * eff_radius**2 * impact_velocity**2 / e_star) ** 0.2


@njit(cache=True, error_model="numpy")
def hertz_collision_time(mass_eff, eff_radius, e_star, impact_velocity):
    """t_c = 2.87 (m*² / (R* E*² v))^{1/5}, total elastic Hertz collision time (appendix A)."""
    return 2.87 * (mass_eff**2 / (eff_radius * e_star**2 * impact_velocity)) ** 0.2


@njit(cache=True, error_model="numpy")
def geometric_contact_radius(radius_i, radius_j, overlap):
    """Radius of the intersection circle of two spheres (appendix A, R_c^geo).

    Written with the cap height of sphere i, h_i = δ (2R_j - δ) / (2 d) with d = R_i + R_j - δ,
    and a² = h_i (2R_i - h_i). This equals the spec's form in d_ij but avoids its cancellation
    for small δ (one division, no difference of nearly equal squares). A wall (R_j = inf) has
    the limit h_i = δ, a² = δ (2R_i - δ). Equal spheres: a² = Rδ - δ²/4.
    """
    if overlap <= 0.0:
        return 0.0
    if radius_j == math.inf:
        h = overlap
    else:
        h = overlap * (2.0 * radius_j - overlap) / (2.0 * (radius_i + radius_j - overlap))
    a2 = h * (2.0 * radius_i - h)
    return math.sqrt(a2) if a2 > 0.0 else 0.0


def require(mat: Material, prop: str, model: str) -> float:
    """A material property a model needs, or a ValueError naming it."""
    value = getattr(mat, prop)
    if value is None:
        raise ValueError(f"model {model} needs the material property {prop!r}, which is not set")
    return float(value)


def effective_youngs_modulus_real(pair: PairContext, model: str) -> float:
    """E*_real from both materials' ``youngs_modulus_real`` (required by the corrections)."""
    require(pair.mat_i, "youngs_modulus_real", model)
    require(pair.mat_j, "youngs_modulus_real", model)
    return effective_youngs_modulus(pair.mat_i, pair.mat_j, real=True)


# ------------------------------------------------------------------------------ none
class NoneParams(StrictModel):
    """No contact radius (0): for cases where no selected model uses it."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def none_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    return 0.0


# -------------------------------------------------------------------------- geometric
class GeometricParams(StrictModel):
    """Radius of the circle where the two spheres' surfaces intersect (Weisstein; Musser 2011).

    Independent of the contact law; spec appendix A "geometry based". No parameters.
    """


def pack_geometric(params: GeometricParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def geometric_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    return geometric_contact_radius(r_i, r_j, overlap)


# ------------------------------------------------------------------------ Hertz (force)
class HertzForceParams(StrictModel):
    """Static Hertz radius from the normal force, R_c = (3 F_n R*/(4 E*))^{1/3} (Hertz 1882;
    Johnson 1985; spec appendix A), with the simulation's E*. Row: [E*]."""


def pack_hertz_force(params: HertzForceParams, pair: PairContext) -> np.ndarray:
    return packed(HERTZ_FORCE_COLUMNS, {"e_star": pair.effective_youngs_modulus})


@njit(cache=True, error_model="numpy")
def hertz_force_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    return hertz_radius_from_force(f_n, effective_radius(r_i, r_j), p[HF_E_STAR])


# ---------------------------------------------------------------------- Hertz (overlap)
class HertzOverlapParams(StrictModel):
    """Hertz radius from the overlap, R_c = sqrt(R* δ) (Hertz 1882; spec appendix A)."""


def pack_hertz_overlap(params: HertzOverlapParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def hertz_overlap_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    return math.sqrt(effective_radius(r_i, r_j) * overlap)


# ---------------------------------------------------------------------------- Zhou 2010
class Zhou2010Params(StrictModel):
    """Low-stiffness correction of Zhou, Yu & Zulli (2010), Powder Technol. 197, 102-110.

    R_c^cor = (E*_sim / E*_real)^{1/5} R_c^htz: the Hertz radius of an elastic impact scales as
    E*^{-1/5} at a given impact speed (appendix A, R_c^max). ``hertz_from`` selects the Hertz
    radius that is scaled: ``overlap`` (sqrt(R* δ), independent of the contact law, default) or
    ``force`` ((3 F_n R*/(4 E*_sim))^{1/3}, as in Beaulieu 2020). Needs ``youngs_modulus_real``
    on both materials. Row: [E*_sim, (E*_sim/E*_real)^{1/5}, 0 overlap | 1 force].
    """

    hertz_from: Literal["overlap", "force"] = Field(
        default="overlap", description="Hertz radius that is corrected: from overlap or force"
    )


def pack_zhou2010(params: Zhou2010Params, pair: PairContext) -> np.ndarray:
    e_sim = pair.effective_youngs_modulus
    e_real = effective_youngs_modulus_real(pair, "contact_radius.zhou2010")
    mode = 1.0 if params.hertz_from == "force" else 0.0
    values = {"e_star": e_sim, "correction_factor": (e_sim / e_real) ** 0.2, "from_force": mode}
    return packed(ZHOU2010_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def zhou2010_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    r_eff = effective_radius(r_i, r_j)
    if p[Z10_FROM_FORCE] == 1.0:
        return p[Z10_FACTOR] * hertz_radius_from_force(f_n, r_eff, p[Z10_E_STAR])
    return p[Z10_FACTOR] * math.sqrt(r_eff * overlap)


# ------------------------------------------------------------------------------ Lu 2017
class Lu2017Params(StrictModel):
    """Low-stiffness correction of Lu, Morris, Li & Benyahia (2017), IJHMT 111, 723-735,
    for a linear spring contact law, derived from its definition.

    The real Hertz contact carries the same normal force as the simulation's linear spring:
    k_n δ = (4/3) E*_real sqrt(R*) δ_real^{3/2}, so δ_real = (k_n δ / K_HZ,real)^{2/3} and

        R_c^cor = sqrt(R* δ_real) = (3 k_n δ R* / (4 E*_real))^{1/3}.

    The spec prints R_c^cor = (K_n R_c / K_HZ,real)^{2/3}: that is the real *overlap* for a
    force K_n R_c (R_c standing where δ should be), not a radius; it differs from the
    derivation by the factor (3 k_n / (4 E*_real R*))^{1/3}. See docs/models/contact_radius-
    lu2017.md. The elastic spring force k_n δ is used (not the damped normal force).
    Needs ``youngs_modulus_real`` on both materials. Row: [k_n, E*_real].
    """

    normal_stiffness: float = Field(
        gt=0,
        description="k_n [N/m], the linear spring stiffness used by the simulation's normal "
        "contact law (the same value as normal.linear's stiffness)",
    )


def pack_lu2017(params: Lu2017Params, pair: PairContext) -> np.ndarray:
    e_real = effective_youngs_modulus_real(pair, "contact_radius.lu2017")
    values = {"normal_stiffness": params.normal_stiffness, "e_star_real": e_real}
    return packed(LU2017_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def lu2017_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    f_spring = p[LU_STIFFNESS] * overlap
    return hertz_radius_from_force(f_spring, effective_radius(r_i, r_j), p[LU_E_STAR_REAL])


# ------------------------------------------------------------------------ Morris 2016a
class Morris2016AreaParams(StrictModel):
    """Area correction of Morris, Pannala, Ma & Hrenya (2016a), AIChE J. 62, 4526-4535.

    R_c^cor = (3 F_n R* / (4 E*_real))^{1/3}: the real Hertz radius at the simulated normal
    force. The spec prints (F_n R*/E*_real)^{1/3}, without the 3/4 of the Hertz radius it
    replaces (appendix A); the Hertz form is used here so that E_real = E_sim gives back the
    uncorrected Hertz radius. Needs ``youngs_modulus_real``. Row: [E*_real].
    """


def pack_morris2016_area(params: Morris2016AreaParams, pair: PairContext) -> np.ndarray:
    e_real = effective_youngs_modulus_real(pair, "contact_radius.morris2016_area")
    return packed(MORRIS_AREA_COLUMNS, {"e_star_real": e_real})


@njit(cache=True, error_model="numpy")
def morris2016_area_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    return hertz_radius_from_force(f_n, effective_radius(r_i, r_j), p[MA_E_STAR_REAL])


class Morris2016AreaTimeParams(StrictModel):
    """Area and time corrections of Morris et al. (2016a), as an effective radius.

    R_c^eff = (3 F_n R*/(4 E*_real))^{1/3} (t_c,real / t_c)^{2/3}, so that Q = 2 k R_c^eff ΔT
    (Batchelor & O'Brien simple) is Morris' corrected rate. Only meaningful for conduction laws
    linear in R_c (batchelor_obrien_simple), not for area-based ones (thermal pipes).
    t_c,real is the Hertz collision time with E*_real (appendix A); t_c that of the simulation's
    contact law: ``hertz`` (E*_sim; the ratio is then (E*_sim/E*_real)^{2/5}) or ``linear``
    (undamped half period π sqrt(m*/k_n)). The time factor is applied only while
    contact_duration < t_c and for impact_velocity > 0: Morris' time correction is derived for
    a binary collision and is unity for enduring (static) contacts.
    Needs ``youngs_modulus_real``. Row: [E*_real, E*_sim, 0 hertz | 1 linear, k_n].
    """

    contact_law: Literal["hertz", "linear"] = Field(
        default="hertz", description="normal contact law of the simulation (for t_c)"
    )
    normal_stiffness: float | None = Field(
        default=None,
        gt=0,
        description="k_n [N/m] of the linear spring contact law; required when contact_law is "
        "'linear'",
    )


def pack_morris2016_area_time(params: Morris2016AreaTimeParams, pair: PairContext) -> np.ndarray:
    e_real = effective_youngs_modulus_real(pair, "contact_radius.morris2016_area_time")
    linear = params.contact_law == "linear"
    if linear and params.normal_stiffness is None:
        raise ValueError(
            "contact_radius.morris2016_area_time with contact_law 'linear' needs normal_stiffness"
        )
    k_n = params.normal_stiffness or 0.0
    values = {"e_star_real": e_real, "e_star": pair.effective_youngs_modulus,
              "linear_law": 1.0 if linear else 0.0, "normal_stiffness": k_n}  # fmt: skip
    return packed(MORRIS_AREA_TIME_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def morris2016_area_time_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    r_eff = effective_radius(r_i, r_j)
    radius = hertz_radius_from_force(f_n, r_eff, p[MAT_E_STAR_REAL])
    if v_impact <= 0.0:
        return radius
    if p[MAT_LINEAR] == 1.0:
        t_sim = math.pi * math.sqrt(m_eff / p[MAT_STIFFNESS])
    else:
        t_sim = hertz_collision_time(m_eff, r_eff, p[MAT_E_STAR], v_impact)
    if t_contact >= t_sim:
        return radius
    t_real = hertz_collision_time(m_eff, r_eff, p[MAT_E_STAR_REAL], v_impact)
    return radius * (t_real / t_sim) ** (2.0 / 3.0)


# ---------------------------------------------------------------------------- dispatcher
@njit(cache=True, inline="always", error_model="numpy")
def contact_radius_dispatch(model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):
    """Contact radius of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    if model_id == GEOMETRIC:
        return geometric_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == HERTZ_FORCE:
        return hertz_force_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == HERTZ_OVERLAP:
        return hertz_overlap_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == ZHOU2010:
        return zhou2010_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == LU2017:
        return lu2017_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == MORRIS2016_AREA:
        return morris2016_area_radius(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)
    elif model_id == MORRIS2016_AREA_TIME:
        return morris2016_area_time_radius(
            p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff
        )
    elif model_id == NONE:
        return 0.0
    return np.nan


# --------------------------------------------------------------------------- registration
_COMMON = dict(family=FAMILY, antisymmetric=False, symmetric=True, swap_pairs=())
#: 2D (``planar``): the geometric radius is the half length of the chord of two overlapping
#: circles (the spec's formula is written for "circles / spheres"), so it holds for discs;
#: the Hertz-based radii are those of two spheres (point contact): spheres in a plane only.
_BOTH = ("disc", "sphere")
_SPHERE = ("sphere",)
_NO_COLUMNS = ()
_HERTZ = "Hertz (1882); Johnson (1985) Contact Mechanics, CUP"
_REAL = ("youngs_modulus", "poisson_ratio", "youngs_modulus_real")

register(
    name="none",
    columns=_NO_COLUMNS,
    model_id=NONE,
    kernel=none_radius,
    params=NoneParams,
    pack=pack_none,
    summary="no contact radius (0)",
    reference="-",
    planar=_BOTH,
    **_COMMON,
)
register(
    name="geometric",
    columns=_NO_COLUMNS,
    model_id=GEOMETRIC,
    kernel=geometric_radius,
    params=GeometricParams,
    pack=pack_geometric,
    summary="radius of the intersection circle of the overlapping spheres (chord of discs)",
    reference="Musser (2011) PhD thesis WVU; Weisstein, Sphere-Sphere Intersection (MathWorld)",
    planar=_BOTH,
    **_COMMON,
)
register(
    name="hertz_force",
    columns=HERTZ_FORCE_COLUMNS,
    model_id=HERTZ_FORCE,
    kernel=hertz_force_radius,
    params=HertzForceParams,
    pack=pack_hertz_force,
    summary="static Hertz radius from the normal force, (3 F R*/(4 E*))^(1/3)",
    reference=_HERTZ,
    requires=("youngs_modulus", "poisson_ratio"),
    planar=_SPHERE,
    **_COMMON,
)
register(
    name="hertz_overlap",
    columns=_NO_COLUMNS,
    model_id=HERTZ_OVERLAP,
    kernel=hertz_overlap_radius,
    params=HertzOverlapParams,
    pack=pack_hertz_overlap,
    summary="Hertz radius from the overlap, sqrt(R* δ)",
    reference=_HERTZ,
    planar=_SPHERE,
    **_COMMON,
)
register(
    name="zhou2010",
    columns=ZHOU2010_COLUMNS,
    model_id=ZHOU2010,
    kernel=zhou2010_radius,
    params=Zhou2010Params,
    pack=pack_zhou2010,
    summary="Hertz radius × (E*_sim/E*_real)^(1/5) low-stiffness correction",
    reference="Zhou, Yu & Zulli (2010) Powder Technol. 197, 102-110",
    requires=_REAL,
    planar=_SPHERE,
    **_COMMON,
)
register(
    name="lu2017",
    columns=LU2017_COLUMNS,
    model_id=LU2017,
    kernel=lu2017_radius,
    params=Lu2017Params,
    pack=pack_lu2017,
    summary="real Hertz radius carrying the linear spring force k_n δ (Lu et al. 2017, derived)",
    reference="Lu, Morris, Li & Benyahia (2017) Int. J. Heat Mass Transf. 111, 723-735",
    requires=_REAL,
    example_params={"normal_stiffness": 1.0e5},
    planar=_SPHERE,
    **_COMMON,
)
register(
    name="morris2016_area",
    columns=MORRIS_AREA_COLUMNS,
    model_id=MORRIS2016_AREA,
    kernel=morris2016_area_radius,
    params=Morris2016AreaParams,
    pack=pack_morris2016_area,
    summary="real Hertz radius at the simulated normal force (Morris 2016a area correction)",
    reference="Morris, Pannala, Ma & Hrenya (2016a) AIChE J. 62, 4526-4535",
    requires=_REAL,
    planar=_SPHERE,
    **_COMMON,
)
register(
    name="morris2016_area_time",
    columns=MORRIS_AREA_TIME_COLUMNS,
    model_id=MORRIS2016_AREA_TIME,
    kernel=morris2016_area_time_radius,
    params=Morris2016AreaTimeParams,
    pack=pack_morris2016_area_time,
    summary="Morris 2016a area × (t_c,real/t_c)^(2/3) collision-time correction (effective radius)",
    reference="Morris, Pannala, Ma & Hrenya (2016a) AIChE J. 62, 4526-4535",
    requires=_REAL,
    planar=_SPHERE,
    **_COMMON,
)
