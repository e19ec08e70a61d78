"""Warnings of a case that runs but may not do what it says, told before its first step by
``thermodem validate`` and ``thermodem run`` (:func:`thermodem.engine.validation.pre_run_checks`):
temperatures that look like °C, output intervals in steps or below the time step, pours that
pour nothing, a skin of many diameters, a wall closing a periodic axis, ``thermal: null``,
material values in another unit, model parameters far outside any real material and
selections that do nothing.
Each names the key, the value and what was probably meant; none refuses the case."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.engine.start_checks import largest_radius
from thermodem.geometry.walls import rectangle_separates

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation


def end_time_text(case: Case) -> str:
    """The end of the run for a message: 'simulation.end_time = 0.25 s', or after ``thermodem
    run --steps 20`` 'the end of this run, t = 0.0001 s (--steps 20; simulation.end_time =
    0.25 s)': the shortened end is the option's, not the case's key."""
    end = case.simulation.end_time
    shortened = case._shortened
    if shortened is None:
        return f"simulation.end_time = {end:g} s"
    option, own = shortened
    return f"the end of this run, t = {end:g} s ({option}; simulation.end_time = {own:g} s)"


def insertion_warnings(case: Case) -> list[str]:
    """Pour entries that pour nothing before ``simulation.end_time``."""
    end = case.simulation.end_time
    dt = case.simulation.time_step
    out = []
    for k, e in enumerate(case.insertion):
        if e.kind != "pour":
            continue
        first = e.start_time + e.interval
        if e.end_time is not None:
            first = min(first, e.end_time)
        stop = end if e.end_time is None else min(e.end_time, end)
        if first - 0.5 * dt > end:
            out.append(
                f"insertion.{k}: its first batch is due at t = {first:g} s (start_time "
                f"{e.start_time:g} s + interval {e.interval:g} s), after "
                f"{end_time_text(case)}: nothing is poured in this run"
            )
        elif e.rate * max(0.0, stop - e.start_time) < 1.0:
            out.append(
                f"insertion.{k}: rate {e.rate:g}/s from t = {e.start_time:g} s to {stop:g} s "
                "asks for less than one particle: nothing is poured in this run"
            )
    return out


#: Below these a value is told as one in another unit: a density in g/cm³ (osmium, the
#: densest element, is 22.6 g/cm³) and a specific heat in kJ/(kg K) (solids near room
#: temperature: 100 J/(kg K) and more). Warnings: cryogenic or exotic cases can ignore them.
DENSITY_SUSPECT_BELOW = 30.0
SPECIFIC_HEAT_SUSPECT_BELOW = 20.0


def property_warnings(case: Case) -> list[str]:
    """Material values that look like another unit (a density in g/cm³, a specific heat in
    kJ/(kg K), also in a c(T) table), and a ``youngs_modulus_real`` below ``youngs_modulus``
    (the low-stiffness corrections of the contact radius scale the simulation's softer
    modulus up to the real one: the two swapped?)."""
    out = []
    for name, m in case.materials.items():
        key = f"materials.{name}"
        if m.density < DENSITY_SUSPECT_BELOW:
            out.append(
                f"{key}.density: {m.density:g} kg/m³ is below {DENSITY_SUSPECT_BELOW:g} kg/m³, "
                f"lighter than any solid: is it in g/cm³? ({m.density:g} g/cm³ = "
                f"{1000.0 * m.density:g} kg/m³); a case of such a material can ignore this"
            )
        if case.thermal is not None:
            values = [("specific_heat", m.specific_heat)] if not m.specific_heat_table else []
            values += [
                (f"specific_heat_table (row {k})", row[1])
                for k, row in enumerate(m.specific_heat_table or [])
            ]
            low = [(k, v) for k, v in values if v is not None]
            if low:
                which, value = min(low, key=lambda kv: kv[1])
                if value < SPECIFIC_HEAT_SUSPECT_BELOW:
                    out.append(
                        f"{key}.{which}: {value:g} J/(kg K) is below "
                        f"{SPECIFIC_HEAT_SUSPECT_BELOW:g} J/(kg K), less than any solid near "
                        f"room temperature (lead: 129): is it in kJ/(kg K)? ({value:g} kJ/(kg "
                        f"K) = {1000.0 * value:g} J/(kg K)); a cryogenic case can ignore this"
                    )
        real = m.youngs_modulus_real
        if real is not None and real < m.youngs_modulus:
            out.append(
                f"{key}.youngs_modulus_real: {real:g} Pa is below youngs_modulus "
                f"{m.youngs_modulus:g} Pa: the real modulus of the low-stiffness corrections "
                "is the stiffer one (the simulation softens the material to take longer time "
                "steps); are the two swapped?"
            )
    return out


