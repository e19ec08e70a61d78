"""The neighbour lists of a :class:`~thermodem.engine.simulation.Simulation`.

:func:`rebuild_lists` sorts the particles by cell (slab axis major), lists the particle pairs
and particle-wall pairs within the interaction cut-off plus the skin into fresh index arrays,
groups the particle pairs by slab layer (:mod:`thermodem.kernels.slabs`) and carries the
contact history to the new lists by particle identity, in place (the kernels are in
:mod:`thermodem.kernels.neighbors`). :func:`rebuild_due` decides
when: after an insertion, at every step with ``rebuild_every_step``, or when a particle moved
more than half the skin or a particle plus a wall moved more than the skin since the last
build.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from thermodem.errors import SimulationError
from thermodem.geometry import wall_layout as WL
from thermodem.kernels import contact as C
from thermodem.kernels import neighbors as NB
from thermodem.kernels import slabs as SL
from thermodem.kernels.integrate import max_wall_shift
from thermodem.state.pairs import PairBuffers

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def cell_size(sim: Simulation) -> float:
    """Edge of the neighbour cells: 2 r_max + extra distance + skin (sets a default skin)."""
    r_max = float(sim.particles.radius.max()) if sim.particles.count else 0.0
    if sim.skin is None and r_max > 0:
        sim.skin = 0.2 * r_max
    return 2.0 * r_max + sim.extra + (sim.skin or 0.0)


def cell_grid(sim: Simulation, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Cells per axis and their edges for a cut-off ``cell``; a 2D case has one layer along z
    (its particles lie in the plane z = 0), so a particle's stencil holds 9 cells, not 27."""
    dims, edge = NB.cell_grid(sim.lower, sim.upper, cell, sim.periodic)
    if sim.planar:
        dims[2] = 1
        edge[2] = sim.upper[2] - sim.lower[2]
    return dims, edge


def check_periodic_length(
    sim: Simulation, cell: float, r_max: float, skin: float | None = None
) -> None:
    """SimulationError naming ``domain.periodic`` when a periodic axis is shorter than two
    neighbour cells of ``cell`` = 2 R_max + extra distance + skin (the minimum image;
    ``skin``: the one in ``cell``, default ``sim.skin``)."""
    skin = sim.skin if skin is None else skin
    length = sim.upper - sim.lower
    for a in range(3):
        if sim.periodic[a] and length[a] < 2.0 * cell:
            raise SimulationError(
                f"domain.periodic: axis {'xyz'[a]} is periodic, but the domain is "
                f"{length[a]:.6g} m long along it (domain.upper - domain.lower), shorter than "
                f"twice the neighbour cell {cell:.6g} m (2 R_max {2.0 * r_max:.6g} m + "
                + (f"neighbors.extra_distance {sim.extra:.6g} m + " if sim.extra else "")
                + f"neighbors.skin {skin or 0.0:.6g} m); the minimum image needs >= "
                f"{2 * cell:.6g} m: a longer periodic axis, smaller particles or a smaller "
                "neighbors.skin",
                sim.step_count,
                sim.time,
            )


def check_next_build(sim: Simulation) -> None:
    """What the next :func:`rebuild_lists` of the particles present would refuse, checked
    without building or changing anything (:func:`check_periodic_length`; the skin a first
    build would default to): a restart sets up with it, so that a changed case whose fault
    shows only when the lists are built (a shorter periodic axis) is refused before step 1."""
    p = sim.particles
    if p.count == 0:
        return
    r_max = float(p.radius.max())
    skin = sim.skin if sim.skin is not None else 0.2 * r_max  # (as cell_size)
    check_periodic_length(sim, 2.0 * r_max + sim.extra + skin, r_max, skin)


#: Bytes per cell of the neighbour grid (its cell_start array, int64).
CELL_BYTES = 8.0


def max_cells() -> float:
    """The most cells of the neighbour grid: those whose cell_start array fits in the
    machine's physical memory (1e9, 8 GB, where it is unknown)."""
    from thermodem.engine.resources import physical_memory

    total = physical_memory()[0]
    return total / CELL_BYTES if math.isfinite(total) and total > 0 else 1.0e9


