"""Per-contact geometry for output (``engine/contacts.py``): contact points, normals, overlaps
and contact radii of the touching pairs of the contact lists, at output frames only."""

from __future__ import annotations

import math

from numba import prange

from thermodem.kernels.contact import H_DURATION, H_IMPACT_VELOCITY
from thermodem.kernels.neighbors import pair_separation, wall_distance
from thermodem.kernels.variants import parallel_kernel
from thermodem.models.thermal.contact_radius import contact_radius_dispatch


@parallel_kernel(error_model="numpy")
def pair_geometry(
    position, radius, mass, type_id, pair_i, pair_j, rows, normal_force, history, lower, upper,
    periodic, radius_id, radius_table, out_point, out_normal, out_overlap, out_radius,
):  # fmt: skip
    """For the pairs ``rows`` of a particle pair list: the contact point (the middle of the
    overlap on the line of centres), the unit normal from i to j, the overlap and the contact
    radius of model ``radius_id``."""
    length = upper - lower
    for m in prange(rows.shape[0]):
        k = rows[m]
        i = pair_i[k]
        j = pair_j[k]
        dx, dy, dz, dist = pair_separation(position, i, j, length, periodic)
        ri = radius[i]
        rj = radius[j]
        overlap = ri + rj - dist
        nx, ny, nz = dx / dist, dy / dist, dz / dist
        s = ri - 0.5 * overlap
        out_point[m, 0] = position[i, 0] + s * nx
        out_point[m, 1] = position[i, 1] + s * ny
        out_point[m, 2] = position[i, 2] + s * nz
        out_normal[m, 0] = nx
        out_normal[m, 1] = ny
        out_normal[m, 2] = nz
        out_overlap[m] = overlap
        m_eff = mass[i] * mass[j] / (mass[i] + mass[j])
        out_radius[m] = contact_radius_dispatch(
            radius_id, radius_table[type_id[i], type_id[j]], ri, rj, dist, overlap,
            normal_force[k], history[k, H_DURATION], history[k, H_IMPACT_VELOCITY], m_eff,
        )  # fmt: skip


@parallel_kernel(error_model="numpy")
def wall_geometry(
    position, radius, mass, type_id, wall_pair_i, wall_pair_w, rows, normal_force, history,
    wall_kind, wall_rows, wall_material, radius_id, radius_table, out_point, out_normal,
    out_overlap, out_radius,
):  # fmt: skip
    """The same for particle-wall pairs (normal from the particle towards the wall; the
    contact point on the wall surface)."""
    for m in prange(rows.shape[0]):
        k = rows[m]
        i = wall_pair_i[k]
        w = wall_pair_w[k]
        d, wnx, wny, wnz, qx, qy, qz = wall_distance(wall_kind[w], wall_rows[w], position[i])
        ri = radius[i]
        overlap = ri - d
        out_point[m, 0] = qx
        out_point[m, 1] = qy
        out_point[m, 2] = qz
        out_normal[m, 0] = -wnx
        out_normal[m, 1] = -wny
        out_normal[m, 2] = -wnz
        out_overlap[m] = overlap
        out_radius[m] = contact_radius_dispatch(
            radius_id, radius_table[type_id[i], wall_material[w]], ri, math.inf, d, overlap,
            normal_force[k], history[k, H_DURATION], history[k, H_IMPACT_VELOCITY], mass[i],
        )  # fmt: skip