#: An RMS asperity slope above this is told: real surfaces have 0.05-0.5 (asperity angles of
#: 3°-27°); 2 is an angle of 63°. A value in degrees is the usual cause.
SLOPE_SUSPECT_ABOVE = 2.0
#: A microhardness outside these [Pa] is told: real ones are 1e8-1e10 Pa (lead about 5e7 Pa,
#: diamond about 1e11 Pa); a value in MPa or GPa is the usual cause.
MICROHARDNESS_SUSPECT_BELOW = 1.0e7
MICROHARDNESS_SUSPECT_ABOVE = 2.0e11


def _slope_text(key: str, value: float) -> str:
    hint = ""
    if value < 90.0:
        hint = f": is it an angle in degrees? ({value:g}° is a slope tan {value:g}° = " + (
            f"{math.tan(math.radians(value)):.3g})"
        )
    return (
        f"{key}: {value:g} is above {SLOPE_SUSPECT_ABOVE:g}, steeper than any real surface (the "
        "RMS asperity slope, the tangent of the asperities' angle, is usually 0.05-0.5)" + hint
    )


def parameter_warnings(case: Case) -> list[str]:
    """Parameters far outside any real material (a unit mistake) and selections that do
    nothing, in a case with heat: a ``surface_slope`` above :data:`SLOPE_SUSPECT_ABOVE` (an
    angle in degrees?), a ``microhardness`` outside 1e7-2e11 Pa (MPa or GPa?), a radiation
    model whose particle materials all have emissivity 0 (it exchanges no heat), a heat
    generation model with ``conversion_fraction: 0`` (it generates none). Warnings: each
    names the key, the value and the usual range. (A convection model in a fluid at rest is
    the natural-convection limit, Nu = 2: not told.)"""
    th = case.thermal
    if th is None:
        return []
    out = []
    for name, m in case.materials.items():
        key = f"materials.{name}"
        if m.surface_slope is not None and m.surface_slope > SLOPE_SUSPECT_ABOVE:
            out.append(_slope_text(f"{key}.surface_slope", m.surface_slope))
        hardness = m.microhardness
        if hardness is not None and hardness < MICROHARDNESS_SUSPECT_BELOW:
            out.append(
                f"{key}.microhardness: {hardness:g} Pa is below "
                f"{MICROHARDNESS_SUSPECT_BELOW:g} Pa, softer than any solid (real "
                "microhardnesses are 1e8-1e10 Pa, lead about 5e7 Pa): is it in MPa or GPa? "
                f"({hardness:g} MPa = {hardness * 1e6:g} Pa, {hardness:g} GPa = "
                f"{hardness * 1e9:g} Pa)"
            )
        elif hardness is not None and hardness > MICROHARDNESS_SUSPECT_ABOVE:
            out.append(
                f"{key}.microhardness: {hardness:g} Pa is above "
                f"{MICROHARDNESS_SUSPECT_ABOVE:g} Pa, harder than diamond (about 1e11 Pa; real "
                "microhardnesses are 1e8-1e10 Pa): is it in another unit?"
            )
    for k, o in enumerate(case.interactions):
        if o.surface_slope is not None and o.surface_slope > SLOPE_SUSPECT_ABOVE:
            out.append(_slope_text(f"interactions.{k}.surface_slope", o.surface_slope))
    if th.radiation.model != "none":
        particles = sorted({e.material for e in case.insertion})
        values = {n: case.materials[n].emissivity for n in particles if n in case.materials}
        if values and all(v is not None and v == 0.0 for v in values.values()):
            keys = ", ".join(f"materials.{n}.emissivity = 0" for n in values)
            out.append(
                f"thermal.radiation = {th.radiation.model!r}, but every particle material has "
                f"emissivity 0 ({keys}): the radiation model exchanges no heat; most solids "
                "have 0.2-0.95 (polished metals 0.02-0.1): give the emissivity, or radiation: "
                "none"
            )
    generation = th.heat_generation
    fraction = getattr(generation.params, "conversion_fraction", None)
    if generation.model != "none" and fraction is not None and fraction == 0.0:
        out.append(
            f"thermal.heat_generation = {generation.model!r} with conversion_fraction 0: it "
            "turns none of the dissipation into heat, so the model does nothing; give the "
            "fraction χ that becomes heat (usually 0.85-1), or heat_generation: none"
        )
    porosity = th.porosity
    size = getattr(porosity, "cell_size", None) if porosity is not None else None
    if porosity is not None and porosity.kind == "cell" and size is not None:
        axes = 2 if case.simulation.planar else 3
        edges = [hi - lo for lo, hi in zip(case.domain.lower, case.domain.upper, strict=True)]
        edges = edges[:axes]
        if size > max(edges):
            out.append(
                f"thermal.porosity.cell_size: {size:g} m is larger than the domain (edges "
                f"{', '.join(f'{e:g}' for e in edges)} m): the cells, rounded to tile the "
                "domain, are one cell, the whole domain, so every particle gets the domain's "
                "mean porosity (a global porosity, not a local one); give a cell edge of a few "
                "particle diameters (the default: three), or porosity: {kind: global, value: ...}"
            )
    return out + generation_mechanism_warnings(case)


