"""The pair pass: contact geometry and forces, each pair computed once.

:func:`particle_pair_pass` and the wall pair pass (:mod:`thermodem.kernels.wall_pass`)
compute, for every listed particle pair and particle-wall pair, the geometry (distance, unit
normal, overlap, relative velocity at the contact point), the contact response of
:mod:`thermodem.kernels.contact` and, when heat is due, the conduction of the pair.

The particle pass runs over the slab groups of the list (:mod:`thermodem.kernels.slabs`): the
even groups in parallel, then the odd ones. Each pair adds its force and torque (and, when
heat is due, its heat rate and conductance) straight into the arrays of its two particles,
which no other group of the same parity touches, and writes its own per-pair rows
(normal force, state; with heat generation the dissipated energy per mechanism goes into the
two particles' accumulators); each group writes its own ledger row.
The wall pass runs over fixed chunks of particles and their wall pairs. Nothing is accumulated
with atomics and every particle receives its contributions in an order fixed by the list, so
the results do not depend on the number of threads.

Sign conventions: see :mod:`thermodem.kernels.contact`.
"""

from __future__ import annotations

from numba import prange

from thermodem.kernels import planar_pass
from thermodem.kernels.contact import (
    H_DURATION,
    L_COLLISION,
    L_MAX_OVERLAP_RATIO,
    NG,
    STATE_FAR,
    STATE_NEAR,
    STATE_TOUCHING,
    _open_contact,
    collision_loss,
    contact_response,
    deposit_pair,
    deposit_particle,
    deposits,
    dissipates,
    kinetic_energy,
)
from thermodem.kernels.contact_conduction import _pp_conductance, reusable
from thermodem.kernels.neighbors import pair_separation
from thermodem.kernels.variants import parallel_kernel
from thermodem.kernels.wall_pass import WALL_CHUNK, wall_pass_for  # noqa: F401 (WALL_CHUNK: re-exported)
from thermodem.state import history as HL
from thermodem.state.heat import G_COLLISION, M_DIRECT

_PASSES: dict[tuple, tuple] = {}


def passes_for(
    heat_on: bool,
    radius_id: int,
    conduction_id: int,
    override: int,
    layout: tuple[int, ...],
    generation: bool,
    mechanics: tuple[int, int, int],
    planar: bool = False,
) -> tuple:
    """(particle pair pass, wall pair pass) for one model combination and history layout.

    ``planar`` (a 2D case): the particle pair pass is the planar pass
    (:func:`thermodem.kernels.planar_pass.planar_pair_pass`, one kernel whose model choice is
    run-time) where it covers the case (:func:`thermodem.kernels.planar_pass.covers`: the
    disc laws, no contact conduction, no heat generation), else the 3D pass below.

    The heat switch, the contact radius and direct conduction model ids, the k(T)/ρc(T)
    override, the history offsets ``layout`` (``HistoryLayout.offsets``: normal, spring,
    roll, collision, reuse; -1 for an absent block; state/history.py), the heat generation
    switch and the ``mechanics`` model ids (normal, tangential, rolling) are compile-time
    constants of the particle pair pass, so the compiler drops the code of every other model,
    of absent history blocks and, without heat generation, of the deposits into the
    generation accumulators: the generic loop with the model switches inside costs the
    simple conduction models ~20 ns per particle more (docs/architecture.md, "Cost of the
    generic model switch"), and with every mechanics law inlined the pass took 12 s to
    compile instead of 6 s. Its arguments keep their order and types; the model, layout and
    generation arguments passed in are ignored (the heat switch passed in is honoured by the
    pass compiled with heat). Each combination in use compiles once
    (~6 s on a 2-core machine) and is then cached on disk (Numba keys closures on their
    constants) and in this process. The wall pass is compiled per mechanics combination,
    history layout and generation switch (:func:`wall_pass_for`); the conduction from walls
    follows it in a small pass compiled per conduction model combination
    (:func:`thermodem.kernels.thermal.conduction_wall_pass_for`): the generic wall pass with
    every conduction model inlined took 16 s of a 40 s cold start.
    """
    key = (bool(heat_on), int(radius_id), int(conduction_id), int(override))
    if not key[0]:
        key = (False, 0, 0, 0)
    layout = tuple(int(c) for c in layout)
    mechanics = tuple(int(m) for m in mechanics)
    key = (*key, layout, bool(generation), mechanics)
    flat = bool(planar) and planar_pass.covers(key[0], bool(generation), mechanics)
    if (flat, key) not in _PASSES:
        _PASSES[flat, key] = (
            planar_pass.planar_pair_pass if flat else _compile_pair_pass(*key),
            wall_pass_for(bool(generation), layout, mechanics),
        )
    return _PASSES[flat, key]


