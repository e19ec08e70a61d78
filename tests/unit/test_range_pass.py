"""The range pair pass (kernels/range_pass.py), in chunks (gather, conductance and scatter
loops) and fused, against a plain loop in pair order over the same pairs with the kernel
called pair by pair (heat_terms.term_conductance): the same conductances, heat rates and
conductance sums bit for bit, with one parameter row for all pairs, with several rows, and
with the k(T) override replacing row columns; 1 and 2 threads."""

from __future__ import annotations

import numpy as np
import pytest

from thermodem.engine.threads import apply_threads
from thermodem.kernels.heat_terms import EVAL_INDIRECT, term_conductance
from thermodem.kernels.range_pass import CHUNK, _compile_range_passes, range_passes_for
from thermodem.models import registry
from thermodem.state.gas import GasProperties
from thermodem.state.materials import Material, resolve_pair

GAS = GasProperties(thermal_conductivity=0.03)


def _material(k: float) -> Material:
    return Material(density=2500.0, youngs_modulus=1e8, poisson_ratio=0.25,
                    specific_heat=800.0, thermal_conductivity=k)  # fmt: skip


def _table(model: str, conductivities: list[float], params: list[dict]) -> np.ndarray:
    """(types, types, width) rows of ``model``; type a's row parameters ``params[a]``."""
    spec = registry.get("indirect_conduction", model)
    mats = [_material(k) for k in conductivities]
    rows = [
        [spec.pack(spec.params(**params[max(a, b)]), resolve_pair(ma, mb, gas=GAS))
         for b, mb in enumerate(mats)]
        for a, ma in enumerate(mats)
    ]  # fmt: skip
    return np.array(rows, dtype=np.float64)


def _bed(n: int, seed: int) -> tuple[np.ndarray, ...]:
    """Spheres of 0.8-1.2 mm on a jittered lattice (touching, overlapping and separated
    pairs) and every pair with a surface gap below 0.6 mm, in a random order of pairs
    (the pass must not assume more than the list gives)."""
    rng = np.random.default_rng(seed)
    side = round(n ** (1 / 3)) + 1
    grid = np.stack(np.meshgrid(*[np.arange(side)] * 3, indexing="ij"), -1).reshape(-1, 3)
    position = (grid[:n] * 2.05e-3 + rng.uniform(-1.5e-4, 1.5e-4, (n, 3))).astype(np.float64)
    radius = rng.uniform(0.8e-3, 1.2e-3, n)
    i, j = np.triu_indices(n, 1)
    gap = np.linalg.norm(position[j] - position[i], axis=1) - radius[i] - radius[j]
    keep = np.nonzero(gap < 6e-4)[0]
    keep = keep[rng.permutation(keep.shape[0])]
    swap = rng.random(keep.shape[0]) < 0.5
    pi = np.where(swap, j[keep], i[keep]).astype(np.int32)
    pj = np.where(swap, i[keep], j[keep]).astype(np.int32)
    temperature = rng.uniform(280.0, 420.0, n)
    type_id = rng.integers(0, 2, n).astype(np.int32)
    return position, radius, temperature, type_id, pi, pj


def _reference(model_id, position, radius, temperature, type_id, pi, pj, table, k_cols,  # noqa: ANN001, ANN202
               k_particle):  # fmt: skip
    n = radius.shape[0]
    heat = np.zeros(n)
    sums = np.zeros(n)
    hs = np.zeros(pi.shape[0])
    for k in range(pi.shape[0]):
        i, j = int(pi[k]), int(pj[k])
        dist = float(np.sqrt(np.sum((position[j] - position[i]) ** 2)))
        row = table[type_id[i], type_id[j]].copy()
        if k_cols[0] >= 0:
            row[k_cols[0]], row[k_cols[1]] = k_particle[i], k_particle[j]
        h = term_conductance(EVAL_INDIRECT, model_id, row, radius[i], radius[j], dist, 0.0, 0.0)
        hs[k] = h
        q = h * (temperature[j] - temperature[i])
        heat[i] += q
        heat[j] -= q
        sums[i] += h
        sums[j] += h
    return heat, sums, hs