def _mechanism_zero_reason(mechanism: str, case: Case) -> str | None:
    """Why the contact laws of ``case`` produce none of ``mechanism``'s dissipation, or None
    (docs/models/heat_generation-mechanical_dissipation.md)."""
    laws = case.contact
    normal, tangential, rolling = laws.normal.model, laws.tangential.model, laws.rolling.model
    if mechanism == "sliding_friction" and tangential == "none":
        return "contact.tangential is 'none': no tangential force, so no friction work"
    if mechanism == "rolling_friction" and rolling == "none":
        return "contact.rolling is 'none': no rolling torque, so no rolling dissipation"
    if mechanism == "normal_damping" and normal == "walton_braun":
        return (
            "contact.normal is 'walton_braun', which has no dashpot (its loss is "
            "plastic_deformation)"
        )
    if mechanism == "tangential_damping" and tangential == "none":
        return "contact.tangential is 'none': no tangential dashpot"
    if mechanism == "tangential_damping" and normal == "walton_braun":
        return (
            "the tangential dashpot takes the normal law's damping, and contact.normal "
            "'walton_braun' has none"
        )
    if mechanism == "plastic_deformation" and normal != "walton_braun":
        return (
            f"contact.normal is {normal!r}, an elastic law: only the elasto-plastic "
            "'walton_braun' deforms plastically"
        )
    return None


