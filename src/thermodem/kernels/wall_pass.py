"""The wall pair pass: contact geometry and forces of every particle-wall pair, compiled per
mechanics combination, history layout and heat generation switch (:func:`wall_pass_for`;
the particle pair pass and the sign conventions: :mod:`thermodem.kernels.pair_pass`,
:mod:`thermodem.kernels.contact`).

It runs over fixed chunks of particles and their wall pairs (one ledger row per chunk), so
every particle receives its contributions in an order fixed by the list and the results do
not depend on the number of threads. The conduction from fixed-temperature walls is a pass
of its own after this one (:func:`thermodem.kernels.thermal.conduction_wall_pass_for`).
"""

from __future__ import annotations

from numba import prange

from thermodem.geometry.wall_layout import (
    COL_AXIS,
    COL_OMEGA,
    COL_POINT,
    COL_THERMAL_KIND,
    COL_VELOCITY,
)
from thermodem.kernels.contact import (
    H_DURATION,
    L_COLLISION,
    L_MAX_OVERLAP_RATIO,
    L_WALL_GENERATION,
    L_WALL_WORK,
    STATE_FAR,
    STATE_NEAR,
    STATE_TOUCHING,
    _open_contact,
    collision_loss,
    contact_response,
    deposit_wall,
    deposits,
    dissipates,
    kinetic_energy,
    prefetch_row,
)
from thermodem.kernels.neighbors import wall_distance
from thermodem.kernels.variants import parallel_kernel
from thermodem.state import history as HL
from thermodem.state.heat import G_COLLISION

WALL_CHUNK = 4096  # particles per chunk of the wall pass (one ledger row per chunk)
WALL_AHEAD = 16  # wall pairs ahead whose particle's generation accumulators are prefetched


_WALL_PASSES: dict[tuple, object] = {}


def wall_pass_for(generation: bool, layout: tuple[int, ...], mechanics: tuple[int, int, int]):  # noqa: ANN201
    """The wall pair pass for one mechanics combination (normal, tangential, rolling ids) and
    history layout, with (or without) the heat generation deposits compiled in: all three are
    compile-time constants (the generic pass with every law inlined took 6 s to compile)."""
    key = (bool(generation), tuple(int(c) for c in layout), tuple(int(m) for m in mechanics))
    if key not in _WALL_PASSES:
        _WALL_PASSES[key] = _compile_wall_pass(*key)
    return _WALL_PASSES[key]


