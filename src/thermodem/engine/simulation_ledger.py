"""The simulation's energy ledger and what it reports: the ledger sums of the pair passes, the
mechanical energies and the balance error, the touching contacts (pairs, per-contact data,
coordination numbers), the stable time steps, and one row of the time series.

A mixin of :class:`thermodem.engine.simulation.Simulation` (split from that module by concern).
"""

from __future__ import annotations

import numpy as np

from thermodem.kernels import contact as C
from thermodem.kernels import pair_pass as PP
from thermodem.kernels.integrate import ledger_totals
from thermodem.state.heat import GENERATION

LEDGER_DISSIPATION = (
    "normal_damping",
    "tangential_damping",
    "sliding_friction",
    "rolling_friction",
    "plastic_deformation",
)
#: ledger columns of the dissipation mechanisms, in the order of LEDGER_DISSIPATION
_DISSIPATION_COLUMNS = (
    C.L_NORMAL_DAMPING,
    C.L_TANGENTIAL_DAMPING,
    C.L_SLIDING_FRICTION,
    C.L_ROLLING_FRICTION,
    C.L_PLASTIC_DEFORMATION,
)


class SimulationLedger:
    """Energy ledger, contacts and reports of the simulation (see the module docstring)."""

    # ------------------------------------------------------------------------------ ledger
    def _accumulate_ledger(self, count_dissipation: bool) -> None:
        pb, wb = self.pairs, self.walls
        nwc = (self.particles.count + PP.WALL_CHUNK - 1) // PP.WALL_CHUNK
        totals = self._ledger_totals
        ledger_totals(pb.chunk_ledger, pb.ngroups, wb.chunk_ledger, nwc,
                      C.L_MAX_OVERLAP_RATIO, totals)  # fmt: skip
        sums = totals.tolist()  # (Python floats: cheaper to add up than NumPy scalars)
        self.elastic = totals[C.L_ELASTIC_NORMAL : C.L_ELASTIC_ROLLING + 1].copy()
        self.contact_count = int(sums[C.L_TOUCHING])
        self.max_overlap_ratio = sums[C.LEDGER_WIDTH]
        if count_dissipation:
            cum = self.ledger_cumulative
            for name, column in zip(LEDGER_DISSIPATION, _DISSIPATION_COLUMNS, strict=True):
                cum[name] += sums[column]
            cum["stiffness_work"] += sums[C.L_STIFFNESS_WORK]
            cum["wall_work"] += sums[C.L_WALL_WORK]
            if self.generation:
                cum["collision_energy_loss"] += sums[C.L_COLLISION]
                for g, name in enumerate(GENERATION):
                    cum[f"wall_generation_{name}"] += sums[C.L_WALL_GENERATION + g]

    def energies(self) -> dict[str, float]:
        """Current mechanical energies [J] and cumulative dissipation by mechanism [J]."""
        p = self.particles
        ke_t = 0.5 * float(np.sum(p.mass * np.sum(p.velocity**2, axis=1)))
        ke_r = 0.5 * float(np.sum(p.moment_of_inertia * np.sum(p.angular_velocity**2, axis=1)))
        grav = -float(np.sum(p.mass * (p.position @ self.gravity)))
        out = {
            "kinetic_translational": ke_t,
            "kinetic_rotational": ke_r,
            "gravitational": grav,
            "elastic_normal": float(self.elastic[0]),
            "elastic_tangential": float(self.elastic[1]),
            "elastic_rolling": float(self.elastic[2]),
        }
        out.update(
            {
                f"dissipated_{k}": v
                for k, v in self.ledger_cumulative.items()
                if k in LEDGER_DISSIPATION
            }
        )
        if self.generation:  # kinetic energy lost in collisions (not a term of the balance)
            out["collision_energy_loss"] = self.ledger_cumulative["collision_energy_loss"]
        out["stiffness_work"] = self.ledger_cumulative["stiffness_work"]
        out["wall_work"] = self.ledger_cumulative["wall_work"]
        out["external_work"] = self.ledger_cumulative.get("external_work", 0.0)
        out["inserted_energy"] = self.ledger_cumulative["inserted_energy"]
        return out

    def total_energy(self) -> float:
        """Mechanical energy now: kinetic + gravitational + elastic [J]."""
        e = self.energies()
        return (
            e["kinetic_translational"]
            + e["kinetic_rotational"]
            + e["gravitational"]
            + e["elastic_normal"]
            + e["elastic_tangential"]
            + e["elastic_rolling"]
        )

    def energy_balance_error(self) -> float:
        """E(t) + dissipated - stiffness, wall and external work - inserted - E(0) [J]; ~0."""
        e = self.energies()
        dissipated = sum(e[f"dissipated_{k}"] for k in LEDGER_DISSIPATION)
        return (
            self.total_energy()
            + dissipated
            - e["stiffness_work"]
            - e["wall_work"]
            - e["external_work"]
            - e["inserted_energy"]
            - self.initial_energy
        )

    # ------------------------------------------------------------------------ pair access
    def touching_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """Global ids (a, b), a < b, of the touching particle pairs."""
        pb = self.pairs
        mask = pb.state[: pb.count] == C.STATE_TOUCHING
        gid = self.particles.global_id
        return gid[pb.i[: pb.count][mask]], gid[pb.j[: pb.count][mask]]

    def contacts(self) -> dict[str, np.ndarray]:
        """Per-contact arrays of the touching contacts: global ids, contact point, normal,
        overlap, normal force, contact radius and, with heat, each thermal term's conductance
        and heat rate (``thermodem.engine.contacts``)."""
        from thermodem.engine.contacts import contact_data

        self.complete_rates()
        return contact_data(self)

    def coordination_number(self) -> np.ndarray:
        """Touching contacts per particle (particle and wall contacts)."""
        n = self.particles.count
        pb, wb = self.pairs, self.walls
        mask = pb.state[: pb.count] == C.STATE_TOUCHING
        z = np.bincount(pb.i[: pb.count][mask], minlength=n)
        z += np.bincount(pb.j[: pb.count][mask], minlength=n)
        wmask = wb.state[: wb.count] == C.STATE_TOUCHING
        z += np.bincount(wb.i[: wb.count][wmask], minlength=n)
        return z

    def stable_time_steps(self) -> dict[str, float]:
        """Rayleigh and Hertz collision times of the current particles (see engine.checks)."""
        from thermodem.engine.checks import critical_times

        return critical_times(
            self.case, self.particles.radius, self.particles.type_id, self.material_names
        )

    # ------------------------------------------------------------------------------ reports
    def report(self) -> dict[str, float]:
        """One row of the time series: the energy ledger, its balance error, counts and the
        largest overlap ratio, plus the thermal summary when there is a thermal engine.

        ``engine/runner.py`` writes every key as a column of ``timeseries.csv``.
        """
        self.complete_rates()
        out: dict[str, float] = dict(self.energies())
        out["energy_balance_error"] = self.energy_balance_error()
        out["particle_count"] = self.particles.count
        out["contact_count"] = self.contact_count
        out["max_overlap_ratio"] = self.max_overlap_ratio
        if self.thermal is not None:
            out.update(self.thermal.summary())
        return out
