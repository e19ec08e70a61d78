"""Two-dimensional discs (issue 16): heat against closed forms and conservation.

References (not the code under test):

* Disc of thickness b: heat capacity C = ρ π R² b c.
* Rojek (2014)'s 2D bar (spec 2.4, "2D model: b is assumed as unity"): Q = k_p b ΔT between
  two touching discs, k_p the series (harmonic) mean; to a wall (the half bar, length R and
  section 2 R b): Q = 2 k b ΔT.
* The 2D thermal pipe: a strip of the contact length across the thickness, A_p = 2 a b with
  a the half length of the chord of the overlapping circles, Q = k A_p / d ΔT; to a line,
  a_w = sqrt(R² - (R - δ)²) and the particle's half pipe R - δ.
* Two equal discs: ΔT' = -2 H/C ΔT; explicit Euler multiplies ΔT by (1 - 2 H Δt/C) per step.
* A chain of discs between two lines at fixed temperatures is a chain of resistances in
  series (1/H of each link, the two wall links at the ends): the steady temperatures are
  T_0 + (T_1 - T_0) × (resistance from the cold wall) / (total resistance).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.io.checkpoint import checkpoint_name, write_checkpoint
from thermodem.models import registry

R = 0.002
RHO = 2500.0
K = 1.5
C = 800.0
MATERIAL = {
    "density": RHO,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "thermal_conductivity": K,
    "specific_heat": C,
    "restitution": 0.5,
    "sliding_friction": 0.4,
    "rolling_friction": 0.05,
}


pytestmark = pytest.mark.usefixtures("one_thread")


def disc_case(
    positions: list, temperatures: list, thermal: dict, thickness: float = 0.01, walls=()
) -> dict:
    return {
        "simulation": {
            "time_step": 1e-5,
            "end_time": 1e6,
            "dimension": 2,
            "thickness": thickness,
            "gravity": [0.0, 0.0],
        },
        "domain": {"lower": [-0.05, -0.05], "upper": [0.05, 0.05]},
        "materials": {"glass": dict(MATERIAL)},
        "walls": list(walls),
        "insertion": [
            {
                "kind": "list",
                "material": "glass",
                "positions": positions,
                "radius": R,
                "temperatures": temperatures,
            }
        ],
        "thermal": thermal,
        "output": {"vtu": False},
    }


def by_gid(sim: Simulation) -> np.ndarray:
    return sim.particles.temperature[np.argsort(sim.particles.global_id)]


def chord_half_length(d: float) -> float:
    """Half length of the common chord of two circles of radius R whose centres are d apart."""
    return math.sqrt(R * R - 0.25 * d * d)


@pytest.mark.parametrize("model", ["rojek2014", "thermal_pipe"])
@pytest.mark.parametrize("thickness", [1.0, 0.004])
def test_two_discs_exchange_heat_through_the_2d_conductance(model: str, thickness: float) -> None:
    d = 2.0 * R - 1e-5
    h = K * thickness if model == "rojek2014" else K * 2.0 * chord_half_length(d) * thickness / d
    cap = RHO * math.pi * R**2 * thickness * C
    dt_th = 0.01 * cap / h
    thermal = {
        "frozen_mechanics": True,
        "time_step": dt_th,
        "contact_radius": "geometric",
        "direct_conduction": model,
    }
    sim = Simulation(
        case_from_dict(disc_case([[0, 0], [d, 0]], [300.0, 400.0], thermal, thickness))
    )
    assert sim.thermal.conductance_sum[0] == pytest.approx(h, rel=1e-12)
    steps = 50
    sim.run(steps=steps)
    t = by_gid(sim)
    expected = 100.0 * (1.0 - 2.0 * h * dt_th / cap) ** steps
    assert t[1] - t[0] == pytest.approx(expected, rel=1e-10)
    assert t.sum() == pytest.approx(700.0, rel=1e-15)  # what one disc loses the other gains
    # per unit thickness: the temperatures do not depend on b (H and C both scale with it)
    exact = 100.0 * math.exp(-2.0 * h / cap * steps * dt_th)
    # explicit Euler at Δt = 0.01 C/H: relative error ~ n (2 H Δt/C)² / 2 = 1 %
    assert t[1] - t[0] == pytest.approx(exact, rel=0.015)


def chain_case(model: str, n: int, spacing: float, wall_overlap: float) -> dict:
    x0 = R - wall_overlap
    xs = [x0 + k * spacing for k in range(n)]
    length = xs[-1] + x0
    walls = [
        {"kind": "plane", "point": [0, 0], "normal": [1, 0], "material": "glass",
         "thermal": {"kind": "fixed", "temperature": 300.0}},
        {"kind": "plane", "point": [length, 0], "normal": [-1, 0], "material": "glass",
         "thermal": {"kind": "fixed", "temperature": 400.0}},
    ]  # fmt: skip
    thermal = {
        "frozen_mechanics": True,
        "time_step": 1.0,  # set below from the conductances
        "contact_radius": "geometric",
        "direct_conduction": model,
    }
    case = disc_case([[x, 0.0] for x in xs], [350.0] * n, thermal, 0.003, walls)
    case["domain"] = {"lower": [-0.01, -0.05], "upper": [length + 0.01, 0.05]}
    return case


@pytest.mark.parametrize("model", ["rojek2014", "thermal_pipe"])
def test_chain_of_discs_between_fixed_lines_reaches_the_series_resistance_profile(
    model: str,
) -> None:
    n, b = 7, 0.003
    spacing, wall_overlap = 2.0 * R - 2e-5, 1.5e-5
    if model == "rojek2014":
        link, wall = 1.0 / (K * b), 1.0 / (2.0 * K * b)
    else:
        a = chord_half_length(spacing)
        a_w = math.sqrt(R**2 - (R - wall_overlap) ** 2)
        link = spacing / (K * 2.0 * a * b)
        wall = (R - wall_overlap) / (K * 2.0 * a_w * b)
    total = 2.0 * wall + (n - 1) * link
    expected = 300.0 + 100.0 * np.array([(wall + k * link) / total for k in range(n)])
    case = chain_case(model, n, spacing, wall_overlap)
    cap = RHO * math.pi * R**2 * b * C
    dt = 0.4 * cap / (2.0 / min(link, wall))  # below the explicit limit C/ΣH
    case["thermal"]["time_step"] = dt
    sim = Simulation(case_from_dict(case))
    # the slowest mode of the chain decays by (1 - λ_min Δt) per step, λ_min the smallest
    # eigenvalue of the conductance matrix over C: run until it is down by 1e-13
    g = np.zeros((n, n))
    for k in range(n - 1):
        g[k, k] += 1.0 / link
        g[k + 1, k + 1] += 1.0 / link
        g[k, k + 1] = g[k + 1, k] = -1.0 / link
    g[0, 0] += 1.0 / wall
    g[-1, -1] += 1.0 / wall
    rate = float(np.linalg.eigvalsh(g / cap).min())
    sim.run(steps=int(math.log(1e13) / -math.log1p(-rate * dt)) + 1)
    np.testing.assert_allclose(by_gid(sim), expected, rtol=1e-10)
    # steady: what the hot line gives, the cold line takes
    q = sim.particles.heat_rate_by_mechanism
    assert abs(q.sum()) < 1e-9 * 100.0 / total
    assert abs(sim.thermal.balance_error()) < 1e-12 * sim.thermal.thermal_energy()


def test_disc_sources_heat_the_rim_and_the_area_of_a_disc() -> None:
    """Flux q on the rim 2π R b, power density s on the area π R² b: dT/dt = 2 q/(ρ R c) and
    s/(ρ c), whatever the thickness."""
    q, s, t_end = 500.0, 2.0e5, 10.0
    thermal = {
        "frozen_mechanics": True,
        "time_step": 0.5,
        "direct_conduction": "none",
        "contact_radius": "none",
        "heat_flux": [{"select": {"ids": [0]}, "flux": q}],
        "volumetric_source": [{"select": {"ids": [1]}, "power_density": s}],
    }
    case = disc_case([[0, 0], [0.02, 0]], [300.0, 300.0], thermal, thickness=0.007)
    sim = Simulation(case_from_dict(case))
    sim.run(until=t_end)
    t = by_gid(sim)
    assert t[0] == pytest.approx(300.0 + 2.0 * q * t_end / (RHO * R * C), rel=1e-12)
    assert t[1] == pytest.approx(300.0 + s * t_end / (RHO * C), rel=1e-12)


def heated_bed(tmp_path: Path, side: int = 12, pour: bool = True) -> dict:
    """Discs with random velocities and temperatures above a hot line (y = 0, 400 K) in a
    box; optionally a pour entry adding discs later: contacts form and break, heat flows."""
    rng = np.random.default_rng(4)
    spacing = 2.0 * R + 1e-4
    xy = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) * spacing
    xy += [spacing, R + 5e-5]  # the first row just above the hot floor
    v = rng.uniform(-0.3, 0.3, xy.shape)
    t = rng.uniform(290.0, 330.0, xy.shape[0])
    path = tmp_path / "bed.txt"
    np.savetxt(path, np.column_stack([xy, np.full(len(t), R), v, t]),
               header="x y radius vx vy temperature", comments="")  # fmt: skip
    top = (side + 1) * spacing
    case = disc_case([[0, 0]], [300.0], {}, thickness=0.002)
    case["simulation"].update(time_step=5e-6, gravity=[0.0, -9.81])
    case["domain"] = {"lower": [0.0, 0.0], "upper": [top, 2.0 * top]}
    case["walls"] = [
        {"kind": "box", "lower": [0, 0], "upper": [top, 2 * top], "material": "glass",
         "thermal": {"kind": "fixed", "temperature": 400.0}},
    ]  # fmt: skip
    case["contact"] = {"normal": "hertz_2d", "tangential": "linear", "rolling": "epsd"}
    case["insertion"] = [{"kind": "file", "material": "glass", "path": str(path)}]
    if pour:
        case["insertion"].append(
            {"kind": "pour", "material": "glass", "rate": 20000.0, "interval": 5e-4,
             "start_time": 1e-4, "end_time": 2e-3, "temperature": 350.0,
             "distribution": {"kind": "mono", "radius": R}, "velocity": [0.0, -0.5],
             "region": {"kind": "box", "lower": [0.0, 1.5 * top], "upper": [top, 2.0 * top]}}
        )  # fmt: skip
    case["thermal"] = {
        "contact_radius": "geometric",
        "direct_conduction": "thermal_pipe",
        "substeps": 2,
    }
    return case


def test_heat_ledger_of_a_moving_2d_bed_closes_to_round_off(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(heated_bed(tmp_path)))
    sim.run(steps=600)
    th = sim.thermal
    assert sim.pourers[0].inserted > 0
    assert th.cumulative["heat_in_wall_direct_conduction"] > 0.0
    assert abs(th.balance_error()) <= 1e-12 * th.thermal_energy()


def test_2d_restart_is_bit_identical(tmp_path: Path) -> None:
    case = heated_bed(tmp_path)
    reference = Simulation(case_from_dict(case))
    reference.run(steps=500)
    first = Simulation(case_from_dict(case))
    first.run(steps=173)
    path = write_checkpoint(first, tmp_path / checkpoint_name(first.step_count))
    del first
    second = Simulation.from_checkpoint(path)
    assert second.planar and second.disc_thickness == 0.002
    second.run(steps=327)
    for name, arr in reference.particles.arrays().items():
        assert np.array_equal(arr, getattr(second.particles, name)), name
    pa, pb = reference.pairs, second.pairs
    assert pa.count == pb.count and np.array_equal(pa.history[: pa.count], pb.history[: pb.count])
    assert reference.energies() == second.energies()
    assert reference.thermal.balance_error() == second.thermal.balance_error()


def models_without_2d_form() -> list[tuple[str, str]]:
    families = ("contact_radius", "direct_conduction", "indirect_conduction", "radiation")
    return [
        (m.family, m.name)
        for m in registry.all_models()
        if m.family in families and "disc" not in m.planar
    ]


@pytest.mark.parametrize(("family", "name"), models_without_2d_form())
def test_a_thermal_model_without_a_2d_form_is_refused_for_discs_naming_it(
    family: str, name: str
) -> None:
    spec = registry.get(family, name)
    thermal = {"direct_conduction": "rojek2014", family: {"model": name, **spec.example_params}}
    case = disc_case([[0, 0]], [300.0], thermal)
    with pytest.raises(ConfigError) as err:
        case_from_dict(case)
    message = str(err.value)
    assert f"thermal.{family}: model {name!r} is not available in a 2D case of discs" in message


def test_the_3d_default_direct_conduction_is_refused_for_discs_as_the_default() -> None:
    case = disc_case([[0, 0]], [300.0], {"contact_radius": "geometric"})
    with pytest.raises(ConfigError, match=r"thermal\.direct_conduction: model "
                       r"'batchelor_obrien_simple' \(the default: name a model of 2D\) is not "
                       r"available in a 2D case of discs .*rojek2014, thermal_pipe"):  # fmt: skip
        case_from_dict(case)


def test_every_model_says_whether_it_supports_2d() -> None:
    for spec in registry.all_models():
        assert set(spec.planar) <= {"disc", "sphere"}
        if spec.only_2d:
            assert spec.planar == ("disc",)
    names = {(m.family, m.name) for m in registry.all_models() if "disc" in m.planar}
    assert ("direct_conduction", "rojek2014") in names
    assert ("direct_conduction", "thermal_pipe") in names
    assert ("contact_radius", "geometric") in names
    assert ("direct_conduction", "batchelor_obrien_simple") not in names


@pytest.mark.parametrize("model", ["rojek2014", "thermal_pipe"])
def test_square_lattice_of_discs_has_the_lattice_sum_conductivity(
    tmp_path: Path, model: str
) -> None:
    """A square lattice (spacing a) of touching discs, periodic along y: in steady state the
    temperature is linear along x and each disc passes H ΔT to its x neighbour, so
    k_eff = H a / (a b) = H / b (engine/etc.py; its cross-section in 2D is width × b). For
    Rojek's bars H = k b: k_eff = k, the bars tile the plane; for the pipe H = k 2 a_c b / a."""
    from thermodem.engine.etc import effective_conductivity

    b, a = 0.003, 2.0 * R - 2e-5
    nx, ny = 14, 4
    rows = [f"{(i + 0.5) * a!r} {(j + 0.5) * a!r} {R!r}" for i in range(nx) for j in range(ny)]
    path = tmp_path / "square.txt"
    path.write_text("x y r\n" + "\n".join(rows) + "\n")
    case = disc_case([[0, 0]], [300.0], {}, thickness=b)
    case["domain"] = {"lower": [-0.01, 0.0], "upper": [nx * a + 0.01, ny * a],
                      "periodic": [False, True]}  # fmt: skip
    case["insertion"] = [{"kind": "file", "material": "glass", "path": str(path)}]
    case["thermal"] = {"frozen_mechanics": True, "time_step": 1.0,
                       "contact_radius": "geometric", "direct_conduction": model}  # fmt: skip
    sim = Simulation(case_from_dict(case))
    assert sim.contact_count == 2 * nx * ny - ny  # x bonds (nx - 1) ny, y bonds nx ny
    (res,) = effective_conductivity(sim, "x")
    h = K * b if model == "rojek2014" else K * 2.0 * chord_half_length(a) * b / a
    assert res.area == pytest.approx(ny * a * b, rel=1e-12)
    assert res.conductivity == pytest.approx(h / b, rel=1e-9)
    with pytest.raises(ConfigError, match="allowed: letters of 'xy'"):
        effective_conductivity(sim, "z")


