"""CLI commands: models, validate (three layers), argument errors, progress output, the API."""

from __future__ import annotations

import io
from pathlib import Path

import yaml
from typer.testing import CliRunner

import thermodem
from thermodem.cli import app
from thermodem.engine.runner import run_case
from thermodem.models.registry import FAMILIES, all_models

ROOT = Path(__file__).parents[2]
SMALL = """
simulation: {time_step: 1.0e-5, end_time: 0.0005}
domain: {lower: [0, 0, 0], upper: [0.01, 0.01, 0.01]}
materials:
  glass: {density: 2500, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
walls:
  - {kind: box, lower: [0, 0, 0], upper: [0.01, 0.01, 0.01], material: glass}
insertion:
  - {kind: lattice, material: glass, distribution: {kind: mono, radius: 0.0008},
     lower: [0, 0, 0], upper: [0.01, 0.01, 0.01], spacing: 0.002}
"""


def test_models_lists_every_family_and_model_with_parameters() -> None:
    result = CliRunner().invoke(app, ["models"])
    assert result.exit_code == 0
    for family in FAMILIES:
        assert f"== {family} ==" in result.output
    for spec in all_models():
        assert f"{spec.family}.{spec.name}:" in result.output
        assert spec.reference in result.output
    # a parameter line: unit, default, bounds
    assert "damping_ratio: [-], default 0.3, >= 0" in result.output
    assert "stiffness: [N/m], required, > 0" in result.output
    one = CliRunner().invoke(app, ["models", "rolling"])
    assert "rolling.epsd" in one.output and "normal.hertz" not in one.output
    bad = CliRunner().invoke(app, ["models", "rollin"])
    assert bad.exit_code == 2


def test_models_lists_the_gas_conduction_models_with_every_parameter_and_its_unit() -> None:
    """Every parameter of the models that conduct through the gas is listed; the numeric ones
    with their unit; where each runs and which key sets its range."""
    out = CliRunner().invoke(app, ["models", "indirect_conduction"]).output
    lines = out.splitlines()
    for spec in all_models():
        if spec.family != "indirect_conduction" or spec.target == "external":
            continue
        start = lines.index(next(x for x in lines if x.startswith(f"  {spec.family}.{spec.name}:")))
        block = []
        for x in lines[start + 1 :]:
            if not x.startswith("    "):
                break
            block.append(x)
        if spec.name == "none":
            assert block == ["    parameters: none", "    reference: -"]
            continue
        for name, field in spec.params.model_fields.items():
            line = next(x for x in block if x.startswith(f"    {name}:"))
            if field.annotation in (float, float | None):
                assert line.startswith(f"    {name}: ["), line  # a unit
            assert "  " not in line.strip(), line
        runs = next(x for x in block if x.startswith("    runs on:"))
        if spec.target == "range":
            assert "range pair set" in runs and spec.range_parameter in runs
        else:
            assert runs == "    runs on: touching pairs (contact lists)", runs
    assert "cutoff_gap_ratio: [-], default 1.0, > 0" in out
    assert "min_separation: [m], default 2.75e-08, > 0" in out
    assert "liquid_conductivity: [W/(m K)], default None, > 0" in out
    assert "filling_angle: [rad], default 0.0, >= 0, < 1.5708" in out


def test_validate_prints_estimates_and_a_loadable_resolved_case(tmp_path: Path) -> None:
    case = tmp_path / "c.yaml"
    case.write_text(SMALL)
    result = CliRunner().invoke(app, ["validate", str(case)])
    assert result.exit_code == 0, result.output
    assert "# particles: 125 now" in result.output
    assert "# estimated memory:" in result.output and "# estimated run time:" in result.output
    data = yaml.safe_load(result.stdout)
    assert data["contact"]["normal"] == {"model": "hertz"}
    assert data["output"]["checkpoint_keep"] == 2
    assert data["simulation"]["time_step_check"]["collision_min_steps"] == 10.0
    assert thermodem.case_from_dict(data) == thermodem.load_case(case)


def test_run_argument_errors_exit_2(tmp_path: Path) -> None:
    runner = CliRunner()
    no_case = runner.invoke(app, ["run", "--output", str(tmp_path / "o")])
    assert no_case.exit_code == 2 and "give a case file" in no_case.output
    no_ckpt = runner.invoke(
        app, ["run", "--restart", str(tmp_path / "x.h5"), "--output", str(tmp_path / "o")]
    )
    assert no_ckpt.exit_code == 2 and "does not exist" in no_ckpt.output
    threads = runner.invoke(app, ["run", "c.yaml", "--output", "o", "--threads", "0"])
    assert threads.exit_code == 2


def test_progress_bar_and_plain_lines(tmp_path: Path) -> None:
    case = thermodem.case_from_dict(yaml.safe_load(SMALL))
    bar = io.StringIO()
    run_case(case, tmp_path / "a", log=bar, progress=True)
    assert "steps/s" in bar.getvalue() and "contacts" in bar.getvalue()
    plain = io.StringIO()
    run_case(case, tmp_path / "b", log=plain, progress=False, log_interval=0.0)
    lines = [x for x in plain.getvalue().splitlines() if x.startswith("t = ")]
    assert len(lines) >= 10
    for field in ("%)", "step ", "steps/s", "particle-steps/s", "ETA", "particles", "contacts"):
        assert field in lines[0], field
    # the log file has the plain lines either way
    assert "particle-steps/s" in (tmp_path / "a" / "run.log").read_text()


def test_api_names() -> None:
    for name in ("load_case", "case_from_dict", "Case", "Simulation", "run_case", "restart_run",
                 "ConfigError", "SimulationError", "RunInterrupted"):  # fmt: skip
        assert getattr(thermodem, name) is not None
    case = thermodem.Case(
        simulation={"time_step": 1e-5, "end_time": 1e-4},
        domain={"lower": [0, 0, 0], "upper": [1, 1, 1]},
        materials={"m": {"density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.2}},
    )
    sim = thermodem.Simulation(case)
    sim.run(steps=3)
    assert sim.step_count == 3 and sim.particles.count == 0
