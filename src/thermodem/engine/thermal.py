"""The thermal engine: temperatures, conduction, conditions, sources, explicit Euler, ledger.

Each particle is a lumped capacitance (spec 1.1): m c dT/dt = Q. Heat is solved with forward
(explicit) Euler exactly as the spec's calculation cycle (1.2): at the start of a step the
thermal pass uses the positions, contacts and temperatures of the previous step, and the
mechanics of the same step does not see the new temperatures (the physics are decoupled within
a step). With ``substeps: n`` the heat is advanced every n mechanical steps with Δt_th = n Δt;
with ``frozen_mechanics`` the particles do not move and each step is a thermal step of
``thermal.time_step``.

Heat ledger: U = Σ m c T changes by exactly the time-integrated wall heat and sources, minus
the heat absorbed by fixed-temperature particles (pairwise conduction cancels by construction);
``balance_error`` returns the difference, which is round-off.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from thermodem.config.thermal import Selection, ThermalSettings
from thermodem.engine.expressions import compile_expression
from thermodem.errors import ConfigError, SimulationError
from thermodem.geometry import wall_layout as WL
from thermodem.kernels import thermal as K
from thermodem.state.materials import resolve_pair
from thermodem.state.particles import HEAT_MECHANISMS

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def _wall_temperature_function(spec):  # noqa: ANN001, ANN202
    """t -> T of a fixed-temperature wall (constant, table or expression)."""
    value = spec.temperature
    if isinstance(value, int | float):
        return lambda t: float(value)
    if isinstance(value, list):
        times = np.array([a for a, _ in value])
        temps = np.array([b for _, b in value])
        return lambda t: float(np.interp(t, times, temps))
    expr = compile_expression(value, ("t",))
    return lambda t: float(expr(t))


class ThermalEngine:
    """Owns every thermal array and the thermal step of a :class:`Simulation`."""

    def __init__(self, sim: Simulation, settings: ThermalSettings) -> None:
        self.sim = sim
        self.settings = settings
        case = sim.case
        names = sim.material_names
        self.radius_id = settings.contact_radius.spec.model_id
        self.conduction_id = settings.direct_conduction.spec.model_id
        # conductance reuse (0: the model is evaluated at every thermal step), see
        # docs/models/conductance_reuse.md; the pair histories carry REUSE_COLUMNS more columns
        self.tolerance = float(settings.conductance_force_tolerance)
        # which materials meet: particle materials with each other and with walls that
        # exchange heat (fixed-temperature walls)
        particle_mats = set(self._particle_materials(case))
        hot_walls = {w.material for w in case.walls if w.thermal.kind == "fixed"}
        n = len(names)
        overrides = {frozenset(o.materials): o for o in case.interactions}
        self.radius_table = np.zeros((n, n, 16))
        self.conduction_table = np.zeros((n, n, 16))
        for a, na in enumerate(names):
            for b, nb in enumerate(names):
                meets = (na in particle_mats and (nb in particle_mats or nb in hot_walls)) or (
                    nb in particle_mats and na in hot_walls
                )
                if not meets:
                    continue
                pair = resolve_pair(
                    case.materials[na],
                    case.materials[nb],
                    overrides.get(frozenset((na, nb))),
                    is_wall=nb in hot_walls and nb not in particle_mats,
                    gas=settings.gas,
                )
                for table, choice in (
                    (self.radius_table, settings.contact_radius),
                    (self.conduction_table, settings.direct_conduction),
                ):
                    try:
                        table[a, b] = choice.spec.pack(choice.params, pair)
                    except ValueError as exc:
                        raise ConfigError(
                            f"thermal.{choice.family} = {choice.model!r} cannot be set up for "
                            f"materials {na!r} and {nb!r}: {exc}"
                        ) from None
        self._property_tables(case, names, particle_mats)
        self.specific_heat_by_type = np.zeros(n)
        for t, name in enumerate(names):
            c = case.materials[name].specific_heat
            if name in particle_mats and c is None:
                raise ConfigError(
                    f"materials.{name}.specific_heat: required by the thermal engine for "
                    "particles of this material (J/(kg K), > 0)"
                )
            self.specific_heat_by_type[t] = c or 0.0
        self.wall_functions = []
        for w in case.walls:
            fn = _wall_temperature_function(w.thermal) if w.thermal.kind == "fixed" else None
            count = 6 - int(w.open_top) if w.kind == "box" else 1
            self.wall_functions.extend([fn] * count)
        self.pair_conductance = np.zeros(0)
        self.pair_heat = np.zeros(0)
        self.wall_conductance = np.zeros(0)
        self.wall_heat = np.zeros(0)
        self._empty = np.zeros(0)
        self.fixed = np.zeros(0, np.bool_)
        self.source = np.zeros(0)
        self.conductance_sum = np.zeros(0)
        self.cumulative = {
            "wall_heat": 0.0,
            "source_heat": 0.0,
            "fixed_absorbed": 0.0,
            "inserted_heat": 0.0,
            "fixed_reset": 0.0,
        }
        self.limit = math.inf
        self.limit_particle = -1
        self.substeps = 1 if settings.substeps == "auto" else int(settings.substeps)
        self.thermal_steps = 0
        self.next_step = 0
        self.fresh = False
        # frozen mechanics: conductances of the first pass are reused (conduction_passes);
        # reuse_conductance = False re-evaluates them at every thermal step (tests)
        self.conductance_ready = False
        self.reuse_conductance = True
        self._warned = False
        self.initial_energy = 0.0

    @staticmethod
    def _particle_materials(case) -> list[str]:  # noqa: ANN001
        return [e.material for e in case.insertion]

    def _property_tables(self, case, names: list[str], particle_mats: set[str]) -> None:  # noqa: ANN001
        """Per-material tables of k(T) and c(T) (a constant is a one-node table)."""
        n = len(names)
        width = 1
        for name in names:
            m = case.materials[name]
            for tab in (m.thermal_conductivity_table, m.specific_heat_table):
                width = max(width, len(tab) if tab else 1)
        self.k_t = np.zeros((n, width))
        self.k_v = np.zeros((n, width))
        self.k_n = np.ones(n, np.int64)
        self.c_t = np.zeros((n, width))
        self.c_v = np.zeros((n, width))
        self.c_n = np.ones(n, np.int64)
        self.density_by_type = np.array([case.materials[m].density for m in names])
        has_k = has_c = False
        for a, name in enumerate(names):
            m = case.materials[name]
            for tab, const, tt, vv, nn in (
                (m.thermal_conductivity_table, m.thermal_conductivity, self.k_t, self.k_v,
                 self.k_n),
                (m.specific_heat_table, m.specific_heat, self.c_t, self.c_v, self.c_n),
            ):  # fmt: skip
                if tab:
                    arr = np.asarray(tab, float)
                    nn[a] = arr.shape[0]
                    tt[a, : nn[a]] = arr[:, 0]
                    vv[a, : nn[a]] = arr[:, 1]
                else:
                    vv[a, 0] = const or 0.0
            has_k |= m.thermal_conductivity_table is not None
            has_c |= m.specific_heat_table is not None and name in particle_mats
        self.has_c_table = has_c
        self.override = 2 if (has_c or has_k) and has_c else (1 if has_k else 0)
        self.scratch = np.zeros((1, 16))
        self.euler_partials = np.zeros((1, 6))

    def _interp(
        self,
        tt: np.ndarray,
        vv: np.ndarray,
        nn: np.ndarray,
        type_id: np.ndarray,
        temperature: np.ndarray,
    ) -> np.ndarray:
        out = vv[type_id, 0].copy()
        for a in np.nonzero(nn > 1)[0]:
            sel = type_id == a
            out[sel] = np.interp(temperature[sel], tt[a, : nn[a]], vv[a, : nn[a]])
        return out

    # ------------------------------------------------------------------ initial conditions
    def initial_temperature(self, position: np.ndarray, type_id: np.ndarray) -> np.ndarray:
        """Initial temperatures [K] of new particles from ``thermal.initial_temperature``."""
        rule = self.settings.initial_temperature
        n = position.shape[0]
        default = self.sim.case.simulation.initial_temperature
        if rule is None:
            return np.full(n, default)
        if rule.kind == "uniform":
            return np.full(n, rule.value)
        if rule.kind == "per_material":
            names = self.sim.material_names
            values = np.array([rule.values.get(m, rule.default) for m in names])
            return values[type_id]
        if rule.kind == "regions":
            out = np.full(n, rule.default)
            for box, temp in rule.regions:
                out[self._in_box(position, box)] = temp
            return out
        fn = compile_expression(rule.expression, ("x", "y", "z"))
        return np.broadcast_to(fn(position[:, 0], position[:, 1], position[:, 2]), (n,)).copy()

    @staticmethod
    def _in_box(position: np.ndarray, box) -> np.ndarray:  # noqa: ANN001
        lo = np.asarray(box.lower)
        hi = np.asarray(box.upper)
        return np.all((position >= lo) & (position <= hi), axis=1)

    def _select(self, sel: Selection) -> np.ndarray:
        p = self.sim.particles
        mask = np.ones(p.count, bool)
        if sel.material is not None:
            mask &= p.type_id == self.sim.material_index[sel.material]
        if sel.region is not None:
            mask &= self._in_box(p.position, sel.region)
        if sel.ids is not None:
            mask &= np.isin(p.global_id, np.asarray(sel.ids, np.int64))
        return mask

    # ------------------------------------------------------------------------ conditions
    def _fixed_and_sources(self, time: float) -> tuple[np.ndarray, np.ndarray]:
        p = self.sim.particles
        s = self.settings
        if self.fixed.shape[0] != p.count:
            self.fixed = np.zeros(p.count, np.bool_)
            self.source = np.zeros(p.count)
        fixed, source = self.fixed, self.source
        if not (s.fixed_temperature or s.heat_flux or s.volumetric_source or s.external_source):
            return fixed, source
        fixed[:] = False
        source[:] = 0.0
        for f in s.fixed_temperature:
            mask = self._select(f.select)
            fixed |= mask
            before = self.thermal_energy(mask)
            p.temperature[mask] = f.temperature
            # a particle that becomes fixed is set to the bath temperature: ledgered
            self.cumulative["fixed_reset"] += self.thermal_energy(mask) - before
        for h in s.heat_flux:
            mask = self._select(h.select)
            source[mask] += h.flux * 4.0 * np.pi * p.radius[mask] ** 2
        for v in s.volumetric_source:
            mask = self._select(v.select)
            source[mask] += v.power_density * 4.0 / 3.0 * np.pi * p.radius[mask] ** 3
        for e in s.external_source:
            if not (e.start_time <= time < e.end_time):
                continue
            mask = self._in_box(p.position, e.region)
            if not mask.any():
                continue
            weight = np.pi * p.radius[mask] ** 2
            if e.profile == "gaussian":
                axis = np.asarray(e.axis, float) / np.linalg.norm(e.axis)
                centre = 0.5 * (np.asarray(e.region.lower) + np.asarray(e.region.upper))
                r = p.position[mask] - centre
                r -= np.outer(r @ axis, axis)
                weight = weight * np.exp(-(r**2).sum(axis=1) / (2.0 * e.sigma**2))
            total = weight.sum()
            if total > 0.0:
                source[mask] += e.power * weight / total
        return fixed, source

    def _update_walls(self, time: float) -> None:
        rows = self.sim.wall_rows
        for w, fn in enumerate(self.wall_functions):
            if fn is None:
                rows[w, WL.COL_THERMAL_KIND] = 0.0
            else:
                rows[w, WL.COL_THERMAL_KIND] = 1.0
                rows[w, WL.COL_TEMPERATURE] = fn(time)

    # ------------------------------------------------------------------------------ step
    def _buffers(self) -> None:
        sim = self.sim
        if (
            self.pair_heat.shape[0] < sim.pairs.capacity
            or self.wall_heat.shape[0] < sim.walls.capacity
        ):
            self.conductance_ready = False
        if self.pair_heat.shape[0] < sim.pairs.capacity:
            self.pair_conductance = np.zeros(sim.pairs.capacity)
            self.pair_heat = np.zeros(sim.pairs.capacity)
        if self.wall_heat.shape[0] < sim.walls.capacity:
            self.wall_conductance = np.zeros(sim.walls.capacity)
            self.wall_heat = np.zeros(sim.walls.capacity)

    def prepare(self, time: float) -> None:
        """Buffers, wall temperatures at ``time`` and k(T), ρc(T) arrays for a conduction pass."""
        sim = self.sim
        p = sim.particles
        pb, wb = sim.pairs, sim.walls
        self._buffers()
        self._update_walls(time)
        # fixed-temperature particles take their temperature before any conduction pass sees it
        self._fixed_and_sources(time)
        self.k_p = self.rhoc_p = self.k_w = self.rhoc_w = self._empty
        if self.override:
            self.k_p = self._interp(self.k_t, self.k_v, self.k_n, p.type_id, p.temperature)
            c_p = self._interp(self.c_t, self.c_v, self.c_n, p.type_id, p.temperature)
            self.rhoc_p = self.density_by_type[p.type_id] * c_p
            wt = sim.wall_rows[:, WL.COL_TEMPERATURE]
            self.k_w = self._interp(self.k_t, self.k_v, self.k_n, sim.wall_material, wt)
            self.rhoc_w = self.density_by_type[sim.wall_material] * self._interp(
                self.c_t, self.c_v, self.c_n, sim.wall_material, wt
            )
        rows = max(pb.count, wb.count) // K.CHUNK + 1
        if self.scratch.shape[0] < rows:
            self.scratch = np.zeros((rows, 16))

    def pair_heat_args(self) -> tuple:
        """Arguments of the fused contact pass (particle pairs) that switch conduction on."""
        return (True, self.sim.particles.temperature, self.radius_id, self.radius_table,
                self.conduction_id, self.conduction_table, self.override, self.k_p, self.rhoc_p,
                self.scratch, self.sim.particles.heat_rate_by_mechanism,
                self.conductance_sum, self.tolerance)  # fmt: skip

    def wall_heat_args(self) -> tuple:
        """Arguments of the fused contact pass (wall pairs) that switch conduction on."""
        return (True, self.sim.particles.temperature, self.radius_id, self.radius_table,
                self.conduction_id, self.conduction_table, self.override, self.k_p, self.rhoc_p,
                self.k_w, self.rhoc_w, self.scratch, self.sim.particles.heat_rate_by_mechanism,
                self.conductance_sum, self.tolerance)  # fmt: skip

    def fused_rows(self, rows: int) -> None:
        """Scratch rows (one per slab group or wall chunk) and the per-particle conductance
        sums for a fused contact pass."""
        if self.scratch.shape[0] < rows:
            self.scratch = np.zeros((rows, 16))
        n = self.sim.particles.count
        if self.conductance_sum.shape[0] != n:
            self.conductance_sum = np.zeros(n)

    def conduction_passes(self) -> None:
        """Heat-only conduction passes over the current pair lists (frozen mechanics, init).

        With frozen mechanics and temperature-independent properties the conductances cannot
        change (same positions, contacts, forces and materials), so after the first pass only
        the heat rates H (T_j - T_i) are recomputed from them (bit-identical, tested).
        """
        sim = self.sim
        p = sim.particles
        pb, wb = sim.pairs, sim.walls
        reuse = self.reuse_conductance and self.settings.frozen_mechanics and self.override == 0
        if reuse and self.conductance_ready:
            K.heat_from_conductance(
                pb.i, pb.j, pb.count, wb.i, wb.j, wb.count, sim.wall_rows, p.temperature,
                self.pair_conductance, self.wall_conductance, self.pair_heat, self.wall_heat,
            )  # fmt: skip
            return
        K.conduction_pair_pass_for(self.radius_id, self.conduction_id, self.override)(
            p.position, p.radius, p.mass, p.temperature, p.type_id, pb.i, pb.j, pb.count,
            pb.state, pb.normal_force, pb.history, sim.lower, sim.upper, sim.periodic,
            self.radius_id, self.radius_table, self.conduction_id, self.conduction_table,
            self.override, self.k_p, self.rhoc_p, self.scratch, self.pair_conductance,
            self.pair_heat, self.tolerance,
        )  # fmt: skip
        K.conduction_wall_pass(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.i, wb.j, wb.count,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, self.radius_id, self.radius_table, self.conduction_id,
            self.conduction_table, self.override, self.k_p, self.rhoc_p, self.k_w, self.rhoc_w,
            self.scratch, self.wall_conductance, self.wall_heat, self.tolerance,
        )  # fmt: skip
        self.conductance_ready = reuse

    def gather(self, time: float, reduced: bool = False) -> np.ndarray:
        """Per-particle heat rates from the pair heat arrays and the sources; returns the
        fixed-temperature mask. ``reduced``: the fused contact pass already summed the pairs."""
        sim = self.sim
        p = sim.particles
        fixed, source = self._fixed_and_sources(time)
        if reduced:
            K.finish_heat(source, p.heat_rate, p.heat_rate_by_mechanism)
            return fixed
        if self.conductance_sum.shape[0] != p.count:
            self.conductance_sum = np.zeros(p.count)
        K.heat_scatter(
            sim.pairs.i, sim.pairs.j, sim.pairs.group_start, self.pair_conductance,
            self.pair_heat, sim.wall_row_start, self.wall_conductance, self.wall_heat, source,
            p.heat_rate, p.heat_rate_by_mechanism, self.conductance_sum,
        )  # fmt: skip
        return fixed

    def compute_rates(self, time: float) -> np.ndarray:
        """Heat rates of the current state (fills particles.heat_rate and by_mechanism).

        Returns the fixed-temperature mask.
        """
        self.prepare(time)
        self.conduction_passes()
        return self.gather(time)

    def specific_heat(self) -> np.ndarray:
        """c(T) of every particle [J/(kg K)]."""
        p = self.sim.particles
        if self.has_c_table:
            return self._interp(self.c_t, self.c_v, self.c_n, p.type_id, p.temperature)
        return self.specific_heat_by_type[p.type_id]

    def step(self, dt: float, time: float) -> None:
        """Advance temperatures by dt using the state at ``time`` (explicit Euler)."""
        sim = self.sim
        p = sim.particles
        if self.fresh:  # the fused contact pass already computed the pair heat at this state
            fixed, source = self._fixed_and_sources(time)
        else:
            fixed = self.compute_rates(time)
            source = self.source
        self.fresh = False
        if self.has_c_table:
            K.finish_heat(source, p.heat_rate, p.heat_rate_by_mechanism)
            c = self.specific_heat()
            self.limit, where = K.stability_limit(p.mass, c, self.conductance_sum, fixed)
            wall_q = float(np.sum(p.heat_rate_by_mechanism[:, K.M_WALL]))
            source_q = float(np.sum(source))
            absorbed, bad = K.euler_update_enthalpy(p.temperature, p.heat_rate, p.mass,
                                                    p.type_id, self.c_t, self.c_v, self.c_n,
                                                    fixed, dt)  # fmt: skip
        else:
            # one fused pass: heat rate, Euler limit, update and the ledger sums
            rows = p.count // K.EULER_CHUNK + 1
            if self.euler_partials.shape[0] < rows:
                self.euler_partials = np.zeros((rows, 6))
            self.limit, where, wall_q, source_q, absorbed, bad = K.euler_step(
                p.temperature, p.heat_rate, p.heat_rate_by_mechanism, source, p.mass,
                p.type_id, self.specific_heat_by_type, self.conductance_sum, fixed, dt,
                self.euler_partials,
            )  # fmt: skip
        self.limit_particle = int(p.global_id[where]) if where >= 0 else -1
        if dt > self.limit and not self.settings.stability.allow_unstable:
            raise SimulationError(
                f"thermal time step {dt:.4g} s exceeds the explicit Euler limit m c / ΣH = "
                f"{self.limit:.4g} s of particle {self.limit_particle} at step "
                f"{sim.step_count} (t = {time:.6g} s); use a smaller thermal.substeps / "
                "thermal.time_step or 'auto'",
                sim.step_count,
                time,
                self.limit_particle,
            )
        self.cumulative["wall_heat"] += wall_q * dt
        self.cumulative["source_heat"] += source_q * dt
        self.cumulative["fixed_absorbed"] += absorbed * dt
        self.thermal_steps += 1
        if bad >= 0:
            gid = int(p.global_id[bad])
            raise SimulationError(
                f"temperature of particle {gid} became {p.temperature[bad]:.6g} K at step "
                f"{sim.step_count} (t = {time:.6g} s); likely cause: thermal time step "
                f"{dt:.4g} s against the limit {self.limit:.4g} s",
                sim.step_count,
                time,
                gid,
            )
        if self.settings.substeps == "auto" and math.isfinite(self.limit):
            n = int(0.5 * self.limit / sim.dt)
            self.substeps = min(max(n, 1), self.settings.max_substeps)

    # ---------------------------------------------------------------------------- ledger
    def thermal_energy(self, mask: np.ndarray | None = None) -> float:
        """Σ m c T over all particles (or ``mask``) [J] (Σ m h(T) with a tabulated c)."""
        p = self.sim.particles
        t, m, ty = p.temperature, p.mass, p.type_id
        if mask is not None:
            t, m, ty = t[mask], m[mask], ty[mask]
        if self.has_c_table:
            return K.total_enthalpy(t, m, ty, self.c_t, self.c_v, self.c_n)
        return float(np.sum(m * self.specific_heat_by_type[ty] * t))

    def inserted(self, temperature: np.ndarray, mass: np.ndarray, type_id: np.ndarray) -> None:
        """Ledger the thermal energy that inserted particles bring in."""
        if self.has_c_table:
            e = K.total_enthalpy(temperature, mass, type_id, self.c_t, self.c_v, self.c_n)
        else:
            e = float(np.sum(mass * self.specific_heat_by_type[type_id] * temperature))
        self.cumulative["inserted_heat"] += e

    def balance_error(self) -> float:
        """U(t) - U(0) - wall heat - sources + heat absorbed by fixed particles - heat of
        inserted particles - resets of newly fixed particles [J]; round-off."""
        cum = self.cumulative
        return (self.thermal_energy() - self.initial_energy - cum["wall_heat"]
                - cum["source_heat"] + cum["fixed_absorbed"] - cum["inserted_heat"]
                - cum["fixed_reset"])  # fmt: skip

    def summary(self) -> dict[str, float]:
        """Temperature statistics, heat by mechanism [W] and the heat ledger [J]."""
        p = self.sim.particles
        out: dict[str, float] = {}
        if p.count:
            out.update(temperature_mean=float(p.temperature.mean()),
                       temperature_min=float(p.temperature.min()),
                       temperature_max=float(p.temperature.max()))  # fmt: skip
        # absolute heat exchanged by mechanism (pairwise terms sum to zero, so report |Q|/2)
        for k, name in enumerate(HEAT_MECHANISMS):
            col = p.heat_rate_by_mechanism[:, k]
            if np.any(col):
                total = float(np.abs(col).sum())
                out[f"heat_rate_{name}"] = 0.5 * total if name == "direct_conduction" else total
        out["thermal_energy"] = self.thermal_energy()
        out.update({f"heat_{k}": v for k, v in self.cumulative.items()})
        out["heat_balance_error"] = self.balance_error()
        out["thermal_limit"] = self.limit
        return out
