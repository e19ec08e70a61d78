"""Integer-switch dispatchers of the mechanical families.

One dispatcher per family, switching on the model ids written in the model modules. The fused
pair loop calls these, so a single compiled loop serves every model combination and loads from
Numba's on-disk cache in a new process. ``tests/unit/test_registry_conformance.py`` checks that
each dispatcher agrees with every registered model's own kernel (a missing branch fails there).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from thermodem.models.mechanics import normal, rolling, tangential


@njit(cache=True, inline="always", error_model="numpy")
def normal_dispatch(model_id, p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap):
    if model_id == normal.HERTZ:
        return normal.hertz_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap)
    if model_id == normal.LINEAR:
        return normal.linear_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap)
    if model_id == normal.WALTON_BRAUN:
        return normal.walton_braun_force(
            p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap
        )
    if model_id == normal.HERTZ_2D:
        return normal.hertz_2d_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap)
    nan = np.nan  # unknown id: NaN forces stop the run at the next check
    return nan, nan, nan, nan, nan, nan, nan


@njit(cache=True, inline="always", error_model="numpy")
def tangential_dispatch(
    model_id,
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
    if model_id == tangential.MINDLIN:
        return tangential.mindlin(
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
        )
    if model_id == tangential.LINEAR:
        return tangential.linear_tangential(
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
        )
    return tangential.no_tangential(
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
    )


@njit(cache=True, inline="always", error_model="numpy")
def rolling_dispatch(
    model_id,
    p,
    ref_stiffness,
    eff_radius,
    rolling_inertia,
    normal_force,
    wx,
    wy,
    wz,
    mx,
    my,
    mz,
    dt,
):
    if model_id == rolling.CONSTANT_TORQUE:
        return rolling.constant_torque(
            p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt
        )
    if model_id == rolling.EPSD:
        return rolling.epsd(
            p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt
        )
    return rolling.no_rolling(
        p, ref_stiffness, eff_radius, rolling_inertia, normal_force, wx, wy, wz, mx, my, mz, dt
    )