def _compile_wall_pass(GENERATION: bool, LAYOUT: tuple[int, ...], MECHANICS: tuple[int, int, int]):  # noqa: ANN202, N803
    """Define the wall pair pass with the generation switch, the history layout and the
    mechanics model ids captured as constants."""
    NORMAL_ID, TANGENTIAL_ID, ROLLING_ID = MECHANICS  # noqa: N806
    H_NORMAL = LAYOUT[HL.NORMAL]  # noqa: N806
    H_SPRING = LAYOUT[HL.SPRING]  # noqa: N806
    H_ROLL = LAYOUT[HL.ROLL]  # noqa: N806
    H_COLLISION = LAYOUT[HL.COLLISION] if GENERATION else -1  # noqa: N806
    ROLLS, PLASTIC = dissipates(MECHANICS, LAYOUT)  # noqa: N806

    @parallel_kernel(error_model="numpy")
    def wall_pair_pass(
        position,
        velocity,
        angular_velocity,
        radius,
        mass,
        inertia,
        type_id,
        wall_pair_i,
        wall_pair_w,
        wall_row_start,
        history,
        wall_kind,
        wall_rows,
        wall_material,
        extra,
        dt,
        normal_id,
        normal_table,
        tangential_id,
        tangential_table,
        rolling_id,
        rolling_table,
        force,
        torque,
        out_normal_force,
        out_state,
        chunk_ledger,
        layout,
        generation,
        gen_energy,
        gen_select,
        gen_partition,
    ):
        """Contact forces of every listed particle-wall pair (wall = j, infinite radius and mass),
        added to ``force`` and ``torque`` after the particle pairs.

        Runs over chunks of WALL_CHUNK particles and their wall pairs (``wall_row_start``). The
        conduction from fixed-temperature walls is a pass of its own after this one
        (:func:`thermodem.kernels.thermal.conduction_wall_pass_for`, compiled per conduction
        model combination: the wall pairs are few). ``layout`` and the model ids: ignored,
        compile-time constants (:func:`wall_pass_for`). With ``generation`` the dissipated
        energies go to the particle's accumulators, its share ``gen_partition[type, wall
        material]`` of a wall with a fixed temperature (all of it at an adiabatic wall), the
        wall's share to the chunk's ledger row.
        """
        # the model choice and history layout as compile-time constants (see wall_pass_for)
        normal_id = NORMAL_ID
        tangential_id = TANGENTIAL_ID
        rolling_id = ROLLING_ID
        h_normal = H_NORMAL
        h_spring = H_SPRING
        h_roll = H_ROLL
        h_collision = H_COLLISION
        n = radius.shape[0]
        nchunks = (n + WALL_CHUNK - 1) // WALL_CHUNK
        use = deposits(gen_select, GENERATION, ROLLS, PLASTIC)  # (see contact.deposits)
        energy = gen_energy.reshape(gen_energy.size)  # (flat: see contact.NG)
        for c in prange(nchunks):
            row = chunk_ledger[c]
            for q in range(row.shape[0]):
                row[q] = 0.0
            first = wall_row_start[c * WALL_CHUNK]
            last = wall_row_start[min(n, (c + 1) * WALL_CHUNK)]
            for k in range(first, last):
                i = wall_pair_i[k]
                if GENERATION and use[7]:
                    # the accumulators of the particle WALL_AHEAD pairs on: the particles
                    # touching walls are scattered through the arrays, each row a cache miss
                    # (measured: 0.11 -> 0.05 ms of deposits per step for 3,500 wall pairs)
                    prefetch_row(energy, wall_pair_i[min(k + WALL_AHEAD, last - 1)])
                w = wall_pair_w[k]
                wrow = wall_rows[w]
                d, wnx, wny, wnz, qx, qy, qz = wall_distance(wall_kind[w], wrow, position[i])
                ri = radius[i]
                overlap = ri - d
                psi_f = psi_o = 1.0  # the particle's share (adiabatic wall: all of it)
                if GENERATION and wrow[COL_THERMAL_KIND] != 0.0:
                    psi_f = gen_partition[type_id[i], wall_material[w], 0]
                    psi_o = gen_partition[type_id[i], wall_material[w], 1]
                if overlap <= 0.0:
                    if GENERATION and h_collision >= 0 and history[k, H_DURATION] != 0.0:
                        lost = collision_loss(
                            history, k, h_collision,
                            kinetic_energy(velocity, angular_velocity, mass, inertia, i),
                        )  # fmt: skip
                        row[L_COLLISION] += lost
                        if gen_select[G_COLLISION] != 0.0:
                            gen_energy[i, G_COLLISION] += psi_o * lost
                            row[L_WALL_GENERATION + G_COLLISION] += lost - psi_o * lost
                    e_spring, e_rspring = _open_contact(
                        k, history, h_spring, h_roll, out_normal_force, out_state, row
                    )
                    if GENERATION and (e_spring != 0.0 or e_rspring != 0.0):
                        deposit_wall(
                            gen_energy, i, use, psi_f, psi_o, 0.0, 0.0, e_spring, e_rspring, 0.0,
                            row,
                        )  # fmt: skip
                    out_state[k] = STATE_NEAR if -overlap < extra else STATE_FAR
                else:
                    out_state[k] = STATE_TOUCHING
                    # n from the particle towards the wall
                    nx = -wnx
                    ny = -wny
                    nz = -wnz
                    # wall surface velocity at q: v_w + Ω a × (q - c)
                    om = wrow[COL_OMEGA]
                    ax = wrow[COL_AXIS] * om
                    ay = wrow[COL_AXIS + 1] * om
                    az = wrow[COL_AXIS + 2] * om
                    rx = qx - wrow[COL_POINT]
                    ry = qy - wrow[COL_POINT + 1]
                    rz = qz - wrow[COL_POINT + 2]
                    vwx = wrow[COL_VELOCITY] + ay * rz - az * ry
                    vwy = wrow[COL_VELOCITY + 1] + az * rx - ax * rz
                    vwz = wrow[COL_VELOCITY + 2] + ax * ry - ay * rx
                    wix = angular_velocity[i, 0]
                    wiy = angular_velocity[i, 1]
                    wiz = angular_velocity[i, 2]
                    vrx = velocity[i, 0] - vwx + (wiy * nz - wiz * ny) * ri
                    vry = velocity[i, 1] - vwy + (wiz * nx - wix * nz) * ri
                    vrz = velocity[i, 2] - vwz + (wix * ny - wiy * nx) * ri
                    ti = type_id[i]
                    tw = wall_material[w]
                    rolling_inertia = inertia[i] + mass[i] * ri * ri
                    if GENERATION and h_collision >= 0 and history[k, H_DURATION] == 0.0:
                        history[k, h_collision] = kinetic_energy(
                            velocity, angular_velocity, mass, inertia, i
                        )
                    out = contact_response(
                        k,
                        history,
                        nx,
                        ny,
                        nz,
                        overlap,
                        ri,
                        mass[i],
                        rolling_inertia,
                        vrx,
                        vry,
                        vrz,
                        wix - ax,
                        wiy - ay,
                        wiz - az,
                        dt,
                        normal_id,
                        normal_table[ti, tw],
                        tangential_id,
                        tangential_table[ti, tw],
                        rolling_id,
                        rolling_table[ti, tw],
                        h_normal,
                        h_spring,
                        h_roll,
                        out_normal_force,
                        row,
                    )
                    (f_n, ftx, fty, ftz, tx, ty, tz, e_ndamp, e_tdamp, e_slip, e_roll,
                     e_plastic) = out  # fmt: skip
                    if GENERATION and dt > 0.0:  # (none at the t = 0 evaluation)
                        deposit_wall(
                            gen_energy, i, use, psi_f, psi_o, e_ndamp, e_tdamp, e_slip, e_roll,
                            e_plastic, row,
                        )  # fmt: skip
                    # work done by the wall on the particle this step
                    fx = -f_n * nx + ftx
                    fy = -f_n * ny + fty
                    fz = -f_n * nz + ftz
                    force[i, 0] += fx
                    force[i, 1] += fy
                    force[i, 2] += fz
                    torque[i, 0] += ri * (ny * ftz - nz * fty) + tx
                    torque[i, 1] += ri * (nz * ftx - nx * ftz) + ty
                    torque[i, 2] += ri * (nx * fty - ny * ftx) + tz
                    row[L_WALL_WORK] += (
                        fx * vwx + fy * vwy + fz * vwz + tx * ax + ty * ay + tz * az
                    ) * dt
                    ratio = overlap / ri
                    if ratio > row[L_MAX_OVERLAP_RATIO]:
                        row[L_MAX_OVERLAP_RATIO] = ratio

    return wall_pair_pass