def _compile_pair_pass(HEAT_ON: bool, RADIUS_ID: int, CONDUCTION_ID: int, OVERRIDE: int,  # noqa: N803
                       LAYOUT: tuple[int, ...], GENERATION: bool,  # noqa: N803
                       MECHANICS: tuple[int, int, int]):  # noqa: ANN202, N803  # fmt: skip
    """Define the particle pair pass with the model choice captured as constants."""
    NORMAL_ID, TANGENTIAL_ID, ROLLING_ID = MECHANICS  # noqa: N806
    REUSABLE = reusable(CONDUCTION_ID)  # noqa: N806
    H_NORMAL = LAYOUT[HL.NORMAL]  # noqa: N806
    H_SPRING = LAYOUT[HL.SPRING]  # noqa: N806
    H_ROLL = LAYOUT[HL.ROLL]  # noqa: N806
    H_COLLISION = LAYOUT[HL.COLLISION] if GENERATION else -1  # noqa: N806
    H_REUSE = LAYOUT[HL.REUSE]  # noqa: N806
    REUSABLE = REUSABLE and H_REUSE >= 0  # noqa: N806
    ROLLS, PLASTIC = dissipates(MECHANICS, LAYOUT)  # noqa: N806

    @parallel_kernel(error_model="numpy")
    def particle_pair_pass(
        position,
        velocity,
        angular_velocity,
        radius,
        mass,
        inertia,
        type_id,
        pair_i,
        pair_j,
        group_start,
        history,
        lower,
        upper,
        periodic,
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
        heat_on,
        temperature,
        radius_id,
        radius_table,
        conduction_id,
        conduction_table,
        override,
        k_particle,
        rhoc_particle,
        scratch,
        by_mechanism,
        conductance_sum,
        tolerance,
        layout,
        generation,
        gen_energy,
        gen_select,
        gen_partition,
    ):
        """Contact forces of every listed particle pair, added to ``force`` and ``torque``
        (see module docstring; the caller sets them to their non-contact values first).

        With heat generation (the ``generation`` constant of :func:`passes_for`) each contact
        adds the energy it dissipates in this step, per mechanism selected by
        ``gen_select``, to the accumulators ``gen_energy`` of its two particles, shared by
        ``gen_partition[type_i, type_j]`` (i's share of friction and other heat), and a
        collision that ends adds the kinetic energy the pair lost (with a collision block).

        With ``heat_on`` (an argument: the pass compiled with heat serves the steps without
        heat too, with the arguments ``Simulation._no_heat``; one compiled variant less, 6 s
        of a cold start; compiled without heat, the code is dropped) the same pass evaluates
        the conduction of every touching pair (see
        :func:`thermodem.kernels.conduction.pair_conductance`) with the temperatures of this
        moment, and adds the heat rate to the direct-conduction column of ``by_mechanism`` and
        the conductance to ``conductance_sum`` of both particles (the caller zeroes them first).
        """
        # the model choice as compile-time constants (see passes_for)
        radius_id = RADIUS_ID
        conduction_id = CONDUCTION_ID
        override = OVERRIDE
        normal_id = NORMAL_ID
        tangential_id = TANGENTIAL_ID
        rolling_id = ROLLING_ID
        if not REUSABLE:
            tolerance = 0.0  # (the reuse's code is dropped)
        length = upper - lower
        ngroups = group_start.shape[0] - 1
        use = deposits(gen_select, GENERATION, ROLLS, PLASTIC)  # (see contact.deposits)
        energy = gen_energy.reshape(gen_energy.size)  # (flat: see contact.NG)
        # the partition table (types, types, 2) flat too, a row of type i's pairs 2 ntypes wide
        # (measured: ~0.1-0.2 ms of the drum's 0.65 ms of deposits per step against the 3-D index)
        shares = gen_partition.reshape(gen_partition.size)
        shares_row = 2 * gen_partition.shape[1]
        for parity in range(2):
            for half in prange((ngroups + 1 - parity) // 2):
                g = 2 * half + parity
                srow = scratch[g] if HEAT_ON and heat_on else scratch[0]  # (one row if no heat)
                row = chunk_ledger[g]
                for q in range(row.shape[0]):
                    row[q] = 0.0
                # heat generation: i's shares summed over its run of pairs (the list holds
                # each i's pairs together) and added when i changes, j's share at once
                owner = -1
                a_ndamp = a_tdamp = a_slip = a_roll = a_plastic = 0.0
                for k in range(group_start[g], group_start[g + 1]):
                    i = pair_i[k]
                    j = pair_j[k]
                    if GENERATION and i != owner:
                        if owner >= 0:
                            deposit_particle(energy, owner * NG, use, a_ndamp, a_tdamp, a_slip,
                                             a_roll, a_plastic)  # fmt: skip
                        owner = i
                        a_ndamp = a_tdamp = a_slip = a_roll = a_plastic = 0.0
                    dx, dy, dz, dist = pair_separation(position, i, j, length, periodic)
                    ri = radius[i]
                    rj = radius[j]
                    overlap = ri + rj - dist
                    eff_mass = 0.0
                    if overlap <= 0.0 or dist == 0.0:
                        if GENERATION and H_COLLISION >= 0 and history[k, H_DURATION] != 0.0:
                            # a collision ends: the kinetic energy the pair lost
                            lost = collision_loss(
                                history, k, H_COLLISION,
                                kinetic_energy(velocity, angular_velocity, mass, inertia, i)
                                + kinetic_energy(velocity, angular_velocity, mass, inertia, j),
                            )  # fmt: skip
                            row[L_COLLISION] += lost
                            if gen_select[G_COLLISION] != 0.0:
                                share = gen_partition[type_id[i], type_id[j], 1] * lost
                                gen_energy[i, G_COLLISION] += share
                                gen_energy[j, G_COLLISION] += lost - share
                        e_spring, e_rspring = _open_contact(
                            k, history, H_SPRING, H_ROLL, out_normal_force, out_state, row
                        )
                        if GENERATION and (e_spring != 0.0 or e_rspring != 0.0):
                            at = type_id[i] * shares_row + 2 * type_id[j]
                            deposit_pair(
                                energy, i, j, use, shares[at], shares[at + 1], 0.0, 0.0,
                                e_spring, e_rspring, 0.0,
                            )  # fmt: skip
                        out_state[k] = STATE_NEAR if -overlap < extra else STATE_FAR
                    else:
                        out_state[k] = STATE_TOUCHING
                        nx = dx / dist
                        ny = dy / dist
                        nz = dz / dist
                        wix = angular_velocity[i, 0]
                        wiy = angular_velocity[i, 1]
                        wiz = angular_velocity[i, 2]
                        wjx = angular_velocity[j, 0]
                        wjy = angular_velocity[j, 1]
                        wjz = angular_velocity[j, 2]
                        # (ω_i R_i + ω_j R_j) × n
                        sx = wix * ri + wjx * rj
                        sy = wiy * ri + wjy * rj
                        sz = wiz * ri + wjz * rj
                        vrx = velocity[i, 0] - velocity[j, 0] + sy * nz - sz * ny
                        vry = velocity[i, 1] - velocity[j, 1] + sz * nx - sx * nz
                        vrz = velocity[i, 2] - velocity[j, 2] + sx * ny - sy * nx
                        eff_radius = ri * rj / (ri + rj)
                        eff_mass = mass[i] * mass[j] / (mass[i] + mass[j])
                        rolling_inertia = 0.0  # used by the rolling models only
                        if rolling_id != 0:
                            ii = inertia[i] + mass[i] * ri * ri
                            ij = inertia[j] + mass[j] * rj * rj
                            rolling_inertia = ii * ij / (ii + ij)
                        ti = type_id[i]
                        tj = type_id[j]
                        if GENERATION and H_COLLISION >= 0 and history[k, H_DURATION] == 0.0:
                            # a collision starts: the pair's kinetic energy now
                            history[k, H_COLLISION] = kinetic_energy(
                                velocity, angular_velocity, mass, inertia, i
                            ) + kinetic_energy(velocity, angular_velocity, mass, inertia, j)
                        (
                            f_n,
                            ftx,
                            fty,
                            ftz,
                            tx,
                            ty,
                            tz,
                            e_ndamp,
                            e_tdamp,
                            e_slip,
                            e_roll,
                            e_plastic,
                        ) = contact_response(
                            k,
                            history,
                            nx,
                            ny,
                            nz,
                            overlap,
                            eff_radius,
                            eff_mass,
                            rolling_inertia,
                            vrx,
                            vry,
                            vrz,
                            wix - wjx,
                            wiy - wjy,
                            wiz - wjz,
                            dt,
                            normal_id,
                            normal_table[ti, tj],
                            tangential_id,
                            tangential_table[ti, tj],
                            rolling_id,
                            rolling_table[ti, tj],
                            H_NORMAL,
                            H_SPRING,
                            H_ROLL,
                            out_normal_force,
                            row,
                        )
                        if GENERATION and dt > 0.0:  # (none at the t = 0 evaluation)
                            at = ti * shares_row + 2 * tj  # (gen_partition[ti, tj])
                            psi_f = shares[at]
                            psi_o = shares[at + 1]
                            s_ndamp = psi_o * e_ndamp
                            s_tdamp = psi_o * e_tdamp
                            s_slip = psi_f * e_slip
                            s_roll = psi_f * e_roll
                            s_plastic = psi_o * e_plastic
                            a_ndamp += s_ndamp
                            a_tdamp += s_tdamp
                            a_slip += s_slip
                            a_roll += s_roll
                            a_plastic += s_plastic
                            deposit_particle(
                                energy, j * NG, use, e_ndamp - s_ndamp, e_tdamp - s_tdamp,
                                e_slip - s_slip, e_roll - s_roll, e_plastic - s_plastic,
                            )  # fmt: skip
                        # force on i: -F_n n + F_t; torque R n x F_t on both, rolling torque ±
                        fx = -f_n * nx + ftx
                        fy = -f_n * ny + fty
                        fz = -f_n * nz + ftz
                        lx = ny * ftz - nz * fty
                        ly = nz * ftx - nx * ftz
                        lz = nx * fty - ny * ftx
                        force[i, 0] += fx
                        force[i, 1] += fy
                        force[i, 2] += fz
                        force[j, 0] -= fx
                        force[j, 1] -= fy
                        force[j, 2] -= fz
                        torque[i, 0] += ri * lx + tx
                        torque[i, 1] += ri * ly + ty
                        torque[i, 2] += ri * lz + tz
                        torque[j, 0] += rj * lx - tx
                        torque[j, 1] += rj * ly - ty
                        torque[j, 2] += rj * lz - tz
                        r_min = min(ri, rj)
                        if overlap > row[L_MAX_OVERLAP_RATIO] * r_min:  # (no division per contact)
                            row[L_MAX_OVERLAP_RATIO] = overlap / r_min
                    # conduction of touching pairs (one call site: Numba's SSA check warns
                    # when the inlined model selection appears twice in one function); pairs
                    # across a gap are the range set's (engine/range_set.py)
                    if HEAT_ON and heat_on and out_state[k] == STATE_TOUCHING:
                        h = _pp_conductance(
                            k, i, j, ri, rj, dist, overlap, eff_mass, type_id, history,
                            out_normal_force, radius_id, radius_table, conduction_id,
                            conduction_table, override, k_particle, rhoc_particle, srow,
                            H_REUSE, tolerance,
                        )  # fmt: skip
                        q_ij = h * (temperature[j] - temperature[i])
                        by_mechanism[M_DIRECT, i] += q_ij
                        by_mechanism[M_DIRECT, j] -= q_ij
                        conductance_sum[i] += h
                        conductance_sum[j] += h
                if GENERATION and owner >= 0:
                    deposit_particle(energy, owner * NG, use, a_ndamp, a_tdamp, a_slip,
                                     a_roll, a_plastic)  # fmt: skip

    return particle_pair_pass
