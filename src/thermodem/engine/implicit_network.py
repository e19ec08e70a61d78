"""The conductance network's data types and assembly for the implicit schemes
(``engine/implicit.py``): the network of one state, the rates the ledger needs, the solve
timings, the pair lists read from the engine's last evaluation and the sparse Laplacian."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

if TYPE_CHECKING:
    from thermodem.engine.thermal import ThermalEngine


@dataclass
class Network:
    """The linearised conductance network of one state."""

    conductance: sp.csr_matrix  # K = L(H) + diag(D) [W/K]
    rhs: np.ndarray  # b [W]
    fixed: np.ndarray  # Dirichlet rows (fixed-temperature particles)
    temperature: np.ndarray  # the state's temperatures (fixed ones at their bath value)


@dataclass
class Rates:
    """What the ledger needs from the heat rates of one state."""

    boundary: np.ndarray  # Σ_i Q_i,m for every boundary column m [W]
    absorbed: float  # Σ over fixed particles of Q_i [W]
    heat_rate: np.ndarray  # Q_i [W]
    temperature: np.ndarray
    time: float


@dataclass
class Timings:
    """Cumulative wall-clock seconds and counts of the implicit solves."""

    assembly: float = 0.0
    preconditioner: float = 0.0
    solve: float = 0.0
    evaluation: float = 0.0
    setups: int = 0
    solves: int = 0
    cg_iterations: int = 0
    picard_iterations: int = 0
    extra: dict = field(default_factory=dict)


_BLAS: list = []  # the threadpoolctl controller (its library scan costs ~2 ms a call)


def serial_blas() -> contextlib.AbstractContextManager:
    """BLAS on one thread for the solves (``implicit_solve.SparseSolve._solve`` says why)."""
    if not _BLAS:
        from threadpoolctl import ThreadpoolController

        _BLAS.append(ThreadpoolController())  # (numpy's and scipy's BLAS are loaded by now)
    return _BLAS[0].limit(limits=1, user_api="blas")


def pair_lists(engine: ThermalEngine) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, H) of every pair of every term at the engine's last evaluation (the arrays its
    kernels stored; pairs may repeat across terms: the matrix sums them)."""
    sim = engine.sim
    parts_i, parts_j, parts_h = [], [], []
    pb = sim.pairs
    if engine.contact.active and pb.count:
        parts_i.append(pb.i[: pb.count])
        parts_j.append(pb.j[: pb.count])
        parts_h.append(engine.pair_conductance[: pb.count])
    for index, term in enumerate(engine.terms):
        if term.target == "range":
            s = engine.range_set
            n = s.count
        elif term.target == "contacts":
            s, n = pb, pb.count
        elif term.target == "external":
            s = engine.external
            n = s.count
        else:
            continue
        if n:
            parts_i.append(s.i[:n])
            parts_j.append(s.j[:n])
            parts_h.append(engine.term_conductance[index][:n])
    if not parts_i:
        empty = np.zeros(0, np.int64)
        return empty, empty, np.zeros(0)
    i = np.concatenate(parts_i).astype(np.int64)
    j = np.concatenate(parts_j).astype(np.int64)
    h = np.concatenate(parts_h)
    keep = h != 0.0
    return i[keep], j[keep], h[keep]


def laplacian(
    n: int, i: np.ndarray, j: np.ndarray, h: np.ndarray, diag: np.ndarray
) -> sp.csr_matrix:
    """L(H) + diag(diag) as CSR: off-diagonal -H_ij (both triangles), diagonal ΣH + diag."""
    ar = np.arange(n, dtype=np.int64)
    pair_sum = np.bincount(i, h, n) + np.bincount(j, h, n)
    rows = np.concatenate([i, j, ar])
    cols = np.concatenate([j, i, ar])
    data = np.concatenate([-h, -h, pair_sum + diag])
    return sp.coo_matrix((data, (rows, cols)), shape=(n, n)).tocsr()
