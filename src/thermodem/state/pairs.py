"""Pair-list state: indices, contact history and per-pair outputs, with a capacity.

The arrays are indexed by pair; ``count`` of them are in use. History rows are carried across
neighbour rebuilds by particle identity, in place (see
:func:`thermodem.kernels.neighbors.move_rows`).

Memory layout (bytes per pair slot, history width W from the layout of
:mod:`thermodem.state.history`: 6 for Hertz–Mindlin, 10 with a rolling spring): ``i``,
``j`` int32 (8), ``history`` float64 (8 W), ``normal_force`` (8), ``state`` int8 (1): 65 B
with W = 6. Forces and torques are not stored per pair: the pair passes add them straight into
the particles' arrays (:mod:`thermodem.kernels.slabs`), and neither is the dissipation (the
ledger sums it per slab group; heat generation accumulates it per particle). The
capacity grows to 1.1 x the count a rebuild needed, never shrinks; capacity that is never
written is not resident.

For particle pairs ``group_start`` holds the slab groups of the list (``ngroups + 1``
offsets); for particle-wall pairs the list is grouped by particle (``Simulation.wall_row_start``).
"""

from __future__ import annotations

import numpy as np

from thermodem.kernels import contact as C

#: Capacity margin over the number of pairs a rebuild found.
GROWTH = 1.1


class PairBuffers:
    """Pair-list arrays with a capacity; grown (never shrunk) when a rebuild needs more."""

    def __init__(self, capacity: int, history_width: int) -> None:
        self.count = 0
        self.history_width = history_width
        self.group_start = np.zeros(2, np.int64)
        self.chunk_ledger = np.zeros((1, C.LEDGER_WIDTH))
        self.allocate(capacity)

    @property
    def ngroups(self) -> int:
        return self.group_start.shape[0] - 1

    def allocate(self, capacity: int, keep: int = 0) -> None:
        """Arrays of ``capacity`` slots; the first ``keep`` history rows are kept, the other
        contents are zero (count unchanged)."""
        capacity = max(int(capacity), 16)
        old = getattr(self, "history", None)
        self.capacity = capacity
        self.i = np.zeros(capacity, np.int32)
        self.j = np.zeros(capacity, np.int32)
        self.history = np.zeros((capacity, self.history_width))
        if keep and old is not None:
            self.history[:keep] = old[:keep]
        del old
        self.normal_force = np.zeros(capacity)
        self.state = np.zeros(capacity, np.int8)

    def ledger_rows(self, rows: int) -> np.ndarray:
        """The per-group (or per-chunk) ledger table with at least ``rows`` rows."""
        if self.chunk_ledger.shape[0] < rows:
            self.chunk_ledger = np.zeros((rows, C.LEDGER_WIDTH))
        return self.chunk_ledger

    @staticmethod
    def grown(capacity: int, needed: int) -> int:
        """The capacity to allocate when ``needed`` slots do not fit in ``capacity``."""
        return max(int(needed * GROWTH) + 16, capacity)
