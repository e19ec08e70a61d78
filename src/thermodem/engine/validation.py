"""Validation layers 2 and 3 (layer 1, the schema, is :mod:`thermodem.config.load`).

2. **Completeness**, when the simulation is built (:func:`check_completeness`): every selected
   model's ``requires`` (registry) names material properties; each must be set for every
   material that can meet that model. Mechanical models meet the materials of the particles
   (every insertion entry) and of the walls; thermal models meet the particle materials and the
   materials of walls with a thermal condition. With a thermal section every particle material
   also needs ``specific_heat``.
3. **Physics sanity**, before the run: the time step checks of :mod:`thermodem.engine.checks`
   and the estimated memory and run time (:func:`estimate_resources`); the run is refused
   when the estimated memory exceeds the physical memory of the machine.

:func:`validate_case` runs all three for ``thermodem validate``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel

from thermodem.engine.case_warnings import (
    insertion_warnings,
    output_interval_warnings,
    parameter_warnings,
    periodic_wall_warnings,
    property_warnings,
    section_warnings,
    skin_warnings,
    step_interval_warnings,
    temperature_warnings,
    time_table_warnings,
)
from thermodem.engine.start_checks import (
    check_length_scales,
    check_pour_walls,
    check_wall_overlaps,
    check_walls_in_domain,
)
from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

MECHANICAL_FAMILIES = ("normal", "tangential", "rolling")
#: Material properties an ``interactions`` entry may give for the pair instead (equivalent
#: values): a material need not give them when every pair it forms has them.
PAIR_PROPERTIES = ("surface_roughness", "surface_slope")

#: The run time estimate: a fixed cost per step (Python orchestration and kernel launches,
#: independent of the particle count) plus a cost per particle-step, each for mechanics and
#: for heat, on 1 thread; 2 or more threads divide the per-particle part by THREAD_SPEED_UP
#: and add THREAD_STEP_SECONDS per step (waking the threads). Measured on the 2-core VM
#: (2026-12-02; tools/measure_threads.py, jammed beds of 8 to 16,000 spheres, Hertz-Mindlin,
#: and whole runs of the examples): 1 thread, 0.04-0.05 ms per step below 125 spheres,
#: 0.19-0.22 µs per particle-step; heat (batchelor_obrien_simple every step) +0.015 ms per
#: step, +0.03 µs per particle-step; the 50,000-sphere bench bed: 6 M particle-steps/s on 1
#: thread, 11 M on 2 (docs/STATUS.md). Estimated / measured: default example 9 s / 11 s,
#: heated_bed 13 s / 10 s, two spheres with heat (100,000 steps) 6 s / 6 s. A machine shared
#: with other processes is slower: the progress lines' ETA then tells the truth.
STEP_SECONDS = 4.5e-5
PARTICLE_STEP_SECONDS = 2.0e-7
HEAT_STEP_SECONDS = 1.5e-5
HEAT_PARTICLE_STEP_SECONDS = 3.0e-8
#: Per-particle-step heat cost of the direct conduction models that cost more than the
#: default's (bench/bench_packed_bed.py --heat: resistance_network +130 % over mechanics).
HEAT_PARTICLE_STEP_SECONDS_BY_MODEL = {"resistance_network": 2.2e-7}
THREAD_SPEED_UP = 1.8
THREAD_STEP_SECONDS = 2.0e-5
#: Writing outputs: a time-series row; a frame or checkpoint file, and per particle in it [s]
#: (VTU of 200,000 particles: 0.11-0.15 s, io/vtk.py).
ROW_SECONDS = 2.0e-4
FILE_SECONDS = 3.0e-3
FILE_SECONDS_PER_PARTICLE = 1.0e-6
#: Memory model: bytes per particle (state arrays, neighbour index, copies while sorting) and
#: per listed pair (indices, history, normal force, state, and a rebuild's new
#: indices; ×1.25 growth margin), and pairs per particle in a dense bed (3.6 measured in the
#: benchmark bed, plus near pairs). Measured: ~560 B per particle in that bed.
BYTES_PER_PARTICLE = 400.0
PAIRS_PER_PARTICLE = 4.5
BASELINE_BYTES = 250e6


def model_choices(case: Case) -> list[tuple[str, Any]]:
    """Every model choice in the case with its key path ('contact.normal', ...)."""
    from thermodem.config.schema import ModelChoice

    found: list[tuple[str, Any]] = []

    def walk(value: Any, path: str) -> None:
        if isinstance(value, ModelChoice):
            found.append((path, value))
        elif isinstance(value, BaseModel):
            for name in type(value).model_fields:
                walk(getattr(value, name), f"{path}.{name}" if path else name)

    walk(case, "")
    return found


def meeting_materials(case: Case) -> tuple[set[str], set[str], set[str]]:
    """(particle materials, wall materials, wall materials with a thermal condition)."""
    particles = {e.material for e in case.insertion}
    walls = {w.material for w in case.walls}
    thermal = getattr(case, "thermal", None)
    hot = {
        w.material
        for w in case.walls
        if getattr(getattr(w, "thermal", None), "kind", "adiabatic") != "adiabatic"
    }
    return particles, walls, hot if thermal is not None else set()


def check_completeness(case: Case) -> None:
    """Raise ConfigError naming ``materials.NAME.PROPERTY`` for each missing property."""
    particles, walls, hot = meeting_materials(case)
    overrides = {frozenset(o.materials): o for o in case.interactions}

    def given_per_pair(name: str, prop: str, partners: set[str]) -> bool:
        """Every pair of ``name`` with its partners has an interactions entry giving
        ``prop`` (pair properties: the equivalent surface roughness and slope)."""
        if prop not in PAIR_PROPERTIES:
            return False
        return all(
            getattr(overrides.get(frozenset((name, other))), prop, None) is not None
            for other in partners
        )

    problems: list[str] = []
    for path, choice in model_choices(case):
        spec = choice.spec
        if choice.family in MECHANICAL_FAMILIES:
            meets = sorted(particles | (walls if particles else set()))
        else:
            meets = sorted(particles | (hot if particles else set()))
        for name in meets:
            material = case.materials[name]
            partners = (set(meets) if name in particles else set(particles)) or {name}
            for prop in spec.required(choice.params):
                if getattr(material, prop, None) is None and not given_per_pair(
                    name, prop, partners
                ):
                    role = "particles" if name in particles else "walls"
                    problems.append(
                        f"materials.{name}.{prop}: missing; required by {path} = "
                        f"{choice.model!r} ({name} is a material of {role} that meet it)"
                    )
    if getattr(case, "thermal", None) is not None:
        for name in sorted(particles):
            if case.materials[name].specific_heat is None:
                problems.append(
                    f"materials.{name}.specific_heat: missing; required by the thermal "
                    f"section for particles of {name} [J/(kg K), > 0]"
                )
    if problems:
        unique = list(dict.fromkeys(problems))
        raise ConfigError("incomplete case:\n" + "\n".join(unique))


def gas_note(case: Case) -> str | None:
    """One line on the case's interstitial gas (``thermal.gas``): given or the air default,
    which selected models read it, its values with Λ and Pr; None without a thermal section."""
    thermal = getattr(case, "thermal", None)
    if thermal is None:
        return None
    users = [f"{path} = {c.model!r}" for path, c in model_choices(case) if c.spec.uses_gas]
    origin = "given" if "gas" in thermal.model_fields_set else "default: air at 300 K, 1 atm"
    read = f"read by {', '.join(users)}" if users else "not read by the selected models"
    return f"thermal.gas ({origin}; {read}): {thermal.gas.summary()}"


# ----------------------------------------------------------------------------- resources
def physical_memory() -> tuple[float, float]:
    """(total, available) physical memory [bytes]; NaN where unknown."""
    total = avail = math.nan
    try:
        text = Path("/proc/meminfo").read_text()
        values = {line.split(":")[0]: float(line.split()[1]) * 1024.0 for line in text.splitlines()}
        total = values.get("MemTotal", math.nan)
        avail = values.get("MemAvailable", math.nan)
    except (OSError, ValueError, IndexError):
        try:
            total = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
        except (ValueError, OSError, AttributeError):
            pass
    return total, avail


def poured_particles(entry: Any, start: float, end: float) -> tuple[float, float]:
    """(particles a pour entry adds between ``start`` and ``end``, their particle-seconds
    until ``end``)."""
    t0 = max(float(entry.start_time), start)
    t1 = min(float(entry.end_time) if entry.end_time is not None else end, end)
    if t1 <= t0:
        return 0.0, 0.0
    count = entry.rate * (t1 - t0)
    return count, entry.rate * (0.5 * (t1 - t0) ** 2 + (t1 - t0) * (end - t1))


@dataclass
class ResourceEstimate:
    particles_now: int
    particles_final: int
    steps: int
    particle_steps: float
    memory_bytes: float
    run_seconds: float
    threads: int
    memory_total: float
    memory_available: float
    step_seconds: float = 0.0  # the fixed part of run_seconds

    def lines(self) -> list[str]:
        def gb(x: float) -> str:
            return "unknown" if not math.isfinite(x) else f"{x / 1e9:.3g} GB"

        return [
            f"particles: {self.particles_now} now, about {self.particles_final} at the end",
            f"steps: {self.steps} ({self.particle_steps:.3g} particle-steps)",
            f"estimated memory: {gb(self.memory_bytes)} (physical memory {gb(self.memory_total)}, "
            f"available {gb(self.memory_available)})",
            f"estimated run time: {format_duration(self.run_seconds)} on {self.threads} "
            f"thread(s) ({format_duration(self.step_seconds)} of it a fixed cost per step, "
            f"the rest per particle; measured on a 2-core VM, a busy machine is slower)",
        ]


def format_duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "unknown"
    seconds = int(round(seconds))
    h, rem = divmod(seconds, 3600)
    m, s = divmod(rem, 60)
    if h:
        return f"{h} h {m:02d} min"
    if m:
        return f"{m} min {s:02d} s"
    return f"{s} s"


def total_steps(sim: Simulation, end_time: float | None = None) -> int:
    """Steps from t = 0 to end_time (thermal steps with frozen mechanics)."""
    end = sim.case.simulation.end_time if end_time is None else end_time
    dt = sim.dt
    th = sim.thermal
    if th is not None and th.settings.frozen_mechanics:
        dt = th.settings.time_step
    return int(round(end / dt))


def estimate_resources(sim: Simulation, threads: int | None = None) -> ResourceEstimate:
    """Rough memory and run time of running ``sim`` from its current step to end_time."""
    import numba

    threads = int(threads or getattr(sim, "threads", 0) or numba.get_num_threads())
    end = sim.case.simulation.end_time
    steps = max(0, total_steps(sim) - sim.step_count)
    dt_run = end / max(total_steps(sim), 1)
    n_now = sim.particles.count
    final = float(n_now)
    particle_seconds = n_now * max(0.0, end - sim.time)
    for pourer in sim.pourers:
        count, seconds = poured_particles(pourer.entry, sim.time, end)
        final += count
        particle_seconds += seconds
    particle_steps = particle_seconds / dt_run
    per_particle = bytes_per_particle(sim.pairs.history_width, sim.thermal is not None)
    memory = BASELINE_BYTES + final * per_particle
    fixed, variable = run_time(sim, steps, particle_steps, threads)
    total, avail = physical_memory()
    return ResourceEstimate(
        particles_now=n_now,
        particles_final=int(round(final)),
        steps=steps,
        particle_steps=particle_steps,
        memory_bytes=memory,
        run_seconds=fixed + variable,
        threads=threads,
        memory_total=total,
        memory_available=avail,
        step_seconds=fixed,
    )


def run_time(
    sim: Simulation, steps: int, particle_steps: float, threads: int
) -> tuple[float, float]:
    """(fixed seconds, per-particle seconds) of ``steps`` steps and ``particle_steps``
    particle-steps of ``sim`` on ``threads`` threads (the constants above), outputs included."""
    th = sim.thermal
    per_step, per_particle = STEP_SECONDS, PARTICLE_STEP_SECONDS
    if th is not None:
        model = th.settings.direct_conduction.model
        heat = HEAT_PARTICLE_STEP_SECONDS_BY_MODEL.get(model, HEAT_PARTICLE_STEP_SECONDS)
        if th.settings.frozen_mechanics:  # thermal steps only
            per_step, per_particle = HEAT_STEP_SECONDS, heat
        else:
            every = max(1, int(th.substeps))
            per_step += HEAT_STEP_SECONDS / every
            per_particle += heat / every
    if threads > 1:
        per_step += THREAD_STEP_SECONDS
        per_particle /= THREAD_SPEED_UP
    out = sim.case.output
    end = sim.case.simulation.end_time

    def count(interval: float | None, default: int) -> int:  # default: end_time / default
        return min(default if interval is None else int(end / interval), steps) + 1

    rows = count(out.timeseries_interval, 1000)
    files = count(out.checkpoint_interval, 10) + (count(out.interval, 20) if out.vtu else 0)
    n = sim.particles.count + sum(poured_particles(p.entry, sim.time, end)[0] for p in sim.pourers)
    writing = rows * ROW_SECONDS + files * (FILE_SECONDS + n * FILE_SECONDS_PER_PARTICLE)
    return steps * per_step + writing, particle_steps * per_particle


def bytes_per_particle(history_width: int = 6, thermal: bool = False) -> float:
    """Estimated memory per particle [B]: its arrays plus its share of the pair lists."""
    pair_bytes = 1.25 * (8 + 8 * history_width + 8 + 1 + 9)
    if thermal:
        pair_bytes += 16  # conductance and heat rate (heat-only passes)
    return BYTES_PER_PARTICLE + PAIRS_PER_PARTICLE * pair_bytes


def insertion_counts(case: Case) -> list[tuple[str, float, str]]:
    """(key path, about how many particles, how the number comes about) of every insertion
    entry, computed from the case alone (nothing is allocated; particle files: their data
    lines are not counted, 0)."""
    from thermodem.geometry.distributions import mean_sphere_volume
    from thermodem.geometry.insertion import lattice_axis_counts

    out: list[tuple[str, float, str]] = []
    end = case.simulation.end_time
    planar = case.simulation.planar
    for k, entry in enumerate(case.insertion):
        key = f"insertion.{k}"
        if entry.kind == "lattice":
            nx, ny, nz = lattice_axis_counts(entry, planar)
            out.append((key, float(nx) * ny * nz, f"a lattice of {nx} × {ny} × {nz} sites"))
        elif entry.kind in ("random_box", "random_cylinder"):
            if entry.count is not None:
                out.append((key, float(entry.count), f"count {entry.count}"))
            else:
                extent = np.subtract(entry.upper, entry.lower)
                volume = entry.volume_fraction * float(np.prod(extent[:2] if planar else extent))
                n = volume / mean_sphere_volume(entry.distribution, planar=planar)
                out.append((key, n, f"volume_fraction {entry.volume_fraction}"))
        elif entry.kind == "pour":
            n, _ = poured_particles(entry, 0.0, end)
            out.append((key, n, f"rate {entry.rate:g}/s until t = {end:g} s"))
        elif entry.kind == "list":
            out.append((key, float(len(entry.positions)), "positions"))
        else:
            out.append((key, 0.0, "a particle file"))
    return out


def check_insertion_memory(case: Case) -> None:
    """Refuse, before anything is allocated, a case whose insertion entries would need more
    memory than the machine has (a lattice of 1e9 sites, a count of 1e9): ConfigError naming
    the largest entry."""
    counts = insertion_counts(case)
    if not counts:
        return
    total_count = sum(n for _, n, _ in counts)
    from thermodem.engine.simulation import history_layout_of

    width = history_layout_of(case).width
    memory = BASELINE_BYTES + total_count * bytes_per_particle(width, case.thermal is not None)
    total, _ = physical_memory()
    if math.isfinite(total) and memory > total:
        key, n, how = max(counts, key=lambda c: c[1])
        raise ConfigError(
            f"{key}: {how} gives about {n:.3g} particles; the estimated memory "
            f"{memory / 1e9:.3g} GB for about {total_count:.3g} particles exceeds the physical "
            f"memory {total / 1e9:.3g} GB of this machine (refused before allocating); use "
            "fewer particles (a larger spacing, a smaller count or region)"
        )


def check_resources(estimate: ResourceEstimate) -> list[str]:
    """Warnings; ConfigError when the estimated memory exceeds the physical memory."""
    mem, total, avail = estimate.memory_bytes, estimate.memory_total, estimate.memory_available
    if math.isfinite(total) and mem > total:
        raise ConfigError(
            f"estimated memory {mem / 1e9:.3g} GB for about {estimate.particles_final} "
            f"particles exceeds the physical memory {total / 1e9:.3g} GB of this machine"
        )
    warnings = []
    if math.isfinite(avail) and mem > 0.8 * avail:
        warnings.append(
            f"estimated memory {mem / 1e9:.3g} GB is more than 80 % of the available "
            f"{avail / 1e9:.3g} GB"
        )
    return warnings


# ------------------------------------------------------------------ the built simulation


def check_thermal_selections(sim: Simulation) -> list[str]:
    """The thermal conditions' selections on the particles present at the start: an entry
    that takes none of them is refused when it can take none later either (no region, no
    pour entry: material and ids are fixed); a selection with global ids beyond the
    particles is refused likewise. A region or a pour that may bring particles later gives a
    warning. Returns the warnings."""
    from thermodem.engine.external_loads import selected

    th = sim.case.thermal
    if th is None:
        return []
    p = sim.particles
    count = sim.global_count  # (on several MPI ranks: every rank's particles together)
    pours = any(e.kind == "pour" for e in sim.case.insertion)
    warnings: list[str] = []
    for key in ("fixed_temperature", "heat_flux", "volumetric_source"):
        for k, entry in enumerate(getattr(th, key)):
            sel, where = entry.select, f"thermal.{key}.{k}.select"
            shown = sel.model_dump(mode="json", exclude_none=True)
            if sel.ids is not None and not pours:
                missing = [i for i in sel.ids if i >= count]
                if missing:
                    raise ConfigError(
                        f"{where}.ids: {missing} are no particle: the {count} particles have "
                        f"the global ids 0 ... {count - 1} (in insertion order) and none is "
                        "poured later"
                    )
            taken = selected(sel, p, sim.material_index, sim.planar)[: sim.owned_count]
            if sim.sum_over_ranks(float(np.count_nonzero(taken))) > 0.0:
                continue
            if sel.region is None and not pours:
                raise ConfigError(
                    f"{where}: selects no particle ({shown}); material and ids are fixed and no "
                    "particle is poured later, so it never will"
                )
            later = (
                "its region is evaluated at every thermal step: particles that move into it "
                "are taken"
                if sel.region is not None
                else "particles poured later may be taken"
            )
            warnings.append(f"{where}: selects no particle at the start ({shown}); {later}")
    return warnings


def check_step_count(sim: Simulation) -> None:
    """``thermodem run`` makes ``round(end_time / time_step)`` steps (thermal steps with frozen
    mechanics): refuse an end time that gives none (the run said 'done: 0 steps')."""
    if total_steps(sim) - sim.step_count >= 1:
        return
    th = sim.thermal
    frozen = th is not None and th.settings.frozen_mechanics
    key = "thermal.time_step" if frozen else "simulation.time_step"
    dt = th.settings.time_step if frozen else sim.dt
    end = sim.case.simulation.end_time
    shortened = sim.case._shortened
    if shortened is not None:  # (--end-time: the case's own end time is not at fault)
        raise ConfigError(
            f"{shortened[0]}: the end of this run, t = {end:g} s, gives no step of {key} = "
            f"{dt:g} s after t = {sim.time:g} s (the run makes round((end - t) / time_step) "
            f"steps; simulation.end_time = {shortened[1]:g} s); give at least {sim.time + dt:g}"
        )
    raise ConfigError(
        f"simulation.end_time: {end:g} s gives no step of {key} = {dt:g} s after t = "
        f"{sim.time:g} s (the run makes round((end_time - t) / time_step) steps); the end time "
        f"is in seconds: give at least {sim.time + dt:g}"
    )


def on_every_rank(sim: Simulation, check: Any) -> Any:
    """``check(sim)`` of this rank's particles; on several MPI ranks a refusal on any rank
    is every rank's ConfigError (the lowest such rank's message), so that no rank runs on
    while another stops. Returns this rank's result."""
    comm = getattr(sim, "comm", None)
    if comm is None:
        return check(sim)
    error, result = None, None
    try:
        result = check(sim)
    except ConfigError as exc:
        error = str(exc)
    first = next((e for e in comm.allgather(error) if e is not None), None)
    if first is not None:
        raise ConfigError(first)
    return result


