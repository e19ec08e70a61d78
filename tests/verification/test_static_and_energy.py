"""Static equilibrium against closed forms, energy conservation and the energy ledger.

* A sphere resting on a plane under gravity settles at the overlap where the contact law
  carries its weight: Hertz m g = (4/3) E* sqrt(R) δ^{3/2} (spec appendix A, R* = R for a wall),
  linear m g = k δ. At rest the damping force vanishes, so the discrete equilibrium of velocity
  Verlet is exactly the force balance and the error after settling is set by the decay only.
* A handful of elastic, frictionless spheres bouncing in a box under gravity: velocity Verlet
  conserves the total energy to O(dt²) (for the Hertz law the potential δ^{5/2} is C² at contact,
  so the entry into contact does not spoil the order): halving dt divides the largest relative
  error over the run by about 4.
* A damped frictional drum (Hertz-Mindlin, e = 0.5, μ = 0.5, rolling resistance, rotating
  cylinder wall): E(t) + dissipated - wall work - stiffness work - E(0) -> 0 as dt -> 0.
  The ledger takes each step's dissipated power at the half-step velocities of that step
  (rectangle rule), so it closes to first order in dt: the error halves with dt.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.geometry.insertion import InsertedParticles, save_particle_file

G = 9.81
DENSITY = 2500.0
YOUNG = 1.0e7
POISSON = 0.3
E_STAR = 1.0 / (2.0 * (1.0 - POISSON**2) / YOUNG)  # same material for sphere and wall
STIFFNESS = 2.0e4


pytestmark = pytest.mark.usefixtures("one_thread")


def make_sim(
    tmp: Path,
    position,
    radius,
    velocity,
    *,
    dt: float,
    lower,
    upper,
    walls,
    material: dict,
    contact: dict,
    gravity=(0.0, 0.0, -G),
    tag: str = "p",
) -> Simulation:
    path = tmp / f"{tag}.txt"
    save_particle_file(
        path,
        InsertedParticles(
            np.asarray(position, float),
            np.asarray(radius, float),
            np.asarray(velocity, float),
            None,
            "grain",
        ),
    )
    mat = {"density": DENSITY, "youngs_modulus": YOUNG, "poisson_ratio": POISSON}
    mat.update(material)
    case = {
        "simulation": {"time_step": dt, "end_time": 1.0, "gravity": list(gravity)},
        "domain": {"lower": list(lower), "upper": list(upper)},
        "materials": {"grain": mat},
        "contact": contact,
        "walls": walls,
        "insertion": [{"kind": "file", "material": "grain", "path": str(path)}],
    }
    return Simulation(case_from_dict(case))


# ------------------------------------------------------------------------ static overlap
@pytest.mark.parametrize("normal", ["hertz", "linear"])
def test_resting_sphere_static_overlap(tmp_path, normal):
    radius = 0.01
    mass = DENSITY * 4.0 / 3.0 * math.pi * radius**3
    weight = mass * G
    if normal == "hertz":
        expected = (3.0 * weight / (4.0 * E_STAR * math.sqrt(radius))) ** (2.0 / 3.0)
        # linearised stiffness at the equilibrium, for the time step
        k_lin = 1.5 * (4.0 / 3.0) * E_STAR * math.sqrt(radius) * math.sqrt(expected)
        law = "hertz"
    else:
        expected = weight / STIFFNESS
        k_lin = STIFFNESS
        law = {"model": "linear", "stiffness": STIFFNESS}
    period = 2.0 * math.pi * math.sqrt(mass / k_lin)
    sim = make_sim(
        tmp_path,
        [[0.0, 0.0, radius]],
        [radius],
        [[0.0, 0.0, 0.0]],
        dt=period / 100,
        lower=(-0.05, -0.05, -0.01),
        upper=(0.05, 0.05, 0.05),
        walls=[{"kind": "plane", "material": "grain", "point": [0, 0, 0], "normal": [0, 0, 1]}],
        material={"restitution": 0.3, "sliding_friction": 0.5},
        contact={"normal": law, "tangential": "mindlin", "rolling": "none"},
    )
    sim.run(steps=2000)  # 20 periods of the linearised oscillation; e = 0.3 per half period
    overlap = radius - sim.particles.position[0, 2]
    assert abs(overlap / expected - 1.0) < 1e-6, overlap / expected - 1.0
    assert np.abs(sim.particles.velocity).max() < 1e-6 * math.sqrt(G * expected)
    assert sim.particles.position[0, :2] == pytest.approx([0.0, 0.0], abs=1e-15)


# ------------------------------------------------------------------ energy conservation
BOX = 0.1
BOUNCERS_POSITION = [
    [0.03, 0.05, 0.05],
    [0.07, 0.05, 0.05],  # head-on pair, falling side by side
    [0.02, 0.02, 0.08],
    [0.08, 0.08, 0.06],
    [0.02, 0.08, 0.03],
]
BOUNCERS_RADIUS = [0.01, 0.01, 0.01, 0.012, 0.008]
BOUNCERS_VELOCITY = [[0.5, 0, 0], [-0.5, 0, 0], [0, 0, 0], [0, 0, 0.3], [0, 0, -1.0]]


def elastic_energy_error(tmp: Path, dt: float, duration: float) -> tuple[float, dict]:
    sim = make_sim(
        tmp,
        BOUNCERS_POSITION,
        BOUNCERS_RADIUS,
        BOUNCERS_VELOCITY,
        dt=dt,
        lower=(-0.01, -0.01, -0.01),
        upper=(0.11, 0.11, 0.11),
        walls=[{"kind": "box", "material": "grain", "lower": [0, 0, 0], "upper": [BOX, BOX, BOX]}],
        material={"restitution": 1.0, "sliding_friction": 0.0},
        contact={"normal": "hertz", "tangential": "none", "rolling": "none"},
        tag=f"bouncers-{dt:g}",
    )
    e0 = sim.total_energy()
    stats = {"max": 0.0, "pair_steps": 0, "wall_steps": 0}

    def watch(s: Simulation) -> None:
        stats["max"] = max(stats["max"], abs(s.total_energy() - e0) / e0)
        pairs = len(s.touching_pairs()[0])
        stats["pair_steps"] += pairs
        stats["wall_steps"] += s.contact_count - pairs

    sim.run(until=duration, callback=watch)
    stats["balance"] = abs(sim.energy_balance_error()) / e0
    return stats["max"], stats


def test_elastic_energy_conserved_second_order(tmp_path):
    err_coarse, coarse = elastic_energy_error(tmp_path, 2e-5, 0.2)
    err_fine, fine = elastic_energy_error(tmp_path, 1e-5, 0.2)
    ratio = err_coarse / err_fine
    # particle-particle and particle-wall contacts both happened (in steps of dt = 1e-5)
    assert fine["pair_steps"] > 100 and fine["wall_steps"] > 1000, fine
    assert err_coarse < 1e-4, err_coarse
    assert 3.0 < ratio < 5.5, (err_coarse, err_fine, ratio)
    # nothing dissipated: the ledger is the energy error itself
    assert fine["balance"] <= err_fine


# ------------------------------------------------------------------------- energy ledger
def drum(tmp: Path, dt: float, rolling: str) -> Simulation:
    """Ten polydisperse spheres in the lower half of a drum (axis y) rotating at 6 rad/s,
    closed by two planes; z = 0 is the bottom of the drum."""
    rng = np.random.default_rng(7)
    centre_z, drum_r = 0.06, 0.05
    pos, rad = [], []
    for x in np.arange(-0.03, 0.031, 0.021):
        for y in (-0.01, 0.012):
            for z in (0.025, 0.046):
                r = rng.uniform(0.008, 0.01)
                if math.hypot(x, z - centre_z) + r < drum_r:
                    pos.append((x, y, z))
                    rad.append(r)
    vel = rng.uniform(-0.2, 0.2, (len(pos), 3))
    walls = [
        {
            "kind": "cylinder",
            "material": "grain",
            "center": [0, 0, centre_z],
            "axis": [0, 1, 0],
            "radius": drum_r,
            "angular_velocity": 6.0,
        },
        {"kind": "plane", "material": "grain", "point": [0, -0.025, 0], "normal": [0, 1, 0]},
        {"kind": "plane", "material": "grain", "point": [0, 0.025, 0], "normal": [0, -1, 0]},
    ]
    return make_sim(
        tmp,
        pos,
        rad,
        vel,
        dt=dt,
        lower=(-0.06, -0.03, 0.0),
        upper=(0.06, 0.03, 0.12),
        walls=walls,
        material={"restitution": 0.5, "sliding_friction": 0.5, "rolling_friction": 0.1},
        contact={"normal": "hertz", "tangential": "mindlin", "rolling": rolling},
        tag=f"drum-{rolling}-{dt:g}",
    )


@pytest.mark.parametrize("rolling", ["epsd", "constant_torque"])
def test_energy_ledger_closes_with_rotating_wall(tmp_path, rolling):
    errors = []
    for dt in (2e-5, 1e-5):
        sim = drum(tmp_path, dt, rolling)
        e0 = sim.initial_energy
        worst = [0.0]

        def watch(s: Simulation, worst=worst) -> None:
            worst[0] = max(worst[0], abs(s.energy_balance_error()))

        sim.run(until=0.1, callback=watch, every=10)
        e = sim.energies()
        dissipated = sum(v for k, v in e.items() if k.startswith("dissipated_"))
        # every mechanism is exercised; the drum drives the bed (wall work > 0), and leaving the
        # wall work out of the ledger would break it by far more than its error
        for key in (
            "dissipated_normal_damping",
            "dissipated_tangential_damping",
            "dissipated_sliding_friction",
            "dissipated_rolling_friction",
        ):
            assert e[key] > 0.0, key
        assert e["wall_work"] > 10.0 * worst[0], (e["wall_work"], worst[0])
        assert worst[0] < 0.02 * e0, worst[0] / e0
        assert worst[0] < 0.05 * dissipated, worst[0] / dissipated
        errors.append(worst[0] / e0)
    # first order in dt (see the module docstring): halving dt at least ~halves the error
    assert errors[0] / errors[1] > 1.6, errors
