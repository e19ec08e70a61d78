"""A simulation on several MPI ranks: the serial kernels on each rank's owned + ghost particles.

Each rank owns the particles in its box of the recursive bisection
(:mod:`thermodem.mpi.decomposition`) and holds copies (*ghosts*) of the particles of other
ranks within the halo width of its box: one :class:`Particles` array, the ``owned_count``
owned particles first, the ghosts after them. The serial kernels run unchanged on it:

- **Pair lists.** The contact list is built over owned + ghost particles and split in two:
  ``pairs``, the pairs whose particle i (the lower global id, the serial orientation) is
  owned, and ``mirror``, the pairs whose i is a ghost and j owned. Pairs of two ghosts are
  dropped. A pair that straddles two ranks is in ``pairs`` on the rank owning its lower
  global id and in ``mirror`` on the other; both evaluate it from bitwise the same inputs
  (positions, velocities, history, temperatures), so both compute the same force, history
  and heat, and each keeps its own particle's side. The ledger rows of ``mirror`` are
  discarded, so every pair's dissipation, stored energy and contact count is counted once
  (on the owner of its lower global id). Wall pairs are listed for owned particles only.
- **Each step**: the thermal step on the owned particles (the limit and failures agreed by
  a reduction), kick and drift of the owned particles, a reduction of the largest
  displacement and of any failure, the halo exchange of the moving state of the ghosts
  (position, velocity, angular velocity, temperature), the pair passes, the second kick of
  the owned particles, a reduction of the largest overlap.
- **Rebuild** (when the largest displacement over all ranks passes half the skin, as in
  serial): the touching pairs' histories become records keyed by the two global ids, which
  travel with the pair's lower-id particle; the bisection is recomputed when the particle
  count of the fullest rank exceeds the mean by more than ``rebalance_threshold``; owned
  particles that left their box migrate with their whole state (every particle array, the
  thermal arrays, their pairs' and wall pairs' history records); the ghosts within the halo
  width ``h = 2 R_max + skin + max(extra_distance, largest range gap)`` of each box are sent
  with their records; the lists are built and each listed pair takes its record.

Ledgers are per rank and summed over the ranks when reported (:mod:`thermodem.mpi.gather`).
"""

from __future__ import annotations

import time as wallclock
import warnings
from typing import Any

import numpy as np

from thermodem.config.schema import Case
from thermodem.engine import external_loads as EL
from thermodem.engine.neighbor_list import rebuild_due
from thermodem.engine.simulation import Simulation
from thermodem.errors import SimulationError
from thermodem.geometry import wall_layout as WL
from thermodem.geometry.insertion import InsertedParticles
from thermodem.kernels import contact as C
from thermodem.kernels import pair_pass as PP
from thermodem.kernels.halo import near_box
from thermodem.kernels.integrate import (
    CHECK_CHUNK,
    advance_walls,
    final_kick,
    kick_drift,
    reduce_checks,
    reset_forces,
)
from thermodem.mpi import exchange as X
from thermodem.mpi.decomposition import box_distance
from thermodem.mpi.support import check_case, check_thermal
from thermodem.state.pairs import PairBuffers
from thermodem.state.particles import Particles

#: Default imbalance (largest rank count / mean - 1) above which a rebuild re-bisects.
REBALANCE_THRESHOLD = 0.1


