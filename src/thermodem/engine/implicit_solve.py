"""The sparse linear solve of the implicit heat schemes: δ with (A δ)_free = r_free, δ = 0 on
the fixed rows, for A = K + C/(θΔt) of a step or K of the steady state
(``engine/implicit.py``).

A sparse direct solve below ``direct_below`` unknowns, else conjugate gradients
preconditioned by smoothed-aggregation algebraic multigrid (``pyamg``; Ruge & Stüben 1987,
Vaněk, Mandel & Brezina 1996) or by the diagonal (``thermal.implicit.preconditioner:
jacobi``). The free block, the capacity matrix and the multigrid hierarchy are kept while
the matrix does not change (constant properties: one setup per run).

A mixin of :class:`thermodem.engine.implicit.ImplicitSolver` (split from that module by
concern).
"""

from __future__ import annotations

import time as _time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from thermodem.errors import SimulationError


class SparseSolve:
    """The linear solves of the implicit solver (see the module docstring)."""

    # ---------------------------------------------------------------------- linear solve
    def _solve(
        self,
        matrix: sp.csr_matrix,
        residual: np.ndarray,
        fixed: np.ndarray,
        reference: float | None = None,
    ) -> np.ndarray:
        """δ with (matrix δ)_free = residual_free, δ = 0 on the fixed rows.

        BLAS runs on one thread here: the vectors are short (a dot product of 50,000 values
        takes microseconds), threads of OpenBLAS only contend with the Numba pool (measured:
        4× slower CG on the 2-core machine), and one thread fixes the order of the
        reductions, so the results do not depend on the machine's BLAS thread count.
        """
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return self._solve_serial(matrix, residual, fixed, reference)

    def _solve_serial(
        self,
        matrix: sp.csr_matrix,
        residual: np.ndarray,
        fixed: np.ndarray,
        reference: float | None = None,
    ) -> np.ndarray:
        n = matrix.shape[0]
        delta = np.zeros(n)
        free = ~fixed
        if not free.any():
            return delta
        a = self._free_block(matrix, fixed)
        r = residual[free]
        norm = float(np.linalg.norm(r))
        if norm == 0.0:
            return delta
        t0 = _time.perf_counter()
        if a.shape[0] < self.direct_below:
            delta[free] = spla.spsolve(a.tocsc(), r)
            self.timings.solve += _time.perf_counter() - t0
            self.timings.solves += 1
            return delta
        if self.options.preconditioner == "jacobi":
            inverse = 1.0 / a.diagonal()
            preconditioner = spla.LinearOperator(a.shape, matvec=lambda v: inverse * v)
        else:
            preconditioner = self._preconditioner(a)
        t1 = _time.perf_counter()
        count = [0]

        def tick(_x: np.ndarray) -> None:
            count[0] += 1

        # relative to the residual of the stage's start (a warm start keeps that scale)
        rtol, atol = self.options.tolerance, 0.0
        if reference is not None:
            rtol, atol = 0.0, self.options.tolerance * reference
        x, info = spla.cg(
            a, r, rtol=rtol, atol=atol, maxiter=self.options.max_iterations,
            M=preconditioner, callback=tick,
        )  # fmt: skip
        self.timings.solve += _time.perf_counter() - t1
        self.timings.solves += 1
        self.timings.cg_iterations += count[0]
        if info != 0:
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
        self._system = (matrix, fixed.copy(), a)
        return a

    def _matrix(self, conductance: sp.csr_matrix, cap: np.ndarray) -> sp.csr_matrix:
        """K + diag(cap) (cap = C/(θΔt)), kept while K (the same object) and cap are the
        same."""
        m = self._capacity_matrix
        if m is not None and m[0] is conductance and np.array_equal(m[1], cap):
            return m[2]
        matrix = (conductance + sp.diags(cap)).tocsr()
        self._capacity_matrix = (conductance, cap.copy(), matrix)
        return matrix

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