def check_contact_law_agreement(case: Case) -> None:
    """Refuse a contact radius correction whose copy of the normal contact law disagrees with
    ``contact.normal`` (the models cannot read it: they take the law and k_n as their own
    parameters): lu2017's ``normal_stiffness`` against ``normal: linear``'s ``stiffness`` (or a
    Hertz law, which has no k_n), morris2016_area_time's ``contact_law`` and
    ``normal_stiffness``. They ran with the other law's radius or collision time silently."""
    th = case.thermal
    if th is None:
        return
    radius = th.contact_radius
    normal = case.contact.normal
    key = "thermal.contact_radius"
    if radius.model not in ("lu2017", "morris2016_area_time"):
        return
    k_n = getattr(normal.params, "stiffness", None) if normal.model == "linear" else None
    own = radius.params.normal_stiffness
    linear_law = radius.model == "lu2017" or radius.params.contact_law == "linear"
    if radius.model == "morris2016_area_time":
        law = radius.params.contact_law
        wants = "linear" if normal.model == "linear" else "hertz"
        if normal.model in ("linear", "hertz", "hertz_2d") and law != wants:
            given = "" if "contact_law" in radius.params.model_fields_set else " (the default)"
            fix = f"contact_law: {wants}" + (
                f" with normal_stiffness: {k_n:g} (contact.normal.stiffness)"
                if wants == "linear" and own is None
                else ""
            )
            raise ConfigError(
                f"{key}.contact_law: {law!r}{given} but contact.normal is {normal.model!r}: "
                f"the collision time t_c of morris2016_area_time would be that of another "
                f"contact law than the one the simulation runs; allowed: {fix}"
            )
    if not linear_law:
        return
    if normal.model in ("hertz", "hertz_2d"):
        raise ConfigError(
            f"{key}: {radius.model!r} is the correction of a linear spring contact law "
            f"(normal_stiffness k_n), but contact.normal is {normal.model!r}, which has no k_n; "
            "allowed: normal: linear, or a correction of a Hertz law (morris2016_area, "
            "zhou2010)"
        )
    if k_n is not None and own is not None and not math.isclose(own, k_n, rel_tol=1e-9):
        raise ConfigError(
            f"{key}.normal_stiffness = {own:g} N/m but contact.normal.stiffness = {k_n:g} N/m: "
            f"{radius.model!r} needs the k_n of the simulation's linear spring ("
            + (
                "its contact radius carries the force k_n δ"
                if radius.model == "lu2017"
                else "its collision time is π sqrt(m*/k_n)"
            )
            + f"); allowed: normal_stiffness: {k_n:g}"
        )


