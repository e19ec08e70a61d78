"""The complete restart state of a :class:`~thermodem.engine.simulation.Simulation`.

:func:`capture` returns everything a simulation needs to continue exactly where it stopped;
:func:`restore` puts it into a simulation built from the same case with
``insert_particles=False``. A run stopped at step k, restored in a new process and continued is
bit-identical to the uninterrupted run (``tests/unit/test_checkpoint.py``).

The state is a plain nested dict, which :mod:`thermodem.io.checkpoint` writes to HDF5::

    {
      "scalars":   {time, step_count, next_global_id, skin, moved, rebuild_count,
                    _needs_rebuild, initial_energy, max_overlap_ratio, contact_count,
                    ledger_cumulative, rng (the bit generator state), pourers (state dicts),
                    material_names, history_width, history_layout, pair_capacity,
                    wall_pair_capacity},
      "particles": {every Particles array, in the current memory order},
      "pairs":     {i, j, history, normal_force, state: the first `count` rows;
                    group_start: the slab groups of the list},
      "walls":     {the same for particle-wall pairs},
      "arrays":    {wall_row_start, reference, wall_reference, wall_rows, elastic},
      "thermal":   {"scalars": {...}, "arrays": {...}}   (only with a thermal engine)
    }

Everything else on a Simulation is rebuilt from the case (tables, domain, wall geometry) or is
scratch space that the next step overwrites (:data:`DERIVED`). ``tests/unit/test_checkpoint.py``
fails when a new attribute appears on Simulation that is in neither list, so new state cannot be
forgotten silently.
"""

from __future__ import annotations

from dataclasses import fields
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import ConfigError
from thermodem.state.particles import Particles

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation

#: Scalar attributes of Simulation that are state.
SCALARS: tuple[str, ...] = (
    "time",
    "step_count",
    "next_global_id",
    "skin",
    "moved",
    "rebuild_count",
    "_needs_rebuild",
    "initial_energy",
    "max_overlap_ratio",
    "contact_count",
    "slab_axis",
)
#: Array attributes of Simulation that are state (saved whole).
ARRAYS: tuple[str, ...] = (
    "wall_row_start",
    "reference",
    "wall_reference",
    "wall_rows",
    "elastic",
)
#: Per-pair arrays of a pair buffer that are state (the first ``count`` rows).
PAIR_ARRAYS: tuple[str, ...] = (
    "i",
    "j",
    "history",
    "normal_force",
    "state",
)
#: Attributes handled by name in capture/restore (containers of state).
CONTAINERS: tuple[str, ...] = (
    "particles",
    "pairs",
    "walls",
    "rng",
    "pourers",
    "ledger_cumulative",
    "thermal",
)
#: Attributes rebuilt from the case, or scratch overwritten before it is read.
DERIVED: tuple[str, ...] = (
    "case",
    "dt",
    "gravity",
    "material_names",
    "material_index",
    "density",
    "model_ids",
    "normal_table",
    "tangential_table",
    "rolling_table",
    "lower",
    "upper",
    "periodic",
    "planar",  # 2D (simulation.dimension) and the disc thickness: from the case
    "disc_thickness",
    "wall_kind",
    "wall_labels",
    "wall_material",
    "extra",
    "rebuild_every_step",
    "callbacks",
    "chunk_check",
    "_complete",  # the argument of the step in progress
    "_no_heat",
    "_no_generation",
    "_passes",
    "_ledger_totals",
    "generation",
    "mechanisms",
    "history_layout",
    # the thread count: the new process's request or choice (results do not depend on it)
    "requested_threads",
    "threads",
    "threads_reason",
    "governor",  # (engine/threads.py: ThreadGovernor, made by set_threads)
    # the log line of heat that started at this restart (restore; engine/heat_start.py)
    "heat_start",
)
#: Attributes of the thermal engine that are never saved (objects, back references).
THERMAL_SKIP: tuple[str, ...] = ("sim", "settings", "wall_functions")


def _plain(value: Any) -> Any:
    """NumPy scalars to Python scalars (for JSON)."""
    if isinstance(value, np.generic):
        return value.item()
    return value


def _is_scalar(value: Any) -> bool:
    return value is None or isinstance(value, bool | int | float | str | np.generic)


