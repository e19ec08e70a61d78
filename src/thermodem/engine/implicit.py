"""Implicit heat for frozen mechanics: the conductance network as a sparse matrix.

With the particles at rest every heat term of the engine is, at a given state, a linear
network: pairs (i, j) with a conductance H_ij (contact conduction, the range set's gap
conduction, the external set's faces), and per-particle boundary terms b_i - D_i T_i (walls
at a fixed temperature: b = Σ H T_w, D = Σ H; the per-particle terms: their linearisation
Q(T*) - G (T - T*), G = -dQ/dT as the kernels return it; sources: b = Q, D = 0). With
K = L(H) + diag(D), L the graph Laplacian of the pairs, the lumped capacitances C = m c give

    C (T^{n+1} - T^n) / Δt = θ (b - K T^{n+1}) + (1 - θ) Q(T^n)

(θ = 1: backward Euler, first order; θ = ½: Crank–Nicolson, second order; both
unconditionally stable), and the steady state K T = b. Fixed-temperature particles are
Dirichlet rows (their temperature at t + Δt, not solved). Temperature-dependent k(T), c(T)
and the T³-dependent linearisation of radiation are handled by Picard iteration: the network
is re-evaluated at the last iterate until the largest temperature change is below
``thermal.implicit.picard_tolerance``; with c(T) the capacity term is written on the enthalpy,
m (h(T^{n+1}) - h(T^n)), linearised as m [h(T^k) - h(T^n) + c(T^k)(T - T^k)], so that the
converged step conserves Σ m h exactly like the explicit one.

The network is read from the engine itself (``ThermalEngine.compute_rates`` with
``record_conductances``): the per-pair conductances that its kernels store, the conductance
sums ΣH_i + ΣG_i and the boundary mechanism columns; D_i is ΣH_i - Σ_pairs H and
b_i = Q_boundary,i + D_i T_i. Nothing about a model is repeated here, so every selected term
enters the matrix (a test compares K T - b with the engine's own heat rates).

The system is assembled as COO arrays by numpy (no loop over pairs;
``engine/implicit_network.py``) and solved for the increment T - T^k with conjugate
gradients preconditioned by the diagonal or by smoothed-aggregation algebraic multigrid
(``pyamg``; Ruge & Stüben 1987, Vaněk, Mandel & Brezina 1996; ``preconditioner: auto``
chooses, docs/implicit.md), or by a sparse direct solve below ``direct_below`` unknowns. The
multigrid hierarchy is kept while the matrix does not change. The solves are
``engine/implicit_solve.py`` (a mixin of :class:`ImplicitSolver`).
"""

from __future__ import annotations

import math
import time as _time
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from thermodem.engine.implicit_network import (
    Network,
    Rates,
    Timings,
    laplacian,
    pair_lists,
    serial_blas,
)
from thermodem.engine.implicit_solve import SparseSolve
from thermodem.errors import ConfigError, SimulationError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import thermal as kernels
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.thermal import ThermalEngine


