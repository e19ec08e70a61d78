"""Heat-only passes of the thermal terms that are not the fused contact conduction.

Every pass evaluates one term on one pair set and **adds** the heat rate into its particles'
mechanism column and the conductance into ``conductance_sum`` (the explicit stability limit).
The range passes are compiled per model (``kernels/range_pass.py``: the model a compile-time
constant, so the hot gap terms pay no model switch); the passes here select the model
at run time by its evaluator and model id through an integer switch (one compiled kernel per
pass kind serves every model). Either way the compiled variants grow with the models
selected, not with their combinations.

- ``range_pair_pass``, ``range_wall_pass``: pairs and particle-wall pairs of the range set
  (surface gap within the term's interaction range, touching pairs included), compiled per
  model: :mod:`thermodem.kernels.range_pass`;
- :func:`contact_term_pair_pass`, :func:`contact_term_wall_pass`: touching pairs of the
  contact lists (terms that need the contact radius model and the normal force);
- ``EXTERNAL_PAIR_PASSES`` (an external pair pass for the Voronoi models, one for the
  other terms) and :func:`csr_heat`: pairs of an external pair set (not bounded by a cell
  edge): a conductance per pair, then every particle sums its pairs through a CSR index
  (``engine/external_set.py``);
- :func:`particle_pass`: per-particle terms (radiation, convection), each returning a heat
  rate and a linearised conductance G = -dQ/dT_i that the stability limit adds to
  ``conductance_sum``;
- :func:`pair_heat_from_conductance`, :func:`wall_heat_from_conductance`: heat rates from
  conductances stored by an earlier evaluation of the same pairs (frozen mechanics).

Pairwise heat is antisymmetric by construction: one number q is added to i and subtracted
from j. The conductance H of a pair is the model's value; the heat into i is H (T_j - T_i).
With ``store`` the passes also write H per pair (``out_conductance``), which the frozen-
mechanics path reuses and the per-contact output reads.

The k(T) override: with ``k_col_i >= 0`` the row's columns ``k_col_i``, ``k_col_j`` are
replaced by the two bodies' current conductivities (a scratch row per group or chunk).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from thermodem.geometry.wall_layout import COL_TEMPERATURE, COL_THERMAL_KIND
from thermodem.kernels.contact import H_DURATION, H_IMPACT_VELOCITY, STATE_TOUCHING
from thermodem.kernels.fields import F_SCRATCH_CONDUCTANCE, F_SCRATCH_HEAT
from thermodem.kernels.neighbors import minimum_image, pair_separation, wall_distance
from thermodem.kernels.variants import parallel_kernel
from thermodem.models.thermal.contact_radius import (
    contact_radius_dispatch,
    geometric_contact_radius,
)
from thermodem.models.thermal.convection import GUNN, convection_dispatch, gunn_chunk
from thermodem.models.thermal.direct_conduction import separated_conductance
from thermodem.models.thermal.indirect_conduction import indirect_conduction_dispatch
from thermodem.models.thermal.radiation import radiation_dispatch
from thermodem.models.thermal.voronoi import (
    voronoi_cutoff_distance,
    voronoi_dispatch,
    voronoi_side,
)

#: Evaluators of pair terms: an indirect_conduction model, or the separated-pair part of a
#: direct_conduction model with an interaction range.
EVAL_INDIRECT = 0
EVAL_SEPARATED = 1
#: Evaluators of per-particle terms.
EVAL_RADIATION = 2
EVAL_CONVECTION = 3
#: Evaluator of the models of an external pair set that read the pair's input row (the
#: Voronoi models: models/thermal/voronoi.py).
EVAL_VORONOI = 4

WALL_CHUNK = 4096  # particles per chunk of the wall passes
PARTICLE_CHUNK = 4096  # particles per chunk of the per-particle passes


@njit(cache=True, inline="always", error_model="numpy")
def term_conductance(evaluator, model_id, p, r_i, r_j, dist, r_c, f_n):
    """Conductance [W/K] of one pair for a pair term (see the module docstring)."""
    if evaluator == EVAL_SEPARATED:
        return separated_conductance(model_id, p, r_i, r_j, dist)
    return indirect_conduction_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n)


@njit(cache=True, inline="always", error_model="numpy")
def add_pair_heat(by_mechanism, column, conductance_sum, temperature, i, j, h):
    """A pair's exchange of conductance ``h``: q = h (T_j - T_i) added to i's mechanism
    column and subtracted from j's (antisymmetric: what i gains j loses), h added to both
    particles' conductance sums (the explicit stability limit)."""
    q = h * (temperature[j] - temperature[i])
    by_mechanism[column, i] += q
    by_mechanism[column, j] -= q
    conductance_sum[i] += h
    conductance_sum[j] += h