def pre_run_checks(sim: Simulation) -> list[str]:
    """Every check of a built simulation before the first step of a fresh run: ``thermodem
    validate``, ``thermodem run`` (:func:`thermodem.engine.runner.run_case`) and its MPI
    runner (:func:`thermodem.mpi.runner.run_distributed`; collective there: every rank calls
    it, and a refusal on one rank is every rank's). Raises ConfigError; returns the warnings
    (the time-step ones last)."""
    from thermodem.engine.checks import check_simulation_time_step

    case = sim.case
    notes: list[str] = []
    try:
        check_contact_law_agreement(case)
        check_step_count(sim)
        on_every_rank(sim, check_wall_overlaps)
        check_pour_walls(sim)
        check_length_scales(sim)
        notes += check_walls_in_domain(sim) + periodic_wall_warnings(case) + skin_warnings(sim)
        notes += section_warnings(case) + check_thermal_selections(sim)
        notes += insertion_warnings(case) + time_table_warnings(case) + property_warnings(case)
        notes += parameter_warnings(case)
        notes += temperature_warnings(sim) + step_interval_warnings(sim)
        return notes + list(on_every_rank(sim, check_simulation_time_step))
    except ConfigError as exc:
        with_warnings(exc, case, notes)
        raise


def case_level_warnings(case: Case) -> list[str]:
    """The warnings of the case alone (no simulation needed): sections, pours, time tables,
    material values in another unit, implausible model parameters."""
    return (
        section_warnings(case)
        + insertion_warnings(case)
        + time_table_warnings(case)
        + property_warnings(case)
        + parameter_warnings(case)
    )