def _object_state(obj: Any, skip: tuple[str, ...]) -> dict[str, Any]:
    """Scalars, flat containers of scalars and arrays among an object's attributes."""
    scalars: dict[str, Any] = {}
    arrays: dict[str, np.ndarray] = {}
    for name, value in vars(obj).items():
        if name in skip:
            continue
        if isinstance(value, np.ndarray):
            arrays[name] = value.copy()
        elif _is_scalar(value):
            scalars[name] = _plain(value)
        elif isinstance(value, dict) and all(_is_scalar(v) for v in value.values()):
            scalars[name] = {str(k): _plain(v) for k, v in value.items()}
        elif isinstance(value, list | tuple) and all(_is_scalar(v) for v in value):
            scalars[name] = [_plain(v) for v in value]
    return {"scalars": scalars, "arrays": arrays}


def _pair_state(buf: Any) -> dict[str, np.ndarray]:
    n = buf.count
    state = {name: getattr(buf, name)[:n].copy() for name in PAIR_ARRAYS}
    state["group_start"] = buf.group_start.copy()  # the slab groups of the list
    return state


def capture(sim: Simulation) -> dict[str, Any]:
    """The complete restart state of ``sim`` (copies; the simulation can go on)."""
    sim.complete_rates()  # the stored heat rates are complete (Simulation.step)
    scalars: dict[str, Any] = {name: _plain(getattr(sim, name)) for name in SCALARS}
    scalars["ledger_cumulative"] = {k: float(v) for k, v in sim.ledger_cumulative.items()}
    scalars["rng"] = sim.rng.bit_generator.state
    scalars["pourers"] = [p.state_dict() for p in sim.pourers]
    scalars["material_names"] = list(sim.material_names)
    scalars["history_width"] = sim.pairs.history_width
    scalars["history_layout"] = sim.history_layout.describe()
    scalars["pair_capacity"] = sim.pairs.capacity
    scalars["wall_pair_capacity"] = sim.walls.capacity
    scalars["pair_count"] = sim.pairs.count
    scalars["wall_pair_count"] = sim.walls.count
    scalars["step_length"] = step_length(sim)
    state: dict[str, Any] = {
        "scalars": scalars,
        "particles": {k: v.copy() for k, v in sim.particles.arrays().items()},
        "pairs": _pair_state(sim.pairs),
        "walls": _pair_state(sim.walls),
        "arrays": {name: np.array(getattr(sim, name)) for name in ARRAYS},
    }
    th = sim.thermal
    if th is not None:
        if hasattr(th, "state_dict"):
            state["thermal"] = th.state_dict()
        else:
            state["thermal"] = _object_state(th, THERMAL_SKIP)
    return state


def _mismatch(what: str, saved: Any, now: Any) -> ConfigError:
    return ConfigError(
        f"checkpoint does not fit this case: {what} is {saved!r} in the checkpoint and "
        f"{now!r} in the case"
    )


def _load_pairs(buf: Any, arrays: dict[str, np.ndarray], count: int, capacity: int) -> None:
    buf.allocate(max(capacity, count))
    for name in PAIR_ARRAYS:
        target = getattr(buf, name)
        source = np.asarray(arrays[name])
        if source.shape[1:] != target.shape[1:]:
            raise _mismatch(f"pair array {name!r} shape", source.shape[1:], target.shape[1:])
        target[:count] = source[:count]
    buf.count = count
    buf.group_start = np.array(arrays["group_start"], np.int64)


#: Scalars a state must hold besides :data:`SCALARS`.
STATE_SCALARS: tuple[str, ...] = (
    "ledger_cumulative",
    "rng",
    "pourers",
    "material_names",
    "history_width",
    "history_layout",
    "pair_capacity",
    "wall_pair_capacity",
    "pair_count",
    "wall_pair_count",
)


