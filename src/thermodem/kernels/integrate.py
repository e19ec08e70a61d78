"""Per-particle passes: reduction of pair outputs and velocity Verlet integration.

Velocity Verlet (spheres, so rotation needs no orientation):
    v(t+dt/2) = v(t) + F(t) dt / 2m,   x(t+dt) = x(t) + v(t+dt/2) dt,
    v(t+dt)   = v(t+dt/2) + F(t+dt) dt / 2m,
and the same for ω with T / I. Contact forces at t+dt use x(t+dt) and the half-step velocities
(the usual choice for velocity-dependent forces in DEM).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

CHECK_CHUNK = 4096


@njit(cache=True, parallel=True, error_model="numpy")
def kick_drift(
    position,
    velocity,
    angular_velocity,
    force,
    torque,
    mass,
    inertia,
    dt,
    lower,
    upper,
    periodic,
    reference,
    chunk_check,
):
    """First half kick and drift; wraps positions on periodic axes.

    In the same pass, per chunk of CHECK_CHUNK particles, ``chunk_check`` receives the largest
    squared displacement since ``reference`` (minimum image), and the first particle with a
    non-finite value (code 1) or outside the domain on a non-periodic axis (code 2).
    :func:`reduce_checks` combines the chunks in a fixed order.
    """
    n = position.shape[0]
    half = 0.5 * dt
    nchunks = (n + CHECK_CHUNK - 1) // CHECK_CHUNK
    for c in prange(nchunks):
        best = 0.0
        bad = -1
        code = 0
        for i in range(c * CHECK_CHUNK, min(n, (c + 1) * CHECK_CHUNK)):
            inv_m = half / mass[i]
            inv_i = half / inertia[i]
            d2 = 0.0
            for a in range(3):
                velocity[i, a] += force[i, a] * inv_m
                angular_velocity[i, a] += torque[i, a] * inv_i
                x = position[i, a] + velocity[i, a] * dt
                length = upper[a] - lower[a]
                if periodic[a]:
                    x -= length * math.floor((x - lower[a]) / length)
                position[i, a] = x
                dx = x - reference[i, a]
                if periodic[a]:
                    dx -= length * math.floor(dx / length + 0.5)
                d2 += dx * dx
                if bad < 0:
                    if not (math.isfinite(x) and math.isfinite(velocity[i, a])):
                        bad = i
                        code = 1
                    elif not periodic[a] and (x < lower[a] or x > upper[a]):
                        bad = i
                        code = 2
            if d2 > best:
                best = d2
        chunk_check[c, 0] = best
        chunk_check[c, 1] = bad
        chunk_check[c, 2] = code


@njit(cache=True, error_model="numpy")
def reduce_checks(chunk_check, n):
    """(largest displacement, first bad particle index or -1, its code) over all chunks."""
    nchunks = (n + CHECK_CHUNK - 1) // CHECK_CHUNK
    best = 0.0
    for c in range(nchunks):
        if chunk_check[c, 1] >= 0:
            return math.sqrt(best), int(chunk_check[c, 1]), int(chunk_check[c, 2])
        if chunk_check[c, 0] > best:
            best = chunk_check[c, 0]
    return math.sqrt(best), -1, 0


@njit(cache=True, parallel=True, error_model="numpy")
def reduce_and_kick(
    radius,
    mass,
    inertia,
    velocity,
    angular_velocity,
    force,
    torque,
    gravity,
    dt,
    row_start,
    entries,
    pair_force,
    pair_lever,
    pair_roll,
    wall_row_start,
    wall_force,
    wall_lever,
    wall_roll,
    kick,
    heat_on,
    pair_conductance,
    pair_heat,
    wall_conductance,
    wall_heat,
    by_mechanism,
    conductance_sum,
):
    """Sum each particle's pair and wall contributions in a fixed order, add gravity, and
    (if ``kick``) apply the second half kick.

    With ``heat_on`` the same traversal sums the pair heat rates (column 0 of
    ``by_mechanism``, direct conduction), the wall heat rates (column 6) and the conductances
    of each particle (``conductance_sum``, for the explicit Euler limit).
    """
    n = radius.shape[0]
    has_roll = pair_roll.shape[0] > 0
    has_wall_roll = wall_roll.shape[0] > 0
    half = 0.5 * dt
    for i in prange(n):
        ri = radius[i]
        fx = mass[i] * gravity[0]
        fy = mass[i] * gravity[1]
        fz = mass[i] * gravity[2]
        tx = 0.0
        ty = 0.0
        tz = 0.0
        q_direct = 0.0
        q_wall = 0.0
        h_sum = 0.0
        for q in range(row_start[i], row_start[i + 1]):
            # entry e >= 0: pair e with i as its first particle, else pair -e-1 with i second;
            # the sign is exact (±1), so a sum with it equals adding or subtracting
            e = entries[q]
            k = e
            sign = 1.0
            if e < 0:
                k = -e - 1
                sign = -1.0
            fx += sign * pair_force[k, 0]
            fy += sign * pair_force[k, 1]
            fz += sign * pair_force[k, 2]
            tx += ri * pair_lever[k, 0]
            ty += ri * pair_lever[k, 1]
            tz += ri * pair_lever[k, 2]
            if has_roll:
                tx += sign * pair_roll[k, 0]
                ty += sign * pair_roll[k, 1]
                tz += sign * pair_roll[k, 2]
            if heat_on:
                h_sum += pair_conductance[k]
                q_direct += sign * pair_heat[k]
        for k in range(wall_row_start[i], wall_row_start[i + 1]):
            if heat_on:
                h_sum += wall_conductance[k]
                q_wall += wall_heat[k]
            fx += wall_force[k, 0]
            fy += wall_force[k, 1]
            fz += wall_force[k, 2]
            tx += ri * wall_lever[k, 0]
            ty += ri * wall_lever[k, 1]
            tz += ri * wall_lever[k, 2]
            if has_wall_roll:
                tx += wall_roll[k, 0]
                ty += wall_roll[k, 1]
                tz += wall_roll[k, 2]
        if heat_on:
            by_mechanism[i, 0] = q_direct
            by_mechanism[i, 6] = q_wall
            conductance_sum[i] = h_sum
        force[i, 0] = fx
        force[i, 1] = fy
        force[i, 2] = fz
        torque[i, 0] = tx
        torque[i, 1] = ty
        torque[i, 2] = tz
        if kick:
            inv_m = half / mass[i]
            inv_i = half / inertia[i]
            velocity[i, 0] += fx * inv_m
            velocity[i, 1] += fy * inv_m
            velocity[i, 2] += fz * inv_m
            angular_velocity[i, 0] += tx * inv_i
            angular_velocity[i, 1] += ty * inv_i
            angular_velocity[i, 2] += tz * inv_i


@njit(cache=True, error_model="numpy")
def sum_rows(table, count):
    """Column sums of the first ``count`` rows, in a fixed order."""
    out = np.zeros(table.shape[1])
    for r in range(count):
        for c in range(table.shape[1]):
            out[c] += table[r, c]
    return out


@njit(cache=True, error_model="numpy")
def max_column(table, count, col):
    best = 0.0
    for r in range(count):
        if table[r, col] > best:
            best = table[r, col]
    return best
