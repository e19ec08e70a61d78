"""The MPI rebuild's key lookup (kernels/halo.py: fill_key_table, look_up_keys; mpi/rebuild.py:
_positions_of) against a Python dict: random and structured keys (global-id pairs), absent
keys, empty tables and one key."""

from __future__ import annotations

import numpy as np
import pytest

from thermodem.mpi.rebuild import _positions_of


def _reference(keys: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    where = {k: i for i, k in enumerate(keys.tolist())}
    return np.array([where.get(w, -1) for w in wanted.tolist()], np.int64)


@pytest.mark.parametrize("n", [0, 1, 2, 7, 1000, 50000])
def test_random_keys(n):
    rng = np.random.default_rng(n)
    keys = rng.choice(2**62, n, replace=False).astype(np.int64)
    wanted = np.concatenate([rng.permutation(keys), rng.integers(0, 2**62, n + 3)])
    assert np.array_equal(_positions_of(keys, wanted), _reference(keys, wanted))


def test_pair_keys_of_global_ids():
    # gid_i * base + gid_j for neighbouring ids: the keys of a pair list, densely clustered
    gid = np.arange(20000, dtype=np.int64)
    base = 20001
    keys = (gid[:, None] * base + (gid[:, None] + np.arange(1, 7))).ravel()
    wanted = np.concatenate([keys[::-1], keys[:50] + base * 30000])
    got = _positions_of(keys, wanted)
    assert np.array_equal(got, _reference(keys, wanted))
    assert np.all(got[-50:] == -1)
