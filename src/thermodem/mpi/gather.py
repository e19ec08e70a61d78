"""Global numbers of a run on several MPI ranks: reports, frames and checkpoints.

- **Reports** (:func:`global_energies`, :func:`global_report`): the per-rank sums (energies
  over the owned particles, the ledgers each rank accumulated, the thermal summary) reduced
  over the ranks, with the same keys in the same order as the serial ``Simulation.report``.
- **Frames** (:func:`gathered_view`): the owned particles of every rank gathered to rank 0
  in global-id order, as an object the serial frame writer takes.
- **Checkpoints** (:func:`gathered_state`): the complete state gathered to rank 0 in the
  serial layout (engine/restart.py), so that one file per output time is written and any
  number of ranks, or a serial run, continues from it. The pair lists are stored as one slab
  group and marked for a rebuild; the thermal engine's per-pair arrays and the range set are
  stored empty (rebuilt at the next thermal step). :func:`load_distributed` loads such a
  state (or a serial one) on every rank; the next rebuild distributes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.engine import generation
from thermodem.engine.restart import THERMAL_RECOMPUTED  # stored empty in a gathered checkpoint
from thermodem.engine.simulation_ledger import LEDGER_DISSIPATION
from thermodem.mpi import exchange as X
from thermodem.state import heat
from thermodem.state.particles import Particles

if TYPE_CHECKING:
    from thermodem.mpi.simulation import DistributedSimulation

ENERGY_KEYS = ("kinetic_translational", "kinetic_rotational", "gravitational",
               "elastic_normal", "elastic_tangential", "elastic_rolling")  # fmt: skip
LEDGER_KEYS = ("stiffness_work", "wall_work", "external_work", "inserted_energy")
#: Per-particle arrays of the thermal engine: gathered with the particles in checkpoints.
THERMAL_PARTICLE_ARRAYS = ("conductance_sum",)


# ---------------------------------------------------------------------------------- reports
def global_energies(sim: DistributedSimulation) -> dict[str, float]:
    """Simulation.energies() of the whole simulation (collective)."""
    return global_ledger(sim)[0]


def global_ledger(sim: DistributedSimulation) -> tuple[dict[str, float], dict[str, float]]:
    """Simulation.energies() of the whole simulation and its ``ledger_cumulative`` (every
    key: the heat generation's ``collision_energy_loss`` and ``wall_generation_<g>`` too)
    summed over the ranks; collective, one reduction."""
    p = sim.particles
    n = sim.owned_count
    m, v, w = p.mass[:n], p.velocity[:n], p.angular_velocity[:n]
    cum = sim.ledger_cumulative
    keys = list(cum)  # (the same keys in the same order on every rank: the same case)
    local = np.array(
        [
            0.5 * float(np.sum(m * np.sum(v**2, axis=1))),
            0.5 * float(np.sum(p.moment_of_inertia[:n] * np.sum(w**2, axis=1))),
            -float(np.sum(m * (p.position[:n] @ sim.gravity))),
            *(float(e) for e in sim.elastic),
            *(cum[k] for k in keys),
        ]
    )
    total = X.allreduce_sum(sim.comm, local)
    out = dict(zip(ENERGY_KEYS, (float(x) for x in total[:6]), strict=True))
    ledger = dict(zip(keys, (float(x) for x in total[6:]), strict=True))
    for name in LEDGER_DISSIPATION:
        out[f"dissipated_{name}"] = ledger[name]
    if sim.generation:  # kinetic energy lost in collisions (as Simulation.energies)
        out["collision_energy_loss"] = ledger["collision_energy_loss"]
    for name in LEDGER_KEYS:
        out[name] = ledger.get(name, 0.0)
    return out, ledger


def global_report(sim: DistributedSimulation) -> dict[str, float]:
    """Simulation.report() of the whole simulation, the same keys in the same order."""
    out: dict[str, float] = dict(global_energies(sim))
    e = out
    mechanical = sum(e[k] for k in ENERGY_KEYS)
    dissipated = sum(e[f"dissipated_{k}"] for k in LEDGER_DISSIPATION)
    out["energy_balance_error"] = (
        mechanical + dissipated - e["stiffness_work"] - e["wall_work"] - e["external_work"]
        - e["inserted_energy"] - sim.initial_energy
    )  # fmt: skip
    counts = X.allreduce_sum(sim.comm, np.array([sim.owned_count, sim.contact_count], np.int64))
    worst = X.allreduce_max(sim.comm, np.array([sim.max_overlap_ratio]))
    out["particle_count"] = int(counts[0])
    out["contact_count"] = int(counts[1])
    out["max_overlap_ratio"] = float(worst[0])
    sim._global_contacts = int(counts[1])
    if sim.thermal is not None:
        out.update(global_thermal_summary(sim))
    return out


def global_thermal_summary(sim: DistributedSimulation) -> dict[str, float]:
    """ThermalEngine.summary() of the whole simulation (the same keys and order)."""
    th = sim.thermal
    p = sim.particles
    n = sim.owned_count
    t = p.temperature[:n]
    cols = p.heat_rate_by_mechanism[:n]
    cum_keys = list(th.cumulative)
    rates = []
    for k in th.in_use:
        col = cols[:, k]
        rates.append(
            float(col.sum()) if heat.MECHANISMS[k].boundary else 0.5 * float(np.abs(col).sum())
        )
    range_pairs = 0
    if th.range_set is not None:
        rs = th.range_set
        if not rs.valid or rs.reference.shape[0] != p.count:
            # stale since a rebuild renumbered the particles (a restart's first row, or a row
            # between a rebuild and the next thermal step): its indices are the old ones. Built
            # now, on these positions, as the next heat evaluation would (local to the rank)
            rs.build(sim, *th._range_gaps())
        range_pairs = int(np.count_nonzero(rs.i[: rs.count] < n))  # once: i, the lower id
    gen_keys: list[str] = []
    pending: list[float] = []
    if th.generation.active:  # the ledger it reads, the energies waiting in owned particles
        gen_keys = generation.ledger_keys(th)
        pending = p.generation_energy[:n].sum(axis=0).tolist()
    local = np.array([float(t.sum()), float(n), *rates, *(th.cumulative[k] for k in cum_keys),
                      float(range_pairs), *(sim.ledger_cumulative[k] for k in gen_keys),
                      *pending])  # fmt: skip
    total = X.allreduce_sum(sim.comm, local)
    extremes = X.allreduce_max(
        sim.comm, np.array([float(t.max()) if n else -np.inf, -float(t.min()) if n else -np.inf])
    )
    energy = th.thermal_energy()  # (collective)
    out: dict[str, float] = {}
    count = total[1]
    if count:
        out.update(temperature_mean=float(total[0] / count), temperature_min=float(-extremes[1]),
                   temperature_max=float(extremes[0]))  # fmt: skip
    q = 2
    for k in th.in_use:
        out[f"heat_rate_{heat.MECHANISMS[k].name}"] = float(total[q])
        q += 1
    cumulative = {}
    for key in cum_keys:
        cumulative[key] = float(total[q])
        q += 1
    out["thermal_energy"] = energy
    for k in th.in_use:
        if heat.MECHANISMS[k].boundary:
            name = f"heat_in_{heat.HEAT_MECHANISMS[k]}"
            out[name] = cumulative[name]
    out.update({k: v for k, v in cumulative.items() if not k.startswith("heat_in_")})
    boundary = sum(v for k, v in cumulative.items() if k.startswith("heat_in_"))
    out["heat_balance_error"] = (energy - th.initial_energy - boundary
                                 + cumulative["fixed_absorbed"] - cumulative["inserted_heat"]
                                 - cumulative["fixed_reset"])  # fmt: skip
    range_count = int(total[q])
    q += 1
    if th.generation.active:
        summed = dict(zip(gen_keys, (float(x) for x in total[q : q + len(gen_keys)]),
                          strict=True))  # fmt: skip
        out.update(generation.ledger_of(th, summed, total[q + len(gen_keys) :], cumulative))
    out["thermal_limit"] = th.limit
    if th.range_set is not None:
        out["range_pair_count"] = range_count
    return out


# ------------------------------------------------------------------------------------ gather
def gather_rows(comm: Any, rows: np.ndarray, root: int = 0) -> np.ndarray | None:
    """Rows of every rank stacked on ``root`` in rank order (None elsewhere)."""
    from mpi4py import MPI

    rows = np.ascontiguousarray(rows, np.float64)
    width = rows.shape[1]
    counts = np.zeros(comm.Get_size(), np.int64)
    comm.Gather(np.array([rows.shape[0]], np.int64), counts, root=root)
    if comm.Get_rank() != root:
        comm.Gatherv(rows.reshape(-1), None, root=root)
        return None
    out = np.empty((int(counts.sum()), width))
    sizes = counts * width
    displs = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    comm.Gatherv(rows.reshape(-1), [out.reshape(-1), (sizes, displs), MPI.DOUBLE], root=root)
    return out


def _gathered_particles(
    sim: DistributedSimulation, extras: tuple[np.ndarray, ...]
) -> tuple[Particles, list[np.ndarray]] | None:
    """The owned particles of every rank (with per-particle ``extras``) on rank 0, sorted by
    global id; None on the other ranks."""
    n = sim.owned_count
    rows = X.pack_particles(sim.particles, slice(0, n), extras)
    widths = tuple(1 if e.ndim == 1 else int(e.shape[1]) for e in extras)
    rows = gather_rows(sim.comm, rows)
    if rows is None:
        return None
    particles, out = X.unpack_particles(rows, sim.particles, widths)
    order = np.argsort(particles.global_id, kind="stable")
    return X.take_particles(particles, order), [e[order] for e in out]


class GatheredView:
    """The particles of every rank on rank 0, with what the frame writers read of a
    Simulation (io/vtk.py, io/run_files.py: FrameWriter)."""

    def __init__(
        self, sim: DistributedSimulation, particles: Particles, coordination: np.ndarray
    ) -> None:
        self.particles = particles
        self._coordination = coordination
        self.thermal = sim.thermal
        self.material_names = sim.material_names
        self.wall_rows = sim.wall_rows
        self.wall_kind = sim.wall_kind
        self.wall_labels = sim.wall_labels
        self.time = sim.time
        self.step_count = sim.step_count
        self._contacts: dict[str, np.ndarray] | None = None

    def coordination_number(self) -> np.ndarray:
        return self._coordination

    def contacts(self) -> dict[str, np.ndarray]:
        """The contacts of every rank (gathered with the particles: ``output.contacts``)."""
        if self._contacts is None:
            raise RuntimeError("the contacts were not gathered with this frame")
        return self._contacts

    def complete_rates(self) -> None:
        """The ranks formed their heat rates before the gather (:func:`gathered_view`)."""


def gathered_view(sim: DistributedSimulation) -> GatheredView | None:
    """The frame data gathered to rank 0 (None on the other ranks); collective."""
    sim.complete_rates()  # heat rates left to the next thermal step (Simulation.step)
    contacts = sim.contacts() if sim.case.output.contacts else None
    z = sim.coordination_number()[: sim.owned_count].astype(np.float64)
    out = _gathered_particles(sim, (np.concatenate([z, np.zeros(sim.ghost_count)]),))
    if out is None:
        return None
    particles, (coordination,) = out
    view = GatheredView(sim, particles, coordination.astype(np.int32))
    view._contacts = contacts
    return view


def gathered_contacts(sim: DistributedSimulation, local: dict[str, np.ndarray]) -> dict:
    """Every rank's per-contact arrays ``local`` joined on every rank (collective): the
    particle pairs of ranks 0, 1, ... then their wall contacts."""
    parts = sim.comm.allgather(local)
    pair = [part["wall"] < 0 for part in parts]
    return {
        key: np.concatenate(
            [part[key][mask] for part, mask in zip(parts, pair, strict=True)]
            + [part[key][~mask] for part, mask in zip(parts, pair, strict=True)]
        )
        for key in local
    }


def _pair_rows(sim: DistributedSimulation, buf: Any, wall: bool) -> np.ndarray:
    """Rows [gid i, gid j (wall index), history, normal force, state] of a list."""
    c = buf.count
    gid = sim.particles.global_id
    w = buf.history_width
    rows = np.empty((c, 2 + w + 2))
    rows[:, 0] = gid[buf.i[:c]]
    rows[:, 1] = buf.j[:c] if wall else gid[buf.j[:c]]
    rows[:, 2 : 2 + w] = buf.history[:c]
    rows[:, 2 + w] = buf.normal_force[:c]
    rows[:, 3 + w] = buf.state[:c]
    return rows


def _pair_arrays(
    rows: np.ndarray, index_of: np.ndarray, width: int, wall: bool
) -> dict[str, np.ndarray]:
    i = index_of[rows[:, 0].astype(np.int64)]
    j = rows[:, 1].astype(np.int64) if wall else index_of[rows[:, 1].astype(np.int64)]
    return {
        "i": i.astype(np.int32),
        "j": j.astype(np.int32),
        "history": np.ascontiguousarray(rows[:, 2 : 2 + width]),
        "normal_force": np.ascontiguousarray(rows[:, 2 + width]),
        "state": rows[:, 3 + width].astype(np.int8),
    }


def gathered_state(sim: DistributedSimulation) -> dict | None:
    """The restart state of the whole simulation on rank 0 (serial layout), None elsewhere."""
    from thermodem.engine.restart import SCALARS, _plain, step_length

    sim.complete_rates()  # heat rates left to the next thermal step (Simulation.step)
    th = sim.thermal
    n_all = sim.particles.count
    extras = [sim.reference]
    if th is not None:
        cs = th.conductance_sum if th.conductance_sum.shape[0] == n_all else np.zeros(n_all)
        extras.append(cs)
    gathered = _gathered_particles(sim, tuple(extras))
    pair_rows = gather_rows(sim.comm, _pair_rows(sim, sim.pairs, wall=False))
    wall_rows = gather_rows(sim.comm, _pair_rows(sim, sim.walls, wall=True))
    ledger = global_ledger(sim)[1]  # (collective: the ledger sums)
    counts = X.allreduce_sum(sim.comm, np.array([sim.contact_count], np.int64))
    elastic = X.allreduce_sum(sim.comm, np.asarray(sim.elastic, np.float64))
    worst = X.allreduce_max(sim.comm, np.array([sim.max_overlap_ratio]))
    cumulative = None
    if th is not None:
        keys = list(th.cumulative)
        values = X.allreduce_sum(sim.comm, np.array([th.cumulative[k] for k in keys]))
        cumulative = dict(zip(keys, (float(v) for v in values), strict=True))
    if gathered is None:
        return None
    particles, extra = gathered
    n = particles.count
    index_of = np.full(int(sim.next_global_id) + 1, -1, np.int64)
    index_of[particles.global_id] = np.arange(n)
    width = sim.pairs.history_width
    pairs = _pair_arrays(pair_rows, index_of, width, wall=False)
    walls = _pair_arrays(wall_rows, index_of, width, wall=True)
    order = np.lexsort((walls["j"], walls["i"]))
    walls = {k: v[order] for k, v in walls.items()}
    wall_row_start = np.zeros(n + 1, np.int64)
    np.add.at(wall_row_start, walls["i"].astype(np.int64) + 1, 1)
    wall_row_start = np.cumsum(wall_row_start)
    pairs["group_start"] = np.array([0, pairs["i"].shape[0]], np.int64)
    walls["group_start"] = np.zeros(2, np.int64)
    scalars: dict[str, Any] = {name: _plain(getattr(sim, name)) for name in SCALARS}
    scalars.update(
        _needs_rebuild=True, slab_axis=None, max_overlap_ratio=float(worst[0]),
        contact_count=int(counts[0]),
    )  # fmt: skip
    scalars["ledger_cumulative"] = ledger
    scalars["rng"] = sim.rng.bit_generator.state
    scalars["pourers"] = [pourer.state_dict() for pourer in sim.pourers]  # (the same on all)
    scalars["material_names"] = list(sim.material_names)
    scalars["history_width"] = width
    scalars["history_layout"] = sim.history_layout.describe()
    scalars["pair_capacity"] = max(pairs["i"].shape[0], 16)
    scalars["wall_pair_capacity"] = max(walls["i"].shape[0], 16)
    scalars["pair_count"] = int(pairs["i"].shape[0])
    scalars["wall_pair_count"] = int(walls["i"].shape[0])
    scalars["step_length"] = step_length(sim)
    state: dict[str, Any] = {
        "scalars": scalars,
        "particles": {k: v.copy() for k, v in particles.arrays().items()},
        "pairs": pairs,
        "walls": walls,
        "arrays": {
            "wall_row_start": wall_row_start,
            "reference": np.ascontiguousarray(extra[0]),
            "wall_reference": sim.wall_reference.copy(),
            "wall_rows": sim.wall_rows.copy(),
            "elastic": elastic,
        },
    }
    if th is not None:
        state["thermal"] = _thermal_state(sim, extra[1], cumulative)
    return state


def _thermal_state(
    sim: DistributedSimulation, conductance_sum: np.ndarray, cumulative: dict
) -> dict:
    from thermodem.engine.fields import MEMBER_ARRAYS
    from thermodem.engine.thermal_ledger import FIELDS_PREFIX, RANGE_PREFIX

    th = sim.thermal
    state = th.state_dict()
    scalars, arrays = state["scalars"], state["arrays"]
    scalars["cumulative"] = cumulative
    scalars["conductance_ready"] = False
    arrays["conductance_sum"] = np.ascontiguousarray(conductance_sum)
    for name in THERMAL_RECOMPUTED:
        if name in arrays:
            arrays[name] = np.zeros((0, *arrays[name].shape[1:]), arrays[name].dtype)
    if "term_ready" in arrays:
        arrays["term_ready"] = np.zeros_like(arrays["term_ready"])
    # the pair sets hold this rank's indices: empty, built again at the first use
    if "range_set" in scalars:
        scalars["range_set"] = _emptied_set(scalars["range_set"], arrays, RANGE_PREFIX)
    fields = scalars.get("field_provider")
    if fields is not None and "neighbourhood" in fields:
        fields = dict(fields)
        fields["neighbourhood"] = _emptied_set(fields["neighbourhood"], arrays, FIELDS_PREFIX)
        fields.pop("members", None)  # (the radiation's listing: made again from the set)
        for name in (*MEMBER_ARRAYS, "members_reference"):
            arrays.pop(f"{FIELDS_PREFIX}{name}", None)
        scalars["field_provider"] = fields
    return state


def _emptied_set(scalars: dict, arrays: dict, prefix: str) -> dict:
    """The state of a range pair set (engine/range_set.py) with no pairs, to be built again."""
    out = dict(scalars)
    out.update(count=0, wall_count=0, valid=False)
    for name in ("i", "j", "wall_i", "wall_w"):
        arrays[f"{prefix}{name}"] = np.zeros(0, np.int32)
    arrays[f"{prefix}group_start"] = np.zeros(2, np.int64)
    arrays[f"{prefix}reference"] = np.zeros((0, 3))
    arrays[f"{prefix}wall_row_start"] = np.zeros(1, np.int64)
    return out


def load_distributed(sim: DistributedSimulation, state: dict) -> None:
    """Load a restart state (serial layout) on every rank; the rebuild distributes it."""
    from thermodem.engine.restart import restore

    # every rank holds the whole restored set until the rebuild below, so all of it is owned
    # meanwhile: the heat computed before the rebuild (here, and by engine/heat_start.py in
    # restore) sees every particle (with the empty start's owned count, 0, the range set was
    # built empty and its heat left out of the first thermal step)
    sim._distributed = False
    restore(sim, state)
    sim._needs_rebuild = True
    sim.decomposition = None
    th = sim.thermal
    if th is not None and not th.fresh and th.next_step <= sim.step_count:
        # a thermal step at the first step without the rates of a contact pass (a state
        # between two thermal steps renumbered by another time step, engine/restart.py:
        # _adapt_step_length): compute them now, on the whole set with the restored lists, as
        # the serial step does; they travel with the particles. After the rebuild every pair
        # is unset until the next contact pass, and the heat-only passes do not evaluate the
        # mirror list: the thermal step found no contact and added no contact heat.
        th.compute_rates(sim.time)
        th.fresh = True
    if sim.rank != 0:  # the ledgers are sums over the ranks: rank 0 holds the stored totals
        for key in sim.ledger_cumulative:
            sim.ledger_cumulative[key] = 0.0
        sim.elastic = np.zeros_like(sim.elastic)
        sim.contact_count = 0
        if sim.thermal is not None:
            for key in sim.thermal.cumulative:
                sim.thermal.cumulative[key] = 0.0
    if th is not None and th.range_set is not None:
        th.range_set.invalidate()
    sim.rebuild()
    if th is not None and getattr(sim, "heat_start", None):
        # heat started at this restart (engine/heat_start.py): U(0) of the owned particles
        # summed over the ranks, now that they are distributed (before, every rank held all)
        th.initial_energy = th.thermal_energy()
    sim.set_threads()


__all__ = ["GatheredView", "gathered_state", "gathered_view", "global_report"]
