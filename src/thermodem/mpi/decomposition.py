"""Recursive coordinate bisection (RCB) of the domain by particle count.

The domain box is cut in two along its longest axis at the coordinate that splits its
particles in proportion to the ranks on each side (P // 2 : P - P // 2), and each half is cut
again the same way until every rank has one box. The boxes tile the domain; a particle
belongs to the box that contains it (a particle on a cut belongs to the upper side).

The cut coordinates are found by bisection on the coordinate with the global count below it
from an ``Allreduce`` per iteration (all the cuts of one tree level in one reduction), so no
rank ever holds the positions of another; every rank computes the same cuts from the same
integer sums. A cut stops as soon as its count is the target, or after :data:`MAX_ITERATIONS`
halvings (then the closest count found is used, an imbalance of the few particles that share a
coordinate to 2^-60 of the box).

:class:`Decomposition` holds the tree (for the owner of a position, by descending it) and the
boxes (for the halo: which ranks are within the interaction range of which).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from thermodem.kernels.halo import owner_ranks

MAX_ITERATIONS = 60


@dataclass
class Decomposition:
    """The RCB tree and the box of every rank.

    Node k: ``axis[k]``, ``cut[k]``, children ``left[k]``, ``right[k]``; a child < 0 is the
    leaf of rank ``-child - 1``. ``boxes[r]`` = (lower, upper) of rank r, shape (P, 2, 3).
    """

    axis: np.ndarray
    cut: np.ndarray
    left: np.ndarray
    right: np.ndarray
    boxes: np.ndarray

    @property
    def size(self) -> int:
        return int(self.boxes.shape[0])

    def owner(self, position: np.ndarray) -> np.ndarray:
        """The rank whose box contains each position (int64, vectorised descent)."""
        n = position.shape[0]
        if self.axis.shape[0] == 0:  # one rank
            return np.zeros(n, np.int64)
        rank = np.empty(n, np.int64)
        owner_ranks(np.ascontiguousarray(position), np.ascontiguousarray(self.axis, np.int64),
                    np.ascontiguousarray(self.cut, np.float64),
                    np.ascontiguousarray(self.left, np.int64),
                    np.ascontiguousarray(self.right, np.int64), rank)  # fmt: skip
        return rank

    def rotated(self, shift: int) -> Decomposition:
        """The same boxes handed to other ranks: box r to rank (r + shift) mod P (tests use it
        to make every particle migrate at every rebuild)."""
        size = self.size

        def relabel(child: np.ndarray) -> np.ndarray:
            leaf = child < 0
            out = child.copy()
            out[leaf] = -((-child[leaf] - 1 + shift) % size) - 1
            return out

        boxes = np.empty_like(self.boxes)
        boxes[(np.arange(size) + shift) % size] = self.boxes
        return Decomposition(self.axis, self.cut, relabel(self.left), relabel(self.right), boxes)

    def state(self) -> dict[str, Any]:
        return {
            "axis": self.axis.tolist(),
            "cut": self.cut.tolist(),
            "left": self.left.tolist(),
            "right": self.right.tolist(),
            "boxes": self.boxes.tolist(),
        }


def bisect(
    comm: Any,
    position: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    size: int,
    planar: bool = False,
) -> Decomposition:
    """RCB of the box [lower, upper] into ``size`` boxes, balancing the particles whose
    positions are ``position`` on this rank (and their counterparts on the others); a
    collective call (``comm``: an mpi4py communicator, or None for one process). ``planar``
    (discs in the plane z = 0): cut along x and y only."""
    from thermodem.mpi.exchange import allreduce_sum

    lower = np.asarray(lower, np.float64)
    upper = np.asarray(upper, np.float64)
    nodes = 2 * size  # more than enough (size - 1 internal nodes)
    axis = np.zeros(nodes, np.int64)
    cut = np.zeros(nodes)
    left = np.zeros(nodes, np.int64)
    right = np.zeros(nodes, np.int64)
    boxes = np.zeros((size, 2, 3))
    # the open nodes of the current level: (node id, lower, upper, first rank, ranks)
    n_local = position.shape[0]
    member = np.zeros(n_local, np.int64)  # the open node of each local particle
    total = int(allreduce_sum(comm, np.array([n_local], np.int64))[0])
    level = [(0, lower.copy(), upper.copy(), 0, size, total)]
    next_node = 1
    if size == 1:
        boxes[0, 0], boxes[0, 1] = lower, upper
        return Decomposition(axis[:0], cut[:0], left[:0], right[:0], boxes)
    while level:
        m = len(level)
        cut_axes = 2 if planar else 3
        ax = np.array(
            [int(np.argmax((hi - lo)[:cut_axes])) for _, lo, hi, _, _, _ in level], np.int64
        )
        a = np.array([lo[ax[q]] for q, (_, lo, _, _, _, _) in enumerate(level)])
        b = np.array([hi[ax[q]] for q, (_, _, hi, _, _, _) in enumerate(level)])
        target = np.array([cnt * (r // 2) // r for _, _, _, _, r, cnt in level], np.int64)
        found = np.zeros(m, np.bool_)
        best = 0.5 * (a + b)
        best_err = np.full(m, np.iinfo(np.int64).max)
        lut = np.full(nodes, -1, np.int64)
        lut[[node for node, *_rest in level]] = np.arange(m)
        local_q = np.where(member >= 0, lut[member.clip(0)], -1)
        active = np.nonzero(local_q >= 0)[0]  # (particles of the boxes still being cut)
        active_q = local_q[active]
        coord = np.zeros(n_local)
        coord[active] = position[active, ax[active_q]]
        for _ in range(MAX_ITERATIONS):
            mid = np.where(found, best, 0.5 * (a + b))
            below = np.zeros(m, np.int64)
            if active.shape[0]:
                np.add.at(below, active_q, coord[active] < mid[active_q])
            below = allreduce_sum(comm, below)
            err = np.abs(below - target)
            better = (err < best_err) & ~found
            best = np.where(better, mid, best)
            best_err = np.where(better, err, best_err)
            found |= err == 0
            if found.all():
                break
            high = below > target
            b = np.where(~found & high, mid, b)
            a = np.where(~found & ~high, mid, a)
        new_level = []
        side = member.copy()  # (particles in a finished box keep its leaf)
        for q, (node, lo, hi, first, ranks, _count) in enumerate(level):
            c = float(best[q])
            axis[node], cut[node] = ax[q], c
            nleft = ranks // 2
            children = []
            for half, (r0, nr) in enumerate(((first, nleft), (first + nleft, ranks - nleft))):
                clo, chi = lo.copy(), hi.copy()
                if half == 0:
                    chi[ax[q]] = c
                else:
                    clo[ax[q]] = c
                if nr == 1:
                    boxes[r0, 0], boxes[r0, 1] = clo, chi
                    children.append(-r0 - 1)
                else:
                    k = next_node
                    next_node += 1
                    children.append(k)
                    new_level.append((k, clo, chi, r0, nr, 0))
            left[node], right[node] = children
            # move each local particle of this node to its child
            mine = local_q == q
            if n_local:
                up = coord >= c
                side[mine & ~up] = children[0]
                side[mine & up] = children[1]
        member = side if n_local else member
        # exact counts of the new open nodes
        if new_level:
            lut = np.full(nodes, -1, np.int64)
            lut[[k for k, *_rest in new_level]] = np.arange(len(new_level))
            open_q = np.where(member >= 0, lut[member.clip(0)], -1)
            counts = np.bincount(open_q[open_q >= 0], minlength=len(new_level)).astype(np.int64)
            counts = allreduce_sum(comm, counts)
            new_level = [
                (k, lo, hi, r0, nr, int(counts[e]))
                for e, (k, lo, hi, r0, nr, _) in enumerate(new_level)
            ]
        level = new_level
    used = next_node
    return Decomposition(axis[:used], cut[:used], left[:used], right[:used], boxes)


def box_distance(
    lo_a: np.ndarray,
    hi_a: np.ndarray,
    lo_b: np.ndarray,
    hi_b: np.ndarray,
    length: np.ndarray,
    periodic: np.ndarray,
) -> float:
    """Smallest distance between two axis-aligned boxes (periodic images on periodic axes)."""
    d2 = 0.0
    for a in range(3):
        shifts = (-length[a], 0.0, length[a]) if periodic[a] else (0.0,)
        best = np.inf
        for s in shifts:
            gap = max(0.0, lo_b[a] + s - hi_a[a], lo_a[a] - hi_b[a] - s)
            best = min(best, gap)
        d2 += best * best
    return float(np.sqrt(d2))


def point_box_distance(
    position: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    length: np.ndarray,
    periodic: np.ndarray,
) -> np.ndarray:
    """Distance of each position to the box [lo, hi] (periodic images on periodic axes)."""
    d2 = np.zeros(position.shape[0])
    for a in range(3):
        x = position[:, a]
        gap = np.maximum(np.maximum(lo[a] - x, x - hi[a]), 0.0)
        if periodic[a]:
            for s in (-length[a], length[a]):
                xs = x + s
                gap = np.minimum(gap, np.maximum(np.maximum(lo[a] - xs, xs - hi[a]), 0.0))
        d2 += gap * gap
    return np.sqrt(d2)
