"""The simulation: orchestration in plain Python around the Numba kernels.

Order inside one step (``Simulation.step``):

0. a thermal step when one is due (every ``thermal.substeps`` steps, see
   ``thermodem.engine.thermal``): the heat terms are evaluated on the state at the end of the
   previous step (the contact conduction was computed by that step's pair pass) and the
   temperatures advance by explicit Euler; with frozen mechanics every step is a thermal step
   and nothing moves;
1. first half kick and drift (velocity Verlet); in the same pass each particle is checked
   (non-finite value, outside the domain) and the largest displacement since the last
   neighbour build is found; a failed check raises before anything else moves; the work of
   the external loads over the drift is added to the ledger;
2. walls translate; pouring inserts the particles that are due;
3. the pair lists are rebuilt if a particle moved more than half the skin, or a particle plus
   a wall moved more than the skin, or particles were inserted (history carried by identity);
4. forces set to the weights, torques to zero, plus the constant external loads (and the
   conduction sums, when heat is due);
   pair passes: geometry and contact forces of every particle and wall pair, added straight
   into the particles by slab group (``thermodem.kernels.slabs``), dissipation per mechanism,
   history, ledger rows per group; when a thermal step follows, the same passes evaluate the
   contact conduction of the touching pairs, and the other heat terms are evaluated right
   after them on the same state (so the heat rates by mechanism are complete at the end of
   the step; the source column and the totals too, or, with ``step(complete=False)``, when
   :meth:`Simulation.complete_rates` or the next thermal update forms them);
5. the second half kick;
6. overlap check; 7. writers on their triggers (owned by the caller, see
   ``thermodem.engine.runner``).
"""

from __future__ import annotations

from collections.abc import Callable
from time import perf_counter

import numpy as np

from thermodem.config.schema import Case
from thermodem.engine import diagnostics as D
from thermodem.engine import external_loads as EL
from thermodem.engine.malloc import fix_mmap_threshold
from thermodem.engine.neighbor_list import rebuild_due, rebuild_lists
from thermodem.engine.simulation_insertion import ParticleInsertion
from thermodem.engine.simulation_ledger import LEDGER_DISSIPATION, SimulationLedger
from thermodem.engine.threads import ThreadGovernor, apply_threads
from thermodem.engine.validation import check_completeness, check_insertion_memory
from thermodem.errors import SimulationError
from thermodem.geometry import wall_layout as WL
from thermodem.geometry.insertion import Pourer, insert
from thermodem.geometry.walls import wall_rows
from thermodem.kernels import contact as C
from thermodem.kernels import pair_pass as PP
from thermodem.kernels.integrate import (
    CHECK_CHUNK,
    advance_walls,
    final_kick,
    kick_drift,
    reduce_checks,
    reset_forces,
)
from thermodem.models import registry
from thermodem.models.tables import pair_table  # noqa: F401 (public here too)
from thermodem.state.heat import GENERATION, HEAT_MECHANISMS
from thermodem.state.history import HistoryLayout, layout_for
from thermodem.state.pairs import PairBuffers
from thermodem.state.particles import Particles


def history_layout_of(case: Case) -> HistoryLayout:
    """The contact history columns of a case: the registered history widths of its normal,
    tangential and rolling laws, the conductance reuse's block when
    ``thermal.conductance_force_tolerance`` > 0, and the collision block of a heat generation
    model that registers one (state/history.py)."""
    models = case.contact
    thermal = case.thermal
    return layout_for(
        models.normal.spec.history_width,
        models.tangential.spec.history_width,
        models.rolling.spec.history_width,
        reuse=thermal is not None and thermal.conductance_force_tolerance > 0.0,
        collision=thermal is not None and thermal.heat_generation.spec.history_width > 0,
    )


