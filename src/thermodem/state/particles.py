"""Particle state as a structure of arrays.

Every per-particle quantity is a contiguous NumPy array with the particle as first index.
``global_id`` is the stable identity of a particle (history keys, restarts, output); the array
order changes when the neighbour list sorts particles by cell. ``heat_rate_by_mechanism`` has
one column per heat transfer mechanism (:data:`thermodem.state.heat.MECHANISMS`), stored
column by column (Fortran order, kept so by every constructor, :meth:`permute` and
:meth:`append`); the kernels take its transpose :attr:`Particles.heat_columns`, a row per
mechanism in C order whatever the particle count. A pass that adds to one mechanism, such as
the contact pass to the direct conduction, so touches 8 B per particle, not the whole 104 B
row (on the 50,000-sphere shared bed the row layout made the contact pass's heat cost ~3×
more, docs/architecture.md).
``external_force`` and ``external_torque`` hold the constant loads of the case key
``external_force`` (added to the weight at every force reset); without that key they have no
columns (0 B per particle). ``generation_energy`` accumulates, per mechanism of
:data:`thermodem.state.heat.GENERATION`, the particle's share of the energy its contacts
dissipated since the last thermal step (heat generation; no columns without it).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from thermodem.state.heat import GENERATION, HEAT_MECHANISMS  # defined in state/heat.py


def particle_mass(
    density: np.ndarray, radius: np.ndarray, disc_thickness: float = 0.0
) -> np.ndarray:
    """Mass [kg] of solid spheres, ρ 4/3 π R³, or (``disc_thickness`` b > 0) of solid discs,
    ρ π R² b."""
    if disc_thickness > 0.0:
        return density * np.pi * radius**2 * disc_thickness
    return density * (4.0 / 3.0) * np.pi * radius**3


@dataclass
class Particles:
    """Per-particle arrays (SI units)."""

    position: np.ndarray  # (n, 3) [m]
    velocity: np.ndarray  # (n, 3) [m/s]
    angular_velocity: np.ndarray  # (n, 3) [rad/s]
    force: np.ndarray  # (n, 3) [N]
    torque: np.ndarray  # (n, 3) [N m]
    radius: np.ndarray  # (n,) [m]
    mass: np.ndarray  # (n,) [kg]
    moment_of_inertia: np.ndarray  # (n,) [kg m^2]
    temperature: np.ndarray  # (n,) [K]
    heat_rate: np.ndarray  # (n,) [W]
    heat_rate_by_mechanism: np.ndarray  # (n, len(HEAT_MECHANISMS)) [W]
    type_id: np.ndarray  # (n,) int32, index into the material table
    global_id: np.ndarray  # (n,) int64, stable identity
    external_force: np.ndarray  # (n, 3) [N], constant; (n, 0) when the case has none
    external_torque: np.ndarray  # (n, 3) [N m], constant; (n, 0) when the case has none
    generation_energy: np.ndarray  # (n, len(GENERATION)) [J]; (n, 0) without heat generation

    def __post_init__(self) -> None:
        self.heat_rate_by_mechanism = np.asfortranarray(self.heat_rate_by_mechanism)

    @property
    def heat_columns(self) -> np.ndarray:
        """``heat_rate_by_mechanism`` as the kernels take it: (mechanisms, n), C order, a row per
        mechanism (a view: the kernels' writes are the particles' heat rates)."""
        return self.heat_rate_by_mechanism.T

    @property
    def count(self) -> int:
        return int(self.radius.shape[0])

    @classmethod
    def empty(
        cls,
        mechanisms: int = len(HEAT_MECHANISMS),
        external: bool = False,
        generation: bool = False,
    ) -> Particles:
        return cls.create(
            np.zeros((0, 3)),
            np.zeros(0),
            np.zeros(0),
            np.zeros(0, np.int32),
            np.zeros(0, np.int64),
            mechanisms=mechanisms,
            external=external,
            generation=generation,
        )

    @classmethod
    def create(
        cls,
        position: np.ndarray,
        radius: np.ndarray,
        density: np.ndarray,
        type_id: np.ndarray,
        global_id: np.ndarray,
        velocity: np.ndarray | None = None,
        temperature: np.ndarray | None = None,
        mechanisms: int = len(HEAT_MECHANISMS),
        external: bool = False,
        disc_thickness: float = 0.0,
        generation: bool = False,
    ) -> Particles:
        """Solid spheres: m = ρ 4/3 π R³, I = 2/5 m R²; with ``disc_thickness`` b > 0 (a 2D
        case of discs) solid discs of that thickness: m = ρ π R² b, I = 1/2 m R² (about the
        disc's axis, z).

        ``mechanisms`` is the number of columns of ``heat_rate_by_mechanism``: all of
        :data:`HEAT_MECHANISMS` with a thermal engine, 0 for mechanics only (64 B/particle less).
        ``external``: the case has external loads (``external_force`` and ``external_torque``
        get 3 columns, zero until the simulation assigns them). ``generation``: the case has a
        heat generation model (``generation_energy`` gets a column per mechanism).
        """
        n = radius.shape[0]
        radius = np.ascontiguousarray(radius, dtype=np.float64)
        mass = particle_mass(np.asarray(density, dtype=np.float64), radius, disc_thickness)
        return cls(
            position=np.ascontiguousarray(position, dtype=np.float64).reshape(n, 3),
            velocity=np.zeros((n, 3))
            if velocity is None
            else np.ascontiguousarray(velocity, dtype=np.float64).reshape(n, 3),
            angular_velocity=np.zeros((n, 3)),
            force=np.zeros((n, 3)),
            torque=np.zeros((n, 3)),
            radius=radius,
            mass=mass,
            moment_of_inertia=(0.5 if disc_thickness > 0.0 else 0.4) * mass * radius**2,
            temperature=np.zeros(n)
            if temperature is None
            else np.ascontiguousarray(temperature, dtype=np.float64),
            heat_rate=np.zeros(n),
            heat_rate_by_mechanism=np.zeros((n, mechanisms), order="F"),
            type_id=np.ascontiguousarray(type_id, dtype=np.int32),
            global_id=np.ascontiguousarray(global_id, dtype=np.int64),
            external_force=np.zeros((n, 3 if external else 0)),
            external_torque=np.zeros((n, 3 if external else 0)),
            generation_energy=np.zeros((n, len(GENERATION) if generation else 0)),
        )

    def permute(self, order: np.ndarray) -> None:
        """Reorder every array so that new index k holds old particle order[k]."""
        for f in fields(self):
            if f.name == "heat_rate_by_mechanism":  # one copy, in its column order
                self.heat_rate_by_mechanism = np.take(self.heat_columns, order, axis=1).T
            else:
                setattr(self, f.name, np.ascontiguousarray(getattr(self, f.name)[order]))

    def append(self, other: Particles) -> None:
        for f in fields(self):
            if f.name == "heat_rate_by_mechanism":  # one copy, in its column order
                rows = np.concatenate([self.heat_columns, other.heat_columns], axis=1)
                self.heat_rate_by_mechanism = rows.T
            else:
                both = [getattr(self, f.name), getattr(other, f.name)]
                setattr(self, f.name, np.concatenate(both))

    def arrays(self) -> dict[str, np.ndarray]:
        return {f.name: getattr(self, f.name) for f in fields(self)}
