"""Per-particle fields read by the per-particle heat terms (convection, radiation).

The thermal engine holds one array ``fields`` of shape (NFIELDS, n): a row per field (a
contiguous array over the particles), defined here, once, and filled by the providers of
``engine/fields.py`` at every thermal step before the per-particle terms run. A model kernel
reads ``fields[F_..., i]``. A pass that fills one field writes one contiguous row (with a
row per particle, (n, NFIELDS), it wrote one value in every 128-byte row: on the 50k bed the
relative speed pass took 0.66 ms and the cell porosity 1.19 ms per step inside a run, busy
machine). Rows a case does not need stay zero (a zero wall view factor, for example, means
"no wall in view"). The constants below name the rows ("columns" in the names of the
helpers, as before).

Kernels of this module (all compiled, no Python loops over particles; every particle writes
only its own row, or a pair pass adds by slab groups, so the results do not depend on the
thread count):

- :func:`fill_column`, :func:`zero_columns`: constant columns;
- :func:`table_column`: a property table of temperature at the fluid or particle temperature;
- :func:`grid_sample`: trilinear interpolation of a rectilinear grid field at the particles;
- :func:`relative_speed`: |u_f - v_p|;
- :func:`wall_view`: view factors and Σ F T_w⁴ of the fixed-temperature walls in view.

The porosity kernels (by a cell count, in a shell) are in ``kernels/porosity.py``; the sums
over the sphere of radiative influence of the continuum radiation models in
``kernels/neighbourhood.py``.
"""

from __future__ import annotations

import math

from numba import njit, prange

from thermodem.geometry.wall_layout import COL_TEMPERATURE, COL_THERMAL_KIND
from thermodem.kernels.neighbors import wall_distance
from thermodem.kernels.variants import parallel_kernel

#: Columns of the per-particle field array (the engine's ``fields``).
F_POROSITY = 0  # local porosity ε [-]
F_FLUID_TEMPERATURE = 1  # T_f at the particle [K]
F_RELATIVE_SPEED = 2  # |u_f - v_p| [m/s]
F_FLUID_CONDUCTIVITY = 3  # k_f at T_f [W/(m K)]
F_FLUID_DENSITY = 4  # ρ_f at T_f [kg/m³]
F_FLUID_SPECIFIC_HEAT = 5  # c_f at T_f [J/(kg K)]
F_FLUID_VISCOSITY = 6  # μ_f at T_f [Pa s]
F_SURFACE_VISCOSITY = 7  # μ_fs at the particle (surface) temperature [Pa s]
F_PRANDTL = 8  # Pr = c_f μ_f / k_f [-]
F_PRANDTL_CBRT = 9  # Pr^(1/3) [-]
F_NEIGHBOURS = 10  # n_p: particles whose centre lies in the sphere of radiative influence
F_NEIGHBOUR_TEMPERATURE = 11  # Σ_j T_j over them [K]
F_NEIGHBOUR_EMISSION = 12  # Σ_j ε_j A_j T_j⁴ / 2 over them [m² K⁴]
F_NEIGHBOUR_AREA = 13  # Σ_j ε_j A_j / 2 over them [m²]
F_WALL_VIEW = 14  # Σ_w F_iw over the fixed-temperature walls in view [-]
F_WALL_EMISSION = 15  # Σ_w F_iw T_w⁴ [K⁴]
#: Scratch rows of the per-particle pass (``kernels/heat_terms.py: particle_pass``): a
#: term's heat rate and conductance of each particle before they are added to the
#: particle's sums. Written and read by that pass only (no provider fills them; their
#: values between steps mean nothing).
F_SCRATCH_HEAT = 16
F_SCRATCH_CONDUCTANCE = 17
NFIELDS = 18

FIELD_NAMES: tuple[str, ...] = (
    "porosity",
    "fluid_temperature",
    "relative_speed",
    "fluid_conductivity",
    "fluid_density",
    "fluid_specific_heat",
    "fluid_viscosity",
    "surface_viscosity",
    "prandtl",
    "prandtl_cbrt",
    "neighbour_count",
    "neighbour_temperature_sum",
    "neighbour_emission",
    "neighbour_emissive_area",
    "wall_view_factor",
    "wall_emission",
    "scratch_heat_rate",
    "scratch_conductance",
)

CHUNK = 4096  # particles per chunk of the parallel passes


@parallel_kernel(error_model="numpy")
def fill_column(fields, column, value):
    """fields[column, :] = value."""
    n = fields.shape[1]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            fields[column, i] = value


@parallel_kernel(error_model="numpy")
def zero_columns(fields, first, last):
    """fields[first:last, :] = 0."""
    n = fields.shape[1]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            for k in range(first, last):
                fields[k, i] = 0.0


@njit(cache=True, inline="always", error_model="numpy")
def interp_held(x, nodes, values):
    """Linear interpolation in a table, held at the first / last value outside it."""
    m = nodes.shape[0]
    if m == 1 or x <= nodes[0]:
        return values[0]
    if x >= nodes[m - 1]:
        return values[m - 1]
    lo = 0
    hi = m - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if nodes[mid] <= x:
            lo = mid
        else:
            hi = mid
    w = (x - nodes[lo]) / (nodes[hi] - nodes[lo])
    return values[lo] + w * (values[hi] - values[lo])


