"""The external pair set (engine/external_set.py): pairs by global id with per-pair inputs,
kept through the particle reorders of neighbour rebuilds, summed through a CSR index.

A gap-conduction term moved onto an external set holding the brute-force list of pairs must
give the range set's heat rates (to round-off: the summation order differs), and later, with
the particles reordered by rebuilds, an O(N²) sum over the same pairs; a restart from a
checkpoint continues bit-identically.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from thermodem.config.load import case_from_dict
from thermodem.engine.external_set import ExternalPairSet
from thermodem.engine.simulation import Simulation
from thermodem.geometry.insertion import InsertedParticles, save_particle_file
from thermodem.io.checkpoint import write_checkpoint
from thermodem.models.thermal.direct_conduction import separated_conductance
from thermodem.state import heat

GLASS = {
    "density": 2500.0,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "restitution": 0.5,
    "thermal_conductivity": 1.0,
    "specific_heat": 800.0,
}
KEY = "thermal.direct_conduction"


def _case(tmp_path: Path) -> dict:
    rng = np.random.default_rng(11)
    n, box = 120, 0.008
    pos: list[np.ndarray] = []
    rad: list[float] = []
    while len(pos) < n:
        r = rng.uniform(4e-4, 6e-4)
        x = rng.uniform(r, box - r, 3)
        if all(np.linalg.norm(x - y) > r + s + 5e-5 for y, s in zip(pos, rad, strict=True)):
            pos.append(x)
            rad.append(r)
    path = tmp_path / "bed.txt"
    vel = rng.normal(0.0, 0.3, (n, 3))
    temp = rng.uniform(300.0, 500.0, n)
    save_particle_file(path, InsertedParticles(np.array(pos), np.array(rad), vel, temp, "glass"))
    return {
        "simulation": {"time_step": 2e-6, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [box, box, box]},
        "materials": {"glass": dict(GLASS)},
        "walls": [{"kind": "box", "lower": [0, 0, 0], "upper": [box] * 3, "material": "glass"}],
        "neighbors": {"skin": 5e-5},
        "insertion": [{"kind": "file", "material": "glass", "path": str(path)}],
        "thermal": {"direct_conduction": {"model": "batchelor_obrien_complete"}},
    }


def _all_pairs(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    """Global ids of every pair within 2 × the conducting gap (brute force)."""
    p = sim.particles
    d = np.linalg.norm(p.position[:, None] - p.position[None], axis=-1)
    gap = d - p.radius[:, None] - p.radius[None]
    a, b = np.nonzero(np.triu(gap < 2 * 0.5 * 6e-4, 1))
    return p.global_id[a], p.global_id[b]


def _expected(sim: Simulation, gid_i: np.ndarray, gid_j: np.ndarray) -> np.ndarray:
    p = sim.particles
    term = sim.thermal.terms[0]
    where = np.argsort(p.global_id)
    q = np.zeros(p.count)
    for a, b in zip(where[gid_i], where[gid_j], strict=True):
        d = float(np.linalg.norm(p.position[b] - p.position[a]))
        row = term.table[p.type_id[a], p.type_id[b]]
        h = separated_conductance(term.model_id, row, p.radius[a], p.radius[b], d)
        q[a] += h * (p.temperature[b] - p.temperature[a])
        q[b] -= h * (p.temperature[b] - p.temperature[a])
    return q


def _external(tmp_path: Path) -> tuple[Simulation, ExternalPairSet]:
    sim = Simulation(case_from_dict(_case(tmp_path)))
    pairs = ExternalPairSet(input_width=2)
    gid_i, gid_j = _all_pairs(sim)
    inputs = np.stack([gid_i * 1.0, gid_j * 1.0], axis=1)  # inputs that name their pair
    pairs.set_pairs(gid_j, gid_i, inputs)  # given in the other orientation on purpose
    sim.thermal.set_external_term(KEY, pairs)
    sim.thermal.compute_rates(sim.time)
    return sim, pairs


def test_external_set_gives_the_range_sets_heat_and_keeps_its_pairs_through_rebuilds(
    tmp_path: Path,
) -> None:
    ranged = Simulation(case_from_dict(_case(tmp_path)))
    sim, pairs = _external(tmp_path)
    col = heat.M_INDIRECT
    a = ranged.particles.heat_rate_by_mechanism[np.argsort(ranged.particles.global_id), col]
    b = sim.particles.heat_rate_by_mechanism[np.argsort(sim.particles.global_id), col]
    scale = np.abs(a).max()
    assert scale > 0.0
    assert np.abs(a - b).max() <= 1e-12 * scale
    assert abs(b.sum()) <= 1e-13 * np.abs(b).sum()  # what i gains j loses
    rebuilds = sim.rebuild_count
    sim.run(steps=300)
    assert sim.rebuild_count > rebuilds + 2  # the particles were reordered
    sim.thermal.compute_rates(sim.time)
    # the pairs and their inputs stayed with their particles (oriented by global id)
    assert np.all(pairs.gid_i < pairs.gid_j)
    assert np.array_equal(np.sort(pairs.inputs, axis=1), np.stack([pairs.gid_i, pairs.gid_j], 1))
    p = sim.particles
    got = p.heat_rate_by_mechanism[:, col]
    want = _expected(sim, pairs.gid_i, pairs.gid_j)
    assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()
    th = sim.thermal
    assert abs(th.balance_error()) <= 1e-12 * th.initial_energy


def test_restart_with_an_external_set_is_bit_identical(tmp_path: Path) -> None:
    reference, _ = _external(tmp_path)
    reference.run(steps=200)
    first, _ = _external(tmp_path)
    first.run(steps=90)
    path = write_checkpoint(first, tmp_path / "c.h5")
    second = Simulation.from_checkpoint(path)
    second.run(steps=110)
    for name in ("position", "temperature", "heat_rate_by_mechanism"):
        assert np.array_equal(getattr(reference.particles, name), getattr(second.particles, name))
    assert reference.thermal.cumulative == second.thermal.cumulative
    assert math.isfinite(second.thermal.balance_error())
