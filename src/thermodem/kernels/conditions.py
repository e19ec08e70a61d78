"""Compiled passes of the thermal conditions (``engine/thermal_conditions.py``): fixed
temperatures and flux/volumetric sources per selection entry, and the weights of external
sources. Parallel over fixed chunks of particles whose partial sums are combined in chunk
order, so the results do not depend on the number of threads."""

from __future__ import annotations

import math

from numba import njit, prange

CHUNK = 4096  # particles per chunk of the condition passes

# kinds of entries of apply_conditions
FIXED = 0
FLUX = 1
VOLUMETRIC = 2


@njit(cache=True, parallel=True, error_model="numpy")
def apply_conditions(
    position, radius, mass, type_id, temperature, c_by_type, static_mask, kinds, values,
    has_region, boxes, fixed, source, part, disc_thickness,
):  # fmt: skip
    """Fixed temperatures and flux/volumetric sources of every entry, in entry order.

    A flux q heats a particle's surface, a power density s its volume: Q = q 4π R² and
    s 4/3 π R³ for spheres; for the discs of a 2D case (``disc_thickness`` b > 0) Q = q 2π R b
    (the disc's rim: a 2D model has no faces) and s π R² b.

    Entry e (``kinds[e]``: FIXED, FLUX or VOLUMETRIC, ``values[e]``: its temperature, flux or
    power density) holds for particle i when ``static_mask[i, e]`` and, if ``has_region[e]``,
    the particle is inside ``boxes[e]`` (lower 0:3, upper 3:6). A fixed particle gets its bath
    temperature (the last holding entry wins); ``part[c]`` collects per chunk the energy that
    this reset adds, m c (T_bath - T), with the constant specific heats ``c_by_type``.
    Rewrites ``fixed`` and ``source`` completely.
    """
    n = temperature.shape[0]
    nentries = kinds.shape[0]
    nchunks = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunks):
        reset = 0.0
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            is_fixed = False
            bath = 0.0
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
                    bath = values[e]
                elif kind == FLUX:
                    r = radius[i]
                    if disc_thickness > 0.0:
                        q += values[e] * 2.0 * math.pi * r * disc_thickness
                    else:
                        q += values[e] * 4.0 * math.pi * r * r
                else:
                    r = radius[i]
                    if disc_thickness > 0.0:
                        q += values[e] * math.pi * r * r * disc_thickness
                    else:
                        q += values[e] * 4.0 / 3.0 * math.pi * r * r * r
            fixed[i] = is_fixed
            source[i] = q
            if is_fixed:
                t_old = temperature[i]
                temperature[i] = bath
                reset += mass[i] * c_by_type[type_id[i]] * (bath - t_old)
        part[c] = reset
    total = 0.0
    for c in range(nchunks):
        total += part[c]
    return total


@njit(cache=True, parallel=True, error_model="numpy")
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


@njit(cache=True, parallel=True, error_model="numpy")
def add_weighted(source, weight, scale):
    """source += scale × weight."""
    for i in prange(source.shape[0]):
        if weight[i] != 0.0:
            source[i] += scale * weight[i]
