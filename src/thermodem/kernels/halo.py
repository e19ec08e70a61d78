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


@njit(cache=True, error_model="numpy", inline="always")
def _slot(key, shift):
    return np.int64((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> shift)


@njit(cache=True, error_model="numpy", inline="always")
def _shift(size):
    bits = 0
    while (1 << bits) < size:
        bits += 1
    return np.uint64(64 - bits)


@njit(cache=True, error_model="numpy")
def fill_key_table(keys, table):
    """An open-addressing hash table of ``keys`` (unique, non-negative; ``table``: int64, a
    power of two >= 2 and at least twice len(keys)) with Fibonacci hashing and linear probing,
    built once and looked up by :func:`look_up_keys` as often as needed: O(n) against a sort
    and binary searches (the MPI rebuild matches the history records of every listed pair by
    the key of its two global ids; 10^5-10^6 keys)."""
    size = table.shape[0]
    shift = _shift(size)
    mask = np.int64(size - 1)
    for s in range(size):
        table[s] = -1
    for k in range(keys.shape[0]):
        s = _slot(keys[k], shift)
        while table[s] >= 0:
            s = (s + 1) & mask
        table[s] = k


@njit(cache=True, error_model="numpy")
def look_up_keys(keys, table, wanted, out):
    """``out[q]``: the index of ``wanted[q]`` in ``keys`` through their table, or -1."""
    size = table.shape[0]
    shift = _shift(size)
    mask = np.int64(size - 1)
    for q in range(wanted.shape[0]):
        key = wanted[q]
        s = _slot(key, shift)
        found = -1
        while table[s] >= 0:
            if keys[table[s]] == key:
                found = table[s]
                break
            s = (s + 1) & mask
        out[q] = found


@njit(cache=True, error_model="numpy")
def history_records(history, pair_i, pair_j, count, selected, global_id, wall, rows, owner):
    """The history records of the rows k < ``count`` whose history has a non-zero value and
    whose particle ``pair_i[k]`` is ``selected``, in one pass (numpy's ``any(history != 0,
    axis=1)`` and fancy indexing made temporaries of the whole history): ``rows[m] = [gid_i,
    gid_j (the wall index for a wall pair), history...]`` and ``owner[m] = pair_i[k]``;
    returns how many (``rows`` and ``owner``: at least ``count`` rows, scratch beyond)."""
    width = history.shape[1]
    m = 0
    for k in range(count):
        i = pair_i[k]
        if not selected[i]:
            continue
        touched = False
        for c in range(width):
            if history[k, c] != 0.0:
                touched = True
                break
        if not touched:
            continue
        rows[m, 0] = global_id[i]
        rows[m, 1] = pair_j[k] if wall else global_id[pair_j[k]]
        for c in range(width):
            rows[m, 2 + c] = history[k, c]
        owner[m] = i
        m += 1
    return m


@njit(cache=True, error_model="numpy")
def record_keys(records, base, out):
    """``out[m]``: the key gid_i × ``base`` + other of record ``m`` (its first two columns)."""
    for m in range(records.shape[0]):
        out[m] = np.int64(records[m, 0]) * base + np.int64(records[m, 1])


@njit(cache=True, error_model="numpy")
def pair_keys(global_id, pair_i, pair_j, count, base, out):
    """``out[k]``: the key gid(pair_i[k]) × ``base`` + gid(pair_j[k]) of listed pair k."""
    for k in range(count):
        out[k] = np.int64(global_id[pair_i[k]]) * base + np.int64(global_id[pair_j[k]])


@njit(cache=True, error_model="numpy")
def history_from_records(history, count, found, records):
    """History row k < ``count`` from record ``found[k]`` (its columns after the two ids), or
    zero where ``found[k]`` is -1 (a new pair)."""
    width = history.shape[1]
    for k in range(count):
        f = found[k]
        if f >= 0:
            for c in range(width):
                history[k, c] = records[f, 2 + c]
        else:
            for c in range(width):
                history[k, c] = 0.0


@njit(cache=True, error_model="numpy")
def owner_ranks(position, axis, cut, left, right, out):
    """``out[i]``: the rank whose box holds position i, by descending the bisection tree
    (node k cuts ``axis[k]`` at ``cut[k]``; a position on the cut goes right; a child < 0 is
    the leaf of rank -child - 1). One pass, no temporaries (the NumPy descent made a few
    arrays of the particle count per tree level: ~5 % of a 2-rank rebuild)."""
    for i in range(position.shape[0]):
        k = 0
        while True:
            child = right[k] if position[i, axis[k]] >= cut[k] else left[k]
            if child < 0:
                out[i] = -child - 1
                break
            k = child


@njit(cache=True, error_model="numpy")
def near_box(position, lower, upper, length, periodic, width, out):
    """``out[:m]``: the indices of the positions closer than ``width`` to the box
    [lower, upper] (periodic images on periodic axes), in order; returns m. The distance is
    formed as decomposition.point_box_distance forms it (same operations, same order)."""
    m = 0
    for i in range(position.shape[0]):
        d2 = 0.0
        for a in range(3):
            x = position[i, a]
            gap = max(max(lower[a] - x, x - upper[a]), 0.0)
            if periodic[a]:
                for s in (-length[a], length[a]):
                    xs = x + s
                    gap = min(gap, max(max(lower[a] - xs, xs - upper[a]), 0.0))
            d2 += gap * gap
        if np.sqrt(d2) < width:
            out[m] = i
            m += 1
    return m
