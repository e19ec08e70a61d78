"""Core invariants of the engine, each against an independent oracle.

- the cell-list pair list equals an O(N²) brute force (polydisperse, walls, periodic axes);
- a Verlet-skin run equals a rebuild-every-step run to round-off (history carried by key);
- 1 and 2 threads give bit-identical results;
- the mechanical energy ledger closes, with an error that shrinks with the time step.
"""

from __future__ import annotations

import copy

import numba
import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation

MATERIAL = {
    "density": 2500.0,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "restitution": 0.5,
    "sliding_friction": 0.5,
    "rolling_friction": 0.1,
}


def _case(
    periodic=(False, False, False),
    walls=True,
    count=150,
    dt=2e-6,
    rolling="none",
    extra=0.0,
    rebuild_every_step=False,
    seed=3,
) -> dict:
    case = {
        "simulation": {"time_step": dt, "end_time": 1.0, "seed": seed},
        "domain": {"lower": [0, 0, 0], "upper": [0.012, 0.012, 0.012], "periodic": list(periodic)},
        "materials": {"glass": dict(MATERIAL)},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": rolling},
        "neighbors": {"extra_distance": extra, "rebuild_every_step": rebuild_every_step},
        "insertion": [
            {
                "kind": "random_box",
                "material": "glass",
                "count": count,
                "distribution": {"kind": "uniform", "min_radius": 0.0003, "max_radius": 0.0008},
                "lower": [0.0008, 0.0008, 0.0008],
                "upper": [0.0112, 0.0112, 0.0112],
            }
        ],
    }
    if walls:
        case["insertion"] = [
            {
                "kind": "random_cylinder",
                "material": "glass",
                "count": count,
                "distribution": {"kind": "uniform", "min_radius": 0.0003, "max_radius": 0.0008},
                "base_centre": [0.006, 0.006, 0.0012],
                "axis": [0, 0, 1],
                "radius": 0.0052,
                "length": 0.0096,
            }
        ]
        case["walls"] = [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [0.012, 0.012, 0.012],
                "material": "glass",
            },
            {
                "kind": "cylinder",
                "center": [0.006, 0.006, 0.006],
                "axis": [0, 0, 1],
                "radius": 0.0058,
                "length": 0.01,
                "material": "glass",
                "angular_velocity": 20.0,
            },
        ]
    return case


def _brute_force_pairs(sim: Simulation) -> set[tuple[int, int]]:
    p = sim.particles
    d = p.position[:, None, :] - p.position[None, :, :]
    length = sim.upper - sim.lower
    for a in range(3):
        if sim.periodic[a]:
            d[..., a] -= length[a] * np.round(d[..., a] / length[a])
    dist = np.sqrt((d**2).sum(axis=2))
    cut = p.radius[:, None] + p.radius[None, :] + sim.extra + sim.skin
    i, j = np.nonzero(np.triu(dist < cut, k=1))
    gi, gj = p.global_id[i], p.global_id[j]
    return set(zip(np.minimum(gi, gj).tolist(), np.maximum(gi, gj).tolist(), strict=True))


@pytest.mark.parametrize(
    "periodic", [(False, False, False), (True, False, False), (True, True, True)]
)
def test_cell_list_equals_brute_force(periodic) -> None:
    sim = Simulation(case_from_dict(_case(periodic=periodic, walls=False, extra=0.0002, count=300)))
    # squeeze particles across periodic faces too: shift everything by a third of the box
    sim.particles.position[:] = (sim.particles.position + 0.004) % 0.012
    sim.rebuild()
    pb = sim.pairs
    gid = sim.particles.global_id
    listed = list(zip(gid[pb.i[: pb.count]].tolist(), gid[pb.j[: pb.count]].tolist(), strict=True))
    assert all(a < b for a, b in listed)  # oriented by global id
    assert len(set(listed)) == len(listed)  # each pair once
    assert set(listed) == _brute_force_pairs(sim)