def generation_mechanism_warnings(case: Case) -> list[str]:
    """A heat generation mechanism the case names (``mechanical_dissipation``'s listed
    ``mechanisms``, ``rojek2014``'s sliding friction, ``richard2008``'s normal damping) that
    the contact laws cannot produce, or that the material values switch off for every pair of
    materials that can meet (sliding friction 0, restitution 1, ...:
    ``engine/generation_materials.py``): it gives zero heat. A warning each, naming the
    mechanism and why (the law, or the keys and values). ``mechanical_dissipation``'s default
    list (all five) is told about only when none of them gives heat."""
    from thermodem.engine.generation_materials import material_zero_reason

    th = case.thermal
    if th is None:
        return []
    generation = th.heat_generation
    key = f"thermal.heat_generation = {generation.model!r}"
    default = False
    if generation.model == "mechanical_dissipation":
        listed = list(generation.params.mechanisms)
        default = "mechanisms" not in generation.params.model_fields_set
        if not default:
            key = "thermal.heat_generation.mechanisms"
    elif generation.model == "rojek2014":
        listed = ["sliding_friction"]
    elif generation.model == "richard2008":
        listed = ["normal_damping"]
    else:
        return []
    out, reasons = [], []
    for mechanism in listed:
        reason = _mechanism_zero_reason(mechanism, case)
        if reason is not None:
            reasons.append(f"{mechanism!r}: {reason}")
            out.append(
                f"{key}: {mechanism!r} gives zero heat with these contact laws: {reason}; "
                "remove it, or choose a contact law that dissipates that way"
            )
            continue
        reason = material_zero_reason(mechanism, case)
        if reason is not None:
            reasons.append(f"{mechanism!r}: {reason}")
            out.append(
                f"{key}: {mechanism!r} gives zero heat with these material values: {reason}; "
                "remove it, or give values that dissipate that way"
            )
    if not default:
        return out
    if len(reasons) < len(listed):
        return []
    return [
        f"{key} gives zero heat: none of its mechanisms (the default, all five) dissipates with "
        f"these contact laws and material values ({'; '.join(reasons)}); give values that "
        "dissipate, or heat_generation: none"
    ]


def time_table_warnings(case: Case) -> list[str]:
    """Tables of time (a fixed wall's temperature, the fluid's temperature and velocity) whose
    first change (row 1) comes after the end of the run: the first row's value holds for the
    whole run, and the table does nothing (times in ms, or a table of another case)."""
    end = case.simulation.end_time
    tables: list[tuple[str, list]] = []
    for k, wall in enumerate(case.walls):
        value = wall.thermal.temperature if wall.thermal.kind == "fixed" else None
        if isinstance(value, list):
            tables.append((f"walls.{k}.thermal.temperature", value))
    fluid = case.thermal.fluid if case.thermal is not None else None
    for name in ("temperature", "velocity"):
        source = getattr(fluid, name, None)
        if getattr(source, "kind", None) == "table":
            tables.append((f"thermal.fluid.{name}", source.table))
    out = []
    for key, table in tables:
        if len(table) < 2 or not table[1][0] > end:
            continue
        unit = " K" if key.endswith("temperature") else " m/s"
        first = ", ".join(f"{v:g}" for v in table[0][1:])
        first = f"[{first}]{unit}" if len(table[0]) > 2 else f"{first}{unit}"
        out.append(
            f"{key}: the table's first change is at t = {table[1][0]:g} s (row 1), after "
            f"{end_time_text(case)}: the value of row 0, {first}, holds for the whole run; "
            "table times are simulated seconds (are they in another unit?)"
        )
    return out


#: A Verlet skin above this many largest particle diameters is warned about.
SKIN_WARN_DIAMETERS = 2.0


def skin_warnings(sim: Simulation) -> list[str]:
    """A neighbour skin (``neighbors.skin``, ``thermal.range_skin``) of more than
    :data:`SKIN_WARN_DIAMETERS` largest particle diameters: every particle then lists every
    other within that distance (the number of listed pairs grows as the cube of the skin),
    which costs time and memory at every step and buys nothing (a skin only saves list
    rebuilds). Typically a length typed in mm or a domain size given as the skin."""
    diameter = 2.0 * largest_radius(sim)
    if diameter <= 0.0:
        return []
    case = sim.case
    skins = [("neighbors.skin", case.neighbors.skin)]
    if case.thermal is not None:
        skins.append(("thermal.range_skin", case.thermal.range_skin))
    out = []
    for key, skin in skins:
        if skin is not None and skin > SKIN_WARN_DIAMETERS * diameter:
            out.append(
                f"{key} = {skin:g} m is {skin / diameter:.3g} times the largest particle "
                f"diameter ({diameter:g} m): every particle lists all the others within "
                f"{skin:g} m (the listed pairs grow as the cube of the skin), which slows every "
                "step and takes memory for nothing; a skin of 0.1-0.5 diameters is usual (the "
                "default, left out, is 0.2 times the largest radius). A length in mm?"
            )
    return out


