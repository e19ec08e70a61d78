"""The neighbour lists of a :class:`~thermodem.engine.simulation.Simulation`.

:func:`rebuild_lists` sorts the particles by cell, lists the particle pairs and particle-wall
pairs within the interaction cut-off plus the skin into fresh index arrays, builds the
per-particle CSR of the pairs and carries the contact history to the new lists by particle
identity (the kernels are in :mod:`thermodem.kernels.neighbors`). :func:`rebuild_due` decides
when: after an insertion, at every step with ``rebuild_every_step``, or when a particle moved
more than half the skin or a particle plus a wall moved more than the skin since the last
build.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from thermodem.errors import SimulationError
from thermodem.geometry import wall_layout as WL
from thermodem.kernels import contact as C
from thermodem.kernels import neighbors as NB
from thermodem.state.pairs import PairBuffers

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def cell_size(sim: Simulation) -> float:
    """Edge of the neighbour cells: 2 r_max + extra distance + skin (sets a default skin)."""
    r_max = float(sim.particles.radius.max()) if sim.particles.count else 0.0
    if sim.skin is None and r_max > 0:
        sim.skin = 0.2 * r_max
    return 2.0 * r_max + sim.extra + (sim.skin or 0.0)


def rebuild_lists(sim: Simulation) -> None:
    """Sort particles by cell, list pairs and wall pairs, carry the history by identity."""
    p = sim.particles
    n = p.count
    cell = cell_size(sim)
    if n == 0:
        sim.pairs.count = 0
        sim.walls.count = 0
        sim.row_start = np.zeros(1, np.int64)
        sim.wall_row_start = np.zeros(1, np.int64)
        sim.reference = p.position.copy()
        return
    length = sim.upper - sim.lower
    for a in range(3):
        if sim.periodic[a] and length[a] < 2.0 * cell:
            raise SimulationError(
                f"periodic axis {'xyz'[a]}: domain length {length[a]:.6g} m is shorter than "
                f"twice the interaction cut-off {cell:.6g} m (minimum image needs >= "
                f"{2 * cell:.6g} m)",
                sim.step_count,
                sim.time,
            )
    pb, wb = sim.pairs, sim.walls
    dims, edge = NB.cell_grid(sim.lower, sim.upper, cell, sim.periodic)
    ncell = int(dims[0] * dims[1] * dims[2])
    order = np.empty(n, np.int64)
    cell_start = np.zeros(ncell + 1, np.int64)
    NB.sort_by_cell(p.position, sim.lower, edge, dims, order, cell_start)
    p.permute(order)
    new_index = np.empty(n, np.int32)  # old particle index -> index after the sort
    new_index[order] = np.arange(n, dtype=np.int32)
    del order
    # particle pairs: list into fresh index arrays, then carry the history
    old_i, old_j, old_history, old_count = pb.i, pb.j, pb.history, pb.count
    new_i = np.empty(pb.capacity, np.int32)
    new_j = np.empty(pb.capacity, np.int32)
    while True:
        count = NB.build_pairs(
            p.position,
            p.radius,
            p.global_id,
            sim.lower,
            sim.upper,
            sim.periodic,
            dims,
            edge,
            cell_start,
            sim.extra,
            sim.skin,
            new_i,
            new_j,
        )
        if count <= new_i.shape[0]:
            break
        new_i = np.empty(PairBuffers.grown(pb.capacity, count), np.int32)
        new_j = np.empty_like(new_i)
    if new_i.shape[0] > pb.capacity:
        pb.allocate(new_i.shape[0])  # old_* still hold the previous list
    pb.i, pb.j, pb.count = new_i, new_j, count
    if sim.row_start.shape[0] != n + 1:
        sim.row_start = np.zeros(n + 1, np.int64)
    if sim.entries.shape[0] < 2 * pb.capacity:
        sim.entries = np.zeros(2 * pb.capacity, np.int32)
    NB.particle_pair_csr(pb.i, pb.j, count, p.global_id, n, sim.row_start, sim.entries)
    spare = pb.spare_history()
    NB.carry_pair_history(
        old_i, old_j, old_count, old_history, new_index, sim.row_start, sim.entries,
        pb.j, spare, count,
    )  # fmt: skip
    pb.swap_history()  # (after a growth too: old_history is then the previous array)
    pb.state[:count] = C.STATE_UNSET  # outputs live in the old history memory now
    del old_i, old_j, old_history
    # wall pairs
    if sim.wall_row_start.shape[0] != n + 1:
        sim.wall_row_start = np.zeros(n + 1, np.int64)
    old_i, old_w, old_history, old_count = wb.i, wb.j, wb.history, wb.count
    new_i = np.empty(wb.capacity, np.int32)
    new_w = np.empty(wb.capacity, np.int32)
    while True:
        wcount = NB.build_wall_pairs(
            p.position,
            p.radius,
            sim.wall_kind,
            sim.wall_rows,
            sim.extra,
            sim.skin,
            new_i,
            new_w,
            sim.wall_row_start,
        )
        if wcount <= new_i.shape[0]:
            break
        new_i = np.empty(PairBuffers.grown(wb.capacity, wcount), np.int32)
        new_w = np.empty_like(new_i)
    if new_i.shape[0] > wb.capacity:
        wb.allocate(new_i.shape[0])
    wb.i, wb.j, wb.count = new_i, new_w, wcount
    NB.carry_wall_history(
        old_i, old_w, old_count, old_history, new_index, sim.wall_row_start, wb.j,
        wb.spare_history(), wcount,
    )  # fmt: skip
    wb.swap_history()
    wb.state[:wcount] = C.STATE_UNSET
    sim.reference = p.position.copy()
    sim.wall_reference = sim.wall_rows[:, WL.COL_POINT : WL.COL_POINT + 3].copy()
    sim.rebuild_count += 1
    sim._needs_rebuild = False


def rebuild_due(sim: Simulation) -> bool:
    """Whether the lists must be rebuilt before the next pair pass (see the module docstring)."""
    if sim._needs_rebuild or sim.rebuild_every_step:
        return True
    moved = sim.moved
    wall_moved = 0.0
    if sim.wall_rows.shape[0]:
        shift = sim.wall_rows[:, WL.COL_POINT : WL.COL_POINT + 3] - sim.wall_reference
        wall_moved = float(np.sqrt((shift**2).sum(axis=1)).max())
    return 2.0 * moved > sim.skin or moved + wall_moved > sim.skin
