"""The rebuild of a :class:`~thermodem.mpi.simulation.DistributedSimulation`.

In order (every step collective, see the simulation module's docstring):

1. this rank's share: its owned particles (before the first build every rank holds the same
   full set, from the insertion or a checkpoint, and takes the slice N r / P .. N (r+1) / P),
   on rank 0 with the particles poured since the last rebuild;
2. history records of the share's touching pairs (particle pairs whose lower global id is
   in the share, wall pairs of the share): rows ``[gid, other, history...]`` keyed by the
   two global ids (the wall index for a wall pair), which travel with particle ``gid``;
3. global counts and R_max; the bisection again when the imbalance passes the threshold;
4. migration: each particle (every array, the per-particle thermal arrays, its records) to
   the rank whose box contains it;
5. the owned particles sorted by cell of this rank's grid (box + halo);
6. ghosts: the owned particles within the halo width of each neighbour box, with their
   records, sent to that neighbour; received ghosts sorted by cell after the owned ones;
7. the contact list over owned + ghost particles, split into ``pairs`` (i owned) and
   ``mirror`` (i a ghost, j owned), each grouped by slab; wall pairs of the owned particles;
   every listed pair takes the history of its record (none: a new pair, zero history).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from thermodem.engine.neighbor_list import check_periodic_length
from thermodem.geometry import wall_layout as WL
from thermodem.kernels import contact as C
from thermodem.kernels import neighbors as NB
from thermodem.kernels import slabs as SL
from thermodem.kernels.halo import (
    fill_key_table,
    history_from_records,
    history_records,
    look_up_keys,
    pair_keys,
    record_keys,
)
from thermodem.mpi import exchange as X
from thermodem.mpi.decomposition import bisect
from thermodem.state.pairs import PairBuffers

if TYPE_CHECKING:
    from thermodem.mpi.simulation import DistributedSimulation


# ------------------------------------------------------------------------------- records
def pair_records(
    buf: PairBuffers, global_id: np.ndarray, selected: np.ndarray, wall: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``[gid_i, gid_j or wall, history...]`` of the pairs with a non-zero history whose
    particle i is ``selected`` (a mask over the particles), and the index of each one's i
    (one pass, kernels/halo.py: history_records)."""
    c = buf.count
    rows = np.empty((c, 2 + buf.history.shape[1]))
    owner = np.empty(c, np.int64)
    m = history_records(buf.history, buf.i, buf.j, c, selected, global_id, wall, rows, owner)
    return rows[:m], owner[:m]


def _record_keys(records: np.ndarray, base: np.int64) -> np.ndarray:
    """The key gid_i × base + other of every record."""
    out = np.empty(records.shape[0], np.int64)
    record_keys(records, base, out)
    return out


class _KeyTable:
    """The hash table of unique, non-negative ``keys`` (kernels/halo.py: fill_key_table; a
    sort and binary searches took about a third of an MPI rebuild), built once and looked up
    as often as needed."""

    def __init__(self, keys: np.ndarray) -> None:
        self.keys = np.ascontiguousarray(keys, np.int64)
        self.table = np.empty(1 << max(int(2 * self.keys.shape[0]).bit_length(), 1), np.int64)
        fill_key_table(self.keys, self.table)

    def positions(self, wanted: np.ndarray) -> np.ndarray:
        """Index in the keys of each of ``wanted`` (-1 when absent)."""
        out = np.empty(wanted.shape[0], np.int64)
        look_up_keys(self.keys, self.table, np.ascontiguousarray(wanted, np.int64), out)
        return out


