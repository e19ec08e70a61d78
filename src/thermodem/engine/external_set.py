"""The external pair set: pairs given from outside the engine, with per-pair inputs.

Some thermal models do not run on pairs within a distance but on the pairs of a geometric
construction, with inputs per pair: the Voronoi models need the neighbours of a tessellation
and the area of their shared face. A provider (a tessellation, a user script through
:meth:`ExternalPairSet.set_pairs`) gives the pairs by **global id** with an input row each;
the set keeps them by global id, so they survive the contact list's rebuilds (which reorder
the particles): after a reorder the particle indices are recomputed from the ids, the input
rows stay with their pairs.

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
        self.valid = True

    def state_dict(self) -> dict[str, Any]:
        return {
            "scalars": {"input_width": self.input_width, "updates": self.updates},
            "arrays": {"gid_i": self.gid_i, "gid_j": self.gid_j, "inputs": self.inputs},
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.input_width = int(state["scalars"]["input_width"])
        self.updates = int(state["scalars"]["updates"])
        a = state["arrays"]
        self.gid_i = np.array(a["gid_i"], np.int64)
        self.gid_j = np.array(a["gid_j"], np.int64)
        self.inputs = np.array(a["inputs"], np.float64).reshape(self.count, self.input_width)
        self.valid = False
