"""Heat generation in the thermal engine: the accumulated dissipation becomes heat, and its
ledger (docs/thermal-engine.md, "Heat generation").

The contact passes add every contact's dissipated energy per mechanism into its particles'
accumulators (``Particles.generation_energy``) at each mechanical step; :func:`rates` turns them
into the heat rates χ E / Δt_th of the ``generation_<mechanism>`` columns for the thermal step
that follows, and :func:`clear` empties them once that step has applied them. :func:`ledger`
reports, per selected mechanism, what the mechanics dissipated (× χ), what went into the
particles, to the walls and what waits for the next thermal step; they close to round-off.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from thermodem.kernels import generation as kernels
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.thermal import ThermalEngine


def rates(engine: ThermalEngine) -> None:
    """χ E / Δt_th into the generation column of every selected mechanism (nothing without a
    generation model)."""
    gen = engine.generation
    if not gen.active:
        return
    p = engine.sim.particles
    kernels.generation_heat(p.generation_energy, gen.select, gen.conversion_fraction,
                            engine.thermal_dt(), p.heat_columns)  # fmt: skip


def clear(engine: ThermalEngine) -> None:
    """The thermal step applied the generated heat: empty the accumulators."""
    if engine.generation.active:
        engine.sim.particles.generation_energy[:] = 0.0


def ledger(engine: ThermalEngine) -> dict[str, float]:
    """The heat generation ledger [J] per selected mechanism g: χ × the energy the mechanics
    dissipated (``generated_<g>``: the mechanical ledger's ``dissipated_<g>``, or the kinetic
    energy lost in collisions; counted from the heat's start when it started at a restart),
    the heat that went to walls with a fixed temperature (``heat_to_walls_generation_<g>``),
    the heat accumulated in the particles but not yet
    applied by a thermal step (``heat_pending_generation_<g>``); with the heat into the
    particles (``heat_in_generation_<g>``, the heat ledger) they close:
    ``generation_balance_error`` = Σ_g generated - in - walls - pending, round-off."""
    sim = engine.sim
    # (the particles this process owns: all of them; on several MPI ranks the owned ones,
    # mpi/gather.py sums ledger_of over the ranks)
    pending = sim.particles.generation_energy[: sim.owned_count].sum(axis=0)
    return ledger_of(engine, sim.ledger_cumulative, pending, engine.cumulative)


def ledger_keys(engine: ThermalEngine) -> list[str]:
    """The keys of the mechanical ledger (``ledger_cumulative``) that :func:`ledger_of`
    reads."""
    keys = []
    for g in engine.generation.mechanisms:
        name = heat.GENERATION[g]
        source = "collision_energy_loss" if g == heat.G_COLLISION else name
        keys += [source, f"wall_generation_{name}"]
    return keys


def ledger_of(
    engine: ThermalEngine, cum: dict[str, float], pending: Any, cumulative: dict[str, float]
) -> dict[str, float]:
    """:func:`ledger` from the mechanical ledger ``cum``, the energies waiting in the
    accumulators ``pending`` (one per mechanism of GENERATION) and the heat ledger
    ``cumulative`` (the sums over the ranks on several MPI ranks)."""
    gen = engine.generation
    chi = gen.conversion_fraction
    base = engine.generation_baseline  # (heat started at a restart: counted from there)
    out: dict[str, float] = {}
    error = 0.0
    for g in gen.mechanisms:
        name = heat.GENERATION[g]
        source = "collision_energy_loss" if g == heat.G_COLLISION else name
        wall_key = f"wall_generation_{name}"
        generated = chi * (cum[source] - base.get(source, 0.0))
        walls = chi * (cum[wall_key] - base.get(wall_key, 0.0))
        waiting = chi * float(pending[g])
        out[f"generated_{name}"] = generated
        out[f"heat_to_walls_generation_{name}"] = walls
        out[f"heat_pending_generation_{name}"] = waiting
        into = cumulative[f"heat_in_generation_{name}"]
        error += generated - walls - waiting - into
    out["generation_balance_error"] = error
    return out
