"""The pair pass: contact geometry and forces, each pair computed once.

:func:`particle_pair_pass` and :func:`wall_pair_pass` compute, for every listed particle pair
and particle-wall pair, the geometry (distance, unit normal, overlap, relative velocity at the
contact point), the contact response of :mod:`thermodem.kernels.contact` and, when heat is due,
the conduction of the pair.

``prange`` runs over fixed-size chunks of the pair list; each pair writes its own output rows
(force on i, lever vector n x F_t, rolling torque on i, dissipated power per mechanism, state),
and each chunk writes its own ledger row. Nothing is accumulated across pairs with atomics, so
the results do not depend on the number of threads; the per-particle reduction is
:func:`thermodem.kernels.integrate.reduce_and_kick`.

Sign conventions: see :mod:`thermodem.kernels.contact`.
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
from thermodem.kernels.contact import (
    CHUNK,
    H_DURATION,
    H_IMPACT_VELOCITY,
    L_MAX_OVERLAP_RATIO,
    L_WALL_WORK,
    STATE_FAR,
    STATE_NEAR,
    STATE_TOUCHING,
    _open_contact,
    contact_response,
)
from thermodem.kernels.neighbors import minimum_image, wall_distance


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


_PASSES: dict[tuple[bool, int, int, int], tuple] = {}


def passes_for(heat_on: bool, radius_id: int, conduction_id: int, override: int) -> tuple:
    """(particle pair pass, wall pair pass) for one model combination.

    The heat switch, the contact radius and direct conduction model ids and the k(T)/ρc(T)
    override are compile-time constants of the particle pair pass, so the compiler drops the
    code of every other model: the generic loop with the model switches inside costs the
    simple conduction models ~20 ns per particle more (docs/architecture.md, "Cost of the
    generic model switch"). Its arguments keep their order and types; the model arguments
    passed in are ignored. Each combination in use compiles once (~7 s on a 2-core machine)
    and is then cached on disk (Numba keys closures on their constants) and in this process.
    The wall pass, a few percent of the time, is one generic kernel for all combinations.
    """
    key = (bool(heat_on), int(radius_id), int(conduction_id), int(override))
    if not key[0]:
        key = (False, 0, 0, 0)
    if key not in _PASSES:
        _PASSES[key] = (_compile_pair_pass(*key), wall_pair_pass)
    return _PASSES[key]


def _compile_pair_pass(HEAT_ON: bool, RADIUS_ID: int, CONDUCTION_ID: int, OVERRIDE: int):  # noqa: N803, ANN202
    """Define the particle pair pass with the model choice captured as constants."""

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
        # the model choice as compile-time constants (see passes_for)
        heat_on = HEAT_ON
        radius_id = RADIUS_ID
        conduction_id = CONDUCTION_ID
        override = OVERRIDE
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
                        if out_state[k] == STATE_NEAR:
                            h = _pp_conductance(
                                k, i, j, ri, rj, dist, overlap,
                                mass[i] * mass[j] / (mass[i] + mass[j]), type_id, history,
                                out_normal_force, radius_id, radius_table, conduction_id,
                                conduction_table, override, k_particle, rhoc_particle, srow,
                            )  # fmt: skip
                            out_conductance[k] = h
                            out_heat[k] = h * (temperature[j] - temperature[i])
                        else:  # beyond the interaction distance: no exchange
                            out_conductance[k] = 0.0
                            out_heat[k] = 0.0
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
                        k, i, j, ri, rj, dist, overlap, eff_mass, type_id, history,
                        out_normal_force, radius_id, radius_table, conduction_id,
                        conduction_table, override, k_particle, rhoc_particle, srow,
                    )  # fmt: skip
                    out_conductance[k] = h
                    out_heat[k] = h * (temperature[j] - temperature[i])

    return particle_pair_pass


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
                        conduction_table, override, k_particle, rhoc_particle, k_wall,
                        rhoc_wall, srow,
                    )  # fmt: skip
                out_conductance[k] = h
                out_heat[k] = h * (wrow[COL_TEMPERATURE] - temperature[i])