def periodic_wall_warnings(case: Case) -> list[str]:
    """A periodic axis that a wall closes: a plane whose normal has a component along it, a box
    (its faces close every axis), a cylinder holding the particles inside (its mantle closes
    every axis across its own; along the axis is the periodic drum slice), a rectangle that
    spans the domain's whole cross-section (a plate with a way around it closes nothing).
    Particles are wrapped across the periodic boundary, so the particles on either side of
    such a wall interact through the domain's faces: the wall does not separate them. A
    warning each, naming ``domain.periodic`` and the wall."""
    periodic = case.domain.periodic
    axes = "xy" if case.simulation.planar else "xyz"
    shown = "[" + ", ".join("true" if p else "false" for p in periodic[: len(axes)]) + "]"
    out = []
    for k, wall in enumerate(case.walls):
        label = wall.name or f"{wall.kind}{k}"
        if wall.kind == "plane":
            n = np.asarray(wall.normal, float)
            n = n / np.linalg.norm(n)
            closed = [a for a in range(len(axes)) if periodic[a] and abs(n[a]) > 1e-9]
            what = f"a plane with normal {[float(c) for c in wall.normal]}"
        elif wall.kind == "box":
            closed = [a for a in range(len(axes)) if periodic[a]]
            what = "a box (its faces close every axis)"
        elif wall.kind == "cylinder" and wall.inside:  # the mantle closes the axes across it
            a = np.asarray(wall.axis, float)
            a = a / np.linalg.norm(a)
            closed = [b for b in range(len(axes)) if periodic[b] and abs(a[b]) < 1.0 - 1e-9]
            what = f"a cylinder around the axis {[float(c) for c in wall.axis]}"
        elif wall.kind == "rectangle":
            lower, upper = case.domain.lower, case.domain.upper
            closed = [
                b for b in range(len(axes))
                if periodic[b] and rectangle_separates(wall, b, lower, upper, len(axes) == 2)
            ]  # fmt: skip
            what = (
                f"a rectangle with normal {[float(c) for c in wall.normal]} spanning the domain's "
                "whole cross-section"
            )
        else:
            continue
        if not closed:
            continue
        names = " and ".join(axes[a] for a in closed)
        out.append(
            f"domain.periodic: {shown} makes {names} periodic, but walls.{k} ({label}) is {what} "
            f"that closes {names}: particles are wrapped across the periodic boundary, so those "
            "on either side of the wall interact through the domain's faces, past the wall; a "
            f"wall bounds an axis that is not periodic: set {names} false in domain.periodic, "
            "or remove the wall"
        )
    return out


def section_warnings(case: Case) -> list[str]:
    """``thermal: null`` (an empty ``thermal:`` key, its settings commented out or indented
    wrongly) is the absent section, so the case runs mechanics only: said, since it reads
    like the heat with every default (``thermal: {}``)."""
    if case.thermal is not None or "thermal" not in case.model_fields_set:
        return []
    return [
        "thermal: null (an empty 'thermal:' key) means no thermal section: this case runs "
        "mechanics only, without heat; write thermal: {} for the heat with every default, or "
        "remove the key"
    ]


#: A temperature below this [K] is told as a likely value in °C: colder than any natural
#: temperature on Earth (the record is 184 K), while the Celsius values of a case (room
#: temperature to a few hundred °C) all lie below it. Cryogenic cases are legitimate: a
#: warning, never an error.
CELSIUS_SUSPECT_BELOW = 200.0


