"""What a run on several MPI ranks supports, checked before any simulation time is spent.

Supported (docs/mpi.md): the mechanics (every normal, tangential and rolling model, walls of
every kind, moving walls, periodic axes, constant external forces and torques), static
insertion and pouring (mpi/simulation.py: DistributedSimulation.pour), the thermal engine
with explicit Euler, the contact conduction of the fused contact pass (every contact radius
and direct conduction model, the conductance reuse, k(T) and c(T) tables), the range pair set (gap
conduction of Batchelor & O'Brien complete / modified, indirect conduction through the
fluid), the per-particle terms that need no neighbours (convection with a fluid given as
uniform / table / expression / grid and a global porosity, radiation ``surroundings`` with
its walls), fixed-temperature walls, fixed-temperature particles, heat flux and volumetric
sources, external sources, heat generation (every model: the deposits of the contact passes,
each rank keeping its own particles' side), heat terms on the contact lists outside the fused
pass (vargas_mccarthy2002: over the list and the mirror list), frozen mechanics with the
explicit scheme, discs (2D), checkpoints, frames (contact frames included) and time series.

Refused, each with a message naming the case key (never a silently wrong result):
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.thermal import ThermalEngine

#: porosity kinds computed from the neighbours of each particle, and what they count
NEIGHBOUR_POROSITY = {
    "cell": "the porosity of each cell from the particles in it",
    "shell": "the porosity of a shell around each particle from its neighbours",
    "voronoi": "the porosity of each particle's Voronoi cell (a global tessellation)",
}
#: radiation models that sum over each particle's neighbourhood
NEIGHBOUR_RADIATION = ("zhou2009", "krause2017")

#: (case key, why) of every refused feature, in the order they are checked (docs/mpi.md).
REFUSED: tuple[tuple[str, str], ...] = (
    ("thermal.scheme", "the implicit schemes (backward Euler, CN, TR-BDF2, exponential)"),
    ("thermal.porosity.kind", "local porosities from the neighbours (cell, shell, voronoi)"),
    ("thermal.radiation", "radiation from the neighbourhood (zhou2009, krause2017)"),
    ("thermal.indirect_conduction", "Voronoi models (their external pair set)"),
)


def _refuse(key: str, what: str) -> ConfigError:
    return ConfigError(
        f"{key}: {what} — MPI does not support it yet (this run has several MPI ranks); run "
        "it without mpiexec (or with mpiexec -n 1), or remove the key. Supported under MPI: "
        "docs/mpi.md"
    )


def check_case(case: Case) -> None:
    """ConfigError for the first case key that a multi-rank run does not support."""
    th = case.thermal
    if th is None:
        return
    if th.scheme != "explicit":
        raise _refuse(f"thermal.scheme = {th.scheme!r}", "the implicit heat schemes")
    porosity = th.porosity
    if porosity is not None and porosity.kind in NEIGHBOUR_POROSITY:
        raise _refuse(
            f"thermal.porosity.kind = {porosity.kind!r}",
            f"{NEIGHBOUR_POROSITY[porosity.kind]} (the neighbours of particles on other "
            "ranks; porosity: {kind: global, value: ...} runs under MPI)",
        )
    radiation = th.radiation
    if radiation is not None and radiation.model in NEIGHBOUR_RADIATION:
        raise _refuse(
            f"thermal.radiation = {radiation.model!r}",
            "radiation from the particles of each one's neighbourhood (the neighbours of "
            "particles on other ranks; radiation 'surroundings', with its walls, runs under "
            "MPI)",
        )
    ic = th.indirect_conduction
    if ic is not None and ic.model != "none" and ic.spec.target not in ("range", "contacts"):
        what = {
            "external": "Voronoi models (their external pair set)",
        }.get(ic.spec.target, f"heat terms on the pair set {ic.spec.target!r}")
        raise _refuse(f"thermal.indirect_conduction = {ic.model!r}", what)


def check_thermal(engine: ThermalEngine) -> None:
    """ConfigError for a heat term whose pair set MPI does not handle yet (the terms are
    known once the thermal engine has built them from the registry)."""
    for term in engine.terms:
        if term.target in ("range", "contacts", "particles"):  # (neighbourhoods: check_case)
            continue
        what = {
            "external": "a Voronoi model (external pair set)",
        }.get(term.target, f"a heat term on the pair set {term.target!r}")
        raise _refuse(f"{term.key} = {term.choice.model!r}", what)
