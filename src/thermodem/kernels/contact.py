"""The pair pass: contact geometry and forces, each pair computed once.

``prange`` runs over fixed-size chunks of the pair list; each pair writes its own output rows
(force on i, lever vector n x F_t, rolling torque on i, dissipated power per mechanism, state),
and each chunk writes its own ledger row. Nothing is accumulated across pairs with atomics, so
the results do not depend on the number of threads; the per-particle reduction is
:func:`thermodem.kernels.integrate.reduce_and_kick`.

Sign conventions: n is the unit vector from i to j; the relative velocity of i with respect to j
at the contact point is v_rel = (v_i + ω_i × R_i n) - (v_j - ω_j × R_j n); the overlap rate is
v_rel · n (> 0 approaching). The lever arms are the particle radii. A wall is j with infinite
radius and mass, its surface velocity at the contact point v_w + Ω a × (q - c).
"""

from __future__ import annotations

import math

from numba import njit, prange

from thermodem.geometry.wall_layout import (
    COL_AXIS,
    COL_OMEGA,
    COL_POINT,
    COL_TEMPERATURE,
    COL_THERMAL_KIND,
    COL_VELOCITY,
)
from thermodem.kernels.conduction import pair_conductance
from thermodem.kernels.neighbors import minimum_image, wall_distance
from thermodem.models.mechanics.dispatch import (
    normal_dispatch,
    rolling_dispatch,
    tangential_dispatch,
)

CHUNK = 2048

# History columns of a contact (particle-particle or particle-wall).
H_SPRING = 0  # 0:3 tangential spring displacement [m]
H_SPRING_ENERGY = 3  # elastic energy of the tangential spring at the end of the last step [J]
H_DURATION = 4  # time in contact [s]; 0 when not touching (first touching step counts dt)
H_IMPACT_VELOCITY = 5  # normal approach speed at first contact [m/s]
H_ROLL = 6  # 6:9 elastic rolling torque [N m] (only with a rolling spring model)
H_ROLL_ENERGY = 9  # elastic energy of the rolling spring [J]
HISTORY_WIDTH_BASE = 6
HISTORY_WIDTH_ROLLING = 10

# Ledger columns written per chunk.
L_ELASTIC_NORMAL = 0
L_ELASTIC_TANGENTIAL = 1
L_ELASTIC_ROLLING = 2
L_NORMAL_DAMPING = 3
L_TANGENTIAL_DAMPING = 4
L_SLIDING_FRICTION = 5
L_ROLLING_FRICTION = 6
L_STIFFNESS_WORK = 7
L_WALL_WORK = 8
L_MAX_OVERLAP_RATIO = 9
L_TOUCHING = 10
LEDGER_WIDTH = 11

# Per-pair dissipated power columns.
D_NORMAL_DAMPING = 0
D_TANGENTIAL_DAMPING = 1
D_SLIDING_FRICTION = 2
D_ROLLING_FRICTION = 3

STATE_FAR = 0
STATE_NEAR = 1
STATE_TOUCHING = 2
STATE_UNSET = 3  # listed by a rebuild, not yet evaluated (outputs not written)


