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
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.config.thermal import ThermalSettings
from thermodem.engine import generation
from thermodem.engine.external_set import ExternalPairSet
from thermodem.engine.fields import STATE_PREFIX as FIELDS_PREFIX
from thermodem.engine.fields import FieldProvider
from thermodem.engine.range_set import RangePairSet
from thermodem.engine.terms import HeatTerm, build_generation, build_terms
from thermodem.engine.thermal_conditions import ThermalConditions
from thermodem.engine.voronoi import INPUT_WIDTH, VoronoiProvider
from thermodem.errors import ConfigError, SimulationError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import fields as field_kernels
from thermodem.kernels import heat_terms as passes
from thermodem.kernels import thermal as kernels
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation

#: Attributes never saved in checkpoints (objects, back references, derived tables).
SKIP = ("sim", "settings", "conditions", "contact", "terms", "generation", "range_set",
        "external", "_empty",
        "_conditions_key", "field_provider", "fields", "voronoi", "external_wall_conductance",
        "external_stamp", "implicit", "record_conductances")  # fmt: skip
#: Prefixes of the pair sets' state in the engine's checkpoint scalars and arrays.
RANGE_PREFIX = "range_set__"
EXTERNAL_PREFIX = "external__"
VORONOI_PREFIX = "voronoi__"
IMPLICIT_PREFIX = "implicit__"


