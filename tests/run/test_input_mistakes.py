"""Mistakes of a new user that are not a broken case on their own (the corpus in
tests/cases/broken covers those): warnings that `validate` and `run` print for a case that runs
but does not do what it says, and the refusals that need a run directory or a checkpoint."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from run_cases import base_case
from typer.testing import CliRunner

from thermodem.cli import app

CASE = base_case()

POUR = {
    "kind": "pour",
    "material": "glass",
    "distribution": {"kind": "mono", "radius": 0.001},
    "region": {"kind": "box", "lower": [0, 0, 0.006], "upper": [0.01, 0.01, 0.01]},
    "rate": 1000.0,
    "interval": 1.0,
}


def _write(tmp_path: Path, **sections) -> Path:  # noqa: ANN003
    data = json.loads(json.dumps(CASE))
    data.update(sections)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _cli(*args: str):  # noqa: ANN202
    return CliRunner().invoke(app, [str(a) for a in args])


def test_a_pour_that_pours_nothing_before_the_end_is_told(tmp_path: Path) -> None:
    case = _write(tmp_path, insertion=[CASE["insertion"][0], POUR])
    result = _cli("validate", case)
    assert result.exit_code == 0, result.output
    assert (
        "warning: insertion.1: its first batch is due at t = 1 s (start_time 0 s + interval "
        "1 s), after simulation.end_time = 0.001 s: nothing is poured in this run"
    ) in result.output
    result = _cli("run", case, "--output", tmp_path / "out", "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "warning: insertion.1: its first batch is due at t = 1 s" in result.output
    assert "insertion.1: its first batch" in (tmp_path / "out" / "run.log").read_text()
    # --steps / --end-time shorten the run: the end is theirs, not simulation.end_time's
    # (it said 'after simulation.end_time = 2e-05 s' of a case whose end_time is 0.001 s)
    assert (
        "after the end of this run, t = 2e-05 s (--steps 2; simulation.end_time = 0.001 s): "
        "nothing is poured in this run"
    ) in result.output
    result = _cli("run", case, "--output", tmp_path / "o2", "--end-time", "3e-5", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "after the end of this run, t = 3e-05 s (--end-time 3e-05; simulation.end_time = " in (
        result.output
    )
    result = _cli("run", case, "--output", tmp_path / "o3", "--end-time", "1e-9", "--no-progress")
    assert result.exit_code == 2, result.output
    assert (
        "error: --end-time 1e-09: the end of this run, t = 1e-09 s, gives no step of "
        "simulation.time_step = 1e-05 s after t = 0 s"
    ) in result.output


def test_a_pour_rate_below_one_particle_is_told(tmp_path: Path) -> None:
    pour = {**POUR, "rate": 10.0, "interval": 1.0e-4}
    result = _cli("validate", _write(tmp_path, insertion=[pour]))
    assert result.exit_code == 0, result.output
    assert "insertion.0: rate 10/s from t = 0 s to 0.001 s asks for less than one particle" in (
        result.output
    )


def test_an_output_interval_in_steps_is_told(tmp_path: Path) -> None:
    """LIGGGHTS dumps every N steps; thermodem's intervals are simulated seconds."""
    result = _cli("validate", _write(tmp_path, output={"interval": 1000, "checkpoint_interval": 5}))
    assert result.exit_code == 0, result.output
    assert (
        "warning: output.interval = 1000 s is longer than simulation.end_time = 0.001 s: written "
        "at the start and the end only (intervals are simulated seconds, not steps)"
    ) in result.output
    assert "warning: output.checkpoint_interval = 5 s is longer" in result.output
    assert "warning: output.timeseries_interval" not in result.output


def test_an_output_interval_shorter_than_the_time_step_is_told(tmp_path: Path) -> None:
    """An interval below the time step (meant in ms, or in steps of a smaller unit) wrote a
    frame at every step silently: 100 frames here, 50 000 for the default example."""
    case = _write(tmp_path, output={"interval": 1.0e-6, "timeseries_interval": 1.0e-5})
    result = _cli("validate", case)
    assert result.exit_code == 0, result.output
    assert (
        "warning: output.interval = 1e-06 s is shorter than simulation.time_step = 1e-05 s: a "
        "frame is written at every step (100 steps to simulation.end_time); intervals are "
        "simulated seconds: give at least 1e-05 s"
    ) in result.output
    assert "output.timeseries_interval" not in result.output  # (= the time step: fine)
    result = _cli("run", case, "--output", tmp_path / "out", "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "warning: output.interval = 1e-06 s is shorter than simulation.time_step" in (
        result.output
    )
    assert "(2 steps to the end of this run (--steps 2))" in result.output


