"""The sparse linear solve of the implicit heat schemes: δ with (A δ)_free = r_free, δ = 0 on
the fixed rows, for A = K + C/(θΔt) of a step or K of the steady state
(``engine/implicit.py``).

A sparse direct solve below ``direct_below`` unknowns, else conjugate gradients
preconditioned by smoothed-aggregation algebraic multigrid (``pyamg``; Ruge & Stüben 1987,
Vaněk, Mandel & Brezina 1996) or by the diagonal (``thermal.implicit.preconditioner``:
``jacobi``; ``auto``, the default: the diagonal for a time step whose capacity term bounds
the condition number by :data:`AUTO_CONDITION`, multigrid otherwise). The free block of K,
the step's matrix K_ff + C'/(θΔt) (its diagonal updated in place) and the multigrid hierarchy
are kept while they do not change (constant properties: one free block per run).

A time step's solution is corrected so that its residual sums to zero over the free
particles: the energy that the step's ledger counts is then exactly the change of Σ C T,
whatever the solver's tolerance.

A mixin of :class:`thermodem.engine.implicit.ImplicitSolver` (split from that module by
concern).
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from thermodem.errors import SimulationError

#: ``preconditioner: auto`` takes the diagonal while its bound on the condition number of a
#: time step's system is at most this (measured on the 50k bed: CG with the diagonal needs
#: ~7 √κ iterations to 1e-10; one pyamg V-cycle costs ~35 of its iterations)
AUTO_CONDITION = 1000.0


def conjugate_gradients(
    a: sp.csr_matrix,
    b: np.ndarray,
    preconditioner: np.ndarray | Callable[[np.ndarray], np.ndarray],
    stop: float,
    max_iterations: int,
    weight: np.ndarray | None = None,
    bound: float = 0.0,
) -> tuple[np.ndarray, int, bool]:
    """x with a x ≈ b by preconditioned conjugate gradients from x = 0 (Hestenes & Stiefel
    1952; the preconditioned form: Saad 2003, *Iterative Methods for Sparse Linear Systems*,
    2nd ed., Algorithm 9.1). ``preconditioner``: the inverse diagonal (Jacobi) or a function
    z = M⁻¹ r. Stops when ‖r‖₂ ≤ ``stop`` or, with ``weight``, when Σ wᵢ rᵢ² ≤ ``bound``.
    Returns (x, iterations, converged).

    The weighted test bounds the error of a time step's solve: with a = C' + K_ff, C' the
    capacity term C/(θΔt) and K_ff positive semi-definite, the error e = a⁻¹ r satisfies
    eᵀ C' e ≤ eᵀ a e = rᵀ a⁻¹ r ≤ rᵀ C'⁻¹ r, so with w = 1/C' and bound = ε² ΣC' the
    capacity-weighted RMS of the error is ≤ ε [K].

    Written out rather than ``scipy.sparse.linalg.cg`` for the second test and for vectors
    updated in place (one product by ``a``, one preconditioner application, two dot products
    per iteration); deterministic with BLAS on one thread.
    """
    x = np.zeros_like(b)
    r = b.copy()
    work = np.empty_like(b)
    stop2 = stop * stop

    def done() -> bool:
        if float(r @ r) <= stop2:
            return True
        if weight is None:
            return False
        np.multiply(r, weight, out=work)
        return float(work @ r) <= bound

    if done():
        return x, 0, True
    jacobi = isinstance(preconditioner, np.ndarray)
    z = preconditioner * r if jacobi else preconditioner(r)
    p = z.copy()
    rz = float(r @ z)
    for iteration in range(1, max_iterations + 1):
        q = a @ p
        alpha = rz / float(p @ q)
        np.multiply(p, alpha, out=work)
        x += work
        q *= alpha
        r -= q
        if done():
            return x, iteration, True
        if jacobi:
            np.multiply(preconditioner, r, out=z)
        else:
            z = preconditioner(r)
        rz_next = float(r @ z)
        p *= rz_next / rz
        p += z
        rz = rz_next
    return x, max_iterations, False


@dataclass
class StepBlock:
    """The free block of a time step's matrix and what its solves need of it."""

    matrix: sp.csr_matrix  # a = K_ff + diag(C')
    capacity: np.ndarray  # C' of the free particles
    source: np.ndarray  # the capacity array (all particles) it was made from
    inverse: np.ndarray  # 1/aᵢᵢ (Jacobi)
    weight: np.ndarray  # 1/C'ᵢ (the error bound)
    capacity_sum: float  # ΣC'
    row_sum: float  # Σ (a 1)ᵢ (the conservative correction)
    condition: float  # the bound 2 max aᵢᵢ/C'ᵢ on κ(D⁻¹a)

    @classmethod
    def of(cls, k_ff: sp.csr_matrix, on_diagonal: np.ndarray | None, k_diagonal: np.ndarray,
           k_rows: np.ndarray, c: np.ndarray, source: np.ndarray) -> StepBlock:  # fmt: skip
        diagonal = k_diagonal + c
        if on_diagonal is not None:  # (K_ff's index arrays shared)
            data = k_ff.data.copy()
            data[on_diagonal] = diagonal
            a = sp.csr_matrix((data, k_ff.indices, k_ff.indptr), shape=k_ff.shape, copy=False)
        else:
            a = (k_ff + sp.diags(c)).tocsr()
        # κ(D⁻¹a) ≤ 2 max aᵢᵢ/C'ᵢ: Gershgorin bounds D⁻¹a's spectrum by 2 above (a
        # diagonally dominant M-matrix) and a ≥ C' by min C'ᵢ/aᵢᵢ below
        return cls(a, c, source, 1.0 / diagonal, 1.0 / c, float(c.sum()),
                   float(k_rows.sum() + c.sum()), 2.0 * float(np.max(diagonal / c)))  # fmt: skip


