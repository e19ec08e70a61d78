"""Packing of the ghost halo of an MPI run (``thermodem.mpi.exchange``).

Every step the owners send the moving state of the particles other ranks hold as ghosts:
position, velocity, angular velocity (9 float64) and, with a thermal engine, the temperature
(1 more). :func:`pack_moving` gathers the rows of a send list into a contiguous buffer (the
mpi4py buffer API sends it as is), :func:`unpack_moving` scatters a received buffer into the
ghost slots. Serial loops: a halo is a few percent of the particles, and the copy is memory
bound.
"""

from __future__ import annotations

import numpy as np
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


@njit(cache=True, error_model="numpy")
def rows_with_history(history, pair_i, count, selected, out):
    """The rows k < ``count`` whose history has a non-zero value and whose particle
    ``pair_i[k]`` is ``selected``, into ``out``; returns how many (one pass: numpy's
    ``any(history != 0, axis=1)`` made a temporary of the whole history)."""
    m = 0
    for k in range(count):
        if not selected[pair_i[k]]:
            continue
        for c in range(history.shape[1]):
            if history[k, c] != 0.0:
                out[m] = k
                m += 1
                break
    return m


@njit(cache=True, error_model="numpy")
def key_positions(keys, wanted, table, out):
    """``out[q]``: the index k with ``keys[k] == wanted[q]``, -1 when absent (keys unique and
    non-negative). An open-addressing hash table (``table``: int64, a power of two >= 2 and
    at least twice len(keys), scratch) with Fibonacci hashing and linear probing: O(n) against a
    sort and binary searches (the MPI rebuild matches the history records of every listed
    pair by the key of its two global ids; 10^5-10^6 keys)."""
    size = table.shape[0]
    bits = 0
    while (1 << bits) < size:
        bits += 1
    shift = np.uint64(64 - bits)
    mask = np.int64(size - 1)
    golden = np.uint64(0x9E3779B97F4A7C15)
    for s in range(size):
        table[s] = -1
    for k in range(keys.shape[0]):
        s = np.int64((np.uint64(keys[k]) * golden) >> shift)
        while table[s] >= 0:
            s = (s + 1) & mask
        table[s] = k
    for q in range(wanted.shape[0]):
        key = wanted[q]
        s = np.int64((np.uint64(key) * golden) >> shift)
        found = -1
        while table[s] >= 0:
            if keys[table[s]] == key:
                found = table[s]
                break
            s = (s + 1) & mask
        out[q] = found
