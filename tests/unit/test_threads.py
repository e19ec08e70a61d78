"""Results do not depend on the number of Numba threads.

The pair pass adds each pair straight into its two particles, slab group by slab group (even
groups in parallel, then odd ones; kernels/slabs.py), so every particle receives its
contributions in an order fixed by the list; each group and each chunk of particles writes
its own ledger row. A run with 1 thread and a run with 2 threads must therefore be
bit-identical. The bed below has more than 4096 particles and many slab groups, so every
parallel loop is split between the threads. A second run adds heat (resistance network with
the conductance reuse, whose per-pair state sits after the rolling model's history columns,
and heat generation, whose per-particle accumulators receive every contact's dissipation, heat
every third step), a third gap conduction on the range pair set, a fourth liquid bridges on
the contact lists. Each parallel loop is checked once per template: the range and
contact-list passes hold one model each as a compile-time constant (kernels/heat_terms.py),
and the loops, which decide the order of the sums, are the same for every model (each
indirect model runs single-threaded in tests/verification/test_thermal_registry.py; the
separated part of batchelor_obrien_complete runs on the same range pass). A
parametrisation per model cost ~15-35 s of compilation each with an empty cache.

Without a request the thread count is chosen from the work (engine/threads.py): 1 thread for
small systems, every thread Numba has for large ones.
"""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.geometry.insertion import InsertedParticles, save_particle_file
from thermodem.kernels import contact as C
from thermodem.state.heat import M_INDIRECT

R0 = 0.005
SPACING = 1.99 * R0
SHAPE = (17, 17, 16)  # 4624 particles


