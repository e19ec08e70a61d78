"""Thermal passes: conduction per pair, then per-particle sums and explicit Euler.

The pair pass computes, for each listed particle pair and particle–wall pair, the conductance
H (the direct-conduction model evaluated at T_i = 0, T_j = 1: every model of the spec is linear
in the temperature difference) and the heat rate into i, Q = H (T_j - T_i). It writes per-pair
arrays; the particle pass sums them in the same fixed per-particle order as the forces, so what
i gains j loses exactly and the result does not depend on the number of threads.
"""

from __future__ import annotations

import math

from numba import njit, prange

from thermodem.geometry.wall_layout import COL_TEMPERATURE, COL_THERMAL_KIND
from thermodem.kernels.contact import CHUNK, H_DURATION, H_IMPACT_VELOCITY, STATE_FAR
from thermodem.kernels.neighbors import minimum_image, wall_distance
from thermodem.models.thermal.contact_radius import contact_radius_dispatch
from thermodem.models.thermal.direct_conduction import direct_conduction_dispatch

# per-particle mechanism columns (see thermodem.state.particles.HEAT_MECHANISMS)
M_DIRECT = 0
M_SOURCE = 5
M_WALL = 6


@njit(cache=True, parallel=True, error_model="numpy")
def conduction_pair_pass(
    position, radius, mass, temperature, type_id, pair_i, pair_j, npairs, state, normal_force,
    history, lower, upper, periodic, radius_id, radius_table, conduction_id, conduction_table,
    out_conductance, out_heat,
):  # fmt: skip
    """Conductance and heat rate into i of every listed particle pair (near pairs included)."""
    length = upper - lower
    nchunks = (npairs + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        for k in range(c * CHUNK, min(npairs, (c + 1) * CHUNK)):
            if state[k] == STATE_FAR:
                out_conductance[k] = 0.0
                out_heat[k] = 0.0
                continue
            i = pair_i[k]
            j = pair_j[k]
            dx = minimum_image(position[j, 0] - position[i, 0], length[0], periodic[0])
            dy = minimum_image(position[j, 1] - position[i, 1], length[1], periodic[1])
            dz = minimum_image(position[j, 2] - position[i, 2], length[2], periodic[2])
            dist = math.sqrt(dx * dx + dy * dy + dz * dz)
            ri = radius[i]
            rj = radius[j]
            overlap = ri + rj - dist
            m_eff = mass[i] * mass[j] / (mass[i] + mass[j])
            ti = type_id[i]
            tj = type_id[j]
            duration = history[k, H_DURATION]
            v_imp = history[k, H_IMPACT_VELOCITY]
            r_c = 0.0
            if overlap > 0.0:
                r_c = contact_radius_dispatch(
                    radius_id,
                    radius_table[ti, tj],
                    ri,
                    rj,
                    dist,
                    overlap,
                    normal_force[k],
                    duration,
                    v_imp,
                    m_eff,
                )
            h = direct_conduction_dispatch(
                conduction_id,
                conduction_table[ti, tj],
                0.0,
                1.0,
                ri,
                rj,
                dist,
                overlap,
                r_c,
                normal_force[k],
                duration,
                v_imp,
                m_eff,
            )
            out_conductance[k] = h
            out_heat[k] = h * (temperature[j] - temperature[i])


@njit(cache=True, parallel=True, error_model="numpy")
def conduction_wall_pass(
    position, radius, mass, temperature, type_id, wall_pair_i, wall_pair_w, nwpairs, state,
    normal_force, history, wall_kind, wall_rows, wall_material, radius_id, radius_table,
    conduction_id, conduction_table, out_conductance, out_heat,
):  # fmt: skip
    """Heat from fixed-temperature walls into particles (adiabatic walls give zero)."""
    nchunks = (nwpairs + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        for k in range(c * CHUNK, min(nwpairs, (c + 1) * CHUNK)):
            w = wall_pair_w[k]
            wrow = wall_rows[w]
            if state[k] == STATE_FAR or wrow[COL_THERMAL_KIND] == 0.0:
                out_conductance[k] = 0.0
                out_heat[k] = 0.0
                continue
            i = wall_pair_i[k]
            d = wall_distance(wall_kind[w], wrow, position[i])[0]
            ri = radius[i]
            overlap = ri - d
            ti = type_id[i]
            tw = wall_material[w]
            duration = history[k, H_DURATION]
            v_imp = history[k, H_IMPACT_VELOCITY]
            r_c = 0.0
            if overlap > 0.0:
                r_c = contact_radius_dispatch(
                    radius_id,
                    radius_table[ti, tw],
                    ri,
                    math.inf,
                    d,
                    overlap,
                    normal_force[k],
                    duration,
                    v_imp,
                    mass[i],
                )
            h = direct_conduction_dispatch(
                conduction_id,
                conduction_table[ti, tw],
                0.0,
                1.0,
                ri,
                math.inf,
                d,
                overlap,
                r_c,
                normal_force[k],
                duration,
                v_imp,
                mass[i],
            )
            out_conductance[k] = h
            out_heat[k] = h * (wrow[COL_TEMPERATURE] - temperature[i])


@njit(cache=True, parallel=True, error_model="numpy")
def heat_gather(
    row_start, entries, pair_conductance, pair_heat, wall_row_start, wall_conductance, wall_heat,
    source, heat_rate, by_mechanism, conductance_sum,
):  # fmt: skip
    """Per-particle heat rate by mechanism and the sum of conductances, in a fixed order."""
    n = heat_rate.shape[0]
    for i in prange(n):
        q_direct = 0.0
        h_sum = 0.0
        for q in range(row_start[i], row_start[i + 1]):
            e = entries[q]
            if e >= 0:
                q_direct += pair_heat[e]
                h_sum += pair_conductance[e]
            else:
                k = -e - 1
                q_direct -= pair_heat[k]
                h_sum += pair_conductance[k]
        q_wall = 0.0
        for k in range(wall_row_start[i], wall_row_start[i + 1]):
            q_wall += wall_heat[k]
            h_sum += wall_conductance[k]
        for m in range(by_mechanism.shape[1]):
            by_mechanism[i, m] = 0.0
        by_mechanism[i, M_DIRECT] = q_direct
        by_mechanism[i, M_WALL] = q_wall
        by_mechanism[i, M_SOURCE] = source[i]
        heat_rate[i] = q_direct + q_wall + source[i]
        conductance_sum[i] = h_sum


@njit(cache=True, error_model="numpy")
def euler_update(temperature, heat_rate, mass, specific_heat, fixed, dt):
    """T += dt Q / (m c) except for fixed-temperature particles.

    Returns (heat absorbed by fixed particles [W] summed, smallest m c / ΣH limit is not
    computed here, index of the first non-finite or non-positive temperature or -1).
    """
    absorbed = 0.0
    bad = -1
    for i in range(temperature.shape[0]):
        if fixed[i]:
            absorbed += heat_rate[i]
            continue
        t = temperature[i] + dt * heat_rate[i] / (mass[i] * specific_heat[i])
        temperature[i] = t
        if bad < 0 and not (t > 0.0 and math.isfinite(t)):
            bad = i
    return absorbed, bad


@njit(cache=True, error_model="numpy")
def stability_limit(mass, specific_heat, conductance_sum, fixed):
    """min over free particles of m c / ΣH [s] and the particle index (inf, -1 if none)."""
    best = math.inf
    where = -1
    for i in range(mass.shape[0]):
        if fixed[i] or conductance_sum[i] <= 0.0:
            continue
        lim = mass[i] * specific_heat[i] / conductance_sum[i]
        if lim < best:
            best = lim
            where = i
    return best, where