@njit(cache=True, inline="always", error_model="numpy")
def _rotate_into_plane(h, k, c0, nx, ny, nz):
    """Project the 3-vector h[k, c0:c0+3] onto the plane normal to n, keeping its length."""
    ax = h[k, c0]
    ay = h[k, c0 + 1]
    az = h[k, c0 + 2]
    old2 = ax * ax + ay * ay + az * az
    if old2 == 0.0:
        return 0.0, 0.0, 0.0
    dot = ax * nx + ay * ny + az * nz
    ax -= dot * nx
    ay -= dot * ny
    az -= dot * nz
    new2 = ax * ax + ay * ay + az * az
    if new2 > 0.0:
        s = math.sqrt(old2 / new2)
        return ax * s, ay * s, az * s
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always", error_model="numpy")
def contact_response(
    k,
    history,
    nx,
    ny,
    nz,
    overlap,
    eff_radius,
    eff_mass,
    rolling_inertia,
    vrx,
    vry,
    vrz,
    wrx,
    wry,
    wrz,
    dt,
    normal_id,
    p_normal,
    tangential_id,
    p_tangential,
    rolling_id,
    p_rolling,
    out_force,
    out_lever,
    out_roll,
    out_diss,
    out_normal_force,
    ledger_row,
):
    """Forces of one touching contact (row k of the pair or wall-pair arrays).

    Writes the force on i (out_force[k]), n x F_t (out_lever[k]), the rolling torque on i
    (out_roll[k] when present), the dissipated power per mechanism (out_diss[k]), the normal
    force, updates the history row and adds energies to the ledger row.
    """
    rate = vrx * nx + vry * ny + vrz * nz
    f_el, f_damp, k_ref, gamma_n, u_n = normal_dispatch(
        normal_id, p_normal, overlap, rate, eff_radius, eff_mass
    )
    f_n = f_el + f_damp
    # tangential relative velocity
    vtx = vrx - rate * nx
    vty = vry - rate * ny
    vtz = vrz - rate * nz
    sx, sy, sz = _rotate_into_plane(history, k, H_SPRING, nx, ny, nz)
    ftx, fty, ftz, sx, sy, sz, k_t, p_tdamp, e_slip = tangential_dispatch(
        tangential_id,
        p_tangential,
        k_ref,
        gamma_n,
        eff_radius,
        overlap,
        f_n,
        vtx,
        vty,
        vtz,
        sx,
        sy,
        sz,
        dt,
    )
    u_t_rotated = (
        0.5
        * k_t
        * (
            history[k, H_SPRING] ** 2
            + history[k, H_SPRING + 1] ** 2
            + history[k, H_SPRING + 2] ** 2
        )
    )
    stiffness_work = u_t_rotated - history[k, H_SPRING_ENERGY]
    u_t = 0.5 * k_t * (sx * sx + sy * sy + sz * sz)
    history[k, H_SPRING] = sx
    history[k, H_SPRING + 1] = sy
    history[k, H_SPRING + 2] = sz
    history[k, H_SPRING_ENERGY] = u_t
    if history[k, H_DURATION] == 0.0:
        history[k, H_IMPACT_VELOCITY] = rate
    history[k, H_DURATION] += dt
    # rolling (relative angular velocity projected on the tangent plane)
    wn = wrx * nx + wry * ny + wrz * nz
    wrx -= wn * nx
    wry -= wn * ny
    wrz -= wn * nz
    has_roll_history = history.shape[1] >= HISTORY_WIDTH_ROLLING
    if has_roll_history:
        mx, my, mz = _rotate_into_plane(history, k, H_ROLL, nx, ny, nz)
    else:
        mx = 0.0
        my = 0.0
        mz = 0.0
    tx, ty, tz, mx, my, mz, k_r, e_roll = rolling_dispatch(
        rolling_id,
        p_rolling,
        k_ref,
        eff_radius,
        rolling_inertia,
        f_n,
        wrx,
        wry,
        wrz,
        mx,
        my,
        mz,
        dt,
    )
    u_r = 0.0
    if has_roll_history:
        if k_r > 0.0:
            old_m2 = history[k, H_ROLL] ** 2 + history[k, H_ROLL + 1] ** 2
            old_m2 += history[k, H_ROLL + 2] ** 2
            stiffness_work += 0.5 * old_m2 / k_r - history[k, H_ROLL_ENERGY]
            u_r = 0.5 * (mx * mx + my * my + mz * mz) / k_r
        history[k, H_ROLL] = mx
        history[k, H_ROLL + 1] = my
        history[k, H_ROLL + 2] = mz
        history[k, H_ROLL_ENERGY] = u_r
    # outputs: force on i = -F_n n + F_t
    out_force[k, 0] = -f_n * nx + ftx
    out_force[k, 1] = -f_n * ny + fty
    out_force[k, 2] = -f_n * nz + ftz
    out_lever[k, 0] = ny * ftz - nz * fty
    out_lever[k, 1] = nz * ftx - nx * ftz
    out_lever[k, 2] = nx * fty - ny * ftx
    if out_roll.shape[0] > k:
        out_roll[k, 0] = tx
        out_roll[k, 1] = ty
        out_roll[k, 2] = tz
    p_ndamp = f_damp * rate
    out_diss[k, D_NORMAL_DAMPING] = p_ndamp
    out_diss[k, D_TANGENTIAL_DAMPING] = p_tdamp
    inv_dt = 1.0 / dt if dt > 0.0 else 0.0
    out_diss[k, D_SLIDING_FRICTION] = e_slip * inv_dt
    out_diss[k, D_ROLLING_FRICTION] = e_roll * inv_dt
    out_normal_force[k] = f_n
    ledger_row[L_ELASTIC_NORMAL] += u_n
    ledger_row[L_ELASTIC_TANGENTIAL] += u_t
    ledger_row[L_ELASTIC_ROLLING] += u_r
    ledger_row[L_NORMAL_DAMPING] += p_ndamp * dt
    ledger_row[L_TANGENTIAL_DAMPING] += p_tdamp * dt
    ledger_row[L_SLIDING_FRICTION] += e_slip
    ledger_row[L_ROLLING_FRICTION] += e_roll
    ledger_row[L_STIFFNESS_WORK] += stiffness_work
    ledger_row[L_TOUCHING] += 1.0
    return f_n, ftx, fty, ftz, tx, ty, tz