def check_state(state: Any) -> None:
    """Raise ConfigError unless ``state`` is a complete, self-consistent restart state: every
    group and scalar present, every particle array of the same length, pair arrays with at
    least ``count`` rows and indices of existing particles, slab groups in order. A damaged
    or hand-edited checkpoint is refused here, before anything is built or written."""
    if not isinstance(state, dict):
        raise ConfigError(f"the state is a {type(state).__name__}, not a mapping of groups")
    missing = [g for g in ("scalars", "particles", "pairs", "walls", "arrays") if g not in state]
    if missing:
        raise ConfigError(f"the group(s) {', '.join(missing)} are missing")
    s = state["scalars"]
    if not isinstance(s, dict):
        raise ConfigError("the scalars are not a mapping")
    absent = [k for k in (*SCALARS, *STATE_SCALARS) if k not in s]
    if absent:
        raise ConfigError(f"the scalar(s) {', '.join(absent)} are missing")
    names = {f.name for f in fields(Particles)}
    particles = state["particles"]
    if set(particles) != names:
        raise ConfigError(
            f"the particle arrays are {sorted(particles)}, this version has {sorted(names)}"
        )
    n = int(np.shape(particles["global_id"])[0]) if np.ndim(particles["global_id"]) else -1
    for name in sorted(names):
        shape = np.shape(particles[name])
        if len(shape) < 1 or shape[0] != n:
            raise ConfigError(
                f"particle array {name!r} has shape {shape}, but there are {n} particles "
                "(global_id); the arrays are truncated or damaged"
            )
        if name in ("position", "velocity", "angular_velocity", "force", "torque") and (
            len(shape) != 2 or shape[1] != 3
        ):
            raise ConfigError(f"particle array {name!r} has shape {shape}, expected ({n}, 3)")
    wall_rows = np.shape(state["arrays"].get("wall_rows", np.zeros((0, 0))))
    for group, count_key, j_limit in (
        ("pairs", "pair_count", n),
        ("walls", "wall_pair_count", wall_rows[0] if wall_rows else 0),
    ):
        arrays = state[group]
        count = int(s[count_key])
        lacking = [k for k in (*PAIR_ARRAYS, "group_start") if k not in arrays]
        if lacking:
            raise ConfigError(f"{group}: the array(s) {', '.join(lacking)} are missing")
        for name in PAIR_ARRAYS:
            rows = np.shape(arrays[name])
            if not rows or rows[0] < count:
                raise ConfigError(
                    f"{group} array {name!r} has {rows[0] if rows else 0} rows but the state "
                    f"counts {count} pairs; the arrays are truncated or damaged"
                )
        i = np.asarray(arrays["i"])[:count]
        j = np.asarray(arrays["j"])[:count]
        if count and (i.min() < 0 or i.max() >= n or j.min() < 0 or j.max() >= max(j_limit, 1)):
            raise ConfigError(
                f"{group}: pair indices outside 0..{n - 1} (particles) or the walls; the "
                "arrays are damaged"
            )
        start = np.asarray(arrays["group_start"])
        if start.ndim != 1 or start.size < 1 or np.any(np.diff(start) < 0) or start[-1] > count:
            raise ConfigError(f"{group}: the slab groups (group_start) are out of order")
    for name in ARRAYS:
        if name not in state["arrays"]:
            raise ConfigError(f"arrays: {name!r} is missing")
    ref = np.shape(state["arrays"]["reference"])
    if n and ref[0] not in (0, n):
        raise ConfigError(f"arrays: 'reference' has {ref[0]} rows for {n} particles")
    if "thermal" in state and not (
        isinstance(state["thermal"], dict) and {"scalars", "arrays"} <= set(state["thermal"])
    ):
        raise ConfigError("thermal: the scalars or the arrays are missing")


