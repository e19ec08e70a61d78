"""Restarts with a changed case, through the command line (run_cases.cli, as a user runs them):
heat that starts at a restart (a mechanics-only run settled, then ``run CASE --restart CKPT``
with a ``thermal`` section; engine/heat_start.py), the reverse refused, a run directory whose
run never started, and the list of the changes a restart applies."""

from __future__ import annotations

import copy
import subprocess
from pathlib import Path

import numpy as np
import yaml
from run_cases import cli

from thermodem.io.checkpoint import read_checkpoint
from thermodem.io.run_files import read_timeseries

R = 0.001  # [m]
GLASS = {"density": 2500.0, "youngs_modulus": 1.0e7, "poisson_ratio": 0.3,
         "restitution": 0.6, "sliding_friction": 0.4, "thermal_conductivity": 50.0,
         "specific_heat": 800.0}  # fmt: skip
#: a column of four spheres on the floor of a box, each touching the next (1 % overlap):
#: two list entries of two spheres each; 20 steps without heat
SETTLE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 2.0e-4, "seed": 5},
    "domain": {"lower": [0, 0, 0], "upper": [0.004, 0.004, 0.01]},
    "materials": {"glass": GLASS},
    "walls": [
        {
            "kind": "box",
            "lower": [0, 0, 0],
            "upper": [0.004, 0.004, 0.01],
            "open_top": True,
            "material": "glass",
        }
    ],  # fmt: skip
    "insertion": [
        {
            "kind": "list",
            "material": "glass",
            "radius": R,
            "positions": [[0.002, 0.002, 0.99 * R], [0.002, 0.002, 2.97 * R]],
        },
        {
            "kind": "list",
            "material": "glass",
            "radius": R,
            "positions": [[0.002, 0.002, 4.95 * R], [0.002, 0.002, 6.93 * R]],
        },
    ],  # fmt: skip
    "output": {
        "vtu": False,
        "timeseries_interval": 5.0e-5,
        "checkpoint_interval": 1.0e-4,
        "checkpoint_keep": None,
    },
}


def _cli(*args: str) -> subprocess.CompletedProcess:
    return cli(*args, "--no-progress")  # the command line in this process (run_cases.cli)


def _write(path: Path, case: dict) -> Path:
    path.write_text(yaml.safe_dump(case))
    return path


def _settled(tmp_path: Path) -> Path:
    res = _cli("run", str(_write(tmp_path / "settle.yaml", SETTLE)), "-o", str(tmp_path / "s"))
    assert res.returncode == 0, res.stderr
    return tmp_path / "s" / "checkpoints" / "checkpoint_000000020.h5"


def _particles(path: Path) -> dict[str, np.ndarray]:
    p = read_checkpoint(path).state["particles"]
    order = np.argsort(p["global_id"])
    return {k: np.asarray(v)[order] for k, v in p.items()}


