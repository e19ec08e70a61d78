"""Two-dimensional discs (issue 16, docs/two-dimensional.md): mechanics against closed forms.

References (not the code under test):

* Disc of thickness b, radius R, density ρ: m = ρ π R² b, I = m R²/2 (solid cylinder about
  its axis).
* The 2D line contact ``hertz_2d``: F = k δ + γ δ', k = (π/4) E* b (the stiffness of two
  parallel cylinders of Kratos DEM's 2D Hertz law), γ = 2 ζ sqrt(m* k). The damped
  oscillator δ'' + 2ζω δ' + ω² δ = 0, ω = sqrt(k/m*), δ(0) = 0, δ'(0) = v returns to δ = 0 at
  t_c = π/(ω sqrt(1 - ζ²)) with the speed e v, e = exp(-ζπ/sqrt(1 - ζ²)); so ζ(e) =
  -ln e/sqrt(π² + ln² e). A wall is a body of infinite mass: m* = m.
* Tolerances as in test_collisions.py: the exit is interpolated between the last touching and
  the first free step, the damping force lags half a step (first order), so the damped
  contact time is held to one time step and the restitution to a few dt/t_c.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError

RADIUS = 0.005
DENSITY = 2500.0
YOUNG = 1.0e7
POISSON = 0.3
E_STAR = 1.0 / (2.0 * (1.0 - POISSON**2) / YOUNG)
STEPS_PER_CONTACT = 400


pytestmark = pytest.mark.usefixtures("one_thread")


def material(e: float, mu: float = 0.0, mu_r: float = 0.0) -> dict:
    return {
        "density": DENSITY,
        "youngs_modulus": YOUNG,
        "poisson_ratio": POISSON,
        "restitution": e,
        "sliding_friction": mu,
        "rolling_friction": mu_r,
    }


def zeta(e: float) -> float:
    return -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2) if e < 1.0 else 0.0


def contact_time(m_eff: float, k: float, e: float) -> float:
    return math.pi / (math.sqrt(k / m_eff) * math.sqrt(1.0 - zeta(e) ** 2))


def disc_case(
    thickness: float, e: float, dt: float, positions, velocities, walls=(), **extra
) -> dict:
    case = {
        "simulation": {
            "time_step": dt,
            "end_time": 1.0,
            "dimension": 2,
            "thickness": thickness,
            "gravity": [0.0, 0.0],
        },
        "domain": {"lower": [-0.1, -0.1], "upper": [0.1, 0.1]},
        "materials": {"glass": material(e)},
        "contact": {"normal": "hertz_2d", "tangential": "none", "rolling": "none"},
        "walls": list(walls),
        "insertion": [
            {
                "kind": "list",
                "material": "glass",
                "positions": positions,
                "radius": RADIUS,
                "velocities": velocities,
            }
        ],
        "output": {"vtu": False},
    }
    case.update(extra)
    return case


def collide(case: dict, wall: bool) -> tuple[float, float, float]:
    """(contact time, restitution, largest out-of-plane value) of a head-on collision along x:
    two discs (or one disc and the line x = 0)."""
    sim = Simulation(case_from_dict(case))
    p = sim.particles
    dt = sim.dt

    def overlap() -> float:
        x = p.position[:, 0]
        return RADIUS - x[0] if wall else 2.0 * RADIUS - abs(x[1] - x[0])

    def rel_speed() -> float:
        v = p.velocity[:, 0]
        return -v[0] if wall else v[0] - v[1]

    v0 = rel_speed()
    start = None
    prev = overlap()
    out_of_plane = 0.0
    for _ in range(100000):
        sim.step()
        out_of_plane = max(
            out_of_plane,
            float(np.abs(p.position[:, 2]).max()),
            float(np.abs(p.velocity[:, 2]).max()),
            float(np.abs(p.angular_velocity[:, :2]).max()),
        )
        d = overlap()
        if start is None and d > 0.0:
            start = sim.time - dt * d / (d - prev)  # linear interpolation of the entry
        if start is not None and d <= 0.0:
            end = sim.time - dt * d / (d - prev)
            break
        prev = d
    else:
        raise AssertionError("the collision did not end")
    for _ in range(3):  # free flight: the velocity is the rebound velocity
        sim.step()
    return end - start, -rel_speed() / v0, out_of_plane


@pytest.mark.parametrize("wall", [False, True], ids=["disc-disc", "disc-wall"])
@pytest.mark.parametrize("e", [1.0, 0.5, 0.1])
@pytest.mark.parametrize("thickness", [1.0, 0.002])
def test_disc_collision_time_and_restitution_match_the_closed_forms(
    wall: bool, e: float, thickness: float
) -> None:
    v = 0.5
    mass = DENSITY * math.pi * RADIUS**2 * thickness
    m_eff = mass if wall else 0.5 * mass
    k = 0.25 * math.pi * E_STAR * thickness
    t_c = contact_time(m_eff, k, e)
    dt = t_c / STEPS_PER_CONTACT
    gap = 2.0 * v * dt
    if wall:
        positions, velocities = [[RADIUS + gap, 0.0]], [[-v, 0.0]]
        walls = [{"kind": "plane", "point": [0, 0], "normal": [1, 0], "material": "glass"}]
    else:
        positions = [[-RADIUS - gap / 2, 0.0], [RADIUS + gap / 2, 0.0]]
        velocities, walls = [[v / 2, 0.0], [-v / 2, 0.0]], []
    measured_t, measured_e, out_of_plane = collide(
        disc_case(thickness, e, dt, positions, velocities, walls), wall
    )
    phase = (math.pi / STEPS_PER_CONTACT) ** 2 / 4.0
    if e == 1.0:
        assert measured_t == pytest.approx(t_c, rel=phase)
        assert measured_e == pytest.approx(1.0, abs=phase)
    else:
        assert abs(measured_t - t_c) <= dt
        assert measured_e == pytest.approx(e, abs=3.0 * dt / t_c)
    assert out_of_plane == 0.0  # the discs never leave the plane z = 0, nor tilt


def test_disc_mass_and_inertia_are_those_of_a_cylinder_of_the_thickness() -> None:
    b = 0.003
    case = disc_case(b, 0.5, 1e-5, [[0.0, 0.0], [0.02, 0.0]], [[0.0, 0.0], [0.0, 0.0]])
    sim = Simulation(case_from_dict(case))
    m = DENSITY * math.pi * RADIUS**2 * b
    np.testing.assert_allclose(sim.particles.mass, m, rtol=1e-15)
    np.testing.assert_allclose(sim.particles.moment_of_inertia, 0.5 * m * RADIUS**2, rtol=1e-15)
    case["simulation"]["particle_shape"] = "sphere"
    case["contact"]["normal"] = "hertz"
    case["simulation"].pop("thickness")
    sim = Simulation(case_from_dict(case))
    m = DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3
    np.testing.assert_allclose(sim.particles.mass, m, rtol=1e-15)
    np.testing.assert_allclose(sim.particles.moment_of_inertia, 0.4 * m * RADIUS**2, rtol=1e-15)


def test_disc_rolls_without_slip_on_a_line_as_a_cylinder() -> None:
    """A disc launched without spin on a rough line slides until it rolls: Coulomb friction
    μ m g decelerates v (dv/dt = -μ g) and spins it up (torque μ m g R, I = m R²/2, so
    d(ωR)/dt = 2 μ g); it rolls from t = v0/(3 μ g) on, at v = ω R = 2 v0/3 (the angular
    momentum about the contact point, m v0 R = m v R + I ω = 3/2 m v R, is conserved). The
    kinetic energy falls from ½ m v0² to ½ m v² + ½ I ω² = ¾ m v² = ⅓ m v0²: the sliding
    dissipates m v0²/6 (a sphere: 5 v0/7 and m v0²/7), and the ledger closes."""
    v0, mu, b = 0.3, 0.4, 0.01
    dt = 2e-6
    case = disc_case(b, 0.5, dt, [[0.0, RADIUS - 1e-6]], [[v0, 0.0]])
    case["simulation"]["gravity"] = [0.0, -9.81]
    case["materials"]["glass"] = material(0.5, mu)
    case["contact"] = {"normal": "hertz_2d", "tangential": "linear", "rolling": "none"}
    case["walls"] = [{"kind": "plane", "point": [0, 0], "normal": [0, 1], "material": "glass"}]
    sim = Simulation(case_from_dict(case))
    t_roll = v0 / (3.0 * mu * 9.81)  # v0 - μ g t = (2 μ g / R) t R  -> t = v0 / (3 μ g)
    sim.run(until=2.0 * t_roll)
    p = sim.particles
    assert p.velocity[0, 0] == pytest.approx(2.0 * v0 / 3.0, rel=2e-3)
    assert -p.angular_velocity[0, 2] * RADIUS == pytest.approx(2.0 * v0 / 3.0, rel=2e-3)
    m = p.mass[0]
    en = sim.energies()
    sliding = en["dissipated_sliding_friction"] + en["dissipated_tangential_damping"]
    assert sliding == pytest.approx(m * v0**2 / 6.0, rel=5e-3)
    assert abs(sim.energy_balance_error()) <= 1e-3 * m * v0**2


def agitated_bed(tmp_path, threads: int, steps: int, side: int = 60, dt: float = 4e-6, seed=3):
    """``side`` × ``side`` discs (R 2-2.5 mm, 2 mm thick) on a square lattice 0.1 mm apart,
    with random in-plane velocities of up to 0.5 m/s (a file with x y r vx vy columns), in a
    box under gravity (hertz_2d, friction, EPSD rolling): many collisions from the start."""
    rng = np.random.default_rng(seed)
    spacing = 0.0051
    xy = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) + 1.0
    xy = xy * spacing
    r = rng.uniform(0.002, 0.0025, xy.shape[0])
    v = rng.uniform(-0.35, 0.35, xy.shape)
    path = tmp_path / f"bed-{side}-{seed}.txt"
    np.savetxt(path, np.column_stack([xy, r, v]), header="x y r vx vy", comments="")
    top = (side + 1) * spacing
    case = {
        "simulation": {
            "time_step": dt,
            "end_time": 1.0,
            "dimension": 2,
            "thickness": 0.002,
            "seed": seed,
        },
        "domain": {"lower": [0.0, 0.0], "upper": [top, 2.0 * top]},
        "materials": {"glass": material(0.5, 0.4, 0.05)},
        "contact": {"normal": "hertz_2d", "tangential": "linear", "rolling": "epsd"},
        "walls": [{"kind": "box", "lower": [0, 0], "upper": [top, 2.0 * top], "material": "glass"}],
        "insertion": [{"kind": "file", "material": "glass", "path": str(path)}],
        "output": {"vtu": False},
    }
    sim = Simulation(case_from_dict(case), threads=threads)
    sim.run(steps=steps)
    return sim


def test_one_and_two_threads_give_identical_bits_in_2d(tmp_path) -> None:
    a = agitated_bed(tmp_path, 1, 400)
    b = agitated_bed(tmp_path, 2, 400)
    assert a.pairs.ngroups > 8
    assert a.contact_count > 150
    for name in ("position", "velocity", "angular_velocity", "force", "torque"):
        assert np.array_equal(getattr(a.particles, name), getattr(b.particles, name)), name
    assert a.energies() == b.energies()


def test_a_2d_bed_lists_the_pairs_of_a_brute_force_search(tmp_path) -> None:
    sim = agitated_bed(tmp_path, 1, 50, side=25)
    p = sim.particles
    built = sim.reference  # the positions of the last rebuild (particle order of the list)
    assert np.array_equal(built[:, 2], np.zeros(p.count))
    d = built[:, None, :2] - built[None, :, :2]
    dist = np.sqrt((d**2).sum(axis=2))
    cut = p.radius[:, None] + p.radius[None, :] + sim.skin + sim.extra
    close = zip(*np.nonzero(dist < cut), strict=True)
    brute = {(min(i, j), max(i, j)) for i, j in close if i != j}
    pb = sim.pairs
    pairs = zip(pb.i[: pb.count], pb.j[: pb.count], strict=True)
    listed = {(min(int(i), int(j)), max(int(i), int(j))) for i, j in pairs}
    assert listed == brute


def test_energy_ledger_of_an_agitated_2d_bed_closes_to_first_order(tmp_path) -> None:
    """The balance error is the first-order error of the dashpots (docs/architecture.md,
    "Balance"): halving the time step halves it (measured 1.39 % then 0.69 % of the
    dissipated energy at ~55 and ~110 steps per collision; 3D: 1 % at 50 steps)."""
    errors = []
    for dt in (4e-6, 2e-6):
        sim = agitated_bed(tmp_path, 1, int(round(4e-3 / dt)), side=20, dt=dt)
        en = sim.energies()
        dissipated = sum(v for k, v in en.items() if k.startswith("dissipated_"))
        assert en["dissipated_sliding_friction"] > 0.0
        assert en["dissipated_rolling_friction"] > 0.0
        errors.append(abs(sim.energy_balance_error()) / dissipated)
    assert errors[1] < 0.01
    assert 1.6 < errors[0] / errors[1] < 2.5


def test_3d_laws_are_refused_for_discs_and_hertz_2d_in_3d() -> None:
    case = disc_case(0.01, 0.5, 1e-5, [[0.0, 0.0]], [[0.0, 0.0]])
    case["contact"]["normal"] = "hertz"
    with pytest.raises(
        ConfigError, match=r"contact\.normal: model 'hertz' is not available in a 2D"
    ):
        case_from_dict(case)
    case["contact"] = {"normal": "hertz_2d", "tangential": "mindlin"}
    with pytest.raises(ConfigError, match=r"contact\.tangential: model 'mindlin'.*particle_shape"):
        case_from_dict(case)
    case["simulation"]["dimension"] = 3
    case["simulation"].pop("thickness")
    case["simulation"]["gravity"] = [0.0, 0.0, 0.0]
    case["domain"] = {"lower": [-0.1, -0.1, -0.1], "upper": [0.1, 0.1, 0.1]}
    case["insertion"][0]["positions"] = [[0.0, 0.0, 0.0]]
    case["insertion"][0]["velocities"] = [[0.0, 0.0, 0.0]]
    case["contact"] = {"normal": "hertz_2d"}
    with pytest.raises(ConfigError, match=r"contact\.normal: model 'hertz_2d' is a law of 2D"):
        case_from_dict(case)


def test_a_disc_rests_in_a_drum_circle_with_the_overlap_of_its_weight() -> None:
    """A disc at rest at the bottom of a circle (a cylinder wall along z, the drum): the line
    contact holds its weight, k δ = m g with k = (π/4) E* b (disc-wall E* as disc-disc)."""
    b, drum = 0.004, 0.05
    case = disc_case(b, 0.1, 2e-6, [[0.0, -(drum - RADIUS) + 1e-5]], [[0.0, 0.0]])
    case["simulation"]["gravity"] = [0.0, -9.81]
    case["walls"] = [{"kind": "cylinder", "center": [0, 0], "axis": [0, 0, 1], "radius": drum,
                      "material": "glass"}]  # fmt: skip
    sim = Simulation(case_from_dict(case))
    sim.run(until=0.05)
    p = sim.particles
    overlap = RADIUS - (drum - math.hypot(p.position[0, 0], p.position[0, 1]))
    k = 0.25 * math.pi * E_STAR * b
    assert overlap == pytest.approx(p.mass[0] * 9.81 / k, rel=1e-6)
    assert abs(p.position[0, 0]) < 1e-12 and p.position[0, 2] == 0.0


def test_periodic_x_strip_of_discs_lists_minimum_image_pairs_and_conserves_momentum(
    tmp_path,
) -> None:
    rng = np.random.default_rng(8)
    n_side = 12
    spacing = 0.0051
    xy = np.stack(np.meshgrid(np.arange(n_side), np.arange(n_side)), -1).reshape(-1, 2)
    xy = (xy + 0.5) * spacing
    v = rng.uniform(-0.3, 0.3, xy.shape)
    v -= v.mean(axis=0)
    path = tmp_path / "strip.txt"
    np.savetxt(path, np.column_stack([xy, np.full(len(xy), 0.0024), v]),
               header="x y r vx vy", comments="")  # fmt: skip
    width = n_side * spacing
    case = disc_case(0.002, 0.5, 4e-6, [[0, 0]], [[0, 0]])
    case["domain"] = {"lower": [0.0, -0.01], "upper": [width, width + 0.01],
                      "periodic": [True, False]}  # fmt: skip
    case["materials"]["glass"] = material(0.5, 0.4)
    case["contact"]["tangential"] = "linear"
    case["insertion"] = [{"kind": "file", "material": "glass", "path": str(path)}]
    sim = Simulation(case_from_dict(case))
    p0 = (sim.particles.mass[:, None] * sim.particles.velocity).sum(axis=0)
    sim.run(steps=600)
    p = sim.particles
    assert sim.contact_count > 10
    assert np.any(p.position[:, 0] < 0.5 * spacing)  # someone crossed the periodic boundary
    momentum = (p.mass[:, None] * p.velocity).sum(axis=0)
    scale = float(np.sum(p.mass * np.abs(p.velocity).sum(axis=1)))
    assert np.all(np.abs(momentum - p0) <= 1e-13 * scale)  # no walls: pairwise forces only
    built = sim.reference
    d = built[:, None, :2] - built[None, :, :2]
    d[..., 0] -= width * np.floor(d[..., 0] / width + 0.5)  # minimum image along x
    dist = np.sqrt((d**2).sum(axis=2))
    cut = p.radius[:, None] + p.radius[None, :] + sim.skin
    brute = {(i, j) for i, j in zip(*np.nonzero(dist < cut), strict=True) if i < j}
    pb = sim.pairs
    pairs = zip(pb.i[: pb.count], pb.j[: pb.count], strict=True)
    assert {(min(int(i), int(j)), max(int(i), int(j))) for i, j in pairs} == brute
