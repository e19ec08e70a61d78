"""Heat that starts at a restart: ``thermodem run CASE --restart CKPT`` where the checkpoint was
written without a ``thermal`` section and ``CASE`` has one (settle, then heat).

The checkpoint's particles get the temperatures the case assigns at t = 0 in a fresh run
(:meth:`Simulation.add_particles`): the temperature of their insertion entry (an entry's
``temperature``, a ``list`` entry's ``temperatures``, a particle file's temperature column),
else ``thermal.initial_temperature`` (uniform, per material, by region or an expression),
else ``simulation.initial_temperature``. A particle's entry follows from its global id: the
static entries (lattice, random, list, file) hold ids ``0 .. N-1`` in their order (their
counts are found by inserting them again, as t = 0 did, only when some static entry carries
its own temperatures), the pour entries the ids after them. The rules that depend on the
position (``regions``, ``expression``) are evaluated at the particles' positions at the
restart (where they have settled), not where they were inserted.

The thermal engine starts fresh at the checkpoint's step (its step counters aligned to it),
its heat ledger at zero, U(0) = Σ m c T of the assigned temperatures: the time series' heat
columns start at zero at the checkpoint's time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import ConfigError
from thermodem.state.heat import GENERATION

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def _carries_temperatures(entry: Any) -> bool:
    """Whether an insertion entry may give its particles their own temperatures."""
    if getattr(entry, "temperature", None) is not None:
        return True
    if getattr(entry, "temperatures", None) is not None:
        return True
    return entry.kind == "file"  # (a file may have a temperature column)


def _static_temperatures(sim: Simulation, count: int) -> np.ndarray:
    """Temperatures (NaN: the rule's) of the static entries' particles, by global id
    ``0 .. count-1``: the entries inserted again as at t = 0 (the same random generator)."""
    from thermodem.geometry.insertion import insert

    case = sim.case
    rng = np.random.default_rng(case.simulation.seed)
    positions, radii = np.zeros((0, 3)), np.zeros(0)
    out: list[np.ndarray] = []
    for k, entry in enumerate(case.insertion):
        if entry.kind == "pour":
            continue
        try:
            new = insert(
                entry, rng, positions, radii, key=f"insertion.{k}",
                domain=(sim.lower, sim.upper),
                max_overlap_ratio=case.simulation.max_overlap_ratio, planar=sim.planar,
                periodic=case.domain.periodic,
            )  # fmt: skip
        except ConfigError as exc:
            raise ConfigError(
                f"heat starts at this restart, and the particles of insertion.{k} get the "
                f"temperatures that entry gives them at t = 0, but it cannot be inserted "
                f"again to tell which particles are its: {exc}"
            ) from None
        n = len(new)
        out.append(np.full(n, np.nan) if new.temperature is None else new.temperature)
        positions = np.concatenate([positions, new.position])
        radii = np.concatenate([radii, new.radius])
    given = np.concatenate(out) if out else np.zeros(0)
    if given.shape[0] != count:
        raise ConfigError(
            f"heat starts at this restart, but the static insertion entries give "
            f"{given.shape[0]} particles at t = 0 and the checkpoint's run had {count}: the "
            "particles cannot be matched to their entries' temperatures; give the "
            "temperatures with thermal.initial_temperature instead"
        )
    return given


def _poured_temperature(sim: Simulation, type_id: np.ndarray) -> np.ndarray:
    """The pour entries' temperatures (NaN: the rule's) of poured particles of the materials
    ``type_id``: the entry that poured them, when the entries that poured differ."""
    entries = [(p.entry, p.inserted) for p in sim.pourers if p.inserted > 0]
    out = np.full(type_id.shape[0], np.nan)
    by_material: dict[int, set] = {}
    for entry, _ in entries:
        by_material.setdefault(sim.material_index[entry.material], set()).add(entry.temperature)
    for t, temperatures in by_material.items():
        if len(temperatures) > 1:
            raise ConfigError(
                f"heat starts at this restart, but the pour entries of material "
                f"{sim.material_names[t]!r} give their particles different temperatures "
                f"({', '.join(sorted(str(v) for v in temperatures))}) and the checkpoint does "
                "not say which entry poured which particle; give the pour entries of one "
                "material one temperature, or use thermal.initial_temperature"
            )
        (value,) = temperatures
        if value is not None:
            out[type_id == t] = float(value)
    return out


def initial_temperatures(sim: Simulation) -> tuple[np.ndarray, list[str]]:
    """The temperatures [K] the case gives ``sim``'s particles at t = 0 (see the module
    docstring) and the sources used, for the log."""
    p = sim.particles
    th = sim.thermal
    gid = p.global_id
    poured_total = sum(pourer.inserted for pourer in sim.pourers)
    static_count = int(sim.next_global_id) - int(poured_total)
    given = np.full(p.count, np.nan)
    sources: list[str] = []
    static = [e for e in sim.case.insertion if e.kind != "pour"]
    if any(_carries_temperatures(e) for e in static):
        by_id = _static_temperatures(sim, static_count)
        held = gid < static_count
        given[held] = by_id[gid[held]]
        if np.isfinite(given).any():
            sources.append("the insertion entries' temperatures")
    poured = gid >= static_count
    if poured.any():
        given[poured] = _poured_temperature(sim, p.type_id[poured])
        if np.isfinite(given[poured]).any() and not sources:
            sources.append("the insertion entries' temperatures")
    temperature = given
    rest = ~np.isfinite(given)
    if rest.any():
        temperature = given.copy()
        temperature[rest] = th.initial_temperature(p.position[rest], p.type_id[rest])
        rule = th.settings.initial_temperature
        if rule is None:
            sources.append("simulation.initial_temperature")
        else:
            where = (
                " at the particles' positions now" if rule.kind in ("regions", "expression") else ""
            )
            sources.append(f"thermal.initial_temperature ({rule.kind}{where})")
    return np.ascontiguousarray(temperature, dtype=np.float64), sources


def start_heat(sim: Simulation, ledger: dict[str, float]) -> str:
    """Start the thermal engine of ``sim`` (built from a case with a ``thermal`` section,
    loaded from a state without heat) at the state's time: the particles' heat arrays and
    temperatures, the mechanical ledger's keys of a heat generation model, the engine's step
    counters aligned to the state's step, rates and U(0) computed as a fresh run does at
    t = 0. Returns the line for the log."""
    th = sim.thermal
    p = sim.particles
    n = p.count
    p.heat_rate = np.zeros(n)
    p.heat_rate_by_mechanism = np.zeros((n, sim.mechanisms), order="F")
    p.generation_energy = np.zeros((n, len(GENERATION) if sim.generation else 0))
    temperature, sources = initial_temperatures(sim)
    p.temperature = temperature
    # keys of a heat generation model the mechanics-only ledger did not have
    sim.ledger_cumulative = {**dict.fromkeys(ledger, 0.0), **sim.ledger_cumulative}
    if th.generation.active:  # the energy dissipated before the heat started is no heat
        from thermodem.engine.generation import ledger_keys

        th.generation_baseline = {k: float(sim.ledger_cumulative[k]) for k in ledger_keys(th)}
    th.next_step = sim.step_count  # a thermal step at the first step after the restart
    th.particles_reordered()
    th.compute_rates(sim.time)
    # the first thermal step takes these rates, as a run's first step takes those of t = 0
    # (on several MPI ranks they travel with the particles to their ranks)
    th.fresh = True
    th.initial_energy = th.thermal_energy()
    th.cumulative["fixed_reset"] = 0.0  # (as at t = 0: resets before the start are the start)
    if n:
        low, high = float(temperature.min()), float(temperature.max())
        spread = f"{low:.6g} K" if low == high else f"{low:.6g}-{high:.6g} K"
    else:
        spread = "no particles yet"
    return (
        f"heat starts at t = {sim.time:.6g} s (step {sim.step_count}) from the case's initial "
        f"temperatures ({spread}; from {' and '.join(sources) or 'the case'}): the checkpoint "
        "was written without a thermal section"
    )
