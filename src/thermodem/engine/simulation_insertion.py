"""Particles added while a simulation exists (pouring, scripts): a mixin of
:class:`~thermodem.engine.simulation.Simulation` (on several MPI ranks
``thermodem.mpi.simulation`` overrides :meth:`pour` and :meth:`add_particles`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from thermodem.engine import external_loads as EL
from thermodem.geometry.insertion import InsertedParticles
from thermodem.state.particles import Particles


class ParticleInsertion:
    """Fresh global ids, external loads, ledger entries, and the lists rebuilt after."""

    particles: Particles
    pourers: list
    case: Any
    thermal: Any

    def add_particles(self, new: InsertedParticles) -> None:
        """Append particles of one material; they get fresh global ids."""
        extra = self.new_particles(new)
        if extra is None:
            return
        self.particles.append(extra)
        if hasattr(self, "reference"):
            self.reference = np.concatenate([self.reference, extra.position])
        self._needs_rebuild = True

    def pour(self) -> None:
        """Insert the batches of the pour entries that are due at this step's time."""
        for pourer in self.pourers:
            if pourer.due(self.time, self.dt):
                p = self.particles
                self.add_particles(pourer.emit(self.time, p.position, p.radius))

    def new_particles(self, new: InsertedParticles) -> Particles | None:
        """The particle arrays of ``new`` (None if empty), with fresh global ids, their
        external loads, and their energies entered in the ledgers (not yet added)."""
        n = len(new)
        if n == 0:
            return None
        t = self.material_index[new.material]
        temperature = new.temperature
        if temperature is None and self.thermal is not None:
            temperature = self.thermal.initial_temperature(new.position, np.full(n, t))
        elif temperature is None:
            temperature = np.full(n, self.case.simulation.initial_temperature)
        gids = np.arange(self.next_global_id, self.next_global_id + n, dtype=np.int64)
        self.next_global_id += n
        extra = Particles.create(
            new.position,
            new.radius,
            np.full(n, self.density[t]),
            np.full(n, t, np.int32),
            gids,
            new.velocity,
            temperature,
            mechanisms=self.mechanisms,
            external=bool(self.case.external_force),
            disc_thickness=self.disc_thickness,
            generation=self.generation,
        )
        EL.assign(self.case, extra, self.material_index)
        if hasattr(self, "ledger_cumulative"):
            self.ledger_cumulative["inserted_energy"] += float(
                0.5 * np.sum(extra.mass * np.sum(extra.velocity**2, axis=1))
                - np.sum(extra.mass * (extra.position @ self.gravity))
            )
        if self.thermal is not None and hasattr(self, "ledger_cumulative"):
            self.thermal.inserted(extra.temperature, extra.mass, extra.type_id)
        return extra
