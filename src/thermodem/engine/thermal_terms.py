"""Heat terms on their pair sets: the part of the thermal engine that evaluates every term
other than the fused contact conduction (range set, contact lists, external and Voronoi
sets, particle terms) and checks the range sets against the domain.

A mixin of :class:`thermodem.engine.thermal.ThermalEngine` (split from that module by concern;
the state it reads and writes is the engine's).
"""

from __future__ import annotations

import numpy as np

from thermodem.engine import generation
from thermodem.engine.external_set import ExternalPairSet
from thermodem.engine.terms import HeatTerm
from thermodem.engine.voronoi import INPUT_WIDTH, VoronoiProvider
from thermodem.errors import ConfigError
from thermodem.kernels import fields as field_kernels
from thermodem.kernels import heat_terms as passes
from thermodem.kernels import range_pass


class TermEvaluation:
    """The heat-term passes of the thermal engine (see the module docstring)."""

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
            n = sim.owned_count  # (on several MPI ranks the ghosts take no per-particle term)
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
            voronoi = term.evaluator == passes.EVAL_VORONOI
            self.external_evaluations += passes.EXTERNAL_PAIR_PASSES[voronoi](
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
        """A per-particle term, and the next one in the same pass if given, on the particles
        this process owns (all; on several MPI ranks not the ghosts, whose heat their owners
        compute: the pass loops over the length of the temperatures it is given)."""
        p = self.sim.particles
        n = self.sim.owned_count
        other = second or term
        passes.particle_pass(
            p.temperature[:n], p.radius, p.type_id, self.fields, term.evaluator, term.model_id,
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
        range_pair_pass, range_wall_pass = range_pass.range_passes_for(
            term.evaluator, term.model_id, term.needs_contact_radius, k_i >= 0,
            term.table.shape[2],
        )  # fmt: skip
        chunked = range_pass.runs_in_chunks(term.evaluator, term.model_id)
        geometry, cols = range_pass.chunk_buffers(
            self.range_chunks, rs.ngroups, term.table.shape[2], chunked
        )
        range_pair_pass(
            p.position, p.radius, p.temperature, p.type_id, rs.i, rs.j, rs.group_start,
            sim.lower, sim.upper, sim.periodic, term.evaluator, term.model_id, term.table, k_i,
            k_j, self.k_p, scratch, term.column, by_mech, self.conductance_sum, store, pair_h,
            term.needs_contact_radius, geometry, cols,
        )  # fmt: skip
        range_wall_pass(
            p.position, p.radius, p.temperature, p.type_id, rs.wall_w, rs.wall_row_start,
            sim.wall_kind, sim.wall_rows, sim.wall_material, term.evaluator, term.model_id,
            term.table, k_i, k_j, self.k_p, self.k_w, scratch, term.wall_column, by_mech,
            self.conductance_sum, store, wall_h, term.needs_contact_radius,
        )  # fmt: skip
        self.term_ready[index] = frozen

    def _contact_term(self, index: int, term: HeatTerm, frozen: bool) -> None:
        """A heat term on the contact list (and, on several MPI ranks, on the mirror list:
        pairs whose particle i is a ghost and j owned, whose heat j needs) and the wall
        contacts."""
        sim = self.sim
        p = sim.particles
        pb, wb = sim.pairs, sim.walls
        by_mech = p.heat_columns
        store = frozen or self.record_conductances
        pair_h, wall_h = self._stored(index, pb.count if store else 0, wb.count if store else 0)
        lists = [(pb, pair_h)]
        mirror = sim.mirror
        if mirror is not None and mirror.count:
            mirror_h = self.term_mirror_conductance[index]
            if store and mirror_h.shape[0] < mirror.count:
                mirror_h = self.term_mirror_conductance[index] = np.zeros(mirror.capacity)
                self.term_ready[index] = False
            lists.append((mirror, mirror_h))
        if frozen and self.term_ready[index]:
            for buf, h in lists:
                passes.pair_heat_from_conductance(
                    buf.i, buf.j, buf.group_start, h, p.temperature, term.column, by_mech,
                    self.conductance_sum,
                )  # fmt: skip
            passes.wall_heat_from_conductance(
                wb.j, sim.wall_row_start, sim.wall_rows, wall_h, p.temperature,
                term.wall_column, by_mech, self.conductance_sum,
            )  # fmt: skip
            return
        k_i, k_j = term.k_columns if self.override else (-1, -1)
        rows = max(*(buf.ngroups for buf, _ in lists), p.count // passes.WALL_CHUNK + 1)
        scratch = self._term_rows(rows)
        for buf, h in lists:
            passes.contact_term_pair_pass(
                p.position, p.radius, p.mass, p.temperature, p.type_id, buf.i, buf.j,
                buf.group_start, buf.state, buf.normal_force, buf.history, sim.lower,
                sim.upper, sim.periodic, self.radius_id, self.radius_table, term.evaluator,
                term.model_id, term.table, k_i, k_j, self.k_p, scratch, term.column, by_mech,
                self.conductance_sum, store, h,
            )  # fmt: skip
        passes.contact_term_wall_pass(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.j, sim.wall_row_start,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, self.radius_id, self.radius_table, term.evaluator,
            term.model_id, term.table, k_i, k_j, self.k_p, self.k_w, scratch, term.wall_column,
            by_mech, self.conductance_sum, store, wall_h,
        )  # fmt: skip
        self.term_ready[index] = frozen


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