#: Thermal engine attributes made from the case (model ids and parameter tables, property
#: tables, a column list, scratch sizes): written to checkpoints but never restored, so that a
#: restart with a changed case (``thermodem run CASE --restart CKPT``) runs the new case's
#: models. The first group is compared with the checkpoint's: when one differs, the stored
#: conductances (frozen mechanics, conductance reuse) are dropped.
THERMAL_FROM_CASE: tuple[str, ...] = (
    "radius_id", "conduction_id", "radius_table", "conduction_table", "tolerance", "override",
    "has_c_table", "k_t", "k_v", "k_n", "c_t", "c_v", "c_n", "density_by_type",
    "specific_heat_by_type",
)  # fmt: skip
#: (the second group: the mechanism columns the case's terms write and the explicit update
#: sums, and the flags they follow from; restored, a restart that swapped radiation for
#: convection summed the radiation column and left the convection heat out, silently)
THERMAL_LAYOUT: tuple[str, ...] = (
    "boundary_columns", "scratch", "term_scratch", "euler_partials", "sum_columns",
    "euler_columns", "in_use", "fuse_generation", "conducts", "walls_conduct",
)  # fmt: skip
#: Thermal arrays computed again before they are read: a state may hold them empty (a
#: checkpoint gathered from MPI ranks, thermodem.mpi.gather) with ``conductance_ready`` False.
THERMAL_RECOMPUTED: tuple[str, ...] = (
    "k_p", "rhoc_p", "k_w", "rhoc_w", "fields", "pair_conductance", "wall_conductance",
    "external_wall_conductance", "mirror_conductance",
)  # fmt: skip


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.shape == b.shape and bool(np.array_equal(a, b))
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def keep_derived_thermal(engine: Any, scalars: dict[str, Any], arrays: dict[str, Any]) -> bool:
    """Remove the case-made entries (:data:`THERMAL_FROM_CASE`, :data:`THERMAL_LAYOUT`) from a
    thermal state before it is loaded into ``engine`` (built from the case to continue); a
    fixed ``thermal.substeps`` is the case's too. True when a model or property table differs
    from the checkpoint's (the case changed)."""
    changed = False
    for name in (*THERMAL_FROM_CASE, *THERMAL_LAYOUT):
        for group in (scalars, arrays):
            if name in group:
                saved = group.pop(name)
                if name in THERMAL_FROM_CASE and not _same(saved, getattr(engine, name, None)):
                    changed = True
    if engine.settings.substeps != "auto":
        scalars.pop("substeps", None)
    return changed


def check_thermal_arrays(engine: Any, arrays: dict[str, Any]) -> None:
    """ConfigError for a thermal state array that cannot be this engine's: another dtype kind
    or number of dimensions, other trailing dimensions, or fewer rows than the engine built
    from the case allocates (the arrays grow with the pair lists; a short one is damaged).
    An empty :data:`THERMAL_RECOMPUTED` array is no damage: it is computed again."""
    for name, value in arrays.items():
        current = getattr(engine, name, None)
        if not isinstance(current, np.ndarray):
            continue
        saved = np.asarray(value)
        if name in THERMAL_RECOMPUTED and saved.ndim and saved.shape[0] == 0:
            continue
        if (
            saved.dtype.kind != current.dtype.kind
            or saved.ndim != current.ndim
            or saved.shape[1:] != current.shape[1:]
            or (saved.ndim and saved.shape[0] < current.shape[0])
        ):
            raise ConfigError(
                f"thermal array {name!r} has shape {saved.shape} ({saved.dtype}), this case's "
                f"thermal engine needs {current.shape[1:] or '()'} per row, at least "
                f"{current.shape[0] if current.ndim else 0} rows ({current.dtype}); the "
                "checkpoint is damaged or belongs to another case"
            )


def check_values(state: dict[str, Any]) -> None:
    """ConfigError unless the particle values of a state that can be continued are possible:
    material indices of the stored materials, unique global ids below the next id, positive
    finite radii, masses and moments of inertia, finite positions, velocities, forces and
    torques, finite positive temperatures (a failure is never stored as a continuable
    checkpoint: the run stops before)."""
    s, p = state["scalars"], state["particles"]
    n_materials = len(s["material_names"])
    type_id = np.asarray(p["type_id"])
    if type_id.size and (type_id.min() < 0 or type_id.max() >= n_materials):
        bad = int(np.nonzero((type_id < 0) | (type_id >= n_materials))[0][0])
        raise ConfigError(
            f"particle {bad} has material index {int(type_id[bad])}, but there are "
            f"{n_materials} materials ({', '.join(map(str, s['material_names']))})"
        )
    gid = np.asarray(p["global_id"])
    if gid.size:
        unique, counts = np.unique(gid, return_counts=True)
        if counts.max() > 1:
            raise ConfigError(f"global id {int(unique[counts > 1][0])} is held by two particles")
        if unique[0] < 0 or unique[-1] >= int(s["next_global_id"]):
            raise ConfigError(
                f"global ids {int(unique[0])}..{int(unique[-1])} are outside 0.."
                f"{int(s['next_global_id']) - 1} (next_global_id)"
            )
    for name, positive in (
        ("radius", True), ("mass", True), ("moment_of_inertia", True), ("temperature", True),
        ("position", False), ("velocity", False), ("angular_velocity", False), ("force", False),
        ("torque", False),
    ):  # fmt: skip
        values = np.asarray(p[name], dtype=float)
        bad = ~np.isfinite(values) | ((values <= 0.0) if positive else False)
        if bad.any():
            row = int(np.nonzero(bad.reshape(bad.shape[0], -1).any(axis=1))[0][0])
            what = "finite and > 0" if positive else "finite"
            raise ConfigError(
                f"particle array {name!r}: the value of particle {row} (global id "
                f"{int(gid[row])}) is {values[row].tolist()}, it must be {what}"
            )


