"""The neighbourhood sums of the continuum radiation models, by a member list per particle.

Zhou et al. (2009) and Krause et al. (2017) (spec, "DEM Radiation Models") give each particle
i an environment made of the particles j whose centre lies in its sphere of radiative
influence, |x_j - x_i| < q R_i (q = ``radius_ratio``, 3 by default). Their fields
(``kernels/fields.py``: F_NEIGHBOURS, F_NEIGHBOUR_TEMPERATURE, F_NEIGHBOUR_EMISSION,
F_NEIGHBOUR_AREA) are sums over those j at every thermal step:

    n_p = Σ 1,   Σ T_j,   Σ ε_j A_j T_j⁴ / 2,   Σ ε_j A_j / 2.

Which particles are in a sphere hardly changes from one step to the next, so the candidates
are listed once per particle from the pairs of the neighbourhood range set
(``engine/range_set.py``), classified at the positions of the listing with a band b:

- members: d < q R_i - b, inside the sphere;
- border entries: |d - q R_i| <= b, near its surface: their distance is tested at every step;
- farther than q R_i + b: not listed.

While no particle has moved more than b/2 since the listing, no distance has changed by more
than b, so a member is still inside and an unlisted particle still outside: the sums over the
list, with the border entries tested at the current positions, are exactly the sums over the
sphere (``engine/fields.py`` lists again before that, and whenever the range set is rebuilt).
Rows are CSR (``offsets``; ``index`` the neighbour rows, each row its members, then from
``border[i]`` its border entries, each part sorted by neighbour index). Each particle sums
its own row in that order (the border entries with 0/1 weights): the sums do not depend on
the thread count; they depend on the listing (which entries are members), so the listing is
saved in checkpoints and a restart is bit-identical. The members' count and Σ ε_j A_j / 2 do
not change while the listing holds (:func:`member_constants`); at each step a row sums the
members' ε_j A_j T_j⁴ / 2 (krause2017) or T_j (zhou2009) from one compact array, and tests its
border entries. Against the pair pass over the range set it replaces (a distance per pair,
four read-modify-writes of the neighbours' sums), about a third of the time on the 50k bed
(1 thread, busy machine; ~14 listed neighbours per particle, ~7 % of them border entries
with b = a quarter of the range set's skin).

The border entries are classified in their turn (:func:`border_classes`, band b' = b / 4 in
``engine/neighbourhood_fields.py``): INSIDE (d < q R_i - b'), OUTSIDE (d > q R_i + b') or
TESTED; while no particle has moved more than b' / 2 since, only the TESTED ones (~a quarter)
need their distance at a step, and the sums add the INSIDE and TESTED entries with their
0/1 weights in one flat loop per chunk of rows (:func:`border_lists`), in the row order of
before: the classes change no bit of the sums (an OUTSIDE entry added 0). On the 50k bed this
and the members' branch-free remainder (:func:`_row_sum`) took the sums from ~1.3 to ~0.9 ms
per step (1 thread, the kernel alone; most of the border entries' cost was the mispredicted
end of each row's loop over its 0-3 entries, not the distances).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from thermodem.kernels.fields import (
    CHUNK,
    F_NEIGHBOUR_AREA,
    F_NEIGHBOUR_EMISSION,
    F_NEIGHBOUR_TEMPERATURE,
    F_NEIGHBOURS,
)
from thermodem.kernels.neighbors import minimum_image, pair_separation
from thermodem.kernels.variants import parallel_kernel

#: Kinds of a listed neighbour.
MEMBER = 0
BORDER = 1


@njit(cache=True, inline="always", error_model="numpy")
def _classify(d, limit, band):
    """0 member, 1 border, -1 not listed (d the centre distance, limit = q R_i)."""
    if d < limit - band:
        return MEMBER
    if d <= limit + band:
        return BORDER
    return -1


@njit(cache=True, error_model="numpy")
def member_counts(position, radius, pair_i, pair_j, count, lower, upper, periodic, ratio, band,
                  counts):  # fmt: skip
    """counts[i] = the listed neighbours of particle i (members and border entries) among the
    first ``count`` pairs of a range set."""
    length = upper - lower
    counts[:] = 0
    for k in range(count):
        i = pair_i[k]
        j = pair_j[k]
        d = pair_separation(position, i, j, length, periodic)[3]
        if _classify(d, ratio * radius[i], band) >= 0:
            counts[i] += 1
        if _classify(d, ratio * radius[j], band) >= 0:
            counts[j] += 1


@njit(cache=True, error_model="numpy")
def member_fill(position, radius, pair_i, pair_j, count, lower, upper, periodic, ratio, band,
                offsets, border, index):  # fmt: skip
    """Fill the rows (``offsets`` from :func:`member_counts`): each row holds its members,
    then from ``border[i]`` on its border entries, each part sorted by neighbour index."""
    length = upper - lower
    n = offsets.shape[0] - 1
    members = np.zeros(n, np.int64)
    for k in range(count):
        i = pair_i[k]
        j = pair_j[k]
        d = pair_separation(position, i, j, length, periodic)[3]
        if _classify(d, ratio * radius[i], band) == MEMBER:
            members[i] += 1
        if _classify(d, ratio * radius[j], band) == MEMBER:
            members[j] += 1
    fill = offsets[:n].copy()
    for a in range(n):
        border[a] = offsets[a] + members[a]
    fill_border = border.copy()
    for k in range(count):
        i = pair_i[k]
        j = pair_j[k]
        d = pair_separation(position, i, j, length, periodic)[3]
        for side in range(2):
            a = i if side == 0 else j
            b = j if side == 0 else i
            c = _classify(d, ratio * radius[a], band)
            if c == MEMBER:
                index[fill[a]] = b
                fill[a] += 1
            elif c == BORDER:
                index[fill_border[a]] = b
                fill_border[a] += 1
    _sort_rows(offsets, border, index)


@njit(cache=True, inline="always", error_model="numpy")
def _insertion_sort(index, lo, hi):
    for e in range(lo + 1, hi):
        v = index[e]
        f = e - 1
        while f >= lo and index[f] > v:
            index[f + 1] = index[f]
            f -= 1
        index[f + 1] = v


# a parallel kernel called from the serial member_fill: no serial twin (kernels/variants.py)
@njit(cache=True, parallel=True, error_model="numpy")
def _sort_rows(offsets, border, index):
    """The members and the border entries of each row by neighbour index (rows of ~15)."""
    n = offsets.shape[0] - 1
    for c in prange((n + CHUNK - 1) // CHUNK):
        for a in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            _insertion_sort(index, offsets[a], border[a])
            _insertion_sort(index, border[a], offsets[a + 1])


#: What :func:`neighbourhood_sums` computes (bits of its ``mode``).
NB_KRAUSE = 1  # Σ ε_j A_j T_j⁴ / 2 and Σ ε_j A_j / 2 (krause2017)
NB_ZHOU = 2  # n_p and Σ T_j (zhou2009)


@parallel_kernel(error_model="numpy")
def neighbourhood_weights(radius, temperature, type_id, emissivity, area, emission):
    """Per particle: area[i] = ε_i A_i / 2 and emission[i] = ε_i A_i T_i⁴ / 2, what it adds
    to the sums of the spheres it lies in (krause2017)."""
    n = radius.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            t = temperature[i]
            w = 2.0 * math.pi * radius[i] * radius[i] * emissivity[type_id[i]]
            area[i] = w
            emission[i] = w * (t * t) * (t * t)


@parallel_kernel(error_model="numpy")
def neighbourhood_emission(area, temperature, emission):
    """emission[i] = area[i] T_i⁴ with ``area`` from :func:`neighbourhood_weights` (the same
    bits as it gives: the area holds while the listing does, only T changes)."""
    n = area.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        # over slices indexed from 0 (no negative-index wrap-around on the index): LLVM
        # vectorises this loop (the kernel alone ~0.07 -> ~0.015 ms on the 50k bed)
        a = area[lo:hi]
        t_p = temperature[lo:hi]
        out = emission[lo:hi]
        for k in range(hi - lo):
            t = t_p[k]
            out[k] = a[k] * (t * t) * (t * t)


@parallel_kernel(error_model="numpy")
def member_constants(offsets, border, index, area, member_area, member_count):
    """The parts of the sums that do not change while the listing holds: Σ ε_j A_j / 2 and
    the count over each row's members (in row order: the same numbers as summing them at
    every step)."""
    n = offsets.shape[0] - 1
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            s = 0.0
            for e in range(offsets[i], border[i]):
                s += area[index[e]]
            member_area[i] = s
            member_count[i] = float(border[i] - offsets[i])


@njit(cache=True, inline="always", error_model="numpy")
def _row_sum(values, index, first, last):
    """Σ values[index[e]] for e in [first, last), in four interleaved partial sums (entries
    e ≡ 0, 1, 2, 3 mod 4 from ``first``, added up as (a + b) + (c + d)): four independent
    addition chains instead of one, so the gathers overlap (a fixed order: the same bits for
    any thread count). The last 0-3 entries are added with 0/1 weights (the clamped index
    stays in the row, x + 0 = x): no branch on the row's length, whose outcome changes from
    row to row (~0.3 of ~0.9 ms on the 50k bed's members, 1 thread). Both indexings are
    unsigned (:func:`_at`): with signed ones Numba adds a negative-index wrap-around to each
    load, and with it the rows' sums took ~0.66 instead of ~0.16 ms (the members alone)."""
    if last <= first:
        return 0.0
    a = 0.0
    b = 0.0
    c = 0.0
    d = 0.0
    e = first
    while e + 4 <= last:
        a += _at(values, index, e)
        b += _at(values, index, e + 1)
        c += _at(values, index, e + 2)
        d += _at(values, index, e + 3)
        e += 4
    rest = last - e
    top = last - 1
    a += (1.0 if rest > 0 else 0.0) * _at(values, index, min(e, top))
    b += (1.0 if rest > 1 else 0.0) * _at(values, index, min(e + 1, top))
    c += (1.0 if rest > 2 else 0.0) * _at(values, index, min(e + 2, top))
    return (a + b) + (c + d)


@njit(cache=True, inline="always", error_model="numpy")
def _at(values, index, e):
    """values[index[e]] with both indices unsigned (e >= 0 and the listed rows are): no
    wrap-around test of a negative index on either load."""
    return values[np.uint32(index[np.uint64(e)])]


#: Classes of a border entry in ``weight`` (:func:`border_classes`).
OUTSIDE = 0
INSIDE = 1
TESTED = 2


@parallel_kernel(error_model="numpy")
def border_classes(position, radius, offsets, border, index, lower, upper, periodic, ratio,
                   band, weight):  # fmt: skip
    """weight[e] of every border entry at the current positions: INSIDE (d < q R_i - band),
    OUTSIDE (d > q R_i + band) or TESTED (in between). While no particle moves more than
    band / 2 these classes hold and only the TESTED entries need their distance."""
    length = upper - lower
    n = offsets.shape[0] - 1
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            limit = ratio * radius[i]
            for e in range(border[i], offsets[i + 1]):
                d = pair_separation(position, i, index[e], length, periodic)[3]
                if d < limit - band:
                    weight[e] = INSIDE
                elif d > limit + band:
                    weight[e] = OUTSIDE
                else:
                    weight[e] = TESTED


@njit(cache=True, error_model="numpy")
def border_lists(offsets, border, weight, rows, entries, starts, tested_rows, tested_entries):
    """From the classes of :func:`border_classes`: the border entries that can add to a sum
    (INSIDE or TESTED; an OUTSIDE one adds 0) as (row, entry) in row order into ``rows`` and
    ``entries``, ``starts[c]`` the first of them in the chunk of rows c (CHUNK rows; one
    more value at the end), and the TESTED ones into ``tested_rows`` and ``tested_entries``
    (each array at least as long as the border entries). Returns (listed, tested)."""
    n = offsets.shape[0] - 1
    k = 0
    t = 0
    for i in range(n):
        if i % CHUNK == 0:
            starts[i // CHUNK] = k
        for e in range(border[i], offsets[i + 1]):
            w = weight[e]
            if w != OUTSIDE:
                rows[k] = i
                entries[k] = e
                k += 1
            if w == TESTED:
                tested_rows[t] = i
                tested_entries[t] = e
                t += 1
    starts[(n + CHUNK - 1) // CHUNK] = k
    return k, t


@parallel_kernel(error_model="numpy")
def neighbourhood_sums(position, radius, temperature, offsets, border, index, weight, rows,
                       entries, starts, tested_rows, tested_entries, tested, area, emission,
                       member_area, member_count, lower, upper, periodic, ratio, mode,
                       fields):  # fmt: skip
    """fields[F_NEIGHBOURS .. F_NEIGHBOUR_AREA, i] = (n_p, Σ T_j, Σ ε_j A_j T_j⁴ / 2,
    Σ ε_j A_j / 2) over the particles j inside q R_i: the members of row i (their count and
    area from :func:`member_constants`), then its border entries in row order with their
    0/1 weights ``weight`` (the listed ones of :func:`border_lists`: an OUTSIDE entry adds
    0). First the weights of the ``tested`` TESTED entries from the current distances;
    then the members' sums of every row; then the listed border entries in one flat loop
    per chunk of rows (no branch on a row's number of border entries, whose outcome changes
    from row to row). ``mode``: NB_KRAUSE and/or NB_ZHOU; the rows of the other are not
    written (they stay 0)."""
    length = upper - lower
    q2 = ratio * ratio
    krause = (mode & NB_KRAUSE) != 0
    zhou = (mode & NB_ZHOU) != 0
    for c in prange((tested + CHUNK - 1) // CHUNK):
        for k in range(c * CHUNK, min(tested, (c + 1) * CHUNK)):
            i = np.uint64(tested_rows[k])
            e = np.uint64(tested_entries[k])
            j = np.uint32(index[e])
            dx = minimum_image(position[j, 0] - position[i, 0], length[0], periodic[0])
            dy = minimum_image(position[j, 1] - position[i, 1], length[1], periodic[1])
            dz = minimum_image(position[j, 2] - position[i, 2], length[2], periodic[2])
            inside = dx * dx + dy * dy + dz * dz < q2 * radius[i] * radius[i]
            weight[e] = INSIDE if inside else OUTSIDE
    n = offsets.shape[0] - 1
    for c in prange((n + CHUNK - 1) // CHUNK):
        # each row's members over slices of the chunk (indexed from 0), then the border
        # entries; the rows are independent, so the order of the two models' loops does
        # not matter
        lo = c * CHUNK
        hi = min(n, lo + CHUNK)
        first = offsets[lo:hi]
        last = border[lo:hi]
        if zhou:
            counts = fields[F_NEIGHBOURS, lo:hi]
            t_sums = fields[F_NEIGHBOUR_TEMPERATURE, lo:hi]
            m_counts = member_count[lo:hi]
            for t in range(hi - lo):
                counts[t] = m_counts[t]
                t_sums[t] = _row_sum(temperature, index, first[t], last[t])
        if krause:
            e_sums = fields[F_NEIGHBOUR_EMISSION, lo:hi]
            a_sums = fields[F_NEIGHBOUR_AREA, lo:hi]
            m_areas = member_area[lo:hi]
            for t in range(hi - lo):
                e_sums[t] = _row_sum(emission, index, first[t], last[t])
                a_sums[t] = m_areas[t]
        for k in range(starts[c], starts[c + 1]):
            i = np.uint64(rows[k])
            e = np.uint64(entries[k])
            j = np.uint32(index[e])
            m = float(weight[e])
            if zhou:
                fields[F_NEIGHBOURS, i] += m
                fields[F_NEIGHBOUR_TEMPERATURE, i] += m * temperature[j]
            if krause:
                fields[F_NEIGHBOUR_EMISSION, i] += m * emission[j]
                fields[F_NEIGHBOUR_AREA, i] += m * area[j]


def empty_members(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(offsets, border, index) of a list with no neighbours for n particles."""
    return np.zeros(n + 1, np.int64), np.zeros(n, np.int64), np.zeros(0, np.int32)
