"""Per-particle passes: force reset and velocity Verlet integration.

Velocity Verlet (spheres, so rotation needs no orientation):
    v(t+dt/2) = v(t) + F(t) dt / 2m,   x(t+dt) = x(t) + v(t+dt/2) dt,
    v(t+dt)   = v(t+dt/2) + F(t+dt) dt / 2m,
and the same for ω with T / I. Contact forces at t+dt use x(t+dt) and the half-step velocities
(the usual choice for velocity-dependent forces in DEM).

``planar`` (a 2D case): the particles move in the plane z = 0 and turn about z only, so each
kick advances x, y and ω_z only and sets v_z = 0 and ω_x = ω_y = 0; the drift moves x and y
(z stays 0). The out-of-plane force and torque components are not read: with in-plane loads
they are exactly zero anyway (every normal, lever arm and velocity has z = 0; the planar pair
pass does not write them), and the constraint makes sure of it whatever the round-off.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from thermodem.kernels.variants import parallel_kernel

CHECK_CHUNK = 4096


@parallel_kernel(error_model="numpy")
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
    planar,
):
    """First half kick and drift; wraps positions on periodic axes (``planar``: x, y and ω_z
    only, see the module docstring).

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
            if planar:  # x, y and ω_z move; z, v_z, ω_x, ω_y stay 0 (F_z, T_x, T_y not read)
                velocity[i, 2] = 0.0
                angular_velocity[i, 0] = 0.0
                angular_velocity[i, 1] = 0.0
                angular_velocity[i, 2] += torque[i, 2] * inv_i
                for a in range(2):
                    velocity[i, a] += force[i, a] * inv_m
                    d, fault = _drift(position, velocity, i, a, dt, lower, upper, periodic,
                                      reference, bad < 0)  # fmt: skip
                    d2 += d
                    if fault != 0:
                        bad = i
                        code = fault
            else:
                for a in range(3):
                    velocity[i, a] += force[i, a] * inv_m
                    angular_velocity[i, a] += torque[i, a] * inv_i
                    d, fault = _drift(position, velocity, i, a, dt, lower, upper, periodic,
                                      reference, bad < 0)  # fmt: skip
                    d2 += d
                    if fault != 0:
                        bad = i
                        code = fault
            if d2 > best:
                best = d2
        chunk_check[c, 0] = best
        chunk_check[c, 1] = bad
        chunk_check[c, 2] = code


@njit(cache=True, inline="always", error_model="numpy")
def _drift(position, velocity, i, a, dt, lower, upper, periodic, reference, check):
    """Drift particle i along axis a (wrapped on a periodic axis): (the squared displacement
    along a since ``reference``, minimum image; with ``check``, 1 for a non-finite value, 2
    for a position outside the domain on a non-periodic axis, else 0)."""
    x = position[i, a] + velocity[i, a] * dt
    length = upper[a] - lower[a]
    if periodic[a]:
        x -= length * math.floor((x - lower[a]) / length)
    position[i, a] = x
    dx = x - reference[i, a]
    if periodic[a]:
        dx -= length * math.floor(dx / length + 0.5)
    fault = 0
    if check:
        if not (math.isfinite(x) and math.isfinite(velocity[i, a])):
            fault = 1
        elif not periodic[a] and (x < lower[a] or x > upper[a]):
            fault = 2
    return dx * dx, fault


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


@parallel_kernel(error_model="numpy")
def reset_forces(
    force,
    torque,
    mass,
    gravity,
    heat_on,
    by_mechanism,
    conductance_sum,
    external_force,
    external_torque,
):
    """Set each particle's force to its weight plus its constant external force and its
    torque to the external torque (none when ``external_force`` has no columns) before the
    pair passes add the contacts; with ``heat_on`` also zero the heat sums the passes and the
    thermal terms add to (every column of ``by_mechanism``, ``conductance_sum``)."""
    external = external_force.shape[1] == 3
    for i in prange(force.shape[0]):
        m = mass[i]
        if external:
            for a in range(3):
                force[i, a] = m * gravity[a] + external_force[i, a]
                torque[i, a] = external_torque[i, a]
        else:
            for a in range(3):
                force[i, a] = m * gravity[a]
                torque[i, a] = 0.0
        if heat_on:
            for c in range(by_mechanism.shape[0]):
                by_mechanism[c, i] = 0.0
            conductance_sum[i] = 0.0


