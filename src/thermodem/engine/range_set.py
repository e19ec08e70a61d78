"""The range pair set: particle pairs (and particle-wall pairs) within an interaction range.

Thermal terms that conduct across a gap (``target="range"``: indirect conduction through the
fluid, the separated-pair part of Batchelor & O'Brien) run on this set, not on the contact
list: the contact list stays as short as the mechanics needs, and the range set is built and
evaluated at thermal steps only. It has

- its own cut-off: the largest surface gap at which any selected range term conducts
  (each term's registered ``interaction_range`` at the largest particle radius; the kernels
  themselves return 0 beyond their own per-pair range),
- its own Verlet skin (``thermal.range_skin``, default the contact list's skin): a pair is
  listed when its gap is below cut-off + skin; the set is rebuilt at the next thermal step
  when a particle moved more than half the skin since the build (or a particle plus a wall
  moved more than the skin), and whenever the contact list's rebuild reordered the particles
  (the set holds particle indices) or particles were inserted,
- no history: only the two int32 indices per pair (8 B), the reference positions of its
  last build (24 B per particle) and its slab groups, so a range pass is race-free and
  deterministic like the contact pass (:mod:`thermodem.kernels.slabs`).

The set is saved in checkpoints (its pair order fixes the summation order of the heat), so a
restart is bit-identical.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import SimulationError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import heat_terms, slabs
from thermodem.kernels import neighbors as nbr
from thermodem.state.pairs import PairBuffers

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation

#: Scalars of the set saved in checkpoints (with its arrays, see ``state_dict``).
STATE_SCALARS = ("count", "wall_count", "valid", "gap", "wall_gap", "skin", "builds")


class RangePairSet:
    """Pairs whose surface gap is within ``gap`` (+ skin); see the module docstring."""

    def __init__(self, skin: float | None) -> None:
        self.requested_skin = skin
        self.skin = 0.0
        self.gap = 0.0
        self.wall_gap = 0.0
        self.count = 0
        self.i = np.zeros(16, np.int32)
        self.j = np.zeros(16, np.int32)
        self.group_start = np.zeros(2, np.int64)
        self.reference = np.zeros((0, 3))
        self.wall_count = 0
        self.wall_i = np.zeros(16, np.int32)
        self.wall_w = np.zeros(16, np.int32)
        self.wall_row_start = np.zeros(1, np.int64)
        self.wall_reference = np.zeros((0, 3))
        self.valid = False
        self.builds = 0
        #: largest displacement since the build, found by the last due() [m] (or a bound of
        #: it: see due())
        self.moved = 0.0
        #: the simulation's neighbour-list builds and displacement when this set was built
        self._sim_builds = -1
        self._sim_moved = 0.0
        self.bounded = 0  # due() calls the bound decided (no displacement pass)
        self._part = np.zeros(1)

    @property
    def ngroups(self) -> int:
        return self.group_start.shape[0] - 1

    def invalidate(self) -> None:
        """The particles were reordered or inserted: rebuild before the next evaluation."""
        self.valid = False

    def due(self, sim: Simulation) -> bool:
        """Whether the set must be rebuilt before it is evaluated on the current positions."""
        if not self.valid or self.reference.shape[0] != sim.particles.count:
            return True
        p = sim.particles
        wall_moved = 0.0
        if sim.wall_rows.shape[0]:
            shift = sim.wall_rows[:, wall_cols.COL_POINT : wall_cols.COL_POINT + 3]
            wall_moved = float(np.sqrt(((shift - self.wall_reference) ** 2).sum(axis=1)).max())
        if self._sim_builds == sim.rebuild_count and sim.owned_count == p.count:
            # no pass of its own while the bed hardly moves: |x - x_set| <= |x - x_sim| +
            # |x_set - x_sim| <= sim.moved now + sim.moved at the build (x_sim: the positions
            # at the simulation's last list build, which came before this set's build); the
            # exact displacement below decides when this bound is too large, so the decisions
            # are those of the exact test
            bound = sim.moved + self._sim_moved
            if not (2.0 * bound > self.skin or bound + wall_moved > self.skin):
                self.moved = bound
                self.bounded += 1
                return False
        rows = p.count // heat_terms.PARTICLE_CHUNK + 1
        if self._part.shape[0] < rows:
            self._part = np.zeros(rows)
        moved = heat_terms.largest_displacement(
            p.position, self.reference, sim.lower, sim.upper, sim.periodic, self._part
        )
        self.moved = float(moved)
        return 2.0 * moved > self.skin or moved + wall_moved > self.skin

    def build(self, sim: Simulation, gap: float, wall_gap: float) -> None:
        """List the pairs within ``gap`` + skin and the wall pairs within ``wall_gap`` + skin."""
        p = sim.particles
        n = p.count
        self.gap = float(gap)
        self.wall_gap = float(wall_gap)
        self.skin = float(
            self.requested_skin if self.requested_skin is not None else sim.skin or 0.0
        )
        self.builds += 1
        self.valid = True
        self.moved = 0.0
        self._sim_builds = sim.rebuild_count
        self._sim_moved = float(sim.moved)
        self.reference = p.position.copy()
        self.wall_reference = sim.wall_rows[:, wall_cols.COL_POINT : wall_cols.COL_POINT + 3].copy()
        if n == 0:
            self.count = self.wall_count = 0
            self.group_start = np.zeros(2, np.int64)
            self.wall_row_start = np.zeros(1, np.int64)
            return
        r_max = sim.radius_max()  # (every rank's: the check below agrees on all ranks)
        cell = 2.0 * r_max + self.gap + self.skin
        length = sim.upper - sim.lower
        for a in range(3):
            if sim.periodic[a] and length[a] < 2.0 * cell:
                raise SimulationError(
                    f"periodic axis {'xyz'[a]}: domain length {length[a]:.6g} m is shorter than "
                    f"twice the thermal range cut-off {cell:.6g} m (2 R_max + largest conducting "
                    f"gap {self.gap:.6g} m + skin {self.skin:.6g} m); reduce the models' range "
                    "(thermal.indirect_conduction parameters) or enlarge the domain",
                    sim.step_count,
                    sim.time,
                )
        # the region of the particles (the domain; on several MPI ranks this rank's box and
        # its halo, periodic only where the halo wraps: Simulation.grid_box)
        lower, upper, periodic = sim.grid_box()
        dims, edge = nbr.cell_grid(lower, upper, cell, periodic)
        if getattr(sim, "planar", False):  # 2D: one cell layer along z (as the contact list)
            dims[2] = 1
            edge[2] = upper[2] - lower[2]
        # the slab axis of the contact list: the particles lie in memory by layers along it,
        # so each group of this set touches a compact block of memory (see below)
        axis = getattr(sim, "slab_axis", None)
        if axis is None:
            axis = int(slabs.choose_axis(p.position, lower, edge, dims))
        axes = np.array([axis, *(a for a in range(3) if a != axis)], np.int64)
        order = np.empty(n, np.int32)
        cell_start = np.zeros(int(dims[0] * dims[1] * dims[2]) + 1, np.int64)
        nbr.sort_by_cell(p.position, lower, edge, dims, axes, order, cell_start)
        # the pairs are found among cell-sorted copies, then mapped back to particle indices
        position = np.ascontiguousarray(p.position[order])
        radius = np.ascontiguousarray(p.radius[order])
        global_id = np.ascontiguousarray(p.global_id[order])
        new_i, new_j = self.i, self.j
        while True:
            count = nbr.build_pairs(
                position, radius, global_id, lower, upper, periodic, dims, edge, axes,
                cell_start, self.gap, self.skin, new_i, new_j,
            )  # fmt: skip
            if count <= new_i.shape[0]:
                break
            new_i = np.empty(PairBuffers.grown(new_i.shape[0], count), np.int32)
            new_j = np.empty_like(new_i)
        del position, radius, global_id, cell_start
        new_i[:count] = order[new_i[:count]]
        new_j[:count] = order[new_j[:count]]
        del order
        own = sim.owned_count
        if own < n:  # several MPI ranks: a pair of two ghosts is another rank's
            keep = np.nonzero((new_i[:count] < own) | (new_j[:count] < own))[0]
            count = keep.shape[0]
            new_i[:count] = new_i[keep]
            new_j[:count] = new_j[keep]
            del keep
        nlayers = slabs.layer_count(int(dims[axis]), bool(periodic[axis]))
        group_start = np.zeros(nlayers + 1, np.int64)
        args = (p.position, lower, edge, dims, axis, nlayers, new_i, new_j, count, group_start)
        if not slabs.group_pairs(*args):
            sorted_i, sorted_j = np.empty_like(new_i), np.empty_like(new_j)
            slabs.sort_pairs_by_group(*args, sorted_i, sorted_j, np.empty(count, np.int32))
            new_i, new_j = sorted_i, sorted_j
        # within each group, pairs in the order of their lower particle index: the pass then
        # walks the particle arrays forwards (found in this set's own cell order, consecutive
        # pairs were ~250 particles apart in memory: a cache miss per pair)
        nbr_order_within_groups(new_i, new_j, count, group_start)
        self.i, self.j, self.count, self.group_start = new_i, new_j, count, group_start
        # particle-wall pairs, grouped by particle
        if self.wall_row_start.shape[0] != n + 1:
            self.wall_row_start = np.zeros(n + 1, np.int64)
        while True:  # (of the owned particles: on several MPI ranks the ghosts have none)
            wcount = nbr.build_wall_pairs(
                p.position[:own], p.radius[:own], sim.wall_kind, sim.wall_rows, self.wall_gap,
                self.skin, self.wall_i, self.wall_w, self.wall_row_start[: own + 1],
            )  # fmt: skip
            if wcount <= self.wall_i.shape[0]:
                break
            self.wall_i = np.empty(PairBuffers.grown(self.wall_i.shape[0], wcount), np.int32)
            self.wall_w = np.empty_like(self.wall_i)
        self.wall_row_start[own + 1 :] = wcount
        self.wall_count = wcount

    # ------------------------------------------------------------------------ checkpoints
    def state_dict(self) -> dict[str, Any]:
        arrays = {
            "i": self.i[: self.count].copy(),
            "j": self.j[: self.count].copy(),
            "group_start": self.group_start.copy(),
            "reference": self.reference.copy(),
            "wall_i": self.wall_i[: self.wall_count].copy(),
            "wall_w": self.wall_w[: self.wall_count].copy(),
            "wall_row_start": self.wall_row_start.copy(),
            "wall_reference": self.wall_reference.copy(),
        }
        scalars = {name: _plain(getattr(self, name)) for name in STATE_SCALARS}
        return {"scalars": scalars, "arrays": arrays}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        s, a = state["scalars"], state["arrays"]
        self._sim_builds = -1  # (the exact displacement until the next build)
        for name in STATE_SCALARS:
            setattr(self, name, s[name])
        self.count, self.wall_count = int(self.count), int(self.wall_count)
        self.valid = bool(self.valid)
        self.i = _buffer(a["i"])
        self.j = _buffer(a["j"])
        self.group_start = np.array(a["group_start"], np.int64)
        self.reference = np.array(a["reference"], np.float64).reshape(-1, 3)
        self.wall_i = _buffer(a["wall_i"])
        self.wall_w = _buffer(a["wall_w"])
        self.wall_row_start = np.array(a["wall_row_start"], np.int64)
        self.wall_reference = np.array(a["wall_reference"], np.float64).reshape(-1, 3)


def nbr_order_within_groups(
    pair_i: np.ndarray, pair_j: np.ndarray, count: int, group_start: np.ndarray
) -> None:
    """Sort the pairs of each group (in place) by their lower particle index (stable;
    :func:`thermodem.kernels.slabs.order_within_groups`)."""
    if count == 0:
        return
    slabs.order_within_groups(pair_i, pair_j, count, group_start)


def _buffer(values: Any) -> np.ndarray:
    """An int32 index buffer holding ``values`` (at least 16 slots)."""
    values = np.asarray(values, np.int32)
    out = np.zeros(max(values.shape[0], 16), np.int32)
    out[: values.shape[0]] = values
    return out


def _plain(value: Any) -> Any:
    return value.item() if isinstance(value, np.generic) else value
