"""Inputs whose fault shows only once the case is built, through the installed command in a
subprocess as a user runs it: a failure met while the simulation is built (before step 0) is an
input error (exit 2, the key named), not a failed run (exit 1); a heat generation mechanism that
the material values switch off for every pair that can meet is warned about."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import yaml

EXE = str(Path(sys.executable).with_name("thermodem"))

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.001},
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
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.001},
            "lower": [0, 0, 0],
            "upper": [0.006, 0.006, 0.006],
            "count": [2, 2, 2],
        }
    ],
}


def _write(tmp_path: Path, name: str = "case", **sections) -> Path:  # noqa: ANN003
    data = json.loads(json.dumps(CASE))
    data.update(sections)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _cli(*args: object) -> subprocess.CompletedProcess:
    res = subprocess.run(
        [EXE, *[str(a) for a in args]], capture_output=True, text=True, timeout=300
    )
    assert "Traceback" not in res.stdout + res.stderr, res.stdout + res.stderr
    return res


def _glass(**changes: float) -> dict:
    return {"glass": {**CASE["materials"]["glass"], **changes}}


def test_a_failure_while_the_case_is_built_is_an_input_error(tmp_path: Path) -> None:
    """A periodic axis shorter than two neighbour cells of the inserted particles raised a
    SimulationError while the simulation was built: validate and run exited 1 (a failed
    simulation), run left no status.json and nothing in run.log, and the message named no
    key. Now exit 2 naming domain.periodic, recorded as a refused input; a failure met while
    the run steps (particles given overlapping, overlap_check: false) still exits 1."""
    lattice = {**CASE["insertion"][0], "upper": [0.0025, 0.006, 0.006], "count": [1, 2, 2]}
    domain = {"lower": [0, 0, 0], "upper": [0.0025, 0.01, 0.01], "periodic": [True, False, False]}
    case = _write(tmp_path, domain=domain, insertion=[lattice])
    message = (
        "error: domain.periodic: axis x is periodic, but the domain is 0.0025 m long along it "
        "(domain.upper - domain.lower), shorter than twice the neighbour cell 0.0022 m (2 R_max "
        "0.002 m + neighbors.skin 0.0002 m); the minimum image needs >= 0.0044 m: a longer "
        "periodic axis, smaller particles or a smaller neighbors.skin (met while the case was "
        "built, before any step)"
    )
    res = _cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr
    out = tmp_path / "out"
    for _ in range(2):  # (the refusal's record counts as empty: the same error again)
        res = _cli("run", case, "--output", out, "--no-progress")
        assert res.returncode == 2, res.stdout + res.stderr
        assert message in res.stderr
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "failed" and status["refused_input"] is True
    assert message in (out / "run.log").read_text()
    assert not (out / "checkpoints").exists() or not any((out / "checkpoints").iterdir())
    # a failure of the run itself: exit 1 as before
    given = {"kind": "list", "material": "glass", "radius": 0.001, "overlap_check": False,
             "positions": [[0.005, 0.005, 0.005], [0.0055, 0.005, 0.005]]}  # fmt: skip
    case = _write(tmp_path, "overlapping", insertion=[given])
    assert _cli("validate", case).returncode == 0
    res = _cli("run", case, "--output", tmp_path / "o2", "--no-progress")
    assert res.returncode == 1, res.stdout + res.stderr
    assert "error: overlap of 1.41 × the smaller radius (particle 0 and particle 1) at step 1" in (
        res.stderr
    )


def test_a_tessellation_the_start_cannot_make_is_an_input_error(tmp_path: Path) -> None:
    """A Voronoi case with a plane wall across the bed: the tessellation made while the
    simulation is built failed with exit 1; it is an input error naming thermal.tessellation."""
    data = yaml.safe_load((Path(__file__).parents[2] / "examples" / "voronoi_bed.yaml").read_text())
    data["simulation"]["end_time"] = 1.0e-4
    data["walls"].append(
        {"kind": "plane", "point": [0, 0, 0.003], "normal": [0, 0, 1], "material": "steel"}
    )
    case = tmp_path / "voronoi.yaml"
    case.write_text(yaml.safe_dump(data))
    res = _cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "error: thermal.tessellation (plain): particle index 0 " in res.stderr
    assert "(met while the case was built, before any step)" in res.stderr


def test_a_generation_mechanism_the_material_values_switch_off_is_told(tmp_path: Path) -> None:
    """rojek2014 with sliding_friction 0, richard2008 with restitution 1 (no damping), a listed
    rolling_friction with the default rolling friction 0 gave zero heat without a word; told
    once before the run (validate, run and run.log), only when every pair that can meet gives
    zero."""
    glass = _glass(sliding_friction=0.0)
    case = _write(tmp_path, materials=glass, thermal={"heat_generation": "rojek2014"})
    told = (
        "warning: thermal.heat_generation = 'rojek2014': 'sliding_friction' gives zero heat with "
        "these material values: every pair of materials that can meet has sliding friction 0 "
        "(the Coulomb cap μ F_n holds no tangential force): materials.glass.sliding_friction = "
        "0; remove it, or give values that dissipate that way"
    )
    res = _cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stderr.count(told) == 1, res.stderr
    out = tmp_path / "out"
    res = _cli("run", case, "--output", out, "--steps", "2", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    assert (res.stdout + res.stderr).count(told) == 1
    assert (out / "run.log").read_text().count(told[len("warning: ") :]) == 1
    # a steel wall with friction: the glass-steel pair dissipates, nothing to tell
    steel = {**CASE["materials"]["glass"], "density": 7800, "sliding_friction": 0.4}
    wall = {**CASE["walls"][0], "material": "steel"}
    case = _write(tmp_path, "steel", materials={**glass, "steel": steel}, walls=[wall],
                  thermal={"heat_generation": "rojek2014"})  # fmt: skip
    res = _cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "gives zero heat" not in res.stderr
    # ... unless an interactions entry sets that pair's friction to 0
    override = [{"materials": ["glass", "steel"], "sliding_friction": 0.0}]
    case = _write(tmp_path, "override", materials={**glass, "steel": steel}, walls=[wall],
                  interactions=override, thermal={"heat_generation": "rojek2014"})  # fmt: skip
    res = _cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "sliding friction 0 (the Coulomb cap μ F_n holds no tangential force): "
        "materials.glass.sliding_friction = 0, interactions.0.sliding_friction = 0; remove it"
    ) in res.stderr
    # restitution 1: no normal damping; a listed rolling friction with the default 0
    listed = ["normal_damping", "rolling_friction", "sliding_friction"]
    generation = {"model": "mechanical_dissipation", "mechanisms": listed}
    case = _write(tmp_path, "elastic", materials=_glass(restitution=1.0),
                  contact={"rolling": "epsd"}, thermal={"heat_generation": generation})  # fmt: skip
    res = _cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: thermal.heat_generation.mechanisms: 'normal_damping' gives zero heat with "
        "these material values: every pair of materials that can meet has restitution 1 "
        "(perfectly elastic: no damping, no plastic work): materials.glass.restitution = 1;"
    ) in res.stderr
    assert (
        "'rolling_friction' gives zero heat with these material values: every pair of "
        "materials that can meet has rolling friction 0 (no rolling torque): "
        "materials.glass.rolling_friction = 0 (the default);"
    ) in res.stderr
    assert "'sliding_friction' gives zero" not in res.stderr  # (the default 0.5)
    case = _write(tmp_path, "richard", materials=_glass(restitution=1.0),
                  thermal={"heat_generation": "richard2008"})  # fmt: skip
    res = _cli("validate", case)
    assert "thermal.heat_generation = 'richard2008': 'normal_damping' gives zero heat" in (
        res.stderr
    )


def test_the_default_mechanisms_are_told_only_when_none_gives_heat() -> None:
    """mechanical_dissipation's default list (all five): one mechanism switched off is not
    told (the others heat); all of them off is."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.case_warnings import generation_mechanism_warnings

    def told(**glass: float) -> list[str]:
        data = json.loads(json.dumps(CASE))
        data["materials"] = _glass(**glass)
        data["thermal"] = {"heat_generation": "mechanical_dissipation"}
        return generation_mechanism_warnings(case_from_dict(data))

    assert told(sliding_friction=0.0) == []
    (text,) = told(sliding_friction=0.0, restitution=1.0)
    assert text.startswith(
        "thermal.heat_generation = 'mechanical_dissipation' gives zero heat: none of its "
        "mechanisms (the default, all five) dissipates"
    )
    assert "'rolling_friction': contact.rolling is 'none'" in text