@parallel_kernel(error_model="numpy")
def external_power(velocity, angular_velocity, external_force, external_torque, scratch):
    """Σ_i F_ext,i · v_i + T_ext,i · ω_i [W] (constant external loads), summed per chunk of
    CHECK_CHUNK particles in parallel (into column 0 of ``scratch``, the chunk check array of
    :func:`kick_drift` once :func:`reduce_checks` has read it) and over the chunks in a fixed
    order. Called with the half-step velocities right after :func:`kick_drift`, times Δt it is
    the work of the loads over the step's displacement and rotation."""
    n = velocity.shape[0]
    nchunks = (n + CHECK_CHUNK - 1) // CHECK_CHUNK
    for c in prange(nchunks):
        s = 0.0
        for i in range(c * CHECK_CHUNK, min(n, (c + 1) * CHECK_CHUNK)):
            for a in range(3):
                s += external_force[i, a] * velocity[i, a]
                s += external_torque[i, a] * angular_velocity[i, a]
        scratch[c, 0] = s
    total = 0.0
    for c in range(nchunks):
        total += scratch[c, 0]
    return total


@parallel_kernel(error_model="numpy")
def final_kick(velocity, angular_velocity, force, torque, mass, inertia, dt, planar):
    """Second half kick of velocity Verlet with the forces and torques at t + dt
    (``planar``: v_z and ω_x, ω_y kept at zero)."""
    half = 0.5 * dt
    for i in prange(force.shape[0]):
        inv_m = half / mass[i]
        inv_i = half / inertia[i]
        if planar:
            velocity[i, 0] += force[i, 0] * inv_m
            velocity[i, 1] += force[i, 1] * inv_m
            velocity[i, 2] = 0.0
            angular_velocity[i, 0] = 0.0
            angular_velocity[i, 1] = 0.0
            angular_velocity[i, 2] += torque[i, 2] * inv_i
            continue
        for a in range(3):
            velocity[i, a] += force[i, a] * inv_m
            angular_velocity[i, a] += torque[i, a] * inv_i


@njit(cache=True, error_model="numpy")
def sum_rows(table, count):
    """Column sums of the first ``count`` rows, in a fixed order."""
    out = np.zeros(table.shape[1])
    for r in range(count):
        for c in range(table.shape[1]):
            out[c] += table[r, c]
    return out


@njit(cache=True, error_model="numpy")
def ledger_totals(pair_table, pair_count, wall_table, wall_count, max_col, out):
    """The step's ledger: into ``out[:width]`` the column sums of the first ``pair_count``
    rows of ``pair_table`` plus those of the first ``wall_count`` rows of ``wall_table`` (in
    a fixed order), into ``out[width]`` the largest value of column ``max_col`` of both (the
    overlap ratio; 0 if none). One kernel call per step instead of four and no allocation."""
    width = pair_table.shape[1]
    best = 0.0
    for c in range(width):
        a = 0.0
        for r in range(pair_count):
            a += pair_table[r, c]
        b = 0.0
        for r in range(wall_count):
            b += wall_table[r, c]
        out[c] = a + b
    for r in range(pair_count):
        if pair_table[r, max_col] > best:
            best = pair_table[r, max_col]
    for r in range(wall_count):
        if wall_table[r, max_col] > best:
            best = wall_table[r, max_col]
    out[width] = best


@njit(cache=True, error_model="numpy")
def advance_walls(wall_rows, point_col, velocity_col, dt):
    """Move every wall's reference point by its velocity × dt (rows of geometry/wall_layout)."""
    for w in range(wall_rows.shape[0]):
        for a in range(3):
            wall_rows[w, point_col + a] += wall_rows[w, velocity_col + a] * dt


@njit(cache=True, error_model="numpy")
def max_wall_shift(wall_rows, point_col, reference):
    """Largest distance of a wall's reference point from its position at the last rebuild."""
    best = 0.0
    for w in range(wall_rows.shape[0]):
        d2 = 0.0
        for a in range(3):
            d = wall_rows[w, point_col + a] - reference[w, a]
            d2 += d * d
        best = max(best, d2)
    return np.sqrt(best)


@njit(cache=True, error_model="numpy")
def max_column(table, count, col):
    best = 0.0
    for r in range(count):
        if table[r, col] > best:
            best = table[r, col]
    return best