def check_cell_count(sim: Simulation, cell: float, r_max: float) -> None:
    """SimulationError when the neighbour grid of cells of edge ``cell`` (2 R_max + extra
    distance + skin) would have more than :func:`max_cells` cells: particles vanishingly small
    for the domain (a lognormal distribution of a huge sigma draws radii of 1e-20 m), which
    ended in a NumPy "array is too big" traceback. At the first build (validate, run) it is an
    input error."""
    length = np.asarray(sim.upper, float) - np.asarray(sim.lower, float)
    per_axis = np.maximum(np.floor(length / max(cell, 1e-300)), 1.0)
    if sim.planar:
        per_axis[2] = 1.0
    cells = math.prod(float(c) for c in per_axis)  # (inf beyond 1e308, without a warning)
    if cells <= 1.0e8:  # (0.8 GB: fine on any machine; the memory is not read each build)
        return
    most = max_cells()
    if cells <= most:
        return
    count = f"{cells:.3g}" if np.isfinite(cells) else "more than 1e308"
    raise SimulationError(
        f"the neighbour grid would have {count} cells (more than {most:.3g}, "
        "whose index alone fills the physical memory): its cell "
        f"edge is {cell:.3g} m (2 R_max + neighbors.extra_distance + skin, the largest particle "
        f"radius R_max being {r_max:.3g} m) in a domain of {length[0]:.3g} × {length[1]:.3g} × "
        f"{length[2]:.3g} m; allowed: a domain (domain.lower, domain.upper) at most about "
        f"{(most ** (1.0 / (2 if sim.planar else 3))) * cell:.3g} m wide for these particles. "
        "The usual causes: a domain in another unit (mm: 10 for 10 mm), radii in another unit "
        "(a particle file's or a list's), or a radius distribution drawing vanishing radii (a "
        "lognormal of a large sigma: give min_radius, or a sigma of 0.05-1)"
    )