def _positions_of(keys: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Index in ``keys`` (unique, non-negative) of each of ``wanted`` (-1 when absent)."""
    return _KeyTable(keys).positions(wanted)


def _split(dest: np.ndarray, rows: np.ndarray, size: int) -> list[np.ndarray]:
    """Rows grouped by destination rank (stable)."""
    order = np.argsort(dest, kind="stable")
    counts = np.bincount(dest, minlength=size)
    starts = np.concatenate([[0], np.cumsum(counts)])
    sorted_rows = rows[order]
    return [sorted_rows[starts[r] : starts[r + 1]] for r in range(size)]


def _take_history(
    buf: PairBuffers, keys: np.ndarray, records: np.ndarray, table: _KeyTable
) -> None:
    """History rows of the listed pairs (``keys``) from the records with the same key (zero
    for a pair without one: new); ``table``: the records' keys."""
    count = keys.shape[0]
    if table.keys.shape[0] == 0:
        buf.history[:count] = 0.0
        return
    history_from_records(buf.history, count, table.positions(keys), records)


# ------------------------------------------------------------------------------- rebuild
def rebuild_distributed(sim: DistributedSimulation) -> None:
    from thermodem.mpi.simulation import halo_members, halo_width, neighbour_ranks

    comm, size = sim.comm, sim.size
    p = sim.particles
    th = sim.thermal
    n_all = p.count
    # 1. the share
    if sim._distributed:
        first, last = 0, sim._owned
    else:
        first, last = sim.rank * n_all // size, (sim.rank + 1) * n_all // size
    share = slice(first, last)  # (a slice: the copies below are block copies)
    selected = np.zeros(n_all, np.bool_)
    selected[first:last] = True
    # 2. records, the per-particle thermal arrays
    records, rec_owner = pair_records(sim.pairs, p.global_id, selected, wall=False)
    wall_records, wall_owner = pair_records(sim.walls, p.global_id, selected, wall=True)
    rec_owner -= first  # (index in the share)
    wall_owner -= first
    extras: tuple[np.ndarray, ...] = ()
    if th is not None:
        cs = th.conductance_sum if th.conductance_sum.shape[0] == n_all else np.zeros(n_all)
        extras = (cs,)
    owned = X.view_particles(p, share)  # (views: the cell sort below copies them)
    extra_own = tuple(e[share] for e in extras)
    del p
    if sim.poured:  # particles poured since the last rebuild (rank 0): owned until migrated
        k = sum(q.count for q in sim.poured)
        owned = X.concatenate_particles([owned, *sim.poured])
        extra_own = tuple(np.concatenate([e, np.zeros(k)]) for e in extra_own)
        sim.poured = []
    # 3. global numbers and the decomposition
    local_r = float(owned.radius.max()) if owned.count else 0.0
    stats = X.allreduce_max(comm, np.array([float(owned.count), local_r]))
    total = int(X.allreduce_sum(comm, np.array([owned.count], np.int64))[0])
    r_max = float(stats[1])
    sim._radius_max = r_max
    if sim.skin is None and r_max > 0:
        sim.skin = 0.2 * r_max  # the serial default (engine/neighbor_list.py: cell_size)
    cell = 2.0 * r_max + sim.extra + (sim.skin or 0.0)
    if r_max > 0.0:  # (no particles, a restart's empty start: nothing to list)
        check_periodic_length(sim, cell, r_max)
    if not cell > 0.0:  # no particles (a restart's empty start): one cell
        cell = float(np.max(sim.upper - sim.lower))
    imbalance = stats[0] * size / max(total, 1) - 1.0
    if sim.decomposition is None or imbalance > sim.rebalance_threshold:
        if sim.decomposition is not None:
            sim.rebalances += 1
        sim.decomposition = bisect(
            comm, owned.position, sim.lower, sim.upper, size, planar=bool(sim.planar)
        )
    if sim.rotate_owners:  # (tests: every particle migrates, the results must not change)
        sim.decomposition = sim.decomposition.rotated(1)
    # 4. migration
    # (only the particles that leave are packed and sent; the others stay in place)
    dest = sim.decomposition.owner(owned.position)
    leave = dest != sim.rank
    sim.migrated += int(np.count_nonzero(leave))
    leaving = np.nonzero(leave)[0]
    widths = tuple(1 for _ in extras)
    width = X.row_width(owned, widths)
    rows = X.pack_particles(owned, leaving, extra_own)
    rows, _ = X.alltoallv_rows(comm, _split(dest[leaving], rows, size), width)
    arrived, extra_arrived = X.unpack_particles(rows, owned, widths)
    del rows
    rec_width = records.shape[1]
    moved_records = []
    for recs, owner in ((records, rec_owner), (wall_records, wall_owner)):
        go = leave[owner]
        sent, _ = X.alltoallv_rows(comm, _split(dest[owner[go]], recs[go], size), rec_width)
        if go.any() or sent.shape[0]:  # (else the records stay as they are: no copy)
            recs = np.concatenate([recs[~go], sent])
        moved_records.append((recs, owner[~go], sent))
    (records, rec_owner, rec_arrived), (wall_records, _, _) = moved_records
    if leaving.shape[0] or arrived.count:  # (else the owned particles stay as they are)
        staying = np.nonzero(~leave)[0]
        owned = X.concatenate_particles([X.take_particles(owned, staying), arrived])
        extra_own = [
            np.concatenate([e[staying], a]) for e, a in zip(extra_own, extra_arrived, strict=True)
        ]
        # the owner of every particle record, in the new owned numbering: a staying
        # particle's rank among the staying ones, an arrived record's particle by its id
        new_index = np.cumsum(~leave) - 1
        at = _positions_of(arrived.global_id, rec_arrived[:, 0].astype(np.int64))
        if at.shape[0] and at.min() < 0:
            raise AssertionError("an arrived history record without its particle")
        rec_owner = np.concatenate([new_index[rec_owner], staying.shape[0] + at])
    # 5. this rank's grid; the owned particles sorted by its cells
    h = halo_width(sim, r_max)
    sim.halo_width = h
    box = sim.decomposition.boxes[sim.rank]
    glo, ghi, gper = box[0].copy(), box[1].copy(), np.zeros(3, np.bool_)
    for a in range(3):
        if sim.periodic[a] and (box[0, a] - h <= sim.lower[a] or box[1, a] + h >= sim.upper[a]):
            glo[a], ghi[a], gper[a] = sim.lower[a], sim.upper[a], True
        else:
            glo[a] = max(sim.lower[a], box[0, a] - h)
            ghi[a] = min(sim.upper[a], box[1, a] + h)
    sim._grid = (glo, ghi, gper)
    dims, edge = NB.cell_grid(glo, ghi, cell, gper)
    if sim.planar:  # 2D: one cell layer along z (as the serial list, engine/neighbor_list.py)
        dims[2] = 1
        edge[2] = ghi[2] - glo[2]
    axis = int(SL.choose_axis(owned.position, glo, edge, dims)) if owned.count else 0
    axes = np.array([axis, *(a for a in range(3) if a != axis)], np.int64)
    order = _cell_order(owned.position, glo, edge, dims, axes)
    own = owned.count
    # (the owned particles are copied in this order once, with the ghosts after them, in 7;
    # until then the sorted positions and ids alone, and the sorted index k is order[k])
    sorted_position = owned.position[order]
    # 6. ghosts with their records
    neighbours = neighbour_ranks(sim, h)
    sorted_index = np.empty(own, np.int64)  # owned index -> sorted index
    sorted_index[order] = np.arange(own)
    rec_owner = sorted_index[rec_owner]
    ghost_blocks = [np.zeros((0, width)) for _ in range(size)]
    record_blocks = [np.zeros((0, rec_width)) for _ in range(size)]
    send = []
    for r in neighbours:
        idx = halo_members(sim, sorted_position, r, h)
        if idx.shape[0] == 0:
            continue
        send.append((r, idx.astype(np.int64)))
        ghost_blocks[r] = X.pack_particles(owned, order[idx], tuple(extra_own))
        member = np.zeros(own, np.bool_)
        member[idx] = True
        record_blocks[r] = records[member[rec_owner]]
    ghost_rows, from_rank = X.alltoallv_rows(comm, ghost_blocks, width)
    ghost_records, _ = X.alltoallv_rows(comm, record_blocks, rec_width)
    del ghost_blocks, record_blocks
    ghosts, extra_ghost = X.unpack_particles(ghost_rows, owned, widths)
    source = np.repeat(np.arange(size), from_rank)
    gorder = _cell_order(ghosts.position, glo, edge, dims, axes)
    landing = np.empty(gorder.shape[0], np.int64)  # received row -> local index
    landing[gorder] = own + np.arange(gorder.shape[0])
    recv = []
    for r in range(size):
        rows_from_r = np.nonzero(source == r)[0]
        if rows_from_r.shape[0]:
            recv.append((r, landing[rows_from_r]))
    sim.halo.send, sim.halo.recv = send, recv
    sim.halo.allocate(with_temperature=th is not None)
    # 7. the particles of this rank, the lists
    sim.particles = X.take_joined(owned, order, ghosts, gorder)
    sim._owned, sim._total, sim._distributed = own, total, True
    if th is not None:
        th.conductance_sum = np.concatenate([extra_own[0][order], extra_ghost[0][gorder]])
        th.particles_reordered()
    sim.slab_axis = axis
    all_records = np.concatenate([records, ghost_records])
    _build_lists(sim, dims, edge, axes, axis, all_records, wall_records)
    p = sim.particles
    sim.reference = p.position.copy()
    sim.wall_reference = sim.wall_rows[:, WL.COL_POINT : WL.COL_POINT + 3].copy()
    sim.rebuild_count += 1
    sim._needs_rebuild = False


def _cell_order(position: np.ndarray, lower, edge, dims, axes) -> np.ndarray:  # noqa: ANN001
    n = position.shape[0]
    order = np.empty(n, np.int32)
    cell_start = np.zeros(int(dims[0] * dims[1] * dims[2]) + 1, np.int64)
    if n:
        NB.sort_by_cell(position, lower, edge, dims, axes, order, cell_start)
    return order.astype(np.int64)


def _build_lists(sim: DistributedSimulation, dims, edge, axes, axis: int, records: np.ndarray,
                 wall_records: np.ndarray) -> None:  # noqa: ANN001  # fmt: skip
    p = sim.particles
    n, own = p.count, sim._owned
    glo, ghi, gper = sim._grid
    pb = sim.pairs
    if sim.mirror is None:
        sim.mirror = PairBuffers(64, pb.history_width)
    mb, wb = sim.mirror, sim.walls
    # every pair among owned + ghosts, found on cell-sorted copies
    order = np.empty(n, np.int32)
    cell_start = np.zeros(int(dims[0] * dims[1] * dims[2]) + 1, np.int64)
    if n:
        NB.sort_by_cell(p.position, glo, edge, dims, axes, order, cell_start)
    position = np.ascontiguousarray(p.position[order])
    radius = np.ascontiguousarray(p.radius[order])
    gid = np.ascontiguousarray(p.global_id[order])
    cap = max(pb.capacity + mb.capacity, 16)
    si = np.empty(cap, np.int32)
    sj = np.empty(cap, np.int32)
    while True:
        count = NB.build_pairs(position, radius, gid, glo, ghi, gper, dims, edge, axes,
                               cell_start, sim.extra, sim.skin or 0.0, si, sj)  # fmt: skip
        if count <= si.shape[0]:
            break
        si = np.empty(PairBuffers.grown(si.shape[0], count), np.int32)
        sj = np.empty_like(si)
    del position, radius, gid, cell_start
    i = order[si[:count]]
    j = order[sj[:count]]
    del si, sj, order
    key_base = np.int64(max(sim.next_global_id, 1))
    record_table = _KeyTable(_record_keys(records, key_base))
    nlayers = SL.layer_count(int(dims[axis]), bool(gper[axis]))
    for buf, mask in ((pb, i < own), (mb, (i >= own) & (j < own))):
        li = np.ascontiguousarray(i[mask], np.int32)
        lj = np.ascontiguousarray(j[mask], np.int32)
        m = li.shape[0]
        group_start = np.zeros(nlayers + 1, np.int64)
        args = (p.position, glo, edge, dims, axis, nlayers, li, lj, m, group_start)
        if not SL.group_pairs(*args):
            oi, oj = np.empty_like(li), np.empty_like(lj)
            SL.sort_pairs_by_group(*args, oi, oj, np.empty(m, np.int32))
            li, lj = oi, oj
        from thermodem.engine.range_set import nbr_order_within_groups

        nbr_order_within_groups(li, lj, m, group_start)
        if m > buf.capacity:
            buf.allocate(PairBuffers.grown(buf.capacity, m))
        buf.i[:m], buf.j[:m] = li, lj
        buf.count, buf.group_start = m, group_start
        keys = np.empty(m, np.int64)
        pair_keys(p.global_id, li, lj, m, key_base, keys)
        _take_history(buf, keys, records, record_table)
        buf.state[:m] = C.STATE_UNSET
    # wall pairs of the owned particles
    if sim.wall_row_start.shape[0] != n + 1:
        sim.wall_row_start = np.zeros(n + 1, np.int64)
    wi = np.empty(wb.capacity, np.int32)
    ww = np.empty(wb.capacity, np.int32)
    while True:
        wcount = NB.build_wall_pairs(p.position[:own], p.radius[:own], sim.wall_kind,
                                     sim.wall_rows, sim.extra, sim.skin or 0.0, wi, ww,
                                     sim.wall_row_start[: own + 1])  # fmt: skip
        if wcount <= wi.shape[0]:
            break
        wi = np.empty(PairBuffers.grown(wb.capacity, wcount), np.int32)
        ww = np.empty_like(wi)
    sim.wall_row_start[own + 1 :] = wcount
    if wi.shape[0] > wb.capacity:
        wb.allocate(wi.shape[0])
    wb.i[:wcount], wb.j[:wcount], wb.count = wi[:wcount], ww[:wcount], wcount
    nwalls = np.int64(max(sim.wall_rows.shape[0], 1))
    wkeys = p.global_id[wi[:wcount]].astype(np.int64) * nwalls + ww[:wcount].astype(np.int64)
    wrec_keys = _record_keys(wall_records, nwalls)
    _take_history(wb, wkeys, wall_records, _KeyTable(wrec_keys))
    wb.state[:wcount] = C.STATE_UNSET
