"""Per-contact data: the touching particle pairs and particle-wall pairs with their geometry,
forces and heat, for ParaView (``output.contacts``) and the Python API (``sim.contacts()``).

One row per touching contact, particle pairs first, then particle-wall pairs:

- ``id_i`` (m,) int64: global id of particle i; ``id_j``: of particle j, -1 for a wall;
  ``wall``: the wall row index of a wall contact, -1 for a particle pair;
- ``point`` (m, 3): the contact point, the middle of the overlap on the line of centres (on
  the wall surface for a wall); ``normal`` (m, 3): the unit normal from i towards j (the wall);
- ``overlap`` δ [m], ``normal_force`` F_n [N] (positive compressive), ``contact_radius`` R_c
  [m] of the thermal contact radius model (geometric without a thermal section);
- ``conductance_<mechanism>`` H [W/K] of each thermal term that conducts through the contact,
  named after its pair column (``direct_conduction``, ``indirect_conduction``; wall contacts
  included), and ``heat_rate_<mechanism>`` = H (T_j − T_i) [W] into i (T_j the wall
  temperature for a wall).

The conductances are evaluated from the state now with the same kernels as the thermal step
(the contact conduction by its heat-only pass, gap terms on these pairs by their own passes),
so they equal what the next thermal step uses. The wall ``conductance_*`` of adiabatic walls
are 0.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import contact_output, heat_terms, range_pass
from thermodem.kernels import thermal as thermal_kernels
from thermodem.kernels.contact import STATE_TOUCHING
from thermodem.models import registry
from thermodem.state import heat

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def contact_data(sim: Simulation) -> dict[str, np.ndarray]:
    """The per-contact arrays of the module docstring for the current state."""
    p = sim.particles
    pb, wb = sim.pairs, sim.walls
    rows = np.nonzero(pb.state[: pb.count] == STATE_TOUCHING)[0].astype(np.int64)
    wrows = np.nonzero(wb.state[: wb.count] == STATE_TOUCHING)[0].astype(np.int64)
    n1, n2 = rows.size, wrows.size
    gid = p.global_id
    th = sim.thermal
    if th is not None:
        radius_id, radius_table = th.radius_id, th.radius_table
    else:
        radius_id = registry.get("contact_radius", "geometric").model_id
        radius_table = np.zeros((len(sim.material_names),) * 2 + (1,))
    point = np.zeros((n1 + n2, 3))
    normal = np.zeros((n1 + n2, 3))
    overlap = np.zeros(n1 + n2)
    radius = np.zeros(n1 + n2)
    contact_output.pair_geometry(
        p.position, p.radius, p.mass, p.type_id, pb.i, pb.j, rows, pb.normal_force, pb.history,
        sim.lower, sim.upper, sim.periodic, radius_id, radius_table, point[:n1], normal[:n1],
        overlap[:n1], radius[:n1],
    )  # fmt: skip
    contact_output.wall_geometry(
        p.position, p.radius, p.mass, p.type_id, wb.i, wb.j, wrows, wb.normal_force, wb.history,
        sim.wall_kind, sim.wall_rows, sim.wall_material, radius_id, radius_table, point[n1:],
        normal[n1:], overlap[n1:], radius[n1:],
    )  # fmt: skip
    out = {
        "id_i": np.concatenate([gid[pb.i[rows]], gid[wb.i[wrows]]]).astype(np.int64),
        "id_j": np.concatenate([gid[pb.j[rows]], np.full(n2, -1)]).astype(np.int64),
        "wall": np.concatenate([np.full(n1, -1), wb.j[wrows]]).astype(np.int64),
        "point": point,
        "normal": normal,
        "overlap": overlap,
        "normal_force": np.concatenate([pb.normal_force[rows], wb.normal_force[wrows]]),
        "contact_radius": radius,
    }
    if th is not None:
        out.update(_heat(sim, rows, wrows))
    return out


def _heat(sim: Simulation, rows: np.ndarray, wrows: np.ndarray) -> dict[str, np.ndarray]:
    """Conductance and heat rate into i of every thermal term on the contacts."""
    th = sim.thermal
    p = sim.particles
    pb, wb = sim.pairs, sim.walls
    th.prepare(sim.time)
    t_i = np.concatenate([p.temperature[pb.i[rows]], p.temperature[wb.i[wrows]]])
    t_j = np.concatenate(
        [p.temperature[pb.j[rows]], sim.wall_rows[wb.j[wrows], wall_cols.COL_TEMPERATURE]]
    )
    out: dict[str, np.ndarray] = {}

    def add(column: int, pair_h: np.ndarray, wall_h: np.ndarray) -> None:
        h = np.concatenate([pair_h[rows], wall_h[wrows]])
        name = heat.HEAT_MECHANISMS[column]
        if f"conductance_{name}" in out:
            out[f"conductance_{name}"] += h
        else:
            out[f"conductance_{name}"] = h
        out[f"heat_rate_{name}"] = out[f"conductance_{name}"] * (t_j - t_i)

    if th.contact.active:
        pair_h = np.zeros(max(pb.count, 1))
        wall_h = np.zeros(max(wb.count, 1))
        thermal_kernels.conduction_pair_pass_for(th.radius_id, th.conduction_id, th.override)(
            p.position, p.radius, p.mass, p.temperature, p.type_id, pb.i, pb.j, pb.count,
            pb.state, pb.normal_force, pb.history, sim.lower, sim.upper, sim.periodic,
            th.radius_id, th.radius_table, th.conduction_id, th.conduction_table, th.override,
            th.k_p, th.rhoc_p, th.scratch, pair_h, -1, 0.0,
        )  # fmt: skip
        thermal_kernels.conduction_wall_pass_for(th.radius_id, th.conduction_id, th.override)(
            p.position, p.radius, p.mass, p.temperature, p.type_id, wb.i, wb.j, wb.count,
            wb.state, wb.normal_force, wb.history, sim.wall_kind, sim.wall_rows,
            sim.wall_material, th.radius_id, th.radius_table, th.conduction_id,
            th.conduction_table, th.override, th.k_p, th.rhoc_p, th.k_w, th.rhoc_w, th.scratch,
            wall_h, -1, 0.0,
        )  # fmt: skip
        add(heat.M_DIRECT, pair_h, wall_h)  # wall contacts too: the `wall` key tells them
    # the other pair terms, evaluated on the contact pairs (side effects into scratch sums)
    by_mech = np.zeros_like(p.heat_columns)  # (scratch: the kernels take a row per mechanism)
    sums = np.zeros(p.count)
    rows_needed = max(pb.ngroups, p.count // heat_terms.WALL_CHUNK + 1)
    for term in th.terms:
        if term.target not in ("range", "contacts"):
            continue
        pair_h = np.zeros(max(pb.count, 1))
        wall_h = np.zeros(max(wb.count, 1))
        k_i, k_j = term.k_columns if th.override else (-1, -1)
        scratch = th._term_rows(rows_needed)
        if term.target == "range":
            range_pair_pass, range_wall_pass = range_pass.range_passes_for(
                term.evaluator, term.model_id, term.needs_contact_radius, k_i >= 0,
                term.table.shape[2],
            )  # fmt: skip
            chunked = range_pass.runs_in_chunks(term.evaluator, term.model_id)
            groups = pb.group_start.shape[0] - 1
            geometry, cols = range_pass.chunk_buffers(
                th.range_chunks, groups, term.table.shape[2], chunked
            )
            range_pair_pass(
                p.position, p.radius, p.temperature, p.type_id, pb.i, pb.j, pb.group_start,
                sim.lower, sim.upper, sim.periodic, term.evaluator, term.model_id, term.table,
                k_i, k_j, th.k_p, scratch, term.column, by_mech, sums, True, pair_h,
                term.needs_contact_radius, geometry, cols,
            )  # fmt: skip
            range_wall_pass(
                p.position, p.radius, p.temperature, p.type_id, wb.j, sim.wall_row_start,
                sim.wall_kind, sim.wall_rows, sim.wall_material, term.evaluator, term.model_id,
                term.table, k_i, k_j, th.k_p, th.k_w, scratch, term.wall_column, by_mech, sums,
                True, wall_h, term.needs_contact_radius,
            )  # fmt: skip
        else:
            heat_terms.contact_term_pair_pass(
                p.position, p.radius, p.mass, p.temperature, p.type_id, pb.i, pb.j,
                pb.group_start, pb.state, pb.normal_force, pb.history, sim.lower, sim.upper,
                sim.periodic, th.radius_id, th.radius_table, term.evaluator, term.model_id,
                term.table, k_i, k_j, th.k_p, scratch, term.column, by_mech, sums, True,
                pair_h,
            )  # fmt: skip
            heat_terms.contact_term_wall_pass(
                p.position, p.radius, p.mass, p.temperature, p.type_id, wb.j,
                sim.wall_row_start, wb.state, wb.normal_force, wb.history, sim.wall_kind,
                sim.wall_rows, sim.wall_material, th.radius_id, th.radius_table,
                term.evaluator, term.model_id, term.table, k_i, k_j, th.k_p, th.k_w, scratch,
                term.wall_column, by_mech, sums, True, wall_h,
            )  # fmt: skip
        add(term.column, pair_h, wall_h)
    return out
