"""Constant external forces and torques on selected particles (case key ``external_force``).

Each particle's external force and torque are evaluated once, when it is added to the
simulation (construction, pouring), into the ``Particles`` arrays ``external_force`` and
``external_torque``; they follow the particle through the neighbour-list sorts (``permute``)
and restarts like every particle array. The force reset adds them to the weights
(:func:`thermodem.kernels.integrate.reset_forces`): no per-step work in Python.

Their work enters the energy ledger as ``external_work``: each step, right after the drift,
Σ (F_ext · v + T_ext · ω) Δt with the half-step velocities, which is the work along the step's
displacement exactly (velocity Verlet moves x by v Δt), so the balance stays closed.
"""

from __future__ import annotations

import numpy as np

from thermodem.config.schema import Case
from thermodem.errors import ConfigError
from thermodem.state.particles import Particles


def selected(
    entry_select,  # noqa: ANN001
    particles: Particles,
    material_index: dict[str, int],
    planar: bool = False,
) -> np.ndarray:
    """Mask of the particles a :class:`~thermodem.config.thermal.Selection` takes (all of its
    criteria: material, box region on the current positions (2D, ``planar``: z ignored),
    global ids)."""
    from thermodem.engine.thermal_conditions import in_box

    mask = np.ones(particles.count, bool)
    if entry_select.material is not None:
        mask &= particles.type_id == material_index[entry_select.material]
    if entry_select.region is not None:
        mask &= in_box(particles.position, entry_select.region, planar)
    if entry_select.ids is not None:
        mask &= np.isin(particles.global_id, np.asarray(entry_select.ids, np.int64))
    return mask


def assign(case: Case, particles: Particles, material_index: dict[str, int]) -> None:
    """Fill ``external_force``/``external_torque`` of newly added ``particles`` from every
    ``external_force`` entry (they add up); nothing when the case has none."""
    if particles.external_force.shape[1] != 3:
        return
    particles.external_force[:] = 0.0
    particles.external_torque[:] = 0.0
    for entry in case.external_force:
        mask = selected(entry.select, particles, material_index, case.simulation.planar)
        particles.external_force[mask] += np.asarray(entry.force, float)
        particles.external_torque[mask] += np.asarray(entry.torque, float)


def check_selected(case: Case, particles: Particles, material_index: dict[str, int]) -> None:
    """Refuse an entry that takes none of the particles present at the start when no particle
    will be poured later (a wrong id, material or region), naming the key."""
    if any(e.kind == "pour" for e in case.insertion):
        return
    for k, entry in enumerate(case.external_force):
        if not selected(entry.select, particles, material_index, case.simulation.planar).any():
            sel = entry.select.model_dump(exclude_none=True)
            raise ConfigError(
                f"external_force.{k}.select: selects no particle ({sel}); the selection is "
                "evaluated on the particles present at the start (material, region on their "
                "positions, global ids 0 ... N-1 in insertion order)"
            )


def step_work(sim) -> float:  # noqa: ANN001
    """Work of the external loads over the step just drifted [J] (call after kick_drift and
    reduce_checks: the per-chunk sums reuse the chunk check scratch)."""
    from thermodem.kernels.integrate import external_power

    p = sim.particles
    n = sim.owned_count  # (all of them; on several MPI ranks the ghosts are others' to count)
    power = external_power(p.velocity[:n], p.angular_velocity[:n], p.external_force[:n],
                           p.external_torque[:n], sim.chunk_check)  # fmt: skip
    return sim.dt * power