def _expression_minimum(expression: str, names: tuple[str, ...], grid: tuple) -> float:
    """The smallest value of a temperature expression on ``grid`` (NaN if it fails)."""
    from thermodem.engine.expressions import compile_expression

    try:
        values = np.asarray(compile_expression(expression, names)(*grid), dtype=np.float64)
        return float(np.min(values))
    except (ValueError, ArithmeticError, TypeError):
        return math.nan


def _grid_minimum(sim: Simulation, source: Any) -> tuple[str, float | None]:
    """(key, smallest value) of the fluid temperature grid file as the run reads it (None when
    no selected model reads the fluid temperature: the file is not read)."""
    provider = getattr(sim.thermal, "field_provider", None)
    values = provider.grid_values("temperature") if provider is not None else None
    if values is None:
        return "thermal.fluid.temperature", None
    k = np.unravel_index(int(np.argmin(values)), values.shape)
    where = tuple(int(v) for v in k[:3])
    return (
        f"thermal.fluid.temperature (grid file {source.file}, field {source.field!r}: its "
        f"smallest value, at grid index {where})",
        float(values[k]),
    )


def temperature_warnings(sim: Simulation) -> list[str]:
    """Every temperature key of the case (and the particles' start temperatures, which files
    give) below :data:`CELSIUS_SUSPECT_BELOW`: a warning each naming the key and the value
    (``initial_temperature: 25`` meant in °C is 25 K). Expressions and tables: their
    smallest value (an initial temperature on a grid spanning the domain, a wall temperature
    from t = 0 to the end time)."""
    case = sim.case
    th = case.thermal
    found: list[tuple[str, float]] = []

    def add(key: str, value: Any) -> None:
        if value is not None and math.isfinite(float(value)):
            found.append((key, float(value)))

    add("simulation.initial_temperature", case.simulation.initial_temperature)
    for k, entry in enumerate(case.insertion):
        add(f"insertion.{k}.temperature", getattr(entry, "temperature", None))
        listed = getattr(entry, "temperatures", None)
        if listed:
            i = int(np.argmin(listed))
            add(f"insertion.{k}.temperatures.{i}", listed[i])
    for name, material in case.materials.items():
        for prop in ("thermal_conductivity_table", "specific_heat_table"):
            table = getattr(material, prop)
            if table and th is not None:  # (the abscissae: T [K]; row 0 is the lowest)
                add(f"materials.{name}.{prop} (row 0, its lowest temperature)", table[0][0])
    times = np.linspace(0.0, case.simulation.end_time, 2001)
    for k, wall in enumerate(case.walls):
        value = wall.thermal.temperature if wall.thermal.kind == "fixed" else None
        key = f"walls.{k}.thermal.temperature"
        if isinstance(value, list):
            i = int(np.argmin([row[1] for row in value]))
            add(f"{key} (row {i})", value[i][1])
        elif isinstance(value, str):
            add(f"{key} (its smallest value)", _expression_minimum(value, ("t",), (times,)))
        else:
            add(key, value)
    if th is not None:
        rule = th.initial_temperature
        key = "thermal.initial_temperature"
        if rule is not None and rule.kind == "uniform":
            add(f"{key}.value", rule.value)
        elif rule is not None and rule.kind == "per_material":
            for name, value in rule.values.items():
                add(f"{key}.values.{name}", value)
            add(f"{key}.default", rule.default)
        elif rule is not None and rule.kind == "regions":
            for i, (_, value) in enumerate(rule.regions):
                add(f"{key}.regions.{i}", value)
            add(f"{key}.default", rule.default)
        elif rule is not None:
            axes = [
                np.linspace(lo, hi, 21)
                for lo, hi in zip(case.domain.lower, case.domain.upper, strict=True)
            ]
            grid = tuple(np.meshgrid(*axes, indexing="ij"))
            low = _expression_minimum(rule.expression, ("x", "y", "z"), grid)
            add(f"{key}.expression (its smallest value in the domain)", low)
        for k, entry in enumerate(th.fixed_temperature):
            add(f"thermal.fixed_temperature.{k}.temperature", entry.temperature)
        if "temperature" in th.gas.model_fields_set:
            add("thermal.gas.temperature", th.gas.temperature)
        fluid = th.fluid.temperature if th.fluid is not None else None
        if fluid is not None and fluid.kind == "uniform":
            add("thermal.fluid.temperature", fluid.value[0])
        elif fluid is not None and fluid.kind == "table":
            i = int(np.argmin([row[1] for row in fluid.table]))
            add(f"thermal.fluid.temperature (row {i})", fluid.table[i][1])
        elif fluid is not None and fluid.kind == "grid":
            add(*_grid_minimum(sim, fluid))
        elif fluid is not None and fluid.kind == "expression":
            from thermodem.config.schema import fluid_probe_samples

            names = ("t", "x", "y", "z")
            low = min(_expression_minimum(fluid.expression[0], names, samples)
                      for samples in fluid_probe_samples(case))  # fmt: skip
            add("thermal.fluid.temperature (its smallest value in the domain until the end "
                "time)", low)  # fmt: skip
        for family in ("radiation",):
            params = getattr(th, family).params
            add(f"thermal.{family}.environment_temperature",
                getattr(params, "environment_temperature", None))  # fmt: skip
    bad = [(key, value) for key, value in found if value < CELSIUS_SUSPECT_BELOW]
    p = sim.particles
    n = sim.owned_count
    if n and not any(k.startswith(("insertion", "thermal.initial", "simulation")) for k, _ in bad):
        i = int(np.argmin(p.temperature[:n]))
        if p.temperature[i] < CELSIUS_SUSPECT_BELOW:  # (a particle file's column)
            bad.append((f"particle {int(p.global_id[i])} (its start temperature)",
                        float(p.temperature[i])))  # fmt: skip
    return [
        f"{key}: {value:g} K is below {CELSIUS_SUSPECT_BELOW:g} K, colder than any natural "
        "temperature on Earth (the record is 184 K): temperatures are in kelvin, is it a value "
        f"in °C? ({value:g} °C = {value + 273.15:g} K); a cryogenic case can ignore this"
        for key, value in bad
    ]


