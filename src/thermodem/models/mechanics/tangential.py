"""Tangential contact laws (family ``tangential``): spring with history and a Coulomb cap.

Kernel signature (all float64)::

    kernel(p, ref_stiffness, normal_damping, eff_radius, overlap, normal_force,
           vtx, vty, vtz, sx, sy, sz, dt)
        -> (ftx, fty, ftz, sx, sy, sz, stiffness, damping_energy, friction_energy)

``v_t`` is the tangential velocity of i relative to j at the contact point; ``s`` the
accumulated tangential spring displacement (history), already rotated into the current tangent
plane by the caller. Returned: the tangential force on i, the updated displacement, the spring
stiffness k_t (the stored elastic energy is ½ k_t |s|²), and the energies dissipated this step
by the tangential dashpot and by sliding [J]. When the trial force exceeds the Coulomb limit
μ max(F_n, 0), force and dashpot are scaled by λ = limit/|trial| and the displacement by λ,
so that spring plus scaled dashpot force equals the limit (the history is "rescaled when the
cap is reached"); the relative displacement v_t Δt of the step is then split into an elastic
part (the change of s) and a slip (the rest). The dashpot dissipates the work of its force
along the elastic part, sliding the work of the capped force along the slip, with the spring
force averaged over the step as velocity Verlet sees it; with the change of ½ k_t |s|² the
two add up to the work of the tangential force on the relative motion (docs/architecture.md,
"Work of the tangential force").

The tangential dashpot uses the damping ratio of the normal law: γ_t = γ_n sqrt(k_t / k_n),
where k_n is the normal law's reference stiffness (Tsuji et al. 1992 use the same α for both
directions, which is this rule for Hertz–Mindlin).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.state.materials import PairContext

NONE = 0
MINDLIN = 1
LINEAR = 2

#: Parameter row columns (named; ``register(columns=...)`` sets the row width).
MINDLIN_COLUMNS = ("effective_shear_modulus", "sliding_friction")
MINDLIN_G_STAR, MINDLIN_FRICTION = 0, 1
LINEAR_COLUMNS = ("stiffness_ratio", "sliding_friction")
LINEAR_STIFFNESS_RATIO, LINEAR_FRICTION = 0, 1


#: Squares below this lose precision (subnormal near 1e-308): compared by their roots.
_TINY_SQUARE = 1e-280


@njit(cache=True, error_model="numpy")
def _spring_dashpot_capped(k_t, gamma_t, mu, normal_force, vtx, vty, vtz, sx, sy, sz, dt):
    """Shared algorithm: incremental spring + dashpot, Coulomb cap with history rescale.

    Energies of the step (docs/architecture.md, "Work of the tangential force"): with s0 the
    stored displacement, s1 = s0 + v Δt the trial one, s the new one and λ the cap scale,
    the elastic increment is s - s0 and the slip s1 - s; the dashpot dissipates
    λ γ v · (s - s0) (clipped to [0, total]) and sliding the work of the capped force along
    the slip, (λ γ v + ½ k (s0 + s)) · (s1 - s). Below the cap: γ |v|² Δt and 0.
    """
    v2 = vtx * vtx + vty * vty + vtz * vtz
    tx = sx + vtx * dt
    ty = sy + vty * dt
    tz = sz + vtz * dt
    fx = -k_t * tx - gamma_t * vtx
    fy = -k_t * ty - gamma_t * vty
    fz = -k_t * tz - gamma_t * vtz
    f_mag2 = fx * fx + fy * fy + fz * fz
    f_cap = mu * max(normal_force, 0.0)
    cap2 = f_cap * f_cap
    # squares: the root is only needed when the cap applies (not for forces so small that
    # their squares lose precision or vanish, below ~1e-140 N: those are compared exactly)
    if f_mag2 <= cap2 and cap2 > _TINY_SQUARE:
        return fx, fy, fz, tx, ty, tz, k_t, gamma_t * v2 * dt, 0.0
    f_mag = math.sqrt(f_mag2) if f_mag2 > _TINY_SQUARE else math.hypot(fx, math.hypot(fy, fz))
    if f_mag <= f_cap:
        return fx, fy, fz, tx, ty, tz, k_t, gamma_t * v2 * dt, 0.0
    lam = f_cap / f_mag if f_mag > 0.0 else 0.0
    fx *= lam
    fy *= lam
    fz *= lam
    # new spring: spring + scaled dashpot = the limit, i.e. s = λ s1 (nothing held if k_t = 0)
    scale = lam if k_t > 0.0 else 0.0
    nx = scale * tx
    ny = scale * ty
    nz = scale * tz
    g = lam * gamma_t  # the dashpot coefficient at the limit
    damping = g * (vtx * (nx - sx) + vty * (ny - sy) + vtz * (nz - sz))
    half_k = 0.5 * k_t
    friction = (
        (g * vtx + half_k * (sx + nx)) * (tx - nx)
        + (g * vty + half_k * (sy + ny)) * (ty - ny)
        + (g * vtz + half_k * (sz + nz)) * (tz - nz)
    )
    # a dashpot gives no energy back: when the spring unloads while sliding, the energy it
    # releases goes to the slider (the sum is kept, so the ledger still closes)
    total = damping + friction
    damping = min(max(damping, 0.0), max(total, 0.0))
    return fx, fy, fz, nx, ny, nz, k_t, damping, total - damping


# ------------------------------------------------------------------------------------ none
class NoneParams(StrictModel):
    """No tangential force (frictionless spheres)."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def no_tangential(
    p,
    ref_stiffness,
    normal_damping,
    eff_radius,
    overlap,
    normal_force,
    vtx,
    vty,
    vtz,
    sx,
    sy,
    sz,
    dt,
):
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


