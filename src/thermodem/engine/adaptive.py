"""Adaptive TR-BDF2: internal steps with an embedded error estimate (``thermal.scheme: tr_bdf2``).

TR-BDF2 (Bank, Coughran, Fichtner, Grosse, Rose & Smith 1985, IEEE Trans. CAD 4, 436-451;
Hosea & Shampine 1996, Appl. Numer. Math. 20, 21-37) is a one-step, second-order, L-stable
scheme of two implicit stages per step h, with γ = 2 - √2 and d = γ/2:

    stage 1, trapezoid over γh:   C (T_γ - T_n) = d h [Q(T_n) + Q(T_γ)]
    stage 2, BDF2 from t_n, t_n+γh:  C (T_{n+1} - a T_γ + b T_n) = d h Q(T_{n+1}),
                                   a = 1/(γ(2 - γ)), b = (1 - γ)²/(γ(2 - γ)),

so both stages solve with the same matrix K + C/(d h) (stage 1 is a Crank–Nicolson step of
γh, stage 2 a backward-Euler step of d h from the virtual state a T_γ - b T_n; with c(T) the
capacity term is written on the enthalpy, the virtual state being a h(T_γ) - b h(T_n)).
Summed, C (T_{n+1} - T_n) = h [w Q_n + w Q_γ + d Q_{n+1}] with w = a d = √2/4: the ledger adds
the boundary heats with these weights and closes to the solver's residual. L-stability damps
the stiff modes that a non-smooth start excites (Crank–Nicolson only flips their sign).

The local error is k₃ h³ T''' with k₃ = (-3γ² + 4γ - 2)/(12(2 - γ)) (the scheme's error
constant), T''' estimated by the divided difference of the three slopes f = Q/C:

    e = 2 k₃ h (f_n/γ - f_γ/(γ(1 - γ)) + f_{n+1}/(1 - γ))

A step is accepted when the RMS of the estimate over the free particles is
≤ ``implicit.error_tolerance`` [K]. (Hosea & Shampine's filter (C/(dh) + K)^{-1} C/(dh) e,
against the estimate's overshoot on stiff components, costs one more solve per step and did
not change the number of steps on the 50k bed (150 against 151 at 1e-3 K): not used.)
The next step is h · min(5, max(0.2, 0.9 (tol/err)^{1/3})) (no growth right after a
rejection). The internal steps land exactly on the engine's steps (``thermal.time_step``, the
output cadence); the proposed size is carried to the next engine step and kept in
checkpoints. The first step is ``implicit.initial_step`` or the explicit limit m c/ΣH.

Each stage starts from a predicted state, a parabola with the slope f_n = Q(T_n)/C at t_n
(stage 1: through T_{n-1} and T_n; stage 2: through T_n and T_γ); the conjugate gradients stop
when their error is bounded by ``SOLVE_FRACTION`` × ``error_tolerance`` (a rigorous bound,
``implicit_solve.conjugate_gradients``), so a good prediction saves iterations, not accuracy
(on the 50k bed 925 iterations in 304 solves, against 1947 from the straight lines).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from thermodem.errors import SimulationError
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.implicit import ImplicitSolver
    from thermodem.engine.implicit_network import Rates

GAMMA = 2.0 - math.sqrt(2.0)
D = GAMMA / 2.0
A = 1.0 / (GAMMA * (2.0 - GAMMA))
B = (1.0 - GAMMA) ** 2 / (GAMMA * (2.0 - GAMMA))
W = A * D  # quadrature weight of the first two stages (√2/4); the third is D
K3 = (-3.0 * GAMMA**2 + 4.0 * GAMMA - 2.0) / (12.0 * (2.0 - GAMMA))
#: the linear solves of a stage stop when their error is bounded by this × error_tolerance
SOLVE_FRACTION = 0.01


class AdaptiveTRBDF2:
    """The ``tr_bdf2`` scheme of an implicit solver."""

    def __init__(self, solver: ImplicitSolver) -> None:
        self.solver = solver
        self.engine = solver.engine
        options = solver.options
        self.tolerance = options.error_tolerance
        self.step_size = float(options.initial_step or 0.0)  # the next proposed h [s]
        self.accepted = 0
        self.rejected = 0
        self._previous: tuple[float, np.ndarray] | None = None  # (h, T_n - T_{n-1})
        self.predict = True  # start the stages from the predictors (False: from T_n, T_γ)

    # --------------------------------------------------------------------------- step
    def step(self, dt: float, time: float) -> None:
        """Advance from ``time`` to ``time + dt`` by accepted internal steps."""
        eng = self.engine
        end = time + dt
        now = time
        if self.step_size <= 0.0:
            self.step_size = self._first_step(time)
        limit = math.inf
        while now < end - 1e-12 * max(abs(end), 1.0):
            h = min(self.step_size, end - now)
            if end - (now + h) < 1e-9 * h:  # do not leave a sliver
                h = end - now
            landing = h < self.step_size  # cut to land on the engine's step
            attempt = 0
            while True:
                attempt += 1
                ok, err, limit = self._try(h, now)
                factor = 0.9 * (self.tolerance / err) ** (1.0 / 3.0) if err > 0 else 5.0
                if ok:
                    self.accepted += 1
                    grow = 1.0 if attempt > 1 else 5.0
                    proposal = h * min(grow, max(0.2, factor))
                    if landing and attempt == 1 and proposal < self.step_size:
                        proposal = self.step_size  # a step cut to land is no evidence
                    self.step_size = proposal
                    now = end if h == end - now else now + h
                    break
                self.rejected += 1
                h *= min(0.9, max(0.2, factor))
                if h < 1e-12 * max(dt, 1.0):
                    raise SimulationError(
                        f"tr_bdf2: the step size fell below {h:.3g} s without meeting "
                        f"thermal.implicit.error_tolerance = {self.tolerance:g} K "
                        f"(t = {now:.6g} s)",
                        eng.sim.step_count + 1,
                        now,
                        -1,
                    )
        eng.limit = limit

    def _first_step(self, time: float) -> float:
        """The explicit limit m c/ΣH of the start (the fastest particle's time scale)."""
        from thermodem.kernels import thermal as kernels

        eng = self.engine
        p = eng.sim.particles
        self.solver.start_rates(time)
        limit, _ = kernels.stability_limit(
            p.mass, eng.specific_heat(), eng.conductance_sum, eng.fixed
        )
        return float(limit) if math.isfinite(limit) and limit > 0 else 1.0

    def _try(self, h: float, time: float) -> tuple[bool, float, float]:
        """One internal step of size h from ``time``; on rejection the state is restored."""
        solver = self.solver
        eng = self.engine
        p = eng.sim.particles
        start = solver.start_rates(time)
        t_n = p.temperature.copy()
        h_n = solver._enthalpy(t_n) if eng.has_c_table else None
        # stage 1: Crank–Nicolson over γh
        guess = None
        slope = start.heat_rate / solver._capacities()[0] if self.predict else None  # f_n
        if self._previous is not None and slope is not None:
            # the parabola through T_{n-1} and T_n with the slope f_n at t_n, at t_n + γh
            h_prev, change = self._previous
            s = GAMMA * h
            curve = (slope * h_prev - change) / (h_prev * h_prev)
            guess = t_n + s * slope + (s * s) * curve
        accuracy = SOLVE_FRACTION * self.tolerance
        limit, where = solver.solve_stage(GAMMA * h, time + GAMMA * h, 0.5, t_n, h_n,
                                          0.5 * start.heat_rate, guess, accuracy)  # fmt: skip
        mid = solver._rates(time + GAMMA * h)
        t_g = p.temperature.copy()
        # stage 2: backward Euler over d h from the virtual state a T_γ - b T_n
        if h_n is not None:
            h_virtual = A * solver._enthalpy(t_g) - B * h_n
            t_virtual = t_g  # not used with the enthalpy form
        else:
            h_virtual = None
            t_virtual = A * t_g - B * t_n
        guess = None
        if slope is not None:  # the parabola through T_n (slope f_n) and T_γ, at t_n + h
            s = GAMMA * h
            curve = (t_g - t_n - s * slope) / (s * s)
            guess = t_n + h * slope + (h * h) * curve
        solver.solve_stage(D * h, time + h, 1.0, t_virtual, h_virtual, None, guess, accuracy)
        end = solver._rates(time + h)
        err = self._error(h, start, mid, end)
        if err > self.tolerance:
            p.temperature[:] = t_n
            solver._end = start
            return False, err, limit
        solver._end = end
        self._previous = (h, p.temperature - t_n)
        for m, q0, q1, q2 in zip(eng.boundary_columns, start.boundary, mid.boundary,
                                 end.boundary, strict=True):  # fmt: skip
            q = W * (q0 + q1) + D * q2
            eng.cumulative[f"heat_in_{heat.HEAT_MECHANISMS[m]}"] += float(q) * h
        absorbed = W * (start.absorbed + mid.absorbed) + D * end.absorbed
        eng.cumulative["fixed_absorbed"] += absorbed * h
        eng.limit_particle = int(p.global_id[where]) if where >= 0 else -1
        return True, err, limit

    def _error(self, h: float, start: Rates, mid: Rates, end: Rates) -> float:
        """RMS over the free particles of the local error estimate [K]."""
        eng = self.engine
        p = eng.sim.particles
        fixed = eng.fixed if eng.fixed.shape[0] == p.count else np.zeros(p.count, np.bool_)
        free = ~fixed
        if not free.any():
            return 0.0
        cap = self.solver._capacities()[0]  # m c(T)
        slopes = (start.heat_rate / GAMMA - mid.heat_rate / (GAMMA * (1.0 - GAMMA))
                  + end.heat_rate / (1.0 - GAMMA))  # fmt: skip
        estimate = 2.0 * K3 * h * slopes[free] / cap[free]
        return float(np.sqrt(np.mean(estimate**2)))

    # -------------------------------------------------------------------------- restart
    def state(self) -> tuple[dict, dict]:
        scalars = {"step_size": self.step_size, "accepted": self.accepted,
                   "rejected": self.rejected}  # fmt: skip
        arrays = {}
        if self._previous is not None:
            scalars["previous_step"] = self._previous[0]
            arrays["previous_change"] = self._previous[1].copy()
        return scalars, arrays

    def load(self, scalars: dict, arrays: dict) -> None:
        self.step_size = float(scalars["step_size"])
        self.accepted = int(scalars["accepted"])
        self.rejected = int(scalars["rejected"])
        if "previous_step" in scalars:
            self._previous = (float(scalars["previous_step"]),
                              np.array(arrays["previous_change"], copy=True))  # fmt: skip
        else:
            self._previous = None
