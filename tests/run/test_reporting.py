"""What a run reports and writes, through the command line (run_cases.cli): the warnings
said while a case is built reach run.log, the last line names only files that were written,
export leaves out what a run never computed, warnings come with (before) the refusal they
explain, and implausible model parameters are told."""

from __future__ import annotations

import copy
import subprocess
from pathlib import Path

import pytest
import yaml
from run_cases import cli

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 5.0e-5},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {
        "glass": {
            "density": 2500,
            "youngs_modulus": 1.0e7,
            "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0,
            "specific_heat": 800,
        }
    },
    "walls": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "glass"}],
    "insertion": [
        {
            "kind": "list",
            "material": "glass",
            "positions": [[0.003, 0.003, 0.003], [0.005, 0.003, 0.003]],
            "radii": [0.001, 0.001],
        }
    ],
}


def _write(tmp_path: Path, name: str = "case.yaml", **sections) -> Path:  # noqa: ANN003
    data = copy.deepcopy(CASE)
    for key, value in sections.items():
        data[key] = value
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _run(case: Path, out: Path) -> subprocess.CompletedProcess:
    return cli("run", case, "--output", out, "--no-progress")


def test_without_vtu_the_last_line_names_no_pvd(tmp_path: Path) -> None:
    """output.vtu: false: the last line said 'open OUT/particles.pvd in ParaView', a file that
    was never written."""
    out = tmp_path / "out"
    res = _run(_write(tmp_path, output={"vtu": False}), out)
    assert res.returncode == 0, res.stdout + res.stderr
    last = res.stdout.strip().splitlines()[-1]
    assert "particles.pvd" not in last, last
    assert "no VTU frames were written (output.vtu: false)" in last
    assert f"time series {out / 'timeseries.csv'}" in last
    assert not (out / "particles.pvd").exists()
    assert "no VTU frames were written" in (out / "run.log").read_text()
    # with frames: the file it names exists
    res = _run(_write(tmp_path), tmp_path / "frames")
    assert res.returncode == 0, res.stdout + res.stderr
    assert f"open {tmp_path / 'frames' / 'particles.pvd'} in ParaView" in res.stdout
    assert (tmp_path / "frames" / "particles.pvd").is_file()


def test_a_warning_said_while_the_case_is_built_reaches_run_log(tmp_path: Path) -> None:
    """thermal.fluid that no selected model reads is told while the simulation is built (a
    RuntimeWarning): the CLI printed it on stderr, run.log did not have it."""
    out = tmp_path / "out"
    case = _write(tmp_path, thermal={"fluid": {"temperature": 300.0, "velocity": [0, 0, 0.1]}})
    res = _run(case, out)
    assert res.returncode == 0, res.stdout + res.stderr
    text = "warning: thermal.fluid is given but no selected model reads it"
    assert res.stdout.count(text) == 1, res.stdout
    assert text not in res.stderr, res.stderr
    assert (out / "run.log").read_text().count(text) == 1


def test_a_warning_said_while_a_restart_is_built_reaches_run_log(tmp_path: Path) -> None:
    """thermodem restart DIR and run CASE --restart CKPT build the simulation before they open
    run.log: the warnings said then went to stderr only."""
    out = tmp_path / "out"
    case = _write(tmp_path, thermal={"fluid": {"temperature": 300.0, "velocity": [0, 0, 0.1]}})
    assert _run(case, out).returncode == 0
    text = "warning: thermal.fluid is given but no selected model reads it"
    final = sorted((out / "checkpoints").glob("*.h5"))[-1]
    again = tmp_path / "again"
    for args, log in (
        (
            ("run", case, "--restart", final, "-o", again, "--end-time", 1.0e-4, "--no-progress"),
            again / "run.log",
        ),
        (("restart", out, "--end-time", 1.0e-4, "--no-progress"), out / "run.log"),
    ):
        res = cli(*args)
        assert res.returncode == 0, res.stdout + res.stderr
        assert res.stdout.count(text) == 1, res.stdout
        assert text not in res.stderr, res.stderr
        assert log.read_text().count(text) == (2 if log.parent == out else 1)


def test_the_warnings_before_a_refusal_are_told_with_it(tmp_path: Path) -> None:
    """density: 2.5 (g/cm³) gives a mass 1000 times too small and a time step refused for it;
    the refusal came alone, without the density warning that explains it."""
    glass = {**CASE["materials"]["glass"], "density": 2.5}
    case = _write(tmp_path, materials={"glass": glass})
    warning = "warning: materials.glass.density: 2.5 kg/m³ is below 30 kg/m³"
    res = cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count(warning) == 1, res.stderr
    assert res.stderr.index(warning) < res.stderr.index("error: time step refused")
    out = tmp_path / "out"
    res = _run(case, out)
    assert res.returncode == 2, res.stdout + res.stderr
    assert (res.stdout + res.stderr).count(warning) == 1, res.stdout + res.stderr
    assert "error: time step refused" in res.stderr
    log = (out / "run.log").read_text()
    assert log.count(warning) == 1
    assert log.index(warning) < log.index("error: time step refused")


