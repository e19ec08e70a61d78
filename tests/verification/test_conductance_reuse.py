"""Conductance reuse (``thermal.conductance_force_tolerance``) of the resistance network.

Between two evaluations a contact's conductance follows the secant of its last two evaluations
while its normal force stays within tol of the last one (docs/models/conductance_reuse.md).
The bound |H_used - H| <= tol² H rests on two properties of the model, checked here by finite
differences of the model function itself: elasticity |F H'/H| <= 1 and curvature
F² |H''|/H <= 2/3 (for r_c < r/2 and P_0 < H'/2). The engine is then checked against the
exact conductances recomputed here from its own pair lists and normal forces.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.kernels.contact import STATE_TOUCHING
from thermodem.models.thermal.resistance_network import resistance_network_conductance
from thermodem.state import heat

R = 1e-3
TOL = 0.02
GLASS = {
    "density": 2500.0,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "restitution": 0.5,
    "sliding_friction": 0.4,
    "thermal_conductivity": 50.0,
    "specific_heat": 800.0,
    "microhardness": 3e7,
    "surface_roughness": 1e-7,
    "surface_slope": 0.1,
    "thermal_accommodation": 0.8,
}  # soft, smooth and conducting, no low-stiffness correction: the microcontacts carry most of
# the heat and H grows almost in proportion to F_n (the reuse's error is largest)


def _bed_file(path: Path) -> Path:
    """4 × 4 × 3 spheres of radius 0.999-1 mm on a 1.996 mm lattice (pressed together: they
    start in contact and ring) resting on the floor."""
    rng = np.random.default_rng(2)
    rows = ["x y z radius"]
    for a, b, c in np.ndindex(4, 4, 3):
        x, y, z = 0.998 * 2 * R * np.array([a, b, c]) + [1.01 * R, 1.01 * R, 0.999 * R]
        rows.append(f"{x:.17g} {y:.17g} {z:.17g} {R * rng.uniform(0.999, 1.0):.17g}")
    path.write_text("\n".join(rows) + "\n")
    return path


def _case(tolerance: float, bed: Path, **thermal) -> dict:
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "seed": 11},
        "domain": {"lower": [0, 0, 0], "upper": [0.008, 0.008, 0.016]},
        "materials": {"glass": dict(GLASS), "steel": dict(GLASS, thermal_conductivity=20.0)},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [0.008, 0.008, 0.016],
                "open_top": True,
                "material": "steel",
                "thermal": {"kind": "fixed", "temperature": 400.0},
            }
        ],
        "insertion": [{"kind": "file", "material": "glass", "path": str(bed)}],
        "thermal": {
            "direct_conduction": "resistance_network",
            "conductance_force_tolerance": tolerance,
            "gas": {"thermal_conductivity": 0.002},
            "initial_temperature": {
                "kind": "expression",
                "expression": "300 + 20000 * (x + 2 * y + 3 * z)",
            },
            **thermal,
        },
    }


def _exact(sim: Simulation) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The exact conductance of every touching particle pair and particle-wall pair (NaN for
    the others) from the engine's contacts and normal forces, and per particle the exact
    direct + wall heat rate and Σ H |ΔT| over its contacts (the scale of the allowed error)."""
    p, th = sim.particles, sim.thermal
    t = p.temperature
    rate = np.zeros(p.count)
    scale = np.zeros(p.count)

    def conductance(a: int, b: int, r_i: float, r_j: float, force: float) -> float:
        row = th.conduction_table[a, b]
        return resistance_network_conductance(
            row[0], row[1], r_i, r_j, force, *(row[q] for q in range(4, 12))
        )

    pb, wb = sim.pairs, sim.walls
    pair_h = np.full(pb.count, np.nan)
    wall_h = np.full(wb.count, np.nan)
    for k in range(pb.count):
        if pb.state[k] != STATE_TOUCHING:  # (the network conducts between touching spheres)
            continue
        i, j = pb.i[k], pb.j[k]
        h = conductance(
            p.type_id[i], p.type_id[j], p.radius[i], p.radius[j], max(pb.normal_force[k], 0.0)
        )
        pair_h[k] = h
        rate[i] += h * (t[j] - t[i])
        rate[j] -= h * (t[j] - t[i])
        scale[i] += h * abs(t[j] - t[i])
        scale[j] += h * abs(t[j] - t[i])
    for k in range(wb.count):
        if wb.state[k] != STATE_TOUCHING:
            continue
        i, w = wb.i[k], wb.j[k]
        h = conductance(
            p.type_id[i], sim.wall_material[w], p.radius[i], math.inf, max(wb.normal_force[k], 0)
        )
        wall_h[k] = h
        rate[i] += h * (400.0 - t[i])
        scale[i] += h * abs(400.0 - t[i])
    return pair_h, wall_h, rate, scale