def rebuild_lists(sim: Simulation) -> None:
    """Sort particles by cell, list pairs and wall pairs, carry the history by identity."""
    p = sim.particles
    n = p.count
    cell = cell_size(sim)
    pb, wb = sim.pairs, sim.walls
    if n == 0:
        pb.count = 0
        pb.group_start = np.zeros(2, np.int64)
        wb.count = 0
        sim.wall_row_start = np.zeros(1, np.int64)
        sim.reference = p.position.copy()
        return
    check_periodic_length(sim, cell, float(p.radius.max()))
    check_cell_count(sim, cell, float(p.radius.max()))
    dims, edge = cell_grid(sim, cell)
    axis = int(SL.choose_axis(p.position, sim.lower, edge, dims))
    sim.slab_axis = axis  # the particles' memory order is by layers along it (range set)
    axes = np.array([axis, *(a for a in range(3) if a != axis)], np.int64)
    ncell = int(dims[0] * dims[1] * dims[2])
    order = np.empty(n, np.int32)
    cell_start = np.zeros(ncell + 1, np.int64)
    NB.sort_by_cell(p.position, sim.lower, edge, dims, axes, order, cell_start)
    p.permute(order)
    if sim.thermal is not None:
        sim.thermal.particles_reordered()  # derived per-particle state and the range set
    new_index = np.empty(n, np.int32)  # old particle index -> index after the sort
    new_index[order] = np.arange(n, dtype=np.int32)
    del order
    # particle pairs: list into fresh index arrays
    old_i, old_j, old_count = pb.i, pb.j, pb.count
    new_i = np.empty(pb.capacity, np.int32)
    new_j = np.empty(pb.capacity, np.int32)
    while True:
        count = NB.build_pairs(
            p.position, p.radius, p.global_id, sim.lower, sim.upper, sim.periodic, dims, edge,
            axes, cell_start, sim.extra, sim.skin, new_i, new_j,
        )  # fmt: skip
        if count <= new_i.shape[0]:
            break
        new_i = np.empty(PairBuffers.grown(pb.capacity, count), np.int32)
        new_j = np.empty_like(new_i)
    del cell_start
    pb.i, pb.j = new_i, new_j
    # where each old touching pair's history goes (written over the old i array)
    dest = old_i[:old_count]
    if old_count:
        offsets = np.empty(n + 1, np.int32)
        if not NB.lower_index_offsets(new_i, new_j, count, n, offsets):
            raise AssertionError("build_pairs must list pairs by their lower index")
        NB.carry_destinations(
            old_i, old_j, old_count, pb.history, new_index, offsets, new_i, new_j, dest
        )
        del offsets
    del old_j
    # slab groups (pairs across a periodic boundary need a sort)
    nlayers = SL.layer_count(int(dims[axis]), bool(sim.periodic[axis]))
    group_start = np.zeros(nlayers + 1, np.int64)
    args = (p.position, sim.lower, edge, dims, axis, nlayers, new_i, new_j, count, group_start)
    if not SL.group_pairs(*args):
        sorted_i, sorted_j = np.empty_like(new_i), np.empty_like(new_j)
        where = np.empty(count, np.int32)
        SL.sort_pairs_by_group(*args, sorted_i, sorted_j, where)
        new_i, new_j = sorted_i, sorted_j
        carried = dest >= 0
        dest[carried] = where[dest[carried]]
        del where, carried
    # history: moved in place to the new pair of the same two particles
    if new_i.shape[0] > pb.capacity:
        pb.allocate(new_i.shape[0], keep=old_count)
    done = np.empty(old_count, np.int8)
    width = pb.history_width
    NB.move_rows(pb.history, dest, old_count, count, done, np.empty(width), np.empty(width))
    del dest, done, old_i
    pb.i, pb.j, pb.count, pb.group_start = new_i, new_j, count, group_start
    pb.state[:count] = C.STATE_UNSET  # per-pair outputs of the old list: rewrite all
    # wall pairs (few: a fresh history table)
    if sim.wall_row_start.shape[0] != n + 1:
        sim.wall_row_start = np.zeros(n + 1, np.int64)
    old_i, old_w, old_history, old_count = wb.i, wb.j, wb.history, wb.count
    new_i = np.empty(wb.capacity, np.int32)
    new_w = np.empty(wb.capacity, np.int32)
    while True:
        wcount = NB.build_wall_pairs(
            p.position, p.radius, sim.wall_kind, sim.wall_rows, sim.extra, sim.skin, new_i,
            new_w, sim.wall_row_start,
        )  # fmt: skip
        if wcount <= new_i.shape[0]:
            break
        new_i = np.empty(PairBuffers.grown(wb.capacity, wcount), np.int32)
        new_w = np.empty_like(new_i)
    if new_i.shape[0] > wb.capacity:
        wb.allocate(new_i.shape[0])
    new_history = np.zeros_like(wb.history)
    NB.carry_wall_history(
        old_i, old_w, old_count, old_history, new_index, sim.wall_row_start, new_w,
        new_history, wcount,
    )  # fmt: skip
    wb.i, wb.j, wb.count, wb.history = new_i, new_w, wcount, new_history
    wb.state[:wcount] = C.STATE_UNSET
    if sim.reference.shape == p.position.shape:
        sim.reference[:] = p.position
    else:
        sim.reference = p.position.copy()
    sim.wall_reference = sim.wall_rows[:, WL.COL_POINT : WL.COL_POINT + 3].copy()
    sim.rebuild_count += 1
    sim._needs_rebuild = False


def rebuild_due(sim: Simulation) -> bool:
    """Whether the lists must be rebuilt before the next pair pass (see the module docstring)."""
    if sim._needs_rebuild or sim.rebuild_every_step or sim.skin is None:
        return True  # (no skin yet: no particle listed so far, on every MPI rank alike)
    moved = sim.moved
    wall_moved = 0.0
    if sim.wall_rows.shape[0]:
        wall_moved = max_wall_shift(sim.wall_rows, WL.COL_POINT, sim.wall_reference)
    return 2.0 * moved > sim.skin or moved + wall_moved > sim.skin