def test_export_and_plot_of_a_run_without_heat_leave_the_heat_out(tmp_path: Path) -> None:
    """A run without a thermal section was exported with temperature 293.15 and heat_rate 0,
    values it never computed."""
    out = tmp_path / "out"
    res = _run(_write(tmp_path), out)
    assert res.returncode == 0, res.stdout + res.stderr
    for args in (("--frame", "-1"), ()):
        res = cli("export", out, *args, "--out", "-")
        assert res.returncode == 0, res.stdout + res.stderr
        first, header, row = res.stdout.splitlines()[:3]
        assert "no thermal section: the run computed no temperature or heat rate" in first
        assert "temperature [K]" not in first
        assert header == "global_id,material,x,y,z,vx,vy,vz,radius"
        assert len(row.split(",")) == 9
    res = cli("plot", out)
    assert res.returncode == 0, res.stdout + res.stderr
    assert sorted(Path(p).name for p in res.stdout.split()) == ["contacts.png", "energies.png"]
    # with heat: the columns are there
    heated = tmp_path / "heated"
    assert _run(_write(tmp_path, thermal={}), heated).returncode == 0
    res = cli("export", heated, "--out", "-")
    assert res.stdout.splitlines()[1].endswith(",radius,temperature,heat_rate")


SURFACE = {"surface_slope": 0.1, "microhardness": 3.0e9, "surface_roughness": 1.0e-6,
           "thermal_accommodation": 0.9}  # fmt: skip
NETWORK = {"direct_conduction": "resistance_network"}
RADIATION = {"radiation": {"model": "surroundings", "environment_temperature": 300.0}}
GENERATION = {"heat_generation": {"model": "rojek2014", "conversion_fraction": 0.0}}


@pytest.mark.parametrize(
    ("glass", "thermal", "message"),
    [
        (
            {**SURFACE, "surface_slope": 50.0},
            NETWORK,
            "warning: materials.glass.surface_slope: 50 is above 2, steeper than any real surface "
            "(the RMS asperity slope, the tangent of the asperities' angle, is usually 0.05-0.5): "
            "is it an angle in degrees? (50° is a slope tan 50° = 1.19)",
        ),
        (
            {**SURFACE, "microhardness": 1.0e-3},
            NETWORK,
            "warning: materials.glass.microhardness: 0.001 Pa is below 1e+07 Pa, softer than any "
            "solid (real microhardnesses are 1e8-1e10 Pa, lead about 5e7 Pa): is it in MPa or GPa?",
        ),
        (
            {**SURFACE, "microhardness": 3.0e15},
            NETWORK,
            "warning: materials.glass.microhardness: 3e+15 Pa is above 2e+11 Pa, harder than "
            "diamond",
        ),
        (
            {"emissivity": 0.0},
            RADIATION,
            "warning: thermal.radiation = 'surroundings', but every particle material has "
            "emissivity 0 (materials.glass.emissivity = 0): the radiation model exchanges no heat",
        ),
        (
            {},
            GENERATION,
            "warning: thermal.heat_generation = 'rojek2014' with conversion_fraction 0: it turns "
            "none of the dissipation into heat, so the model does nothing",
        ),
    ],
    ids=["slope", "microhardness_low", "microhardness_high", "emissivity", "generation"],
)
def test_implausible_parameters_are_warned_about(
    tmp_path: Path, glass: dict, thermal: dict, message: str
) -> None:
    """Values far outside any real material (a slope of 50, a microhardness of 1e-3 Pa) and
    selections that do nothing (radiation with every emissivity 0, heat generation with
    χ = 0) ran without a word."""
    materials = {"glass": {**CASE["materials"]["glass"], **glass}}
    res = cli("validate", _write(tmp_path, materials=materials, thermal=thermal))
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stderr.count(message) == 1, res.stderr


def test_plausible_parameters_and_a_fluid_at_rest_are_not_warned_about(tmp_path: Path) -> None:
    """Real values give none of those warnings; a convection model in a fluid at rest is the
    natural-convection limit (Nu = 2), not a mistake."""
    materials = {"glass": {**CASE["materials"]["glass"], **SURFACE, "emissivity": 0.9}}
    thermal = {**NETWORK, **RADIATION, "heat_generation": {"model": "rojek2014"}}
    res = cli("validate", _write(tmp_path, materials=materials, thermal=thermal))
    assert res.returncode == 0, res.stdout + res.stderr
    for key in ("surface_slope", "microhardness", "emissivity", "conversion_fraction"):
        assert key not in res.stderr, res.stderr
    still = {"convection": "ranz_marshall1952",
             "fluid": {"temperature": 300.0, "velocity": [0.0, 0.0, 0.0]}}  # fmt: skip
    res = cli("validate", _write(tmp_path, thermal=still))
    assert res.returncode == 0, res.stdout + res.stderr
    assert "velocity" not in res.stderr, res.stderr
