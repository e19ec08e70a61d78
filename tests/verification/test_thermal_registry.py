"""Every registered conduction and contact-radius model runs in a small packed bed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.models import registry
from thermodem.state import heat

R = 1e-3
FULL_MATERIAL = {
    "density": 2500.0,
    "youngs_modulus": 1e7,
    "poisson_ratio": 0.3,
    "restitution": 0.5,
    "thermal_conductivity": 1.0,
    "specific_heat": 800.0,
    "emissivity": 0.9,
    "microhardness": 3e9,
    "surface_roughness": 1e-6,
    "surface_slope": 0.1,
    "thermal_accommodation": 0.8,
    "youngs_modulus_real": 7e10,
}
EXAMPLE_PARAMS = {"lu2017": {"normal_stiffness": 1e4}}


def _bed(tmp_path: Path, spacing: float = 1 - 1e-3) -> str:
    """3 × 3 × 3 spheres on a lattice of ``spacing`` × 2R (< 1: touching, > 1: gaps of
    (spacing - 1) 2R, also to the floor)."""
    rng = np.random.default_rng(5)
    rows = ["x y z radius temperature"]
    lift = max(spacing - 1.0, 0.0) * R
    for a in range(3):
        for b in range(3):
            for c in range(3):
                x, y, z = (2 * R * spacing * np.array([a, b, c])) + R + np.array([0, 0, lift])
                rows.append(f"{x:.17g} {y:.17g} {z:.17g} {R:.17g} {rng.uniform(290, 400):.17g}")
    path = tmp_path / "bed.txt"
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def _run(
    tmp_path: Path, conduction: str, radius: str, indirect: str = "none", spacing: float = 1 - 1e-3
) -> Simulation:
    choice = {"model": conduction, **EXAMPLE_PARAMS.get(conduction, {})}
    case = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0},
        "domain": {"lower": [-0.001, -0.001, -0.001], "upper": [0.008, 0.008, 0.01]},
        "materials": {
            "glass": dict(FULL_MATERIAL),
            "steel": dict(FULL_MATERIAL, thermal_conductivity=20.0),
        },
        "insertion": [{"kind": "file", "material": "glass", "path": _bed(tmp_path, spacing)}],
        "walls": [
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal": [0, 0, 1],
                "material": "steel",
                "thermal": {"kind": "fixed", "temperature": 450.0},
            }
        ],
        "neighbors": {"extra_distance": 0.2 * R},
        "thermal": {
            "direct_conduction": choice,
            "contact_radius": {"model": radius, **EXAMPLE_PARAMS.get(radius, {})},
            "indirect_conduction": indirect,
        },
    }
    sim = Simulation(case_from_dict(case))
    sim.run(steps=200)
    return sim


@pytest.mark.parametrize("model", registry.names("direct_conduction"))
def test_every_direct_conduction_model_runs(tmp_path: Path, model: str) -> None:
    # with the default contact radius: the compiled pass of several models is then the one
    # other tests use (each combination costs ~6 s of compilation with an empty cache)
    sim = _run(tmp_path, model, "geometric")
    t = sim.particles.temperature
    assert np.isfinite(t).all() and (t > 0).all()
    u0 = sim.thermal.initial_energy
    assert abs(sim.thermal.balance_error()) < 1e-12 * u0
    if model != "none":
        assert np.abs(sim.particles.heat_rate_by_mechanism[:, 0]).max() > 0.0
        assert sim.thermal.cumulative["heat_in_wall_direct_conduction"] > 0.0


@pytest.mark.parametrize("model", registry.names("contact_radius"))
def test_every_contact_radius_model_runs(tmp_path: Path, model: str) -> None:
    sim = _run(tmp_path, "batchelor_obrien_simple", model)
    assert np.isfinite(sim.particles.temperature).all()
    assert abs(sim.thermal.balance_error()) < 1e-12 * sim.thermal.initial_energy


@pytest.mark.parametrize("model", [m for m in registry.names("indirect_conduction") if m != "none"])
def test_every_indirect_conduction_model_runs_with_contact_conduction(
    tmp_path: Path, model: str
) -> None:
    """Each indirect model on its pair set (range or contacts) next to the contact conduction
    of batchelor_obrien_simple: heat flows through the gas (particles and the hot wall) and
    the ledger closes."""
    # range models: a bed with gaps of 0.04 R (within every default range); contact models:
    # the touching bed
    gapped = registry.get("indirect_conduction", model).target == "range"
    spacing = 1.02 if gapped else 1 - 1e-3
    sim = _run(tmp_path, "batchelor_obrien_simple", "geometric", model, spacing)
    t = sim.particles.temperature
    assert np.isfinite(t).all() and (t > 0).all()
    by_mech = sim.particles.heat_rate_by_mechanism
    assert np.abs(by_mech[:, heat.M_INDIRECT]).max() > 0.0
    assert (
        abs(by_mech[:, heat.M_INDIRECT].sum()) <= 1e-12 * np.abs(by_mech[:, heat.M_INDIRECT]).sum()
    )
    assert sim.thermal.cumulative["heat_in_wall_indirect_conduction"] > 0.0
    assert abs(sim.thermal.balance_error()) < 1e-12 * sim.thermal.initial_energy