class DistributedSimulation(Simulation):
    """A :class:`Simulation` on the ranks of ``comm`` (default MPI.COMM_WORLD); see the module
    docstring. Every method that reports a global number is collective."""

    def __init__(
        self,
        case: Case,
        threads: int | None = None,
        *,
        insert_particles: bool = True,
        comm: Any = None,
        rebalance_threshold: float = REBALANCE_THRESHOLD,
    ) -> None:
        from mpi4py import MPI

        check_case(case)  # before anything is built
        self.comm = comm if comm is not None else MPI.COMM_WORLD
        self.rank = self.comm.Get_rank()
        self.size = self.comm.Get_size()
        self.says_warnings = self.rank == 0
        self.rebalance_threshold = float(rebalance_threshold)
        #: hand each box to the next rank at every rebuild, so that every particle migrates
        #: with its state and pair histories (a test of the migration; results do not change)
        self.rotate_owners = False
        self._owned = 0
        self._total = 0
        self._distributed = False  # every rank holds the same full set until the first build
        self.decomposition = None
        self.halo = X.Halo()
        self.halo_width = 0.0
        self.rebalances = 0
        self.migrated = 0
        self.rebuild_seconds = 0.0
        #: seconds in the per-step reductions (they include waiting for the slowest rank)
        self.reduce_seconds = 0.0
        self._grid: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.mirror: PairBuffers | None = None
        self.stop_requested = 0  # set by a signal handler of this rank
        self.stop_agreed = 0  # any rank asked to stop (after each step)
        self._global_contacts = 0
        #: particles poured on rank 0 waiting for the next rebuild (add_particles)
        self.poured: list[Particles] = []
        self._radius_max = 0.0  # agreed at the last distributing rebuild (radius_max)
        super().__init__(case, threads, insert_particles=insert_particles)
        if self.thermal is not None:
            check_thermal(self.thermal)

    # ------------------------------------------------------------------------ rank hooks
    @property
    def owned_count(self) -> int:
        return self._owned if self._distributed else self.particles.count

    @property
    def global_count(self) -> int:
        return self._total

    @property
    def global_contacts(self) -> int:
        return self._global_contacts

    @property
    def ghost_count(self) -> int:
        return self.particles.count - self.owned_count

    def sum_over_ranks(self, value: float) -> float:
        """Collective. Before the first rebuild distributes them (a restart's rates computed
        on the whole restored set, mpi/gather.py: load_distributed) every rank holds every
        particle: its own sum is the whole simulation's."""
        total = float(X.allreduce_sum(self.comm, np.array([float(value)]))[0])
        return total if self._distributed else float(value)

    def grid_box(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self._grid if self._grid is not None else (self.lower, self.upper, self.periodic)

    def radius_max(self) -> float:
        """The R_max agreed by every rank at the last distributing rebuild (no reduction
        here: the range sets are rebuilt by each rank on its own schedule); the local one
        before the first (every rank then holds every particle)."""
        local = super().radius_max()
        return max(local, self._radius_max) if self._distributed else local

    def set_threads(self, threads: int | None = None) -> int:
        """One Numba thread per rank unless asked (``--threads``): the ranks share the cores."""
        from thermodem.engine.threads import apply_threads

        if threads is not None:
            self.requested_threads = int(threads)
        self.threads = self.requested_threads or 1
        self.threads_reason = (
            "requested" if self.requested_threads else f"one per rank on {self.size} MPI ranks"
        )
        apply_threads(self.threads)
        return self.threads

    # ---------------------------------------------------------------- agreement of failures
    def agree(self, error: SimulationError | None, *values: float) -> np.ndarray:
        """Collective: the maximum over the ranks of ``values``; if any rank has an ``error``,
        every rank raises the error of the lowest such rank (the same message everywhere)."""
        code = float(self.size - self.rank) if error is not None else 0.0
        t0 = wallclock.perf_counter()
        out = X.allreduce_max(self.comm, np.array([code, *values], np.float64))
        self.reduce_seconds += wallclock.perf_counter() - t0
        if out[0] > 0:
            source = self.size - int(out[0])
            payload = None
            if self.rank == source:
                payload = (str(error), error.step, error.time, error.particle)
            message, step, time, particle = self.comm.bcast(payload, root=source)
            raise SimulationError(message, step, time, particle)
        return out[1:]

    def agree_failure(self, error: SimulationError | None) -> None:
        self.agree(error)

    def agree_message(self, message: str | None) -> str | None:
        """The message of the lowest rank that has one, on every rank (one reduction, and a
        broadcast when some rank has one); the caller says it on rank 0 only
        (``says_warnings``), so a warning of the whole simulation is said once."""
        out = X.allreduce_min(
            self.comm, np.array([self.rank if message is not None else self.size], np.int64)
        )
        source = int(out[0])
        if source >= self.size:
            return None
        return self.comm.bcast(message if self.rank == source else None, root=source)

    def agree_thermal(
        self, limit: float, limit_particle: int, bad_particle: int, bad_temperature: float
    ) -> tuple[float, int, int, float]:
        """One reduction per thermal step: the smallest limit and the lowest rank with a bad
        temperature; the particle of the limit is asked for only when the limit is exceeded
        (the message names it)."""
        t0 = wallclock.perf_counter()
        out = X.allreduce_min(
            self.comm, np.array([limit, self.rank if bad_particle >= 0 else self.size], float)
        )
        self.reduce_seconds += wallclock.perf_counter() - t0
        global_limit, source = float(out[0]), int(out[1])
        th = self.thermal
        particle = -1
        if th is not None and th.substeps * self.dt > global_limit:
            mine = limit_particle if limit == global_limit else -1
            particle = int(X.allreduce_max(self.comm, np.array([mine], np.int64))[0])
        if source < self.size:
            payload = (bad_particle, bad_temperature) if self.rank == source else None
            bad_particle, bad_temperature = self.comm.bcast(payload, root=source)
            return global_limit, particle, int(bad_particle), float(bad_temperature)
        return global_limit, particle, -1, float("nan")

    # ------------------------------------------------------------------------------ step
    def step(self, complete: bool = True) -> None:
        """One step on every rank (collective); see the module docstring. ``complete`` as in
        :meth:`Simulation.step` (the total heat rates may be left to the next update)."""
        self._complete = complete
        th = self.thermal
        if th is not None and th.settings.frozen_mechanics:
            self._frozen_step()
            return
        if th is not None and self.step_count >= th.next_step:
            n = th.substeps
            th.step(n * self.dt, self.time, clear=n == 1)
            th.next_step = self.step_count + n
        p = self.particles
        own = self.owned_count
        nchunks = own // CHECK_CHUNK + 1
        if self.chunk_check.shape[0] < nchunks:
            self.chunk_check = np.zeros((nchunks, 3))
        kick_drift(
            p.position[:own], p.velocity[:own], p.angular_velocity[:own], p.force[:own],
            p.torque[:own], p.mass[:own], p.moment_of_inertia[:own], self.dt, self.lower,
            self.upper, self.periodic, self.reference[:own], self.chunk_check, self.planar,
        )  # fmt: skip
        moved, bad, code = reduce_checks(self.chunk_check, own)
        error = None
        if bad >= 0:
            try:
                self._particle_failure(bad, code)
            except SimulationError as exc:
                error = exc
        moved, stop = self.agree(error, moved, float(self.stop_requested))
        self.moved = float(moved)
        self.stop_agreed = int(stop)
        if p.external_force.shape[1]:  # (this rank's share; the ledgers are summed)
            self.ledger_cumulative["external_work"] += EL.step_work(self)
        self.time = (self.step_count + 1) * self.dt
        self.step_count += 1
        if self.wall_rows.shape[0]:
            advance_walls(self.wall_rows, WL.COL_POINT, WL.COL_VELOCITY, self.dt)
        self.pour()
        self._compute_forces(kick=True)
        self._check_overlap()

    def _frozen_step(self) -> None:
        """A step of frozen mechanics (collective): the ghosts take their owners' temperatures
        (the halo exchange), then the heat-only thermal step on the owned particles over the
        list and the mirror list, as the serial step; a stop asked on any rank is agreed."""
        th = self.thermal
        self.halo.exchange(self.comm, self.particles)
        th.step(th.settings.time_step, self.time)
        (stop,) = self.agree(None, float(self.stop_requested))
        self.stop_agreed = int(stop)
        self.step_count += 1
        self.time = self.step_count * th.settings.time_step

    # --------------------------------------------------------------------------- pouring
    def pour(self) -> None:
        """The batches of the pour entries due at this step (collective). Every rank runs each
        due entry on the same data, so their random generators stay in step: the owned
        particles that could touch the entry's region (centre closer to its bounding box
        than its radius: a candidate lies wholly inside the region) are gathered from every
        rank, and every rank draws and checks the same candidates as the serial run. The
        new particles join rank 0's owned ones and the rebuild that follows sends them to
        the ranks whose boxes hold them (:meth:`add_particles`)."""
        if not self._distributed:  # (every rank holds the whole set: as in serial)
            Simulation.pour(self)
            return
        for pourer in self.pourers:
            if not pourer.due(self.time, self.dt):
                continue
            lower, upper = pourer.region_bounds()
            p, own = self.particles, self.owned_count
            position, radius = p.position[:own], p.radius[:own]
            outside = np.maximum(np.maximum(lower - position, position - upper), 0.0)
            near = np.einsum("ij,ij->i", outside, outside) <= radius * radius
            mine = np.concatenate([position[near], radius[near, None]], axis=1)
            rows = np.concatenate(self.comm.allgather(mine))
            with warnings.catch_warnings():
                if self.rank != 0:  # (rank 0 says the warnings of the run)
                    warnings.simplefilter("ignore")
                new = pourer.emit(self.time, rows[:, :3].copy(), rows[:, 3].copy())
            self.add_particles(new)

    def add_particles(self, new: InsertedParticles) -> None:
        """Particles inserted while the run goes (collective, every rank with the same
        ``new``): every rank numbers them; rank 0 builds them, enters their energy in its
        ledgers and keeps them until the rebuild that follows adds them to its owned share
        (mpi/rebuild.py), from where they migrate to their boxes' ranks."""
        if not self._distributed:
            Simulation.add_particles(self, new)
            return
        if len(new) == 0:
            return
        if self.rank == 0:
            extra = self.new_particles(new)
            self.poured.append(extra)
        else:
            self.next_global_id += len(new)
        self._needs_rebuild = True

    def _check_overlap(self) -> None:
        limit = self.case.simulation.max_overlap_ratio
        t0 = wallclock.perf_counter()
        worst = float(X.allreduce_max(self.comm, np.array([self.max_overlap_ratio]))[0])
        self.reduce_seconds += wallclock.perf_counter() - t0
        if worst <= limit:
            return
        error = None
        if self.max_overlap_ratio == worst:
            try:
                Simulation._check_overlap(self)
            except SimulationError as exc:
                error = exc
        self.agree(error)

    # ------------------------------------------------------------------------------ forces
    def _compute_forces(self, kick: bool, contact_dt: float | None = None) -> None:
        """As the serial step's (engine/simulation.py), with the halo exchange before the
        passes, the mirror list evaluated after the list and the kick on owned particles."""
        dt = self.dt if contact_dt is None else contact_dt
        if rebuild_due(self):
            self.rebuild()
        else:
            self.halo.exchange(self.comm, self.particles)
        p = self.particles
        pb, mb, wb = self.pairs, self.mirror, self.walls
        nid, tid, rid = self.model_ids
        layout = self.history_layout.offsets
        th = self.thermal
        heat_due = (  # (as in serial: frozen mechanics heat in their own step)
            th is not None and not th.settings.frozen_mechanics and th.next_step <= self.step_count
        )
        # as in the serial step: the fused pass only with a contact conduction model
        fused = heat_due and th.contact.active
        if heat_due:
            th.prepare(self.time)
        pair_pass, wall_pass = self._contact_passes(th is not None and th.contact.active)
        if not fused:
            pair_heat = self._no_heat
        if self.generation:  # both passes deposit into both sides; the owned side is kept
            gen = (True, p.generation_energy, th.generation.select, th.generation.partition)
        else:
            gen = (False, *self._no_generation)
        nwchunks = (p.count + PP.WALL_CHUNK - 1) // PP.WALL_CHUNK
        if heat_due:
            th.fresh = True
            th.fused_rows(max(pb.ngroups, mb.ngroups, nwchunks))
            if fused:
                pair_heat = th.pair_heat_args()
            th.rates_cleared = False  # zeroed here, owned and ghost rows alike
            reset_forces(p.force, p.torque, p.mass, self.gravity, True, p.heat_columns,
                         th.conductance_sum, p.external_force, p.external_torque)  # fmt: skip
        else:
            no_mech, no_sum = self._no_heat[-3:-1]
            reset_forces(p.force, p.torque, p.mass, self.gravity, False, no_mech, no_sum,
                         p.external_force, p.external_torque)  # fmt: skip
        for buf in (pb, mb):
            if buf.count == 0 and buf is mb:
                continue
            pair_pass(
                p.position, p.velocity, p.angular_velocity, p.radius, p.mass,
                p.moment_of_inertia, p.type_id, buf.i, buf.j, buf.group_start, buf.history,
                self.lower, self.upper, self.periodic, self.extra, dt, nid, self.normal_table,
                tid, self.tangential_table, rid, self.rolling_table, p.force, p.torque,
                buf.normal_force, buf.state, buf.ledger_rows(buf.ngroups), *pair_heat, layout,
                *gen,
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
        if heat_due:
            th.after_contact_pass(self.time, self._complete)
        if kick:
            own = self.owned_count
            final_kick(p.velocity[:own], p.angular_velocity[:own], p.force[:own],
                       p.torque[:own], p.mass[:own], p.moment_of_inertia[:own],
                       self.dt, self.planar)  # fmt: skip
        self._accumulate_ledger(kick)

    # ---------------------------------------------------------------------------- rebuild
    def rebuild(self) -> None:
        """Migration, rebalancing, ghosts and lists (collective); see the module docstring."""
        from thermodem.mpi.rebuild import rebuild_distributed

        t0 = wallclock.perf_counter()
        rebuild_distributed(self)
        self.rebuild_seconds += wallclock.perf_counter() - t0

    # ------------------------------------------------------------------------ reporting
    def energies(self) -> dict[str, float]:
        from thermodem.mpi.gather import global_energies

        return global_energies(self)

    def report(self) -> dict[str, float]:
        from thermodem.mpi.gather import global_report

        self.complete_rates()  # heat rates left to the next thermal step (Simulation.step)
        return global_report(self)

    def contacts(self) -> dict[str, np.ndarray]:
        """The per-contact arrays of the whole simulation (engine/contacts.py), on every rank
        (collective): each rank evaluates its list ``pairs`` (a pair across the cut is in the
        list of the rank owning its lower global id: once) and its owned wall pairs, and the
        rows are gathered in rank order, the particle pairs of every rank first, then the wall
        contacts, as the serial order has them."""
        from thermodem.mpi.gather import gathered_contacts

        return gathered_contacts(self, Simulation.contacts(self))

    def coordination_number(self) -> np.ndarray:
        """Touching contacts of each particle of this rank (exact for the owned ones)."""
        z = super().coordination_number()
        mb = self.mirror
        if mb is not None and mb.count:
            mask = mb.state[: mb.count] == C.STATE_TOUCHING
            z += np.bincount(mb.i[: mb.count][mask], minlength=z.shape[0])
            z += np.bincount(mb.j[: mb.count][mask], minlength=z.shape[0])
        return z

    def state_dict(self) -> dict | None:
        """The complete restart state of the whole simulation, gathered to rank 0 in the
        serial layout (None on the other ranks); collective."""
        from thermodem.mpi.gather import gathered_state

        return gathered_state(self)

    def load_state(self, state: dict) -> None:
        """Continue from a (serial or gathered) restart state: every rank loads it, keeps a
        share and the next rebuild distributes it (collective)."""
        from thermodem.mpi.gather import load_distributed

        load_distributed(self, state)

    @classmethod
    def from_checkpoint(
        cls, path: str, threads: int | None = None, case: Case | None = None
    ) -> DistributedSimulation:
        """A distributed simulation continuing from a checkpoint written by any number of
        ranks (collective: every rank reads the file)."""
        from thermodem.io.checkpoint import Checkpoint, read_checkpoint
        from thermodem.mpi.runner import _build

        ckpt = path if isinstance(path, Checkpoint) else read_checkpoint(path)
        return _build(case or ckpt.case(), threads, REBALANCE_THRESHOLD, ckpt)

    def halo_summary(self) -> dict[str, float]:
        """Communication and balance figures of this run so far (collective)."""
        counts = X.allreduce_max(
            self.comm, np.array([self.owned_count, self.ghost_count], np.int64)
        )
        sums = X.allreduce_sum(
            self.comm,
            np.array([self.owned_count, self.ghost_count, self.halo.seconds, self.rebuild_seconds,
                      self.reduce_seconds, self.mirror.count if self.mirror else 0,
                      self.pairs.count]),
        )  # fmt: skip
        return {
            "ranks": self.size,
            "particles": int(sums[0]),
            "ghosts": int(sums[1]),
            "max_owned": int(counts[0]),
            "max_ghosts": int(counts[1]),
            "imbalance": float(counts[0] * self.size / max(sums[0], 1) - 1.0),
            "halo_seconds_mean": float(sums[2] / self.size),
            "rebuild_seconds_mean": float(sums[3] / self.size),
            "reduce_seconds_mean": float(sums[4] / self.size),
            "mirror_pairs": int(sums[5]),
            "pairs": int(sums[6]),
            "rebalances": self.rebalances,
        }


def neighbour_ranks(sim: DistributedSimulation, width: float) -> list[int]:
    """The other ranks whose boxes are within ``width`` of this rank's box."""
    boxes = sim.decomposition.boxes
    length = sim.upper - sim.lower
    me = boxes[sim.rank]
    return [
        r
        for r in range(sim.size)
        if r != sim.rank
        and box_distance(me[0], me[1], boxes[r, 0], boxes[r, 1], length, sim.periodic) < width
    ]


def halo_members(
    sim: DistributedSimulation, position: np.ndarray, rank: int, width: float
) -> np.ndarray:
    """Indices of ``position`` within ``width`` of the box of ``rank``."""
    box = sim.decomposition.boxes[rank]
    out = np.empty(position.shape[0], np.int64)
    lower, upper = np.ascontiguousarray(box[0]), np.ascontiguousarray(box[1])
    length = sim.upper - sim.lower
    m = near_box(np.ascontiguousarray(position), lower, upper, length, sim.periodic, width, out)
    return out[:m]


def halo_width(sim: DistributedSimulation, r_max: float) -> float:
    """2 R_max + skin + max(extra distance, largest conducting gap of the range set, the
    reach of the neighbourhood fields beyond 2 R_max: engine/fields.py: halo_reach)."""
    gap = 0.0
    th = sim.thermal
    if th is not None and r_max > 0.0:  # (no particles yet: a restart's empty start)
        for term in th.terms:
            if term.target == "range":
                g, w = term.max_gap(r_max)
                gap = max(gap, g)
        gap = max(gap, th.field_provider.halo_reach(r_max) - 2.0 * r_max)
    return 2.0 * r_max + (sim.skin or 0.0) + max(sim.extra, gap)


__all__ = ["DistributedSimulation", "halo_members", "halo_width", "neighbour_ranks"]
