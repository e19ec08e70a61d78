"""Exact-in-time steps of a linear frozen network: the Krylov (Lanczos) exponential integrator.

With frozen mechanics and constant properties the heat of a bed is the linear system

    C dT/dt = b - K T        (free particles; fixed ones enter b through K_fx T_x)

with K symmetric positive semi-definite and C = m c > 0 diagonal. Its exact solution over a
time τ from a state T_o is, with y = C^{1/2} T, A = C^{-1/2} K C^{-1/2} (symmetric) and the
initial rate r_o = C^{-1/2} (b - K T_o),

    y(τ) = y_o + τ φ₁(-τA) r_o,      φ₁(z) = (e^z - 1)/z,

an entire function, so a floating cluster (a singular K) is no special case. The vector
τ φ₁(-τA) r_o is approximated in the Krylov space of A and r_o built by the Lanczos process
(Lanczos 1950): A V_k = V_k T_k + β_k v_{k+1} e_kᵀ gives

    τ φ₁(-τA) r_o ≈ ‖r_o‖ V_k τ φ₁(-τ T_k) e₁

(Saad 1992, SIAM J. Numer. Anal. 29, 209-228; Hochbruck & Lubich 1997, SIAM J. Numer. Anal.
34, 1911-1925: the error falls superlinearly once k exceeds ~√(‖A‖τ)). T_k is tridiagonal and
small; its eigen-decomposition gives the approximation at **every** τ at once, so one basis
built from an origin serves all the steps that follow while the data (K, C, the fixed
temperatures, wall temperatures and sources) stay the same: a step costs a product V_kᵀ c
and the engine's passes, and the basis is extended (more Lanczos vectors) only when a later
time needs more. There is no time-discretisation error; the error is that of the Krylov
approximation, controlled by ``thermal.implicit.krylov_tolerance``: the estimate is the change
of the approximation over the last five Lanczos vectors, as an RMS temperature over the free
particles [K] (superlinear convergence makes it an upper estimate of the error of the longer
one; checked against the converged solution in tests/verification/test_exponential.py).
No reorthogonalisation: in floating point the Lanczos approximation of a matrix function
still converges (Druskin, Greenbaum & Knizhnerman 1998, SIAM J. Sci. Comput. 19, 38-54).

When the basis would need more than ``implicit.krylov_dimension`` vectors, a new origin is
taken at the start of the step; when even the step alone needs more, the step is divided
(halved until the estimate is met) and each part starts a new basis.

Ledger: the network is affine in T, so the heat of a boundary mechanism over a step is
Δt Q_m(T̄) exactly, with T̄ the mean temperature of the step,
∫ y dτ = τ y_o + τ² φ₂(-τA) r_o (φ₂(z) = (e^z - 1 - z)/z², the same basis): one pass of the
engine at T̄ gives every mechanism. The balance error is then the Krylov error (tested).

Restart: the checkpoint keeps the origin (time, temperatures, the number of Lanczos vectors);
the restarted run rebuilds the same vectors from it (deterministic: BLAS on one thread, the
same operations) and continues bit-identically.
"""

from __future__ import annotations

import hashlib
import time as _time
from typing import TYPE_CHECKING

import numpy as np
from scipy.linalg import eigh_tridiagonal

from thermodem.errors import ConfigError, SimulationError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.implicit import ImplicitSolver

#: the estimate compares the approximation with the one this many vectors shorter
LAG = 5