def write_bed(path: Path) -> None:
    rng = np.random.default_rng(99)
    grid = np.stack(np.meshgrid(*(np.arange(n) for n in SHAPE), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * SPACING + rng.uniform(-0.01, 0.01, (grid.size // 3, 3)) * R0
    rad = rng.uniform(0.97 * R0, R0, len(pos))  # jammed start: small overlaps
    vel = rng.normal(0.0, 0.2, pos.shape)
    save_particle_file(path, InsertedParticles(pos, rad, vel, None, "grain"))


HEAT = {  # the resistance network with the conductance reuse (state in the pair history,
    # after the rolling model's columns), a hot floor
    "microhardness": 3e7,
    "surface_roughness": 1e-7,
    "surface_slope": 0.1,
    "thermal_accommodation": 0.8,
    "thermal_conductivity": 50.0,
    "specific_heat": 800.0,
}


def case_dict(path: Path, heat: str = "") -> dict:
    """The bed in its box; ``heat`` adds the thermal models of one parametrisation."""
    upper = [SHAPE[0] * SPACING, SHAPE[1] * SPACING, 0.3]
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
        "domain": {"lower": [-0.01, -0.01, -0.01], "upper": [u + 0.01 for u in upper]},
        "materials": {
            "grain": {
                "density": 2500.0,
                "youngs_modulus": 1e7,
                "poisson_ratio": 0.3,
                "restitution": 0.5,
                "sliding_friction": 0.5,
                "rolling_friction": 0.1,
            }
        },
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        "neighbors": {"skin": 0.01 * R0, "extra_distance": 0.2 * R0},
        "walls": [
            {
                "kind": "box",
                "material": "grain",
                "lower": [0.0, 0.0, 0.0],
                "upper": upper,
                "open_top": True,
            }
        ],
        "insertion": [{"kind": "file", "material": "grain", "path": str(path)}],
    }
    if heat:
        case["materials"]["grain"].update(HEAT)
        case["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 400.0}
        case["thermal"] = {
            "direct_conduction": "resistance_network",
            "conductance_force_tolerance": 0.02,
            "initial_temperature": {"kind": "expression", "expression": "300 + 1000 * x"},
        }
    if heat == "reuse":
        case["thermal"]["heat_generation"] = {"model": "mechanical_dissipation",
                                              "partition": "effusivity"}  # fmt: skip
        case["thermal"]["substeps"] = 3
    if heat in INDIRECT:  # an indirect_conduction model next to the contact conduction
        case["neighbors"]["extra_distance"] = 0.0
        case["thermal"].update(
            direct_conduction="batchelor_obrien_simple",
            indirect_conduction=INDIRECT[heat],
            conductance_force_tolerance=0.0,
            range_skin=0.01 * R0,
        )
    return case


def run(path: Path, threads: int, steps: int, heat: str = "") -> tuple[Simulation, list[int]]:
    numba.set_num_threads(1 if threads > 1 else 2)  # the simulation sets its own count
    sim = Simulation(case_from_dict(case_dict(path, heat)), threads=threads)
    assert sim.threads == threads and sim.threads_reason == "as requested"
    seen: list[int] = []
    sim.run(steps=steps, callback=lambda s: seen.append(numba.get_num_threads()), every=10)
    return sim, seen


#: an indirect_conduction model on each pair set: the range set (gap conduction, rebuilt
#: while the bed moves) and the contact lists (liquid bridges)
INDIRECT = {
    "range-set": {"model": "batchelor_obrien_separated", "cutoff_gap_ratio": 0.4},
    "contact-term": {"model": "vargas_mccarthy2002", "filling_angle": 0.3,
                     "liquid_conductivity": 0.6},
}  # fmt: skip


def by_gid(sim: Simulation, name: str) -> np.ndarray:
    p = sim.particles
    return getattr(p, name)[np.argsort(p.global_id)]


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
@pytest.mark.parametrize(
    "heat",
    ["", "reuse", *INDIRECT],
    ids=["mechanics", "conductance-reuse", *INDIRECT],
)
def test_one_and_two_threads_bit_identical(tmp_path, heat):
    path = tmp_path / "bed.txt"
    write_bed(path)
    previous = numba.get_num_threads()
    try:
        one, seen_one = run(path, 1, 60, heat)
        two, seen_two = run(path, 2, 60, heat)
    finally:
        numba.set_num_threads(previous)
    assert set(seen_one) == {1} and set(seen_two) == {2}
    # every parallel loop has work for both threads
    assert one.particles.count > 4096
    assert one.pairs.count > 2 * C.CHUNK and one.pairs.ngroups >= 8
    assert one.rebuild_count > 1 and one.contact_count > one.particles.count // 2
    assert one.rebuild_count == two.rebuild_count
    names = ["position", "velocity", "angular_velocity", "force", "torque"]
    if heat:
        names += ["temperature", "heat_rate_by_mechanism"]
    if heat == "reuse":
        assert one.history_layout.reuse >= 0 and one.history_layout.roll >= 0
        names += ["generation_energy"]
        assert one.report()["heat_in_generation_sliding_friction"] > 0.0
        assert one.report() == two.report()
    if heat == "range-set":
        rs = one.thermal.range_set
        assert rs.count > 2 * C.CHUNK and rs.ngroups >= 8 and rs.builds > 1
    if heat in INDIRECT:  # the gas or the liquid carries heat
        assert np.abs(one.particles.heat_rate_by_mechanism[:, M_INDIRECT]).max() > 0.0
    for name in names:
        a = by_gid(one, name)
        b = by_gid(two, name)
        assert np.array_equal(a, b), (name, np.abs(a - b).max())
    assert one.energies() == two.energies()


def test_thread_count_chosen_from_the_work(monkeypatch):
    from thermodem.engine import threads as T

    monkeypatch.setattr(T, "available_threads", lambda: 2)
    small, why = T.choose_threads(125, 300)
    assert small == 1 and "1 thread is faster" in why and "125 particles" in why
    assert T.choose_threads(T.PARALLEL_MIN_PARTICLES, 0)[0] == 2
    assert T.choose_threads(10, T.PARALLEL_MIN_PAIRS)[0] == 2  # many pairs: work enough
    assert T.choose_threads(1e6, 1e7, requested=1) == (1, "as requested")
    monkeypatch.setattr(T, "available_threads", lambda: 1)
    assert T.choose_threads(1e6, 1e7)[0] == 1


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
def test_simulation_sets_its_thread_count(tmp_path):
    path = tmp_path / "bed.txt"
    write_bed(path)
    numba.set_num_threads(2)
    # the case of the mechanics run above: the same compiled passes
    case = case_from_dict(case_dict(path))
    from thermodem.engine import threads as T

    sim = Simulation(case)  # 4624 particles
    small = sim.particles.count < T.PARALLEL_MIN_PARTICLES
    expected = 1 if small and sim.pairs.count < T.PARALLEL_MIN_PAIRS else 2
    assert sim.threads == expected and numba.get_num_threads() == expected
    numba.set_num_threads(2)  # another simulation changed it: run() sets it back
    sim.run(steps=1)
    assert numba.get_num_threads() == expected
    assert sim.set_threads(2) == 2 and numba.get_num_threads() == 2
    sim.set_threads(None)  # keeps the request
    assert sim.threads == 2


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
@pytest.mark.parametrize("scheme", ["crank_nicolson", "tr_bdf2", "exponential"])
def test_frozen_implicit_schemes_one_and_two_threads_bit_identical(tmp_path, scheme):
    """The 4624-particle bed frozen, Batchelor & O'Brien complete (contacts and the gaps of
    the range set) under a hot floor: the implicit schemes' solves (one BLAS thread) and the
    engine's passes give the same temperatures and ledger with 1 and 2 Numba threads."""
    path = tmp_path / "bed.txt"
    write_bed(path)
    previous = numba.get_num_threads()
    sims = []
    try:
        for threads in (1, 2):
            numba.set_num_threads(1 if threads > 1 else 2)
            case = {
                "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
                "domain": {"lower": [-0.01, -0.01, -0.01],
                           "upper": [SHAPE[0] * SPACING + 0.01, SHAPE[1] * SPACING + 0.01, 0.31]},
                "materials": {"grain": {**case_dict(path)["materials"]["grain"], **HEAT}},
                # (the contact laws of the runs above: their compiled force pass)
                "contact": case_dict(path)["contact"],
                "walls": [{"kind": "box", "material": "grain", "lower": [0.0, 0.0, 0.0],
                           "upper": [SHAPE[0] * SPACING, SHAPE[1] * SPACING, 0.3],
                           "open_top": True, "thermal": {"kind": "fixed", "temperature": 400.0}}],
                "insertion": [{"kind": "file", "material": "grain", "path": str(path)}],
                "thermal": {"direct_conduction": {"model": "batchelor_obrien_complete",
                                                  "cutoff_gap_ratio": 0.4},
                            "frozen_mechanics": True,
                            "time_step": 5.0, "scheme": scheme,
                            "implicit": {"preconditioner": "jacobi"},
                            "initial_temperature": {"kind": "uniform", "value": 300.0}},
            }  # fmt: skip
            sim = Simulation(case_from_dict(case), threads=threads)
            sim.run(steps=4)
            sims.append(sim)
    finally:
        numba.set_num_threads(previous)
    one, two = sims
    assert one.particles.count > 4096 and one.thermal.range_set.count > 2 * C.CHUNK
    assert np.ptp(one.particles.temperature) > 1.0
    for name in ("temperature", "heat_rate_by_mechanism"):
        assert np.array_equal(by_gid(one, name), by_gid(two, name)), name
    assert one.thermal.cumulative == two.thermal.cumulative
