"""Compiled passes of the thermal conditions (``engine/thermal_conditions.py``): fixed
temperatures and flux/volumetric sources per selection entry (a classification of every
particle at each neighbour-list build, then a per-step pass over the held and candidate
particles only), and the weights of external sources. The sums run over fixed chunks whose
partial sums are combined in chunk order, so the results do not depend on the number of
threads."""

from __future__ import annotations

import math

from numba import njit, prange

from thermodem.kernels.variants import parallel_kernel

CHUNK = 4096  # particles per chunk of the condition passes

# kinds of entries of apply_conditions
FIXED = 0
FLUX = 1
VOLUMETRIC = 2


# classes of a particle in classify_conditions
UNLISTED = 0  # nothing to do per step (not selected, or a source that cannot change)
CANDIDATE = 1  # near the face of a selection region: evaluated at every thermal step
HELD = 2  # fixed whatever it does until the next classification: its temperature is held


@njit(cache=True, inline="always")
def _source_rate(kind, value, r, disc_thickness):
    """Heat rate [W] of a flux q (FLUX) on a particle's surface, or a power density s
    (VOLUMETRIC) in its volume: q 4π R² and s 4/3 π R³ for spheres; for the discs of a 2D case
    (``disc_thickness`` b > 0) q 2π R b (the rim: a 2D model has no faces) and s π R² b."""
    if kind == FLUX:
        if disc_thickness > 0.0:
            return value * 2.0 * math.pi * r * disc_thickness
        return value * 4.0 * math.pi * r * r
    if disc_thickness > 0.0:
        return value * math.pi * r * r * disc_thickness
    return value * 4.0 / 3.0 * math.pi * r * r * r


@njit(cache=True, inline="always")
def _region_class(ref, b, margin, lower, upper, periodic, naxes):
    """0: a particle within ``margin`` of ``ref`` (per axis) is outside box ``b`` (lower 0:3,
    upper 3:6, faces included); 1: inside; 2: it may be either. On a periodic axis a particle
    whose margin interval crosses a face of the domain may wrap: it is 2 unless another axis
    keeps it out. ``naxes``: 3, or 2 in a 2D case (the particles stay at z = 0, which the
    boxes of a 2D case contain)."""
    out = False
    inside = True
    for a in range(naxes):
        lo = ref[a] - margin
        hi = ref[a] + margin
        if periodic[a] and (lo < lower[a] or hi >= upper[a]):
            inside = False
            continue
        if hi < b[a] or lo > b[3 + a]:
            out = True
        elif not (b[a] <= lo and hi <= b[3 + a]):
            inside = False
    if out:
        return 0
    return 1 if inside else 2


@parallel_kernel(error_model="numpy")
def classify_conditions(
    reference, radius, static_mask, kinds, values, has_region, boxes, margin, lower, upper,
    periodic, fixed, source, bath, code, disc_thickness, naxes,
):  # fmt: skip
    """Which particles the selections of fixed temperatures and flux/volumetric sources hold
    for until every particle has moved at most ``margin`` from ``reference`` (the positions of
    the last neighbour-list build: the list is rebuilt before any moves farther).

    Entry e (``kinds[e]``: FIXED, FLUX or VOLUMETRIC, ``values[e]``: its temperature, flux or
    power density) holds for particle i when ``static_mask[i, e]`` and, if ``has_region[e]``,
    the particle is inside ``boxes[e]`` (lower 0:3, upper 3:6, faces included). A particle
    that every region entry of its static selections keeps surely inside or surely outside
    gets its ``fixed``, ``bath`` (the last holding FIXED entry wins) and ``source`` here, and
    ``code`` HELD (fixed) or UNLISTED; one that some region may hold or not is a CANDIDATE,
    evaluated at every thermal step by :func:`apply_listed`. The source rates are those of
    :func:`_source_rate` (``disc_thickness`` > 0: discs of a 2D case, whose boxes are tested
    on ``naxes`` = 2 axes).
    """
    n = radius.shape[0]
    nentries = kinds.shape[0]
    for i in prange(n):
        candidate = False
        is_fixed = False
        t_bath = 0.0
        q = 0.0
        for e in range(nentries):
            if not static_mask[i, e]:
                continue
            if has_region[e]:
                where = _region_class(reference[i], boxes[e], margin, lower, upper, periodic, naxes)
                if where == 0:
                    continue
                if where == 2:
                    candidate = True
                    break
            kind = kinds[e]
            if kind == FIXED:
                is_fixed = True
                t_bath = values[e]
            else:
                q += _source_rate(kind, values[e], radius[i], disc_thickness)
        if candidate:
            code[i] = CANDIDATE
            fixed[i] = False
            source[i] = 0.0
            bath[i] = 0.0
        else:
            code[i] = HELD if is_fixed else UNLISTED
            fixed[i] = is_fixed
            source[i] = q
            bath[i] = t_bath