def phi_integrals(lam: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """τ φ₁(-τλ) = (1 - e^{-τλ})/λ and τ² φ₂(-τλ) = (τλ - 1 + e^{-τλ})/λ², elementwise,
    without cancellation for small τλ (series) and exact at λ = 0 (τ and τ²/2)."""
    x = lam * tau
    small = np.abs(x) < 1e-3
    safe = np.where(small, 1.0, x)
    em1 = np.expm1(-safe)  # e^{-x} - 1
    phi1 = np.where(small, 1.0 - x / 2.0 + x * x / 6.0 - x**3 / 24.0, -em1 / safe)
    phi2 = np.where(small, 0.5 - x / 6.0 + x * x / 24.0 - x**3 / 120.0, (em1 + safe) / safe**2)
    return tau * phi1, tau * tau * phi2


class KrylovExponential:
    """The ``exponential`` scheme: steps of a linear frozen network by a Lanczos basis."""

    def __init__(self, solver: ImplicitSolver) -> None:
        self.solver = solver
        self.engine = solver.engine
        eng = self.engine
        if not solver.linear:
            what = (
                "thermal_conductivity_table / specific_heat_table of a material"
                if eng.override
                else "a per-particle term (convection or radiation)"
            )
            raise ConfigError(
                f"thermal.scheme = 'exponential' needs a linear network with constant "
                f"properties; the case has {what}. Use 'backward_euler', 'crank_nicolson' or "
                "'tr_bdf2' (Picard on the temperature-dependent terms)"
            )
        self.tolerance = solver.options.krylov_tolerance
        self.dimension = solver.options.krylov_dimension
        self._clear()
        # restart state (engine/restart.py through ThermalEngine.state_dict)
        self.origin_time = 0.0
        self.origin_temperature = np.zeros(0)
        self.origin_vectors = 0
        self.origin_key = ""
        self._buffer = np.zeros((0, 0))
        self._pending = False  # restored: rebuild the basis from the origin on the next step

    def _clear(self) -> None:
        self.basis = np.zeros((0, 0))
        self.alpha = np.zeros(0)
        self.beta = np.zeros(0)
        self.vectors = 0  # Lanczos vectors with their α (the dimension of T_k)
        self.norm = 0.0
        self.exact = False  # the Krylov space is invariant: the approximation is exact
        self._data: tuple | None = None
        self._eig: dict = {}

    # --------------------------------------------------------------------------- data
    def _key(self, cap: np.ndarray) -> tuple:
        """What the linear system depends on besides the (constant) conductances: the fixed
        set and temperatures, the capacities, the sources and the wall temperatures, as
        the engine's conditions set them (``prepare``)."""
        eng = self.engine
        sim = eng.sim
        p = sim.particles
        fixed = eng.fixed if eng.fixed.shape[0] == p.count else np.zeros(p.count, np.bool_)
        walls = sim.wall_rows
        wall_t = walls[:, wall_cols.COL_TEMPERATURE].copy() if walls.shape[0] else None
        source = eng.source if eng.source is not None and eng.source.shape[0] else None
        return (
            fixed.copy(),
            p.temperature[fixed].copy(),
            cap.copy(),
            None if source is None else np.array(source, copy=True),
            wall_t,
        )

    @staticmethod
    def _same(a: tuple, b: tuple) -> bool:
        for x, y in zip(a, b, strict=True):
            if (x is None) != (y is None):
                return False
            if x is not None and not np.array_equal(x, y):
                return False
        return True

    @staticmethod
    def _digest(key: tuple) -> str:
        h = hashlib.blake2b(digest_size=16)
        for arr in key:
            if arr is not None:
                h.update(np.ascontiguousarray(arr).tobytes())
        return h.hexdigest()

    # ------------------------------------------------------------------------ basis
    def _origin(self, time: float, net, key: tuple, cap: np.ndarray, data_time: float) -> None:  # noqa: ANN001, E501
        """A new basis from the current temperatures at ``time``; the initial rate b - K T_o
        is the engine's heat rate at them (its pass at ``data_time``, whose conditions are
        those of ``key``), so that a restarted run rebuilds the same vectors bit for bit."""
        p = self.engine.sim.particles
        self._clear()
        free = ~net.fixed
        k_ff = self.solver._free_block(net.conductance, net.fixed)
        scale = 1.0 / np.sqrt(cap[free])
        t_o = p.temperature[free].copy()
        rates = self.solver._rates(data_time)
        r0 = scale * rates.heat_rate[free]
        self.norm = float(np.linalg.norm(r0))
        n = int(free.sum())
        rows = min(self.dimension, 32) + 1
        if self._buffer.shape[1] != n:  # kept across bases (its pages are touched once)
            self._buffer = np.zeros((rows, n))
        self.basis = self._buffer
        self.alpha = np.zeros(self.basis.shape[0])
        self.beta = np.zeros(self.basis.shape[0])
        if self.norm > 0.0:
            self.basis[0] = r0 / self.norm
        else:
            self.exact = True  # at rest: the state does not change
        self._data = (key, free, k_ff, scale, t_o, self._rms_factor(scale), net)
        self.origin_time = time
        self.origin_temperature = p.temperature.copy()
        self.origin_key = self._digest(key)

    @staticmethod
    def _rms_factor(scale: np.ndarray) -> float:
        return float(np.max(scale)) / np.sqrt(max(scale.shape[0], 1))

    def _extend(self, target: int) -> None:
        """Lanczos vectors up to ``target`` (or an invariant subspace)."""
        if self.exact:
            return
        t0 = _time.perf_counter()
        _, _, k_ff, scale, _, _, _ = self._data
        v_all = self.basis
        work = np.empty(v_all.shape[1])
        while self.vectors < target and not self.exact:
            k = self.vectors
            if k + 1 >= v_all.shape[0]:
                grow = min(2 * v_all.shape[0], self.dimension + 1)
                new = np.zeros((grow, v_all.shape[1]))
                new[: v_all.shape[0]] = v_all
                self.basis = self._buffer = v_all = new
                self.alpha = np.resize(self.alpha, grow)
                self.beta = np.resize(self.beta, grow)
            v = v_all[k]
            np.multiply(scale, v, out=work)
            w = k_ff @ work
            w *= scale
            self.solver.timings.cg_iterations += 1  # matrix products
            if k:
                np.multiply(v_all[k - 1], self.beta[k - 1], out=work)
                w -= work
            a = float(v @ w)
            np.multiply(v, a, out=work)
            w -= work
            b = float(np.linalg.norm(w))
            self.alpha[k] = a
            self.beta[k] = b
            self.vectors = k + 1
            # an invariant subspace (to round-off of the largest step): exact from here
            if b <= 1e-13 * max(abs(a), float(np.max(np.abs(self.alpha[: k + 1])))):
                self.exact = True
                break
            np.divide(w, b, out=v_all[k + 1])
        self.solver.timings.solve += _time.perf_counter() - t0

    def _eigen(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Eigen-decomposition of the leading k × k block of T_k (kept: it never changes)."""
        got = self._eig.get(k)
        if got is not None:
            return got
        if k == 1:
            got = self.alpha[:1].copy(), np.ones((1, 1))
        else:
            got = eigh_tridiagonal(self.alpha[:k], self.beta[: k - 1])
        self._eig[k] = got
        return got

    def _coefficients(self, k: int, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients of τφ₁(-τA) r_o and τ²φ₂(-τA) r_o in the first k vectors."""
        lam, q = self._eigen(k)
        f1, f2 = phi_integrals(lam, tau)
        first = q[0] * self.norm
        return q @ (f1 * first), q @ (f2 * first)

    def _estimate(self, k: int, tau: float) -> float:
        """RMS temperature change [K] of the approximation at τ between k - LAG and k
        vectors (an estimate of the error of the shorter one)."""
        c_long, _ = self._coefficients(k, tau)
        c_short, _ = self._coefficients(k - LAG, tau)
        diff = c_long.copy()
        diff[: k - LAG] -= c_short
        return float(np.linalg.norm(diff)) * self._data[5]

    def _limit(self) -> int:
        return LAG * (self.dimension // LAG)

    def _reach(self, tau: float) -> int | None:
        """The number of vectors (a multiple of LAG, the smallest that meets the tolerance
        at τ among those built, found by bisection; else the basis is extended) — None when
        the dimension limit is reached first. Stateless given the basis, so a restarted run
        picks the same number."""
        if self.exact:
            return self.vectors
        top = self.vectors // LAG
        if top >= 2 and self._estimate(LAG * top, tau) <= self.tolerance:
            lo, hi = 2, top  # the estimate is met at hi
            while lo < hi:
                mid = (lo + hi) // 2
                if self._estimate(LAG * mid, tau) <= self.tolerance:
                    hi = mid
                else:
                    lo = mid + 1
            return LAG * hi
        while self.vectors < self._limit():
            self._extend(min(LAG * (self.vectors // LAG + 1), self._limit()))
            if self.exact:
                return self.vectors
            if self.vectors >= 2 * LAG and self._estimate(self.vectors, tau) <= self.tolerance:
                return self.vectors
        return None

    # ----------------------------------------------------------------------------- step
    def step(self, dt: float, time: float) -> None:
        """Advance from ``time`` to ``time + dt`` (boundary data of ``time + dt``, held over
        the step, as backward Euler does)."""
        solver = self.solver
        eng = self.engine
        p = eng.sim.particles
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            # the conditions at the end of the step; the conductances of a linear frozen
            # network do not change, so the network is assembled only for a new basis
            eng.prepare(time + dt)
            cap = p.mass * eng.specific_heat()
            key = self._key(cap)
            if self._pending:
                net = solver.network(time + dt)
                self._restore(net, key, cap, time + dt)
            elif self._data is None or not self._same(self._data[0], key):
                net = solver.network(time + dt)
                self._origin(time, net, key, cap, time + dt)
            net = self._data[6]
            boundary = np.zeros(len(eng.boundary_columns))
            absorbed = 0.0
            now, end = time, time + dt
            while True:
                k = self._reach(end - self.origin_time)
                if k is not None:
                    b, a = self._advance(now, end, k)
                    boundary += b
                    absorbed += a
                    break
                if self.origin_time < now:  # a new basis from the start of this part
                    self._origin(now, net, key, cap, time + dt)
                    continue
                # even this part alone needs more vectors: halve it
                part = end - now
                while k is None:
                    part *= 0.5
                    if part < 1e-9 * max(dt, 1.0):
                        raise SimulationError(
                            f"exponential step: the Krylov estimate does not reach "
                            f"thermal.implicit.krylov_tolerance = {self.tolerance:g} K with "
                            f"thermal.implicit.krylov_dimension = {self.dimension} vectors "
                            f"(t = {now:.6g} s)",
                            eng.sim.step_count + 1,
                            now,
                            -1,
                        )
                    k = self._reach(part)
                b, a = self._advance(now, now + part, k)
                boundary += b
                absorbed += a
                now += part
                self._origin(now, net, key, cap, time + dt)
            self._finish(time, dt, net, boundary, absorbed)

    def _advance(self, start: float, stop: float, k: int) -> tuple[np.ndarray, float]:
        """Temperatures at ``stop`` (k vectors) into the particles; the heat of every boundary
        mechanism over [start, stop], from one pass of the engine at the mean temperature of
        the interval (the network is affine in T). The particles' heat rates are left at
        that pass: the step's mean rates, whose integral the ledger adds."""
        solver = self.solver
        p = self.engine.sim.particles
        t0 = _time.perf_counter()
        _, free, _, scale, t_o, _, _ = self._data
        span = stop - start
        if k == 0:  # at rest
            p.temperature[free] = t_o
            rates = solver._rates(stop, copies=False)
            return rates.boundary * span, rates.absorbed * span
        c_stop, i_stop = self._coefficients(k, stop - self.origin_time)
        _, i_start = self._coefficients(k, start - self.origin_time)
        coef = np.stack([(i_stop - i_start) / span, c_stop])
        y = coef @ self.basis[:k]
        y *= scale
        y += t_o
        solver.timings.solve += _time.perf_counter() - t0
        p.temperature[free] = y[0]
        rates = solver._rates(stop, copies=False)
        p.temperature[free] = y[1]
        return rates.boundary * span, rates.absorbed * span

    def _finish(self, time: float, dt: float, net, boundary, absorbed) -> None:  # noqa: ANN001
        solver = self.solver
        eng = self.engine
        p = eng.sim.particles
        bad = np.nonzero(~(p.temperature > 0.0) | ~np.isfinite(p.temperature))[0]
        if bad.shape[0]:
            gid = int(p.global_id[bad[0]])
            raise SimulationError(
                f"exponential step: temperature of particle {gid} became "
                f"{p.temperature[bad[0]]:.6g} K at t = {time + dt:.6g} s",
                eng.sim.step_count + 1,
                time + dt,
                gid,
            )
        for m, q in zip(eng.boundary_columns, boundary, strict=True):
            eng.cumulative[f"heat_in_{heat.HEAT_MECHANISMS[m]}"] += float(q)
        eng.cumulative["fixed_absorbed"] += float(absorbed)
        from thermodem.kernels import thermal as kernels

        eng.limit, where = kernels.stability_limit(
            p.mass, eng.specific_heat(), eng.conductance_sum, net.fixed
        )
        eng.limit_particle = int(p.global_id[where]) if where >= 0 else -1
        solver.timings.solves += 1

    # -------------------------------------------------------------------------- restart
    def state(self) -> tuple[dict, dict]:
        scalars = {
            "origin_time": self.origin_time,
            "origin_vectors": int(self.vectors),
            "origin_key": self.origin_key,
        }
        return scalars, {"origin_temperature": self.origin_temperature.copy()}

    def load(self, scalars: dict, arrays: dict) -> None:
        self._clear()
        self.origin_time = float(scalars["origin_time"])
        self.origin_vectors = int(scalars["origin_vectors"])
        self.origin_key = str(scalars["origin_key"])
        self.origin_temperature = np.array(arrays["origin_temperature"], copy=True)
        self._pending = self.origin_temperature.shape[0] > 0

    def _restore(self, net, key: tuple, cap: np.ndarray, data_time: float) -> None:  # noqa: ANN001
        """The basis of the uninterrupted run: rebuilt from the saved origin if the data are
        those it was built for (else a new origin now, as that run would have taken)."""
        self._pending = False
        p = self.engine.sim.particles
        if self.origin_temperature.shape[0] != p.count or self._digest(key) != self.origin_key:
            self._origin(self.engine.sim.time, net, key, cap, data_time)
            return
        current = p.temperature.copy()
        p.temperature[:] = self.origin_temperature
        origin_time, vectors = self.origin_time, self.origin_vectors
        self._origin(origin_time, net, key, cap, data_time)
        p.temperature[:] = current
        self._extend(vectors)
