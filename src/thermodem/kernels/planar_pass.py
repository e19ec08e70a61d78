"""The planar particle pair pass of a 2D case (docs/two-dimensional.md, "Performance").

In a 2D case every particle lies in the plane z = 0 and turns about z only, so a pair's
normal, relative velocity, tangential spring and forces lie in the plane and its torques are
along z. :func:`planar_pair_pass` is the particle pair pass of :mod:`thermodem.kernels.pair_pass`
written for that: two-component geometry, the tangential spring as the in-plane vector
(sx, sy), one rotational degree of freedom (ω_z, the rolling torque and its history about z),
and it writes the x and y forces and the z torque only. It computes what the 3D pass computes
with the z components dropped: those are exact zeros there, so the two agree bit for bit up to
the sign of a zero (tested against the 3D pass in tests/unit/test_planar_pass.py).

It has the arguments of the 3D pass (the two are interchangeable), but its model choice is a
run-time argument: one compiled kernel (and its serial twin) serves every 2D case it covers
(:func:`covers`), where the 3D pass compiles one variant per model combination. It covers the
mechanics of discs (normal ``linear`` or ``hertz_2d``, tangential ``linear`` or ``none``,
every rolling law) without contact conduction or heat generation. A 2D case with a contact
conduction model or heat generation, or spheres in a plane with their 3D laws (``hertz``,
``mindlin``), runs the 3D pass compiled for its combination
(:func:`thermodem.kernels.pair_pass.passes_for`): with the conduction and the deposits as
run-time choices the pass took 10 s to compile (its serial twin; 16 s the parallel kernel)
against 4 s without them, more than the few 3D variants of 2D heat cases cost. The slab
groups, the list order and so the thread-count independence are those of the 3D pass.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from thermodem.kernels.contact import (
    H_DURATION,
    H_IMPACT_VELOCITY,
    L_ELASTIC_NORMAL,
    L_ELASTIC_ROLLING,
    L_ELASTIC_TANGENTIAL,
    L_MAX_OVERLAP_RATIO,
    L_NORMAL_DAMPING,
    L_ROLLING_FRICTION,
    L_SLIDING_FRICTION,
    L_STIFFNESS_WORK,
    L_TANGENTIAL_DAMPING,
    L_TOUCHING,
    STATE_FAR,
    STATE_NEAR,
    STATE_TOUCHING,
    clear_opened,
)
from thermodem.kernels.neighbors import minimum_image
from thermodem.kernels.variants import parallel_kernel
from thermodem.models.mechanics import normal as NL
from thermodem.models.mechanics import tangential as TL
from thermodem.models.mechanics.dispatch import rolling_dispatch
from thermodem.state import history as HL

#: The normal and tangential laws of the planar pass (every rolling law is).
NORMAL_LAWS = (NL.LINEAR, NL.HERTZ_2D)
TANGENTIAL_LAWS = (TL.NONE, TL.LINEAR)


# the laws inlined into the pass (a real call per contact costs a few ns: kernels/conduction.py)
_INLINE = {"inline": "always", "error_model": "numpy"}


@njit(**_INLINE)
def _spring_dashpot(k_t, gamma_t, mu, normal_force, vtx, vty, sx, sy, dt):
    """:func:`thermodem.models.mechanics.tangential._spring_dashpot_capped` in the plane (its
    z terms are exact zeros there, so this gives its bits): (F_t x, F_t y, s x, s y, damping
    energy, friction energy)."""
    v2 = vtx * vtx + vty * vty
    tx = sx + vtx * dt
    ty = sy + vty * dt
    fx = -k_t * tx - gamma_t * vtx
    fy = -k_t * ty - gamma_t * vty
    f_mag2 = fx * fx + fy * fy
    f_cap = mu * max(normal_force, 0.0)
    cap2 = f_cap * f_cap
    if f_mag2 <= cap2 and cap2 > TL._TINY_SQUARE:
        return fx, fy, tx, ty, gamma_t * v2 * dt, 0.0
    f_mag = math.sqrt(f_mag2) if f_mag2 > TL._TINY_SQUARE else math.hypot(fx, fy)
    if f_mag <= f_cap:
        return fx, fy, tx, ty, gamma_t * v2 * dt, 0.0
    lam = f_cap / f_mag if f_mag > 0.0 else 0.0
    scale = lam if k_t > 0.0 else 0.0
    if lam >= TL._SMALLEST_NORMAL:
        fx *= lam
        fy *= lam
        nx = scale * tx
        ny = scale * ty
    else:
        fx = fx / f_mag * f_cap
        fy = fy / f_mag * f_cap
        kept = f_cap if k_t > 0.0 else 0.0
        nx = tx / f_mag * kept
        ny = ty / f_mag * kept
    g = lam * gamma_t
    damping = g * (vtx * (nx - sx) + vty * (ny - sy))
    half_k = 0.5 * k_t
    friction = (g * vtx + half_k * (sx + nx)) * (tx - nx) + (g * vty + half_k * (sy + ny)) * (
        ty - ny
    )
    total = damping + friction
    damping = min(max(damping, 0.0), max(total, 0.0))
    return fx, fy, nx, ny, damping, total - damping


def covers(conducts: bool, generation: bool, mechanics: tuple[int, int, int]) -> bool:
    """Whether the planar pass serves a 2D case: no contact conduction compiled into its pass
    and no heat generation, and its normal and tangential laws among :data:`NORMAL_LAWS` and
    :data:`TANGENTIAL_LAWS` (the rest runs the 3D pass: the module docstring)."""
    laws = int(mechanics[0]) in NORMAL_LAWS and int(mechanics[1]) in TANGENTIAL_LAWS
    return laws and not conducts and not generation


@njit(cache=True, inline="always", error_model="numpy")
def _turn_spring(history, k, c0, nx, ny):
    """The in-plane spring history[k, c0:c0+2] turned normal to n, keeping its length
    (:func:`thermodem.kernels.contact._rotate_into_plane` with z = 0)."""
    ax = history[k, c0]
    ay = history[k, c0 + 1]
    old2 = ax * ax + ay * ay
    if old2 == 0.0:
        return 0.0, 0.0
    dot = ax * nx + ay * ny
    ax -= dot * nx
    ay -= dot * ny
    new2 = ax * ax + ay * ay
    if new2 > 0.0:
        s = math.sqrt(old2 / new2)
        return ax * s, ay * s
    return 0.0, 0.0


@njit(**_INLINE)
def _normal_law(normal_id, table, ti, tj, eff_mass):
    """(k, γ) of :func:`thermodem.models.mechanics.normal.hertz_2d_force` or
    :func:`~thermodem.models.mechanics.normal.linear_force` (the same expressions; tested bit
    for bit against the 3D pass, which calls them), read from the table itself: a row view
    ``table[ti, tj]`` per contact costs a reference count increment and decrement (two calls
    into the runtime; measured ~9 of 39 ns per pair)."""
    if normal_id == NL.HERTZ_2D:
        e_star = table[ti, tj, NL.HERTZ_2D_E_STAR]
        k = 0.25 * math.pi * e_star * table[ti, tj, NL.HERTZ_2D_THICKNESS]
        zeta = table[ti, tj, NL.HERTZ_2D_DAMPING_RATIO]
    else:
        k = table[ti, tj, NL.LINEAR_STIFFNESS]
        zeta = table[ti, tj, NL.LINEAR_DAMPING_RATIO]
    return k, 2.0 * zeta * math.sqrt(eff_mass * k)


@njit(cache=True, inline="always", error_model="numpy")
def planar_response(
    k, history, nx, ny, overlap, eff_radius, eff_mass, rolling_inertia, vrx, vry, wrz, dt,
    normal_id, normal_table, tangential_id, tangential_table, rolling_id, rolling_table, ti,
    tj, h_spring, h_roll, out_normal_force,
):  # fmt: skip
    """:func:`thermodem.kernels.contact.contact_response` of a contact in the plane: returns
    (F_n, F_t x, F_t y, rolling torque on i about z, the energies dissipated by normal
    damping, tangential damping, sliding and rolling friction [J], then the elastic energies
    (normal, tangential, rolling) and the stiffness work for the ledger, which the pass sums
    per group in registers); the laws of the planar pass keep no normal history and
    dissipate nothing plastically."""
    rate = vrx * nx + vry * ny
    k_ref, gamma_n = _normal_law(normal_id, normal_table, ti, tj, eff_mass)
    u_n = 0.5 * k_ref * overlap * overlap
    f_el = k_ref * overlap
    f_damp = gamma_n * rate
    f_n = f_el + f_damp
    vtx = vrx - rate * nx
    vty = vry - rate * ny
    ftx = fty = 0.0
    e_tdamp = e_slip = 0.0
    stiffness_work = 0.0
    u_t = 0.0
    if tangential_id == TL.LINEAR and h_spring >= 0:
        sx, sy = _turn_spring(history, k, h_spring, nx, ny)
        # TL.linear_tangential, its row read from the table (see _normal_law)
        ratio = tangential_table[ti, tj, TL.LINEAR_STIFFNESS_RATIO]
        k_t = ratio * k_ref
        gamma_t = gamma_n * math.sqrt(ratio)
        mu = tangential_table[ti, tj, TL.LINEAR_FRICTION]
        ftx, fty, sx, sy, e_tdamp, e_slip = _spring_dashpot(
            k_t, gamma_t, mu, f_n, vtx, vty, sx, sy, dt
        )
        old_s2 = history[k, h_spring] ** 2 + history[k, h_spring + 1] ** 2
        stiffness_work = 0.5 * k_t * old_s2 - history[k, h_spring + 3]
        u_t = 0.5 * k_t * (sx * sx + sy * sy)
        history[k, h_spring] = sx
        history[k, h_spring + 1] = sy
        history[k, h_spring + 3] = u_t
    if history[k, H_DURATION] == 0.0:
        history[k, H_IMPACT_VELOCITY] = rate
    history[k, H_DURATION] += dt
    tz = 0.0
    e_roll = 0.0
    u_r = 0.0
    if rolling_id != 0:
        mz = history[k, h_roll + 2] if h_roll >= 0 else 0.0
        if mz * mz == 0.0:  # (as _rotate_into_plane drops a torque whose square is 0)
            mz = 0.0
        _, _, tz, _, _, mz, k_r, e_roll = rolling_dispatch(
            rolling_id, rolling_table[ti, tj], k_ref, eff_radius, rolling_inertia, f_n, 0.0,
            0.0, wrz, 0.0, 0.0, mz, dt,
        )  # fmt: skip
        if h_roll >= 0:
            if k_r > 0.0:
                old_m2 = history[k, h_roll + 2] ** 2
                stiffness_work += 0.5 * old_m2 / k_r - history[k, h_roll + 3]
                u_r = 0.5 * (mz * mz) / k_r
            history[k, h_roll + 2] = mz
            history[k, h_roll + 3] = u_r
    e_ndamp = f_damp * rate * dt
    out_normal_force[k] = f_n
    return f_n, ftx, fty, tz, e_ndamp, e_tdamp, e_slip, e_roll, u_n, u_t, u_r, stiffness_work


@parallel_kernel(error_model="numpy")
def planar_pair_pass(
    position, velocity, angular_velocity, radius, mass, inertia, type_id, pair_i, pair_j,
    group_start, history, lower, upper, periodic, extra, dt, normal_id, normal_table,
    tangential_id, tangential_table, rolling_id, rolling_table, force, torque,
    out_normal_force, out_state, chunk_ledger, heat_on, temperature, radius_id, radius_table,
    conduction_id, conduction_table, override, k_particle, rhoc_particle, scratch,
    by_mechanism, conductance_sum, tolerance, layout, generation, gen_energy, gen_select,
    gen_partition,
):  # fmt: skip
    """Contact forces of every listed particle pair of a 2D case, added to the x and y
    columns of ``force`` and the z column of ``torque`` (the module docstring). The arguments
    are those of the 3D pass; the heat and heat generation ones are not read (:func:`covers`:
    the pass serves the steps without contact conduction and cases without heat generation).
    """
    h_spring = layout[HL.SPRING]
    h_roll = layout[HL.ROLL]
    length = upper - lower
    ngroups = group_start.shape[0] - 1
    for parity in range(2):
        for half in prange((ngroups + 1 - parity) // 2):
            g = 2 * half + parity
            row = chunk_ledger[g]
            for q in range(row.shape[0]):
                row[q] = 0.0
            # the group's ledger row, summed in pair order as the 3D pass sums into the row
            l_un = l_ut = l_ur = l_ndamp = l_tdamp = l_slip = l_roll = l_work = 0.0
            l_touch = l_ratio = 0.0
            for k in range(group_start[g], group_start[g + 1]):
                i = np.uint32(pair_i[k])  # (unsigned: no wraparound code per index)
                j = np.uint32(pair_j[k])
                dx = minimum_image(position[j, 0] - position[i, 0], length[0], periodic[0])
                dy = minimum_image(position[j, 1] - position[i, 1], length[1], periodic[1])
                dist = math.sqrt(dx * dx + dy * dy)
                ri = radius[i]
                rj = radius[j]
                overlap = ri + rj - dist
                if overlap <= 0.0 or dist == 0.0:
                    e_spring, e_rspring = clear_opened(
                        k, history, h_spring, h_roll, out_normal_force, out_state
                    )
                    l_slip += e_spring
                    l_roll += e_rspring
                    out_state[k] = STATE_NEAR if -overlap < extra else STATE_FAR
                    continue
                out_state[k] = STATE_TOUCHING
                nx = dx / dist
                ny = dy / dist
                wiz = angular_velocity[i, 2]
                wjz = angular_velocity[j, 2]
                sz = wiz * ri + wjz * rj  # (ω_i R_i + ω_j R_j) × n, in the plane
                vrx = velocity[i, 0] - velocity[j, 0] - sz * ny
                vry = velocity[i, 1] - velocity[j, 1] + sz * nx
                mi = mass[i]
                mj = mass[j]
                eff_radius = ri * rj / (ri + rj)
                eff_mass = mi * mj / (mi + mj)
                rolling_inertia = 0.0  # used by the rolling models only
                if rolling_id != 0:
                    ii = inertia[i] + mi * ri * ri
                    ij = inertia[j] + mj * rj * rj
                    rolling_inertia = ii * ij / (ii + ij)
                (f_n, ftx, fty, tz, e_ndamp, e_tdamp, e_slip, e_roll, u_n, u_t, u_r,
                 work) = planar_response(
                    k, history, nx, ny, overlap, eff_radius, eff_mass, rolling_inertia, vrx,
                    vry, wiz - wjz, dt, normal_id, normal_table, tangential_id,
                    tangential_table, rolling_id, rolling_table, np.uint32(type_id[i]),
                    np.uint32(type_id[j]), h_spring, h_roll, out_normal_force,
                )  # fmt: skip
                l_un += u_n
                l_ut += u_t
                l_ur += u_r
                l_ndamp += e_ndamp
                l_tdamp += e_tdamp
                l_slip += e_slip
                l_roll += e_roll
                l_work += work
                l_touch += 1.0
                # force on i: -F_n n + F_t; torque R n x F_t on both, rolling torque ±
                fx = -f_n * nx + ftx
                fy = -f_n * ny + fty
                lz = nx * fty - ny * ftx
                force[i, 0] += fx
                force[i, 1] += fy
                force[j, 0] -= fx
                force[j, 1] -= fy
                torque[i, 2] += ri * lz + tz
                torque[j, 2] += rj * lz - tz
                r_min = min(ri, rj)
                if overlap > l_ratio * r_min:  # (no division per contact)
                    l_ratio = overlap / r_min
            row[L_ELASTIC_NORMAL] = l_un
            row[L_ELASTIC_TANGENTIAL] = l_ut
            row[L_ELASTIC_ROLLING] = l_ur
            row[L_NORMAL_DAMPING] = l_ndamp
            row[L_TANGENTIAL_DAMPING] = l_tdamp
            row[L_SLIDING_FRICTION] = l_slip
            row[L_ROLLING_FRICTION] = l_roll
            row[L_STIFFNESS_WORK] = l_work
            row[L_TOUCHING] = l_touch
            row[L_MAX_OVERLAP_RATIO] = l_ratio
