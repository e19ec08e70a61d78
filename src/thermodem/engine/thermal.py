"""The thermal engine: temperatures, heat terms on pair sets, conditions, explicit Euler, ledger.

Each particle is a lumped capacitance (spec 1.1): m c dT/dt = Q. Heat is solved with forward
(explicit) Euler exactly as the spec's calculation cycle (1.2): at the start of a step the
thermal pass uses the positions, contacts and temperatures of the previous step, and the
mechanics of the same step does not see the new temperatures (the physics are decoupled within
a step). With ``substeps: n`` the heat is advanced every n mechanical steps with Δt_th = n Δt;
with ``frozen_mechanics`` the particles do not move and each step is a thermal step of
``thermal.time_step``.

The heat rate of a particle is the sum of its mechanism columns (``thermodem.state.heat``),
written by the terms (``thermodem.engine.terms``):

1. the contact conduction (contact radius × direct conduction), evaluated inside the fused
   contact pass of the mechanics at the step before a thermal step (or by a heat-only pass
   with frozen mechanics and at the start);
2. every other term, on its pair set, by the heat-only passes of ``kernels/heat_terms.py``:
   the range set (``engine/range_set.py``) for gap conduction, the contact lists for terms
   that need the normal force;
3. the sources of the case (``engine/thermal_conditions.py``).

Heat ledger: U = Σ m c T changes by exactly the time-integrated heat of the boundary
mechanisms (walls, sources, ...), minus the heat absorbed by fixed-temperature particles
(pairwise terms cancel by construction); ``balance_error`` returns the difference, which is
round-off.

The class is split by concern: this module (set-up, the explicit step),
``engine/thermal_contacts.py`` (the contact conduction's heat-only passes),
``engine/thermal_terms.py`` (the other terms' passes) and ``engine/thermal_ledger.py`` (ledger
and checkpoint state), the last three as mixins.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from thermodem.config.thermal import ThermalSettings
from thermodem.engine.external_set import ExternalPairSet
from thermodem.engine.fields import FieldProvider
from thermodem.engine.range_set import RangePairSet
from thermodem.engine.terms import build_generation, build_terms
from thermodem.engine.thermal_conditions import ThermalConditions
from thermodem.engine.thermal_contacts import ContactConduction
from thermodem.engine.thermal_ledger import ThermalLedger
from thermodem.engine.thermal_terms import TermEvaluation
from thermodem.engine.voronoi import VoronoiProvider
from thermodem.errors import ConfigError, SimulationError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import fields as field_kernels
from thermodem.kernels import heat_terms as passes
from thermodem.kernels import thermal as kernels
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


class ThermalEngine(ContactConduction, TermEvaluation, ThermalLedger):
    """Owns every thermal array and the thermal step of a :class:`Simulation`."""

    def __init__(self, sim: Simulation, settings: ThermalSettings) -> None:
        self.sim = sim
        self.settings = settings
        case = sim.case
        names = sim.material_names
        # which materials meet: particle materials with each other and with walls that
        # exchange heat (fixed-temperature walls)
        particle_mats = {e.material for e in case.insertion}
        hot_walls = {w.material for w in case.walls if w.thermal.kind == "fixed"}

        def meets(a: str, b: str) -> bool:
            return (a in particle_mats and (b in particle_mats or b in hot_walls)) or (
                b in particle_mats and a in hot_walls
            )

        def is_wall(a: str, b: str) -> bool:
            return b in hot_walls and b not in particle_mats

        self.contact, self.terms = build_terms(
            case, names, meets, is_wall, lambda name: name in particle_mats
        )
        #: heat generation by the mechanical dissipation (thermal.heat_generation)
        self.generation = build_generation(case, names, meets, is_wall)
        self.radius_id = self.contact.radius_id
        self.conduction_id = self.contact.direct_id
        self.radius_table = self.contact.radius_table
        self.conduction_table = self.contact.direct_table
        # conductance reuse (0: the model is evaluated at every thermal step), see
        # docs/models/conductance_reuse.md; the pair histories carry its block (state/history.py)
        self.tolerance = float(settings.conductance_force_tolerance)
        self._property_tables(case, names, particle_mats)
        self.specific_heat_by_type = np.zeros(len(names))
        for t, name in enumerate(names):
            c = case.materials[name].specific_heat
            if name in particle_mats and c is None:
                raise ConfigError(
                    f"materials.{name}.specific_heat: required by the thermal engine for "
                    "particles of this material (J/(kg K), > 0)"
                )
            self.specific_heat_by_type[t] = c or 0.0
        self.conditions = ThermalConditions(sim, settings)
        #: some wall has a fixed temperature (adiabatic walls take part in no heat pass)
        self.walls_conduct = any(fn is not None for fn in self.conditions.wall_functions)
        self._conditions_key: tuple = ()
        #: the external pair set of terms with target "external" (set_external_term)
        self.external: ExternalPairSet | None = None
        self.external_term = ""
        #: the tessellation (or porosity closure) that fills it for the Voronoi models
        self.voronoi: VoronoiProvider | None = None
        self.external_wall_conductance = np.zeros(0)
        self.external_stamp = -1  # the external set's update count of the stored H (frozen)
        # the Voronoi conductance reuse (thermal.tessellation.conductance_gap_tolerance): a
        # row per pair of the external set (kernels/heat_terms.py, REUSE_*), valid for the
        # set's update count ``external_reuse_stamp``; evaluations / pair-steps so far
        self.external_reuse = np.zeros((0, passes.REUSE_WIDTH))
        self.external_reuse_stamp = -1
        self.external_evaluations = 0
        self.external_pair_steps = 0
        for term in self.terms:
            if term.target == "external":
                self._voronoi_term(term)
        self.range_set = (
            RangePairSet(settings.range_skin)
            if any(t.target == "range" for t in self.terms)
            else None
        )
        if self.range_set is not None and self._radius_bound() > 0.0:
            # before the run: the largest particles the insertions can bring (pours too)
            self.check_ranges(self._radius_bound())
        # per-pair conductances of the contact conduction (heat-only passes, frozen reuse)
        self.pair_conductance = np.zeros(0)
        #: H of the mirror list's pairs (several MPI ranks: i a ghost, j owned)
        self.mirror_conductance = np.zeros(0)
        self.wall_conductance = np.zeros(0)
        # per-pair conductances of the other terms, stored with frozen mechanics
        self.term_conductance = [np.zeros(0) for _ in self.terms]
        self.term_wall_conductance = [np.zeros(0) for _ in self.terms]
        #: (several MPI ranks: a contact term's conductances of the mirror list's pairs)
        self.term_mirror_conductance = [np.zeros(0) for _ in self.terms]
        self.term_ready = np.zeros(len(self.terms), np.bool_)
        #: per-particle fields read by per-particle terms (columns: kernels/fields.py), filled
        #: by the providers of engine/fields.py before the terms run (fluid, porosity, ...)
        self.field_provider = FieldProvider(sim, settings, self.terms)
        self.fields = np.zeros((field_kernels.NFIELDS, 0))  # a row per field
        self._empty = np.zeros(0)
        self.conductance_sum = np.zeros(0)
        #: cumulative ledger [J]: heat in through every boundary mechanism, heat absorbed by
        #: fixed particles, heat of inserted particles, resets of newly fixed particles
        self.cumulative = {f"heat_in_{m.name}": 0.0 for m in heat.MECHANISMS if m.boundary}
        self.cumulative.update(fixed_absorbed=0.0, inserted_heat=0.0, fixed_reset=0.0)
        #: the mechanical ledger's generation sources when the heat started at a restart of a
        #: run without heat (engine/heat_start.py): the generation ledger counts from there
        self.generation_baseline: dict[str, float] = {}
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
        #: the last explicit update zeroed the mechanism rates and conductance sums (step)
        self.rates_cleared = False
        #: the source column and total heat rates are not formed yet (after_contact_pass)
        self.rates_pending = False
        # the implicit schemes read the per-pair conductances of every term at every state
        # (engine/implicit.py); the passes then store them also with k(T) tables
        self.record_conductances = settings.scheme != "explicit"
        self.implicit = None
        if settings.scheme != "explicit":
            from thermodem.engine.implicit import ImplicitSolver

            self.implicit = ImplicitSolver(self)
        self.initial_energy = 0.0
        self.boundary_columns = np.nonzero(heat.BOUNDARY)[0]
        self.boundary_keys = [f"heat_in_{heat.HEAT_MECHANISMS[m]}" for m in self.boundary_columns]
        self.in_use = self._mechanisms_in_use()
        sums = {*self.in_use, heat.M_SOURCE}
        if not self.conditions.has_sources:  # the source column stays zero: not summed
            sums.discard(heat.M_SOURCE)
        self.sum_columns = np.array(sorted(sums), np.int64)
        #: the explicit update turns the generation accumulators into heat itself
        #: (kernels/thermal.py: euler_step), instead of a conversion pass and a clearing pass
        self.fuse_generation = (
            self.generation.active and self.implicit is None and not self.has_c_table
        )
        self._no_gen_energy = np.zeros((1, 1))
        #: some term adds conductances (the explicit limit; else conductance_sum stays zero)
        self.conducts = bool(self.contact.active or self.terms)
        #: the columns the explicit update sums (the fused generation is added apart; the
        #: wall conduction column stays zero with adiabatic walls)
        apart = set(self.generation.columns) if self.fuse_generation else set()
        if not self.walls_conduct:  # (only the wall conduction passes write it)
            apart.add(heat.M_WALL_DIRECT)
        self.euler_columns = np.array([m for m in self.sum_columns if m not in apart], np.int64)

    def _mechanisms_in_use(self) -> list[int]:
        """Mechanism columns this case's terms and conditions can write (reported always)."""
        cols = set()
        if self.contact.active:
            cols |= {heat.M_DIRECT, heat.M_WALL_DIRECT}
        for t in self.terms:
            cols |= {t.column, t.wall_column} - {-1}
        if self.conditions.active:
            cols.add(heat.M_SOURCE)
        if self.generation.active:
            cols |= set(self.generation.columns)
        return sorted(cols)

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
        # 0: constant properties; 1: k(T) replaces the conductivity columns of the rows;
        # 2: k(T) and ρ c(T) replace the conductivity and heat capacity columns
        self.override = 2 if has_c else (1 if has_k else 0)
        self.scratch = np.zeros((1, max(self.conduction_table.shape[-1], 1)))
        self.term_scratch = np.zeros((1, max([t.table.shape[-1] for t in self.terms] + [1])))
        # the range pass's chunk buffers by row width (kernels/range_pass.py: chunk_buffers;
        # a dict of arrays: not part of a checkpoint's state)
        self.range_chunks: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.euler_partials = np.zeros((1, kernels.EULER_FIXED + len(heat.MECHANISMS)))

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

    # ---------------------------------------------------------------- conditions (API)
    @property
    def fixed(self) -> np.ndarray:
        """Mask of the fixed-temperature particles at the last thermal evaluation."""
        return self.conditions.fixed

    @property
    def source(self) -> np.ndarray:
        """Source power of every particle at the last thermal evaluation [W]."""
        return self.conditions.source

    def initial_temperature(self, position: np.ndarray, type_id: np.ndarray) -> np.ndarray:
        """Initial temperatures [K] of new particles from ``thermal.initial_temperature``."""
        return self.conditions.initial_temperature(position, type_id)

    def _update_walls(self, time: float) -> None:
        self.conditions.update_walls(time)

    def particles_reordered(self) -> None:
        """Called after the particles were permuted or inserted (a neighbour rebuild)."""
        self.conditions.invalidate()
        if self.range_set is not None:
            self.range_set.invalidate()
        if self.external is not None:
            self.external.invalidate()
        self.field_provider.invalidate()
        self.term_ready[:] = False

    def _fixed_and_sources(self, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Fixed particles at their bath temperature and the source powers at ``time``; once
        per state (the contact pass's prepare and the thermal step that follows it see the
        same positions and time)."""
        p = self.sim.particles
        key = (self.sim.step_count, time, p.count)
        if key == self._conditions_key and self.conditions.static_valid:
            return self.fixed, self.source
        self._conditions_key = key
        if self.has_c_table and self.conditions.active:
            before = p.temperature.copy()
            fixed, source, _ = self.conditions.apply(time, self.specific_heat_by_type)
            own = fixed.copy()
            own[self.sim.owned_count :] = False  # (on several MPI ranks: not the ghosts)
            after = p.temperature[own]
            self.cumulative["fixed_reset"] += kernels.total_enthalpy(
                after, p.mass[own], p.type_id[own], self.c_t, self.c_v, self.c_n
            ) - kernels.total_enthalpy(
                before[own], p.mass[own], p.type_id[own], self.c_t, self.c_v, self.c_n
            )
            return fixed, source
        fixed, source, reset = self.conditions.apply(time, self.specific_heat_by_type)
        self.cumulative["fixed_reset"] += reset
        return fixed, source

    # ------------------------------------------------------------------------------ step
    def _buffers(self) -> None:
        sim = self.sim
        mirror = sim.mirror
        mirror_capacity = mirror.capacity if mirror is not None else 0
        if (
            self.pair_conductance.shape[0] < sim.pairs.capacity
            or self.wall_conductance.shape[0] < sim.walls.capacity
            or self.mirror_conductance.shape[0] < mirror_capacity
        ):
            self.conductance_ready = False
        if self.pair_conductance.shape[0] < sim.pairs.capacity:
            self.pair_conductance = np.zeros(sim.pairs.capacity)
        if self.wall_conductance.shape[0] < sim.walls.capacity:
            self.wall_conductance = np.zeros(sim.walls.capacity)
        if self.mirror_conductance.shape[0] < mirror_capacity:
            self.mirror_conductance = np.zeros(mirror_capacity)

    def prepare(self, time: float) -> None:
        """Buffers, wall temperatures at ``time``, fixed particles and sources, and the k(T),
        ρc(T) arrays for the passes of this thermal step."""
        sim = self.sim
        p = sim.particles
        self._buffers()
        self.conditions.update_walls(time)
        # fixed-temperature particles take their temperature before any pass sees it
        self._fixed_and_sources(time)
        self.k_p = self.rhoc_p = self.k_w = self.rhoc_w = self._empty
        if self.override:
            self.k_p = self._interp(self.k_t, self.k_v, self.k_n, p.type_id, p.temperature)
            c_p = self._interp(self.c_t, self.c_v, self.c_n, p.type_id, p.temperature)
            self.rhoc_p = self.density_by_type[p.type_id] * c_p
            wt = sim.wall_rows[:, wall_cols.COL_TEMPERATURE]
            self.k_w = self._interp(self.k_t, self.k_v, self.k_n, sim.wall_material, wt)
            self.rhoc_w = self.density_by_type[sim.wall_material] * self._interp(
                self.c_t, self.c_v, self.c_n, sim.wall_material, wt
            )
        mirror = sim.mirror
        listed = max(sim.pairs.count, sim.walls.count, mirror.count if mirror is not None else 0)
        rows = listed // kernels.CHUNK + 1
        self._scratch_rows(rows)
        if self.conductance_sum.shape[0] != p.count:
            self.conductance_sum = np.zeros(p.count)

    def _scratch_rows(self, rows: int) -> None:
        if self.scratch.shape[0] < rows:
            self.scratch = np.zeros((rows, self.scratch.shape[1]))

    def pair_heat_args(self) -> tuple:
        """Arguments of the fused contact pass (particle pairs) that switch conduction on."""
        return (True, self.sim.particles.temperature, self.radius_id, self.radius_table,
                self.conduction_id, self.conduction_table, self.override, self.k_p, self.rhoc_p,
                self.scratch, self.sim.particles.heat_columns,
                self.conductance_sum, self.tolerance)  # fmt: skip

    def fused_rows(self, rows: int) -> None:
        """Scratch rows (one per slab group or wall chunk) and the per-particle conductance
        sums for a fused contact pass."""
        self._scratch_rows(rows)
        n = self.sim.particles.count
        if self.conductance_sum.shape[0] != n:
            self.conductance_sum = np.zeros(n)

    # ------------------------------------------------------------------------- the rates
    def compute_rates(self, time: float) -> np.ndarray:
        """Heat rates of the current state (fills particles.heat_rate and by_mechanism).

        Returns the fixed-temperature mask. The next thermal step evaluates every term again
        (the rates of a fused contact pass, if one ran, are replaced).
        """
        self.prepare(time)
        self.conduction_passes()
        self.evaluate_terms(time)
        self.fresh = False
        return self.finish(time)

    def after_contact_pass(self, time: float, complete: bool = True) -> None:
        """The fused contact pass has added the contact conduction of this state: add every
        other term and (``complete``) form the source column and total heat rates, which the
        thermal step that follows forms anyway: without ``complete`` they are left to it, or
        to :meth:`complete_rates` when something reads them first (``rates_pending``)."""
        self._fixed_and_sources(time)
        self.evaluate_terms(time)
        if complete:
            self.finish(time)
        else:
            self.rates_pending = True

    def complete_rates(self) -> None:
        """Form the source column and the total heat rates if the last contact pass left
        them to the next thermal step (outputs, checkpoints and the API call this)."""
        if self.rates_pending:
            self.finish(self.sim.time)

    def finish(self, time: float) -> np.ndarray:
        """Source column and total heat rate after the passes; returns the fixed mask."""
        p = self.sim.particles
        if self.fuse_generation:  # the generation columns for the readers of the rates
            self.generation_rates()
        kernels.finish_heat(self.source, p.heat_rate, p.heat_columns, self.sum_columns)
        self.rates_pending = False
        return self.fixed

    def specific_heat(self) -> np.ndarray:
        """c(T) of every particle [J/(kg K)]."""
        p = self.sim.particles
        if self.has_c_table:
            return self._interp(self.c_t, self.c_v, self.c_n, p.type_id, p.temperature)
        return self.specific_heat_by_type[p.type_id]

    def _failing_step(self, dt: float, time: float) -> tuple[str, int, float]:
        """Where an explicit heat update over ``dt`` from the state at ``time`` fails: in the
        step being computed (step_count + 1, as the mechanical failures say), not the step of
        the state it starts from, which the last good checkpoint may hold. Over several
        mechanical steps (thermal.substeps = n) the message names the interval too."""
        sim = self.sim
        mechanical = dt if self.settings.frozen_mechanics else sim.dt
        step, at = sim.step_count + 1, time + mechanical
        text = f"at step {step} (t = {at:.6g} s)"
        n = int(round(dt / mechanical)) if mechanical > 0 else 1
        if n > 1:
            text += (
                f", in the heat update over thermal.substeps = {n} steps from t = {time:.6g} s "
                f"to t = {time + dt:.6g} s"
            )
        return text, step, at

    def step(self, dt: float, time: float, clear: bool = False) -> None:
        """Advance temperatures by dt using the state at ``time`` (explicit Euler, or the
        implicit scheme of ``thermal.scheme``: engine/implicit.py).

        ``clear``: the contact pass of this same step evaluates the heat of the next state
        (heat every step): the explicit update then zeroes the mechanism rates and conductance
        sums it has read (``rates_cleared``), so that the force reset need not. Nothing reads
        them in between (outputs are written after the step)."""
        if self.implicit is not None:
            self.implicit.step(dt, time)
            self.thermal_steps += 1
            self._generation_used()
            return
        sim = self.sim
        p = sim.particles
        if self.fresh:  # the contact pass and after_contact_pass computed every rate
            fixed, source = self._fixed_and_sources(time)
        else:
            self.prepare(time)
            self.conduction_passes()
            self.evaluate_terms(time)
            fixed, source = self.fixed, self.source
        self.fresh = False
        # the particles this process owns: all of them (on several MPI ranks the first
        # owned_count, the ghosts after them are updated by their owners, thermodem.mpi)
        n = sim.owned_count
        temperature, heat_rate, mass = p.temperature[:n], p.heat_rate[:n], p.mass[:n]
        # (the kernels loop over the first n particles of the full rows)
        by_mech, type_id = p.heat_columns, p.type_id[:n]
        fixed, source, conductance = fixed[:n], source[:n], self.conductance_sum[:n]
        if self.has_c_table:
            kernels.finish_heat(source, heat_rate, by_mech, self.sum_columns)
            self.rates_pending = False
            c = self.specific_heat()[:n]
            limit, where = kernels.stability_limit(mass, c, conductance, fixed)
            boundary = p.heat_rate_by_mechanism[:n, self.boundary_columns].sum(axis=0)
            absorbed, bad = kernels.euler_update_enthalpy(temperature, heat_rate, mass, type_id,
                                                          self.c_t, self.c_v, self.c_n, fixed,
                                                          dt)  # fmt: skip
        else:
            # one fused pass: heat rate, Euler limit, update and the ledger sums
            rows = n // kernels.EULER_CHUNK + 1
            if self.euler_partials.shape[0] < rows:
                self.euler_partials = np.zeros((rows, self.euler_partials.shape[1]))
            gen_energy = p.generation_energy if self.fuse_generation else self._no_gen_energy
            limit, where, absorbed, bad = kernels.euler_step(
                temperature, heat_rate, by_mech, self.euler_columns, source,
                self.conditions.has_sources, mass, type_id, self.specific_heat_by_type,
                conductance, self.conducts, fixed, dt, self.euler_partials, clear, gen_energy,
                self.fuse_generation, self.generation.conversion_fraction / dt,
            )  # fmt: skip
            # (with MPI ghosts after the owned particles the force reset zeroes them all)
            self.rates_cleared = clear and n == p.count
            self.rates_pending = False  # the update formed them
            boundary = self._empty
            if len(self.boundary_columns):  # (a sum over the chunks' rows: ~35 µs a step)
                boundary = self.euler_partials[:rows, kernels.EULER_FIXED :].sum(axis=0)
                boundary = boundary[self.boundary_columns]
        gid = p.global_id
        # the whole simulation's limit and failure (the same on every MPI rank)
        self.limit, self.limit_particle, bad_gid, bad_temperature = sim.agree_thermal(
            float(limit),
            int(gid[where]) if where >= 0 else -1,
            int(gid[bad]) if bad >= 0 else -1,
            float(temperature[bad]) if bad >= 0 else math.nan,
        )
        if dt > self.limit and not self.settings.stability.allow_unstable:
            where_text, failed_step, failed_time = self._failing_step(dt, time)
            raise SimulationError(
                f"thermal time step {dt:.4g} s exceeds the explicit Euler limit m c / ΣH = "
                f"{self.limit:.4g} s of particle {self.limit_particle} {where_text}; use a "
                "smaller thermal.substeps / thermal.time_step or 'auto'",
                failed_step,
                failed_time,
                self.limit_particle,
            )
        cumulative = self.cumulative
        for key, q in zip(self.boundary_keys, boundary.tolist(), strict=True):
            cumulative[key] += q * dt
        self.cumulative["fixed_absorbed"] += absorbed * dt
        self.thermal_steps += 1
        if not self.fuse_generation:  # (else the update emptied the accumulators)
            self._generation_used()
        if bad_gid >= 0:
            where_text, failed_step, failed_time = self._failing_step(dt, time)
            if dt > 0.5 * self.limit:
                cause = f"thermal time step {dt:.4g} s against the limit {self.limit:.4g} s"
            else:  # a stable step: the heat itself (a source, flux or generation) is too large
                q = float(heat_rate[bad]) if 0 <= bad < heat_rate.shape[0] else math.nan
                cause = (
                    f"its heat rate {q:.4g} W for its heat capacity (a heat source, flux or "
                    f"generation too large; the thermal time step {dt:.4g} s is within the "
                    f"limit {self.limit:.4g} s)"
                )
            raise SimulationError(
                f"temperature of particle {bad_gid} became {bad_temperature:.6g} K "
                f"{where_text}; likely cause: {cause}",
                failed_step,
                failed_time,
                bad_gid,
            )
        if self.settings.substeps == "auto" and math.isfinite(self.limit):
            n = int(0.5 * self.limit / sim.dt)
            self.substeps = min(max(n, 1), self.settings.max_substeps)