def output_interval_warnings(case: Case) -> list[str]:
    """Output intervals longer than ``simulation.end_time``: frames (rows, checkpoints) only at
    the start and the end. A value in steps (LIGGGHTS' dump every N steps) is the usual cause.
    """
    end = case.simulation.end_time
    out = []
    for key in ("interval", "timeseries_interval", "checkpoint_interval"):
        value = getattr(case.output, key)
        if value is not None and value > end:
            out.append(
                f"output.{key} = {value:g} s is longer than simulation.end_time = {end:g} s: "
                "written at the start and the end only (intervals are simulated seconds, not "
                "steps)"
            )
    return out


def step_interval_warnings(sim: Simulation) -> list[str]:
    """Output intervals shorter than the time step: written at every step (a frame per step
    is 50 000 VTU files for 50 000 steps), said before the run; an interval meant in steps or
    in another unit (ms) is the usual cause."""
    case = sim.case
    th = sim.thermal
    frozen = th is not None and th.settings.frozen_mechanics
    key = "thermal.time_step" if frozen else "simulation.time_step"
    dt = th.settings.time_step if frozen else sim.dt
    from thermodem.engine.validation import total_steps  # (validation imports this module)

    steps = total_steps(sim)
    shortened = case._shortened
    target = "simulation.end_time" if shortened is None else f"the end of this run ({shortened[0]})"
    out = []
    for name in ("interval", "timeseries_interval", "checkpoint_interval"):
        value = getattr(case.output, name)
        if value is None or value >= dt * (1.0 - 1e-9):
            continue
        what = "a frame" if name == "interval" else "a row" if name[0] == "t" else "a checkpoint"
        out.append(
            f"output.{name} = {value:g} s is shorter than {key} = {dt:g} s: {what} is written at "
            f"every step ({steps} steps to {target}); intervals are simulated "
            f"seconds: give at least {dt:g} s"
        )
    return out