def test_a_skin_of_many_diameters_is_told(tmp_path: Path) -> None:
    """A skin typed as a domain size (or in mm) listed every pair of the domain: the packed-bed
    example ran 40 times slower without a word. The usual skins are not warned about."""
    result = _cli("validate", _write(tmp_path, neighbors={"skin": 1.0}))
    assert result.exit_code == 0, result.output
    assert (
        "warning: neighbors.skin = 1 m is 500 times the largest particle diameter (0.002 m): "
        "every particle lists all the others within 1 m"
    ) in result.output
    thermal = {"range_skin": 0.05, "indirect_conduction": "rong_horio1999",
               "gas": {"thermal_conductivity": 0.026}}  # fmt: skip
    result = _cli("validate", _write(tmp_path, neighbors={"skin": 0.004}, thermal=thermal))
    assert "thermal.range_skin = 0.05 m is 25 times" in result.output, result.output
    assert "neighbors.skin" not in result.output  # 2 diameters: the limit, not above it
    result = _cli("validate", _write(tmp_path, neighbors={"skin": 0.0005}))
    assert "skin" not in result.output.split("# ")[0], result.output


def test_a_region_selection_empty_at_the_start_is_a_warning(tmp_path: Path) -> None:
    region = {"lower": [0.008, 0.008, 0.008], "upper": [0.01, 0.01, 0.01]}
    thermal = {"heat_flux": [{"select": {"region": region}, "flux": 100.0}]}
    result = _cli("validate", _write(tmp_path, thermal=thermal))
    assert result.exit_code == 0, result.output
    assert (
        "warning: thermal.heat_flux.0.select: selects no particle at the start ({'region': "
        "{'lower': [0.008, 0.008, 0.008], 'upper': [0.01, 0.01, 0.01]}}); its region is "
        "evaluated at every thermal step"
    ) in result.output


def test_a_selection_that_never_selects_is_refused_by_run_before_a_step(tmp_path: Path) -> None:
    select = {"material": "glass", "ids": [8]}
    thermal = {"fixed_temperature": [{"select": select, "temperature": 400.0}]}
    out = tmp_path / "out"
    result = _cli("run", _write(tmp_path, thermal=thermal), "--output", out, "--no-progress")
    assert result.exit_code == 2, result.output
    assert "error: thermal.fixed_temperature.0.select.ids: [8] are no particle" in result.output
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "failed" and status["refused_input"] is True
    assert not (out / "checkpoints").exists() or not any((out / "checkpoints").iterdir())


def test_a_particle_behind_a_plane_is_refused_by_run_before_a_step(tmp_path: Path) -> None:
    walls = [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, -1], "material": "glass"}]
    out = tmp_path / "out"
    result = _cli("run", _write(tmp_path, walls=walls), "--output", out, "--no-progress")
    assert result.exit_code == 2, result.output
    assert "error: walls.0 (plane0): particle 4" in result.output
    assert "its normal [0.0, 0.0, -1.0] must point towards the particles" in result.output
    assert "Traceback" not in result.output
    assert json.loads((out / "status.json").read_text())["refused_input"] is True


