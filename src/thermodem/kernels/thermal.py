"""Thermal passes: conduction per pair, then per-particle sums and explicit Euler.

The pair pass computes, for each listed particle pair and particle–wall pair, the conductance
H (the direct-conduction model evaluated at T_i = 0, T_j = 1: every model of the spec is linear
in the temperature difference) and the heat rate into i, Q = H (T_j - T_i). It writes per-pair
arrays; :func:`heat_scatter` adds them to both particles by slab group, so what i gains j loses
exactly and the result does not depend on the number of threads.
"""

from __future__ import annotations

import math
from typing import Any

from numba import njit, prange

from thermodem.geometry.wall_layout import COL_TEMPERATURE, COL_THERMAL_KIND
from thermodem.kernels.contact import CHUNK, STATE_FAR
from thermodem.kernels.neighbors import pair_separation, wall_distance
from thermodem.kernels.pair_pass import _pp_conductance, _pw_conductance, reusable

# per-particle mechanism columns (see thermodem.state.particles.HEAT_MECHANISMS)
M_DIRECT = 0
M_SOURCE = 5
M_WALL = 6


_CONDUCTION_PASSES: dict[tuple[int, int, int], Any] = {}


def conduction_pair_pass_for(radius_id: int, conduction_id: int, override: int) -> Any:
    """The heat-only particle pair pass compiled for one model combination (frozen mechanics,
    sub-cycled and initial heat evaluations), with the model ids and the k(T)/ρc(T) override as
    compile-time constants, as :func:`thermodem.kernels.pair_pass.passes_for` does for the
    contact pass: the other models' code is dropped (~2× faster for the simple models). The
    model arguments passed to the kernel are ignored."""
    key = (int(radius_id), int(conduction_id), int(override))
    if key not in _CONDUCTION_PASSES:
        _CONDUCTION_PASSES[key] = _compile_conduction_pair_pass(*key)
    return _CONDUCTION_PASSES[key]


def _compile_conduction_pair_pass(RADIUS_ID: int, CONDUCTION_ID: int, OVERRIDE: int):  # noqa: N803, ANN202
    REUSABLE = reusable(CONDUCTION_ID)  # noqa: N806

    @njit(cache=True, parallel=True, error_model="numpy")
    def conduction_pair_pass(
        position, radius, mass, temperature, type_id, pair_i, pair_j, npairs, state, normal_force,
        history, lower, upper, periodic, radius_id, radius_table, conduction_id, conduction_table,
        override, k_particle, rhoc_particle, scratch, out_conductance, out_heat, tolerance,
    ):  # fmt: skip
        """Conductance and heat rate into i of every listed particle pair (near pairs included).

        With ``override`` > 0 the conductivity columns (0, 1) of the model's row are replaced by
        the particles' current k(T), and with ``override`` > 1 also the heat capacity columns
        (2, 3) by ρ c(T) (temperature-dependent properties).
        """
        # the model choice as compile-time constants (see conduction_pair_pass_for)
        radius_id = RADIUS_ID
        conduction_id = CONDUCTION_ID
        override = OVERRIDE
        if not REUSABLE:
            tolerance = 0.0  # (the reuse's code is dropped)
        length = upper - lower
        nchunks = (npairs + CHUNK - 1) // CHUNK
        for c in prange(nchunks):
            row = scratch[c]
            for k in range(c * CHUNK, min(npairs, (c + 1) * CHUNK)):
                if state[k] == STATE_FAR:
                    out_conductance[k] = 0.0
                    out_heat[k] = 0.0
                    continue
                i = pair_i[k]
                j = pair_j[k]
                dist = pair_separation(position, i, j, length, periodic)[3]
                ri = radius[i]
                rj = radius[j]
                overlap = ri + rj - dist
                h = _pp_conductance(
                    k, i, j, ri, rj, dist, overlap, mass[i] * mass[j] / (mass[i] + mass[j]),
                    type_id, history, normal_force, radius_id,
                    radius_table, conduction_id, conduction_table, override, k_particle,
                    rhoc_particle, row, tolerance,
                )  # fmt: skip
                out_conductance[k] = h
                out_heat[k] = h * (temperature[j] - temperature[i])

    return conduction_pair_pass


