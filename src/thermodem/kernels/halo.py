"""Packing of the ghost halo of an MPI run (``thermodem.mpi.exchange``).

Every step the owners send the moving state of the particles other ranks hold as ghosts:
position, velocity, angular velocity (9 float64) and, with a thermal engine, the temperature
(1 more). :func:`pack_moving` gathers the rows of a send list into a contiguous buffer (the
mpi4py buffer API sends it as is), :func:`unpack_moving` scatters a received buffer into the
ghost slots. Serial loops: a halo is a few percent of the particles, and the copy is memory
bound.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy")
def pack_moving(position, velocity, angular_velocity, temperature, with_temperature, index, out):
    """Rows ``index`` of the moving state into ``out`` (len(index), 9 or 10)."""
    for k in range(index.shape[0]):
        i = index[k]
        for a in range(3):
            out[k, a] = position[i, a]
            out[k, 3 + a] = velocity[i, a]
            out[k, 6 + a] = angular_velocity[i, a]
        if with_temperature:
            out[k, 9] = temperature[i]


@njit(cache=True, error_model="numpy")
def unpack_moving(
    buffer, index, position, velocity, angular_velocity, temperature, with_temperature
):
    """The rows of ``buffer`` into the particles ``index`` (the inverse of pack_moving)."""
    for k in range(index.shape[0]):
        i = index[k]
        for a in range(3):
            position[i, a] = buffer[k, a]
            velocity[i, a] = buffer[k, 3 + a]
            angular_velocity[i, a] = buffer[k, 6 + a]
        if with_temperature:
            temperature[i] = buffer[k, 9]
