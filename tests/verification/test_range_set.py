"""Gap conduction on the range pair set (engine/range_set.py).

Checked against things the engine does not compute itself: the closed form of Batchelor &
O'Brien's separated-pair conductance, the exact solution of the explicit Euler recurrence of
two spheres, an O(N²) brute-force pair sum with minimum images (which pairs conduct, and the
per-particle sums) while particles move in and out of range, and the heat ledger.
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
from thermodem.kernels.heat_terms import term_conductance
from thermodem.models import registry
from thermodem.models.thermal.contact_radius import geometric_contact_radius
from thermodem.state import heat

K_GLASS = 1.0
K_GAS = 0.0263
GLASS = {
    "density": 2500.0,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "restitution": 0.5,
    "thermal_conductivity": K_GLASS,
    "specific_heat": 800.0,
}


def _particles(path: Path, pos, radius, velocity=None, temperature=None) -> dict:
    pos = np.asarray(pos, float)
    rad = np.broadcast_to(np.asarray(radius, float), (len(pos),)).copy()
    vel = np.zeros_like(pos) if velocity is None else np.asarray(velocity, float)
    temp = None if temperature is None else np.asarray(temperature, float)
    save_particle_file(path, InsertedParticles(pos, rad, vel, temp, "glass"))
    return {"kind": "file", "material": "glass", "path": str(path)}


def _two_spheres(tmp_path: Path, gap: float, radius: float, **thermal) -> dict:
    x0, x1 = 0.005, 0.005 + 2 * radius + gap
    entry = _particles(
        tmp_path / "two.txt", [[x0, 0.005, 0.005], [x1, 0.005, 0.005]], radius, None, [300, 400]
    )
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [0.012, 0.01, 0.01]},
        "materials": {"glass": dict(GLASS)},
        "insertion": [entry],
        "thermal": {"direct_conduction": "batchelor_obrien_complete", **thermal},
    }


def _bob_separated(r_eff: float, gap: float, cylinder_ratio: float = 2.0) -> float:
    """H of Batchelor & O'Brien (1977) for separated particles, Dai et al.'s minimum rule."""
    kpf = K_GLASS / K_GAS
    r_cyl = cylinder_ratio * r_eff
    return (
        2
        * math.pi
        * r_eff
        * K_GAS
        * min(2 * math.log(kpf), math.log1p(r_cyl**2 / (2 * r_eff * gap)))
    )


def test_two_spheres_a_gap_apart_conduct_with_the_default_neighbour_settings(
    tmp_path: Path,
) -> None:
    """The silent gap of the first thermal engine: 1 mm spheres 0.1 mm apart with
    batchelor_obrien_complete never exchanged heat with neighbors.extra_distance = 0."""
    radius, gap, steps = 5e-4, 1e-4, 20
    sim = Simulation(case_from_dict(_two_spheres(tmp_path, gap, radius)))
    h = _bob_separated(radius / 2, gap)
    p = sim.particles
    order = np.argsort(p.global_id)
    q = p.heat_rate_by_mechanism[order, heat.M_INDIRECT]
    assert q[0] == pytest.approx(h * 100.0, rel=1e-12)
    assert q[1] == pytest.approx(-h * 100.0, rel=1e-12)
    assert np.all(p.heat_rate_by_mechanism[:, heat.M_DIRECT] == 0.0)
    sim.run(steps=steps)
    # explicit Euler of two equal capacities: ΔT_n = ΔT_0 (1 - 2 Δt H / (m c))^n
    mc = GLASS["density"] * 4 / 3 * math.pi * radius**3 * GLASS["specific_heat"]
    expected = 100.0 * (1.0 - 2 * sim.dt * h / mc) ** steps
    t = sim.particles.temperature[np.argsort(sim.particles.global_id)]
    assert t[1] - t[0] == pytest.approx(expected, rel=1e-10)
    assert t[0] + t[1] == pytest.approx(700.0, rel=1e-14)


def test_beyond_the_cutoff_nothing_is_listed_or_exchanged(tmp_path: Path) -> None:
    radius = 5e-4
    gap = 1.1 * radius / 2  # cutoff_gap_ratio 1.0 × R* = 0.25 mm < 0.275 mm
    sim = Simulation(case_from_dict(_two_spheres(tmp_path, gap, radius)))
    sim.run(steps=5)
    assert np.all(sim.particles.heat_rate_by_mechanism == 0.0)
    t = np.sort(sim.particles.temperature)
    assert t.tolist() == [300.0, 400.0]


def _moving_case(
    tmp_path: Path, model: dict, seed: int = 4, indirect: dict | None = None, clearance=5e-5
) -> dict:
    rng = np.random.default_rng(seed)
    n, box = 160, 0.008
    pos, rad = [], []
    while len(pos) < n:  # random sequential placement, no overlaps, room for gaps
        r = rng.uniform(4e-4, 6e-4)
        x = rng.uniform([0, 0, r], [box, box, box - r])
        if clearance < 0 and len(pos) < 12:  # touching the hot floor
            x[2] = r + 0.5 * clearance
        if all(
            np.linalg.norm(_minimum_image(x - y, box)) > r + s + clearance
            for y, s in zip(pos, rad, strict=True)
        ):
            pos.append(x)
            rad.append(r)
    vel = rng.normal(0.0, 0.3, (n, 3))
    temps = rng.uniform(300.0, 500.0, n)
    return {
        "simulation": {"time_step": 2e-6, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [box, box, box], "periodic": [True, True, False]},
        "materials": {
            "glass": dict(GLASS, thermal_accommodation=0.8),
            "steel": dict(GLASS, thermal_conductivity=20.0, thermal_accommodation=0.6),
        },
        "walls": [
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal": [0, 0, 1],
                "material": "steel",
                "thermal": {"kind": "fixed", "temperature": 350.0},
            },
            {"kind": "plane", "point": [0, 0, box], "normal": [0, 0, -1], "material": "steel"},
        ],
        "neighbors": {"skin": 5e-5},
        "insertion": [_particles(tmp_path / "bed.txt", pos, rad, vel, temps)],
        "thermal": {
            "direct_conduction": model,
            "indirect_conduction": indirect or "none",
            "contact_radius": "geometric",
            "range_skin": 1e-4,
        },
    }


def _minimum_image(d: np.ndarray, box: float) -> np.ndarray:
    d = d.copy()
    d[..., :2] -= box * np.round(d[..., :2] / box)
    return d


def _brute_force(sim: Simulation, term) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """Heat of ``term`` per particle (particle pairs, floor wall) by an O(N²) loop in the
    test: every pair within reach of every other (minimum images), R_c the geometric radius
    of touching pairs; a ``contacts`` term counts touching pairs only."""
    p = sim.particles
    box = sim.upper[0] - sim.lower[0]
    n = p.count
    pair_q = np.zeros(n)
    wall_q = np.zeros(n)
    listed = 0
    steel = sim.material_index["steel"]
    for i in range(n):
        for j in range(i + 1, n):
            d = float(np.linalg.norm(_minimum_image(p.position[j] - p.position[i], box)))
            ri, rj = p.radius[i], p.radius[j]
            if term.target == "contacts" and d >= ri + rj:
                continue
            r_c = geometric_contact_radius(ri, rj, ri + rj - d) if d < ri + rj else 0.0
            row = term.table[p.type_id[i], p.type_id[j]]
            h = term_conductance(term.evaluator, term.model_id, row, ri, rj, d, r_c, 0.0)
            if h:
                listed += 1
                q = h * (p.temperature[j] - p.temperature[i])
                pair_q[i] += q
                pair_q[j] -= q
        z = float(p.position[i, 2])
        ri = p.radius[i]
        if term.target == "contacts" and z >= ri:
            continue
        r_c = geometric_contact_radius(ri, math.inf, ri - z) if z < ri else 0.0
        row = term.table[p.type_id[i], steel]
        h = term_conductance(term.evaluator, term.model_id, row, ri, math.inf, z, r_c, 0.0)
        wall_q[i] = h * (350.0 - p.temperature[i])
    assert listed > 5  # the case has conducting pairs
    return pair_q, wall_q


GAP_MODELS = [
    ({"model": "batchelor_obrien_complete", "cutoff_gap_ratio": 1.0}, None),
    ({"model": "batchelor_obrien_modified", "cutoff_gap_ratio": 1.0}, None),
    ("batchelor_obrien_simple", {"model": "batchelor_obrien_separated", "regime": "minimum"}),
    ("batchelor_obrien_simple", {"model": "rong_horio1999", "contact_term": True}),
    ("batchelor_obrien_simple", {"model": "musser2011", "layer_thickness_ratio": 0.2}),
    ("batchelor_obrien_simple", {"model": "vargas_mccarthy2002"}),
]


@pytest.mark.parametrize(
    ("direct", "indirect"),
    GAP_MODELS,
    ids=["bob_complete", "bob_modified", "bob_separated", "rong_horio", "musser", "vargas"],
)
def test_gap_terms_equal_a_brute_force_pair_sum_while_pairs_enter_and_leave(
    tmp_path: Path, direct, indirect
) -> None:
    """Every model that conducts through the gas, on its pair set (the range set, or the
    touching pairs for Vargas & McCarthy), in a bed whose particles move through each
    other's range: the engine's per-particle heat equals an O(N²) sum in the test, the
    pairwise column sums to round-off, the ledger closes to round-off."""
    # Vargas & McCarthy conducts between touching particles: start with small overlaps
    clearance = -2e-5 if indirect and indirect["model"] == "vargas_mccarthy2002" else 5e-5
    case = _moving_case(tmp_path, direct, indirect=indirect, clearance=clearance)
    sim = Simulation(case_from_dict(case))
    th = sim.thermal
    (term,) = [t for t in th.terms if t.column == heat.M_INDIRECT]
    u0 = th.thermal_energy()
    counts = set()
    for _ in range(4):
        sim.run(steps=40)
        th.compute_rates(sim.time)  # the rates of the state now
        pair_q, wall_q = _brute_force(sim, term)
        got = sim.particles.heat_rate_by_mechanism
        scale = np.abs(pair_q).max()
        assert np.abs(got[:, heat.M_INDIRECT] - pair_q).max() <= 1e-12 * scale
        assert np.abs(got[:, heat.M_WALL_INDIRECT] - wall_q).max() <= 1e-12 * max(
            np.abs(wall_q).max(), 1e-30
        )
        # what i gains j loses: the pairwise column sums to round-off
        assert abs(got[:, heat.M_INDIRECT].sum()) <= 1e-13 * np.abs(got[:, heat.M_INDIRECT]).sum()
        counts.add(th.range_set.count if th.range_set is not None else sim.contact_count)
    if th.range_set is not None:
        assert th.range_set.builds > 2
        assert th.range_set.bounded > 0  # the displacement bound decided some steps
    assert len(counts) > 2  # pairs entered and left
    assert abs(th.balance_error()) <= 1e-12 * u0
    assert th.cumulative["heat_in_wall_indirect_conduction"] != 0.0


def test_every_range_model_is_covered_by_the_range_set() -> None:
    """Every model that conducts across a gap declares its range and is evaluated on the range
    set, so its range can never be missed by the neighbour machinery (the contact list holds
    the touching pairs): the silent gap of ``neighbors.extra_distance`` cannot come back."""
    checked = 0
    for spec in registry.all_models():
        if spec.family not in ("direct_conduction", "indirect_conduction") or spec.name == "none":
            continue
        if spec.target == "range":
            assert spec.interaction_range is not None, spec.name
        if spec.interaction_range is None:
            continue
        params = spec.params(**spec.example_params)
        r = 1e-3
        gap = spec.interaction_range(params, r, r)
        wall_gap = spec.interaction_range(params, r, math.inf)
        assert gap >= 0.0 and wall_gap >= 0.0, spec.name
        if spec.target == "range":
            assert gap > 0.0 and wall_gap > 0.0, spec.name
        # ranges grow with the radii (the set's cut-off is taken at the largest radius)
        assert spec.interaction_range(params, 0.5 * r, 0.3 * r) <= gap, spec.name
        assert spec.interaction_range(params, 0.5 * r, math.inf) <= wall_gap, spec.name
        checked += 1
    assert checked >= 2


def test_a_range_larger_than_the_domain_is_refused_naming_the_key(tmp_path: Path) -> None:
    case = _two_spheres(tmp_path, 1e-4, 5e-4)
    case["thermal"]["direct_conduction"] = {"model": "batchelor_obrien_complete",
                                            "cutoff_gap_ratio": 1e3}  # fmt: skip
    with pytest.raises(
        ConfigError,
        match=r"thermal.direct_conduction.cutoff_gap_ratio = 1000.0: .*more than the domain",
    ):
        Simulation(case_from_dict(case))