# --------------------------------------------------------------------------------- Mindlin
class MindlinParams(StrictModel):
    """Mindlin (1949) no-slip tangential stiffness k_t = 8 G* sqrt(R* δ) with a Coulomb cap.

    Mindlin, R.D. (1949) Compliance of elastic bodies in contact, J. Appl. Mech. 16, 259-268;
    the simplified no-slip form as in Di Renzo & Di Maio (2004) Chem. Eng. Sci. 59, 525-541.
    G* = [(2-ν_i)/G_i + (2-ν_j)/G_j]^-1. Friction μ is the pair's sliding friction.
    """


def pack_mindlin(params: MindlinParams, pair: PairContext) -> np.ndarray:
    return packed(
        MINDLIN_COLUMNS,
        {
            "effective_shear_modulus": pair.effective_shear_modulus,
            "sliding_friction": pair.sliding_friction,
        },
    )


@njit(cache=True, error_model="numpy")
def mindlin(
    p,
    ref_stiffness,
    normal_damping,
    eff_radius,
    overlap,
    normal_force,
    vtx,
    vty,
    vtz,
    sx,
    sy,
    sz,
    dt,
):
    k_t = 8.0 * p[MINDLIN_G_STAR] * math.sqrt(eff_radius * overlap)
    gamma_t = normal_damping * math.sqrt(k_t / ref_stiffness) if ref_stiffness > 0.0 else 0.0
    mu = p[MINDLIN_FRICTION]
    return _spring_dashpot_capped(k_t, gamma_t, mu, normal_force, vtx, vty, vtz, sx, sy, sz, dt)


# ---------------------------------------------------------------------------------- linear
class LinearTangentialParams(StrictModel):
    """Linear tangential spring k_t = r k_n with a Coulomb cap (Cundall & Strack 1979).

    k_n is the normal law's reference stiffness (the spring constant of the linear law, the
    secant stiffness of Hertz). The default r = 2/7 makes the tangential and normal oscillation
    periods of a sphere equal (Schäfer, Dippel & Wolf 1996, J. Phys. I France 6, 5-20).
    """

    stiffness_ratio: float = Field(default=2.0 / 7.0, gt=0, description="k_t / k_n [-]")


def pack_linear(params: LinearTangentialParams, pair: PairContext) -> np.ndarray:
    return packed(
        LINEAR_COLUMNS,
        {"stiffness_ratio": params.stiffness_ratio, "sliding_friction": pair.sliding_friction},
    )


@njit(cache=True, error_model="numpy")
def linear_tangential(
    p,
    ref_stiffness,
    normal_damping,
    eff_radius,
    overlap,
    normal_force,
    vtx,
    vty,
    vtz,
    sx,
    sy,
    sz,
    dt,
):
    ratio = p[LINEAR_STIFFNESS_RATIO]
    k_t = ratio * ref_stiffness
    gamma_t = normal_damping * math.sqrt(ratio)
    mu = p[LINEAR_FRICTION]
    return _spring_dashpot_capped(k_t, gamma_t, mu, normal_force, vtx, vty, vtz, sx, sy, sz, dt)


_COMMON = dict(history_width=3, history_flip=(True, True, True))
register(
    family="tangential",
    name="none",
    model_id=NONE,
    kernel=no_tangential,
    params=NoneParams,
    pack=pack_none,
    columns=(),
    summary="no tangential force",
    reference="-",
    history_width=0,
    history_flip=(),
)
register(
    family="tangential",
    name="mindlin",
    model_id=MINDLIN,
    kernel=mindlin,
    params=MindlinParams,
    pack=pack_mindlin,
    columns=MINDLIN_COLUMNS,
    summary="Mindlin no-slip stiffness 8G*sqrt(R*δ), Coulomb cap, history rescaled",
    reference="Mindlin (1949) J. Appl. Mech. 16, 259-268; Di Renzo & Di Maio (2004)",
    requires=("youngs_modulus", "poisson_ratio", "sliding_friction"),
    **_COMMON,
)
register(
    family="tangential",
    name="linear",
    model_id=LINEAR,
    kernel=linear_tangential,
    params=LinearTangentialParams,
    pack=pack_linear,
    columns=LINEAR_COLUMNS,
    summary="linear tangential spring k_t = r k_n, Coulomb cap, history rescaled",
    reference="Cundall & Strack (1979) Geotechnique 29, 47-65",
    requires=("sliding_friction",),
    **_COMMON,
)