class Simulation(ParticleInsertion, SimulationLedger):
    """A thermal DEM simulation built from a validated :class:`~thermodem.config.schema.Case`."""

    #: the MPI communicator of a run on several ranks (``thermodem.mpi``); None here
    comm = None
    #: the pairs whose particle i is another rank's ghost and j owned (``thermodem.mpi``);
    #: None here: one process lists every pair in ``pairs``
    mirror: PairBuffers | None = None

    def __init__(
        self, case: Case, threads: int | None = None, *, insert_particles: bool = True
    ) -> None:
        """Build the simulation; ``insert_particles=False`` skips the static insertion entries
        (used when the state comes from a checkpoint, see :meth:`from_checkpoint`)."""
        fix_mmap_threshold()  # freed arrays go back to the system (engine/malloc.py)
        # the thread count: the request, or chosen from the work once the particles are in
        # (set_threads below; engine/threads.py)
        self.requested_threads = None if threads is None else int(threads)
        self.threads = self.requested_threads or 1
        self.threads_reason = ""
        self.governor = ThreadGovernor(self.threads, automatic=False)
        apply_threads(self.threads)
        check_completeness(case)  # validation layer 2 (engine/validation.py)
        self.case = case
        sim = case.simulation
        self.dt = float(sim.time_step)
        # 2D (docs/two-dimensional.md): particles in the plane z = 0, discs of thickness b
        # (disc_thickness > 0) or spheres kept in the plane (disc_thickness = 0)
        self.planar = bool(sim.planar)
        self.disc_thickness = float(sim.disc_thickness)
        self.time = 0.0
        self.step_count = 0
        self.gravity = np.asarray(sim.gravity, np.float64)
        self.rng = np.random.default_rng(sim.seed)
        # materials and model tables
        self.material_names = list(case.materials)
        self.material_index = {n: k for k, n in enumerate(self.material_names)}
        self.density = np.array([case.materials[n].density for n in self.material_names])
        models = case.contact
        self.model_ids = (
            models.normal.spec.model_id,
            models.tangential.spec.model_id,
            models.rolling.spec.model_id,
        )
        self.normal_table = pair_table(models.normal, case, self.material_names)
        self.tangential_table = pair_table(models.tangential, case, self.material_names)
        self.rolling_table = pair_table(models.rolling, case, self.material_names)
        #: the columns of the contact history, allocated from the registry (state/history.py)
        self.history_layout = history_layout_of(case)
        # domain and walls
        dom = case.domain
        self.lower = np.asarray(dom.lower, np.float64)
        self.upper = np.asarray(dom.upper, np.float64)
        if self.planar:  # the slab of the discs around z = 0 (one cell layer, see rebuild)
            half = 0.5 * (self.disc_thickness if self.disc_thickness > 0.0 else 1.0)
            self.lower[2], self.upper[2] = -half, half
        self.periodic = np.asarray(dom.periodic, np.bool_)
        self.wall_kind, self.wall_rows, self.wall_labels = wall_rows(
            case.walls, self.material_index, self.planar
        )
        self.wall_material = self.wall_rows[:, WL.COL_MATERIAL].astype(np.int32)
        self.wall_reference = self.wall_rows[:, WL.COL_POINT : WL.COL_POINT + 3].copy()
        # thermal engine (absent = mechanics only)
        width = max(spec.width for spec in registry.all_models())  # any row fits
        z1, z3 = np.zeros(0), np.zeros((1, 1, width))
        z2 = np.zeros((1, width))
        # heat arguments of the contact passes when no heat is due (the scratch is unused)
        zm = np.zeros((len(HEAT_MECHANISMS), 1))  # (the layout of Particles.heat_columns)
        self._no_heat = (False, z1, 0, z3, 0, z3, 0, z1, z1, z2, zm, z1, 0.0)
        self._passes: dict[bool, tuple] = {}  # (pair pass, wall pass) by "heat compiled in"
        self._ledger_totals = np.zeros(C.LEDGER_WIDTH + 1)  # scratch of _accumulate_ledger
        self.thermal = None
        if case.thermal is not None:
            from thermodem.engine.thermal import ThermalEngine

            self.thermal = ThermalEngine(self, case.thermal)
        # heat generation: per-particle accumulators of the dissipated energy (the contact
        # passes add to them at every step; the thermal step turns them into heat)
        self.generation = self.thermal is not None and self.thermal.generation.active
        self._no_generation = (np.zeros((1, 0)), np.zeros(len(GENERATION)), np.zeros((1, 1, 2)))
        # particles
        self.mechanisms = len(HEAT_MECHANISMS) if self.thermal is not None else 0
        # constant external loads (engine/external_loads.py): two more particle arrays
        self.particles = Particles.empty(
            self.mechanisms, external=bool(case.external_force), generation=self.generation
        )
        self.next_global_id = 0
        self.pourers: list[Pourer] = []
        if insert_particles:
            check_insertion_memory(case)  # before anything is allocated (engine/validation.py)
        for k, entry in enumerate(case.insertion):
            if entry.kind == "pour":
                self.pourers.append(Pourer(entry, self.rng, self.planar))
            elif insert_particles:
                self.add_particles(
                    insert(
                        entry,
                        self.rng,
                        self.particles.position,
                        self.particles.radius,
                        key=f"insertion.{k}",
                        domain=(self.lower, self.upper),
                        max_overlap_ratio=sim.max_overlap_ratio,
                        planar=self.planar,
                        periodic=tuple(bool(a) for a in self.periodic),
                    )
                )
        if case.external_force and insert_particles:
            EL.check_selected(case, self.particles, self.material_index)
        # neighbour list
        nb = case.neighbors
        self.extra = float(nb.extra_distance)
        self.skin = nb.skin
        self.rebuild_every_step = nb.rebuild_every_step
        self.pairs = PairBuffers(1024, self.history_layout.width)
        self.walls = PairBuffers(64, self.history_layout.width)
        self.wall_row_start = np.zeros(1, np.int64)
        self.reference = np.zeros((0, 3))
        self.chunk_check = np.zeros((1, 3))
        self._complete = True  # step(complete=...): form the total heat rates in the step
        self.moved = 0.0
        self.rebuild_count = 0
        self.slab_axis: int | None = None  # set by each neighbour rebuild
        self._needs_rebuild = True
        # ledger
        ledger_keys = ("stiffness_work", "wall_work", "external_work", "inserted_energy")
        if self.generation:  # the kinetic energy lost in collisions, the walls' shares
            ledger_keys += ("collision_energy_loss", *(f"wall_generation_{g}" for g in GENERATION))
        self.ledger_cumulative = dict.fromkeys((*LEDGER_DISSIPATION, *ledger_keys), 0.0)
        self.elastic = np.zeros(3)
        self.max_overlap_ratio = 0.0
        self.contact_count = 0
        self.callbacks: list[tuple[int, Callable[[Simulation], None]]] = []
        self._compute_forces(kick=False, contact_dt=0.0)
        self.initial_energy = self.total_energy()
        if self.thermal is not None:
            if not self.thermal.fresh:  # (else the contact pass computed every rate)
                self.thermal.compute_rates(self.time)
            self.thermal.initial_energy = self.thermal.thermal_energy()
            self.thermal.cumulative["fixed_reset"] = 0.0  # resets before t = 0 are the start
        self.set_threads()

    # ------------------------------------------------------------------------------ threads
    def set_threads(self, threads: int | None = None) -> int:
        """Set the Numba thread count: ``threads``, else the one given at construction, else
        one chosen from the particles (mean over the rest of the run, pours included) and
        the listed pairs (:func:`thermodem.engine.threads.choose_threads`). Returns it; the
        reason is in ``threads_reason``. Results do not depend on it."""
        from thermodem.engine.threads import choose_threads
        from thermodem.engine.validation import poured_particles

        if threads is not None:
            self.requested_threads = int(threads)
        end = self.case.simulation.end_time
        remaining = max(end - self.time, 0.0)
        particle_seconds = self.particles.count * remaining
        for pourer in self.pourers:
            particle_seconds += poured_particles(pourer.entry, self.time, end)[1]
        mean = particle_seconds / remaining if remaining > 0 else float(self.particles.count)
        mean = max(mean, float(self.particles.count))
        self.threads, self.threads_reason = choose_threads(
            mean, self.pairs.count, self.requested_threads
        )
        self.governor = ThreadGovernor(self.threads, automatic=self.requested_threads is None)
        apply_threads(self.threads)
        return self.threads

    @property
    def running_threads(self) -> int:
        """The thread count the steps run on now: :attr:`threads`, or 1 while the
        :class:`~thermodem.engine.threads.ThreadGovernor` of a chosen count finds 1 faster."""
        return self.governor.current

    # ---------------------------------------------- ranks (thermodem.mpi overrides these)
    @property
    def owned_count(self) -> int:
        """Particles this process owns: all of them (on several MPI ranks, the first
        ``owned_count`` of ``particles``; the ghosts follow)."""
        return self.particles.count

    @property
    def global_count(self) -> int:
        """Particles of the whole simulation (on every MPI rank together)."""
        return self.particles.count

    @property
    def global_contacts(self) -> int:
        """Touching contacts of the whole simulation at the last report (on several MPI
        ranks, updated by each time-series row)."""
        return self.contact_count

    def sum_over_ranks(self, value: float) -> float:
        """``value`` summed over the MPI ranks (itself here)."""
        return value

    def radius_max(self) -> float:
        """R_max of the whole simulation [m], 0 without particles (on several MPI ranks the
        value every rank agreed at the last distributing rebuild: a rank's own particles may
        all be smaller, and a check against it would refuse on one rank only)."""
        return float(self.particles.radius.max()) if self.particles.count else 0.0

    #: whether this process says the run's warnings (on several MPI ranks: rank 0 only)
    says_warnings = True

    def agree_message(self, message: str | None) -> str | None:
        """The warning of the whole simulation: ``message`` here (on several MPI ranks the
        message of the lowest rank that has one, on every rank; collective)."""
        return message

    def agree_failure(self, error: SimulationError | None) -> None:
        """Raise ``error`` (on several MPI ranks every rank raises the lowest failing rank's
        error, the same message everywhere; collective)."""
        if error is not None:
            raise error

    def grid_box(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lower, upper, periodic) of the region the neighbour grids cover: the domain (on
        several MPI ranks, this rank's box with its halo)."""
        return self.lower, self.upper, self.periodic

    def agree_thermal(
        self, limit: float, limit_particle: int, bad_particle: int, bad_temperature: float
    ) -> tuple[float, int, int, float]:
        """The explicit Euler limit, its particle (global id) and the first particle with a
        bad temperature (global id or -1) of the whole simulation (the arguments here)."""
        return limit, limit_particle, bad_particle, bad_temperature

    # ------------------------------------------------------------------------- neighbours
    def rebuild(self) -> None:
        """Sort particles by cell, list pairs and wall pairs, carry the history."""
        rebuild_lists(self)

    # ------------------------------------------------------------------------------ forces
    def _compute_forces(self, kick: bool, contact_dt: float | None = None) -> None:
        """Force reset, pair passes and (if ``kick``) the second half kick.

        ``contact_dt`` is the time the contact histories advance by (the time step, or 0 for
        the force evaluation at t = 0, so that a contact present at the start has not aged).
        """
        dt = self.dt if contact_dt is None else contact_dt
        if rebuild_due(self):
            self.rebuild()
        p = self.particles
        pb, wb = self.pairs, self.walls
        nid, tid, rid = self.model_ids
        layout = self.history_layout.offsets
        th = self.thermal
        heat_due = (
            th is not None and not th.settings.frozen_mechanics and th.next_step <= self.step_count
        )
        # conduction evaluated in the contact pass, for the thermal step that follows (not
        # without a contact conduction model: the pass would add zeros)
        fused = heat_due and th.contact.active
        if heat_due:
            th.prepare(self.time)
        # frozen mechanics: the contact conduction is a pass of its own (thermal_contacts.py),
        # so the force evaluation takes the mechanics-only variant (no compile of the fused one)
        pair_pass, wall_pass = self._contact_passes(
            th is not None and th.contact.active and not th.settings.frozen_mechanics
        )
        if not fused:
            pair_heat = self._no_heat
        if self.generation:
            gen = (True, p.generation_energy, th.generation.select, th.generation.partition)
        else:
            gen = (False, *self._no_generation)
        ngroups = pb.ngroups
        nwchunks = (p.count + PP.WALL_CHUNK - 1) // PP.WALL_CHUNK
        if heat_due:
            th.fresh = True
            th.fused_rows(max(ngroups, nwchunks))
            if fused:
                pair_heat = th.pair_heat_args()
            # the heat sums start at zero: zeroed here, or already by this step's Euler update
            zero = not (th.rates_cleared and th.conductance_sum.shape[0] == p.count)
            th.rates_cleared = False
            reset_forces(p.force, p.torque, p.mass, self.gravity, zero, p.heat_columns,
                         th.conductance_sum, p.external_force, p.external_torque)  # fmt: skip
        else:
            no_mech, no_sum = self._no_heat[-3:-1]
            reset_forces(p.force, p.torque, p.mass, self.gravity, False, no_mech, no_sum,
                         p.external_force, p.external_torque)  # fmt: skip
        pair_pass(
            p.position, p.velocity, p.angular_velocity, p.radius, p.mass, p.moment_of_inertia,
            p.type_id, pb.i, pb.j, pb.group_start, pb.history, self.lower, self.upper,
            self.periodic, self.extra, dt, nid, self.normal_table, tid, self.tangential_table,
            rid, self.rolling_table, p.force, p.torque, pb.normal_force, pb.state,
            pb.ledger_rows(ngroups), *pair_heat, layout, *gen,
        )  # fmt: skip
        wall_pass(
            p.position, p.velocity, p.angular_velocity, p.radius, p.mass, p.moment_of_inertia,
            p.type_id, wb.i, wb.j, self.wall_row_start, wb.history, self.wall_kind,
            self.wall_rows, self.wall_material, self.extra, dt, nid, self.normal_table, tid,
            self.tangential_table, rid, self.rolling_table, p.force, p.torque, wb.normal_force,
            wb.state, wb.ledger_rows(nwchunks), layout, *gen,
        )  # fmt: skip
        if fused:  # the wall pairs' contact conduction (a pass of its own)
            th.wall_conduction()
        if heat_due:  # the other heat terms of this state (the totals: see step())
            th.after_contact_pass(self.time, self._complete)
        if kick:
            final_kick(p.velocity, p.angular_velocity, p.force, p.torque, p.mass,
                       p.moment_of_inertia, self.dt, self.planar)  # fmt: skip
        self._accumulate_ledger(kick)

    def _contact_passes(self, conducts: bool) -> tuple:
        """(particle pair pass, wall pair pass) of this case: compiled with the contact
        conduction when the case has a contact conduction model (that pass serves the steps
        without heat too: one compiled variant, kernels/pair_pass.py), else mechanics only;
        in 2D the planar pass where it covers the case (kernels/planar_pass.py)."""
        passes = self._passes.get(conducts)
        if passes is None:
            layout = self.history_layout.offsets
            if conducts:
                th = self.thermal
                ids = (th.radius_id, th.conduction_id, th.override)
            else:
                ids = (0, 0, 0)
            passes = PP.passes_for(
                conducts, *ids, layout, self.generation, self.model_ids, self.planar
            )
            self._passes[conducts] = passes
        return passes

    # -------------------------------------------------------------------------------- step
    def complete_rates(self) -> None:
        """Form the heat rates a step left to the next thermal step (see :meth:`step`); the
        outputs, checkpoints, :meth:`report`, :meth:`contacts` and :meth:`run` call it."""
        if self.thermal is not None:
            self.thermal.complete_rates()

    def step(self, complete: bool = True) -> None:
        """Advance one time step (see the module docstring for the order); with a chosen
        thread count, timed for the :class:`~thermodem.engine.threads.ThreadGovernor`.

        ``complete=False``: the source column and the total heat rates of the new state are
        left to the next step's thermal update, which forms them anyway (one pass over the
        particles less per step), unless :meth:`complete_rates` is called first; the
        mechanism columns are complete either way. :meth:`run` and the run loop step so and
        complete the rates wherever they are read."""
        if not self.governor.active:
            self._advance(complete)
            return
        start = perf_counter()
        self._advance(complete)
        threads = self.governor.tick(perf_counter() - start)
        if threads is not None:
            apply_threads(threads)

    def _advance(self, complete: bool) -> None:
        """The step itself (:meth:`step`)."""
        self._complete = complete
        th = self.thermal
        if th is not None and th.settings.frozen_mechanics:
            th.step(th.settings.time_step, self.time)
            self.step_count += 1
            self.time = self.step_count * th.settings.time_step
            return
        if th is not None and self.step_count >= th.next_step:
            # heat over the next n steps from the positions, contacts and temperatures now;
            # with n = 1 this step's contact pass adds the heat of the next state at once
            n = th.substeps
            th.step(n * self.dt, self.time, clear=n == 1)
            th.next_step = self.step_count + n
        p = self.particles
        nchunks = p.count // CHECK_CHUNK + 1
        if self.chunk_check.shape[0] < nchunks:
            self.chunk_check = np.zeros((nchunks, 3))
        kick_drift(
            p.position,
            p.velocity,
            p.angular_velocity,
            p.force,
            p.torque,
            p.mass,
            p.moment_of_inertia,
            self.dt,
            self.lower,
            self.upper,
            self.periodic,
            self.reference,
            self.chunk_check,
            self.planar,
        )
        self.moved, bad, code = reduce_checks(self.chunk_check, p.count)
        if bad >= 0:
            self._particle_failure(bad, code)
        if p.external_force.shape[1]:
            self.ledger_cumulative["external_work"] += EL.step_work(self)
        self.time = (self.step_count + 1) * self.dt
        self.step_count += 1
        if self.wall_rows.shape[0]:
            advance_walls(self.wall_rows, WL.COL_POINT, WL.COL_VELOCITY, self.dt)
        self.pour()
        self._compute_forces(kick=True)
        self._check_overlap()

    def run(
        self,
        steps: int | None = None,
        until: float | None = None,
        callback: Callable[[Simulation], None] | None = None,
        every: int = 1,
    ) -> None:
        """Advance ``steps`` steps, or until simulated time ``until`` [s]."""
        if (steps is None) == (until is None):
            raise ValueError("give exactly one of steps= or until=")
        apply_threads(self.running_threads)  # another simulation may have changed it
        if until is not None:
            dt = self.dt
            if self.thermal is not None and self.thermal.settings.frozen_mechanics:
                dt = self.thermal.settings.time_step
            steps = max(0, int(round((until - self.time) / dt)))
        for _ in range(int(steps)):
            self.step(complete=False)
            if callback is not None and self.step_count % every == 0:
                self.complete_rates()
                callback(self)
        self.complete_rates()

    def _where(self) -> str:
        return f"at step {self.step_count} (t = {self.time:.6g} s)"

    def _particle_failure(self, index: int, code: int) -> None:
        p = self.particles
        gid = int(p.global_id[index])
        x = p.position[index]
        v = p.velocity[index]
        # the step number and time refer to the step being taken
        step, time = self.step_count + 1, self.time + self.dt
        where = f"at step {step} (t = {time:.6g} s)"
        if code == 1:
            raise SimulationError(
                f"non-finite position or velocity of particle {gid} {where}: x = {x.tolist()}, "
                f"v = {v.tolist()}; likely cause: {D.time_step_cause(self)}",
                step,
                time,
                gid,
            )
        raise SimulationError(
            f"particle {gid} left the domain {where}: position {x.tolist()} outside "
            f"[{self.lower.tolist()}, {self.upper.tolist()}], velocity {v.tolist()} m/s; "
            f"likely cause: {D.left_domain_cause(self, index)}",
            step,
            time,
            gid,
        )

    def _check_overlap(self) -> None:
        limit = self.case.simulation.max_overlap_ratio
        if self.max_overlap_ratio > limit:
            where = self._where()
            _, gid, other, kind = D.worst_overlap(self)
            who = f"particle {gid} and {kind}" + (f" {other}" if other >= 0 else "")
            ratio = f"{self.max_overlap_ratio:.3g}"
            if float(ratio) <= limit:  # (three digits would show the limit itself)
                ratio = f"{self.max_overlap_ratio:.6g}"
            raise SimulationError(
                f"overlap of {ratio} × the smaller radius ({who}) {where} "
                f"exceeds simulation.max_overlap_ratio = {limit}; likely cause: "
                f"{D.overlap_cause(self)}",
                self.step_count,
                self.time,
                gid,
            )

    # ------------------------------------------------------------------------- restart state
    def state_dict(self) -> dict:
        """The complete restart state (copies); see :mod:`thermodem.engine.restart`."""
        from thermodem.engine.restart import capture

        self.complete_rates()
        return capture(self)

    def load_state(self, state: dict) -> None:
        """Continue from a state of :meth:`state_dict` (same case, built with
        ``insert_particles=False``)."""
        from thermodem.engine.restart import restore

        restore(self, state)
        self.set_threads()  # the restored particles, not the empty start

    @classmethod
    def from_checkpoint(
        cls, path: str, threads: int | None = None, case: Case | None = None
    ) -> Simulation:
        """A simulation continuing from an HDF5 checkpoint (``case``: replaces the stored
        case, e.g. with a later end time)."""
        from thermodem.io.checkpoint import load_simulation

        return load_simulation(path, threads=threads, case=case)
