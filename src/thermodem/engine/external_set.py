"""The external pair set: pairs given from outside the engine, with per-pair inputs.

Some thermal models do not run on pairs within a distance but on the pairs of a geometric
construction, with inputs per pair: the Voronoi models need the neighbours of a tessellation
and the area of their shared face. A provider (a tessellation, a user script through
:meth:`ExternalPairSet.set_pairs`) gives the pairs by **global id** with an input row each;
the set keeps them by global id, so they survive the contact list's rebuilds (which reorder
the particles): after a reorder the particle indices are recomputed from the ids, the input
rows stay with their pairs. It may also hold particle-wall pairs (a particle's global id, a
wall row and an input row: the Voronoi cells' faces on walls), summed per particle.

Its pairs are not bounded by a cell edge, so slab colouring does not apply: a term on it
writes one conductance per pair (a parallel pass over pairs), then every particle sums its
own pairs through a CSR index in pair order (a parallel pass over particles; the same pair
value is added to i and subtracted from j, so what i gains j loses exactly, and the sums do
not depend on the number of threads). The CSR index is rebuilt when the pairs or the
particle order change.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import SimulationError
from thermodem.kernels import heat_terms

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


class ExternalPairSet:
    """Pairs by global id with a row of inputs each (see the module docstring)."""

    def __init__(self, input_width: int = 0) -> None:
        self.input_width = int(input_width)
        self.gid_i = np.zeros(0, np.int64)
        self.gid_j = np.zeros(0, np.int64)
        self.inputs = np.zeros((0, self.input_width))
        self.i = np.zeros(0, np.int32)
        self.j = np.zeros(0, np.int32)
        self.offsets = np.zeros(1, np.int64)  # CSR: pairs of each particle
        self.entries = np.zeros(0, np.int64)  # pair index × 2 + (0: as i, 1: as j)
        self.valid = False
        self.updates = 0
        # particle-wall pairs: global id, wall row, inputs; by particle after prepare()
        self.wall_gid = np.zeros(0, np.int64)
        self.wall_w = np.zeros(0, np.int32)
        self.wall_inputs = np.zeros((0, self.input_width))
        self.wall_i = np.zeros(0, np.int32)
        self.wall_offsets = np.zeros(1, np.int64)  # wall pairs of particle a: [o[a], o[a+1])

    @property
    def wall_count(self) -> int:
        return int(self.wall_gid.shape[0])

    def set_wall_pairs(self, gid: Any, wall: Any, inputs: Any = None) -> None:
        """Replace the particle-wall pairs: a particle's global id, a wall row index and an
        input row per pair (kept in the order given within each particle)."""
        gid = np.asarray(gid, np.int64).ravel()
        wall = np.asarray(wall, np.int32).ravel()
        if gid.shape != wall.shape:
            raise ValueError(f"gid and wall differ in length: {gid.size}, {wall.size}")
        rows = np.zeros((gid.size, self.input_width)) if inputs is None else inputs
        rows = np.ascontiguousarray(rows, np.float64).reshape(gid.size, self.input_width)
        order = np.argsort(gid, kind="stable")
        self.wall_gid, self.wall_w, self.wall_inputs = gid[order], wall[order], rows[order]
        self.valid = False
        self.updates += 1

    @property
    def count(self) -> int:
        return int(self.gid_i.shape[0])

    def set_pairs(self, gid_i: Any, gid_j: Any, inputs: Any = None) -> None:
        """Replace the pairs: global ids of the two particles and an input row per pair."""
        gid_i = np.asarray(gid_i, np.int64).ravel()
        gid_j = np.asarray(gid_j, np.int64).ravel()
        if gid_i.shape != gid_j.shape:
            raise ValueError(f"gid_i and gid_j differ in length: {gid_i.size}, {gid_j.size}")
        if np.any(gid_i == gid_j):
            raise ValueError("a pair of the external set joins a particle with itself")
        rows = np.zeros((gid_i.size, self.input_width)) if inputs is None else inputs
        rows = np.ascontiguousarray(rows, np.float64).reshape(gid_i.size, self.input_width)
        # oriented by global id, like the other pair lists
        swap = gid_i > gid_j
        self.gid_i = np.where(swap, gid_j, gid_i)
        self.gid_j = np.where(swap, gid_i, gid_j)
        self.inputs = rows
        self.valid = False
        self.updates += 1

    def invalidate(self) -> None:
        """The particles were reordered or inserted: recompute indices and the CSR index."""
        self.valid = False

    def prepare(self, sim: Simulation) -> None:
        """Particle indices of the pairs and the CSR index, if the order changed."""
        if self.valid:
            return
        p = sim.particles
        index = np.full(int(p.global_id.max()) + 1 if p.count else 0, -1, np.int64)
        index[p.global_id] = np.arange(p.count)
        bad = (self.gid_i >= index.size) | (self.gid_j >= index.size)
        if not bad.any():
            i, j = index[self.gid_i], index[self.gid_j]
            bad = (i < 0) | (j < 0)
        if bad.any():
            k = int(np.nonzero(bad)[0][0])
            raise SimulationError(
                f"external pair set: pair ({self.gid_i[k]}, {self.gid_j[k]}) names a particle "
                "that does not exist",
                sim.step_count,
                sim.time,
            )
        self.i, self.j = i.astype(np.int32), j.astype(np.int32)
        self.offsets = np.zeros(p.count + 1, np.int64)
        self.entries = np.zeros(2 * self.count, np.int64)
        heat_terms.pair_csr(self.i, self.j, p.count, self.offsets, self.entries)
        # wall pairs by particle index (stable: the given order within a particle)
        wi = index[self.wall_gid] if self.wall_count else np.zeros(0, np.int64)
        if np.any(wi < 0):
            k = int(np.nonzero(wi < 0)[0][0])
            raise SimulationError(
                f"external pair set: wall pair of particle {self.wall_gid[k]}, which does not "
                "exist",
                sim.step_count,
                sim.time,
            )
        order = np.argsort(wi, kind="stable")
        self.wall_gid, self.wall_w = self.wall_gid[order], self.wall_w[order]
        self.wall_inputs = self.wall_inputs[order]
        self.wall_i = wi[order].astype(np.int32)
        self.wall_offsets = np.zeros(p.count + 1, np.int64)
        np.add.at(self.wall_offsets, self.wall_i.astype(np.int64) + 1, 1)
        np.cumsum(self.wall_offsets, out=self.wall_offsets)
        self.valid = True

    def state_dict(self) -> dict[str, Any]:
        return {
            "scalars": {"input_width": self.input_width, "updates": self.updates},
            "arrays": {
                "gid_i": self.gid_i,
                "gid_j": self.gid_j,
                "inputs": self.inputs,
                "wall_gid": self.wall_gid,
                "wall_w": self.wall_w,
                "wall_inputs": self.wall_inputs,
            },  # fmt: skip
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.input_width = int(state["scalars"]["input_width"])
        self.updates = int(state["scalars"]["updates"])
        a = state["arrays"]
        self.gid_i = np.array(a["gid_i"], np.int64)
        self.gid_j = np.array(a["gid_j"], np.int64)
        self.inputs = np.array(a["inputs"], np.float64).reshape(self.count, self.input_width)
        self.wall_gid = np.array(a.get("wall_gid", np.zeros(0)), np.int64)
        self.wall_w = np.array(a.get("wall_w", np.zeros(0)), np.int32)
        self.wall_inputs = np.array(a.get("wall_inputs", np.zeros(0)), np.float64).reshape(
            self.wall_count, self.input_width
        )
        self.valid = False