def test_run_restart_with_an_end_time_before_the_checkpoint_is_refused(tmp_path: Path) -> None:
    case = _write(tmp_path)
    first = tmp_path / "first"
    result = _cli("run", case, "--output", first, "--steps", "5", "--no-progress")
    assert result.exit_code == 0, result.output
    ckpt = first / "checkpoints" / "checkpoint_000000005.h5"
    data = yaml.safe_load(case.read_text())
    data["simulation"]["end_time"] = 2.0e-5  # before the checkpoint's 5e-5 s
    shorter = tmp_path / "shorter.yaml"
    shorter.write_text(yaml.safe_dump(data))
    again = tmp_path / "again"
    result = _cli("run", shorter, "--restart", ckpt, "--output", again, "--no-progress")
    assert result.exit_code == 2, result.output
    assert (
        "error: simulation.end_time = 2e-05 s is not after the time of the checkpoint"
    ) in result.output
    assert "5e-05 s (step 5): there is nothing to run" in result.output
    assert not again.exists()
    # the stored case of the final checkpoint ends at its time: nothing to run either
    result = _cli("run", "--restart", ckpt, "--output", again, "--no-progress")
    assert result.exit_code == 2, result.output
    assert "is not after the time of the checkpoint" in result.output
    result = _cli("run", "--restart", ckpt, "--output", again, "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output


def test_plot_never_replaces_the_users_figures_and_refuses_a_file(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = _cli("run", _write(tmp_path), "--output", out, "--steps", "3", "--no-progress")
    assert result.exit_code == 0, result.output
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "energies.png").write_bytes(b"my own figure")
    result = _cli("plot", out, "--out", mine)
    assert result.exit_code == 2, result.output
    assert "already holds energies.png, which this would replace; give --overwrite" in (
        result.output
    )
    assert (mine / "energies.png").read_bytes() == b"my own figure"
    result = _cli("plot", out, "--out", mine, "--overwrite")
    assert result.exit_code == 0, result.output
    assert (mine / "energies.png").read_bytes()[:4] == b"\x89PNG"
    for _ in range(2):  # DIR/plots is thermodem's: plotted again without --overwrite
        assert _cli("plot", out).exit_code == 0
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    for target, text in ((a_file, "is a file, not a directory"),
                         (a_file / "sub", "is under the file")):  # fmt: skip
        result = _cli("plot", out, "--out", target)
        assert result.exit_code == 2, result.output
        assert text in result.output and "Traceback" not in result.output


def test_export_under_a_file_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert (
        _cli("run", _write(tmp_path), "--output", out, "--steps", "2", "--no-progress").exit_code
        == 0
    )
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    result = _cli("export", out, "--out", a_file / "particles.csv")
    assert result.exit_code == 2, result.output
    assert "a_file is a file, not a directory; choose another --out" in result.output
    assert "Traceback" not in result.output


def test_etc_refuses_impossible_temperatures_and_layers(tmp_path: Path) -> None:
    case = _write(tmp_path, thermal={})
    for args, text in (
        (["--temperature", "-5"], "--temperature -5.0: must be a finite temperature > 0 K"),
        (["--difference", "0"], "--difference 0.0: must be finite and not 0 [K]"),
        (["--difference", "nan"], "--difference nan: must be finite and not 0 [K]"),
        (["--temperature", "10", "--difference", "-20"], "the hot layer would be at -10 K"),
        (["--layer", "-0.002"], "--layer -0.002: must be a finite thickness > 0 [m]"),
    ):
        result = _cli("etc", case, *args)
        assert result.exit_code == 2, (args, result.output)
        assert text in result.output, (args, result.output)


def test_a_pour_of_an_unbounded_lognormal_is_refused_before_the_run(tmp_path: Path) -> None:
    """It was accepted, and a batch that drew a particle larger than the region stopped the
    run with a ValueError traceback from Pourer.emit."""
    pour = {**POUR, "interval": 1.0e-5, "rate": 1.0e5}
    pour["distribution"] = {"kind": "lognormal", "median": 0.0005, "sigma": 1.5}
    case = _write(tmp_path, insertion=[pour])
    for args in (("validate", case), ("run", case, "--output", tmp_path / "o", "--no-progress")):
        result = _cli(*args)
        assert result.exit_code == 2, result.output
        assert (
            "insertion.0.distribution.max_radius: missing; a pour needs a largest "
            "radius, but the lognormal distribution (median 0.0005 m, sigma 1.5) is unbounded"
        ) in result.output
        assert "e.g. max_radius: 0.045" in result.output
        assert "Traceback" not in result.output
    assert not (tmp_path / "o").exists()


def test_a_random_box_too_thin_names_its_sizes_as_plain_numbers(tmp_path: Path) -> None:
    entry = {
        "kind": "random_box",
        "material": "glass",
        "distribution": {"kind": "mono", "radius": 0.003},
        "lower": [0, 0, 0],
        "upper": [0.004, 0.01, 0.01],
        "count": 1,
    }
    result = _cli("validate", _write(tmp_path, insertion=[entry]))
    assert result.exit_code == 2, result.output
    assert (
        "a particle of radius 0.003 m does not fit in the box, which is 0.004 m wide along x"
    ) in result.output
    assert "np.float64" not in result.output


def test_a_pour_region_through_a_wall_is_refused_before_the_run(tmp_path: Path) -> None:
    """Poured particles were not checked against the walls: a region reaching through the
    floor put particles into it (the run stopped blaming the stiffness, or threw them out)."""
    floor = [{"kind": "plane", "point": [0, 0, 0.007], "normal": [0, 0, 1], "material": "glass",
              "name": "floor"}]  # fmt: skip
    case = _write(tmp_path, walls=floor, insertion=[POUR])
    result = _cli("validate", case)
    assert result.exit_code == 2, result.output
    assert (
        "error: insertion.0.region: a particle of radius 0.001 m poured with its centre at "
        "[0.001, 0.001, 0.007] would overlap walls.0 (floor) at the start: the wall passes 0 m "
        "from that centre. Poured particles must start clear of every wall"
    ) in result.output
    out = tmp_path / "out"
    result = _cli("run", case, "--output", out, "--no-progress")
    assert result.exit_code == 2, result.output
    assert "insertion.0.region: a particle of radius 0.001 m" in result.output
    assert json.loads((out / "status.json").read_text())["refused_input"] is True
    # a region wholly behind a one-sided plane, and one outside a box of walls
    flipped = [{**floor[0], "point": [0, 0, 0.002], "normal": [0, 0, -1]}]
    result = _cli("validate", _write(tmp_path, walls=flipped, insertion=[POUR]))
    assert result.exit_code == 2, result.output
    assert "m behind the plane, which is one-sided (its normal [0.0, 0.0, -1.0]" in (result.output)
    box = [{"kind": "box", "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.005],
            "material": "glass"}]  # fmt: skip
    result = _cli("validate", _write(tmp_path, walls=box, insertion=[POUR]))
    assert result.exit_code == 2, result.output
    assert "would start outside the box walls.0 (box0), above its z range 0 .. 0.005 m" in (
        result.output
    )
    # clear of the walls: accepted
    assert _cli("validate", _write(tmp_path, walls=CASE["walls"], insertion=[POUR])).exit_code == 0


def test_a_wall_wholly_outside_the_domain_is_refused_or_told(tmp_path: Path) -> None:
    """A wall that no particle of the domain can touch (a side plane at x = -5 m for a 1 cm
    domain, a box or a drum far away) was accepted silently; a moving one may come in: a
    warning. Walls on the domain's boundary, or enclosing it, are fine."""
    floor = CASE["walls"][0]
    side = {"kind": "plane", "point": [-5.0, 0, 0], "normal": [1, 0, 0], "material": "glass"}
    result = _cli("validate", _write(tmp_path, walls=[floor, side]))
    assert result.exit_code == 2, result.output
    assert (
        "error: walls.1.point: [-5.0, 0.0, 0.0] (a plane with normal [1.0, 0.0, 0.0]) lies 5 m "
        "outside the domain [[0.0, 0.0, 0.0], [0.01, 0.01, 0.01]], facing it: no particle "
        "inside the domain reaches it (they reach at most 0.002 m beyond it), and it does not "
        "move, so it would never act"
    ) in result.output
    # the same plane moving: it may come in
    moving = {**side, "velocity": [1.0, 0, 0]}
    result = _cli("validate", _write(tmp_path, walls=[floor, moving]))
    assert result.exit_code == 0, result.output
    assert (
        "warning: walls.1.point: [-5.0, 0.0, 0.0] (a plane with normal [1.0, 0.0, 0.0]) lies 5 m "
        "outside the domain"
    ) in result.output
    assert "it moves (velocity [1.0, 0.0, 0.0] m/s), so it may come in later" in result.output
    # a flipped plane with the whole domain behind it (no particle yet to overlap it)
    lid = {"kind": "plane", "point": [0, 0, 0.01], "normal": [0, 0, 1], "material": "glass"}
    result = _cli("validate", _write(tmp_path, walls=[lid], insertion=[]))
    assert result.exit_code == 2, result.output
    assert "walls.0.point: [0.0, 0.0, 0.01] (a plane with normal [0.0, 0.0, 1.0]) has the " in (
        result.output
    )
    # a box away from the domain
    box = {"kind": "box", "lower": [1, 1, 1], "upper": [2, 2, 2], "material": "glass"}
    result = _cli("validate", _write(tmp_path, walls=[floor, box]))
    assert result.exit_code == 2, result.output
    assert (
        "error: walls.1: [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]] (a box) lies 0.99 m outside the "
        "domain [[0.0, 0.0, 0.0], [0.01, 0.01, 0.01]] on the x axis (the wall spans 1 .. 2 m, "
        "the domain 0 .. 0.01 m)"
    ) in result.output
    # legitimate: planes on every face of the domain, a box enclosing it, a rectangle and a
    # cylinder touching it from outside
    faces = [
        {"kind": "plane", "point": p, "normal": n, "material": "glass"}
        for p, n in (([0.01, 0, 0], [-1, 0, 0]), ([0, 0, 0], [1, 0, 0]), ([0, 0, 0.01], [0, 0, -1]))
    ]
    around = {"kind": "box", "lower": [-1, -1, -1], "upper": [1, 1, 1], "material": "glass"}
    plate = {"kind": "rectangle", "center": [0.005, 0.005, 0.0105], "normal": [0, 0, 1],
             "u_axis": [1, 0, 0], "half_extents": [0.005, 0.005], "material": "glass"}  # fmt: skip
    drum = {"kind": "cylinder", "center": [0.005, 0.005, 0.021], "axis": [1, 0, 0],
            "radius": 0.01, "length": 0.01, "inside": False, "material": "glass"}  # fmt: skip
    walls = [floor, *faces, around, plate, drum]
    result = _cli("validate", _write(tmp_path, walls=walls))
    assert result.exit_code == 0, result.output
    assert "outside the domain" not in result.output


def test_a_wall_closing_a_periodic_axis_is_told(tmp_path: Path) -> None:
    """Planes on both x faces of a domain periodic along x gave no word: the particles by the
    two walls interact across the periodic boundary, through the walls. So did a drum across
    x and a plate spanning the whole cross-section."""
    x_walls = [
        {"kind": "plane", "point": [0, 0, 0], "normal": [1, 0, 0], "material": "glass"},
        {"kind": "plane", "point": [0.01, 0, 0], "normal": [-1, 0, 0], "material": "glass"},
    ]
    domain = {**CASE["domain"], "periodic": [True, False, False]}
    result = _cli("validate", _write(tmp_path, domain=domain, walls=CASE["walls"] + x_walls))
    assert result.exit_code == 0, result.output
    assert (
        "warning: domain.periodic: [true, false, false] makes x periodic, but walls.1 (plane1) "
        "is a plane with normal [1.0, 0.0, 0.0] that closes x: particles are wrapped across the "
        "periodic boundary"
    ) in result.output
    assert "but walls.2 (plane2) is a plane with normal [-1.0, 0.0, 0.0]" in result.output
    assert "walls.0" not in result.output  # the floor: z is not periodic
    box = [{"kind": "box", "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01], "material": "glass",
            "name": "bin"}]  # fmt: skip
    result = _cli("validate", _write(tmp_path, domain=domain, walls=box))
    assert "but walls.0 (bin) is a box (its faces close every axis) that closes x" in (
        result.output
    )
    result = _cli("validate", _write(tmp_path, domain=domain))  # the floor only: fine
    assert result.exit_code == 0 and "domain.periodic" not in result.output, result.output
    # a drum across x closes it; along x it is the periodic slice of a drum: fine
    drum = {"kind": "cylinder", "center": [0.005, 0.005, 0.005], "radius": 0.01,
            "material": "glass"}  # fmt: skip
    result = _cli("validate", _write(tmp_path, domain=domain, walls=[{**drum, "axis": [0, 1, 0]}]))
    assert result.exit_code == 0, result.output
    assert "walls.0 (cylinder0) is a cylinder around the axis [0.0, 1.0, 0.0] that closes x" in (
        result.output
    )
    for axis, inside in (([1, 0, 0], True), ([0, 1, 0], False)):  # along x; an obstacle
        walls = [{**drum, "axis": axis, "inside": inside, "radius": 0.0005}]
        result = _cli("validate", _write(tmp_path, domain=domain, walls=walls))
        assert "domain.periodic" not in result.output, (axis, result.output)
    # a plate across the whole cross-section (tilted: still every corner) closes x; a plate
    # with a way around it does not
    plate = {"kind": "rectangle", "center": [0.008, 0.005, 0.005], "normal": [1, 0, 0.2],
             "u_axis": [0, 1, 0], "half_extents": [0.005, 0.0052], "material": "glass"}  # fmt: skip
    result = _cli("validate", _write(tmp_path, domain=domain, walls=CASE["walls"] + [plate]))
    assert "walls.1 (rectangle1) is a rectangle with normal [1.0, 0.0, 0.2] spanning the " in (
        result.output
    )
    narrow = {**plate, "half_extents": [0.004, 0.0052]}
    result = _cli("validate", _write(tmp_path, domain=domain, walls=CASE["walls"] + [narrow]))
    assert "domain.periodic" not in result.output, result.output


MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.skipif(
    importlib.util.find_spec("mpi4py") is None or not MPIEXEC.exists(),
    reason="mpi4py and the mpich wheel (test extras) are not installed",
)
def test_mpi_run_makes_the_checks_of_the_serial_run(tmp_path: Path) -> None:
    """mpiexec -n 2 thermodem run refuses what the serial run refuses before a step (the
    flipped plane ran and stopped at step 1 with exit 1)."""
    walls = [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, -1], "material": "glass"}]
    out = tmp_path / "out"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PMI_", "OMPI_", "PMIX_"))}
    cmd = [str(MPIEXEC), "-n", "2", str(Path(sys.executable).parent / "thermodem"), "run",
           str(_write(tmp_path, walls=walls)), "--output", str(out), "--no-progress"]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count("error: walls.0 (plane0): particle") == 1, res.stderr
    assert "its normal [0.0, 0.0, -1.0] must point towards the particles" in res.stderr
    assert "Traceback" not in res.stdout + res.stderr
    assert json.loads((out / "status.json").read_text())["refused_input"] is True


