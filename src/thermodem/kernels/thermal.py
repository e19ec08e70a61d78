"""Thermal passes of the contact conduction, and the per-particle explicit Euler update.

The heat-only contact passes compute, for each touching particle pair and particle–wall pair
of the contact lists, the conductance H of the contact conduction (the direct-conduction model
evaluated at T_i = 0, T_j = 1: every direct model of the spec is linear in the temperature
difference) into per-pair arrays; ``kernels/heat_terms.py`` adds the heat rates
Q = H (T_j - T_i) to both particles by slab group, so what i gains j loses exactly and the
result does not depend on the number of threads. These passes serve frozen mechanics and the
start of a run; otherwise the fused contact pass of the mechanics computes the same numbers.
"""

from __future__ import annotations

import math
from typing import Any

from numba import njit, prange

from thermodem.geometry.wall_layout import COL_THERMAL_KIND
from thermodem.kernels.contact import CHUNK, STATE_TOUCHING
from thermodem.kernels.contact_conduction import _pp_conductance, _pw_conductance, reusable
from thermodem.kernels.neighbors import pair_separation, wall_distance
from thermodem.kernels.variants import parallel_kernel
from thermodem.state.heat import GENERATION, M_GENERATION, M_SOURCE

assert len(GENERATION) == 6  # (euler_step reads the six accumulators unrolled)

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

    @parallel_kernel(error_model="numpy")
    def conduction_pair_pass(
        position, radius, mass, temperature, type_id, pair_i, pair_j, npairs, state, normal_force,
        history, lower, upper, periodic, radius_id, radius_table, conduction_id, conduction_table,
        override, k_particle, rhoc_particle, scratch, out_conductance, reuse_col, tolerance,
    ):  # fmt: skip
        """Conductance of every listed particle pair (0 unless touching).

        With ``override`` > 0 the conductivity columns (0, 1) of the model's row are replaced by
        the particles' current k(T), and with ``override`` > 1 also the heat capacity columns
        (2, 3) by ρ c(T) (temperature-dependent properties). ``reuse_col``: first history
        column of the conductance reuse (state/history.py), with ``tolerance`` > 0.
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
                if state[k] != STATE_TOUCHING:
                    out_conductance[k] = 0.0
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
                    rhoc_particle, row, reuse_col, tolerance,
                )  # fmt: skip
                out_conductance[k] = h

    return conduction_pair_pass


_CONDUCTION_WALL_PASSES: dict[tuple[int, int, int], Any] = {}


def conduction_wall_pass_for(radius_id: int, conduction_id: int, override: int) -> Any:
    """The particle–wall conduction pass for one model combination (the model ids and the
    override as compile-time constants, as :func:`conduction_pair_pass_for`). It serves the
    heat-only steps and follows the mechanics' wall pass at the steps whose contact pass
    conducts (``kernels/pair_pass.py``)."""
    key = (int(radius_id), int(conduction_id), int(override))
    if key not in _CONDUCTION_WALL_PASSES:
        _CONDUCTION_WALL_PASSES[key] = _compile_conduction_wall_pass(*key)
    return _CONDUCTION_WALL_PASSES[key]


def _compile_conduction_wall_pass(RADIUS_ID: int, CONDUCTION_ID: int, OVERRIDE: int):  # noqa: N803, ANN202
    REUSABLE = reusable(CONDUCTION_ID)  # noqa: N806

    @njit(cache=True, error_model="numpy")
    def conduction_wall_pass(
        position, radius, mass, temperature, type_id, wall_pair_i, wall_pair_w, nwpairs, state,
        normal_force, history, wall_kind, wall_rows, wall_material, radius_id, radius_table,
        conduction_id, conduction_table, override, k_particle, rhoc_particle, k_wall, rhoc_wall,
        scratch, out_conductance, reuse_col, tolerance,
    ):  # fmt: skip
        """Conductance of touching particle–fixed-temperature-wall pairs (adiabatic walls: 0).

        ``override`` as in :func:`conduction_pair_pass`; the wall's values are ``k_wall[w]``
        and ``rhoc_wall[w]`` (its material at the wall temperature).
        """
        radius_id = RADIUS_ID
        conduction_id = CONDUCTION_ID
        override = OVERRIDE
        if not REUSABLE:
            tolerance = 0.0  # (the reuse's code is dropped)
        nchunks = (nwpairs + CHUNK - 1) // CHUNK
        for c in range(nchunks):  # (serial: few pairs, and ~1 s less to compile)
            row = scratch[c]
            for k in range(c * CHUNK, min(nwpairs, (c + 1) * CHUNK)):
                w = wall_pair_w[k]
                wrow = wall_rows[w]
                if state[k] != STATE_TOUCHING or wrow[COL_THERMAL_KIND] == 0.0:
                    out_conductance[k] = 0.0
                    continue
                i = wall_pair_i[k]
                d = wall_distance(wall_kind[w], wrow, position[i])[0]
                ri = radius[i]
                overlap = ri - d
                h = _pw_conductance(
                    k, i, w, ri, d, overlap, mass, type_id, wall_material, history, normal_force,
                    radius_id, radius_table, conduction_id, conduction_table, override,
                    k_particle, rhoc_particle, k_wall, rhoc_wall, row, reuse_col, tolerance,
                )  # fmt: skip
                out_conductance[k] = h

    return conduction_wall_pass


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


@parallel_kernel(error_model="numpy")
def finish_heat(source, heat_rate, by_mechanism, columns):
    """Source column and total heat rate: the sum of the mechanism columns ``columns`` (the
    columns in use, ascending; the others are zero)."""
    for i in prange(heat_rate.shape[0]):
        by_mechanism[M_SOURCE, i] = source[i]
        q = 0.0
        for m in columns:
            q += by_mechanism[m, i]
        heat_rate[i] = q


EULER_CHUNK = 1024  # (50,000 particles: 49 chunks, 25 and 24 on two threads; 4096 gave 7 and 6)
#: Columns of the per-chunk partial results of :func:`euler_step` before the per-mechanism sums.
EULER_FIXED = 4


@parallel_kernel(error_model="numpy")
def euler_step(temperature, heat_rate, by_mechanism, columns, source, source_on, mass, type_id,
               c_by_type, conductance_sum, conductances, fixed, dt, part, clear, gen_energy,
               generation, gen_scale):  # fmt: skip
    """One fused per-particle thermal update with constant specific heats.

    Fills the source column (with ``source_on``; without sources it stays zero), forms the
    total heat rate: with ``generation``, the heat generation χ E_g / Δt of the six
    accumulators ``gen_energy`` (n, 6) (the mechanisms not selected stay zero; without
    ``generation`` they are not read, any array will do); ``gen_scale``
    = χ / Δt, the step's own length, so that the heat applied is χ E_g exactly), emptying
    the accumulators (kernels/generation.py's conversion, fused here: no conversion pass and
    no clearing pass; the generation columns are not written, ``columns`` must not hold them:
    ThermalEngine.finish forms them for the readers of the rates), plus the sum of the
    mechanism columns ``columns`` (the others in use, ascending), finds the
    explicit Euler limit min m c / ΣH over free particles, applies T += dt Q / (m c) to free
    particles, and sums per chunk the heat absorbed by fixed particles and every mechanism
    column in use [W] (``part[c, EULER_FIXED + m]``); ``conductances``: some term adds to
    ``conductance_sum`` (else it is neither read nor cleared, and there is no limit). With
    ``clear`` it then zeroes the
    particle's mechanism columns in use and conductance sum, which the contact pass of the
    same step adds to next (instead of a separate zeroing pass over the particles; they are
    in the cache here). Returns (limit, limit index, absorbed, first bad index or -1).
    Parallel over fixed chunks of EULER_CHUNK particles whose partial results are combined in
    chunk order, so the sums do not depend on the number of threads (``part``: at least
    n // EULER_CHUNK + 1 rows of EULER_FIXED + the number of mechanisms, scratch).
    """
    n = temperature.shape[0]
    nmech = by_mechanism.shape[0]
    nchunks = (n + EULER_CHUNK - 1) // EULER_CHUNK
    for c in prange(nchunks):
        limit = math.inf
        where = -1
        absorbed = 0.0
        bad = -1
        row = part[c]
        for m in range(nmech):
            row[EULER_FIXED + m] = 0.0
        # the generation sums of the chunk in scalars (a sum into ``row`` per particle and
        # mechanism chained every addition through memory: 0.28 -> 0.11 ms per step for
        # 50,000 particles); all six accumulators are read, the unselected ones stay zero
        s0 = s1 = s2 = s3 = s4 = s5 = 0.0
        for i in range(c * EULER_CHUNK, min(n, (c + 1) * EULER_CHUNK)):
            if source_on:
                by_mechanism[M_SOURCE, i] = source[i]
            q = 0.0
            if generation:
                q0 = gen_scale * gen_energy[i, 0]
                q1 = gen_scale * gen_energy[i, 1]
                q2 = gen_scale * gen_energy[i, 2]
                q3 = gen_scale * gen_energy[i, 3]
                q4 = gen_scale * gen_energy[i, 4]
                q5 = gen_scale * gen_energy[i, 5]
                gen_energy[i, 0] = 0.0
                gen_energy[i, 1] = 0.0
                gen_energy[i, 2] = 0.0
                gen_energy[i, 3] = 0.0
                gen_energy[i, 4] = 0.0
                gen_energy[i, 5] = 0.0
                s0 += q0
                s1 += q1
                s2 += q2
                s3 += q3
                s4 += q4
                s5 += q5
                q = q0 + q1 + q2 + q3 + q4 + q5
            for m in columns:
                qm = by_mechanism[m, i]
                q += qm
                row[EULER_FIXED + m] += qm
            heat_rate[i] = q
            g = conductance_sum[i] if conductances else 0.0
            if clear:  # (the other columns are never written: zero)
                for m in columns:
                    by_mechanism[m, i] = 0.0
                if conductances:
                    conductance_sum[i] = 0.0
            if fixed[i]:
                absorbed += q
                continue
            mc = mass[i] * c_by_type[type_id[i]]
            if g > 0.0:
                lim = mc / g
                if lim < limit:
                    limit = lim
                    where = i
            t = temperature[i] + dt * q / mc
            temperature[i] = t
            if bad < 0 and not (t > 0.0 and math.isfinite(t)):
                bad = i
        if generation:
            row[EULER_FIXED + M_GENERATION] = s0
            row[EULER_FIXED + M_GENERATION + 1] = s1
            row[EULER_FIXED + M_GENERATION + 2] = s2
            row[EULER_FIXED + M_GENERATION + 3] = s3
            row[EULER_FIXED + M_GENERATION + 4] = s4
            row[EULER_FIXED + M_GENERATION + 5] = s5
        row[0] = limit
        row[1] = where
        row[2] = absorbed
        row[3] = bad
    limit = math.inf
    where = -1
    absorbed = 0.0
    bad = -1
    for c in range(nchunks):
        if part[c, 0] < limit:
            limit = part[c, 0]
            where = int(part[c, 1])
        absorbed += part[c, 2]
        if bad < 0 and part[c, 3] >= 0:
            bad = int(part[c, 3])
    return limit, where, absorbed, bad


@njit(cache=True, error_model="numpy")
def specific_enthalpies(temperature, type_id, table_t, table_c, table_n, out):
    """h(T_i) [J/kg] of every particle into ``out`` (the implicit schemes' Picard update)."""
    for i in range(temperature.shape[0]):
        m = type_id[i]
        out[i] = enthalpy(temperature[i], table_t[m], table_c[m], table_n[m])
