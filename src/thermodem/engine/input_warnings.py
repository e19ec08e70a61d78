"""Warnings of inputs that run but are most likely a mistake, told before the first step by
``thermodem validate`` and ``thermodem run`` (:func:`thermodem.engine.validation.pre_run_checks`,
beside :mod:`thermodem.engine.case_warnings` and :mod:`thermodem.engine.ignored_settings`):
temperatures given in a case without heat, an interstitial gas that no selected model reads,
mechanical values far outside any real material or planet (a unit mistake), an
``extra_distance`` of many particle diameters, and loads and heat fluxes of zero. Each names
the key, the value and what happens instead; none refuses the case."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

#: A Young's modulus below this [Pa] is told: the softest particles simulated (gels) have
#: about 1e4 Pa; a value in MPa or GPa (70 for glass) is the usual cause.
YOUNGS_SUSPECT_BELOW = 1.0e3
#: A sliding or rolling friction coefficient above this is told: real ones are below about
#: 1.5; a friction angle in degrees (30) is the usual cause.
FRICTION_SUSPECT_ABOVE = 5.0
#: A gravitational acceleration above this [m/s²] (about 100 g) is told: a value in mm/s²
#: (9810) or cm/s² (981) is the usual cause.
GRAVITY_SUSPECT_ABOVE = 1000.0
#: A ``neighbors.extra_distance`` above this many largest particle diameters is told.
EXTRA_DISTANCE_WARN_DIAMETERS = 2.0


def _given(model: object, key: str) -> bool:
    """``key`` written in the case with another value than its default: case.resolved.yaml
    writes every default (``initial_temperature: 293.15``, ``sliding_friction: 0.5``), and
    running it again must not warn about values the user never wrote."""
    if key not in model.model_fields_set:  # type: ignore[attr-defined]
        return False
    field = type(model).model_fields[key]  # type: ignore[attr-defined]
    return getattr(model, key) != field.default


def mechanics_only_temperature_warnings(case: Case) -> list[str]:
    """Start temperatures in a case without a thermal section (mechanics only): a
    ``simulation.initial_temperature`` or an insertion entry's ``temperature`` /
    ``temperatures`` is never used (a wall's fixed temperature: ignored_settings)."""
    if case.thermal is not None:
        return []
    why = (
        "but the case has no thermal section, so it runs mechanics only and no temperature is "
        "used; add thermal: {} for the heat with every default, or leave it out"
    )
    out = []
    sim = case.simulation
    if _given(sim, "initial_temperature"):
        out.append(f"simulation.initial_temperature: {sim.initial_temperature:g} K is given, {why}")
    for k, e in enumerate(case.insertion):
        if getattr(e, "temperature", None) is not None:
            out.append(f"insertion.{k}.temperature: {e.temperature:g} K is given, {why}")
        values = getattr(e, "temperatures", None)
        if values:
            shown = ", ".join(f"{t:g}" for t in values[:4]) + (", ..." if len(values) > 4 else "")
            out.append(f"insertion.{k}.temperatures: [{shown}] K are given, {why}")
    return out


def initial_temperature_rule_warnings(case: Case) -> list[str]:
    """``simulation.initial_temperature`` beside a ``thermal.initial_temperature`` rule: the
    rule gives every particle a temperature (``per_material`` and ``regions`` their
    ``default``, 293.15 K, to the particles they do not name), so the simulation's value is
    never used (docs/thermal-engine.md, section 6)."""
    th = case.thermal
    sim = case.simulation
    if th is None or th.initial_temperature is None:
        return []
    if not _given(sim, "initial_temperature"):
        return []
    rule = th.initial_temperature
    default = getattr(rule, "default", None)
    rest = (
        f" (its default, {default:g} K, for the particles it does not name)"
        if default is not None
        else ""
    )
    return [
        f"simulation.initial_temperature: {sim.initial_temperature:g} K is given, but "
        f"thermal.initial_temperature (kind {rule.kind}) gives every particle its temperature"
        f"{rest}, so it is not used; allowed: the temperature in the rule (e.g. its default), "
        "or leave simulation.initial_temperature out"
    ]


#: Direct conduction models whose heat rate is proportional to a power of the contact radius
#: (batchelor_obrien_simple: Q = 4 k R_c ΔT; thermal_pipe: A_p = π R_c²).
RADIUS_PROPORTIONAL = ("batchelor_obrien_simple", "thermal_pipe")


def thermal_choice_warnings(case: Case) -> list[str]:
    """A ``contact_radius: none`` (R_c = 0) under a direct conduction proportional to the
    contact radius (it conducts nothing), and an ``interactions`` entry's ``surface_roughness``
    / ``surface_slope`` without the resistance network, their only reader."""
    th = case.thermal
    out = []
    radius = getattr(th.contact_radius, "model", None) if th is not None else None
    direct = getattr(th.direct_conduction, "model", None) if th is not None else None
    if radius == "none" and direct in RADIUS_PROPORTIONAL:
        out.append(
            f"thermal.contact_radius = 'none' gives the contact radius R_c = 0, so "
            f"thermal.direct_conduction = {direct!r} (a heat rate proportional to R_c) conducts "
            "nothing between touching particles; allowed: a contact_radius model (geometric, "
            "the default), or direct_conduction: none"
        )
    if direct != "resistance_network":
        for k, o in enumerate(case.interactions):
            given = [
                f"{key} = {getattr(o, key):g}"
                for key in ("surface_roughness", "surface_slope")
                if getattr(o, key) is not None
            ]
            if given:
                out.append(
                    f"interactions.{k}: {' and '.join(given)} given, but only "
                    "thermal.direct_conduction = 'resistance_network' reads them (selected: "
                    f"{'no thermal section' if th is None else repr(direct)}): not used; "
                    "allowed: direct_conduction: resistance_network, or leave them out"
                )
    return out


def unread_gas_warnings(case: Case) -> list[str]:
    """A ``thermal.gas`` section that no selected model reads (the default conduction
    ``batchelor_obrien_simple`` reads none): its values change nothing."""
    from thermodem.engine.validation import model_choices

    th = case.thermal
    if th is None or "gas" not in th.model_fields_set:
        return []
    if th.gas.model_dump() == type(th.gas)().model_dump():
        return []  # (the default air, as case.resolved.yaml writes it)
    if any(c.spec.uses_gas for _, c in model_choices(case)):
        return []
    return [
        "thermal.gas is given but no selected model reads it (the gas is read by "
        "direct_conduction batchelor_obrien_complete / _modified and resistance_network, every "
        "indirect_conduction model and the convection models; selected: direct_conduction = "
        f"{getattr(th.direct_conduction, 'model', th.direct_conduction)!r}, indirect_conduction "
        f"= {getattr(th.indirect_conduction, 'model', th.indirect_conduction)!r}, convection = "
        f"{getattr(th.convection, 'model', th.convection)!r}): it has no effect; select a model "
        "that reads it, or leave thermal.gas out"
    ]


def _reads_youngs_modulus(case: Case) -> bool:
    from thermodem.engine.validation import model_choices

    for path, choice in model_choices(case):
        if path.startswith("contact.") and "youngs_modulus" in choice.spec.required(choice.params):
            return True
    return False


def mechanical_value_warnings(case: Case) -> list[str]:
    """Mechanical values no real material or planet has, each the likely result of another
    unit: a ``youngs_modulus`` below :data:`YOUNGS_SUSPECT_BELOW` Pa read by the contact laws
    (GPa or MPa?), a sliding or rolling friction coefficient above
    :data:`FRICTION_SUSPECT_ABOVE` (material or ``interactions`` entry; an angle in degrees?)
    and a gravity above :data:`GRAVITY_SUSPECT_ABOVE` m/s² (mm/s²?)."""
    out = []
    reads_e = _reads_youngs_modulus(case)
    for name, m in case.materials.items():
        if reads_e and m.youngs_modulus < YOUNGS_SUSPECT_BELOW:
            out.append(
                f"materials.{name}.youngs_modulus: {m.youngs_modulus:g} Pa is below "
                f"{YOUNGS_SUSPECT_BELOW:g} Pa, softer than any material simulated as particles "
                "(gels have about 1e4 Pa, softened DEM materials 1e6-1e8 Pa): is it in GPa or "
                f"MPa? (70 GPa = 7e10 Pa); the particles would sink into each other and the "
                "run stop at simulation.max_overlap_ratio"
            )
    pairs = [(f"materials.{n}", m) for n, m in case.materials.items()]
    pairs += [(f"interactions.{k}", o) for k, o in enumerate(case.interactions)]
    for key, entry in pairs:
        for prop in ("sliding_friction", "rolling_friction"):
            value = getattr(entry, prop)
            if value is not None and value > FRICTION_SUSPECT_ABOVE:
                hint = ""
                if value < 90.0:
                    hint = (
                        f"; is it an angle in degrees? (a friction angle of {value:g}° is the "
                        f"coefficient tan {value:g}° = {math.tan(math.radians(value)):.3g})"
                    )
                out.append(
                    f"{key}.{prop}: {value:g} is above {FRICTION_SUSPECT_ABOVE:g}, far above any "
                    f"real coefficient (0.1-1.5){hint}"
                )
    g = case.simulation.gravity
    magnitude = math.sqrt(sum(c * c for c in g))
    if magnitude > GRAVITY_SUSPECT_ABOVE:
        out.append(
            f"simulation.gravity: {list(g)} has the magnitude {magnitude:g} m/s², "
            f"{magnitude / 9.81:.3g} times the Earth's 9.81 m/s²: is it in mm/s² or cm/s²? "
            "Accelerations are in m/s² ([0, 0, -9.81]); a centrifuge case can ignore this"
        )
    return out


def zero_load_warnings(case: Case) -> list[str]:
    """An ``external_force`` entry whose force and torque are both zero, a ``heat_flux`` of
    0 W/m², a ``volumetric_source`` of 0 W/m³ (a constant) or an ``external_source`` of 0 W:
    each does nothing."""
    out = []
    for k, e in enumerate(case.external_force):
        if not any(e.force) and not any(e.torque):
            out.append(
                f"external_force.{k}: force {list(e.force)} and torque {list(e.torque)} are both "
                "zero, so the entry does nothing; give a non-zero force or torque, or remove it"
            )
    th = case.thermal
    if th is not None:
        for key, value_key, unit in (
            ("heat_flux", "flux", "W/m²"),
            ("volumetric_source", "power_density", "W/m³"),
        ):
            for k, e in enumerate(getattr(th, key)):
                value = getattr(e, value_key, None)
                if isinstance(value, (int, float)) and value == 0:
                    out.append(
                        f"thermal.{key}.{k}.{value_key}: 0 {unit} gives no heat, so the entry "
                        "does nothing; give a non-zero value, or remove it"
                    )
        for k, e in enumerate(th.external_source):
            if e.power == 0:
                out.append(
                    f"thermal.external_source.{k}.power: 0 W gives no heat, so the source does "
                    "nothing; give a non-zero power, or remove it"
                )
    return out


def friction_law_warnings(case: Case) -> list[str]:
    """Friction coefficients the contact laws leave unread, and a law with nothing to read:
    a ``rolling_friction`` given while ``contact.rolling`` is ``none`` (the default: other
    codes switch rolling resistance on by the coefficient alone), a ``sliding_friction`` given
    while ``contact.tangential`` is ``none``, and a rolling model whose every coefficient is 0
    (it gives no torque)."""
    out = []
    families = (
        ("rolling_friction", case.contact.rolling, "rolling", "constant_torque or epsd"),
        ("sliding_friction", case.contact.tangential, "tangential", "mindlin or linear"),
    )
    entries = [(f"materials.{n}", m) for n, m in case.materials.items()]
    entries += [(f"interactions.{k}", o) for k, o in enumerate(case.interactions)]
    for prop, choice, family, models in families:
        model = getattr(choice, "model", choice)
        given = [
            f"{key}.{prop} = {getattr(e, prop):g}"
            for key, e in entries
            if _given(e, prop) and getattr(e, prop)
        ]
        if model == "none" and given:
            default = " (the default)" if family not in case.contact.model_fields_set else ""
            out.append(
                f"{', '.join(given)} given, but contact.{family} is 'none'{default}: the "
                f"coefficient is not read and there is no {family} resistance; allowed: "
                f"contact.{family}: {models}, or leave {prop} out"
            )
    rolling = getattr(case.contact.rolling, "model", case.contact.rolling)
    if rolling != "none" and not any((e.rolling_friction or 0.0) > 0.0 for _, e in entries):
        out.append(
            f"contact.rolling = {rolling!r}, but every material's rolling_friction is 0 (the "
            "default) and no interactions entry gives one: the model gives no torque; give "
            "materials.NAME.rolling_friction (e.g. 0.05), or rolling: none"
        )
    return out


def unused_material_warnings(case: Case) -> list[str]:
    """A material that no wall and no insertion entry uses: its values take part in nothing
    (a ``steel`` defined for the walls while the walls still name ``glass``)."""
    used = {w.material for w in case.walls} | {e.material for e in case.insertion}
    unused = [name for name in case.materials if name not in used]
    if not unused or not used:
        return []
    return [
        f"materials.{name}: defined, but no wall and no insertion entry uses it, so its values "
        f"take part in nothing (the walls and entries use {', '.join(sorted(used))}); give "
        "it as a wall's or an entry's material, or remove it"
        for name in unused
    ]


def case_input_warnings(case: Case) -> list[str]:
    """The warnings of this module that need the case alone."""
    return (
        friction_law_warnings(case)
        + unused_material_warnings(case)
        + mechanics_only_temperature_warnings(case)
        + initial_temperature_rule_warnings(case)
        + thermal_choice_warnings(case)
        + unread_gas_warnings(case)
        + mechanical_value_warnings(case)
        + zero_load_warnings(case)
    )


def extra_distance_warnings(sim: Simulation) -> list[str]:
    """A ``neighbors.extra_distance`` of more than :data:`EXTRA_DISTANCE_WARN_DIAMETERS`
    largest diameters: every pair that close is kept in the contact list (state only; heat
    never reads it), as costly as a huge skin. A domain size or a length in mm?"""
    from thermodem.engine.start_checks import largest_radius

    diameter = 2.0 * largest_radius(sim)
    extra = sim.case.neighbors.extra_distance
    if diameter <= 0.0 or extra <= EXTRA_DISTANCE_WARN_DIAMETERS * diameter:
        return []
    return [
        f"neighbors.extra_distance = {extra:g} m is {extra / diameter:.3g} times the largest "
        f"particle diameter ({diameter:g} m): every pair of particles within {extra:g} m of "
        "touching is kept in the contact list, which slows every step and takes memory; it "
        "only keeps near pairs as state (the heat's gap conduction has thermal.range_skin). "
        "A length in mm?"
    ]