def test_thermal_null_is_told_it_runs_mechanics_only(tmp_path: Path) -> None:
    """An explicit null is the absent section (as thermal.fluid: null, and as
    case.resolved.yaml wrote it): a warning, not an error; it ran silently."""
    case = _write(tmp_path, thermal=None)
    text = "warning: thermal: null (an empty 'thermal:' key) means no thermal section: this "
    result = _cli("validate", case)
    assert result.exit_code == 0, result.output
    assert text + "case runs mechanics only, without heat; write thermal: {}" in result.output
    out = tmp_path / "out"
    result = _cli("run", case, "--output", out, "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output
    assert text in result.output and "thermal: null" in (out / "run.log").read_text()
    # the resolved case leaves the absent section out (no warning when it is run again)
    assert "thermal" not in yaml.safe_load((out / "case.resolved.yaml").read_text())
    result = _cli("validate", out / "case.resolved.yaml")
    assert result.exit_code == 0 and "thermal: null" not in result.output
    # without the key: nothing said
    assert "thermal: null" not in _cli("validate", _write(tmp_path)).output


def test_a_constant_and_a_table_of_one_property_are_refused(tmp_path: Path) -> None:
    """Both were accepted and the table replaced the constant silently."""
    table = [[300.0, 1.0], [400.0, 2.0]]
    glass = {**CASE["materials"]["glass"], "thermal_conductivity_table": table}
    result = _cli("validate", _write(tmp_path, materials={"glass": glass}, thermal={}))
    assert result.exit_code == 2, result.output
    assert (
        "materials.glass.thermal_conductivity: 1 W/(m K) is given together with "
        "thermal_conductivity_table [[300.0, 1.0], [400.0, 2.0]]; the table replaces the "
        "constant at run time"
    ) in result.output
    glass = {**CASE["materials"]["glass"], "specific_heat_table": [[300.0, 700.0]]}
    result = _cli("validate", _write(tmp_path, materials={"glass": glass}, thermal={}))
    assert result.exit_code == 2, result.output
    assert "materials.glass.specific_heat: 800 J/(kg K) is given together with" in result.output
    # the table alone runs; its resolved case (which wrote the filled-in constant too) and a
    # checkpoint's stored case of an earlier version are read again
    glass = {k: v for k, v in CASE["materials"]["glass"].items() if k != "thermal_conductivity"}
    case = _write(tmp_path, materials={"glass": {**glass, "thermal_conductivity_table": table}},
                  thermal={})  # fmt: skip
    out = tmp_path / "out"
    result = _cli("run", case, "--output", out, "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output
    assert _cli("validate", out / "case.resolved.yaml").exit_code == 0
    from thermodem.config.load import case_from_dict

    old = {**yaml.safe_load(case.read_text())}
    old["materials"]["glass"]["thermal_conductivity"] = 1.0  # as earlier versions stored it
    assert case_from_dict(old, stored=True).materials["glass"].thermal_conductivity == 1.0


def test_temperatures_that_look_like_celsius_are_warned_about(tmp_path: Path) -> None:
    """initial_temperature: 25 (°C by mistake) ran at 25 K without a word; every temperature
    key below 200 K is told (a warning: cryogenic cases run)."""
    walls = [{**CASE["walls"][0], "thermal": {"kind": "fixed", "temperature": [[0, 300], [1, 80]]}}]
    thermal = {"fixed_temperature": [{"select": {"ids": [0]}, "temperature": 100.0}]}
    case = _write(tmp_path, simulation={**CASE["simulation"], "initial_temperature": 25},
                  walls=walls, thermal=thermal)  # fmt: skip
    result = _cli("validate", case)
    assert result.exit_code == 0, result.output
    assert (
        "warning: simulation.initial_temperature: 25 K is below 200 K, colder than any natural "
        "temperature on Earth (the record is 184 K): temperatures are in kelvin, is it a value "
        "in °C? (25 °C = 298.15 K); a cryogenic case can ignore this"
    ) in result.output
    assert "warning: walls.0.thermal.temperature (row 1): 80 K is below 200 K" in result.output
    assert "warning: thermal.fixed_temperature.0.temperature: 100 K is below" in result.output
    out = tmp_path / "out"
    result = _cli("run", case, "--output", out, "--steps", "2", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "simulation.initial_temperature: 25 K is below 200 K" in (out / "run.log").read_text()
    # kelvin: nothing said
    assert "is below 200 K" not in _cli("validate", _write(tmp_path, thermal={})).output


def test_a_fluid_temperature_grid_in_celsius_is_warned_about(tmp_path: Path) -> None:
    """A fluid grid file of temperatures in °C (26.85) was read silently, while the single
    temperature keys below 200 K are told: its smallest value is told once."""
    import numpy as np

    axis = np.linspace(0.0, 0.01, 3)
    temperature = np.full((3, 3, 3), 26.85)
    temperature[1, 2, 0] = 20.0
    np.savez(tmp_path / "flow.npz", x=axis, y=axis, z=axis, T=temperature)
    fluid = {"temperature": {"file": "flow.npz", "field": "T"}}
    case = _write(tmp_path, thermal={"convection": "stagnant", "fluid": fluid})
    result = _cli("validate", case)
    assert result.exit_code == 0, result.output
    assert result.output.count("thermal.fluid.temperature") == 1, result.output
    assert (
        f"warning: thermal.fluid.temperature (grid file {tmp_path / 'flow.npz'}, field 'T': its "
        "smallest value, at grid index (1, 2, 0)): 20 K is below 200 K, colder than any natural "
        "temperature on Earth"
    ) in result.output
    np.savez(tmp_path / "flow.npz", x=axis, y=axis, z=axis, T=temperature + 273.15)
    assert "is below 200 K" not in _cli("validate", case).output


#: (key, family) of every key that selects a model by name, one case each below.
MODEL_KEYS = [
    ("contact.normal", "normal"),  # a contact law without none
    ("contact.tangential", "tangential"),
    ("contact.rolling", "rolling"),
    ("thermal.contact_radius", "contact_radius"),
    ("thermal.direct_conduction", "direct_conduction"),  # thermal conduction
    ("thermal.indirect_conduction", "indirect_conduction"),
    ("thermal.convection", "convection"),
    ("thermal.radiation", "radiation"),
    ("thermal.heat_generation", "heat_generation"),
]


@pytest.mark.parametrize("key,family", MODEL_KEYS, ids=[k for k, _ in MODEL_KEYS])
@pytest.mark.parametrize("form", ["key", "model"])
def test_a_null_model_key_is_refused(tmp_path: Path, key: str, family: str, form: str) -> None:
    """KEY: null (an empty key) and KEY: {model: null} ran the family's default model
    silently (thermal.direct_conduction: null conducted by Batchelor & O'Brien); they are
    refused, naming the key, the value and the model names."""
    from thermodem.models import registry

    section, name = key.split(".")
    value = None if form == "key" else {"model": None}
    result = _cli("validate", _write(tmp_path, **{section: {name: value}}))
    assert result.exit_code == 2, result.output
    where = key if form == "key" else f"{key}.model"
    word = name if form == "key" else "model"
    assert "error: " in result.output and "Traceback" not in result.output
    assert f"{where}: null (an empty '{word}:' key) is not a model name; " in result.output
    names = registry.names(family)
    assert f"; allowed: {', '.join(names)}" in result.output
    if "none" in names:
        assert f"write none for no {family} model, a model name, or leave the key out" in (
            result.output
        )
    else:
        assert f"{family} has no model none: write a model name" in result.output


def test_a_null_contact_law_names_the_2d_default_too(tmp_path: Path) -> None:
    result = _cli("validate", _write(tmp_path, contact={"normal": None}))
    assert result.exit_code == 2, result.output
    assert "leave the key out for the default (hertz; hertz_2d for 2D discs)" in result.output


def test_a_null_model_key_is_refused_by_the_cli_before_any_step(tmp_path: Path) -> None:
    """The empty key as a user writes it (its model commented out), through the installed
    command in a subprocess: validate and run refuse it (exit 2) before the simulation is
    built; a mapping without model and an absent key still select the default."""
    text = _write(tmp_path).read_text()
    text += "thermal:\n  direct_conduction:   # batchelor_obrien_simple\n  convection: none\n"
    case = tmp_path / "empty_key.yaml"
    case.write_text(text)
    assert yaml.safe_load(text)["thermal"]["direct_conduction"] is None
    exe = str(Path(sys.executable).with_name("thermodem"))
    res = subprocess.run([exe, "validate", str(case)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "thermal.direct_conduction: null (an empty 'direct_conduction:' key) is not a model "
        "name; write none for no direct_conduction model, a model name, or leave the key out "
        "for the default (batchelor_obrien_simple); allowed: batchelor_obrien_complete, "
    ) in res.stderr
    assert "none, " in res.stderr.split("allowed: ")[1]
    assert "Traceback" not in res.stdout + res.stderr
    assert "compiling" not in res.stdout + res.stderr  # refused before the engine is built
    out = tmp_path / "out"
    result = _cli("run", case, "--output", out, "--no-progress")
    assert result.exit_code == 2, result.output
    assert "thermal.direct_conduction: null" in result.output
    assert not (out / "timeseries.csv").exists()
    # a mapping without model and an absent key: the default, as documented
    from thermodem.config.load import case_from_dict

    data = yaml.safe_load(_write(tmp_path, thermal={"convection": {}}).read_text())
    thermal = case_from_dict(data).thermal
    assert thermal.convection.model == "none"
    assert thermal.direct_conduction.model == "batchelor_obrien_simple"


def test_the_resolved_case_writes_no_null_model_key(tmp_path: Path) -> None:
    """Every model key of case.resolved.yaml is {model: NAME, ...}, so the resolved case of a
    run is read again (also in 2D, where the contact defaults of discs are filled in)."""
    from thermodem.models import registry

    for dim, data in (("3d", {"thermal": {}}), ("2d", None)):
        if data is None:
            case = Path(__file__).parents[2] / "examples" / "drum_2d.yaml"
        else:
            case = _write(tmp_path, **data)
        out = tmp_path / f"out_{dim}"
        result = _cli("run", case, "--output", out, "--steps", "2", "--no-progress")
        assert result.exit_code == 0, result.output
        resolved = yaml.safe_load((out / "case.resolved.yaml").read_text())
        for key, family in MODEL_KEYS:
            section, name = key.split(".")
            value = resolved[section][name]
            assert isinstance(value, dict) and value["model"] in registry.names(family), key
        assert _cli("validate", out / "case.resolved.yaml").exit_code == 0


def test_every_model_key_is_covered() -> None:
    """The keys above are every model choice of the schema (a new family is tested too)."""
    from thermodem.config.load import case_from_dict
    from thermodem.config.planar_case import selected_models
    from thermodem.config.schema import MODEL_KEYS as SCHEMA_KEYS

    case = case_from_dict({**json.loads(json.dumps(CASE)), "thermal": {}})
    selected = {key: choice.family for key, choice in selected_models(case)}
    assert selected == dict(MODEL_KEYS) == {v: k for k, v in SCHEMA_KEYS.items()}


def test_the_registry_refuses_a_null_name() -> None:
    from thermodem.models import registry

    with pytest.raises(KeyError, match=r"convection model: null is not a model name; allowed: "):
        registry.get("convection", None)  # type: ignore[arg-type]


def test_a_particle_file_column_beside_the_entrys_value_is_told(tmp_path: Path) -> None:
    """A particle file's temperature (velocity) columns set every particle's value, so the
    entry's `temperature` (a non-zero `velocity`) beside them was silently unused (a list
    entry refuses the same pair); told by validate, and not told without the columns."""
    rows = "x y z radius vx vy vz temperature\n0.003 0.003 0.003 0.001 0 0 0 350\n"
    (tmp_path / "bed.txt").write_text(rows)
    (tmp_path / "plain.txt").write_text("x y z radius\n0.003 0.003 0.003 0.001\n")

    def entry(name: str) -> dict:
        return {"kind": "file", "path": str(tmp_path / name), "material": "glass",
                "temperature": 300.0, "velocity": [0.0, 0.0, -0.1]}  # fmt: skip

    thermal = {"direct_conduction": "none"}
    result = _cli("validate", _write(tmp_path, insertion=[entry("bed.txt")], thermal=thermal))
    assert result.exit_code == 0, result.output
    assert "has a temperature column" in result.output
    assert "the entry's temperature = 300 K is not used" in result.output
    assert "the entry's velocity [0.0, 0.0, -0.1] m/s is not used" in result.output
    result = _cli("validate", _write(tmp_path, insertion=[entry("plain.txt")], thermal=thermal))
    assert result.exit_code == 0, result.output
    assert "is not used" not in result.output


def test_one_particle_written_without_its_outer_brackets_is_one_message(tmp_path: Path) -> None:
    """``positions: [x, y, z]`` for one particle gave three lines 'should be a list of 3
    values (got 0.005)'; one line says what was meant. Two particles in the plane too."""
    entry = {"kind": "list", "material": "glass", "positions": [0.005, 0.005, 0.005],
             "radius": 0.001}  # fmt: skip
    result = _cli("validate", _write(tmp_path, insertion=[entry]))
    assert result.exit_code == 2
    assert (
        "insertion.0.positions: a list of vectors, one [x, y, z] per particle; got the numbers "
        "[0.005, 0.005, 0.005]: for one particle write [[0.005, 0.005, 0.005]]"
    ) in result.output
    assert result.output.count("insertion.0.positions") == 1, result.output
    entry = {**entry, "positions": [[0.005, 0.005, 0.005]], "velocities": [0.0, 0.0, -1.0]}
    result = _cli("validate", _write(tmp_path, insertion=[entry]))
    assert result.exit_code == 2
    assert "insertion.0.velocities: a list of vectors, one [x, y, z] per particle" in result.output
    entry = {**entry, "velocities": [[0.0, 0.0, -1.0]]}
    assert _cli("validate", _write(tmp_path, insertion=[entry])).exit_code == 0
