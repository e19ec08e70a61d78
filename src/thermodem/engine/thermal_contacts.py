"""The contact conduction's heat-only passes of the thermal engine (frozen mechanics, the
start of a run, the heat of a state computed apart from a contact pass): a mixin of
:class:`~thermodem.engine.thermal.ThermalEngine` (the fused contact pass computes the same
heat inside the mechanics, kernels/pair_pass.py).
"""

from __future__ import annotations

from typing import Any

from thermodem.kernels import heat_terms as passes
from thermodem.kernels import thermal as kernels
from thermodem.state import heat


class ContactConduction:
    """Contact conduction by the heat-only passes over the contact lists and wall pairs."""

    sim: Any
    pair_conductance: Any
    mirror_conductance: Any
    wall_conductance: Any

    def _contact_lists(self) -> list[tuple]:
        """The contact lists of the heat-only passes with their conductance arrays: the list
        and, on several MPI ranks, the mirror list (pairs whose particle i is a ghost and j
        owned, mpi/simulation.py), whose heat the owned particle j needs."""
        sim = self.sim
        out = [(sim.pairs, self.pair_conductance)]
        mirror = sim.mirror
        if mirror is not None and mirror.count:
            out.append((mirror, self.mirror_conductance))
        return out

    def conduction_passes(self) -> None:
        """Contact conduction by the heat-only passes (frozen mechanics, start): zeroes the
        mechanism columns and the conductance sums, then adds the contact conduction (on
        several MPI ranks over the list and the mirror list: every owned particle's pairs).

        With frozen mechanics and temperature-independent properties the conductances cannot
        change (same positions, contacts, forces and materials), so after the first pass only
        the heat rates H (T_j - T_i) are recomputed from them (bit-identical, tested).
        """
        sim = self.sim
        p = sim.particles
        by_mech = p.heat_columns
        passes.zero_heat(by_mech, self.conductance_sum)
        if not self.contact.active:
            return
        reuse = self.reuse_conductance and self.settings.frozen_mechanics and self.override == 0
        lists = self._contact_lists()
        if not (reuse and self.conductance_ready):
            pair_pass = kernels.conduction_pair_pass_for(
                self.radius_id, self.conduction_id, self.override
            )
            for buf, conductance in lists:
                pair_pass(
                    p.position, p.radius, p.mass, p.temperature, p.type_id, buf.i, buf.j,
                    buf.count, buf.state, buf.normal_force, buf.history, sim.lower, sim.upper,
                    sim.periodic, self.radius_id, self.radius_table, self.conduction_id,
                    self.conduction_table, self.override, self.k_p, self.rhoc_p, self.scratch,
                    conductance, sim.history_layout.reuse, self.tolerance,
                )  # fmt: skip
            self._wall_conductances()
            self.conductance_ready = reuse
        for buf, conductance in lists:
            passes.pair_heat_from_conductance(
                buf.i, buf.j, buf.group_start, conductance, p.temperature, heat.M_DIRECT,
                by_mech, self.conductance_sum,
            )  # fmt: skip
        self._wall_heat()

    def wall_conduction(self) -> None:
        """The contact conduction of the wall pairs, after the fused contact pass (which
        conducts through the particle pairs only; kernels/pair_pass.py)."""
        self._wall_conductances()
        self._wall_heat()

    def _wall_conductances(self) -> None:
        if not self.walls_conduct:  # adiabatic walls: every wall pair's H stays 0
            return
        sim = self.sim
        p, wb = sim.particles, sim.walls
        kernels.conduction_wall_pass_for(self.radius_id, self.conduction_id, self.override)(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.i, wb.j, wb.count,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, self.radius_id, self.radius_table, self.conduction_id,
            self.conduction_table, self.override, self.k_p, self.rhoc_p, self.k_w, self.rhoc_w,
            self.scratch, self.wall_conductance, sim.history_layout.reuse, self.tolerance,
        )  # fmt: skip

    def _wall_heat(self) -> None:
        if not self.walls_conduct:
            return
        sim = self.sim
        p = sim.particles
        passes.wall_heat_from_conductance(
            sim.walls.j, sim.wall_row_start, sim.wall_rows, self.wall_conductance, p.temperature,
            heat.M_WALL_DIRECT, p.heat_columns, self.conductance_sum,
        )  # fmt: skip