def test_conductances_with_reuse_stay_within_the_bound_of_the_exact_model(
    tmp_path: Path,
) -> None:
    """Per pair |H_used - H| <= tol² H (the conductances of the heat-only pass, which reads the
    same pair state as the fused pass and leaves it unchanged here), and per particle the
    fused pass's heat rate within tol² Σ H |ΔT| of the exact one."""
    sim = Simulation(case_from_dict(_case(TOL, _bed_file(tmp_path / "bed.txt"))))
    th = sim.thermal
    col = sim.history_layout.reuse
    reused = touching = 0
    worst = 0.0
    for _ in range(100):
        sim.run(steps=20)
        pb, wb = sim.pairs, sim.walls
        f = pb.normal_force[: pb.count]
        on = f > 0.0
        touching += int(on.sum())
        reused += int((np.abs(pb.history[: pb.count, col])[on] != f[on]).sum())
        pair_h, wall_h, exact_rate, scale = _exact(sim)
        engine = sim.particles.heat_rate_by_mechanism
        excess = (
            np.abs(engine[:, heat.M_DIRECT] + engine[:, heat.M_WALL_DIRECT] - exact_rate)
            - TOL**2 * scale
        )
        assert excess.max() <= 1e-12 * scale.max(), excess.max()
        history = pb.history[: pb.count].copy()
        th.prepare(sim.time)
        th.conduction_passes()
        assert np.array_equal(pb.history[: pb.count], history)  # (state not changed)
        for used, exact in ((th.pair_conductance[: pb.count], pair_h),
                            (th.wall_conductance[: wb.count], wall_h)):  # fmt: skip
            m = np.isfinite(exact)
            error = np.abs(used[m] - exact[m]) / exact[m]
            assert error.max(initial=0.0) <= TOL**2, error.max()
            worst = max(worst, error.max(initial=0.0))
    # the bound was exercised: most touching pair-steps were reused, with a nonzero error
    assert sim.contact_count > 48
    assert reused > 0.5 * touching, (reused, touching)
    assert worst > 1e-9, worst


def test_without_reuse_the_engine_equals_the_exact_model(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(_case(0.0, _bed_file(tmp_path / "bed.txt"))))
    assert sim.history_layout.reuse == -1
    sim.run(steps=1500)
    engine = sim.particles.heat_rate_by_mechanism
    exact = _exact(sim)[2:]
    assert (
        np.abs(engine[:, heat.M_DIRECT] + engine[:, heat.M_WALL_DIRECT] - exact[0]).max()
        <= 1e-12 * exact[1].max()
    )


@pytest.mark.parametrize(
    ("thermal", "materials", "message"),
    [
        ({"direct_conduction": "batchelor_obrien_simple"}, {}, "resistance_network"),
        (
            {"direct_conduction": {"model": "resistance_network", "maximum_pressure": "overlap"}},
            {},
            "maximum_pressure = 'overlap' also reads the overlap",
        ),
        (
            {},
            {
                "steel": {
                    **{k: v for k, v in GLASS.items() if k != "thermal_conductivity"},
                    "thermal_conductivity_table": [[300, 20.0], [400, 18.0]],
                }
            },
            "steel have a thermal_conductivity_table",
        ),
    ],
)
def test_reuse_is_refused_where_it_does_not_hold(tmp_path, thermal, materials, message) -> None:  # noqa: ANN001
    case = _case(0.01, _bed_file(tmp_path / "bed.txt"), **thermal)
    case["materials"].update(materials)
    with pytest.raises(Exception, match="thermal.conductance_force_tolerance") as err:
        case_from_dict(case)
    assert message in str(err.value)


def test_model_elasticity_and_curvature_bound_the_reuse_error() -> None:
    """|F H'/H| <= 1 and F²|H''|/H <= 2/3 over a wide random parameter range (r_c < r/2,
    P_0 < H'/2), by central differences of the model: the premises of the tol² bound."""
    rng = np.random.default_rng(5)
    worst_elasticity = worst_curvature = 0.0
    checked = 0
    for _ in range(3000):
        r_i = 10 ** rng.uniform(-5, -1)
        r_j = r_i * 10 ** rng.uniform(-1, 1) if rng.random() < 0.9 else math.inf
        e_star = 10 ** rng.uniform(6, 11)
        c = 10 ** rng.uniform(-1, 0) if rng.random() < 0.5 else 1.0
        hardness = 10 ** rng.uniform(8, 10)
        k_i, k_j = 10 ** rng.uniform(-1, 2.5, 2)
        sigma, tau = 10 ** rng.uniform(-7, -5), 10 ** rng.uniform(-2, -0.5)
        k_g, m_gas, b = 10 ** rng.uniform(-2, -0.5), 10 ** rng.uniform(-8, -5), rng.uniform(0, 1.5)
        r_eff = 1 / (1 / r_i + 1 / r_j)
        q = 10 ** rng.uniform(-6, math.log10(0.45))  # P_0/H'
        u = (q * math.pi * r_eff * c * c * hardness / (2 * e_star)) ** 3
        if c * u ** (1 / 3) >= 0.5 * min(r_i, r_j):
            continue
        force = u * e_star / (0.75 * r_eff)
        params = (k_i, k_j, r_i, r_j, e_star, c, hardness, sigma, tau, k_g, m_gas, b)
        h = [resistance_network_conductance(*params[:4], f, *params[4:])
             for f in (force * (1 - 1e-3), force, force * (1 + 1e-3))]  # fmt: skip
        step = 1e-3
        hm, h0, hp = h
        worst_elasticity = max(worst_elasticity, abs(hp - hm) / (2 * step) / h0)
        worst_curvature = max(worst_curvature, abs(hp - 2 * h0 + hm) / step**2 / h0)
        checked += 1
    assert checked > 2000
    assert worst_elasticity <= 1.0, worst_elasticity
    assert worst_curvature <= 2.0 / 3.0, worst_curvature
