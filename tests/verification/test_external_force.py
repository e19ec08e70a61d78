"""Constant external forces and torques (case key ``external_force``) against closed forms.

References (not the code under test):

* Two equal spheres pressed together by equal and opposite forces F come to rest, damped, at
  the Hertz overlap that carries F: F = (4/3) E* sqrt(R*) δ^{3/2}, i.e.
  δ = (9 F² / (16 R* E*²))^{1/3} (spec appendix A). Each sphere moves δ/2 along its force, so
  the loads do the work F δ; at rest the contact stores (2/5) F δ and the dashpot has
  dissipated the rest, (3/5) F δ.
* A free sphere under a constant torque T spins up at T/I; velocity Verlet is exact for a
  constant load, so ω = T t / I and the work of the torque is ½ I ω² to round-off. A sphere
  whose external force cancels its weight stays where it is while its neighbours fall freely,
  z = z0 - ½ g t², also after the neighbour list has reordered the particles.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.geometry.insertion import InsertedParticles, save_particle_file

RADIUS = 1e-3
DENSITY = 2500.0
YOUNG, POISSON = 1e7, 0.3
E_STAR = YOUNG / (2.0 * (1.0 - POISSON**2))
MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3
MATERIAL = {"density": DENSITY, "youngs_modulus": YOUNG, "poisson_ratio": POISSON}


pytestmark = pytest.mark.usefixtures("one_thread")


def _file(path: Path, position, material: str) -> str:
    pos = np.asarray(position, float)
    n = len(pos)
    save_particle_file(
        path, InsertedParticles(pos, np.full(n, RADIUS), np.zeros((n, 3)), None, material)
    )
    return str(path)


def pressed_pair(tmp: Path, force: float, dt: float) -> dict:
    """Sphere 0 selected by its id, sphere 1 by a region around it; zero gravity."""
    return {
        "simulation": {"time_step": dt, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.01] * 3, "upper": [0.01] * 3},
        "materials": {"grain": dict(MATERIAL, restitution=0.3, sliding_friction=0.5)},
        "insertion": [
            {
                "kind": "file",
                "material": "grain",
                "path": _file(tmp / "pair.txt", [[-RADIUS, 0, 0], [RADIUS, 0, 0]], "grain"),
            }
        ],
        "external_force": [
            {"select": {"ids": [0]}, "force": [force, 0.0, 0.0]},
            {
                "select": {"region": {"lower": [0.0, -0.005, -0.005], "upper": [0.005] * 3}},
                "force": [-force, 0.0, 0.0],
            },
        ],
    }


def test_pressed_spheres_come_to_the_hertz_overlap(tmp_path):
    force = 0.01
    r_eff = RADIUS / 2.0
    overlap = (9.0 * force**2 / (16.0 * r_eff * E_STAR**2)) ** (1.0 / 3.0)
    # period of the linearised oscillation at the static overlap (reduced mass m/2)
    stiffness = 1.5 * (4.0 / 3.0) * E_STAR * math.sqrt(r_eff * overlap)
    period = 2.0 * math.pi * math.sqrt(0.5 * MASS / stiffness)
    errors = []
    for steps_per_period in (50, 100):
        sim = Simulation(case_from_dict(pressed_pair(tmp_path, force, period / steps_per_period)))
        sim.run(steps=60 * steps_per_period)  # 60 periods, e = 0.3 per half period
        p = sim.particles
        gap = 2.0 * RADIUS - float(np.linalg.norm(p.position[1] - p.position[0]))
        assert gap == pytest.approx(overlap, rel=1e-9)
        assert np.abs(p.velocity).max() < 1e-9 * overlap / period
        np.testing.assert_allclose(p.position.sum(axis=0), 0.0, atol=1e-15)  # momentum
        e = sim.energies()
        work = force * overlap
        assert e["external_work"] == pytest.approx(work, rel=1e-9)
        assert e["elastic_normal"] == pytest.approx(0.4 * work, rel=1e-9)
        # the dashpot terms are integrated with the half-step velocities (first order in dt)
        assert e["dissipated_normal_damping"] == pytest.approx(0.6 * work, rel=2e-2)
        errors.append(abs(sim.energy_balance_error()) / work)
    assert errors[0] < 1e-2, errors  # leaving the external work out would make it 1
    assert errors[0] / errors[1] > 1.6, errors


def floating_case(tmp: Path, torque: float) -> dict:
    """Six spheres far apart, listed so that the neighbour list reorders them; material 'b'
    carries an upward force equal to its weight and a torque."""
    pos = np.array(
        [[0.018 - 0.003 * k, 0.018 - 0.003 * k, 0.015 + 0.001 * (k % 2)] for k in range(6)]
    )
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
        "domain": {"lower": [0.0] * 3, "upper": [0.02] * 3},
        "materials": {"a": MATERIAL, "b": MATERIAL},
        "neighbors": {"rebuild_every_step": True},
        "insertion": [
            {"kind": "file", "material": "a", "path": _file(tmp / "a.txt", pos[::2], "a")},
            {"kind": "file", "material": "b", "path": _file(tmp / "b.txt", pos[1::2], "b")},
        ],
        "external_force": [
            {"select": {"material": "b"}, "force": [0.0, 0.0, MASS * 9.81]},
            {"select": {"material": "b"}, "torque": [0.0, torque, 0.0]},
        ],
    }


def test_loads_follow_the_particles_through_reordering(tmp_path):
    torque = 1e-9
    case = floating_case(tmp_path, torque)
    sim = Simulation(case_from_dict(case))
    gids = sim.particles.global_id
    start = {int(g): sim.particles.position[k].copy() for k, g in enumerate(gids)}
    sim.run(steps=2000)
    p = sim.particles
    assert list(p.global_id) != sorted(p.global_id)  # the arrays were permuted
    inertia = 0.4 * MASS * RADIUS**2
    t = sim.time
    for k, gid in enumerate(p.global_id):
        z0 = start[int(gid)][2]
        if p.type_id[k] == 1:  # 'b': weight cancelled, spinning up
            np.testing.assert_allclose(p.position[k], start[int(gid)], rtol=0, atol=1e-15)
            assert p.angular_velocity[k, 1] == pytest.approx(torque * t / inertia, rel=1e-12)
        else:
            assert p.position[k, 2] == pytest.approx(z0 - 0.5 * 9.81 * t**2, rel=1e-12)
            assert not p.angular_velocity[k].any()
    e = sim.energies()
    spin = 3 * 0.5 * inertia * (torque * t / inertia) ** 2
    assert e["external_work"] == pytest.approx(spin, rel=1e-12)
    assert abs(sim.energy_balance_error()) < 1e-12 * (abs(sim.initial_energy) + spin)
    # a restart continues with the same loads and ledger, bit for bit
    state = sim.state_dict()
    sim.run(steps=100)
    again = Simulation(case_from_dict(case), insert_particles=False)
    again.load_state(state)
    again.run(steps=100)
    np.testing.assert_array_equal(again.particles.position, sim.particles.position)
    np.testing.assert_array_equal(again.particles.angular_velocity, p.angular_velocity)
    assert again.energies()["external_work"] == sim.energies()["external_work"]


def test_without_the_key_particles_carry_no_load_columns(tmp_path):
    case = floating_case(tmp_path, 0.0)
    del case["external_force"]
    sim = Simulation(case_from_dict(case))
    assert sim.particles.external_force.shape == (6, 0)
    assert sim.energies()["external_work"] == 0.0


@pytest.mark.parametrize(
    ("entry", "message"),
    [
        ({"select": {"ids": [0]}, "force": [1.0, 2.0]}, "external_force.0.force: too few"),
        ({"select": {"ids": [0]}, "force": [1.0, 2.0, math.nan]}, "external_force.0.force.2"),
        ({"select": {"ids": [0]}, "torque": [1.0, "inf", 0.0]}, "external_force.0.torque.1"),
        ({"select": {"material": "glas"}, "force": [0, 0, 1]}, "external_force.0.select.material"),
        ({"select": {}, "force": [0, 0, 1]}, "external_force.0.select: give at least one"),
        ({"select": {"ids": [0]}}, "external_force.0: give force"),
        ({"select": {"ids": [-1]}, "force": [0, 0, 1]}, "select.ids must be >= 0"),
        ({"select": {"ids": [0]}, "forse": [0, 0, 1]}, "external_force.0.forse: unknown key"),
        (
            {"select": {"region": {"lower": [0, 0, 0], "upper": [0, 1, 1]}}, "force": [0, 0, 1]},
            "external_force.0.select.region: lower must be < upper",
        ),
    ],
)
def test_bad_entries_are_refused_naming_the_key(tmp_path, entry, message):
    case = pressed_pair(tmp_path, 0.01, 1e-6)
    case["external_force"] = [entry]
    with pytest.raises(ConfigError, match="invalid case") as err:
        case_from_dict(case)
    assert message in str(err.value)


def test_a_selection_of_no_particle_is_refused(tmp_path):
    case = pressed_pair(tmp_path, 0.01, 1e-6)
    case["external_force"].append({"select": {"ids": [7]}, "force": [0.0, 0.0, 1.0]})
    with pytest.raises(ConfigError, match=r"external_force\.2\.select: selects no particle"):
        Simulation(case_from_dict(case))


def test_poured_particles_get_their_loads(tmp_path):
    """Poured particles are selected when they arrive (region on their insertion position):
    those poured in the upper half float (force = weight), the others fall freely; the
    selection may take nobody at the start, since particles are poured later."""
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
        "domain": {"lower": [0.0] * 3, "upper": [0.02] * 3},
        "materials": {"a": MATERIAL},
        "insertion": [
            {
                "kind": "pour",
                "material": "a",
                "distribution": {"kind": "mono", "radius": RADIUS},
                "region": {"kind": "box", "lower": [0.002, 0.002, 0.01], "upper": [0.018] * 3},
                "rate": 2000.0,
                "end_time": 0.005,
                "interval": 0.005,
            }
        ],
        "external_force": [
            {
                "select": {"region": {"lower": [0, 0, 0.014], "upper": [0.02] * 3}},
                "force": [0.0, 0.0, MASS * 9.81],
            }
        ],
    }
    sim = Simulation(case_from_dict(case))
    assert sim.particles.count == 0
    sim.run(steps=500)  # the batch arrives at t = 0.005 s
    p = sim.particles
    assert p.count == 10
    high = p.external_force[:, 2] > 0.0
    assert 0 < high.sum() < p.count  # (random positions: seed fixed by the case)
    np.testing.assert_allclose(p.external_force[high, 2], MASS * 9.81, rtol=1e-15)
    sim.run(steps=500)
    p = sim.particles
    high = p.external_force[:, 2] > 0.0
    assert np.abs(p.velocity[high]).max() == 0.0
    # inserted after the drift of step 500, then the half kick of that step and 500 steps
    np.testing.assert_allclose(p.velocity[~high, 2], -9.81 * (0.005 + 0.5e-5), rtol=1e-9)
    assert np.all(p.position[high, 2] >= 0.014)