def test_region_selections_of_a_2d_case_take_x_y_boxes() -> None:
    """A fixed temperature and a flux selected by [x, y] boxes (read with z = 0, faces
    included) hold exactly for the discs inside, in a moving bed (the selections are
    classified at neighbour-list builds on the x-y axes)."""
    thermal = {
        "contact_radius": "geometric",
        "direct_conduction": "rojek2014",
        "fixed_temperature": [
            {"select": {"region": {"lower": [-0.01, -0.01], "upper": [0.001, 0.01]}},
             "temperature": 500.0}
        ],
        "heat_flux": [{"select": {"region": {"lower": [0.02, -0.01], "upper": [0.03, 0.01]}},
                       "flux": 1000.0}],
    }  # fmt: skip
    case = disc_case([[0, 0], [0.025, 0], [0.04, 0]], [300.0] * 3, thermal, thickness=0.002)
    case["insertion"][0]["velocities"] = [[0.0, 0.0], [0.0, 0.0], [-0.5, 0.0]]
    sim = Simulation(case_from_dict(case))
    sim.run(steps=200)  # disc 2 moves 1 mm: still outside both boxes
    t = by_gid(sim)
    assert t[0] == 500.0
    q = 1000.0 * 2.0 * math.pi * R * 0.002
    cap = RHO * math.pi * R**2 * 0.002 * C
    assert t[1] == pytest.approx(300.0 + q * sim.time / cap, rel=1e-9)
    assert t[2] == 300.0