@njit(cache=True, inline="always", error_model="numpy")
def _open_contact(
    k, history, out_force, out_lever, out_roll, out_diss, out_normal_force, out_state, ledger_row
):
    """Outputs of a pair that does not touch; a contact that just opened is cleared.

    The energy left in its springs when a contact opens is counted as friction (documented).
    A pair that did not touch at the previous pass already has zero outputs and history: no
    writes (a rebuild marks every pair STATE_UNSET, so the outputs of a new list are written).
    """
    if out_state[k] == STATE_NEAR or out_state[k] == STATE_FAR:
        return
    if history[k, H_DURATION] != 0.0:
        ledger_row[L_SLIDING_FRICTION] += history[k, H_SPRING_ENERGY]
        if history.shape[1] >= HISTORY_WIDTH_ROLLING:
            ledger_row[L_ROLLING_FRICTION] += history[k, H_ROLL_ENERGY]
        for c in range(history.shape[1]):
            history[k, c] = 0.0
    for c in range(3):
        out_force[k, c] = 0.0
        out_lever[k, c] = 0.0
    if out_roll.shape[0] > k:
        for c in range(3):
            out_roll[k, c] = 0.0
    for c in range(out_diss.shape[1]):
        out_diss[k, c] = 0.0
    out_normal_force[k] = 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _pp_conductance(
    k, i, j, ri, rj, dist, overlap, eff_mass, type_id, history, normal_force, radius_id,
    radius_table, conduction_id, conduction_table, override, k_particle, rhoc_particle, srow,
):  # fmt: skip
    ti = type_id[i]
    tj = type_id[j]
    ki = kj = ci = cj = 0.0
    if override > 0:
        ki = k_particle[i]
        kj = k_particle[j]
        if override > 1:
            ci = rhoc_particle[i]
            cj = rhoc_particle[j]
    return pair_conductance(
        ri, rj, dist, overlap, eff_mass, normal_force[k],
        history[k, H_DURATION], history[k, H_IMPACT_VELOCITY], radius_id, radius_table[ti, tj],
        conduction_id, conduction_table[ti, tj], override, ki, kj, ci, cj, srow,
    )  # fmt: skip


