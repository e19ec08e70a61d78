"""Radiation beyond the fixed environment (models/thermal/radiation.py, engine/fields.py).

- the continuum models of Zhou et al. (2009) and Krause et al. (2017) on a small lattice
  against hand-evaluated values (the centre particle of a 3 × 3 × 3 lattice), and on a random
  polydisperse bed of two materials against a brute-force evaluation of the spec's formulas
  (every pair, written here);
- the exposure of radiation.surroundings by the local porosity; particle–wall radiation;
- the explicit stability limit with radiation and convection together at 1500 K;
- the ledger, a restart and 1 vs 2 threads (bit-identical) with the neighbourhood set.
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.errors import SimulationError
from thermodem.kernels import fields as fk
from thermodem.models.thermal.radiation import STEFAN_BOLTZMANN as SIGMA
from thermodem.state import heat

R = 1e-3
EPS = 0.8
MATERIAL = {
    "density": 3000.0,
    "youngs_modulus": 1e8,
    "poisson_ratio": 0.3,
    "thermal_conductivity": 2.0,
    "specific_heat": 900.0,
    "emissivity": EPS,
}


def _write(path: Path, pos: np.ndarray, radius: np.ndarray, temp: np.ndarray) -> str:
    rows = ["x y z radius temperature"]
    rows += [
        " ".join(repr(float(v)) for v in (*x, r, t))
        for x, r, t in zip(pos, radius, temp, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _case(files: list[tuple[str, str]], radiation: dict, extra: dict | None = None) -> dict:
    thermal = {
        "direct_conduction": "none",
        "radiation": radiation,
        "frozen_mechanics": True,
        "time_step": 1e-3,
    }
    thermal.update(extra or {})
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [-0.02, -0.02, -0.02], "upper": [0.03, 0.03, 0.03]},
        "materials": {"a": dict(MATERIAL), "b": dict(MATERIAL, emissivity=0.5)},
        "insertion": [{"kind": "file", "material": m, "path": f} for m, f in files],
        "thermal": thermal,
    }


def _by_gid(sim: Simulation, values: np.ndarray) -> np.ndarray:
    return values[np.argsort(sim.particles.global_id)]


def _lattice(tmp_path: Path) -> tuple[str, np.ndarray]:
    """3 × 3 × 3, spacing 2.1 R: from the centre, 6 faces at 2.1 R, 12 edges at 2.97 R (in
    the sphere of 3 R), 8 corners at 3.64 R (outside). Centre 1000 K, faces 900 K, edges
    800 K, corners 300 K."""
    grid = np.stack(np.meshgrid(*(np.arange(3),) * 3, indexing="ij"), -1).reshape(-1, 3)
    off = np.abs(grid - 1).sum(axis=1)  # 0 centre, 1 face, 2 edge, 3 corner
    temp = np.array([1000.0, 900.0, 800.0, 300.0])[off]
    pos = grid * 2.1 * R
    return _write(tmp_path / "lattice.txt", pos, np.full(27, R), temp), off


def test_krause_on_a_lattice_against_a_hand_evaluation(tmp_path: Path) -> None:
    path, off = _lattice(tmp_path)
    sim = Simulation(case_from_dict(_case([("a", path)], {"model": "krause2017"})))
    q = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    centre = int(np.nonzero(off == 0)[0][0])
    te4 = (6 * 900.0**4 + 12 * 800.0**4) / 18  # equal ε A: T_e⁴ = mean of T_j⁴
    area = 4 * math.pi * R**2
    assert q[centre] == pytest.approx(EPS * area * SIGMA * (te4 - 1000.0**4), rel=1e-12)
    # a corner sees its 3 face-adjacent (edges of the lattice, 800 K) at 2.1 R and the 3
    # face centres (900 K) at 2.97 R
    corner = int(np.nonzero(off == 3)[0][0])
    te4 = (3 * 800.0**4 + 3 * 900.0**4) / 6
    assert q[corner] == pytest.approx(EPS * area * SIGMA * (te4 - 300.0**4), rel=1e-12)
    # Σ ε_j A_j / 2 over the sphere: 18 neighbours of the centre, 6 of a corner
    area_sum = _by_gid(sim, sim.thermal.fields[fk.F_NEIGHBOUR_AREA])
    half = EPS * 2 * math.pi * R**2
    assert area_sum[centre] == pytest.approx(18 * half, rel=1e-14)
    assert area_sum[corner] == pytest.approx(6 * half, rel=1e-14)


def test_zhou_on_a_lattice_against_a_hand_evaluation(tmp_path: Path) -> None:
    path, off = _lattice(tmp_path)
    extra = {"fluid": {"temperature": 300.0}, "porosity": 0.4}
    sim = Simulation(case_from_dict(_case([("a", path)], {"model": "zhou2009"}, extra)))
    q = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    centre = int(np.nonzero(off == 0)[0][0])
    t_e = 0.4 * 300.0 + 0.6 * (6 * 900.0 + 12 * 800.0) / 18  # = 620 K
    assert t_e == pytest.approx(620.0)
    area = 4 * math.pi * R**2
    assert q[centre] == pytest.approx(EPS * area * SIGMA * (620.0**4 - 1000.0**4), rel=1e-12)
    count = _by_gid(sim, sim.thermal.fields[fk.F_NEIGHBOURS])
    assert count[centre] == 18


def _random_bed(tmp_path: Path, n: int = 40, seed: int = 4):  # noqa: ANN202
    rng = np.random.default_rng(seed)
    pos, rad = [], []
    while len(pos) < n:
        x = rng.uniform(0.0, 0.008, 3)
        r = rng.uniform(0.6 * R, 1.2 * R)
        if all(np.linalg.norm(x - p) > r + q for p, q in zip(pos, rad, strict=True)):
            pos.append(x)
            rad.append(r)
    pos, rad = np.array(pos), np.array(rad)
    temp = rng.uniform(500.0, 1400.0, n)
    half = n // 2
    files = [
        ("a", _write(tmp_path / "a.txt", pos[:half], rad[:half], temp[:half])),
        ("b", _write(tmp_path / "b.txt", pos[half:], rad[half:], temp[half:])),
    ]
    emissivity = np.where(np.arange(n) < half, EPS, 0.5)
    return files, pos, rad, temp, emissivity


@pytest.mark.parametrize("model", ["krause2017", "zhou2009"])
def test_continuum_models_on_a_polydisperse_bed_against_brute_force(
    tmp_path: Path, model: str
) -> None:
    files, pos, rad, temp, emis = _random_bed(tmp_path)
    ratio = 2.5
    extra = {"fluid": {"temperature": 450.0}, "porosity": 0.55} if model == "zhou2009" else {}
    sim = Simulation(case_from_dict(_case(files, {"model": model, "radius_ratio": ratio}, extra)))
    got = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    n = len(pos)
    for i in range(n):
        near = [j for j in range(n) if j != i and np.linalg.norm(pos[j] - pos[i]) < ratio * rad[i]]
        if model == "krause2017":
            w = np.array([emis[j] * 4 * math.pi * rad[j] ** 2 / 2 for j in near])
            t4 = np.array([temp[j] ** 4 for j in near])
            te4 = (w * t4).sum() / w.sum() if near else 0.0
            env = 1.0 if near else 0.0
        else:
            mean = np.mean(temp[near]) if near else 450.0
            te4 = (0.55 * 450.0 + 0.45 * mean) ** 4 if near else 450.0**4
            env = 1.0
        area = 4 * math.pi * rad[i] ** 2
        expected = emis[i] * area * SIGMA * env * (te4 - temp[i] ** 4)
        assert got[i] == pytest.approx(expected, rel=1e-11, abs=1e-15), i
    assert sim.thermal.field_provider.neighbourhood.count > n  # pairs listed


def test_krause_without_neighbours_uses_the_optional_environment(tmp_path: Path) -> None:
    path = _write(
        tmp_path / "one.txt", np.array([[0.0, 0.0, 0.0]]), np.array([R]), np.array([900.0])
    )
    sim = Simulation(case_from_dict(_case([("a", path)], {"model": "krause2017"})))
    assert sim.particles.heat_rate_by_mechanism[0, heat.M_RADIATION] == 0.0
    assert sim.thermal.conductance_sum[0] == 0.0
    case = _case([("a", path)], {"model": "krause2017", "environment_temperature": 300.0})
    sim = Simulation(case_from_dict(case))
    area = 4 * math.pi * R**2
    q = sim.particles.heat_rate_by_mechanism[0, heat.M_RADIATION]
    assert q == pytest.approx(EPS * area * SIGMA * (300.0**4 - 900.0**4), rel=1e-12)


# --------------------------------------------------------------- exposure, walls
@pytest.mark.parametrize(
    ("exposure", "factor"),
    [
        ({"exposure": "all"}, 1.0),
        ({"exposure": "fraction"}, 0.45),
        ({"exposure": "threshold", "threshold": 0.4}, 1.0),
        ({"exposure": "threshold", "threshold": 0.5}, 0.0),
    ],
    ids=["all", "fraction", "threshold-exposed", "threshold-hidden"],
)
def test_surroundings_exposure_by_local_porosity(
    tmp_path: Path, exposure: dict, factor: float
) -> None:
    path = _write(
        tmp_path / "one.txt", np.array([[0.0, 0.0, 0.0]]), np.array([R]), np.array([900.0])
    )
    radiation = {"model": "surroundings", "environment_temperature": 300.0, **exposure}
    extra = {"porosity": 0.45} if exposure["exposure"] != "all" else {}
    sim = Simulation(case_from_dict(_case([("a", path)], radiation, extra)))
    area = 4 * math.pi * R**2
    q = sim.particles.heat_rate_by_mechanism[0, heat.M_RADIATION]
    assert q == pytest.approx(
        factor * EPS * area * SIGMA * (300.0**4 - 900.0**4), rel=1e-12, abs=0.0
    )
    assert sim.thermal.conductance_sum[0] == pytest.approx(
        factor * 4 * EPS * area * SIGMA * 900.0**3, rel=1e-12, abs=0.0
    )


def test_exposure_by_shell_porosity_picks_the_free_surface(tmp_path: Path) -> None:
    """Two layers of a simple cubic packing on a floor: a quarter of the top layer's shell
    is above the bed."""
    grid = np.stack(np.meshgrid(np.arange(6), np.arange(6), np.arange(2), indexing="ij"), -1)
    pos = grid.reshape(-1, 3) * 2.0 * R + R
    temp = np.full(len(pos), 900.0)
    path = _write(tmp_path / "bed.txt", pos, np.full(len(pos), R), temp)
    radiation = {
        "model": "surroundings",
        "environment_temperature": 300.0,
        "exposure": "threshold",
        "threshold": 0.55,
    }
    case = _case([("a", path)], radiation, {"porosity": {"kind": "shell"}})
    case["walls"] = [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "a"}]
    sim = Simulation(case_from_dict(case))
    q = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    eps = _by_gid(sim, sim.thermal.fields[0])
    top = pos[:, 2] > 2 * R
    inner = (pos[:, 0] > 2 * R) & (pos[:, 0] < 10 * R) & (pos[:, 1] > 2 * R) & (pos[:, 1] < 10 * R)
    # top: 1 − 0.741 × 0.524 ≈ 0.61 (the shell above the bed is void), bottom: ≈ 0.48
    assert np.all(eps[top & inner] > 0.55) and np.all(eps[~top & inner] < 0.55)
    assert np.all(q[top & inner] < 0.0) and np.all(q[~top & inner] == 0.0)


def test_particle_wall_radiation(tmp_path: Path) -> None:
    # particle 0: surface gap 0.5 R to the hot floor (in view), particle 1: 5 R above it
    pos = np.array([[0.0, 0.0, 1.5 * R], [0.01, 0.0, 6.0 * R]])
    path = _write(tmp_path / "two.txt", pos, np.full(2, R), np.array([600.0, 600.0]))
    radiation = {
        "model": "surroundings",
        "environment_temperature": 300.0,
        "walls": True,
        "wall_view_factor": 0.5,
        "wall_range": 1.0,
    }
    case = _case([("a", path)], radiation)
    wall = {
        "kind": "plane",
        "point": [0, 0, 0],
        "normal": [0, 0, 1],
        "material": "a",
        "thermal": {"kind": "fixed", "temperature": 1200.0},
    }
    case["walls"] = [wall]
    sim = Simulation(case_from_dict(case))
    q = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    g = _by_gid(sim, sim.thermal.conductance_sum)
    c = EPS * 4 * math.pi * R**2 * SIGMA
    assert q[0] == pytest.approx(
        c * (0.5 * (1200.0**4 - 600.0**4) + 0.5 * (300.0**4 - 600.0**4)), rel=1e-12
    )
    assert q[1] == pytest.approx(c * (300.0**4 - 600.0**4), rel=1e-12)
    assert g == pytest.approx([4 * c * 600.0**3] * 2, rel=1e-12)
    # the heat from the wall is ledgered with the radiation
    sim.step()
    th = sim.thermal
    assert abs(th.balance_error()) <= 1e-12 * th.initial_energy
    # an adiabatic wall exchanges nothing: the particle sees only the environment
    case["walls"] = [{k: v for k, v in wall.items() if k != "thermal"}]
    sim = Simulation(case_from_dict(case))
    q = _by_gid(sim, sim.particles.heat_rate_by_mechanism[:, heat.M_RADIATION])
    assert q[0] == pytest.approx(c * (300.0**4 - 600.0**4), rel=1e-12)


def test_three_walls_in_a_corner_share_the_whole_surface(tmp_path: Path) -> None:
    path = _write(
        tmp_path / "one.txt",
        np.array([[1.2 * R, 1.2 * R, 1.2 * R]]),
        np.array([R]),
        np.array([600.0]),
    )
    radiation = {"model": "krause2017", "walls": True}
    case = _case([("a", path)], radiation)
    temps = (1000.0, 800.0, 500.0)
    case["walls"] = [
        {
            "kind": "plane",
            "point": [0, 0, 0],
            "normal": n,
            "material": "a",
            "thermal": {"kind": "fixed", "temperature": t},
        }
        for n, t in zip(([1, 0, 0], [0, 1, 0], [0, 0, 1]), temps, strict=True)
    ]
    sim = Simulation(case_from_dict(case))
    c = EPS * 4 * math.pi * R**2 * SIGMA
    expected = c * sum((t**4 - 600.0**4) / 3 for t in temps)  # 3 × 1/2 scaled to 1
    assert sim.particles.heat_rate_by_mechanism[0, heat.M_RADIATION] == pytest.approx(
        expected, rel=1e-12
    )


# ------------------------------------------------------------- stability, ledger
def test_explicit_limit_with_radiation_and_convection_at_1500_k(tmp_path: Path) -> None:
    """One sphere at 1500 K between two neighbours (Krause) in a gas flow (Ranz & Marshall):
    ΣG = 4 ε σ A T³ + h A; a step 5 % above m c / ΣG is refused, 5 % below cools
    monotonically."""
    pos = np.array([[0.0, 0.0, 0.0], [2.5 * R, 0.0, 0.0], [-2.5 * R, 0.0, 0.0]])
    temp = np.array([1500.0, 700.0, 700.0])
    path = _write(tmp_path / "three.txt", pos, np.array([R, R, R]), temp)
    extra = {
        "convection": "ranz_marshall1952",
        "fluid": {"temperature": 300.0, "velocity": [0, 0, 3.0]},
    }
    case = _case([("a", path)], {"model": "krause2017"}, extra)
    sim = Simulation(case_from_dict(case))
    gid = np.argsort(sim.particles.global_id)
    area = 4 * math.pi * R**2
    rho_g = 101325.0 * 0.0289647 / (8.314462618 * 300.0)
    re = rho_g * 3.0 * 2 * R / 1.846e-5
    nu = 2 + 0.6 * re**0.5 * (1007.0 * 1.846e-5 / 0.0263) ** (1 / 3)
    h_a = 2 * math.pi * R * 0.0263 * nu
    g_rad = 4 * EPS * SIGMA * area * 1500.0**3
    assert sim.thermal.conductance_sum[gid[0]] == pytest.approx(g_rad + h_a, rel=1e-12)
    mass = MATERIAL["density"] * 4 / 3 * math.pi * R**3
    limit = mass * MATERIAL["specific_heat"] / (g_rad + h_a)
    for fraction, ok in ((1.05, False), (0.95, True)):
        case["thermal"]["time_step"] = fraction * limit
        sim = Simulation(case_from_dict(case))
        if not ok:
            with pytest.raises(SimulationError, match="explicit Euler limit"):
                sim.step()
            continue
        temps = []
        for _ in range(40):
            sim.step()
            temps.append(float(_by_gid(sim, sim.particles.temperature)[0]))
        assert np.all(np.diff(temps) < 0.0) and temps[-1] > 300.0


def test_ledger_of_a_lattice_with_continuum_radiation(tmp_path: Path) -> None:
    path, _ = _lattice(tmp_path)
    sim = Simulation(
        case_from_dict(
            _case([("a", path)], {"model": "krause2017", "environment_temperature": 300.0})
        )
    )
    for _ in range(20):
        sim.step()
    th = sim.thermal
    assert th.cumulative["heat_in_radiation"] != 0.0  # not pairwise: ledgered as boundary
    assert abs(th.balance_error()) <= 1e-12 * th.initial_energy


# -------------------------------------------------- restart and threads, bit-identical
def _moving_case(tmp_path: Path, n_side: int) -> dict:
    rng = np.random.default_rng(7)
    grid = np.stack(np.meshgrid(*(np.arange(n_side),) * 2, np.arange(4), indexing="ij"), -1)
    pos = grid.reshape(-1, 3) * 2.02 * R + R + rng.uniform(-0.005, 0.005, (grid.size // 3, 3)) * R
    temp = rng.uniform(600.0, 1200.0, len(pos))
    path = _write(tmp_path / "bed.txt", pos, np.full(len(pos), R), temp)
    side = n_side * 2.02 * R + 2 * R
    case = _case(
        [("a", path)],
        {"model": "krause2017", "walls": True},
        {
            "convection": "gunn1978",
            "porosity": {"kind": "shell"},
            "fluid": {"temperature": 300.0, "velocity": [0.0, 0.0, 1.0]},
            "range_skin": 0.02 * R,
            "substeps": 2,
        },
    )
    case["thermal"].pop("frozen_mechanics")
    case["thermal"].pop("time_step")
    case["simulation"]["gravity"] = [0, 0, -9.81]
    case["domain"] = {"lower": [0, 0, 0], "upper": [side, side, 0.02]}
    case["neighbors"] = {"skin": 0.05 * R}
    case["walls"] = [
        {
            "kind": "box",
            "lower": [0, 0, 0],
            "upper": [side, side, 0.02],
            "material": "a",
            "open_top": True,
            "thermal": {"kind": "fixed", "temperature": 1000.0},
        }
    ]
    return case


def test_restart_with_the_neighbourhood_set_is_bit_identical(tmp_path: Path) -> None:
    from thermodem.io.checkpoint import checkpoint_name as name
    from thermodem.io.checkpoint import write_checkpoint as write

    case = _moving_case(tmp_path, 5)
    reference = Simulation(case_from_dict(case))
    reference.run(steps=300)
    first = Simulation(case_from_dict(case))
    first.run(steps=101)
    path = write(first, tmp_path / name(first.step_count))
    second = Simulation.from_checkpoint(path)
    second.run(steps=199)
    for field in ("position", "velocity", "temperature", "heat_rate_by_mechanism"):
        assert np.array_equal(
            getattr(reference.particles, field), getattr(second.particles, field)
        ), field
    na = reference.thermal.field_provider.neighbourhood
    nb = second.thermal.field_provider.neighbourhood
    assert na.builds > 1 and (na.count, na.builds) == (nb.count, nb.builds)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
def test_one_and_two_threads_bit_identical(tmp_path: Path) -> None:
    case = _moving_case(tmp_path, 34)  # 4624 particles: every chunked loop splits
    previous = numba.get_num_threads()
    runs = []
    try:
        for threads in (1, 2):
            sim = Simulation(case_from_dict(case), threads=threads)
            sim.run(steps=20)
            runs.append(sim)
    finally:
        numba.set_num_threads(previous)
    one, two = runs
    assert one.particles.count > 4096
    assert one.thermal.field_provider.neighbourhood.ngroups >= 8
    for field in ("temperature", "heat_rate_by_mechanism"):
        a = _by_gid(one, getattr(one.particles, field))
        b = _by_gid(two, getattr(two.particles, field))
        assert np.array_equal(a, b), field


@pytest.mark.parametrize("model", ["krause2017", "zhou2009"])
def test_neighbour_listing_stays_exact_while_the_bed_moves(tmp_path: Path, model: str) -> None:
    """The listed neighbours (members fixed per listing, border entries tested every step;
    kernels/neighbourhood.py) give exactly the sums over each sphere at every step while the
    bed settles: compared every 15 steps with a brute-force sum over every pair; the bed moves
    enough that the listing is redone without a rebuild of the range set, and with one."""
    case = _moving_case(tmp_path, 5)
    case["thermal"]["radiation"] = {"model": model}
    case["thermal"]["porosity"] = {"kind": "cell"}
    sim = Simulation(case_from_dict(case))
    fp = sim.thermal.field_provider
    for _ in range(20):
        sim.run(steps=15)
        sim.thermal.compute_rates(sim.time)
        p = sim.particles
        d2 = ((p.position[:, None, :] - p.position[None, :, :]) ** 2).sum(axis=2)
        inside = d2 < (3.0 * p.radius[:, None]) ** 2
        np.fill_diagonal(inside, False)
        w = 2 * math.pi * p.radius**2 * EPS
        f = sim.thermal.fields
        if model == "krause2017":
            assert f[fk.F_NEIGHBOUR_AREA] == pytest.approx(inside @ w, rel=1e-13)
            assert f[fk.F_NEIGHBOUR_EMISSION] == pytest.approx(
                inside @ (w * p.temperature**4), rel=1e-13
            )
        else:
            assert np.array_equal(f[fk.F_NEIGHBOURS], inside.sum(axis=1).astype(float))
            assert f[fk.F_NEIGHBOUR_TEMPERATURE] == pytest.approx(inside @ p.temperature, rel=1e-13)
    ns = fp.neighbourhood
    assert fp.members_listings > ns.builds > 1
    # the border entries' classes were redone between listings too (particles moved a
    # quarter of their band; tests/unit/test_neighbourhood_border.py has tested entries)
    assert fp.border_classifications > fp.members_listings