def _case_wall_columns(sim: Simulation, fresh: np.ndarray) -> None:
    """The wall columns the case sets and no step changes (velocity, angular velocity,
    material, thermal condition, a constant temperature) taken from the case's rows: a
    restart with a changed case runs its wall temperature, speed or material (the whole
    stored row kept the checkpoint's: a wall changed from 350 K to 400 K stayed at 350 K).
    The place of the wall (which moves) stays the checkpoint's; a temperature that is a
    function of time is set from its function at each step. Unchanged case: the same values,
    so a restart stays bit-identical."""
    from thermodem.engine.start_checks import wall_row_owners
    from thermodem.geometry import wall_layout as WL

    rows = sim.wall_rows
    if rows.shape != fresh.shape or rows.shape[0] == 0:
        return
    owners = wall_row_owners(sim.case)
    cols = [*range(WL.COL_VELOCITY, WL.COL_VELOCITY + 3), WL.COL_OMEGA, WL.COL_MATERIAL,
            WL.COL_THERMAL_KIND]  # fmt: skip
    for w in range(rows.shape[0]):
        rows[w, cols] = fresh[w, cols]
        wall = sim.case.walls[owners[w]] if w < len(owners) else None
        temperature = wall.thermal.temperature if wall is not None else None
        if isinstance(temperature, int | float):
            rows[w, WL.COL_TEMPERATURE] = fresh[w, WL.COL_TEMPERATURE]


#: A checkpoint with heat continued by a case without a ``thermal`` section.
NO_THERMAL_SECTION = (
    "thermal: the case has no thermal section, but the checkpoint holds the particles' "
    "temperatures and heat ledger (its run had one); a restart does not drop them. Allowed: "
    "keep the thermal section (as in the case.resolved.yaml of the run that wrote it; its "
    "models, properties and conditions may change), or continue a checkpoint written without "
    "heat"
)


