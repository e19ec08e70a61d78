"""What a run on several MPI ranks supports, checked before any simulation time is spent.

Supported (docs/mpi.md): the mechanics (every normal, tangential and rolling model, walls of
every kind, moving walls, periodic axes, constant external forces and torques), discs (2D),
static insertion and pouring (mpi/simulation.py: DistributedSimulation.pour), the thermal
engine with explicit Euler (frozen mechanics too), the contact conduction of the fused
contact pass (every contact radius and direct conduction model, the conductance reuse, k(T)
and c(T) tables), the range pair set (gap conduction of Batchelor & O'Brien complete /
modified, indirect conduction through the fluid), heat terms on the contact lists outside
the fused pass (vargas_mccarthy2002: over the list and the mirror list), the per-particle
terms (convection with a fluid given as uniform / table / expression / grid; radiation
``surroundings`` with its walls, zhou2009, krause2017; porosity global, cell, shell: the
ghosts reach as far as the neighbourhoods, mpi/simulation.py: halo_width),
fixed-temperature walls, fixed-temperature particles, heat flux and volumetric sources,
external sources, heat generation (every model: the deposits of the contact passes, each
rank keeping its own particles' side), checkpoints, frames (contact frames included) and
time series.

Refused, each with a message naming the case key (never a silently wrong result):
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.thermal import ThermalEngine

#: (case key, why) of every refused feature, in the order they are checked (docs/mpi.md).
REFUSED: tuple[tuple[str, str], ...] = (
    ("thermal.scheme", "the implicit schemes (backward Euler, CN, TR-BDF2, exponential)"),
    ("thermal.porosity.kind", "the Voronoi porosity (a global tessellation)"),
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
    if porosity is not None and porosity.kind == "voronoi":
        raise _refuse(
            "thermal.porosity.kind = 'voronoi'",
            "the porosity of each particle's Voronoi cell (a global tessellation; porosity "
            "cell, shell and global run under MPI)",
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
        if term.target in ("range", "contacts", "particles"):  # (Voronoi porosity: check_case)
            continue
        what = {
            "external": "a Voronoi model (external pair set)",
        }.get(term.target, f"a heat term on the pair set {term.target!r}")
        raise _refuse(f"{term.key} = {term.choice.model!r}", what)