def test_heat_starts_at_a_restart_of_a_run_without_heat(tmp_path: Path) -> None:
    """Settled without heat, continued with a thermal section: the temperatures start as the
    case assigns them at t = 0 (entry 0 by thermal.initial_temperature, entry 1 by its
    ``temperatures``, which may be added at the restart), the floor at 350 K heats the column,
    the heat columns start at zero at the checkpoint's time and Σ m c ΔT equals the heat the
    floor gave (and the balance error is round-off)."""
    ckpt = _settled(tmp_path)
    heat = copy.deepcopy(SETTLE)
    heat["simulation"]["end_time"] = 6.0e-4
    heat["insertion"][1]["temperatures"] = [380.0, 420.0]
    heat["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 350.0}
    heat["thermal"] = {"initial_temperature": {"kind": "uniform", "value": 300.0}}
    out = tmp_path / "h"
    res = _cli("run", str(_write(tmp_path / "heat.yaml", heat)), "--restart", str(ckpt),
               "-o", str(out))  # fmt: skip
    assert res.returncode == 0, res.stderr
    line = "heat starts at t = 0.0002 s (step 20) from the case's initial temperatures"
    assert line in res.stdout, res.stdout
    assert line in (out / "run.log").read_text()
    for change in ("thermal (none) -> (a section)", "walls.0.thermal.kind adiabatic -> fixed",
                   "insertion.1.temperatures (none) -> [380.0, 420.0]"):  # fmt: skip
        assert f"changed from the checkpoint's case: {change}\n" in res.stdout, res.stdout
    first = _particles(out / "checkpoints" / "checkpoint_000000020.h5")
    np.testing.assert_array_equal(first["temperature"], [300.0, 300.0, 380.0, 420.0])
    # the positions and velocities are the settled run's
    np.testing.assert_array_equal(first["position"], _particles(ckpt)["position"])
    last = _particles(out / "checkpoints" / "checkpoint_000000060.h5")
    rise = last["temperature"] - first["temperature"]
    assert rise[0] > 1e-3, rise  # the floor (350 K) heats the bottom sphere
    assert rise[3] < -1e-3, rise  # the top one (420 K) gives heat to the one below
    series = read_timeseries(out / "timeseries.csv")
    assert series["step"][0] == 20 and series["step"][-1] == 60
    assert series["heat_in_wall_direct_conduction"][0] == 0.0
    assert series["heat_balance_error"][0] == 0.0
    stored = np.sum(last["mass"] * GLASS["specific_heat"] * rise)
    floor = series["heat_in_wall_direct_conduction"][-1]
    assert floor > 0.0
    assert abs(stored - floor) <= 1e-9 * abs(floor), (stored, floor)
    assert abs(series["heat_balance_error"][-1]) <= 1e-9 * abs(floor)


def test_adiabatic_heat_start_keeps_the_heat_and_the_reverse_is_refused(tmp_path: Path) -> None:
    """Two temperatures by region (evaluated where the spheres are at the restart), no wall
    heat: Σ m c T stays what it was to round-off while the temperatures even out. A
    checkpoint with heat continued by a case without a thermal section is refused, naming
    the key and what is allowed, before anything is written."""
    ckpt = _settled(tmp_path)
    heat = copy.deepcopy(SETTLE)
    heat["simulation"]["end_time"] = 6.0e-4
    heat["thermal"] = {"initial_temperature": {
        "kind": "regions", "default": 300.0,
        "regions": [[{"lower": [0, 0, 4 * R], "upper": [0.004, 0.004, 0.01]}, 500.0]],
    }}  # fmt: skip
    out = tmp_path / "h"
    res = _cli("run", str(_write(tmp_path / "heat.yaml", heat)), "--restart", str(ckpt),
               "-o", str(out))  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "thermal.initial_temperature (regions at the particles' positions now)" in res.stdout
    first = _particles(out / "checkpoints" / "checkpoint_000000020.h5")
    np.testing.assert_array_equal(first["temperature"], [300.0, 300.0, 500.0, 500.0])
    last = _particles(out / "checkpoints" / "checkpoint_000000060.h5")
    assert last["temperature"][1] > 300.001 and last["temperature"][2] < 499.999
    c = GLASS["specific_heat"]
    before = np.sum(first["mass"] * c * first["temperature"])
    after = np.sum(last["mass"] * c * last["temperature"])
    assert abs(after - before) <= 1e-13 * before, (before, after)
    # the reverse: the heated run's checkpoint, the mechanics-only case
    back = tmp_path / "back"
    res = _cli("run", str(tmp_path / "settle.yaml"), "--restart",
               str(out / "checkpoints" / "checkpoint_000000060.h5"), "--end-time", "0.001",
               "-o", str(back))  # fmt: skip
    assert res.returncode == 2, res.stderr
    assert "thermal: the case has no thermal section, but the checkpoint holds the " in res.stderr
    assert "keep the thermal section" in res.stderr
    assert "Traceback" not in res.stderr
    assert not back.exists()


def test_restart_of_a_run_that_never_started_says_so(tmp_path: Path) -> None:
    """``thermodem restart DIR`` of a run refused before its first step: the message says the
    run never started, with the refusal from its status.json and the command to run it again
    (before: 'no checkpoints in DIR/checkpoints; nothing to restart from')."""
    bad = copy.deepcopy(SETTLE)
    bad["simulation"]["time_step"] = 1.0e-3  # no step before the end time: refused
    out = tmp_path / "out"
    res = _cli("run", str(_write(tmp_path / "bad.yaml", bad)), "-o", str(out))
    assert res.returncode == 2 and "gives no step" in res.stderr, res.stderr
    res = _cli("restart", str(out))
    assert res.returncode == 2, res.stderr
    assert f"cannot restart '{out}': no checkpoints in {out / 'checkpoints'}; the run in " in (
        res.stderr
    )
    assert "never started (status.json: its input was refused: simulation.end_time" in res.stderr
    assert f"after fixing the case (bad) run it again: thermodem run CASE --output {out}" in (
        res.stderr
    )
    assert "Traceback" not in res.stderr


def test_changes_a_restart_applies_are_listed(tmp_path: Path) -> None:
    """``run CASE --restart CKPT`` lists every key CASE changes against the checkpoint's
    stored case, old -> new, in stdout and run.log (before, they were applied silently); at
    most 20 lines, then 'and N more'."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.run_checks import restart_changes

    ckpt = _settled(tmp_path)
    changed = copy.deepcopy(SETTLE)
    changed["simulation"]["end_time"] = 4.0e-4
    changed["simulation"]["time_step"] = 5.0e-6
    changed["materials"]["glass"]["restitution"] = 0.5
    changed["walls"][0]["velocity"] = [0.0, 0.0, 0.01]
    out = tmp_path / "c"
    res = _cli("run", str(_write(tmp_path / "changed.yaml", changed)), "--restart", str(ckpt),
               "-o", str(out))  # fmt: skip
    assert res.returncode == 0, res.stderr
    log = (out / "run.log").read_text()
    lines = [
        "changed from the checkpoint's case: simulation.time_step 1e-05 -> 5e-06",
        "changed from the checkpoint's case: simulation.end_time 0.0002 -> 0.0004",
        "changed from the checkpoint's case: materials.glass.restitution 0.6 -> 0.5",
        "changed from the checkpoint's case: walls.0.velocity [0.0, 0.0, 0.0] -> [0.0, 0.0, 0.01]",
    ]
    for line in lines:
        assert line in res.stdout, res.stdout
        assert line in log
    assert res.stdout.count("changed from the checkpoint's case:") == 4, res.stdout
    # the same case: nothing listed
    res = _cli("run", str(tmp_path / "settle.yaml"), "--restart", str(ckpt), "--end-time",
               "0.0003", "-o", str(tmp_path / "same"))  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert res.stdout.count("changed from the checkpoint's case:") == 1  # (--end-time)
    # more than 20 changes: 20 lines and the count of the others
    many = copy.deepcopy(changed)
    many["simulation"]["gravity"] = [0.1, 0.2, -9.0]
    many["materials"]["glass"].update(density=2400.0, youngs_modulus=2.0e7, poisson_ratio=0.25,
                                      sliding_friction=0.3, thermal_conductivity=2.0,
                                      specific_heat=700.0, rolling_friction=0.1)  # fmt: skip
    many["domain"]["upper"] = [0.004, 0.004, 0.02]
    many["domain"]["lower"] = [-0.001, 0.0, 0.0]
    many["simulation"].update(seed=7, max_overlap_ratio=0.3)
    many["output"] = {"vtu": True, "interval": 1e-4, "timeseries_interval": 1e-5,
                      "checkpoint_interval": 2e-4, "checkpoint_keep": 3}  # fmt: skip
    shown = restart_changes(read_checkpoint(ckpt), case_from_dict(many))
    assert len(shown) == 21, shown  # (21 changes: 20 lines)
    assert shown[-1] == "changed from the checkpoint's case: and 1 more", shown


def test_restart_of_a_run_whose_list_entry_gives_velocities(tmp_path: Path) -> None:
    """A list entry with ``velocities`` (one per position): the checkpoint's stored case holds
    every key, the unused default ``velocity`` too, and reading it back refused 'velocity'
    and 'velocities' together, so ``restart DIR`` of such a run stopped with exit 2 (and
    ``run CASE --restart`` with a changed list geometry too). Both continue now, and the
    continued run reaches the uninterrupted one's state."""
    case = copy.deepcopy(SETTLE)
    case["insertion"][1]["velocities"] = [[0.0, 0.0, -0.05], [0.01, 0.0, 0.0]]
    path = _write(tmp_path / "v.yaml", case)
    res = _cli("run", str(path), "-o", str(tmp_path / "whole"))
    assert res.returncode == 0, res.stderr
    res = _cli("run", str(path), "-o", str(tmp_path / "cut"), "--end-time", "1e-4")
    assert res.returncode == 0, res.stderr
    res = _cli("restart", str(tmp_path / "cut"), "--end-time", "2e-4")
    assert res.returncode == 0, res.stderr
    whole = _particles(tmp_path / "whole" / "checkpoints" / "checkpoint_000000020.h5")
    cut = _particles(tmp_path / "cut" / "checkpoints" / "checkpoint_000000020.h5")
    np.testing.assert_array_equal(whole["position"], cut["position"])
    np.testing.assert_array_equal(whole["velocity"], cut["velocity"])


def test_the_resolved_case_of_a_list_entry_with_velocities_runs(tmp_path: Path) -> None:
    """``case.resolved.yaml`` (every default filled in) of a list entry with ``velocities``
    held the default ``velocity`` too, which the case refuses together with ``velocities``:
    the file a run writes could not be run. It is left out now."""
    case = copy.deepcopy(SETTLE)
    case["insertion"][1]["velocities"] = [[0.0, 0.0, -0.05], [0.01, 0.0, 0.0]]
    res = _cli("run", str(_write(tmp_path / "v.yaml", case)), "-o", str(tmp_path / "a"),
               "--end-time", "5e-5")  # fmt: skip
    assert res.returncode == 0, res.stderr
    resolved = tmp_path / "a" / "case.resolved.yaml"
    assert "velocities" in resolved.read_text()
    res = _cli("run", str(resolved), "-o", str(tmp_path / "b"), "--end-time", "5e-5")
    assert res.returncode == 0, res.stderr