@njit(cache=True, parallel=True, error_model="numpy")
def conduction_wall_pass(
    position, radius, mass, temperature, type_id, wall_pair_i, wall_pair_w, nwpairs, state,
    normal_force, history, wall_kind, wall_rows, wall_material, radius_id, radius_table,
    conduction_id, conduction_table, override, k_particle, rhoc_particle, k_wall, rhoc_wall,
    scratch, out_conductance, out_heat, tolerance,
):  # fmt: skip
    """Heat from fixed-temperature walls into particles (adiabatic walls give zero).

    ``override`` as in :func:`conduction_pair_pass`; the wall's values are ``k_wall[w]`` and
    ``rhoc_wall[w]`` (its material at the wall temperature).
    """
    nchunks = (nwpairs + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        row = scratch[c]
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
            h = _pw_conductance(
                k, i, w, ri, d, overlap, mass, type_id, wall_material, history, normal_force,
                radius_id, radius_table, conduction_id, conduction_table, override, k_particle,
                rhoc_particle, k_wall, rhoc_wall, row, tolerance,
            )  # fmt: skip
            out_conductance[k] = h
            out_heat[k] = h * (wrow[COL_TEMPERATURE] - temperature[i])


@njit(cache=True, parallel=True, error_model="numpy")
def heat_from_conductance(
    pair_i, pair_j, npairs, wall_pair_i, wall_pair_w, nwpairs, wall_rows, temperature,
    pair_conductance, wall_conductance, out_pair_heat, out_wall_heat,
):  # fmt: skip
    """Pair and wall heat rates from conductances already computed for these same contacts:
    Q = H (T_j - T_i), the expression of the conduction passes, so the result is the same to
    the bit. Used with frozen mechanics and temperature-independent properties, where nothing
    that H depends on changes between thermal steps."""
    for c in prange((npairs + CHUNK - 1) // CHUNK):
        for k in range(c * CHUNK, min(npairs, (c + 1) * CHUNK)):
            h = pair_conductance[k]
            out_pair_heat[k] = h * (temperature[pair_j[k]] - temperature[pair_i[k]]) if h else 0.0
    for k in range(nwpairs):
        h = wall_conductance[k]
        t_wall = wall_rows[wall_pair_w[k], COL_TEMPERATURE]
        out_wall_heat[k] = h * (t_wall - temperature[wall_pair_i[k]]) if h else 0.0


@njit(cache=True, parallel=True, error_model="numpy")
def heat_scatter(
    pair_i, pair_j, group_start, pair_conductance, pair_heat, wall_row_start, wall_conductance,
    wall_heat, source, heat_rate, by_mechanism, conductance_sum,
):  # fmt: skip
    """Per-particle heat rate by mechanism and the sum of conductances from the per-pair arrays.

    The pair heat is added to both particles by slab group, even groups then odd groups
    (:mod:`thermodem.kernels.slabs`), in the order of the fused contact pass: what i gains j
    loses exactly, and the sums do not depend on the number of threads.
    """
    n = heat_rate.shape[0]
    for i in prange(n):
        for m in range(by_mechanism.shape[1]):
            by_mechanism[i, m] = 0.0
        conductance_sum[i] = 0.0
    ngroups = group_start.shape[0] - 1
    for parity in range(2):
        for half in prange((ngroups + 1 - parity) // 2):
            g = 2 * half + parity
            for k in range(group_start[g], group_start[g + 1]):
                h = pair_conductance[k]
                if h == 0.0:
                    continue
                i = pair_i[k]
                j = pair_j[k]
                q = pair_heat[k]
                by_mechanism[i, M_DIRECT] += q
                by_mechanism[j, M_DIRECT] -= q
                conductance_sum[i] += h
                conductance_sum[j] += h
    for i in prange(n):
        q_wall = 0.0
        h_sum = conductance_sum[i]
        for k in range(wall_row_start[i], wall_row_start[i + 1]):
            q_wall += wall_heat[k]
            h_sum += wall_conductance[k]
        by_mechanism[i, M_WALL] = q_wall
        by_mechanism[i, M_SOURCE] = source[i]
        heat_rate[i] = by_mechanism[i, M_DIRECT] + q_wall + source[i]
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


@njit(cache=True, error_model="numpy")
def enthalpy(t, tt, cc, n):
    """h(T) = ∫_0^T c dT' [J/kg] for c piecewise linear on the nodes tt[:n] (values cc[:n]),
    constant outside them; a single node is a constant c (h = c T)."""
    if t <= tt[0]:
        return cc[0] * t
    h = cc[0] * tt[0]
    for s in range(n - 1):
        a = tt[s]
        b = tt[s + 1]
        if t <= b:
            x = t - a
            return h + cc[s] * x + 0.5 * (cc[s + 1] - cc[s]) / (b - a) * x * x
        h += 0.5 * (cc[s] + cc[s + 1]) * (b - a)
    return h + cc[n - 1] * (t - tt[n - 1])


@njit(cache=True, error_model="numpy")
def temperature_of_enthalpy(hv, tt, cc, n):
    """Inverse of :func:`enthalpy` (c > 0, so h is increasing)."""
    h = cc[0] * tt[0]
    if hv <= h:
        return hv / cc[0]
    for s in range(n - 1):
        a = tt[s]
        b = tt[s + 1]
        seg = 0.5 * (cc[s] + cc[s + 1]) * (b - a)
        if hv <= h + seg:
            r = hv - h
            slope = (cc[s + 1] - cc[s]) / (b - a)
            # 0.5 slope x² + c_s x = r, in the cancellation-free form
            return a + 2.0 * r / (cc[s] + math.sqrt(cc[s] * cc[s] + 2.0 * slope * r))
        h += seg
    return tt[n - 1] + (hv - h) / cc[n - 1]


@njit(cache=True, error_model="numpy")
def euler_update_enthalpy(
    temperature, heat_rate, mass, type_id, table_t, table_c, table_n, fixed, dt
):
    """Explicit Euler on the specific enthalpy, h += dt Q / m, then T = h⁻¹(h).

    Used with temperature-dependent specific heat: Σ m h(T) then changes by exactly Σ Q dt.
    Returns (heat absorbed by fixed particles [W], first bad particle index or -1).
    """
    absorbed = 0.0
    bad = -1
    for i in range(temperature.shape[0]):
        if fixed[i]:
            absorbed += heat_rate[i]
            continue
        m = type_id[i]
        n = table_n[m]
        h = enthalpy(temperature[i], table_t[m], table_c[m], n) + dt * heat_rate[i] / mass[i]
        t = temperature_of_enthalpy(h, table_t[m], table_c[m], n)
        temperature[i] = t
        if bad < 0 and not (t > 0.0 and math.isfinite(t)):
            bad = i
    return absorbed, bad


@njit(cache=True, error_model="numpy")
def total_enthalpy(temperature, mass, type_id, table_t, table_c, table_n):
    """Σ m h(T) [J]."""
    total = 0.0
    for i in range(temperature.shape[0]):
        m = type_id[i]
        total += mass[i] * enthalpy(temperature[i], table_t[m], table_c[m], table_n[m])
    return total


@njit(cache=True, parallel=True, error_model="numpy")
def finish_heat(source, heat_rate, by_mechanism):
    """Source column and total heat rate after the fused contact pass filled columns 0 and 6
    (:func:`heat_scatter` fills them itself)."""
    for i in prange(heat_rate.shape[0]):
        by_mechanism[i, M_SOURCE] = source[i]
        heat_rate[i] = by_mechanism[i, M_DIRECT] + by_mechanism[i, M_WALL] + source[i]


EULER_CHUNK = 4096


@njit(cache=True, parallel=True, error_model="numpy")
def euler_step(temperature, heat_rate, by_mechanism, source, mass, type_id, c_by_type,
               conductance_sum, fixed, dt, part):  # fmt: skip
    """One fused per-particle thermal update with constant specific heats.

    Fills the source column and the total heat rate, finds the explicit Euler limit
    min m c / ΣH over free particles, applies T += dt Q / (m c) to free particles, and sums the
    wall heat, source heat and heat absorbed by fixed particles [W].
    Returns (limit, limit index, wall heat, source heat, absorbed, first bad index or -1).
    Parallel over fixed chunks of EULER_CHUNK particles whose partial results are combined in
    chunk order, so the sums do not depend on the number of threads (``part``: at least
    n // EULER_CHUNK + 1 rows of 6, scratch).
    """
    n = temperature.shape[0]
    nchunks = (n + EULER_CHUNK - 1) // EULER_CHUNK
    for c in prange(nchunks):
        limit = math.inf
        where = -1
        wall_q = 0.0
        source_q = 0.0
        absorbed = 0.0
        bad = -1
        for i in range(c * EULER_CHUNK, min(n, (c + 1) * EULER_CHUNK)):
            by_mechanism[i, M_SOURCE] = source[i]
            q = by_mechanism[i, M_DIRECT] + by_mechanism[i, M_WALL] + source[i]
            heat_rate[i] = q
            wall_q += by_mechanism[i, M_WALL]
            source_q += source[i]
            if fixed[i]:
                absorbed += q
                continue
            mc = mass[i] * c_by_type[type_id[i]]
            if conductance_sum[i] > 0.0:
                lim = mc / conductance_sum[i]
                if lim < limit:
                    limit = lim
                    where = i
            t = temperature[i] + dt * q / mc
            temperature[i] = t
            if bad < 0 and not (t > 0.0 and math.isfinite(t)):
                bad = i
        part[c, 0] = limit
        part[c, 1] = where
        part[c, 2] = wall_q
        part[c, 3] = source_q
        part[c, 4] = absorbed
        part[c, 5] = bad
    limit = math.inf
    where = -1
    wall_q = 0.0
    source_q = 0.0
    absorbed = 0.0
    bad = -1
    for c in range(nchunks):
        if part[c, 0] < limit:
            limit = part[c, 0]
            where = int(part[c, 1])
        wall_q += part[c, 2]
        source_q += part[c, 3]
        absorbed += part[c, 4]
        if bad < 0 and part[c, 5] >= 0:
            bad = int(part[c, 5])
    return limit, where, wall_q, source_q, absorbed, bad
