"""Settings that the rest of a case leaves unused (engine/ignored_settings.py): `validate` and
`run` ran them silently; each is now a warning naming the key and what happens instead, and
the case still runs (the run does what the documentation says)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from run_cases import base_case
from typer.testing import CliRunner

from thermodem.cli import app

CASE = base_case(
    insertion=[
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.001},
            "lower": [0, 0, 0],
            "upper": [0.006, 0.006, 0.004],
            "spacing": 0.0021,
        }
    ],
    thermal={},
)
FROZEN = {"frozen_mechanics": True, "time_step": 1.0e-4}
POUR = {
    "kind": "pour",
    "material": "glass",
    "distribution": {"kind": "mono", "radius": 0.001},
    "region": {"kind": "box", "lower": [0, 0, 0.006], "upper": [0.01, 0.01, 0.01]},
    "rate": 100000.0,
    "interval": 1.0e-4,
}
FLOOR = CASE["walls"][0]
FIXED_WALL = {**FLOOR, "thermal": {"kind": "fixed", "temperature": 400.0}}


def _case(tmp_path: Path, change) -> Path:  # noqa: ANN001
    data = json.loads(json.dumps(CASE))
    change(data)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _frozen(data: dict) -> dict:
    data["thermal"].update(FROZEN)
    return data


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda d: _frozen(d)["insertion"].append(POUR),
         "insertion.1: a pour entry inserts particles during the run, but "
         "thermal.frozen_mechanics is true: nothing moves and the heat runs on the bed as it is "
         "at t = 0, so it inserts nothing"),
        (lambda d: _frozen(d)["walls"][0].update(velocity=[0, 0, 0.1]),
         "walls.0 (plane0): velocity [0.0, 0.0, 0.1] given, but thermal.frozen_mechanics is "
         "true"),
        (lambda d: _frozen(d)["insertion"][0].update(velocity=[0, 0, -1]),
         "insertion.0.velocity: an initial velocity is given, but thermal.frozen_mechanics is "
         "true"),
        (lambda d: _frozen(d).update(external_force=[{"select": {"material": "glass"},
                                                     "force": [0, 0, 1.0e-3]}]),
         "external_force.0: a constant load is given, but thermal.frozen_mechanics is true"),
        (lambda d: (d.pop("thermal"), d.update(walls=[FIXED_WALL])),
         "walls.0.thermal (plane0): a fixed temperature (400.0) is given, but the case has no "
         "thermal section, so it runs mechanics only and the wall's temperature is not used"),
        (lambda d: d["thermal"].update(external_source=[{
            "power": 1.0, "region": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
            "start_time": 5.0}]),
         "thermal.external_source.0: start_time = 5 s is at or after simulation.end_time = "
         "0.001 s: the source gives no heat in this run"),
        (lambda d: d["walls"].append({**FLOOR, "name": "copy"}),
         "walls.1 (copy) is the same plane as walls.0 (plane0): a particle touching it is pushed "
         "by both"),
        (lambda d: d["thermal"].update(
            fixed_temperature=[{"select": {"ids": [0]}, "temperature": 400.0}],
            heat_flux=[{"select": {"material": "glass"}, "flux": 1000.0}]),
         "thermal.heat_flux.0 and thermal.fixed_temperature.0 both select 1 particle(s) at the "
         "start: a fixed particle is held at 400 K, so the heat_flux does nothing on it"),
        (lambda d: d["thermal"].update(fixed_temperature=[
            {"select": {"ids": [0, 1]}, "temperature": 400.0},
            {"select": {"material": "glass"}, "temperature": 350.0}]),
         "thermal.fixed_temperature.0 (400 K) and thermal.fixed_temperature.1 (350 K) both "
         "select 2 particle(s) at the start: they are held at 350 K (the later entry's)"),
    ],
    ids=["frozen-pour", "frozen-wall-velocity", "frozen-entry-velocity", "frozen-load",
         "fixed-wall-without-heat", "source-after-the-end", "wall-twice", "fixed-and-flux",
         "fixed-twice"],
)  # fmt: skip
def test_an_ignored_setting_is_told(tmp_path: Path, change, expected: str) -> None:  # noqa: ANN001
    result = CliRunner().invoke(app, ["validate", str(_case(tmp_path, change))])
    assert result.exit_code == 0, result.output
    assert f"warning: {expected}" in result.output


def test_a_frozen_run_with_a_moving_wall_runs_and_logs_the_warning(tmp_path: Path) -> None:
    case = _case(tmp_path, lambda d: _frozen(d)["walls"][0].update(velocity=[0, 0, 0.1]))
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, ["run", str(case), "--output", str(out), "--steps", "2", "--no-progress"]
    )
    assert result.exit_code == 0, result.output
    assert "walls.0 (plane0): velocity [0.0, 0.0, 0.1] given" in (out / "run.log").read_text()


@pytest.mark.parametrize(
    "change",
    [
        lambda d: d,  # the plain case
        lambda d: _frozen(d),  # frozen, nothing moving given
        lambda d: d["walls"].append({**FLOOR, "point": [0, 0, 0.01], "normal": [0, 0, -1]}),
        lambda d: d["thermal"].update(
            fixed_temperature=[{"select": {"ids": [0]}, "temperature": 400.0},
                               {"select": {"ids": [1]}, "temperature": 350.0}],
            heat_flux=[{"select": {"ids": [2]}, "flux": 1000.0}]),
    ],
    ids=["plain", "frozen", "lid", "separate-conditions"],
)  # fmt: skip
def test_sensible_cases_get_none_of_these_warnings(tmp_path: Path, change) -> None:  # noqa: ANN001
    result = CliRunner().invoke(app, ["validate", str(_case(tmp_path, change))])
    assert result.exit_code == 0, result.output
    for text in ("frozen_mechanics is true", "the same plane", "both select", "no thermal"):
        assert text not in result.output, result.output
