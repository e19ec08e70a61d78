"""Every example case runs a few steps, and `thermodem run` writes a PVD that meshio opens."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.config.load import load_case
from thermodem.engine.simulation import Simulation

EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.yaml"))


#: What the heat-transfer examples of issues 11 and 13 must show after their first steps: the
#: mechanism that moves their heat, with its sign (heat into the particles), in the ledger.
EXPECTED_HEAT = {
    "voronoi_bed": ("heat_in_wall_indirect_conduction", 1.0),  # walls -> bed through the gas
    "gas_cooled_bed": ("heat_in_convection", -1.0),  # bed -> the gas of the grid field
    "radiating_bed": ("heat_in_radiation", -1.0),  # hot bed -> the cooler walls in view
}


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs_a_few_steps(path: Path) -> None:
    case = load_case(path)
    sim = Simulation(case)
    steps = max(50, int(0.015 / case.simulation.time_step))  # long enough for a pour batch
    sim.run(steps=steps)
    assert sim.particles.count > 0
    assert np.isfinite(sim.particles.position).all()
    th = sim.thermal
    if th is not None:
        assert abs(th.balance_error()) <= 1e-12 * th.initial_energy
    if path.stem in EXPECTED_HEAT:
        key, sign = EXPECTED_HEAT[path.stem]
        assert sign * th.cumulative[key] > 0.0, (key, th.cumulative[key])
        # the mean temperature moves the same way
        mean = float(np.mean(sim.particles.temperature))
        start = case.simulation.initial_temperature
        assert sign * (mean - start) > 0.0


def test_cli_run_writes_pvd_that_meshio_opens(tmp_path: Path) -> None:
    case = tmp_path / "case.yaml"
    case.write_text(
        """
simulation: {time_step: 1.0e-5, end_time: 0.002}
domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}
materials:
  glass: {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
walls:
  - {kind: box, lower: [0, 0, 0], upper: [0.01, 0.01, 0.01], material: glass}
insertion:
  - kind: lattice
    material: glass
    distribution: {kind: mono, radius: 0.0008}
    lower: [0.001, 0.001, 0.001]
    upper: [0.009, 0.009, 0.009]
    spacing: 0.002
output: {interval: 0.001}
"""
    )
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["run", str(case), "--output", str(out)])
    assert result.exit_code == 0, result.output
    root = ET.parse(out / "particles.pvd").getroot()
    files = [d.get("file") for d in root.iter("DataSet")]
    times = [float(d.get("timestep")) for d in root.iter("DataSet")]
    assert times == pytest.approx([0.0, 0.001, 0.002])
    mesh = meshio.read(out / files[-1])
    assert mesh.points.shape == (64, 3)
    for name in ("velocity", "temperature", "global_id", "coordination_number"):
        assert name in mesh.point_data
    assert (out / "walls.pvd").exists()
    # an existing non-empty output directory is refused without --overwrite (exit 2)
    again = CliRunner().invoke(app, ["run", str(case), "--output", str(out)])
    assert again.exit_code == 2
    assert "--overwrite" in again.output


def test_cli_reports_bad_case_with_key_path(tmp_path: Path) -> None:
    case = tmp_path / "bad.yaml"
    case.write_text(
        """
simulation: {time_step: 1.0e-5, end_time: 0.002}
domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}
materials:
  glass: {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.7}
"""
    )
    result = CliRunner().invoke(app, ["validate", str(case)])
    assert result.exit_code == 2
    assert "materials.glass.poisson_ratio" in result.output
    assert "0.7" in result.output


def test_drum_friction_heating_example_closes_its_generation_ledger() -> None:
    """The example's beads gain exactly the heat their contacts dissipated (adiabatic walls:
    no wall share), per mechanism, over a short run with sub-cycled heat."""
    case = load_case(Path(__file__).parents[2] / "examples" / "drum_friction_heating.yaml")
    sim = Simulation(case)
    u0 = sim.thermal.thermal_energy()
    sim.run(steps=6003)  # the bed forms (~20 ms), the heat of 600 thermal steps, 3 pending
    report = sim.report()
    energies = sim.energies()
    gained = 0.0
    for name in ("sliding_friction", "rolling_friction", "normal_damping", "tangential_damping"):
        generated = energies[f"dissipated_{name}"]
        parts = report[f"heat_in_generation_{name}"] + report[f"heat_pending_generation_{name}"]
        assert report[f"heat_to_walls_generation_{name}"] == 0.0
        assert parts == pytest.approx(generated, rel=1e-12), name
        gained += report[f"heat_in_generation_{name}"]
    assert gained > 0.0
    assert sim.thermal.thermal_energy() - u0 == pytest.approx(gained, rel=1e-9)
