"""Pair-list state: indices, contact history and per-pair outputs, with a capacity.

The arrays are indexed by pair; ``count`` of them are in use. History rows are carried across
neighbour rebuilds by key (see :mod:`thermodem.kernels.neighbors`).
"""

from __future__ import annotations

import numpy as np

from thermodem.kernels import contact as C


class PairBuffers:
    """Pair-list arrays with a capacity; grown (never shrunk) when a rebuild needs more."""

    def __init__(self, capacity: int, history_width: int, with_roll: bool) -> None:
        self.count = 0
        self.history_width = history_width
        self.with_roll = with_roll
        self.allocate(capacity)

    def allocate(self, capacity: int) -> None:
        capacity = max(int(capacity), 16)
        self.capacity = capacity
        self.i = np.zeros(capacity, np.int32)
        self.j = np.zeros(capacity, np.int32)
        self.history = np.zeros((capacity, self.history_width))
        self.spare_history = np.zeros((capacity, self.history_width))
        self.force = np.zeros((capacity, 3))
        self.lever = np.zeros((capacity, 3))
        self.roll = np.zeros((capacity if self.with_roll else 0, 3))
        self.dissipation = np.zeros((capacity, 4))
        self.normal_force = np.zeros(capacity)
        self.state = np.zeros(capacity, np.int8)
        self.key_a = np.zeros(capacity, np.int64)
        self.key_b = np.zeros(capacity, np.int64)
        self.lookup_order = np.zeros(capacity, np.int64)
        self.chunk_ledger = np.zeros((capacity // C.CHUNK + 2, C.LEDGER_WIDTH))

    def grow_keep_history(self, capacity: int) -> None:
        """Grow while keeping the current keys and history (for lookups after the rebuild)."""
        old = (self.history, self.key_a, self.key_b, self.lookup_order, self.count)
        self.allocate(capacity)
        history, key_a, key_b, order, count = old
        self.history[:count] = history[:count]
        self.key_a[:count] = key_a[:count]
        self.key_b[:count] = key_b[:count]
        self.lookup_order[:count] = order[:count]
        self.count = count
