"""Per-contact physics: the forces, dissipation and history update of one contact.

:func:`contact_response` evaluates one touching contact, :func:`_open_contact` clears one that
does not touch; the parallel passes that call them for every listed pair are in
:mod:`thermodem.kernels.pair_pass`. This module also holds the column layout of the per-chunk
ledger, the pair states, and the deposit of a contact's dissipated energy into its particles'
heat generation accumulators (:func:`deposits`, :func:`deposit_pair`, :func:`deposit_wall`).

Sign conventions: n is the unit vector from i to j; the relative velocity of i with respect to j
at the contact point is v_rel = (v_i + ω_i × R_i n) - (v_j - ω_j × R_j n); the overlap rate is
v_rel · n (> 0 approaching). The lever arms are the particle radii: the torque of the
tangential force on i is R_i n × F_t, on j R_j n × F_t. A wall is j with infinite
radius and mass, its surface velocity at the contact point v_w + Ω a × (q - c).
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from thermodem.kernels.fastmath_log import bits_float, float_bits
from thermodem.models.mechanics.dispatch import (
    normal_dispatch,
    rolling_dispatch,
    tangential_dispatch,
)
from thermodem.state import history as history_layout
from thermodem.state.heat import (
    G_NORMAL_DAMPING,
    G_PLASTIC_DEFORMATION,
    G_ROLLING_FRICTION,
    G_SLIDING_FRICTION,
    G_TANGENTIAL_DAMPING,
    GENERATION,
)

CHUNK = 2048  # pairs per chunk of the heat-only pair passes

# History columns: allocated per simulation from the registry (state/history.py); the
# kernels take the offsets of the blocks (-1: absent). The contact's own columns are first.
H_DURATION = history_layout.DURATION  # time in contact [s]; 0 when not touching
H_IMPACT_VELOCITY = history_layout.IMPACT_VELOCITY  # normal approach speed at first contact

# Ledger columns written per chunk.
L_ELASTIC_NORMAL = 0
L_ELASTIC_TANGENTIAL = 1
L_ELASTIC_ROLLING = 2
L_NORMAL_DAMPING = 3
L_TANGENTIAL_DAMPING = 4
L_SLIDING_FRICTION = 5
L_ROLLING_FRICTION = 6
L_PLASTIC_DEFORMATION = 7
L_STIFFNESS_WORK = 8
L_WALL_WORK = 9
L_MAX_OVERLAP_RATIO = 10
L_TOUCHING = 11
#: kinetic energy lost by the pairs whose collision ended (heat generation of Al-Arkawazi 2017)
L_COLLISION = 12
#: the walls' share of the generated heat's energy, per mechanism of state/heat.GENERATION
L_WALL_GENERATION = 13
LEDGER_WIDTH = L_WALL_GENERATION + len(GENERATION)

STATE_FAR = 0
STATE_NEAR = 1
STATE_TOUCHING = 2
STATE_UNSET = 3  # listed by a rebuild, not yet evaluated (outputs not written)


@njit(cache=True, inline="always", error_model="numpy")
def _rotate_into_plane(h, k, c0, nx, ny, nz):
    """Project the 3-vector h[k, c0:c0+3] onto the plane normal to n, keeping its length."""
    ax = h[k, c0]
    ay = h[k, c0 + 1]
    az = h[k, c0 + 2]
    old2 = ax * ax + ay * ay + az * az
    if old2 == 0.0:
        return 0.0, 0.0, 0.0
    dot = ax * nx + ay * ny + az * nz
    ax -= dot * nx
    ay -= dot * ny
    az -= dot * nz
    new2 = ax * ax + ay * ay + az * az
    if new2 > 0.0:
        s = math.sqrt(old2 / new2)
        return ax * s, ay * s, az * s
    return 0.0, 0.0, 0.0


@njit(cache=True, inline="always", error_model="numpy")
def contact_response(
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
    wrx,
    wry,
    wrz,
    dt,
    normal_id,
    p_normal,
    tangential_id,
    p_tangential,
    rolling_id,
    p_rolling,
    h_normal,
    h_spring,
    h_roll,
    out_normal_force,
    ledger_row,
):
    """Forces of one touching contact (row k of the pair or wall-pair arrays).

    Returns (F_n, F_t (3), rolling torque on i (3), and the energies dissipated in this step
    by normal damping, tangential damping, sliding friction, rolling friction and plastic
    deformation [J]); the force on i is -F_n n + F_t and the torque on i is R_i n x F_t plus
    the rolling torque. Writes the normal force, updates the history row and adds energies to
    the ledger row. ``h_normal``, ``h_spring``, ``h_roll``: first history column of the normal
    law's value, the tangential spring (its energy follows the 3-vector) and the rolling
    torque, -1 when the selected law keeps none (state/history.py).
    """
    rate = vrx * nx + vry * ny + vrz * nz
    h0 = history[k, h_normal] if h_normal >= 0 else 0.0
    f_el, f_damp, k_ref, gamma_n, u_n, h0, e_plastic = normal_dispatch(
        normal_id, p_normal, overlap, rate, eff_radius, eff_mass, h0
    )
    if h_normal >= 0:
        history[k, h_normal] = h0
    f_n = f_el + f_damp
    # tangential relative velocity
    vtx = vrx - rate * nx
    vty = vry - rate * ny
    vtz = vrz - rate * nz
    if h_spring >= 0:
        sx, sy, sz = _rotate_into_plane(history, k, h_spring, nx, ny, nz)
    else:
        sx = 0.0
        sy = 0.0
        sz = 0.0
    ftx, fty, ftz, sx, sy, sz, k_t, e_tdamp, e_slip = tangential_dispatch(
        tangential_id,
        p_tangential,
        k_ref,
        gamma_n,
        eff_radius,
        overlap,
        f_n,
        vtx,
        vty,
        vtz,
        sx,
        sy,
        sz,
        dt,
    )
    stiffness_work = 0.0
    u_t = 0.0
    if h_spring >= 0:
        old_s2 = history[k, h_spring] ** 2 + history[k, h_spring + 1] ** 2
        old_s2 += history[k, h_spring + 2] ** 2
        stiffness_work = 0.5 * k_t * old_s2 - history[k, h_spring + 3]
        u_t = 0.5 * k_t * (sx * sx + sy * sy + sz * sz)
        history[k, h_spring] = sx
        history[k, h_spring + 1] = sy
        history[k, h_spring + 2] = sz
        history[k, h_spring + 3] = u_t
    if history[k, H_DURATION] == 0.0:
        history[k, H_IMPACT_VELOCITY] = rate
    history[k, H_DURATION] += dt
    # rolling (relative angular velocity projected on the tangent plane)
    wn = wrx * nx + wry * ny + wrz * nz
    wrx -= wn * nx
    wry -= wn * ny
    wrz -= wn * nz
    if h_roll >= 0:
        mx, my, mz = _rotate_into_plane(history, k, h_roll, nx, ny, nz)
    else:
        mx = 0.0
        my = 0.0
        mz = 0.0
    tx, ty, tz, mx, my, mz, k_r, e_roll = rolling_dispatch(
        rolling_id,
        p_rolling,
        k_ref,
        eff_radius,
        rolling_inertia,
        f_n,
        wrx,
        wry,
        wrz,
        mx,
        my,
        mz,
        dt,
    )
    u_r = 0.0
    if h_roll >= 0:
        if k_r > 0.0:
            old_m2 = history[k, h_roll] ** 2 + history[k, h_roll + 1] ** 2
            old_m2 += history[k, h_roll + 2] ** 2
            stiffness_work += 0.5 * old_m2 / k_r - history[k, h_roll + 3]
            u_r = 0.5 * (mx * mx + my * my + mz * mz) / k_r
        history[k, h_roll] = mx
        history[k, h_roll + 1] = my
        history[k, h_roll + 2] = mz
        history[k, h_roll + 3] = u_r
    e_ndamp = f_damp * rate * dt
    out_normal_force[k] = f_n
    ledger_row[L_ELASTIC_NORMAL] += u_n
    ledger_row[L_ELASTIC_TANGENTIAL] += u_t
    ledger_row[L_ELASTIC_ROLLING] += u_r
    ledger_row[L_NORMAL_DAMPING] += e_ndamp
    ledger_row[L_TANGENTIAL_DAMPING] += e_tdamp
    ledger_row[L_SLIDING_FRICTION] += e_slip
    ledger_row[L_ROLLING_FRICTION] += e_roll
    ledger_row[L_PLASTIC_DEFORMATION] += e_plastic
    ledger_row[L_STIFFNESS_WORK] += stiffness_work
    ledger_row[L_TOUCHING] += 1.0
    return f_n, ftx, fty, ftz, tx, ty, tz, e_ndamp, e_tdamp, e_slip, e_roll, e_plastic


@njit(cache=True, inline="always", error_model="numpy")
def clear_opened(k, history, h_spring, h_roll, out_normal_force, out_state):
    """Outputs of a pair that does not touch; a contact that just opened is cleared.

    The energy left in its springs when a contact opens is counted as friction (documented);
    returns it, (sliding, rolling) [J], for the ledger and the heat generation. A pair that
    did not touch at the previous pass already has zero outputs and history: no writes (a
    rebuild marks every pair STATE_UNSET, so the outputs of a new list are written).
    """
    if out_state[k] == STATE_NEAR or out_state[k] == STATE_FAR:
        return 0.0, 0.0
    e_spring = 0.0
    e_roll = 0.0
    if history[k, H_DURATION] != 0.0:
        if h_spring >= 0:
            e_spring = history[k, h_spring + 3]
        if h_roll >= 0:
            e_roll = history[k, h_roll + 3]
        for c in range(history.shape[1]):
            history[k, c] = 0.0
    out_normal_force[k] = 0.0
    return e_spring, e_roll


@njit(cache=True, inline="always", error_model="numpy")
def _open_contact(k, history, h_spring, h_roll, out_normal_force, out_state, ledger_row):
    """:func:`clear_opened`, the springs' energies added to the ledger row (the planar pass
    keeps its ledger sums in registers and calls :func:`clear_opened` itself)."""
    e_spring, e_roll = clear_opened(k, history, h_spring, h_roll, out_normal_force, out_state)
    if e_spring != 0.0:
        ledger_row[L_SLIDING_FRICTION] += e_spring
    if e_roll != 0.0:
        ledger_row[L_ROLLING_FRICTION] += e_roll
    return e_spring, e_roll


# ------------------------------------------------------------------- heat generation deposits
#: Columns of a particle's row of heat generation accumulators (``Particles.generation_energy``,
#: one per mechanism of state/heat.GENERATION). The particle pair pass indexes the accumulators
#: as one flat row, ``energy.reshape(energy.size)``, particle i's first column at ``i * NG``:
#: with the row width a compile-time constant each deposit is an add at a constant offset from
#: one address (the 2-D index multiplies by the run-time row width for every column).
NG = len(GENERATION)


@intrinsic
def _prefetch(typingctx, array, index):  # noqa: ANN001, ANN201, ARG001
    """Ask the processor to bring ``array[index]`` (1-D) into the cache for a write: LLVM's
    ``llvm.prefetch`` (a hint; no effect on any value, and no fault on any address)."""
    if not (isinstance(array, types.Array) and array.ndim == 1):
        return None

    def codegen(context, builder, sig, args):  # noqa: ANN001, ANN202, ARG001
        arr = context.make_array(sig.args[0])(context, builder, args[0])
        offset = context.cast(builder, args[1], sig.args[1], types.intp)
        address = builder.bitcast(builder.gep(arr.data, [offset]), ir.IntType(8).as_pointer())
        i32 = ir.IntType(32)
        hint = ir.FunctionType(ir.VoidType(), [address.type, i32, i32, i32])
        fn = cgutils.get_or_insert_function(builder.module, hint, "llvm.prefetch.p0")
        builder.call(fn, [address, i32(1), i32(3), i32(1)])  # write, keep in all levels, data
        return context.get_dummy_value()

    return types.none(array, index), codegen


@njit(cache=True, inline="always", error_model="numpy")
def prefetch_row(energy, i):
    """Prefetch particle i's first NG - 2 accumulators (the columns the force laws deposit
    into; two cache lines at most) from the flat accumulators ``energy`` (:data:`NG`)."""
    _prefetch(energy, i * NG)
    _prefetch(energy, i * NG + NG - 3)


@njit(cache=True, inline="always", error_model="numpy")
def deposits(select, generation, rolls, plastic):
    """Which deposits a pass makes, read once per pass: for sliding friction, rolling friction,
    normal damping, tangential damping and plastic deformation a bit mask (int64), all ones
    when the mechanism is selected (``select[g]`` != 0) and, for the rolling and plastic ones,
    possible with the pass's mechanics (``rolls``: a rolling law; ``plastic``: the
    elasto-plastic normal law), else 0; then whether rolling and plastic deposits are made at
    all and whether any of the five is (none without ``generation``). The passes give the
    last three arguments as compile-time constants, so the deposits of what is always zero are
    not compiled; and the selection is read once, not at every deposit (the compiler cannot
    keep it in a register across the stores into the accumulators, which might alias it).
    The particle pair pass adds ``kept(e, mask)`` (e, or +0.0 unselected: a bitwise and, no
    branch) for the other three; the wall pass tests the masks."""
    m_slip = _mask(generation and select[G_SLIDING_FRICTION] != 0.0)
    m_roll = _mask(generation and rolls and select[G_ROLLING_FRICTION] != 0.0)
    m_ndamp = _mask(generation and select[G_NORMAL_DAMPING] != 0.0)
    m_tdamp = _mask(generation and select[G_TANGENTIAL_DAMPING] != 0.0)
    m_plastic = _mask(generation and plastic and select[G_PLASTIC_DEFORMATION] != 0.0)
    any_force = (m_slip | m_roll | m_ndamp | m_tdamp | m_plastic) != 0
    return (m_slip, m_roll, m_ndamp, m_tdamp, m_plastic, generation and rolls,
            generation and plastic, any_force)  # fmt: skip


@njit(cache=True, inline="always", error_model="numpy")
def _mask(flag):
    return np.int64(-1) if flag else np.int64(0)


@njit(cache=True, inline="always", error_model="numpy")
def kept(e, mask):
    """``e`` where ``mask`` is all ones, +0.0 where it is 0 (the bits of e and the mask)."""
    return bits_float(float_bits(e) & mask)


@njit(cache=True, inline="always", error_model="numpy")
def deposit_pair(
    energy, i, j, use, psi_friction, psi_other, e_ndamp, e_tdamp, e_slip, e_roll, e_plastic
):
    """Add a particle pair's dissipated energies of one step [J] to the two particles'
    accumulators (flat, :data:`NG`) of the mechanisms ``use`` (:func:`deposits`): ψ e to i,
    the rest to j (``psi_*``: i's share of the friction heat and of the other heat, the heat
    generation row's partition; models/thermal/heat_generation.py)."""
    s_ndamp = psi_other * e_ndamp
    s_tdamp = psi_other * e_tdamp
    s_slip = psi_friction * e_slip
    s_roll = psi_friction * e_roll
    s_plastic = psi_other * e_plastic
    deposit_particle(energy, i * NG, use, s_ndamp, s_tdamp, s_slip, s_roll, s_plastic)
    deposit_particle(energy, j * NG, use, e_ndamp - s_ndamp, e_tdamp - s_tdamp,
                     e_slip - s_slip, e_roll - s_roll, e_plastic - s_plastic)  # fmt: skip


@njit(cache=True, inline="always", error_model="numpy")
def deposit_particle(energy, base, use, e_ndamp, e_tdamp, e_slip, e_roll, e_plastic):
    """Add one particle's shares of dissipated energy [J] to its accumulators of the
    mechanisms ``use`` (:func:`deposits`): ``energy`` flat, the particle's first column at
    ``base`` (= i :data:`NG`). A mechanism not selected gets +0.0 (it stays 0; adding is
    cheaper than a branch per mechanism); rolling and plastic only when the mechanics has
    them. The particle pair pass: j's share of each pair at once, i's shares summed over its
    run of pairs in the list and added when i changes."""
    if use[7]:
        energy[base + G_SLIDING_FRICTION] += kept(e_slip, use[0])
        if use[5]:
            energy[base + G_ROLLING_FRICTION] += kept(e_roll, use[1])
        energy[base + G_NORMAL_DAMPING] += kept(e_ndamp, use[2])
        energy[base + G_TANGENTIAL_DAMPING] += kept(e_tdamp, use[3])
        if use[6]:
            energy[base + G_PLASTIC_DEFORMATION] += kept(e_plastic, use[4])


@njit(cache=True, inline="always", error_model="numpy")
def _deposit_wall(energy, i, g, e, psi, ledger_row):
    share = psi * e
    energy[i, g] += share
    ledger_row[L_WALL_GENERATION + g] += e - share


@njit(cache=True, inline="always", error_model="numpy")
def deposit_wall(
    energy, i, use, psi_friction, psi_other, e_ndamp, e_tdamp, e_slip, e_roll, e_plastic,
    ledger_row,
):  # fmt: skip
    """The same for a particle-wall pair: the particle's share into its accumulators, the
    wall's share into the ledger row (``psi_*`` = 1 for an adiabatic wall)."""
    if use[0] != 0:
        _deposit_wall(energy, i, G_SLIDING_FRICTION, e_slip, psi_friction, ledger_row)
    if use[1] != 0:
        _deposit_wall(energy, i, G_ROLLING_FRICTION, e_roll, psi_friction, ledger_row)
    if use[2] != 0:
        _deposit_wall(energy, i, G_NORMAL_DAMPING, e_ndamp, psi_other, ledger_row)
    if use[3] != 0:
        _deposit_wall(energy, i, G_TANGENTIAL_DAMPING, e_tdamp, psi_other, ledger_row)
    if use[4] != 0:
        _deposit_wall(energy, i, G_PLASTIC_DEFORMATION, e_plastic, psi_other, ledger_row)


@njit(cache=True, inline="always", error_model="numpy")
def kinetic_energy(velocity, angular_velocity, mass, inertia, i):
    """½ m |v|² + ½ I |ω|² of particle i [J]."""
    v2 = velocity[i, 0] ** 2 + velocity[i, 1] ** 2 + velocity[i, 2] ** 2
    w2 = angular_velocity[i, 0] ** 2 + angular_velocity[i, 1] ** 2
    w2 += angular_velocity[i, 2] ** 2
    return 0.5 * (mass[i] * v2 + inertia[i] * w2)


@njit(cache=True, inline="always", error_model="numpy")
def collision_loss(history, k, h_collision, kinetic_now):
    """Kinetic energy the pair of row k lost since its collision started (the value kept at
    the first touching pass), clipped at 0 (Al-Arkawazi 2017, ΔU; documented)."""
    return max(history[k, h_collision] - kinetic_now, 0.0)


def dissipates(mechanics: tuple[int, ...], layout: tuple[int, ...]) -> tuple[bool, bool]:
    """(rolling friction, plastic deformation): whether the mechanics combination can
    dissipate by them, a compile-time constant of the passes (:func:`thermodem.kernels.contact.
    deposits`): a rolling law (id != 0; without one the rolling terms are zero) and the
    elasto-plastic normal law, the one law that keeps a normal history column
    (models/mechanics/normal.py: the elastic laws return a plastic energy of 0)."""
    return int(mechanics[2]) != 0, int(layout[history_layout.NORMAL]) >= 0