CASES = {
    "rong_one_row": ("rong_horio1999", [1.0, 1.0], [{"layer_thickness_ratio": 0.5}] * 2),
    "rong_two_rows": ("rong_horio1999", [1.0, 1.0],
                      [{"layer_thickness_ratio": 0.5},
                       {"layer_thickness_ratio": 0.3, "contact_term": True}]),
    "bob_override": ("batchelor_obrien_separated", [2.0, 5.0], [{}, {}]),
}  # fmt: skip


_PASSES: dict[tuple, object] = {}


def _chunked(model: str, width: int) -> bool:
    """Whether the range pair pass of ``model`` runs in chunks (its CHUNKED constant)."""
    f = range_passes_for(EVAL_INDIRECT, registry.get("indirect_conduction", model).model_id,
                         False, False, width)[0].py_func  # fmt: skip
    return f.__closure__[f.__code__.co_freevars.index("CHUNKED")].cell_contents


def test_rong_horio_runs_in_chunks_the_others_fused() -> None:
    assert _chunked("rong_horio1999", 4)
    assert not _chunked("musser2011", 3)
    assert not _chunked("batchelor_obrien_separated", 6)


@pytest.mark.parametrize(
    ("case", "chunked", "threads"),
    [(case, chunked, 1) for case in CASES for chunked in (False, True)]
    + [("rong_two_rows", True, 2), ("bob_override", True, 2)],
)
def test_range_pass_equals_the_kernel_pair_by_pair(case: str, chunked: bool, threads: int) -> None:
    model, conductivities, params = CASES[case]
    spec = registry.get("indirect_conduction", model)
    table = _table(model, conductivities, params)
    cols = spec.columns or ()
    override = "k_i" in cols
    k_cols = (cols.index("k_i"), cols.index("k_j")) if override else (-1, -1)
    position, radius, temperature, type_id, pi, pj = _bed(400, 7)
    assert pi.shape[0] > 3 * CHUNK  # several chunks, the last one partial
    k_particle = np.random.default_rng(3).uniform(1.0, 9.0, radius.shape[0])
    group_start = np.array([0, pi.shape[0] // 3, pi.shape[0]], np.int64)
    heat = np.zeros((3, radius.shape[0]))
    sums = np.zeros(radius.shape[0])
    out = np.zeros(pi.shape[0])
    key = (EVAL_INDIRECT, spec.model_id, False, override, table.shape[2], chunked)
    if key not in _PASSES:
        _PASSES[key] = _compile_range_passes(*key)[0]
    pair_pass = _PASSES[key]
    apply_threads(threads)
    try:
        pair_pass(
            position, radius, temperature, type_id, pi, pj, group_start, np.zeros(3),
            np.ones(3), np.zeros(3, np.bool_), EVAL_INDIRECT, spec.model_id, table, k_cols[0],
            k_cols[1], k_particle, np.zeros((2, table.shape[2])), 1, heat, sums, True, out,
            False, np.full((2, 4, CHUNK), np.nan), np.full((2, table.shape[2], CHUNK), np.nan),
        )  # fmt: skip
    finally:
        apply_threads(1)
    # the reference in the pass's order: group 0, then group 1 (odd groups after even ones)
    ref_heat, ref_sums, ref_h = _reference(spec.model_id, position, radius, temperature,
                                           type_id, pi, pj, table, k_cols, k_particle)  # fmt: skip
    assert np.count_nonzero(ref_h) > pi.shape[0] // 4
    assert np.array_equal(out, ref_h)
    assert np.array_equal(heat[1], ref_heat)
    assert np.array_equal(sums, ref_sums)
    assert not heat[0].any() and not heat[2].any()
