"""Warnings of settings that the rest of a case leaves unused, told before the first step by
``thermodem validate`` and ``thermodem run`` (:func:`thermodem.engine.validation.pre_run_checks`,
beside :mod:`thermodem.engine.case_warnings`): the motion settings of a run with frozen
mechanics, a wall's fixed temperature in a case without heat, an external source whose time
window lies after the end of the run, a wall given twice, and particles that a fixed
temperature holds while a heat source or another fixed temperature also selects them.
Each names the key, the value and what happens instead; none refuses the case (each may be a
step in building a case up, and the run does what the documentation says)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation


def _moves(vector: tuple[float, float, float]) -> bool:
    return any(c != 0.0 for c in vector)


def frozen_mechanics_warnings(case: Case) -> list[str]:
    """With ``thermal.frozen_mechanics: true`` nothing moves: pour entries insert nothing, and
    walls' velocities and angular velocities, entries' initial velocities and the external
    loads do nothing (docs/thermal-engine.md). Said for each one given."""
    th = case.thermal
    if th is None or not th.frozen_mechanics:
        return []
    why = (
        "but thermal.frozen_mechanics is true: nothing moves and the heat runs on the bed as "
        "it is at t = 0"
    )
    out = []
    for k, e in enumerate(case.insertion):
        if e.kind == "pour":
            out.append(
                f"insertion.{k}: a pour entry inserts particles during the run, {why}, so it "
                "inserts nothing; allowed: frozen_mechanics: false, or remove the entry"
            )
            continue
        velocities = getattr(e, "velocities", None)
        if _moves(e.velocity) or (velocities and any(_moves(v) for v in velocities)):
            key = "velocity" if _moves(e.velocity) else "velocities"
            out.append(
                f"insertion.{k}.{key}: an initial velocity is given, {why}, so the particles "
                f"do not move; allowed: frozen_mechanics: false, or leave {key} out"
            )
    for k, w in enumerate(case.walls):
        label = w.name or f"{w.kind}{k}"
        omega = getattr(w, "angular_velocity", 0.0)
        given = [f"velocity {list(w.velocity)}" for _ in (0,) if _moves(w.velocity)]
        given += [f"angular_velocity {omega:g} rad/s" for _ in (0,) if omega != 0.0]
        if given:
            out.append(
                f"walls.{k} ({label}): {' and '.join(given)} given, {why}, so the wall "
                "stays where it is; allowed: frozen_mechanics: false, or leave them out"
            )
    for k, _ in enumerate(case.external_force):
        out.append(
            f"external_force.{k}: a constant load is given, {why}, so it does nothing; "
            "allowed: frozen_mechanics: false, or remove the entry"
        )
    return out


def wall_temperature_warnings(case: Case) -> list[str]:
    """A wall with ``thermal: {kind: fixed, ...}`` in a case without a thermal section runs
    mechanics only: the wall's temperature is never used."""
    if case.thermal is not None:
        return []
    out = []
    for k, w in enumerate(case.walls):
        if w.thermal.kind != "fixed":
            continue
        label = w.name or f"{w.kind}{k}"
        out.append(
            f"walls.{k}.thermal ({label}): a fixed temperature ({w.thermal.temperature!r}) is "
            "given, but the case has no thermal section, so it runs mechanics only and the "
            "wall's temperature is not used; add thermal: {} for the heat with every default, "
            "or remove the wall's thermal key"
        )
    return out


def external_source_warnings(case: Case) -> list[str]:
    """An external source active only after the end of the run (``start_time`` at or beyond
    ``simulation.end_time``) gives no heat in this run."""
    from thermodem.engine.case_warnings import end_time_text

    th = case.thermal
    if th is None:
        return []
    end = case.simulation.end_time
    return [
        f"thermal.external_source.{k}: start_time = {s.start_time:g} s is at or after "
        f"{end_time_text(case)}: the source gives no heat in this run (times are simulated "
        "seconds)"
        for k, s in enumerate(th.external_source)
        if s.start_time >= end
    ]


def _wall_signature(wall: object) -> tuple:
    """What makes a wall act on particles (its geometry and motion; not name nor thermal)."""
    data = wall.model_dump(exclude={"name", "thermal", "material"})  # type: ignore[attr-defined]
    if data.get("kind") in ("plane", "rectangle", "cylinder"):
        for key in ("normal", "axis", "u_axis"):
            if key in data:
                v = np.asarray(data[key], float)
                data[key] = tuple(np.round(v / np.linalg.norm(v), 12))
    return tuple(sorted((k, repr(v)) for k, v in data.items()))


def duplicate_wall_warnings(case: Case) -> list[str]:
    """A wall given twice (a copied line): a particle touching it feels both, twice the
    contact force and, with a fixed temperature, twice the conduction."""
    seen: dict[tuple, int] = {}
    out = []
    for k, w in enumerate(case.walls):
        sig = _wall_signature(w)
        if sig in seen:
            j = seen[sig]
            out.append(
                f"walls.{k} ({w.name or f'{w.kind}{k}'}) is the same {w.kind} as walls.{j} "
                f"({case.walls[j].name or f'{case.walls[j].kind}{j}'}): a particle touching it "
                "is pushed by both (twice the contact force and conduction); remove one of them"
            )
        else:
            seen[sig] = k
    return out


def case_ignored_warnings(case: Case) -> list[str]:
    """The warnings of this module that need the case alone."""
    return (
        frozen_mechanics_warnings(case)
        + wall_temperature_warnings(case)
        + external_source_warnings(case)
        + duplicate_wall_warnings(case)
    )


def condition_overlap_warnings(sim: Simulation) -> list[str]:
    """Particles present at the start that a ``thermal.fixed_temperature`` entry holds while a
    ``heat_flux`` or ``volumetric_source`` entry also selects them (a held particle's
    temperature does not change: the source does nothing on it), or that two fixed
    temperatures of different values select (the later entry's holds)."""
    from thermodem.engine.external_loads import selected

    th = sim.case.thermal
    if th is None or not th.fixed_temperature:
        return []
    p = sim.particles
    n = sim.owned_count

    def taken(entry: object) -> np.ndarray:
        return np.asarray(selected(entry.select, p, sim.material_index, sim.planar)[:n])  # type: ignore[attr-defined]

    fixed = [taken(e) for e in th.fixed_temperature]
    out = []
    for key in ("heat_flux", "volumetric_source"):
        for k, entry in enumerate(getattr(th, key)):
            mask = taken(entry)
            for j, held in enumerate(fixed):
                both = int(sim.sum_over_ranks(float(np.count_nonzero(mask & held))))
                if both:
                    out.append(
                        f"thermal.{key}.{k} and thermal.fixed_temperature.{j} both select "
                        f"{both} particle(s) at the start: a fixed particle is held at "
                        f"{th.fixed_temperature[j].temperature:g} K, so the {key} does nothing "
                        "on it; narrow one of the selections"
                    )
    for j, held in enumerate(fixed):
        for i in range(j):
            a, b = th.fixed_temperature[i], th.fixed_temperature[j]
            if a.temperature == b.temperature:
                continue
            both = int(sim.sum_over_ranks(float(np.count_nonzero(fixed[i] & held))))
            if both:
                out.append(
                    f"thermal.fixed_temperature.{i} ({a.temperature:g} K) and "
                    f"thermal.fixed_temperature.{j} ({b.temperature:g} K) both select {both} "
                    f"particle(s) at the start: they are held at {b.temperature:g} K (the later "
                    "entry's); narrow one of the selections if that is not meant"
                )
    return out