@njit(cache=True, inline="always", error_model="numpy")
def _pw_conductance(
    k, i, w, ri, d, overlap, mass, type_id, wall_material, history, normal_force, radius_id,
    radius_table, conduction_id, conduction_table, override, k_particle, rhoc_particle, k_wall,
    rhoc_wall, srow,
):  # fmt: skip
    ti = type_id[i]
    tw = wall_material[w]
    ki = kw = ci = cw = 0.0
    if override > 0:
        ki = k_particle[i]
        kw = k_wall[w]
        if override > 1:
            ci = rhoc_particle[i]
            cw = rhoc_wall[w]
    return pair_conductance(
        ri, math.inf, d, overlap, mass[i], normal_force[k], history[k, H_DURATION],
        history[k, H_IMPACT_VELOCITY], radius_id, radius_table[ti, tw], conduction_id,
        conduction_table[ti, tw], override, ki, kw, ci, cw, srow,
    )  # fmt: skip


@njit(cache=True, parallel=True, error_model="numpy")
def particle_pair_pass(
    position,
    velocity,
    angular_velocity,
    radius,
    mass,
    inertia,
    type_id,
    pair_i,
    pair_j,
    npairs,
    history,
    lower,
    upper,
    periodic,
    extra,
    dt,
    normal_id,
    normal_table,
    tangential_id,
    tangential_table,
    rolling_id,
    rolling_table,
    out_force,
    out_lever,
    out_roll,
    out_diss,
    out_normal_force,
    out_state,
    chunk_ledger,
    heat_on,
    temperature,
    radius_id,
    radius_table,
    conduction_id,
    conduction_table,
    override,
    k_particle,
    rhoc_particle,
    scratch,
    out_conductance,
    out_heat,
):
    """Contact forces of every listed particle pair (see module docstring).

    With ``heat_on`` the same pass evaluates the conduction of every touching and near pair
    (see :func:`thermodem.kernels.conduction.pair_conductance`) into ``out_conductance`` and
    ``out_heat`` (heat rate into i), with the temperatures of this moment.
    """
    length = upper - lower
    nchunks = (npairs + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        srow = scratch[c]
        row = chunk_ledger[c]
        for q in range(row.shape[0]):
            row[q] = 0.0
        for k in range(c * CHUNK, min(npairs, (c + 1) * CHUNK)):
            i = pair_i[k]
            j = pair_j[k]
            dx = minimum_image(position[j, 0] - position[i, 0], length[0], periodic[0])
            dy = minimum_image(position[j, 1] - position[i, 1], length[1], periodic[1])
            dz = minimum_image(position[j, 2] - position[i, 2], length[2], periodic[2])
            dist = math.sqrt(dx * dx + dy * dy + dz * dz)
            ri = radius[i]
            rj = radius[j]
            overlap = ri + rj - dist
            if overlap <= 0.0 or dist == 0.0:
                _open_contact(
                    k, history, out_force, out_lever, out_roll, out_diss, out_normal_force,
                    out_state, row,
                )  # fmt: skip
                out_state[k] = STATE_NEAR if -overlap < extra else STATE_FAR
                if heat_on:
                    h = 0.0
                    if out_state[k] == STATE_NEAR:
                        h = _pp_conductance(
                            k, i, j, ri, rj, dist, overlap,
                            mass[i] * mass[j] / (mass[i] + mass[j]), type_id, history,
                            out_normal_force, radius_id, radius_table, conduction_id,
                            conduction_table, override, k_particle, rhoc_particle, srow,
                        )  # fmt: skip
                    out_conductance[k] = h
                    out_heat[k] = h * (temperature[j] - temperature[i])
                continue
            out_state[k] = STATE_TOUCHING
            nx = dx / dist
            ny = dy / dist
            nz = dz / dist
            wix = angular_velocity[i, 0]
            wiy = angular_velocity[i, 1]
            wiz = angular_velocity[i, 2]
            wjx = angular_velocity[j, 0]
            wjy = angular_velocity[j, 1]
            wjz = angular_velocity[j, 2]
            # (ω_i R_i + ω_j R_j) × n
            sx = wix * ri + wjx * rj
            sy = wiy * ri + wjy * rj
            sz = wiz * ri + wjz * rj
            vrx = velocity[i, 0] - velocity[j, 0] + sy * nz - sz * ny
            vry = velocity[i, 1] - velocity[j, 1] + sz * nx - sx * nz
            vrz = velocity[i, 2] - velocity[j, 2] + sx * ny - sy * nx
            eff_radius = ri * rj / (ri + rj)
            eff_mass = mass[i] * mass[j] / (mass[i] + mass[j])
            rolling_inertia = 0.0  # used by the rolling models only
            if rolling_id != 0:
                ii = inertia[i] + mass[i] * ri * ri
                ij = inertia[j] + mass[j] * rj * rj
                rolling_inertia = ii * ij / (ii + ij)
            ti = type_id[i]
            tj = type_id[j]
            contact_response(
                k,
                history,
                nx,
                ny,
                nz,
                overlap,
                eff_radius,
                eff_mass,
                rolling_inertia,
                vrx,
                vry,
                vrz,
                wix - wjx,
                wiy - wjy,
                wiz - wjz,
                dt,
                normal_id,
                normal_table[ti, tj],
                tangential_id,
                tangential_table[ti, tj],
                rolling_id,
                rolling_table[ti, tj],
                out_force,
                out_lever,
                out_roll,
                out_diss,
                out_normal_force,
                row,
            )
            r_min = min(ri, rj)
            if overlap > row[L_MAX_OVERLAP_RATIO] * r_min:  # (no division per contact)
                row[L_MAX_OVERLAP_RATIO] = overlap / r_min
            if heat_on:
                h = _pp_conductance(
                    k, i, j, ri, rj, dist, overlap, eff_mass, type_id, history, out_normal_force,
                    radius_id, radius_table, conduction_id, conduction_table, override,
                    k_particle, rhoc_particle, srow,
                )  # fmt: skip
                out_conductance[k] = h
                out_heat[k] = h * (temperature[j] - temperature[i])


@njit(cache=True, parallel=True, error_model="numpy")
def wall_pair_pass(
    position,
    velocity,
    angular_velocity,
    radius,
    mass,
    inertia,
    type_id,
    wall_pair_i,
    wall_pair_w,
    nwpairs,
    history,
    wall_kind,
    wall_rows,
    wall_material,
    extra,
    dt,
    normal_id,
    normal_table,
    tangential_id,
    tangential_table,
    rolling_id,
    rolling_table,
    out_force,
    out_lever,
    out_roll,
    out_diss,
    out_normal_force,
    out_state,
    chunk_ledger,
    heat_on,
    temperature,
    radius_id,
    radius_table,
    conduction_id,
    conduction_table,
    override,
    k_particle,
    rhoc_particle,
    k_wall,
    rhoc_wall,
    scratch,
    out_conductance,
    out_heat,
):
    """Contact forces of every listed particle-wall pair (wall = j, infinite radius and mass).

    With ``heat_on`` also the conduction from fixed-temperature walls (adiabatic: zero).
    """
    nchunks = (nwpairs + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        srow = scratch[c]
        row = chunk_ledger[c]
        for q in range(row.shape[0]):
            row[q] = 0.0
        for k in range(c * CHUNK, min(nwpairs, (c + 1) * CHUNK)):
            i = wall_pair_i[k]
            w = wall_pair_w[k]
            wrow = wall_rows[w]
            d, wnx, wny, wnz, qx, qy, qz = wall_distance(wall_kind[w], wrow, position[i])
            ri = radius[i]
            overlap = ri - d
            if overlap <= 0.0:
                _open_contact(
                    k, history, out_force, out_lever, out_roll, out_diss, out_normal_force,
                    out_state, row,
                )  # fmt: skip
                out_state[k] = STATE_NEAR if -overlap < extra else STATE_FAR
                if heat_on:
                    h = 0.0
                    if out_state[k] == STATE_NEAR and wrow[COL_THERMAL_KIND] != 0.0:
                        h = _pw_conductance(
                            k, i, w, ri, d, overlap, mass, type_id, wall_material, history,
                            out_normal_force, radius_id, radius_table, conduction_id,
                            conduction_table, override, k_particle, rhoc_particle, k_wall,
                            rhoc_wall, srow,
                        )  # fmt: skip
                    out_conductance[k] = h
                    out_heat[k] = h * (wrow[COL_TEMPERATURE] - temperature[i])
                continue
            out_state[k] = STATE_TOUCHING
            # n from the particle towards the wall
            nx = -wnx
            ny = -wny
            nz = -wnz
            # wall surface velocity at q: v_w + Ω a × (q - c)
            om = wrow[COL_OMEGA]
            ax = wrow[COL_AXIS] * om
            ay = wrow[COL_AXIS + 1] * om
            az = wrow[COL_AXIS + 2] * om
            rx = qx - wrow[COL_POINT]
            ry = qy - wrow[COL_POINT + 1]
            rz = qz - wrow[COL_POINT + 2]
            vwx = wrow[COL_VELOCITY] + ay * rz - az * ry
            vwy = wrow[COL_VELOCITY + 1] + az * rx - ax * rz
            vwz = wrow[COL_VELOCITY + 2] + ax * ry - ay * rx
            wix = angular_velocity[i, 0]
            wiy = angular_velocity[i, 1]
            wiz = angular_velocity[i, 2]
            vrx = velocity[i, 0] - vwx + (wiy * nz - wiz * ny) * ri
            vry = velocity[i, 1] - vwy + (wiz * nx - wix * nz) * ri
            vrz = velocity[i, 2] - vwz + (wix * ny - wiy * nx) * ri
            ti = type_id[i]
            tw = wall_material[w]
            rolling_inertia = inertia[i] + mass[i] * ri * ri
            f_n, ftx, fty, ftz, tx, ty, tz = contact_response(
                k,
                history,
                nx,
                ny,
                nz,
                overlap,
                ri,
                mass[i],
                rolling_inertia,
                vrx,
                vry,
                vrz,
                wix - ax,
                wiy - ay,
                wiz - az,
                dt,
                normal_id,
                normal_table[ti, tw],
                tangential_id,
                tangential_table[ti, tw],
                rolling_id,
                rolling_table[ti, tw],
                out_force,
                out_lever,
                out_roll,
                out_diss,
                out_normal_force,
                row,
            )
            # work done by the wall on the particle this step
            fx = -f_n * nx + ftx
            fy = -f_n * ny + fty
            fz = -f_n * nz + ftz
            row[L_WALL_WORK] += (fx * vwx + fy * vwy + fz * vwz + tx * ax + ty * ay + tz * az) * dt
            ratio = overlap / ri
            if ratio > row[L_MAX_OVERLAP_RATIO]:
                row[L_MAX_OVERLAP_RATIO] = ratio
            if heat_on:
                h = 0.0
                if wrow[COL_THERMAL_KIND] != 0.0:
                    h = _pw_conductance(
                        k, i, w, ri, d, overlap, mass, type_id, wall_material, history,
                        out_normal_force, radius_id, radius_table, conduction_id,
                        conduction_table, override, k_particle, rhoc_particle, k_wall, rhoc_wall,
                        srow,
                    )  # fmt: skip
                out_conductance[k] = h
                out_heat[k] = h * (wrow[COL_TEMPERATURE] - temperature[i])