def test_wall_pairs_equal_brute_force() -> None:
    sim = Simulation(case_from_dict(_case(count=200)))
    p, wb = sim.particles, sim.walls
    listed = set(
        zip(p.global_id[wb.i[: wb.count]].tolist(), wb.j[: wb.count].tolist(), strict=True)
    )
    expected = set()
    x = p.position
    reach = p.radius + sim.extra + sim.skin
    # the box faces are the first six walls: distance to each face plane (the faces span the
    # whole box and particles are inside, so the plane distance is the rectangle distance)
    faces = [(0, 0.0), (0, 0.012), (1, 0.0), (1, 0.012), (2, 0.0), (2, 0.012)]
    for w, (axis, level) in enumerate(faces):
        for k in np.nonzero(np.abs(x[:, axis] - level) < reach)[0]:
            expected.add((int(p.global_id[k]), w))
    rho = np.hypot(x[:, 0] - 0.006, x[:, 1] - 0.006)
    inside = np.abs(x[:, 2] - 0.006) <= 0.005
    for k in np.nonzero(inside & (0.0058 - rho < reach))[0]:
        expected.add((int(p.global_id[k]), 6))
    assert listed == expected


def _run(case: dict, steps: int, threads: int | None = None) -> Simulation:
    sim = Simulation(case_from_dict(copy.deepcopy(case)), threads=threads)
    rng = np.random.default_rng(1)
    sim.particles.velocity[:] = rng.normal(0.0, 0.5, sim.particles.velocity.shape)
    sim.run(steps=steps)
    return sim


def _by_gid(sim: Simulation, name: str) -> np.ndarray:
    order = np.argsort(sim.particles.global_id)
    return getattr(sim.particles, name)[order]


def test_skin_run_equals_rebuild_every_step() -> None:
    base = _case(count=200, rolling="epsd")
    base["simulation"]["gravity"] = [0.0, 0.0, -9.81]
    skin = _run(base, 400)
    every = _run({**base, "neighbors": {"rebuild_every_step": True}}, 400)
    assert skin.rebuild_count > 1 and skin.rebuild_count < every.rebuild_count
    assert skin.contact_count > 5  # touching, frictional pairs carry history
    for name in ("position", "velocity", "angular_velocity"):
        np.testing.assert_allclose(
            _by_gid(skin, name), _by_gid(every, name), rtol=1e-12, atol=1e-15
        )


def test_one_and_two_threads_bit_identical() -> None:
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs 2 threads")
    case = _case(count=200, rolling="epsd")
    runs = []
    for threads in (1, 2):
        runs.append(_run(case, 300, threads))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for name in ("position", "velocity", "angular_velocity", "force"):
        assert np.array_equal(_by_gid(runs[0], name), _by_gid(runs[1], name))
    assert runs[0].energies() == runs[1].energies()


@pytest.mark.parametrize("rolling", ["epsd", "constant_torque"])
def test_energy_ledger_closes_and_error_shrinks_with_dt(rolling) -> None:
    errors = []
    for dt in (2e-6, 1e-6):
        case = _case(count=120, dt=dt, rolling=rolling)
        case["simulation"]["gravity"] = [0.0, 0.0, -9.81]
        sim = Simulation(case_from_dict(case))
        sim.particles.velocity[:] = np.random.default_rng(1).normal(
            0.0, 0.3, sim.particles.velocity.shape
        )
        sim.initial_energy = sim.total_energy()
        sim.run(until=0.006)
        e = sim.energies()
        dissipated = sum(v for k, v in e.items() if k.startswith("dissipated_"))
        assert dissipated > 0.2 * sim.initial_energy  # a strongly dissipative run
        assert e["wall_work"] != 0.0  # the rotating cylinder does work
        errors.append(abs(sim.energy_balance_error()) / dissipated)
    print("ledger error / dissipated energy for dt = 2e-6, 1e-6 s:", errors)
    assert errors[0] < 0.05
    assert errors[1] < 0.7 * errors[0]