def test_a_disc_sliding_until_it_rolls_generates_a_sixth_of_m_v0_squared() -> None:
    """Heat generation for discs (hertz_2d, linear tangential): a disc launched without spin
    on a rough line slides until it rolls at 2 v0/3 and loses m v0²/6 of kinetic energy, all
    by Coulomb sliding (test_two_dimensional.py's rolling disc; a sphere: m v0²/7). With
    ``mechanical_dissipation`` and χ the sliding heat is χ m v0²/6, every joule of it in the
    ledger (an adiabatic line: all of it into the disc), and the disc's temperature rises by
    that heat over its capacity ρ π R² b c."""
    v0, chi, b = 0.3, 0.8, 0.01
    material = dict(MATERIAL, rolling_friction=0.0)
    case = disc_case([[0.0, R - 1e-6]], [300.0], {
        "direct_conduction": "rojek2014",
        "heat_generation": {"model": "mechanical_dissipation", "conversion_fraction": chi},
    }, thickness=b)  # fmt: skip
    case["materials"]["glass"] = material
    case["simulation"].update(time_step=2e-6, gravity=[0.0, -9.81])
    case["contact"] = {"normal": "hertz_2d", "tangential": "linear", "rolling": "none"}
    case["insertion"][0]["velocities"] = [[v0, 0.0]]
    case["walls"] = [{"kind": "plane", "point": [0, 0], "normal": [0, 1], "material": "glass"}]
    sim = Simulation(case_from_dict(case))
    mu = material["sliding_friction"]
    sim.run(until=2.0 * v0 / (3.0 * mu * 9.81))  # twice the time to rolling
    m = sim.particles.mass[0]
    r = sim.report()
    en = sim.energies()

    def generated(mechanism: str) -> float:  # applied + accumulated, not yet applied
        return r[f"heat_in_generation_{mechanism}"] + r[f"heat_pending_generation_{mechanism}"]

    friction = generated("sliding_friction")
    assert friction == pytest.approx(chi * en["dissipated_sliding_friction"], rel=1e-12)
    sliding = friction + generated("tangential_damping")
    assert sliding == pytest.approx(chi * m * v0**2 / 6.0, rel=5e-3)
    assert r["heat_to_walls_generation_sliding_friction"] == 0.0
    capacity = RHO * math.pi * R * R * b * C
    heat_in = sum(r[f"heat_in_generation_{g}"] for g in ("sliding_friction", "tangential_damping",
                                                          "normal_damping"))  # fmt: skip
    assert (sim.particles.temperature[0] - 300.0) * capacity == pytest.approx(heat_in, rel=1e-9)