class ThermalEngine:
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
        self.wall_conductance = np.zeros(0)
        # per-pair conductances of the other terms, stored with frozen mechanics
        self.term_conductance = [np.zeros(0) for _ in self.terms]
        self.term_wall_conductance = [np.zeros(0) for _ in self.terms]
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
        if (
            self.pair_conductance.shape[0] < sim.pairs.capacity
            or self.wall_conductance.shape[0] < sim.walls.capacity
        ):
            self.conductance_ready = False
        if self.pair_conductance.shape[0] < sim.pairs.capacity:
            self.pair_conductance = np.zeros(sim.pairs.capacity)
        if self.wall_conductance.shape[0] < sim.walls.capacity:
            self.wall_conductance = np.zeros(sim.walls.capacity)

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
        rows = max(sim.pairs.count, sim.walls.count) // kernels.CHUNK + 1
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

    def conduction_passes(self) -> None:
        """Contact conduction by the heat-only passes (frozen mechanics, start): zeroes the
        mechanism columns and the conductance sums, then adds the contact conduction.

        With frozen mechanics and temperature-independent properties the conductances cannot
        change (same positions, contacts, forces and materials), so after the first pass only
        the heat rates H (T_j - T_i) are recomputed from them (bit-identical, tested).
        """
        sim = self.sim
        p = sim.particles
        pb = sim.pairs
        by_mech = p.heat_columns
        passes.zero_heat(by_mech, self.conductance_sum)
        if not self.contact.active:
            return
        reuse = self.reuse_conductance and self.settings.frozen_mechanics and self.override == 0
        if not (reuse and self.conductance_ready):
            kernels.conduction_pair_pass_for(self.radius_id, self.conduction_id, self.override)(
                p.position, p.radius, p.mass, p.temperature, p.type_id, pb.i, pb.j, pb.count,
                pb.state, pb.normal_force, pb.history, sim.lower, sim.upper, sim.periodic,
                self.radius_id, self.radius_table, self.conduction_id, self.conduction_table,
                self.override, self.k_p, self.rhoc_p, self.scratch, self.pair_conductance,
                sim.history_layout.reuse, self.tolerance,
            )  # fmt: skip
            self._wall_conductances()
            self.conductance_ready = reuse
        passes.pair_heat_from_conductance(
            pb.i, pb.j, pb.group_start, self.pair_conductance, p.temperature, heat.M_DIRECT,
            by_mech, self.conductance_sum,
        )  # fmt: skip
        self._wall_heat()

    def wall_conduction(self) -> None:
        """The contact conduction of the wall pairs, after the fused contact pass (which
        conducts through the particle pairs only; kernels/pair_pass.py)."""
        self._wall_conductances()
        self._wall_heat()

    def _wall_conductances(self) -> None:
        if not self.walls_conduct:  # adiabatic walls: every wall pair's H stays 0
            return
        sim = self.sim
        p, wb = sim.particles, sim.walls
        kernels.conduction_wall_pass_for(self.radius_id, self.conduction_id, self.override)(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.i, wb.j, wb.count,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, self.radius_id, self.radius_table, self.conduction_id,
            self.conduction_table, self.override, self.k_p, self.rhoc_p, self.k_w, self.rhoc_w,
            self.scratch, self.wall_conductance, sim.history_layout.reuse, self.tolerance,
        )  # fmt: skip

    def _wall_heat(self) -> None:
        if not self.walls_conduct:
            return
        sim = self.sim
        p = sim.particles
        passes.wall_heat_from_conductance(
            sim.walls.j, sim.wall_row_start, sim.wall_rows, self.wall_conductance, p.temperature,
            heat.M_WALL_DIRECT, p.heat_columns, self.conductance_sum,
        )  # fmt: skip

    # ----------------------------------------------------------------- the other terms
    def _term_rows(self, rows: int) -> np.ndarray:
        if self.term_scratch.shape[0] < rows:
            self.term_scratch = np.zeros((rows, self.term_scratch.shape[1]))
        return self.term_scratch

    def _range_gaps(self) -> tuple[float, float]:
        p = self.sim.particles
        if p.count == 0:
            return 0.0, 0.0
        return self.check_ranges(float(p.radius.max()))

    def _radius_bound(self) -> float:
        """Largest radius the case's insertion distributions can produce [m] (0 if none
        is bounded; particle files and lists are checked once inserted)."""
        bounds = [
            getattr(getattr(e, "distribution", None), "max_radius_bound", None)
            for e in self.sim.case.insertion
        ]
        return max([float(b) for b in bounds if b is not None] + [0.0])

    def check_ranges(self, r_max: float) -> tuple[float, float]:
        """The range set's largest conducting gaps of particle pairs and particle-wall pairs
        for particles up to ``r_max`` [m]; a ConfigError naming the model's key and its range
        parameter when a gap exceeds the domain, or when a periodic axis is too short for the
        range set's cells (two cells of 2 r_max + gap + skin)."""
        sim = self.sim
        extent = float(np.min(sim.upper - sim.lower))
        gap = wall_gap = 0.0
        widest = None
        for term in self.terms:
            if term.target != "range":
                continue
            g, w = term.max_gap(r_max)
            if max(g, w) > extent:
                raise ConfigError(
                    f"{_range_key(term)}: {term.choice.model!r} conducts across surface gaps up "
                    f"to {max(g, w):.6g} m for particles of radius {r_max:.6g} m, more than the "
                    f"domain's smallest extent {extent:.6g} m; allowed: "
                    f"{_range_allowed(term, extent / max(g, w))}"
                )
            if widest is None or g > gap:
                widest = term
            gap, wall_gap = max(gap, g), max(wall_gap, w)
        if widest is None:
            return gap, wall_gap
        skin = self.settings.range_skin
        if skin is None:  # the contact list's skin (its default: 0.2 R_max)
            skin = getattr(sim, "skin", None) or sim.case.neighbors.skin or 0.2 * r_max
        cell = 2.0 * r_max + gap + float(skin)
        length = sim.upper - sim.lower
        for a in range(3):
            if sim.periodic[a] and length[a] < 2.0 * cell:
                # the part of the cell the model's range can still take
                room = 0.5 * float(length[a]) - 2.0 * r_max - float(skin)
                raise ConfigError(
                    f"{_range_key(widest)}: periodic axis {'xyz'[a]} of length "
                    f"{length[a]:.6g} m is shorter than two cells of the range pair set "
                    f"(2 R_max {2.0 * r_max:.6g} m + largest conducting gap {gap:.6g} m + "
                    f"thermal.range_skin {float(skin):.6g} m each); allowed: "
                    + (
                        _range_allowed(widest, room / gap)
                        if room > 0.0
                        else "a longer periodic axis or a smaller thermal.range_skin"
                    )
                )
        return gap, wall_gap

    def thermal_dt(self) -> float:
        """Length of the thermal step that the rates being evaluated are for [s]."""
        if self.settings.frozen_mechanics:
            return float(self.settings.time_step)
        return self.substeps * self.sim.dt

    def generation_rates(self) -> None:
        """The heat generation columns from the accumulated dissipated energy
        (engine/generation.py); the thermal step clears the accumulators after using them."""
        generation.rates(self)

    def _generation_used(self) -> None:
        generation.clear(self)

    def evaluate_terms(self, time: float) -> None:
        """Add the heat of every term other than the contact conduction (at this state and
        ``time``; the per-particle fields are filled first), and the heat generation."""
        if not self.fuse_generation:  # (else the explicit update converts them)
            self.generation_rates()
        if not self.terms:
            return
        sim = self.sim
        if self.field_provider.active:
            n = sim.particles.count
            if self.fields.shape != (field_kernels.NFIELDS, n):
                self.fields = np.zeros((field_kernels.NFIELDS, n))
            self.field_provider.update(time, self.fields)
        if self.voronoi is not None:
            self.voronoi.update(self.fields)
        ranged = any(t.target == "range" for t in self.terms)
        if ranged and self.range_set.due(sim):
            self.range_set.build(sim, *self._range_gaps())
            self.term_ready[:] = False
        frozen = self.reuse_conductance and self.settings.frozen_mechanics and self.override == 0
        fused = -1  # a per-particle term already evaluated with the one before it
        for index, term in enumerate(self.terms):
            if index == fused:
                continue
            if term.target == "range":
                self._range_term(index, term, frozen)
            elif term.target == "contacts":
                self._contact_term(index, term, frozen)
            elif term.target == "particles":
                following = self.terms[index + 1] if index + 1 < len(self.terms) else None
                if following is not None and following.target == "particles":
                    fused = index + 1
                    self._particle_term(term, following)
                else:
                    self._particle_term(term)
            elif term.target == "external":
                self._external_term(index, term)
            else:  # pragma: no cover - the registry refuses other targets
                raise ConfigError(f"{term.key}: no pair set of kind {term.target!r}")

    def set_external_term(self, key: str, pairs: ExternalPairSet) -> None:
        """Evaluate the term selected by case key ``key`` on an external pair set.

        The pairs are given by global id (:meth:`ExternalPairSet.set_pairs`) and stay with
        their particles through rebuilds; a provider (the Voronoi tessellation) or a script
        may replace them between steps. Kept in checkpoints.
        """
        (term,) = [t for t in self.terms if t.key == key]
        term.target = "external"
        self.external = pairs
        self.external_term = key
        self.term_ready[:] = False
        self.in_use = self._mechanisms_in_use()

    def _voronoi_term(self, term: HeatTerm) -> None:
        """A Voronoi model: its external set, filled by the tessellation (or, with
        ``geometry: porosity``, by the near pairs and the porosity closure)."""
        closure = getattr(term.params, "geometry", "tessellation") == "porosity"
        self.external = ExternalPairSet(INPUT_WIDTH)
        self.external_term = term.key
        gap = (lambda r_max: max(term.max_gap(r_max))) if closure else None
        self.voronoi = VoronoiProvider(self.sim, self.settings.tessellation, self.external, gap)

    def _external_term(self, index: int, term: HeatTerm) -> None:
        sim = self.sim
        p = sim.particles
        ext = self.external
        ext.prepare(sim)
        h, _ = self._stored(index, ext.count, 0)
        if self.external_wall_conductance.shape[0] < ext.wall_count:
            self.external_wall_conductance = np.zeros(ext.wall_count)
            self.external_stamp = -1
        k_i, k_j = term.k_columns if self.override else (-1, -1)
        # frozen mechanics, constant properties, a tessellation that did not change: the
        # conductances of the last evaluation hold (the heat is recomputed from them)
        frozen = self.reuse_conductance and self.settings.frozen_mechanics and self.override == 0
        reuse = (frozen and self.voronoi is not None and not self.voronoi.closure
                 and self.external_stamp == ext.updates)  # fmt: skip
        rows = max(ext.count // passes.PARTICLE_CHUNK, p.count // passes.WALL_CHUNK) + 1
        scratch = self._term_rows(rows)
        if not reuse:
            tolerance = 0.0
            settings = self.settings.tessellation
            if term.evaluator == passes.EVAL_VORONOI and not frozen and settings is not None:
                tolerance = float(settings.conductance_gap_tolerance)
            if tolerance > 0.0 and (self.external_reuse_stamp != ext.updates
                                    or self.external_reuse.shape[0] != ext.count):  # fmt: skip
                self.external_reuse = np.full((ext.count, passes.REUSE_WIDTH), np.nan)
                self.external_reuse_stamp = ext.updates
            self.external_evaluations += passes.external_pair_pass(
                p.position, p.radius, p.type_id, ext.i, ext.j, ext.inputs, sim.lower, sim.upper,
                sim.periodic, term.evaluator, term.model_id, term.table, k_i, k_j, self.k_p,
                scratch, h, tolerance, self.external_reuse,
            )  # fmt: skip
            self.external_pair_steps += ext.count
            self.external_stamp = ext.updates
        if term.evaluator == passes.EVAL_VORONOI and ext.wall_count:
            passes.external_wall_pass(
                p.position, p.radius, p.temperature, p.type_id, ext.wall_i, ext.wall_w,
                ext.wall_offsets, ext.wall_inputs, sim.wall_kind, sim.wall_rows,
                sim.wall_material, term.model_id, term.table, k_i, k_j, self.k_p, self.k_w,
                scratch, term.wall_column, p.heat_columns, self.conductance_sum,
                not reuse, self.external_wall_conductance,
            )  # fmt: skip
        passes.csr_heat(
            ext.offsets, ext.entries, ext.i, ext.j, h, p.temperature, term.column,
            p.heat_columns, self.conductance_sum,
        )  # fmt: skip

    def _particle_term(self, term: HeatTerm, second: HeatTerm | None = None) -> None:
        """A per-particle term, and the next one in the same pass if given."""
        p = self.sim.particles
        other = second or term
        passes.particle_pass(
            p.temperature, p.radius, p.type_id, self.fields, term.evaluator, term.model_id,
            term.table, term.column, other.evaluator, other.model_id, other.table,
            -1 if second is None else second.column, p.heat_columns,
            self.conductance_sum,
        )  # fmt: skip

    def _stored(self, index: int, pairs: int, walls: int) -> tuple[np.ndarray, np.ndarray]:
        """The per-pair conductance arrays of term ``index`` with at least the given sizes."""
        if self.term_conductance[index].shape[0] < pairs:
            self.term_conductance[index] = np.zeros(pairs)
            self.term_ready[index] = False
        if self.term_wall_conductance[index].shape[0] < walls:
            self.term_wall_conductance[index] = np.zeros(walls)
            self.term_ready[index] = False
        return self.term_conductance[index], self.term_wall_conductance[index]

    def _range_term(self, index: int, term: HeatTerm, frozen: bool) -> None:
        sim = self.sim
        p = sim.particles
        rs = self.range_set
        by_mech = p.heat_columns
        store = frozen or self.record_conductances
        pair_h, wall_h = self._stored(
            index, rs.count if store else 0, rs.wall_count if store else 0
        )
        if frozen and self.term_ready[index]:
            passes.pair_heat_from_conductance(
                rs.i, rs.j, rs.group_start, pair_h, p.temperature, term.column, by_mech,
                self.conductance_sum,
            )  # fmt: skip
            passes.wall_heat_from_conductance(
                rs.wall_w, rs.wall_row_start, sim.wall_rows, wall_h, p.temperature,
                term.wall_column, by_mech, self.conductance_sum,
            )  # fmt: skip
            return
        k_i, k_j = term.k_columns if self.override else (-1, -1)
        rows = max(rs.ngroups, p.count // passes.WALL_CHUNK + 1)
        scratch = self._term_rows(rows)
        range_pair_pass, range_wall_pass = passes.range_passes_for(
            term.evaluator, term.model_id, term.needs_contact_radius, k_i >= 0
        )
        range_pair_pass(
            p.position, p.radius, p.temperature, p.type_id, rs.i, rs.j, rs.group_start,
            sim.lower, sim.upper, sim.periodic, term.evaluator, term.model_id, term.table, k_i,
            k_j, self.k_p, scratch, term.column, by_mech, self.conductance_sum, store, pair_h,
            term.needs_contact_radius,
        )  # fmt: skip
        range_wall_pass(
            p.position, p.radius, p.temperature, p.type_id, rs.wall_w, rs.wall_row_start,
            sim.wall_kind, sim.wall_rows, sim.wall_material, term.evaluator, term.model_id,
            term.table, k_i, k_j, self.k_p, self.k_w, scratch, term.wall_column, by_mech,
            self.conductance_sum, store, wall_h, term.needs_contact_radius,
        )  # fmt: skip
        self.term_ready[index] = frozen

    def _contact_term(self, index: int, term: HeatTerm, frozen: bool) -> None:
        sim = self.sim
        p = sim.particles
        pb, wb = sim.pairs, sim.walls
        by_mech = p.heat_columns
        store = frozen or self.record_conductances
        pair_h, wall_h = self._stored(index, pb.count if store else 0, wb.count if store else 0)
        if frozen and self.term_ready[index]:
            passes.pair_heat_from_conductance(
                pb.i, pb.j, pb.group_start, pair_h, p.temperature, term.column, by_mech,
                self.conductance_sum,
            )  # fmt: skip
            passes.wall_heat_from_conductance(
                wb.j, sim.wall_row_start, sim.wall_rows, wall_h, p.temperature,
                term.wall_column, by_mech, self.conductance_sum,
            )  # fmt: skip
            return
        k_i, k_j = term.k_columns if self.override else (-1, -1)
        rows = max(pb.ngroups, p.count // passes.WALL_CHUNK + 1)
        scratch = self._term_rows(rows)
        passes.contact_term_pair_pass(
            p.position, p.radius, p.mass, p.temperature, p.type_id, pb.i, pb.j, pb.group_start,
            pb.state, pb.normal_force, pb.history, sim.lower, sim.upper, sim.periodic,
            self.radius_id, self.radius_table, term.evaluator, term.model_id, term.table, k_i,
            k_j, self.k_p, scratch, term.column, by_mech, self.conductance_sum, store, pair_h,
        )  # fmt: skip
        passes.contact_term_wall_pass(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.j, sim.wall_row_start,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, self.radius_id, self.radius_table, term.evaluator,
            term.model_id, term.table, k_i, k_j, self.k_p, self.k_w, scratch, term.wall_column,
            by_mech, self.conductance_sum, store, wall_h,
        )  # fmt: skip
        self.term_ready[index] = frozen

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
            raise SimulationError(
                f"thermal time step {dt:.4g} s exceeds the explicit Euler limit m c / ΣH = "
                f"{self.limit:.4g} s of particle {self.limit_particle} at step "
                f"{sim.step_count} (t = {time:.6g} s); use a smaller thermal.substeps / "
                "thermal.time_step or 'auto'",
                sim.step_count,
                time,
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
                f"temperature of particle {bad_gid} became {bad_temperature:.6g} K at step "
                f"{sim.step_count} (t = {time:.6g} s); likely cause: {cause}",
                sim.step_count,
                time,
                bad_gid,
            )
        if self.settings.substeps == "auto" and math.isfinite(self.limit):
            n = int(0.5 * self.limit / sim.dt)
            self.substeps = min(max(n, 1), self.settings.max_substeps)

    # ---------------------------------------------------------------------------- ledger
    def thermal_energy(self, mask: np.ndarray | None = None) -> float:
        """Σ m c T over all particles (or ``mask``) [J] (Σ m h(T) with a tabulated c)."""
        p = self.sim.particles
        n = self.sim.owned_count  # (all particles; on several MPI ranks the owned ones)
        t, m, ty = p.temperature[:n], p.mass[:n], p.type_id[:n]
        if mask is not None:
            t, m, ty = t[mask[:n]], m[mask[:n]], ty[mask[:n]]
        if self.has_c_table:
            return self.sim.sum_over_ranks(
                kernels.total_enthalpy(t, m, ty, self.c_t, self.c_v, self.c_n)
            )
        return self.sim.sum_over_ranks(float(np.sum(m * self.specific_heat_by_type[ty] * t)))

    def inserted(self, temperature: np.ndarray, mass: np.ndarray, type_id: np.ndarray) -> None:
        """Ledger the thermal energy that inserted particles bring in."""
        if self.has_c_table:
            e = kernels.total_enthalpy(temperature, mass, type_id, self.c_t, self.c_v, self.c_n)
        else:
            e = float(np.sum(mass * self.specific_heat_by_type[type_id] * temperature))
        self.cumulative["inserted_heat"] += e

    def boundary_heat(self) -> float:
        """Heat that entered the particles through every boundary mechanism so far [J]."""
        return sum(v for k, v in self.cumulative.items() if k.startswith("heat_in_"))

    def balance_error(self) -> float:
        """U(t) - U(0) - boundary heat + heat absorbed by fixed particles - heat of inserted
        particles - resets of newly fixed particles [J]; round-off."""
        cum = self.cumulative
        return (self.thermal_energy() - self.initial_energy - self.boundary_heat()
                + cum["fixed_absorbed"] - cum["inserted_heat"] - cum["fixed_reset"])  # fmt: skip

    def summary(self) -> dict[str, float]:
        """Temperature statistics, heat rates by mechanism [W] and the heat ledger [J].

        ``heat_rate_<mechanism>``: for pairwise mechanisms the heat exchanged, ½ Σ|Q_i| (they
        sum to zero); for boundary mechanisms the net heat into the particles, Σ Q_i.
        """
        self.complete_rates()
        p = self.sim.particles
        out: dict[str, float] = {}
        if p.count:
            out.update(temperature_mean=float(p.temperature.mean()),
                       temperature_min=float(p.temperature.min()),
                       temperature_max=float(p.temperature.max()))  # fmt: skip
        for k in self.in_use:
            mech = heat.MECHANISMS[k]
            col = p.heat_rate_by_mechanism[:, k]
            total = float(col.sum()) if mech.boundary else 0.5 * float(np.abs(col).sum())
            out[f"heat_rate_{mech.name}"] = total
        out["thermal_energy"] = self.thermal_energy()
        for k in self.in_use:
            if heat.MECHANISMS[k].boundary:
                name = f"heat_in_{heat.HEAT_MECHANISMS[k]}"
                out[name] = self.cumulative[name]
        out.update({k: v for k, v in self.cumulative.items() if not k.startswith("heat_in_")})
        out["heat_balance_error"] = self.balance_error()
        if self.generation.active:
            out.update(generation.ledger(self))
        out["thermal_limit"] = self.limit
        if self.range_set is not None:
            out["range_pair_count"] = self.range_set.count
        if self.voronoi is not None:
            out["voronoi_pair_count"] = self.external.count
            out["tessellation_count"] = self.voronoi.count
            out["tessellation_seconds"] = self.voronoi.seconds
            out["voronoi_evaluated_fraction"] = self.external_evaluations / max(
                self.external_pair_steps, 1
            )
        return out

    # ------------------------------------------------------------------------ checkpoints
    def state_dict(self) -> dict[str, Any]:
        """Scalars and arrays of the engine (the range set's under ``range_set`` and
        ``range_set__<array>``), the layout the checkpoint writer stores."""
        from thermodem.engine.restart import _object_state

        state = _object_state(self, SKIP)
        for name, prefix in (("range_set", RANGE_PREFIX), ("external", EXTERNAL_PREFIX)):
            pairs = getattr(self, name)
            if pairs is not None:
                sub = pairs.state_dict()
                state["scalars"][name] = sub["scalars"]
                state["arrays"].update({f"{prefix}{k}": v for k, v in sub["arrays"].items()})
        if self.voronoi is not None:
            sub = self.voronoi.state_dict()
            state["scalars"]["voronoi"] = sub["scalars"]
            state["arrays"].update({f"{VORONOI_PREFIX}{k}": v for k, v in sub["arrays"].items()})
        if self.field_provider.active:
            sub = self.field_provider.state_dict()
            state["scalars"]["field_provider"] = sub["scalars"]
            state["arrays"].update({f"{FIELDS_PREFIX}{k}": v for k, v in sub["arrays"].items()})
        if self.implicit is not None:
            sub_scalars, sub_arrays = self.implicit.state()
            if sub_scalars:
                state["scalars"]["implicit"] = sub_scalars
                state["arrays"].update({f"{IMPLICIT_PREFIX}{k}": v for k, v in sub_arrays.items()})
        return state

    def load_state_dict(self, state: dict[str, Any]) -> None:
        scalars = dict(state["scalars"])
        arrays = dict(state["arrays"])
        range_scalars = scalars.pop("range_set", None)
        range_arrays = {
            k[len(RANGE_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(RANGE_PREFIX)
        }
        field_scalars = scalars.pop("field_provider", None)
        field_arrays = {
            k[len(FIELDS_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(FIELDS_PREFIX)
        }
        implicit_scalars = scalars.pop("implicit", None)
        implicit_arrays = {
            k[len(IMPLICIT_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(IMPLICIT_PREFIX)
        }
        voronoi_scalars = scalars.pop("voronoi", None)
        voronoi_arrays = {
            k[len(VORONOI_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(VORONOI_PREFIX)
        }
        external_scalars = scalars.pop("external", None)
        external_arrays = {
            k[len(EXTERNAL_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(EXTERNAL_PREFIX)
        }
        from thermodem.engine.restart import check_thermal_arrays, keep_derived_thermal

        # tables and ids made from the case stay this case's (a restart may change the case)
        changed = keep_derived_thermal(self, scalars, arrays)
        check_thermal_arrays(self, arrays)
        for name, value in scalars.items():
            current = getattr(self, name, None)
            if isinstance(current, float) and value is not None:
                value = float(value)
            if isinstance(current, dict):
                value = {k: float(v) for k, v in value.items()}
            setattr(self, name, value)
        for name, value in arrays.items():
            setattr(self, name, np.array(value, copy=True))
        if changed:  # conductances kept from the old case's models are stale
            self.conductance_ready = False
            self.term_ready[:] = False
        if self.range_set is not None:
            if range_scalars is None:
                raise ConfigError(
                    "checkpoint has no range pair set but this case's thermal terms need one "
                    "(thermal.indirect_conduction, or a direct model that conducts across gaps)"
                )
            self.range_set.load_state_dict({"scalars": range_scalars, "arrays": range_arrays})
        if external_scalars is not None:
            if self.external is None:  # a script had put a term on an external set
                self.set_external_term(self.external_term, ExternalPairSet())
            self.external.load_state_dict({"scalars": external_scalars, "arrays": external_arrays})
        if self.voronoi is not None:
            if voronoi_scalars is None:
                raise ConfigError(
                    f"checkpoint has no tessellation state but this case's {self.external_term}"
                    " is a Voronoi model"
                )
            self.voronoi.load_state_dict({"scalars": voronoi_scalars, "arrays": voronoi_arrays})
        if field_scalars is not None and self.field_provider.active:
            self.field_provider.load_state_dict({"scalars": field_scalars, "arrays": field_arrays})
        if implicit_scalars is not None and self.implicit is not None:
            self.implicit.load_state(implicit_scalars, implicit_arrays)
        self.conditions.invalidate()


def _range_key(term: HeatTerm) -> str:
    """'thermal.indirect_conduction.cutoff_gap_ratio = 100.0' (the key that sets the range)."""
    name = term.spec.range_parameter
    if name is None:
        return f"{term.key} = {term.choice.model!r}"
    return f"{term.key}.{name} = {getattr(term.params, name)!r}"


def _range_allowed(term: HeatTerm, factor: float) -> str:
    """What the range parameter may be: its value scaled by ``factor`` (ranges are
    proportional to it)."""
    name = term.spec.range_parameter
    if name is None:
        return "smaller range parameters or a larger domain"
    return f"{name} below {getattr(term.params, name) * factor:.6g} (or a larger domain)"
