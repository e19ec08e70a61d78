"""Rolling resistance (family ``rolling``).

Kernel signature (all float64)::

    kernel(p, ref_stiffness, eff_radius, rolling_inertia, normal_force,
           wx, wy, wz, mx, my, mz, dt)
        -> (tx, ty, tz, mx, my, mz, stiffness, dissipated_energy)

``w`` is the relative angular velocity ω_i - ω_j projected on the tangent plane (rolling, not
twisting); ``m`` the elastic rolling torque carried as history (rotated into the current plane
by the caller). Returned: the rolling torque on i (j receives the opposite), the updated history,
the rolling spring stiffness k_r (stored energy |m|²/(2 k_r); 0 when there is no spring) and the
energy dissipated this step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.mechanics.tangential import _TINY_SQUARE
from thermodem.models.registry import packed, register
from thermodem.state.materials import PairContext

NONE = 0
CONSTANT_TORQUE = 1
EPSD = 2

#: Parameter row columns (named; ``register(columns=...)`` sets the row width).
CONSTANT_COLUMNS = ("rolling_friction", "angular_velocity_threshold")
CONSTANT_MU_R, CONSTANT_THRESHOLD = 0, 1
EPSD_COLUMNS = ("rolling_friction", "damping_ratio", "plastic_damping_factor")
EPSD_MU_R, EPSD_DAMPING_RATIO, EPSD_PLASTIC_DAMPING = 0, 1, 2


class NoneParams(StrictModel):
    """No rolling resistance."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def no_rolling(
    p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt
):
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


class ConstantTorqueParams(StrictModel):
    """Constant directional torque, M = -μ_r R* F_n ω_rel/|ω_rel| (model A of Ai et al. 2011).

    Ai, J., Chen, J.-F., Rotter, J.M., Ooi, J.Y. (2011) Assessment of rolling resistance models
    in discrete element simulations, Powder Technol. 206, 269-282; after Zhou et al. (1999)
    Physica A 269, 536-553. μ_r is the pair's rolling friction coefficient. Below
    ``angular_velocity_threshold`` the torque is zero, which avoids the sign chatter of the
    model at rest (a known limitation of model A, documented there).
    """

    angular_velocity_threshold: float = Field(default=1e-9, ge=0, description="[rad/s]")


def pack_constant(params: ConstantTorqueParams, pair: PairContext) -> np.ndarray:
    return packed(
        CONSTANT_COLUMNS,
        {
            "rolling_friction": pair.rolling_friction,
            "angular_velocity_threshold": params.angular_velocity_threshold,
        },
    )


@njit(cache=True, error_model="numpy")
def constant_torque(
    p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt
):
    w = math.sqrt(wx * wx + wy * wy + wz * wz)
    if w <= p[CONSTANT_THRESHOLD] or normal_force <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    mag = p[CONSTANT_MU_R] * eff_radius * normal_force
    return -mag * wx / w, -mag * wy / w, -mag * wz / w, 0.0, 0.0, 0.0, 0.0, mag * w * dt


class EPSDParams(StrictModel):
    """Elastic–plastic spring–dashpot rolling resistance (model C of Ai et al. 2011).

    k_r = 2.25 k_n μ_r² R*², limit |M| ≤ μ_r R* F_n, viscous torque -η_r 2 sqrt(I_r k_r) ω
    while below the limit (and f η_r of it at the limit, f = ``plastic_damping_factor``).
    I_r is the pair's rolling inertia [(I_i + m_i R_i²)^-1 + (I_j + m_j R_j²)^-1]^-1.
    Ai, Chen, Rotter & Ooi (2011) Powder Technol. 206, 269-282; Iwashita & Oda (1998)
    J. Eng. Mech. 124, 285-292.
    """

    damping_ratio: float = Field(default=0.3, ge=0, description="η_r [-]")
    plastic_damping_factor: float = Field(default=0.0, ge=0, le=1, description="f [-]")