def with_warnings(exc: ConfigError, case: Case, told: list[str] | None = None) -> ConfigError:
    """``exc`` with the warnings that may explain it (``ConfigError.warnings``): those computed
    before the refusal (``told``) and the case's own (:func:`case_level_warnings`), each once;
    a density in g/cm³ gives a mass 1000 times too small and a time step refused for it, and
    the refusal alone does not say why. Kept when ``exc`` has them already."""
    if exc.warnings is None:
        told = list(told or [])
        exc.warnings = told + [w for w in case_level_warnings(case) if w not in told]
    return exc


@dataclass
class Validation:
    case: Case
    simulation: Simulation
    warnings: list[str]
    estimate: ResourceEstimate


def validate_case(path: str | os.PathLike[str], threads: int | None = None) -> Validation:
    """Layers 1-3 for a case file; raises ConfigError at the first layer that fails."""
    from thermodem.config.load import load_case
    from thermodem.engine.simulation import Simulation

    case = load_case(path)
    try:
        check_completeness(case)
        sim = Simulation(case, threads=threads)
        warnings = pre_run_checks(sim)
    except ConfigError as exc:
        with_warnings(exc, case)
        raise
    warnings += output_interval_warnings(case)
    estimate = estimate_resources(sim, threads)
    warnings += check_resources(estimate)
    return Validation(case, sim, warnings, estimate)