@parallel_kernel(error_model="numpy")
def apply_listed(
    listed, code, position, radius, mass, type_id, temperature, c_by_type, static_mask, kinds,
    values, has_region, boxes, fixed, source, bath, part, disc_thickness,
):  # fmt: skip
    """The per-step part of the conditions, over the listed particles only (``listed``: the
    indices whose ``code`` is HELD or CANDIDATE, ascending): a HELD particle takes its bath
    temperature; a CANDIDATE is evaluated against every entry at its current position (as
    in :func:`classify_conditions`, without the margin) and gets ``fixed``, ``source`` and,
    if fixed, its bath temperature. ``part[c]`` collects per chunk of CHUNK listed particles
    the energy the resets add, m c (T_bath - T), with the constant specific heats
    ``c_by_type``; returns their sum in chunk order (independent of the thread count).
    Source rates: :func:`_source_rate` (``disc_thickness`` > 0: the discs of a 2D case)."""
    n = listed.shape[0]
    nentries = kinds.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        reset = 0.0
        for k in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            i = listed[k]
            if code[i] == HELD:
                t_bath = bath[i]
            else:
                is_fixed = False
                t_bath = 0.0
                q = 0.0
                x = position[i, 0]
                y = position[i, 1]
                z = position[i, 2]
                for e in range(nentries):
                    if not static_mask[i, e]:
                        continue
                    if has_region[e]:
                        b = boxes[e]
                        if not (b[0] <= x <= b[3] and b[1] <= y <= b[4] and b[2] <= z <= b[5]):
                            continue
                    kind = kinds[e]
                    if kind == FIXED:
                        is_fixed = True
                        t_bath = values[e]
                    else:
                        q += _source_rate(kind, values[e], radius[i], disc_thickness)
                fixed[i] = is_fixed
                source[i] = q
                if not is_fixed:
                    continue
            t_old = temperature[i]
            temperature[i] = t_bath
            reset += mass[i] * c_by_type[type_id[i]] * (t_bath - t_old)
        part[c] = reset
    total = 0.0
    for c in range(nchunks):
        total += part[c]
    return total


@parallel_kernel(error_model="numpy")
def external_weights(position, radius, lower, upper, gaussian, centre, axis, sigma, weight, part):
    """Weights π R² (× exp(-r²/2σ²) for a Gaussian profile, r the distance from the line
    through ``centre`` along ``axis``) of the particles inside the box, 0 outside; returns
    their sum (chunk partial sums in ``part`` combined in order)."""
    n = radius.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        s = 0.0
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            inside = True
            for a in range(3):
                if not (lower[a] <= position[i, a] <= upper[a]):
                    inside = False
            w = 0.0
            if inside:
                w = math.pi * radius[i] * radius[i]
                if gaussian:
                    rx = position[i, 0] - centre[0]
                    ry = position[i, 1] - centre[1]
                    rz = position[i, 2] - centre[2]
                    dot = rx * axis[0] + ry * axis[1] + rz * axis[2]
                    rx -= dot * axis[0]
                    ry -= dot * axis[1]
                    rz -= dot * axis[2]
                    w *= math.exp(-(rx * rx + ry * ry + rz * rz) / (2.0 * sigma * sigma))
            weight[i] = w
            s += w
        part[c] = s
    total = 0.0
    for c in range(nchunks):
        total += part[c]
    return total


@parallel_kernel(error_model="numpy")
def add_weighted(source, weight, scale):
    """source += scale × weight."""
    for i in prange(source.shape[0]):
        if weight[i] != 0.0:
            source[i] += scale * weight[i]