class ImplicitSolver(SparseSolve):
    """Backward Euler / Crank–Nicolson steps and the steady state of a thermal engine."""

    def __init__(self, engine: ThermalEngine) -> None:
        self.engine = engine
        settings = engine.settings
        self.theta = 0.5 if settings.scheme == "crank_nicolson" else 1.0
        self.options = settings.implicit
        self.timings = Timings()
        self._hierarchy = None
        self._hierarchy_key: tuple = ()
        self._end: Rates | None = None
        self._network_cache: tuple | None = None
        self._rhs_cache: tuple | None = None  # (data key, b) of a linear network
        self._system: tuple | None = None  # (matrix, fixed, free block)
        self._step_system: tuple | None = None  # (K_ff, its diagonal, ..., K_ff + C')
        self._kept_capacities: tuple | None = None
        self._kept_term: tuple | None = None
        self.interval: tuple[float, float] | None = None  # (Δt, t) of the step being computed
        self.direct_below = 200
        self.linear = engine.override == 0 and not any(
            t.target == "particles" for t in engine.terms
        )
        self.exponential = None
        self.adaptive = None
        if settings.scheme == "exponential":
            from thermodem.engine.exponential import KrylovExponential

            self.exponential = KrylovExponential(self)
        elif settings.scheme == "tr_bdf2":
            from thermodem.engine.adaptive import AdaptiveTRBDF2

            self.adaptive = AdaptiveTRBDF2(self)

    # ------------------------------------------------------------------ evaluation
    def _rates(self, time: float, copies: bool = True) -> Rates:
        """The engine's heat rates at the current temperatures and ``time``; ``copies``:
        keep copies of the per-particle rates and temperatures (else empty arrays)."""
        eng = self.engine
        p = eng.sim.particles
        t0 = _time.perf_counter()
        record = eng.record_conductances
        eng.record_conductances = True
        try:
            fixed = eng.compute_rates(time)
        finally:
            eng.record_conductances = record
        by_mech = p.heat_rate_by_mechanism
        empty = np.zeros(0)
        rates = Rates(
            boundary=by_mech.sum(axis=0)[eng.boundary_columns],  # (Fortran order: columns)
            absorbed=float(p.heat_rate[fixed].sum()) if fixed.shape[0] else 0.0,
            heat_rate=p.heat_rate.copy() if copies else empty,
            temperature=p.temperature.copy() if copies else empty,
            time=time,
        )
        cached = self._network_cache
        if self.linear and cached is not None and cached[3].shape[0] == p.count:
            # b of the linear network from the latest pass (a restarted run's first pass is
            # at the state of the uninterrupted run's last one: the same b, bit for bit)
            known = self._rhs_cache
            key = known[0] if known is not None and self._data_holds(known[0]) else None
            self._rhs_cache = (key or self._data_key(), self._boundary_rhs(cached[3]))
        self.timings.evaluation += _time.perf_counter() - t0
        return rates

    def _boundary_rhs(self, diag: np.ndarray) -> np.ndarray:
        """b = Q_boundary + D T of the engine's last pass (per particle)."""
        eng = self.engine
        p = eng.sim.particles
        by_mech = p.heat_rate_by_mechanism
        rhs = diag * p.temperature
        for m in eng.boundary_columns:  # (Fortran order: a column is contiguous)
            rhs += by_mech[:, m]
        return rhs

    def _data(self) -> tuple:
        """What b of a linear network depends on besides the (constant) conductances: the
        fixed set and temperatures, the sources and the wall temperatures, as the engine's
        conditions set them (``ThermalEngine.prepare``); views, see :meth:`_data_key`."""
        eng = self.engine
        sim = eng.sim
        p = sim.particles
        fixed = eng.fixed if eng.fixed.shape[0] == p.count else np.zeros(p.count, np.bool_)
        walls = sim.wall_rows
        source = eng.source if eng.source is not None and eng.source.shape[0] else None
        return (
            fixed,
            p.temperature[fixed],
            None if source is None else np.asarray(source),
            walls[:, wall_cols.COL_TEMPERATURE] if walls.shape[0] else None,
        )

    def _data_key(self) -> tuple:
        """A copy of :meth:`_data`, kept with the b it belongs to."""
        return tuple(None if x is None else np.array(x, copy=True) for x in self._data())

    def _data_holds(self, key: tuple) -> bool:
        """The engine's current data equal ``key``."""
        return all(
            (x is None and y is None) or (x is not None and y is not None and np.array_equal(x, y))
            for x, y in zip(self._data(), key, strict=True)
        )

    def _known_rhs(self, time: float, extra_fixed: np.ndarray | None) -> Network | None:
        """The network of a linear system whose data at ``time`` are those of the last
        evaluation, without the engine's passes: K is constant and b = Q + K T does not
        depend on T (the engine's own conditions still set the fixed particles, walls and
        sources at ``time``). None when the data changed or the network is not linear."""
        eng = self.engine
        p = eng.sim.particles
        cached, known = self._network_cache, self._rhs_cache
        if not self.linear or cached is None or known is None or cached[3].shape[0] != p.count:
            return None
        t0 = _time.perf_counter()
        eng.prepare(time)
        if not self._data_holds(known[0]):
            return None
        fixed = known[0][0].copy()
        if extra_fixed is not None:
            fixed |= extra_fixed
        net = Network(cached[4], known[1].copy(), fixed, p.temperature.copy())
        self.timings.assembly += _time.perf_counter() - t0
        return net

    def network(self, time: float, extra_fixed: np.ndarray | None = None) -> Network:
        """The conductance network at the current temperatures and ``time``."""
        known = self._known_rhs(time, extra_fixed)
        if known is not None:
            return known
        eng = self.engine
        p = eng.sim.particles
        self._rates(time)
        t0 = _time.perf_counter()
        n = p.count
        cached = self._network_cache
        if self.linear and cached is not None and cached[3].shape[0] == n:
            # frozen with constant properties: the conductances cannot have changed
            i, j, h, diag = cached[:4]
        else:
            i, j, h = pair_lists(eng)
            pair_sum = np.bincount(i, h, n) + np.bincount(j, h, n)
            diag = eng.conductance_sum[:n] - pair_sum
            # what the pairs left is the boundary conductance; round-off of the difference
            # is not a conductance
            diag[np.abs(diag) <= 1e-12 * np.abs(eng.conductance_sum[:n])] = 0.0
        rhs = self._boundary_rhs(diag)
        fixed = eng.fixed.copy() if eng.fixed.shape[0] == n else np.zeros(n, np.bool_)
        if extra_fixed is not None:
            fixed |= extra_fixed
        same = cached is not None and (
            cached[0] is i
            or (
                np.array_equal(cached[0], i)
                and np.array_equal(cached[1], j)
                and np.array_equal(cached[2], h)
                and np.array_equal(cached[3], diag)
            )
        )
        if same:
            conductance = cached[4]  # the same network (frozen, constant properties)
        else:
            conductance = laplacian(n, i, j, h, diag)
            self._network_cache = (i.copy(), j.copy(), h.copy(), diag.copy(), conductance)
        if self.linear:
            self._rhs_cache = (self._data_key(), rhs.copy())  # (the first assembly)
        net = Network(conductance, rhs, fixed, p.temperature.copy())
        self.timings.assembly += _time.perf_counter() - t0
        return net

    # ------------------------------------------------------------------------ restart
    def state(self) -> tuple[dict, dict]:
        """What a checkpoint keeps of the solver (the exponential scheme's origin)."""
        for scheme in (self.exponential, self.adaptive):
            if scheme is not None:
                return scheme.state()
        return {}, {}

    def load_state(self, scalars: dict, arrays: dict) -> None:
        for scheme in (self.exponential, self.adaptive):
            if scheme is not None:
                scheme.load(scalars, arrays)

    # ----------------------------------------------------------------------- capacities
    def _enthalpy(self, temperature: np.ndarray) -> np.ndarray:
        eng = self.engine
        p = eng.sim.particles
        out = np.empty(p.count)
        kernels.specific_enthalpies(temperature, p.type_id, eng.c_t, eng.c_v, eng.c_n, out)
        return out

    # ----------------------------------------------------------------------------- step
    def step(self, dt: float, time: float) -> None:
        """One implicit step from ``time`` to ``time + dt`` (the engine's state advances).

        Crank–Nicolson with ``implicit.startup_steps`` = n: the first n steps of the run are
        each two backward-Euler half steps (Rannacher 1984), which damp the stiff modes that a
        non-smooth start (a wall or a layer switched to a new temperature) excites and that
        Crank–Nicolson alone damps only by (1 - x)/(1 + x) per step.
        """
        self.interval = (dt, time)
        if self.exponential is not None:
            self.exponential.step(dt, time)
            return
        with serial_blas():
            self._advance(dt, time)

    def _advance(self, dt: float, time: float) -> None:
        if self.adaptive is not None:
            self.adaptive.step(dt, time)
            return
        if self.theta < 1.0 and self.engine.thermal_steps < self.options.startup_steps:
            self.theta = 1.0
            try:
                self._step(0.5 * dt, time)
                self._step(0.5 * dt, time + 0.5 * dt)
            finally:
                self.theta = 0.5
            return
        self._step(dt, time)

    def failing_step(self) -> tuple[str, int, float]:
        """(text, step, time) of a failure in the heat step being computed (the step after the
        state it starts from, as the explicit update and the mechanics say); outside a time
        step (a steady-state solve) the current state's."""
        interval = self.interval
        if interval is None:
            sim = self.engine.sim
            return f"at step {sim.step_count} (t = {sim.time:.6g} s)", sim.step_count, sim.time
        return self.engine._failing_step(*interval)

    def start_rates(self, time: float) -> Rates:
        """The rates of the current state at ``time`` (those the last step left, if they are
        of this state)."""
        p = self.engine.sim.particles
        start = self._end
        if (
            start is not None
            and start.time == time
            and start.temperature.shape == p.temperature.shape
            and np.array_equal(start.temperature, p.temperature)
        ):
            return start
        return self._rates(time)

    def _step(self, dt: float, time: float) -> None:
        eng = self.engine
        p = eng.sim.particles
        theta = self.theta
        start = self.start_rates(time) if theta < 1.0 else None
        t_n = p.temperature.copy()
        h_n = self._enthalpy(t_n) if eng.has_c_table else None
        explicit = (1.0 - theta) * start.heat_rate if start is not None else None
        limit, where = self.solve_stage(dt, time + dt, theta, t_n, h_n, explicit)
        end = self._rates(time + dt)
        self._end = end
        for m, q_end, q_start in zip(
            eng.boundary_columns,
            end.boundary,
            start.boundary if start is not None else end.boundary,
            strict=True,
        ):
            q = theta * q_end + (1.0 - theta) * q_start
            eng.cumulative[f"heat_in_{heat.HEAT_MECHANISMS[m]}"] += float(q) * dt
        absorbed = theta * end.absorbed + (1.0 - theta) * (
            start.absorbed if start is not None else 0.0
        )
        eng.cumulative["fixed_absorbed"] += absorbed * dt
        eng.limit = limit
        eng.limit_particle = int(p.global_id[where]) if where >= 0 else -1

    def solve_stage(
        self,
        dt: float,
        time: float,
        theta: float,
        t_old: np.ndarray,
        h_old: np.ndarray | None,
        explicit: np.ndarray | None,
        guess: np.ndarray | None = None,
        accuracy: float | None = None,
    ) -> tuple[float, int]:
        """Solve  C (T - T_old)/dt = θ Q(T) + explicit  for the temperatures at ``time``
        (with c(T): m (h(T) - h_old)/dt on the left), Picard on the temperature-dependent
        terms; the solution is left in the particles. ``guess``: the first iterate of the free
        particles (default: their current temperatures); the conjugate-gradient tolerance
        stays relative to the residual at the current temperatures. ``accuracy`` [K]: the
        conjugate gradients also stop when the capacity-weighted RMS of their error is
        bounded by it (``implicit_solve.conjugate_gradients``; the first Picard iterate only);
        the relative tolerance then refers to the residual at the guess (stricter; the bound
        stops them first). Returns the explicit limit and its particle at the first
        iterate."""
        eng = self.engine
        p = eng.sim.particles
        limit, where = math.inf, -1
        start = None
        if guess is not None:
            if accuracy is None:
                start = p.temperature.copy()
            if eng.fixed.shape[0] == p.count:
                np.copyto(p.temperature, guess, where=~eng.fixed)
            else:
                p.temperature[:] = guess
        change = math.inf
        for iteration in range(1, self.options.picard_iterations + 1):
            net = self.network(time)
            t_k = net.temperature
            if iteration == 1:
                limit, where = kernels.stability_limit(
                    p.mass, self._capacities()[1], eng.conductance_sum, net.fixed
                )
            matrix, residual, cap = self._system_of(net, dt, theta, t_old, h_old, explicit, t_k)
            reference = None
            if start is not None and iteration == 1:
                # the tolerance's scale: the residual of the unpredicted start (the same
                # network; fixed particles at their new temperature)
                start[net.fixed] = t_k[net.fixed]
                _, r0, _ = self._system_of(net, dt, theta, t_old, h_old, explicit, start)
                reference = float(np.linalg.norm(r0[~net.fixed]))
            # (the bound for the first solve only: a Picard iteration then converges to
            # picard_tolerance, which a solve stopped at the bound would end early)
            bound = accuracy if iteration == 1 else None
            delta = self._solve(matrix, residual, net.fixed, reference, cap, bound)
            p.temperature[:] = t_k + delta
            self.timings.picard_iterations += 1
            change = float(np.max(np.abs(delta))) if delta.shape[0] else 0.0
            if self.linear or change <= self.options.picard_tolerance:
                break
        else:
            self._not_converged(change, time - dt)
        if not (p.temperature.min() > 0.0 and math.isfinite(p.temperature.max())):
            bad = np.nonzero(~(p.temperature > 0.0) | ~np.isfinite(p.temperature))[0]
            gid = int(p.global_id[bad[0]])
            raise SimulationError(
                f"implicit heat step: temperature of particle {gid} became "
                f"{p.temperature[bad[0]]:.6g} K at t = {time:.6g} s",
                eng.sim.step_count + 1,
                time,
                gid,
            )
        return limit, where

    def _system_of(self, net: Network, dt: float, theta: float, t_old: np.ndarray,
                   h_old: np.ndarray | None, explicit: np.ndarray | None, t_k: np.ndarray
                   ) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray]:  # fmt: skip
        """(K, residual at the temperatures t_k, C' = C/(θΔt)) of the stage's system
        (K + diag(C')) δ = residual, the stage divided by θ so that the stages of one step
        size share one matrix: residual = C'(T_old - t_k) + b + explicit/θ - K t_k, with c(T)
        the capacity term on the enthalpy, -m (h(t_k) - h_old)/(θΔt)."""
        eng = self.engine
        p = eng.sim.particles
        t0 = _time.perf_counter()
        capacity = self._capacity_term(theta * dt)
        if h_old is not None:
            residual = self._enthalpy(t_k) - h_old
            residual *= p.mass / (-theta * dt)
        else:
            residual = t_old - t_k
            residual *= capacity
        residual += net.rhs
        if explicit is not None:
            residual += explicit / theta
        residual -= net.conductance @ t_k
        self.timings.assembly += _time.perf_counter() - t0
        return net.conductance, residual, capacity

    def _capacity_term(self, scale: float) -> np.ndarray:
        """C' = m c/(θΔt) for ``scale`` = θΔt; with constant capacities the same array for
        the same θΔt (the solves key their matrix on it)."""
        mc = self._capacities()[0]
        if self.engine.has_c_table:
            return mc / scale
        kept = self._kept_term
        if kept is not None and kept[0] is mc and kept[1] == scale:
            return kept[2]
        term = mc / scale
        self._kept_term = (mc, scale, term)
        return term

    def _capacities(self) -> tuple[np.ndarray, np.ndarray]:
        """(m c(T) [J/K], c(T) [J/(kg K)]) of every particle (kept with constant properties
        while the network is)."""
        eng = self.engine
        p = eng.sim.particles
        if eng.has_c_table:
            c = eng.specific_heat()
            return p.mass * c, c
        kept = self._kept_capacities
        if kept is not None and kept[0] is self._network_cache and kept[1].shape[0] == p.count:
            return kept[1:]
        c = eng.specific_heat()
        self._kept_capacities = (self._network_cache, p.mass * c, c)
        return self._kept_capacities[1:]

    def _not_converged(self, change: float, time: float) -> None:
        sim = self.engine.sim
        raise SimulationError(
            f"implicit heat step: the Picard iteration on the temperature-dependent terms did "
            f"not converge to thermal.implicit.picard_tolerance = "
            f"{self.options.picard_tolerance:g} K in thermal.implicit.picard_iterations = "
            f"{self.options.picard_iterations} (last change {change:.3g} K) at t = {time:.6g} s",
            sim.step_count + 1,
            time,
            -1,
        )

    # ---------------------------------------------------------------------------- steady
    def steady(
        self,
        time: float | None = None,
        extra_fixed: np.ndarray | None = None,
    ) -> Network:
        """Steady temperatures K T = b (Picard on the temperature-dependent terms) into the
        particles; ``extra_fixed`` marks more Dirichlet particles (at their current T).
        Returns the network at the solution."""
        eng = self.engine
        p = eng.sim.particles
        time = eng.sim.time if time is None else time
        self.interval = None  # (not a time step)
        change = math.inf
        for _ in range(self.options.picard_iterations):
            net = self.network(time, extra_fixed)
            self._check_anchored(net)
            residual = net.rhs - net.conductance @ net.temperature
            with serial_blas():
                delta = self._solve(net.conductance, residual, net.fixed)
            p.temperature[:] = net.temperature + delta
            self.timings.picard_iterations += 1
            change = float(np.max(np.abs(delta))) if delta.shape[0] else 0.0
            if self.linear or change <= self.options.picard_tolerance:
                break
        else:
            self._not_converged(change, time)
        return self.network(time, extra_fixed)

    def _check_anchored(self, net: Network) -> None:
        """Every cluster of free particles must reach a fixed temperature (a wall, a fixed
        particle, a per-particle term), or its steady temperature is undefined."""
        from scipy.sparse.csgraph import connected_components

        free = ~net.fixed
        if not free.any():
            return
        k = net.conductance
        row_sum = np.asarray(k.sum(axis=1)).ravel()  # D_i: L has zero row sums
        anchor = row_sum > 1e-12 * np.abs(k.diagonal())
        anchor |= np.asarray((k[:, net.fixed] != 0).sum(axis=1)).ravel() > 0
        a = k[free][:, free]
        count, labels = connected_components(a, directed=False)
        anchored = np.bincount(labels, anchor[free], count) > 0
        if not anchored.all():
            floating = int(np.sum(~anchored[labels]))
            raise ConfigError(
                f"steady state: {floating} particles in {int(np.sum(~anchored))} clusters "
                "exchange heat with no fixed temperature (a thermal.walls kind fixed, "
                "thermal.fixed_temperature, convection or radiation): their steady "
                "temperature is undefined"
            )


def steady_state(sim, time: float | None = None) -> Network:  # noqa: ANN001
    """Solve the steady temperatures of a simulation's current configuration (Python API).

    The temperatures of the particles are replaced by the steady ones; returns the network.
    """
    if sim.thermal is None:
        raise ConfigError("steady_state: the case has no thermal section")
    eng = sim.thermal
    solver = eng.implicit if eng.implicit is not None else ImplicitSolver(eng)
    return solver.steady(time)
