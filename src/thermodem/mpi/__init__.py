"""Runs on several MPI ranks: spatial domain decomposition (docs/mpi.md).

``mpiexec -n P thermodem run CASE ...`` runs one case on P ranks; ``thermodem run`` alone, or
under ``mpiexec -n 1``, is the plain serial run (mpi4py is not even imported). Whether this
process is one of several ranks is read from the environment the MPI launcher sets
(:func:`world_size`), so the serial path pays nothing for the MPI support.

Modules:

- :mod:`thermodem.mpi.support`: the features refused under MPI, checked before the run;
- :mod:`thermodem.mpi.decomposition`: recursive coordinate bisection by particle count;
- :mod:`thermodem.mpi.exchange`: migration and the ghost halo (mpi4py buffer API);
- :mod:`thermodem.mpi.simulation`: :class:`DistributedSimulation`, the serial kernels on the
  owned + ghost particles of each rank;
- :mod:`thermodem.mpi.gather`: global reports, frames and checkpoints gathered to rank 0;
- :mod:`thermodem.mpi.runner`: the run loop and output directory under MPI.

The Python API under ``mpiexec``::

    from thermodem.mpi import make_simulation
    sim = make_simulation(case)          # a DistributedSimulation on P > 1 ranks
    sim.run(steps=100)
    sim.report()                         # global numbers, on every rank (collective)
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

#: Environment variables of MPI launchers that hold the number of ranks (MPICH/Hydra, Open
#: MPI, PMIx, Slurm's srun).
SIZE_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS")


def world_size() -> int:
    """Number of MPI ranks this process belongs to, from the launcher's environment (1 when
    not started by an MPI launcher). Does not import mpi4py."""
    for name in SIZE_VARIABLES:
        value = os.environ.get(name)
        if value:
            try:
                return max(1, int(value))
            except ValueError:
                continue
    return 1


def under_mpi() -> bool:
    """True when this process is one of several MPI ranks (``mpiexec -n P``, P > 1)."""
    return world_size() > 1


def make_simulation(case: Case, threads: int | None = None, **kwargs: Any) -> Simulation:
    """A :class:`~thermodem.mpi.simulation.DistributedSimulation` when this process is one of
    several MPI ranks, else a plain :class:`~thermodem.engine.simulation.Simulation`."""
    if under_mpi():
        from thermodem.mpi.simulation import DistributedSimulation

        return DistributedSimulation(case, threads=threads, **kwargs)
    from thermodem.engine.simulation import Simulation

    return Simulation(case, threads=threads)