def restore(sim: Simulation, state: dict[str, Any]) -> None:
    """Load ``state`` (from :func:`capture`) into ``sim``, built from the same case. A state
    without heat loaded into a case with a ``thermal`` section starts the heat at its time
    (engine/heat_start.py; the log line in ``sim.heat_start``)."""
    check_state(state)
    s = state["scalars"]
    if list(s["material_names"]) != list(sim.material_names):
        raise _mismatch("the list of materials", list(s["material_names"]), sim.material_names)
    saved_layout = [[str(b), int(c), int(w)] for b, c, w in s["history_layout"]]
    if int(s["history_width"]) != sim.pairs.history_width or saved_layout != [
        [str(b), int(c), int(w)] for b, c, w in sim.history_layout.describe()
    ]:
        raise _mismatch(
            "the contact history layout (its blocks [name, first column, width] follow from "
            "the contact models, thermal.conductance_force_tolerance and the heat generation "
            "model)",
            saved_layout,
            sim.history_layout.describe(),
        )
    saved_rows = np.asarray(state["arrays"]["wall_rows"])
    if saved_rows.shape != sim.wall_rows.shape:
        raise _mismatch("the shape of the wall rows (walls, columns)", saved_rows.shape,
                        sim.wall_rows.shape)  # fmt: skip
    if len(s["pourers"]) != len(sim.pourers):
        raise _mismatch("the number of pour entries", len(s["pourers"]), len(sim.pourers))
    names = {f.name for f in fields(Particles)}
    if set(state["particles"]) != names:
        raise ConfigError(
            f"checkpoint particle arrays {sorted(state['particles'])} differ from this "
            f"version's {sorted(names)}"
        )
    sim.particles = Particles(
        **{k: np.ascontiguousarray(state["particles"][k]) for k in sorted(names)}
    )
    for name in SCALARS:
        value = s.get(name) if name == "slab_axis" else s[name]
        if name in ("step_count", "next_global_id", "rebuild_count", "contact_count") or (
            name == "slab_axis" and value is not None
        ):
            value = int(value)
        elif name == "_needs_rebuild":
            value = bool(value)
        elif value is not None:
            value = float(value)
        setattr(sim, name, value)
    skin = sim.case.neighbors.skin
    if skin is not None and float(skin) != sim.skin:
        # a case with another neighbors.skin (run CASE --restart CKPT) runs it (the stored
        # one was kept, silently); the stored lists are of the old skin: built again before
        # the first pair pass. A case without one keeps the skin its first build chose.
        sim.skin = float(skin)
        sim._needs_rebuild = True
    fresh_ledger = dict(sim.ledger_cumulative)  # (the case's keys, for heat that starts)
    sim.ledger_cumulative = {k: float(v) for k, v in s["ledger_cumulative"].items()}
    _load_pairs(sim.pairs, state["pairs"], int(s["pair_count"]), int(s["pair_capacity"]))
    _load_pairs(sim.walls, state["walls"], int(s["wall_pair_count"]), int(s["wall_pair_capacity"]))
    fresh_rows = sim.wall_rows
    for name in ARRAYS:
        setattr(sim, name, np.array(state["arrays"][name], copy=True))
    _case_wall_columns(sim, fresh_rows)
    # the pourers hold a reference to this generator: set its state in place
    sim.rng.bit_generator.state = s["rng"]
    for pourer, ps in zip(sim.pourers, s["pourers"], strict=True):
        pourer.load_state_dict(dict(ps))
    th = sim.thermal
    sim.heat_start = None
    # a state without heat and a case with heat: the heat starts at this restart, below, once
    # the step is known (engine/heat_start.py)
    starts_heat = th is not None and "thermal" not in state
    if th is not None and not starts_heat:
        if hasattr(th, "load_state_dict"):
            th.load_state_dict(state["thermal"])
        else:
            for name, value in state["thermal"]["scalars"].items():
                current = getattr(th, name, None)
                if isinstance(current, float) and value is not None:
                    value = float(value)
                setattr(th, name, value)
            for name, value in state["thermal"]["arrays"].items():
                setattr(th, name, np.array(value, copy=True))
    elif "thermal" in state:
        raise ConfigError(NO_THERMAL_SECTION)
    _adapt_step_length(sim, float(s.get("step_length", step_length(sim))))
    if starts_heat:
        from thermodem.engine.heat_start import start_heat

        sim.heat_start = start_heat(sim, fresh_ledger)


def step_length(sim: Simulation) -> float:
    """The time one step advances (the thermal time step with frozen mechanics) [s]."""
    th = sim.thermal
    if th is not None and th.settings.frozen_mechanics:
        return float(th.settings.time_step)
    return float(sim.dt)


def _adapt_step_length(sim: Simulation, saved: float) -> None:
    """A case with another time step continues at the same time: the step counter is
    renumbered so that ``step_count × Δt`` is the checkpoint time (which must be a whole
    number of new steps), and heat is solved again at the next step."""
    now = step_length(sim)
    if now == saved:
        return
    steps = sim.time / now
    k = int(round(steps))
    if abs(steps - k) > 1e-6 * max(1.0, steps):
        raise ConfigError(
            f"the checkpoint time {sim.time:.9g} s is not a whole number of steps of the new "
            f"time step {now:g} s ({steps:.6g} steps); choose a time step that divides it"
        )
    sim.step_count = k
    if sim.thermal is not None and hasattr(sim.thermal, "next_step"):
        sim.thermal.next_step = k


def check_complete(sim: Simulation) -> list[str]:
    """Attributes of ``sim`` that are neither saved nor declared derived (should be empty)."""
    known = set(SCALARS) | set(ARRAYS) | set(CONTAINERS) | set(DERIVED)
    return sorted(name for name in vars(sim) if name not in known)
