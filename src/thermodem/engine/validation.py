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
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel

from thermodem.engine.case_warnings import (
    end_time_text,
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
from thermodem.engine.ignored_settings import case_ignored_warnings, condition_overlap_warnings
from thermodem.engine.input_warnings import case_input_warnings, extra_distance_warnings
from thermodem.engine.resources import (  # noqa: F401 (re-exported: the run layer imports them here)
    BASELINE_BYTES,
    BYTES_PER_PARTICLE,
    FILE_SECONDS,
    FILE_SECONDS_PER_PARTICLE,
    HEAT_PARTICLE_STEP_SECONDS,
    HEAT_PARTICLE_STEP_SECONDS_BY_MODEL,
    HEAT_STEP_SECONDS,
    PAIRS_PER_PARTICLE,
    PARTICLE_STEP_SECONDS,
    ROW_SECONDS,
    STEP_SECONDS,
    THREAD_SPEED_UP,
    THREAD_STEP_SECONDS,
    ResourceEstimate,
    bytes_per_particle,
    check_insertion_memory,
    check_resources,
    estimate_resources,
    format_duration,
    insertion_counts,
    physical_memory,
    poured_particles,
    run_time,
    total_steps,
)
from thermodem.engine.start_checks import (
    check_length_scales,
    check_pour_walls,
    check_wall_overlaps,
    check_walls_in_domain,
)
from thermodem.errors import ConfigError, SimulationError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

MECHANICAL_FAMILIES = ("normal", "tangential", "rolling")
#: Material properties an ``interactions`` entry may give for the pair instead (equivalent
#: values): a material need not give them when every pair it forms has them.
PAIR_PROPERTIES = ("surface_roughness", "surface_slope")


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


#: The most steps a run may make (2^53: the step count and t = n Δt stay exact below it).
MAX_STEPS = 2**53


def check_step_count(sim: Simulation) -> None:
    """``thermodem run`` makes ``round(end_time / time_step)`` steps (thermal steps with frozen
    mechanics): refuse an end time that gives none (the run said 'done: 0 steps')."""
    steps = total_steps(sim) - sim.step_count
    if steps > MAX_STEPS:
        frozen = sim.thermal is not None and sim.thermal.settings.frozen_mechanics
        key = "thermal.time_step" if frozen else "simulation.time_step"
        dt = sim.thermal.settings.time_step if frozen else sim.dt
        raise ConfigError(
            f"{key}: {dt:g} s gives {float(steps):.3g} steps until {end_time_text(sim.case)} "
            f"(got {key} = {dt!r}); allowed: at most {MAX_STEPS:.3g} steps (2^53, beyond which "
            "the step count is not exact in floating point; no run makes that many): is the "
            "exponent of the time step mistyped?"
        )
    if steps >= 1:
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
        check_step_count(sim)
        on_every_rank(sim, check_wall_overlaps)
        check_pour_walls(sim)
        check_length_scales(sim)
        notes += check_walls_in_domain(sim) + periodic_wall_warnings(case) + skin_warnings(sim)
        notes += section_warnings(case) + check_thermal_selections(sim)
        notes += insertion_warnings(case) + time_table_warnings(case) + property_warnings(case)
        notes += parameter_warnings(case) + case_ignored_warnings(case)
        notes += case_input_warnings(case) + extra_distance_warnings(sim)
        notes += condition_overlap_warnings(sim)
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
        + case_ignored_warnings(case)
        + case_input_warnings(case)
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


def built_simulation(
    case: Case, threads: int | None = None, build: Callable[[], Simulation] | None = None
) -> Simulation:
    """``Simulation(case)`` of a fresh run (``validate``, ``run``, ``etc``; ``build``: another
    constructor, the MPI runner's), after the checks that need the case alone and would
    otherwise wait for the first kernels to compile. A SimulationError met while it is
    built, before step 0 (a periodic axis shorter than two neighbour cells of the inserted
    particles, a tessellation the start positions cannot make), is an error of the input,
    not of a run: a ConfigError with its message (exit code 2). Failures met while the run
    steps stay SimulationErrors."""
    from thermodem.engine.simulation import Simulation

    check_contact_law_agreement(case)  # the case alone: before any kernel compiles
    try:
        return build() if build is not None else Simulation(case, threads=threads)
    except SimulationError as exc:
        raise ConfigError(f"{exc} (met while the case was built, before any step)") from None


@dataclass
class Validation:
    case: Case
    simulation: Simulation
    warnings: list[str]
    estimate: ResourceEstimate


def validate_case(path: str | os.PathLike[str], threads: int | None = None) -> Validation:
    """Layers 1-3 for a case file; raises ConfigError at the first layer that fails."""
    from thermodem.config.load import load_case

    case = load_case(path)
    try:
        check_completeness(case)
        sim = built_simulation(case, threads)
        warnings = pre_run_checks(sim)
    except ConfigError as exc:
        with_warnings(exc, case)
        raise
    warnings += output_interval_warnings(case)
    estimate = estimate_resources(sim, threads)
    warnings += check_resources(estimate)
    return Validation(case, sim, warnings, estimate)
