"""The passes of one thermal term over the range pair set, compiled per model.

``range_pair_pass`` (:func:`range_passes_for`): pairs of the range set (surface gap within
the term's interaction range, touching pairs included), run by slab groups like the contact
pass (even groups in parallel, then odd ones; :mod:`thermodem.kernels.slabs`): race-free,
and each particle receives its contributions in an order fixed by the list, whatever the
thread count. ``range_wall_pass``: the particle-wall pairs of the set (fixed-temperature
walls). Conventions (heat added into a mechanism column, ``conductance_sum``, ``store``, the
k(T) override): :mod:`thermodem.kernels.heat_terms`.

For a model whose sphere form vectorises (``VECTORISED_SPHERE_FORMS`` of the family
module: Rong & Horio), the pair pass works through each group in chunks of :data:`CHUNK`
pairs, in three loops (issue 10 §3: the range pass of Rong & Horio at 0.5 R̄ on the 50k bed
went from ~25 to ~10-12 ns per pair, 1 thread):

1. *gather*: the squared centre distance, both radii and the pair's parameter row (copied
   column by column; skipped when every row of the table is the same and no column is
   overridden: the columns are then filled once) into contiguous chunk buffers;
2. *conductances*: H of every pair of the chunk from those buffers only. No indexed loads
   (LLVM does not vectorise gathers on this CPU family) and, for a model whose sphere form
   is branch-free and calls no library function (``rong_horio1999`` with the compiled
   logarithm of :mod:`thermodem.kernels.fastmath_log`), no branch: LLVM vectorises this
   loop (AVX-512 on the 2-core VMs: 8 pairs per instruction). Other models run it scalar.
   Sphere pairs only, so the models' wall branch is not in it
   (:func:`~thermodem.models.thermal.indirect_conduction.indirect_sphere_dispatch`);
3. *scatter*: q = H (T_j - T_i) added to i and subtracted from j, in pair order (the
   summation order of the fused loop: bit-identical sums for the same H).

The other models run pair by pair in one fused loop (for them the chunk buffers cost ~3-10 %:
Batchelor & O'Brien's separated part, 40 ns per pair).

The distance is computed with the same operations as ``pair_separation`` and every loop
keeps IEEE semantics (no fast-math), so H is the model's value whatever LLVM vectorises.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from thermodem.geometry.wall_layout import COL_TEMPERATURE, COL_THERMAL_KIND
from thermodem.kernels.heat_terms import (
    EVAL_INDIRECT,
    EVAL_SEPARATED,
    WALL_CHUNK,
    _row,
    add_pair_heat,
    term_conductance,
)
from thermodem.kernels.neighbors import minimum_image, pair_separation, wall_distance
from thermodem.kernels.variants import parallel_kernel
from thermodem.models import registry
from thermodem.models.thermal.contact_radius import geometric_contact_radius
from thermodem.models.thermal.direct_conduction import SEPARATED_FORMS, separated_conductance
from thermodem.models.thermal.indirect_conduction import (
    VECTORISED_SPHERE_FORMS,
    indirect_sphere_dispatch,
)
from thermodem.models.thermal.surrounding_layer import rong_horio1999_spheres

#: Pairs per chunk of the range pair pass (buffers of (width + 4) × CHUNK doubles per group:
#: 8 kB for Rong & Horio's 4 columns, in L1). 128 and 256 measured alike, 64 slower.
CHUNK = 128


@njit(cache=True, inline="always", error_model="numpy")
def term_sphere_conductance(evaluator, model_id, p, r_i, r_j, dist, r_c, f_n):
    """:func:`~thermodem.kernels.heat_terms.term_conductance` of two spheres (r_j finite)."""
    if evaluator == EVAL_SEPARATED:
        return separated_conductance(model_id, p, r_i, r_j, dist)
    return indirect_sphere_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n)


def _selected_form(evaluator: int, model_id: int, spheres: bool) -> Any:
    """The one model kernel H(p, r_i, r_j, dist, r_c) of (evaluator, model id), inlined into
    its caller, or None (an id without a registered kernel: the switch)."""
    if evaluator == EVAL_SEPARATED:
        form = SEPARATED_FORMS.get(model_id)
        if form is None:
            return _nothing

        @njit(inline="always", error_model="numpy")
        def separated(p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
            return form(p, r_i, r_j, dist)

        return separated
    if evaluator != EVAL_INDIRECT:
        return None
    if spheres and model_id in VECTORISED_SPHERE_FORMS:
        kernel = rong_horio1999_spheres  # (the one model with a branch-free sphere form)
    else:
        specs = [m for m in registry.all_models() if m.family == "indirect_conduction"]
        found = [m for m in specs if m.model_id == model_id]
        if not found:
            return None
        kernel = njit(inline="always", error_model="numpy")(found[0].kernel.py_func)

    @njit(inline="always", error_model="numpy")
    def indirect(p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
        return kernel(p, r_i, r_j, dist, r_c, 0.0)

    return indirect


@njit(inline="always", error_model="numpy")
def _nothing(p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
    return 0.0


def range_term(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN201
    """Conductance H [W/K] of the range term (evaluator, model id) for a pair (or a wall:
    ``r_j`` = inf): compiled code only. With both ids compile-time literals (the passes
    compiled per model, :func:`range_passes_for`) it is an inlined copy of that one model's
    kernel: the integer switches of :func:`~thermodem.kernels.heat_terms.term_conductance`
    would compile every gap model into every variant (~4 s of a variant's ~7 s). Else the
    switch."""


def range_sphere_term(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN201
    """:func:`range_term` of two spheres (the sphere form of a model that has one)."""


def _overload_term(spheres: bool) -> Any:
    def typer(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
        if isinstance(evaluator, types.IntegerLiteral) and isinstance(
            model_id, types.IntegerLiteral
        ):
            form = _selected_form(evaluator.literal_value, model_id.literal_value, spheres)
            if form is not None:

                def selected(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
                    return form(p, r_i, r_j, dist, r_c)

                return selected
        if spheres:

            def sphere_switch(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
                return term_sphere_conductance(evaluator, model_id, p, r_i, r_j, dist, r_c, 0.0)

            return sphere_switch

        def switch(evaluator, model_id, p, r_i, r_j, dist, r_c):  # noqa: ANN001, ANN202
            return term_conductance(evaluator, model_id, p, r_i, r_j, dist, r_c, 0.0)

        return switch

    return typer


overload(range_term, inline="always", prefer_literal=True)(_overload_term(False))
overload(range_sphere_term, inline="always", prefer_literal=True)(_overload_term(True))


@njit(cache=True, error_model="numpy")
def uniform_rows(table):
    """Whether every row table[a, b] equals table[0, 0] (one parameter row for all pairs)."""
    first = table[0, 0]
    for a in range(table.shape[0]):
        for b in range(table.shape[1]):
            for q in range(table.shape[2]):
                if table[a, b, q] != first[q]:
                    return False
    return True


_RANGE_PASSES: dict[tuple, tuple] = {}


def runs_in_chunks(evaluator: int, model_id: int) -> bool:
    """Whether the range pair pass of this model runs in chunks (module docstring)."""
    return evaluator == EVAL_INDIRECT and model_id in VECTORISED_SPHERE_FORMS


def chunk_buffers(
    cache: dict[int, tuple[np.ndarray, np.ndarray]], groups: int, width: int, chunked: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The (geometry, columns) chunk buffers of the range pair pass for ``groups`` slab
    groups and rows of ``width`` columns, kept in ``cache`` (the caller's, by width) and
    grown when the groups outnumber them: no allocation per step. Without chunks, empty."""
    if not chunked:
        groups = 0
    held = cache.get(width)
    if held is None or held[0].shape[0] < groups:
        held = (np.empty((groups, 4, CHUNK)), np.empty((groups, width, CHUNK)))
        cache[width] = held
    return held


def range_passes_for(
    evaluator: int, model_id: int, need_rc: bool, override: bool, width: int
) -> tuple:
    """(pair pass, wall pass) of one range term: the evaluator, the model id, whether the
    kernel reads the geometric contact radius, whether the k(T) override replaces row
    columns and the row width (``table.shape[2]``) are compile-time constants, so each pass
    holds one model's code (no run-time model switch; one variant per selected range model:
    the variants grow with the models selected, not with their combinations). The passes
    keep the generic argument list; the evaluator, model and ``need_rc`` arguments passed in
    are ignored, and without ``override`` so are ``k_col_i``/``k_col_j``. The pair pass runs
    in chunks (module docstring) for the models whose sphere form vectorises, else pair by
    pair in one fused loop (the chunks' buffers cost those models ~3-10 %)."""
    chunked = runs_in_chunks(evaluator, model_id)
    key = (int(evaluator), int(model_id), bool(need_rc), bool(override), int(width), chunked)
    if key not in _RANGE_PASSES:
        _RANGE_PASSES[key] = _compile_range_passes(*key)
    return _RANGE_PASSES[key]


def _compile_range_passes(EVALUATOR: int, MODEL_ID: int, NEED_RC: bool, OVERRIDE: bool,  # noqa: ANN202, N803
                          WIDTH: int, CHUNKED: bool):  # fmt: skip  # noqa: N803
    """Define the range passes of one term (see :func:`range_passes_for`)."""

    @parallel_kernel(error_model="numpy")
    def range_pair_pass(
        position, radius, temperature, type_id, pair_i, pair_j, group_start, lower, upper,
        periodic, evaluator, model_id, table, k_col_i, k_col_j, k_particle, scratch, column,
        by_mechanism, conductance_sum, store, out_conductance, need_rc, chunk_geometry,
        chunk_cols,
    ):  # fmt: skip
        """One pair term over the range pair set, by slab groups and chunks of pairs (module
        docstring). The heat of a pair out of range (H = 0) is added as zeros, without a
        branch: in a bed pairs in and out of range alternate at random. ``chunk_geometry``
        (groups, 4, CHUNK) and ``chunk_cols`` (groups, WIDTH, CHUNK): the chunk buffers of
        each group, kept by the caller between steps (:func:`chunk_buffers`; read only when
        the pass runs in chunks)."""
        evaluator = EVALUATOR
        model_id = MODEL_ID
        if not OVERRIDE:
            k_col_i = -1
        override = OVERRIDE and k_col_i >= 0
        copy_rows = override or not (CHUNKED and uniform_rows(table))
        length = upper - lower
        lx, ly, lz = length[0], length[1], length[2]
        px, py, pz = periodic[0], periodic[1], periodic[2]
        ngroups = group_start.shape[0] - 1
        for parity in range(2):
            for half in prange((ngroups + 1 - parity) // 2):
                g = 2 * half + parity
                if not CHUNKED:  # pair by pair, one fused loop
                    srow = scratch[g]
                    for k in range(group_start[g], group_start[g + 1]):
                        i = pair_i[k]
                        j = pair_j[k]
                        dist = pair_separation(position, i, j, length, periodic)[3]
                        ri = radius[i]
                        rj = radius[j]
                        r_c = geometric_contact_radius(ri, rj, ri + rj - dist) if NEED_RC else 0.0
                        ki = kj = 0.0
                        if override:
                            ki = k_particle[i]
                            kj = k_particle[j]
                        p = _row(table[type_id[i], type_id[j]], k_col_i, k_col_j, ki, kj, srow)
                        hk = range_term(evaluator, model_id, p, ri, rj, dist, r_c)
                        if store:
                            out_conductance[k] = hk
                        add_pair_heat(by_mechanism, column, conductance_sum, temperature, i, j, hk)
                else:  # in chunks: gather, conductances, scatter
                    geometry = chunk_geometry[g]  # d², r_i, r_j, H of the chunk's pairs
                    cols = chunk_cols[g]  # their parameter rows, by column
                    if not copy_rows:
                        for c in range(WIDTH):
                            cols[c, :] = table[0, 0, c]
                    d2 = geometry[0]
                    r_i = geometry[1]
                    r_j = geometry[2]
                    h = geometry[3]
                    for start in range(group_start[g], group_start[g + 1], CHUNK):
                        n = min(CHUNK, group_start[g + 1] - start)
                        for t in range(n):  # 1. gather
                            i = pair_i[start + t]
                            j = pair_j[start + t]
                            dx = minimum_image(position[j, 0] - position[i, 0], lx, px)
                            dy = minimum_image(position[j, 1] - position[i, 1], ly, py)
                            dz = minimum_image(position[j, 2] - position[i, 2], lz, pz)
                            d2[t] = dx * dx + dy * dy + dz * dz
                            r_i[t] = radius[i]
                            r_j[t] = radius[j]
                            if copy_rows:
                                row = table[type_id[i], type_id[j]]
                                for c in range(WIDTH):
                                    cols[c, t] = row[c]
                                if override:
                                    cols[k_col_i, t] = k_particle[i]
                                    cols[k_col_j, t] = k_particle[j]
                        for t in range(n):  # 2. conductances (vectorised where the model allows)
                            dist = math.sqrt(d2[t])
                            ri = r_i[t]
                            rj = r_j[t]
                            r_c = 0.0
                            if NEED_RC:
                                r_c = geometric_contact_radius(ri, rj, ri + rj - dist)
                            h[t] = range_sphere_term(
                                evaluator, model_id, cols[:, t], ri, rj, dist, r_c
                            )
                        for t in range(n):  # 3. scatter, in pair order
                            k = start + t
                            if store:
                                out_conductance[k] = h[t]
                            add_pair_heat(by_mechanism, column, conductance_sum, temperature,
                                          pair_i[k], pair_j[k], h[t])  # fmt: skip

    @parallel_kernel(error_model="numpy")
    def range_wall_pass(
        position, radius, temperature, type_id, wall_pair_w, wall_row_start, wall_kind,
        wall_rows, wall_material, evaluator, model_id, table, k_col_i, k_col_j, k_particle,
        k_wall, scratch, column, by_mechanism, conductance_sum, store, out_conductance, need_rc,
    ):  # fmt: skip
        """One pair term over the particle-wall pairs of the range set (``wall_row_start``:
        the wall pairs of each particle); adiabatic walls give nothing."""
        evaluator = EVALUATOR
        model_id = MODEL_ID
        if not OVERRIDE:
            k_col_i = -1
        n = radius.shape[0]
        nchunks = (n + WALL_CHUNK - 1) // WALL_CHUNK
        for c in prange(nchunks):
            srow = scratch[c]
            for i in range(c * WALL_CHUNK, min(n, (c + 1) * WALL_CHUNK)):
                for k in range(wall_row_start[i], wall_row_start[i + 1]):
                    w = wall_pair_w[k]
                    wrow = wall_rows[w]
                    h = 0.0
                    if wrow[COL_THERMAL_KIND] != 0.0:
                        d = wall_distance(wall_kind[w], wrow, position[i])[0]
                        ri = radius[i]
                        r_c = geometric_contact_radius(ri, math.inf, ri - d) if NEED_RC else 0.0
                        ki = kw = 0.0
                        if OVERRIDE and k_col_i >= 0:
                            ki = k_particle[i]
                            kw = k_wall[w]
                        p = _row(
                            table[type_id[i], wall_material[w]], k_col_i, k_col_j, ki, kw, srow
                        )
                        h = range_term(evaluator, model_id, p, ri, math.inf, d, r_c)
                    if store:
                        out_conductance[k] = h
                    if h != 0.0:
                        by_mechanism[column, i] += h * (wrow[COL_TEMPERATURE] - temperature[i])
                        conductance_sum[i] += h

    return range_pair_pass, range_wall_pass
