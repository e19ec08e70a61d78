"""The neighbourhood sums of the continuum radiation models with classified border entries
(kernels/neighbourhood.py): listed with a band b, the border entries classified with b / 4
(inside, outside, tested at every step), then the particles moved by less than b / 16 (the
classes' validity): the sums equal the brute-force sums over every sphere, and some entries
are tested (the moving-bed test of tests/verification/test_radiation_continuum.py rarely has
one)."""

from __future__ import annotations

import numpy as np
import pytest

from thermodem.kernels import fields as fk
from thermodem.kernels import neighbourhood as nh


def _listing(position, radius, ratio, band, lower, upper, periodic):
    n = len(radius)
    pair_i, pair_j = (a.astype(np.int32) for a in np.triu_indices(n, 1))
    count = len(pair_i)
    counts = np.zeros(n, np.int64)
    nh.member_counts(position, radius, pair_i, pair_j, count, lower, upper, periodic, ratio,
                     band, counts)  # fmt: skip
    offsets = np.zeros(n + 1, np.int64)
    np.cumsum(counts, out=offsets[1:])
    border = np.zeros(n, np.int64)
    index = np.zeros(int(offsets[-1]), np.int32)
    nh.member_fill(position, radius, pair_i, pair_j, count, lower, upper, periodic, ratio, band,
                   offsets, border, index)  # fmt: skip
    return offsets, border, index


def test_classified_border_entries_give_the_exact_sums() -> None:
    rng = np.random.default_rng(3)
    n, r, ratio = 400, 1.0, 3.0
    side = 12.0
    lower, upper = np.zeros(3), np.full(3, side)
    periodic = np.array([True, False, False])
    position = rng.uniform(0.0, side, (n, 3))
    radius = rng.uniform(0.8, 1.2, n) * r
    temperature = rng.uniform(300.0, 1500.0, n)
    band = 0.4
    offsets, border, index = _listing(position, radius, ratio, band, lower, upper, periodic)
    weight = np.zeros(index.shape[0], np.int8)
    nh.border_classes(position, radius, offsets, border, index, lower, upper, periodic, ratio,
                      band / 4, weight)  # fmt: skip
    size = int((offsets[1:] - border).sum())
    rows, entries, tested_rows, tested_entries = (np.zeros(size, np.int64) for _ in range(4))
    starts = np.zeros(n // nh.CHUNK + 2, np.int64)
    listed, tested = nh.border_lists(offsets, border, weight, rows, entries, starts,
                                     tested_rows, tested_entries)  # fmt: skip
    assert 0 < tested < listed < size
    # every particle moves by less than band / 16: the classes hold
    step = rng.normal(size=(n, 3))
    step *= (0.999 * band / 16) / np.linalg.norm(step, axis=1)[:, None]
    moved = position + step
    emissivity = np.array([0.7])
    type_id = np.zeros(n, np.int32)
    area, emission = np.zeros(n), np.zeros(n)
    nh.neighbourhood_weights(radius, temperature, type_id, emissivity, area, emission)
    member_area, member_count = np.zeros(n), np.zeros(n)
    nh.member_constants(offsets, border, index, area, member_area, member_count)
    fields = np.zeros((fk.NFIELDS, n))
    nh.neighbourhood_sums(moved, radius, temperature, offsets, border, index, weight,
                          rows[:listed], entries[:listed], starts, tested_rows[:tested],
                          tested_entries[:tested], tested, area, emission, member_area,
                          member_count, lower, upper, periodic, ratio,
                          nh.NB_KRAUSE | nh.NB_ZHOU, fields)  # fmt: skip
    d = moved[None, :, :] - moved[:, None, :]
    d[..., 0] -= side * np.floor(d[..., 0] / side + 0.5)
    inside = (d**2).sum(axis=2) < (ratio * radius[:, None]) ** 2
    np.fill_diagonal(inside, False)
    assert np.array_equal(fields[fk.F_NEIGHBOURS], inside.sum(axis=1).astype(float))
    assert fields[fk.F_NEIGHBOUR_TEMPERATURE] == pytest.approx(inside @ temperature, rel=1e-13)
    assert fields[fk.F_NEIGHBOUR_AREA] == pytest.approx(inside @ area, rel=1e-13)
    assert fields[fk.F_NEIGHBOUR_EMISSION] == pytest.approx(inside @ emission, rel=1e-13)
    # some tested entries changed side: the test is not vacuous
    assert np.any(weight[tested_entries[:tested]] == nh.INSIDE)
    assert np.any(weight[tested_entries[:tested]] == nh.OUTSIDE)
