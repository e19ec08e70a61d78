"""Pair-list state: indices, contact history and per-pair outputs, with a capacity.

The arrays are indexed by pair; ``count`` of them are in use. History rows are carried across
neighbour rebuilds by particle identity (see :func:`thermodem.kernels.neighbors.carry_history`).

Memory layout (bytes per pair slot, history width W = 6 or 10 with a rolling spring): ``i``,
``j`` int32 (8), ``history`` float64 (8 W), ``scratch`` float64 (8 max(W, 6 or 9)),
``dissipation`` float32 (16), ``normal_force`` (8), ``state`` int8 (1). The per-step outputs
``force``, ``lever`` and (with rolling) ``roll`` are C-contiguous views into ``scratch``: every
pair pass rewrites them, so at a rebuild the same memory receives the carried history (no
permanent spare history). The capacity grows to 1.1 x the count a rebuild needed, never shrinks.
"""

from __future__ import annotations

import numpy as np

from thermodem.kernels import contact as C

#: Capacity margin over the number of pairs a rebuild found.
GROWTH = 1.1


class PairBuffers:
    """Pair-list arrays with a capacity; grown (never shrunk) when a rebuild needs more."""

    def __init__(self, capacity: int, history_width: int, with_roll: bool) -> None:
        self.count = 0
        self.history_width = history_width
        self.with_roll = with_roll
        self.allocate(capacity)

    def allocate(self, capacity: int) -> None:
        """Fresh arrays of ``capacity`` slots (contents zero, count unchanged)."""
        capacity = max(int(capacity), 16)
        self.capacity = capacity
        self.i = np.zeros(capacity, np.int32)
        self.j = np.zeros(capacity, np.int32)
        self.history = np.zeros((capacity, self.history_width))
        self.scratch = np.zeros(capacity * self.scratch_width())
        self._output_views()
        self.dissipation = np.zeros((capacity, 4), np.float32)
        self.normal_force = np.zeros(capacity)
        self.state = np.zeros(capacity, np.int8)
        self.chunk_ledger = np.zeros((capacity // C.CHUNK + 2, C.LEDGER_WIDTH))

    def scratch_width(self) -> int:
        """Floats per slot of the scratch block: the history width, and at least the outputs
        (force, lever: 6; with a rolling torque: 9)."""
        return max(self.history_width, 9 if self.with_roll else 6)

    def _output_views(self) -> None:
        cap, s = self.capacity, self.scratch
        self.force = s[: 3 * cap].reshape(cap, 3)
        self.lever = s[3 * cap : 6 * cap].reshape(cap, 3)
        self.roll = s[6 * cap : 9 * cap].reshape(cap, 3) if self.with_roll else np.zeros((0, 3))

    def spare_history(self) -> np.ndarray:
        """The scratch memory as a (capacity, W) history table (valid until the next pass)."""
        cap, width = self.capacity, self.history_width
        return self.scratch[: cap * width].reshape(cap, width)

    def swap_history(self) -> None:
        """After the carried history was written into :meth:`spare_history`: make it the
        history, and the old history memory the scratch space of the outputs."""
        new = self.spare_history()
        if self.scratch_width() == self.history_width:
            self.scratch = self.history.reshape(-1)  # the two blocks swap roles
        else:  # scratch wider than history (constant-torque rolling): give it a fresh block
            self.scratch = np.zeros(self.capacity * self.scratch_width())
        self.history = new
        self._output_views()

    @staticmethod
    def grown(capacity: int, needed: int) -> int:
        """The capacity to allocate when ``needed`` slots do not fit in ``capacity``."""
        return max(int(needed * GROWTH) + 16, capacity)