@parallel_kernel(error_model="numpy")
def table_column(fields, column, nodes, values, at_particle, temperature):
    """fields[column, :] = table(T) with T the fluid temperature at the particle
    (``at_particle`` False) or the particle's temperature (True)."""
    n = fields.shape[1]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            t = temperature[i] if at_particle else fields[F_FLUID_TEMPERATURE, i]
            fields[column, i] = interp_held(t, nodes, values)


@parallel_kernel(error_model="numpy")
def prandtl_columns(fields):
    """Pr = c_f μ_f / k_f and Pr^(1/3) from the property rows."""
    n = fields.shape[1]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            pr = (
                fields[F_FLUID_SPECIFIC_HEAT, i]
                * fields[F_FLUID_VISCOSITY, i]
                / fields[F_FLUID_CONDUCTIVITY, i]
            )
            fields[F_PRANDTL, i] = pr
            fields[F_PRANDTL_CBRT, i] = pr ** (1.0 / 3.0)


@njit(cache=True, inline="always", error_model="numpy")
def _bracket(axis, x):
    """(k, w): axis[k] <= x <= axis[k + 1] with weight w of axis[k + 1], clamped to the ends
    (w = 0 or 1 outside), and whether x was outside."""
    m = axis.shape[0]
    if m == 1:
        return 0, 0.0, x != axis[0]
    if x <= axis[0]:
        return 0, 0.0, x < axis[0]
    if x >= axis[m - 1]:
        return m - 2, 1.0, x > axis[m - 1]
    lo = 0
    hi = m - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if axis[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo, (x - axis[lo]) / (axis[hi] - axis[lo]), False


@parallel_kernel(error_model="numpy")
def grid_sample(position, axis_x, axis_y, axis_z, values, out, first, part):
    """Trilinear interpolation of ``values`` (nx, ny, nz, nc) on the rectilinear grid of the
    three axes at every particle into ``out[first:first + nc, i]``; a position outside the
    grid takes the value at the nearest point of the grid's boundary (held). Returns the number
    of particles outside (``part``: a scratch value per chunk)."""
    n = position.shape[0]
    nc = values.shape[3]
    nchunks = (n + CHUNK - 1) // CHUNK
    one_x = axis_x.shape[0] == 1
    one_y = axis_y.shape[0] == 1
    one_z = axis_z.shape[0] == 1
    for c in prange(nchunks):
        outside = 0
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            kx, wx, ox = _bracket(axis_x, position[i, 0])
            ky, wy, oy = _bracket(axis_y, position[i, 1])
            kz, wz, oz = _bracket(axis_z, position[i, 2])
            if ox or oy or oz:
                outside += 1
            kx1 = kx if one_x else kx + 1
            ky1 = ky if one_y else ky + 1
            kz1 = kz if one_z else kz + 1
            for q in range(nc):
                c00 = values[kx, ky, kz, q] * (1.0 - wx) + values[kx1, ky, kz, q] * wx
                c10 = values[kx, ky1, kz, q] * (1.0 - wx) + values[kx1, ky1, kz, q] * wx
                c01 = values[kx, ky, kz1, q] * (1.0 - wx) + values[kx1, ky, kz1, q] * wx
                c11 = values[kx, ky1, kz1, q] * (1.0 - wx) + values[kx1, ky1, kz1, q] * wx
                c0 = c00 * (1.0 - wy) + c10 * wy
                c1 = c01 * (1.0 - wy) + c11 * wy
                out[first + q, i] = c0 * (1.0 - wz) + c1 * wz
        part[c] = outside
    total = 0
    for c in range(nchunks):
        total += int(part[c])
    return total


@parallel_kernel(error_model="numpy")
def relative_speed(velocity, fluid_velocity, uniform, fields):
    """fields[F_RELATIVE_SPEED, :] = |u_f - v_p| (``fluid_velocity``: (3, n), or (3, 1) with
    ``uniform``)."""
    n = velocity.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            k = 0 if uniform else i
            dx = fluid_velocity[0, k] - velocity[i, 0]
            dy = fluid_velocity[1, k] - velocity[i, 1]
            dz = fluid_velocity[2, k] - velocity[i, 2]
            fields[F_RELATIVE_SPEED, i] = math.sqrt(dx * dx + dy * dy + dz * dz)


@parallel_kernel(error_model="numpy")
def wall_view(position, radius, wall_kind, wall_rows, range_ratio, view_factor, fields):
    """For every particle, the fixed-temperature walls whose surface gap is below
    range_ratio × R_i: Σ F_iw (each wall ``view_factor``) into F_WALL_VIEW and Σ F_iw T_w⁴
    into F_WALL_EMISSION; a sum above 1 (a corner) is scaled down to 1 with the emission."""
    n = position.shape[0]
    nw = wall_kind.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            ri = radius[i]
            view = 0.0
            emission = 0.0
            for w in range(nw):
                row = wall_rows[w]
                if row[COL_THERMAL_KIND] == 0.0:
                    continue
                d = wall_distance(wall_kind[w], row, position[i])[0]
                if d - ri < range_ratio * ri:
                    tw = row[COL_TEMPERATURE]
                    view += view_factor
                    emission += view_factor * (tw * tw) * (tw * tw)
            if view > 1.0:
                emission /= view
                view = 1.0
            fields[F_WALL_VIEW, i] = view
            fields[F_WALL_EMISSION, i] = emission