@njit(cache=True, inline="always", error_model="numpy")
def _row(table_row, k_col_i, k_col_j, k_i, k_j, scratch_row):
    """The parameter row, with the conductivity columns replaced when k_col_i >= 0."""
    if k_col_i < 0:
        return table_row
    for q in range(table_row.shape[0]):
        scratch_row[q] = table_row[q]
    scratch_row[k_col_i] = k_i
    scratch_row[k_col_j] = k_j
    return scratch_row


@parallel_kernel(error_model="numpy")
def contact_term_pair_pass(
    position, radius, mass, temperature, type_id, pair_i, pair_j, group_start, state,
    normal_force, history, lower, upper, periodic, radius_id, radius_table, evaluator,
    model_id, table, k_col_i, k_col_j, k_particle, scratch, column, by_mechanism,
    conductance_sum, store, out_conductance,
):  # fmt: skip
    """One pair term over the touching pairs of the contact list, with the contact radius of
    the case's contact_radius model and the pair's normal force."""
    length = upper - lower
    ngroups = group_start.shape[0] - 1
    for parity in range(2):
        for half in prange((ngroups + 1 - parity) // 2):
            g = 2 * half + parity
            srow = scratch[g]
            for k in range(group_start[g], group_start[g + 1]):
                h = 0.0
                if state[k] == STATE_TOUCHING:
                    i = pair_i[k]
                    j = pair_j[k]
                    dist = pair_separation(position, i, j, length, periodic)[3]
                    ri = radius[i]
                    rj = radius[j]
                    m_eff = mass[i] * mass[j] / (mass[i] + mass[j])
                    f_n = normal_force[k]
                    r_c = contact_radius_dispatch(
                        radius_id, radius_table[type_id[i], type_id[j]], ri, rj, dist,
                        ri + rj - dist, f_n, history[k, H_DURATION], history[k, H_IMPACT_VELOCITY],
                        m_eff,
                    )  # fmt: skip
                    ki = kj = 0.0
                    if k_col_i >= 0:
                        ki = k_particle[i]
                        kj = k_particle[j]
                    p = _row(table[type_id[i], type_id[j]], k_col_i, k_col_j, ki, kj, srow)
                    h = term_conductance(evaluator, model_id, p, ri, rj, dist, r_c, f_n)
                    if h != 0.0:
                        add_pair_heat(by_mechanism, column, conductance_sum, temperature, i, j, h)
                if store:
                    out_conductance[k] = h


@parallel_kernel(error_model="numpy")
def contact_term_wall_pass(
    position, radius, mass, temperature, type_id, wall_pair_w, wall_row_start, state,
    normal_force, history, wall_kind, wall_rows, wall_material, radius_id, radius_table,
    evaluator, model_id, table, k_col_i, k_col_j, k_particle, k_wall, scratch, column,
    by_mechanism, conductance_sum, store, out_conductance,
):  # fmt: skip
    """One pair term over the touching particle-wall pairs of the contact lists."""
    n = radius.shape[0]
    nchunks = (n + WALL_CHUNK - 1) // WALL_CHUNK
    for c in prange(nchunks):
        srow = scratch[c]
        for i in range(c * WALL_CHUNK, min(n, (c + 1) * WALL_CHUNK)):
            for k in range(wall_row_start[i], wall_row_start[i + 1]):
                w = wall_pair_w[k]
                wrow = wall_rows[w]
                h = 0.0
                if state[k] == STATE_TOUCHING and wrow[COL_THERMAL_KIND] != 0.0:
                    d = wall_distance(wall_kind[w], wrow, position[i])[0]
                    ri = radius[i]
                    tw = wall_material[w]
                    f_n = normal_force[k]
                    r_c = contact_radius_dispatch(
                        radius_id, radius_table[type_id[i], tw], ri, math.inf, d, ri - d, f_n,
                        history[k, H_DURATION], history[k, H_IMPACT_VELOCITY], mass[i],
                    )  # fmt: skip
                    ki = kw = 0.0
                    if k_col_i >= 0:
                        ki = k_particle[i]
                        kw = k_wall[w]
                    p = _row(table[type_id[i], tw], k_col_i, k_col_j, ki, kw, srow)
                    h = term_conductance(evaluator, model_id, p, ri, math.inf, d, r_c, f_n)
                    if h != 0.0:
                        by_mechanism[column, i] += h * (wrow[COL_TEMPERATURE] - temperature[i])
                        conductance_sum[i] += h
                if store:
                    out_conductance[k] = h


@njit(cache=True, error_model="numpy")
def pair_csr(pair_i, pair_j, n, offsets, entries):
    """CSR index of a pair list by particle: ``entries[offsets[a]:offsets[a + 1]]`` are
    2 k (particle a is pair k's i) or 2 k + 1 (it is its j), in pair order."""
    offsets[:] = 0
    npairs = pair_i.shape[0]
    for k in range(npairs):
        offsets[pair_i[k] + 1] += 1
        offsets[pair_j[k] + 1] += 1
    for a in range(n):
        offsets[a + 1] += offsets[a]
    fill = offsets[:n].copy()
    for k in range(npairs):
        entries[fill[pair_i[k]]] = 2 * k
        fill[pair_i[k]] += 1
        entries[fill[pair_j[k]]] = 2 * k + 1
        fill[pair_j[k]] += 1


#: Columns of the per-pair state of the Voronoi conductance reuse (the external pair pass):
#: the interval of centre distances where the last evaluation is reused, the distance,
#: conductance and face area of that evaluation, and the slope dH/dd applied (the secant
#: through the last two evaluations, or 0).
REUSE_LOW, REUSE_HIGH, REUSE_DISTANCE, REUSE_CONDUCTANCE, REUSE_SLOPE, REUSE_AREA = range(6)
REUSE_WIDTH = 6
#: Relative guard of the reuse intervals at the cut-off distance (never reuse across it).
CUTOFF_GUARD = 1e-12


@njit(cache=True, error_model="numpy")
def _reuse_row(model_id, p, ri, rj, dist, h, area, tolerance, row):
    """Store an evaluation H(dist) in the pair's reuse row (see ``_compile_external_pair_pass``)."""
    touch = ri + rj
    side = voronoi_side(model_id, p, ri, rj, dist)
    d_b = row[REUSE_DISTANCE]
    w = abs(dist - touch)
    delta = dist - d_b
    slope = 0.0
    window = tolerance * tolerance * w
    if (
        row[REUSE_AREA] == area
        and side == voronoi_side(model_id, p, ri, rj, d_b)
        and delta != 0.0
        and abs(delta) <= 2.0 * tolerance * w
    ):
        slope = (h - row[REUSE_CONDUCTANCE]) / delta
        window = tolerance * w
    # the distances of this side of touching and of the cut-off (with a guard: the
    # interval never holds a distance of the other side)
    cut = voronoi_cutoff_distance(model_id, p, ri, rj)
    if side == 0:
        lo, hi = -np.inf, touch * (1.0 - 4e-16)
    elif side == 1:
        lo, hi = touch, cut * (1.0 - CUTOFF_GUARD)
    else:
        lo, hi = cut * (1.0 + CUTOFF_GUARD), np.inf
    if lo <= dist <= hi:
        row[REUSE_LOW] = max(dist - window, lo)
        row[REUSE_HIGH] = min(dist + window, hi)
    else:  # in a guard zone: evaluate again next time
        row[REUSE_LOW] = np.inf
        row[REUSE_HIGH] = -np.inf
    row[REUSE_DISTANCE] = dist
    row[REUSE_CONDUCTANCE] = h
    row[REUSE_SLOPE] = slope
    row[REUSE_AREA] = area


def _compile_external_pair_pass(VORONOI: bool):  # noqa: ANN202, N803
    """The external pair pass for the Voronoi models (``VORONOI``: they read the pair's input
    row) or for the other pair terms (the gap-conduction models): one model family per
    compiled kernel, so a Voronoi case does not compile every gap model too (serial twin
    6.9 → 3.2 s of compile)."""

    @parallel_kernel(error_model="numpy")
    def external_pair_pass(
        position, radius, type_id, pair_i, pair_j, inputs, lower, upper, periodic, evaluator,
        model_id, table, k_col_i, k_col_j, k_particle, scratch, out_conductance, tolerance,
        reuse,
    ):  # fmt: skip
        """Conductance     of every pair of an external pair set (``inputs``: a row per pair, read
        by the models made for such sets; the gap-conduction models ignore it). Returns the
        number of pairs whose model was evaluated.

        With ``tolerance`` > 0 (Voronoi models only; ``reuse``: a row per pair, NaN rows: no
        evaluation yet) a pair keeps its last evaluation H_b at distance d_b while its face area
        is unchanged and its distance d is within the row's interval: d_b ± tolerance × w,
        w = |d_b - R_i - R_j| its surface gap (or overlap) then, clipped to d_b's side of touching
        and of the cut-off; H = H_b + S (d - d_b) with S the secant slope through its last two
        evaluations (when they were at most 2 tolerance w apart; without one S = 0 and the
        interval is d_b ± tolerance² w). Otherwise the model is evaluated and the row updated.
        docs/models/indirect_conduction-voronoi_a.md, "Conductance reuse"."""
        length = upper - lower
        npairs = pair_i.shape[0]
        nchunks = (npairs + PARTICLE_CHUNK - 1) // PARTICLE_CHUNK
        evaluated = 0
        for c in prange(nchunks):
            srow = scratch[c]
            count = 0
            for k in range(c * PARTICLE_CHUNK, min(npairs, (c + 1) * PARTICLE_CHUNK)):
                i = pair_i[k]
                j = pair_j[k]
                dist = pair_separation(position, i, j, length, periodic)[3]
                if tolerance > 0.0:
                    row = reuse[k]
                    if (
                        row[REUSE_AREA] == inputs[k, 0]
                        and row[REUSE_LOW] <= dist <= row[REUSE_HIGH]
                    ):
                        out_conductance[k] = row[REUSE_CONDUCTANCE] + row[REUSE_SLOPE] * (
                            dist - row[REUSE_DISTANCE]
                        )
                        continue
                ri = radius[i]
                rj = radius[j]
                ki = kj = 0.0
                if k_col_i >= 0:
                    ki = k_particle[i]
                    kj = k_particle[j]
                p = _row(table[type_id[i], type_id[j]], k_col_i, k_col_j, ki, kj, srow)
                r_c = geometric_contact_radius(ri, rj, ri + rj - dist)
                count += 1
                if VORONOI:
                    h = voronoi_dispatch(model_id, p, ri, rj, dist, r_c, inputs[k])
                else:
                    h = term_conductance(evaluator, model_id, p, ri, rj, dist, r_c, 0.0)
                out_conductance[k] = h
                if tolerance > 0.0:
                    _reuse_row(model_id, p, ri, rj, dist, h, inputs[k, 0], tolerance, reuse[k])
            evaluated += count
        return evaluated

    return external_pair_pass


#: The external pair passes: ``EXTERNAL_PAIR_PASSES[evaluator == EVAL_VORONOI]``.
EXTERNAL_PAIR_PASSES = {True: _compile_external_pair_pass(True),
                        False: _compile_external_pair_pass(False)}  # fmt: skip


@parallel_kernel(error_model="numpy")
def external_wall_pass(
    position, radius, temperature, type_id, wall_i, wall_w, wall_offsets, inputs, wall_kind,
    wall_rows, wall_material, model_id, table, k_col_i, k_col_j, k_particle, k_wall, scratch,
    column, by_mechanism, conductance_sum, store, out_conductance,
):  # fmt: skip
    """The particle-wall pairs of an external pair set (``wall_offsets``: the pairs of each
    particle), for the models that read the input row (EVAL_VORONOI): H from the distance to
    the wall and the input row; adiabatic walls give no heat. With ``store`` H is written
    per pair; otherwise ``out_conductance`` holds H from an earlier evaluation and only the
    heat is recomputed from it."""
    n = radius.shape[0]
    nchunks = (n + WALL_CHUNK - 1) // WALL_CHUNK
    for c in prange(nchunks):
        srow = scratch[c]
        for i in range(c * WALL_CHUNK, min(n, (c + 1) * WALL_CHUNK)):
            for k in range(wall_offsets[i], wall_offsets[i + 1]):
                w = wall_w[k]
                wrow = wall_rows[w]
                if store and wrow[COL_THERMAL_KIND] == 0.0:
                    out_conductance[k] = 0.0
                elif store:
                    d = wall_distance(wall_kind[w], wrow, position[i])[0]
                    ri = radius[i]
                    r_c = geometric_contact_radius(ri, math.inf, ri - d)
                    ki = kw = 0.0
                    if k_col_i >= 0:
                        ki = k_particle[i]
                        kw = k_wall[w]
                    p = _row(table[type_id[i], wall_material[w]], k_col_i, k_col_j, ki, kw, srow)
                    out_conductance[k] = voronoi_dispatch(model_id, p, ri, math.inf, d, r_c,
                                                          inputs[k])  # fmt: skip
                h = out_conductance[k]
                if h != 0.0:
                    by_mechanism[column, i] += h * (wrow[COL_TEMPERATURE] - temperature[i])
                    conductance_sum[i] += h


@parallel_kernel(error_model="numpy")
def csr_heat(
    offsets, entries, pair_i, pair_j, conductance, temperature, column, by_mechanism,
    conductance_sum,
):  # fmt: skip
    """Every particle sums its pairs' heat through the CSR index (pair order): the same
    q = H (T_j - T_i) of pair k is added to its i and subtracted from its j."""
    n = offsets.shape[0] - 1
    for a in prange(n):
        for e in range(offsets[a], offsets[a + 1]):
            k = entries[e] >> 1
            h = conductance[k]
            if h != 0.0:
                q = h * (temperature[pair_j[k]] - temperature[pair_i[k]])
                if entries[e] & 1:
                    by_mechanism[column, a] -= q
                else:
                    by_mechanism[column, a] += q
                conductance_sum[a] += h


@njit(cache=True, inline="always", error_model="numpy")
def particle_term(evaluator, model_id, p, t_i, r_i, fields, i):
    """(Q into particle i [W], G = -dQ/dT_i [W/K]) of a per-particle term."""
    if evaluator == EVAL_CONVECTION:
        return convection_dispatch(model_id, p, t_i, r_i, fields, i)
    return radiation_dispatch(model_id, p, t_i, r_i, fields, i)


@parallel_kernel(error_model="numpy")
def particle_pass(
    temperature, radius, type_id, fields, evaluator, model_id, table, column, evaluator2,
    model_id2, table2, column2, by_mechanism, conductance_sum,
):  # fmt: skip
    """One per-particle term over every particle (``table``: a row per material), and a
    second one in the same pass when ``column2`` >= 0 (two consecutive terms, e.g. convection
    and radiation: one pass over the particles and their fields; each particle adds the
    first term, then the second, as two passes would).

    By chunks of PARTICLE_CHUNK particles, term by term: the term's (Q, G) of the chunk's
    particles into the scratch rows ``fields[F_SCRATCH_HEAT]``, ``fields[F_SCRATCH_
    CONDUCTANCE]``, then added to the term's column and to ``conductance_sum`` (each
    particle's sums receive the same numbers in the same order as particle by particle).
    Gunn (1978) fills them in loops that vectorise (``convection.gunn_chunk``); the other
    models particle by particle through the dispatchers."""
    n = temperature.shape[0]
    nterms = 2 if column2 >= 0 else 1
    nchunks = (n + PARTICLE_CHUNK - 1) // PARTICLE_CHUNK
    for c in prange(nchunks):
        lo = c * PARTICLE_CHUNK
        hi = min(n, lo + PARTICLE_CHUNK)
        heat = fields[F_SCRATCH_HEAT, lo:hi]
        conductance = fields[F_SCRATCH_CONDUCTANCE, lo:hi]
        for k in range(nterms):
            first = k == 0
            ev = evaluator if first else evaluator2
            mid = model_id if first else model_id2
            col = column if first else column2
            rows = table if first else table2
            if ev == EVAL_CONVECTION and mid == GUNN:
                gunn_chunk(rows, type_id, radius, temperature, fields, lo, hi, heat, conductance)
            else:
                # one call site of the (inlined) dispatchers: two would double the compile
                # time; an unsigned index (no negative-index wrap-around on its loads)
                for t in range(hi - lo):
                    i = np.uint64(lo + t)
                    q, g = particle_term(ev, mid, rows[np.uint32(type_id[i])], temperature[i],
                                         radius[i], fields, i)  # fmt: skip
                    heat[t] = q
                    conductance[t] = g
            into = by_mechanism[col, lo:hi]
            sums = conductance_sum[lo:hi]
            for t in range(hi - lo):
                into[t] += heat[t]
                sums[t] += conductance[t]


@parallel_kernel(error_model="numpy")
def pair_heat_from_conductance(
    pair_i, pair_j, group_start, conductance, temperature, column, by_mechanism,
    conductance_sum,
):  # fmt: skip
    """Heat rates of a pair list from stored conductances, by slab groups (the order of the
    passes that stored them): q = H (T_j - T_i) added to i, subtracted from j."""
    ngroups = group_start.shape[0] - 1
    for parity in range(2):
        for half in prange((ngroups + 1 - parity) // 2):
            g = 2 * half + parity
            for k in range(group_start[g], group_start[g + 1]):
                h = conductance[k]
                if h != 0.0:
                    add_pair_heat(by_mechanism, column, conductance_sum, temperature,
                                  pair_i[k], pair_j[k], h)  # fmt: skip


@parallel_kernel(error_model="numpy")
def wall_heat_from_conductance(
    wall_pair_w, wall_row_start, wall_rows, conductance, temperature, column, by_mechanism,
    conductance_sum,
):  # fmt: skip
    """Heat rates of particle-wall pairs from stored conductances (particle by particle)."""
    n = temperature.shape[0]
    for i in prange(n):
        for k in range(wall_row_start[i], wall_row_start[i + 1]):
            h = conductance[k]
            if h != 0.0:
                t_wall = wall_rows[wall_pair_w[k], COL_TEMPERATURE]
                by_mechanism[column, i] += h * (t_wall - temperature[i])
                conductance_sum[i] += h


@parallel_kernel(error_model="numpy")
def zero_heat(by_mechanism, conductance_sum):
    """Every mechanism column and the conductance sums to zero (before the terms add)."""
    for i in prange(by_mechanism.shape[1]):
        for m in range(by_mechanism.shape[0]):
            by_mechanism[m, i] = 0.0
        conductance_sum[i] = 0.0


@parallel_kernel(error_model="numpy")
def largest_displacement(position, reference, lower, upper, periodic, part):
    """Largest displacement since the reference positions (minimum image on periodic axes),
    parallel over fixed chunks of PARTICLE_CHUNK (``part``: at least one scratch value per
    chunk); the maximum does not depend on the thread count."""
    length = upper - lower
    n = position.shape[0]
    nchunks = (n + PARTICLE_CHUNK - 1) // PARTICLE_CHUNK
    for c in prange(nchunks):
        local = 0.0
        for i in range(c * PARTICLE_CHUNK, min(n, (c + 1) * PARTICLE_CHUNK)):
            dx = minimum_image(position[i, 0] - reference[i, 0], length[0], periodic[0])
            dy = minimum_image(position[i, 1] - reference[i, 1], length[1], periodic[1])
            dz = minimum_image(position[i, 2] - reference[i, 2], length[2], periodic[2])
            d2 = dx * dx + dy * dy + dz * dz
            if d2 > local:
                local = d2
        part[c] = local
    best = 0.0
    for c in range(nchunks):
        best = max(best, part[c])
    return math.sqrt(best)