class SparseSolve:
    """The linear solves of the implicit solver (see the module docstring)."""

    # ---------------------------------------------------------------------- linear solve
    def _solve(
        self,
        matrix: sp.csr_matrix,
        residual: np.ndarray,
        fixed: np.ndarray,
        reference: float | None = None,
        capacity: np.ndarray | None = None,
        accuracy: float | None = None,
    ) -> np.ndarray:
        """δ with ((matrix + diag(capacity)) δ)_free = residual_free, δ = 0 on the fixed rows.

        ``matrix``: K (kept as the same object while it does not change). ``reference``: the
        residual norm the relative tolerance refers to (default: that of ``residual``).
        ``capacity``: the capacity term C/(θΔt) of a time step (None: the steady state); the
        solution is then corrected so that the residual sums to zero over the free particles
        (the ledger closes whatever the tolerance) and, with ``accuracy`` [K], the iteration
        also stops when its error bound (:func:`conjugate_gradients`) is below it.

        BLAS runs on one thread (the callers' ``ImplicitSolver.serial``): the vectors are
        short (a dot product of 50,000 values takes microseconds), threads of OpenBLAS only
        contend with the Numba pool (measured: 4× slower CG on the 2-core machine), and one
        thread fixes the order of the reductions, so the results do not depend on the
        machine's BLAS thread count.
        """
        n = matrix.shape[0]
        delta = np.zeros(n)
        free = ~fixed
        if not free.any():
            return delta
        t0 = _time.perf_counter()
        block = None
        if capacity is None:
            a = self._free_block(matrix, fixed)
        else:
            block = self._step_block(matrix, fixed, capacity)
            a = block.matrix
        r = residual[free]
        norm = float(np.sqrt(r @ r))
        if norm == 0.0:
            return delta
        if a.shape[0] < self.direct_below:
            delta[free] = spla.spsolve(a.tocsc(), r)
            self.timings.solve += _time.perf_counter() - t0
            self.timings.solves += 1
            return delta
        choice = self.options.preconditioner
        if choice == "auto":
            choice = "jacobi" if block is not None and block.condition <= AUTO_CONDITION else "amg"
        if choice == "jacobi":
            preconditioner = block.inverse if block is not None else 1.0 / a.diagonal()
        else:
            preconditioner = self._preconditioner(a).matvec
        t1 = _time.perf_counter()
        self.timings.assembly += t1 - t0
        # relative to the residual of the stage's start (a warm start keeps that scale)
        stop = self.options.tolerance * (norm if reference is None else reference)
        weight, bound = None, 0.0
        if block is not None and accuracy is not None:
            weight, bound = block.weight, accuracy * accuracy * block.capacity_sum
        x, count, converged = conjugate_gradients(
            a, r, preconditioner, stop, self.options.max_iterations, weight, bound
        )
        if block is not None:
            # the conservative correction: the residual summed over the free particles is
            # the energy that the step's ledger would miss; a uniform shift removes it
            x += float((r - a @ x).sum()) / block.row_sum
        self.timings.solve += _time.perf_counter() - t1
        self.timings.solves += 1
        self.timings.cg_iterations += count
        if not converged:
            achieved = float(np.linalg.norm(r - a @ x)) / norm
            where, step, at = self.failing_step()
            raise SimulationError(
                f"implicit heat solve: conjugate gradients did not reach the relative residual "
                f"thermal.implicit.tolerance = {self.options.tolerance:g} in "
                f"thermal.implicit.max_iterations = {self.options.max_iterations} iterations "
                f"(reached {achieved:.3g}) {where}",
                step,
                at,
                -1,
            )
        delta[free] = x
        return delta

    def _free_block(self, matrix: sp.csr_matrix, fixed: np.ndarray) -> sp.csr_matrix:
        """The rows and columns of the free particles (kept while the matrix is the same
        object and the fixed set the same)."""
        sys = self._system
        if sys is not None and sys[0] is matrix and np.array_equal(sys[1], fixed):
            return sys[2]
        a = matrix[~fixed][:, ~fixed] if fixed.any() else matrix
        a.sort_indices()
        self._system = (matrix, fixed.copy(), a)
        self._step_system = None
        return a

    def _step_block(
        self, conductance: sp.csr_matrix, fixed: np.ndarray, capacity: np.ndarray
    ) -> StepBlock:
        """The free block a = K_ff + diag(C') of a time step, C' the free particles'
        ``capacity``: K_ff is kept (:meth:`_free_block`), a is a copy of it whose diagonal
        entries are overwritten; kept while ``capacity`` is the same array object or equal."""
        k_ff = self._free_block(conductance, fixed)
        base = self._step_system
        if base is None or base[0] is not k_ff:
            coo = k_ff.tocoo()
            on_diagonal = np.flatnonzero(coo.row == coo.col)
            if on_diagonal.shape[0] != k_ff.shape[0]:  # a row without a stored diagonal
                on_diagonal = None
            rows = np.asarray(k_ff.sum(axis=1)).ravel()
            base = (k_ff, on_diagonal, k_ff.diagonal(), rows, None)
        k_ff, on_diagonal, k_diagonal, k_rows, kept = base
        if kept is not None and kept.source is capacity:
            return kept
        c = capacity[~fixed]
        if kept is not None and np.array_equal(kept.capacity, c):
            kept.source = capacity
            return kept
        kept = StepBlock.of(k_ff, on_diagonal, k_diagonal, k_rows, c, capacity)
        self._step_system = (*base[:4], kept)
        return kept

    def _preconditioner(self, a: sp.csr_matrix) -> spla.LinearOperator:
        """Smoothed-aggregation AMG, kept while the matrix is the same (within 10 % per
        entry: a slightly stale hierarchy is still a good preconditioner; CG stays exact)."""
        import pyamg

        key = (a.shape, a.nnz)
        if self._hierarchy is not None and key == self._hierarchy_key:
            old_data, old_indices = self._hierarchy[1], self._hierarchy[2]
            if np.array_equal(old_indices, a.indices) and np.all(
                np.abs(a.data - old_data) <= 0.1 * np.abs(old_data)
            ):
                return self._hierarchy[0].aspreconditioner(cycle="V")
        t0 = _time.perf_counter()
        ml = pyamg.smoothed_aggregation_solver(a, symmetry="symmetric", max_coarse=50)
        self.timings.preconditioner += _time.perf_counter() - t0
        self.timings.setups += 1
        self._hierarchy = (ml, a.data.copy(), a.indices.copy())
        self._hierarchy_key = key
        return ml.aspreconditioner(cycle="V")