def pack_epsd(params: EPSDParams, pair: PairContext) -> np.ndarray:
    return packed(
        EPSD_COLUMNS,
        {
            "rolling_friction": pair.rolling_friction,
            "damping_ratio": params.damping_ratio,
            "plastic_damping_factor": params.plastic_damping_factor,
        },
    )


@njit(cache=True, error_model="numpy")
def epsd(p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt):
    """One step of model C; the dissipated energy is C |ω|² Δt plus, at the limit, the work of
    the spring torque (averaged over the step as velocity Verlet sees it) along the plastic
    rotation: ½ (M0 + M) · (M1 - M) / k_r with M0, M1, M the stored, trial and capped torques
    (docs/architecture.md, "Work of the tangential force"; the rolling spring is the same
    algebra with M = -k_r θ)."""
    mu_r = p[EPSD_MU_R]
    k_r = 2.25 * ref_stiffness * mu_r * mu_r * eff_radius * eff_radius
    c_r = p[EPSD_DAMPING_RATIO] * 2.0 * math.sqrt(rolling_inertia * k_r)
    m_lim = mu_r * eff_radius * max(normal_force, 0.0)
    w2 = wx * wx + wy * wy + wz * wz
    # elastic part: incremental rotation of the spring
    tx = mx - k_r * wx * dt
    ty = my - k_r * wy * dt
    tz = mz - k_r * wz * dt
    m_mag2 = tx * tx + ty * ty + tz * tz
    lim2 = m_lim * m_lim
    # squares below ~1e-280 lose precision (subnormal): those torques are compared by roots
    if m_mag2 <= lim2 and lim2 > _TINY_SQUARE:
        return tx - c_r * wx, ty - c_r * wy, tz - c_r * wz, tx, ty, tz, k_r, c_r * w2 * dt
    m_mag = math.sqrt(m_mag2) if m_mag2 > _TINY_SQUARE else math.hypot(tx, math.hypot(ty, tz))
    if m_mag <= m_lim:
        return tx - c_r * wx, ty - c_r * wy, tz - c_r * wz, tx, ty, tz, k_r, c_r * w2 * dt
    scale = m_lim / m_mag if m_mag > 0.0 else 0.0
    nx = scale * tx
    ny = scale * ty
    nz = scale * tz
    damp = p[EPSD_PLASTIC_DAMPING] * c_r
    dissipated = damp * w2 * dt
    if k_r > 0.0:
        dissipated += (
            0.5 * ((mx + nx) * (tx - nx) + (my + ny) * (ty - ny) + (mz + nz) * (tz - nz)) / k_r
        )
    return nx - damp * wx, ny - damp * wy, nz - damp * wz, nx, ny, nz, k_r, dissipated


register(
    family="rolling",
    name="none",
    model_id=NONE,
    kernel=no_rolling,
    params=NoneParams,
    pack=pack_none,
    columns=(),
    summary="no rolling resistance",
    reference="-",
)
register(
    family="rolling",
    name="constant_torque",
    model_id=CONSTANT_TORQUE,
    kernel=constant_torque,
    params=ConstantTorqueParams,
    pack=pack_constant,
    columns=CONSTANT_COLUMNS,
    summary="constant directional torque μ_r R* F_n opposing relative rolling",
    reference="Ai et al. (2011) Powder Technol. 206, 269-282 (model A); Zhou et al. (1999)",
    requires=("rolling_friction",),
)
register(
    family="rolling",
    name="epsd",
    model_id=EPSD,
    kernel=epsd,
    params=EPSDParams,
    pack=pack_epsd,
    columns=EPSD_COLUMNS,
    summary="elastic-plastic spring-dashpot rolling torque (model C)",
    reference="Ai et al. (2011) Powder Technol. 206, 269-282 (model C); Iwashita & Oda (1998)",
    requires=("rolling_friction",),
    history_width=3,
    history_flip=(True, True, True),
)
