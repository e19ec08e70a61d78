"""What a newcomer meets first (issue 17 §8): ``--version``, ``run --steps / --end-time``, the
compile note of a cold cache, the run-time estimate, ``thermodem export``, the thermal
example showing heat early, and the thread choice in run.log."""

from __future__ import annotations

import csv
import math
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

import thermodem
from thermodem.cli import app
from thermodem.config.load import case_from_dict, load_case
from thermodem.engine import kernel_cache
from thermodem.engine import validation as V
from thermodem.engine.simulation import Simulation
from thermodem.io.checkpoint import list_checkpoints, read_checkpoint

ROOT = Path(__file__).parents[2]
HOT = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.01, "initial_temperature": 300.0},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {
        "glass": {
            "density": 2500,
            "youngs_modulus": 1.0e7,
            "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0,
            "specific_heat": 800.0,
        },
        "steel": {"density": 7800, "youngs_modulus": 1.0e7, "poisson_ratio": 0.3},
    },  # fmt: skip
    "walls": [
        {
            "kind": "box",
            "name": "tray",
            "lower": [0, 0, 0],
            "upper": [0.01, 0.01, 0.01],
            "material": "steel",
            "open_top": True,
        },
        {
            "kind": "plane",
            "name": "heater",
            "point": [0, 0, 0.0002],
            "normal": [0, 0, 1],
            "material": "glass",
            "thermal": {"kind": "fixed", "temperature": 400.0},
        },
    ],  # fmt: skip
    "insertion": [
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.0008},
            "lower": [0, 0, 0],
            "upper": [0.01, 0.01, 0.01],
            "spacing": 0.002,
        },
    ],  # fmt: skip
    "thermal": {"contact_radius": "geometric", "direct_conduction": "batchelor_obrien_simple"},
    "output": {"interval": 0.005},
}


def _case_file(tmp_path: Path, data: dict = HOT) -> Path:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _run(*args: str):  # noqa: ANN202
    return CliRunner().invoke(app, [*args])


def test_version() -> None:
    result = _run("--version")
    assert result.exit_code == 0 and result.output.strip() == f"thermodem {thermodem.__version__}"
    exe = Path(sys.executable).with_name("thermodem")
    proc = subprocess.run([str(exe), "--version"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and proc.stdout.strip() == f"thermodem {thermodem.__version__}"


def test_python_dash_m_runs_the_same_command_line() -> None:
    """``python -m thermodem`` (what users type when the script is not on PATH) is the same
    command line, and its usage names the program ``thermodem``, not ``__main__.py``."""
    version = subprocess.run([sys.executable, "-m", "thermodem", "--version"],
                             capture_output=True, text=True, timeout=60)  # fmt: skip
    assert (
        version.returncode == 0 and version.stdout.strip() == f"thermodem {thermodem.__version__}"
    )
    usage = subprocess.run([sys.executable, "-m", "thermodem", "run"], capture_output=True,
                           text=True, timeout=60)  # fmt: skip
    assert usage.returncode == 2 and "Usage: thermodem run" in usage.stderr, usage.stderr


def test_run_steps_and_end_time_shorten_a_case(tmp_path: Path) -> None:
    case = _case_file(tmp_path)
    out = tmp_path / "steps"
    result = _run("run", str(case), "-o", str(out), "--steps", "40", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "done: 40 steps" in (out / "run.log").read_text()
    resolved = yaml.safe_load((out / "case.resolved.yaml").read_text())
    assert resolved["simulation"]["end_time"] == pytest.approx(40 * 1.0e-5)
    assert read_checkpoint(list_checkpoints(out / "checkpoints")[-1]).step == 40
    out2 = tmp_path / "end"
    result = _run("run", str(case), "-o", str(out2), "--end-time", "3e-4", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "done: 30 steps" in (out2 / "run.log").read_text()
    # from a checkpoint: --steps counts from the checkpoint's step
    ckpt = list_checkpoints(out / "checkpoints")[-1]
    out3 = tmp_path / "more"
    result = _run("run", "--restart", str(ckpt), "-o", str(out3), "--steps", "10", "--no-progress")
    assert result.exit_code == 0, result.output
    assert read_checkpoint(list_checkpoints(out3 / "checkpoints")[-1]).step == 50


@pytest.mark.parametrize(
    "args, message",
    [
        (["--end-time", "-1"], "--end-time -1.0: must be finite and greater than 0"),
        (["--end-time", "nan"], "--end-time nan: must be finite"),
        (["--end-time", "1", "--steps", "3"], "give --end-time or --steps, not both"),
    ],
)
def test_run_shortening_errors(tmp_path: Path, args: list[str], message: str) -> None:
    result = _run("run", str(_case_file(tmp_path)), "-o", str(tmp_path / "o"), *args)
    assert result.exit_code == 2 and message in result.output, result.output
    assert "Traceback" not in result.output
    steps = _run("run", str(_case_file(tmp_path)), "-o", str(tmp_path / "o"), "--steps", "0")
    assert steps.exit_code == 2


def test_compile_note_when_the_cache_is_cold(tmp_path: Path, monkeypatch) -> None:
    mech = case_from_dict({k: v for k, v in HOT.items() if k != "thermal"})
    heat = case_from_dict(HOT)
    empty = tmp_path / "cache"
    empty.mkdir()
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(empty))
    assert kernel_cache.cold_parts(False) == ["mechanics"]
    assert kernel_cache.cold_parts(True) == ["mechanics", "heat"]
    note = kernel_cache.compile_note(heat)
    seconds = kernel_cache.COMPILE_SECONDS_MECHANICS + kernel_cache.COMPILE_SECONDS_HEAT
    assert note == f"compiling kernels (first run only, ~{seconds:.0f} s; kept in {empty})"
    sub = empty / "kernels_0123"
    sub.mkdir()

    def index(name: str, source: str, fresh: bool = True) -> None:
        """An index file as Numba writes it: a pickled version, then (stamp, overloads)."""
        import pickle

        from thermodem import _numba_cache

        stamp = _numba_cache.dependency_stamp(str(_numba_cache.PACKAGE_ROOT / source))
        data = pickle.dumps("version") + pickle.dumps((stamp if fresh else "old", {}))
        (sub / name).write_bytes(data)

    index("integrate.kick_drift-20.py311.nbi", "kernels/integrate.py", fresh=False)
    assert kernel_cache.cold_parts(False) == ["mechanics"]  # a stale entry is cold
    index("integrate.kick_drift-20.py311.nbi", "kernels/integrate.py")
    assert kernel_cache.compile_note(mech) is None
    assert kernel_cache.cold_parts(True) == ["heat"]
    index("thermal.euler_step-306.py311.nbi", "kernels/thermal.py")
    assert kernel_cache.compile_note(heat) is None


def test_run_log_says_compiling_and_the_threads(tmp_path: Path, monkeypatch) -> None:
    from thermodem.engine.runner import run_case

    monkeypatch.setattr(kernel_cache, "cold_parts", lambda heat: ["mechanics", "heat"])
    out = tmp_path / "out"
    case = load_case(_case_file(tmp_path))
    case.simulation.end_time = 1.0e-4
    run_case(case, out, log=None)
    lines = (out / "run.log").read_text().splitlines()
    first = next(i for i, line in enumerate(lines) if "compiling kernels (first run only" in line)
    threads = next(i for i, line in enumerate(lines) if "threads: " in line)
    assert first < threads  # said before the simulation is built
    assert "threads: 1 (chosen for 125 particles" in lines[threads]
    assert "threading layer omp" in lines[threads]


def _estimate(data: dict, threads: int | None = None):  # noqa: ANN202
    sim = Simulation(case_from_dict(data), threads=threads)
    return sim, V.estimate_resources(sim, sim.threads)


def test_run_time_estimate_is_fixed_cost_per_step_plus_per_particle() -> None:
    """The estimate's two parts against the constants, by hand (mechanics and heat)."""
    mech = {k: v for k, v in HOT.items() if k != "thermal"}
    sim, est = _estimate(mech)
    steps = 1000
    assert est.steps == steps and est.threads == 1
    assert est.particle_steps == pytest.approx(125 * steps)
    rows, files = 1001, 11 + 3  # time series end/1000 (+1), checkpoints end/10, frames 2
    writing = rows * V.ROW_SECONDS + files * (V.FILE_SECONDS + 125 * V.FILE_SECONDS_PER_PARTICLE)
    assert est.step_seconds == pytest.approx(steps * V.STEP_SECONDS + writing)
    assert est.run_seconds == pytest.approx(
        est.step_seconds + 125 * steps * V.PARTICLE_STEP_SECONDS
    )
    hsim, hot = _estimate(HOT)
    per_step = V.STEP_SECONDS + V.HEAT_STEP_SECONDS / hsim.thermal.substeps
    assert hot.step_seconds == pytest.approx(steps * per_step + writing)
    assert hot.run_seconds > est.run_seconds
    _, two = _estimate(mech, threads=2) if numba.config.NUMBA_NUM_THREADS > 1 else (None, None)
    if two is not None:
        assert two.step_seconds == pytest.approx(
            steps * (V.STEP_SECONDS + V.THREAD_STEP_SECONDS) + writing
        )
        assert two.run_seconds - two.step_seconds == pytest.approx(
            125 * steps * V.PARTICLE_STEP_SECONDS / V.THREAD_SPEED_UP
        )
    line = next(x for x in est.lines() if x.startswith("estimated run time"))
    assert "fixed cost per step" in line and "on 1 thread(s)" in line


def test_small_case_estimate_is_not_dominated_by_particles() -> None:
    """A 2-sphere case of 100,000 steps is estimated at seconds, not at a fraction of one
    (the old estimate's 2e5 particle-steps at 3e6/s gave 0.07 s plus 15 s of steps)."""
    data = yaml.safe_load(yaml.safe_dump(HOT))
    data["insertion"][0]["spacing"] = 0.0045  # 2 x 2 x 2
    data["simulation"]["end_time"] = 1.0
    sim, est = _estimate(data)
    assert sim.particles.count == 8
    assert est.run_seconds > 100_000 * V.STEP_SECONDS
    assert est.step_seconds / est.run_seconds > 0.9


def test_export_csv_from_a_frame_and_a_checkpoint(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = _run("run", str(_case_file(tmp_path)), "-o", str(out), "--steps", "600",
                  "--no-progress")  # fmt: skip
    assert result.exit_code == 0, result.output
    # the newest checkpoint, by default
    result = _run("export", str(out))
    assert result.exit_code == 0, result.output
    path = Path(result.output.strip())
    assert path == out / "particles_step_000000600.csv"
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# thermodem export: checkpoint") and "step 600" in lines[0]
    rows = list(csv.DictReader(lines[1:]))
    sim = Simulation.from_checkpoint(list_checkpoints(out / "checkpoints")[-1])
    p = sim.particles
    order = np.argsort(p.global_id)
    assert len(rows) == p.count == 125
    assert [int(r["global_id"]) for r in rows] == sorted(p.global_id.tolist())
    assert {r["material"] for r in rows} == {"glass"}
    for name, column in (("x", 0), ("vz", 2)):
        source = p.position if name == "x" else p.velocity
        got = np.array([float(r[name]) for r in rows])
        assert np.array_equal(got, source[order, column])  # exact (repr of the float)
    got_t = np.array([float(r["temperature"]) for r in rows])
    assert np.array_equal(got_t, p.temperature[order]) and got_t.max() > 300.0  # heated
    got_q = np.array([float(r["heat_rate"]) for r in rows])
    assert np.array_equal(got_q, p.heat_rate[order])
    # the last frame (the same state) to standard output
    frame = _run("export", str(out), "--frame", "-1", "--out", "-")
    assert frame.exit_code == 0, frame.output
    frame_rows = list(csv.DictReader(frame.output.splitlines()[1:]))
    assert frame.output.startswith("# thermodem export: frame 2 of")  # 0, 0.005 s, the end
    for a, b in zip(rows, frame_rows, strict=True):
        assert a == b
    # the default file of --frame -1 is named by the frame's own number
    named = _run("export", str(out), "--frame", "-1")
    assert named.exit_code == 0 and Path(named.output.strip()) == out / "particles_frame_2.csv"
    # a file that exists is not replaced without --overwrite
    target = tmp_path / "mine.csv"
    target.write_text("my notes\n")
    refused = _run("export", str(out), "--frame", "0", "--out", str(target))
    assert refused.exit_code == 2 and "--overwrite" in refused.output
    assert target.read_text() == "my notes\n"
    again = _run("export", str(out), "--frame", "0", "--out", str(target), "--overwrite")
    assert again.exit_code == 0 and target.read_text().startswith("# thermodem export: frame 0")


@pytest.mark.parametrize(
    "args, message",
    [
        (["--frame", "7"], "--frame 7: "),
        (["--frame", "0", "--checkpoint", "x.h5"], "not both"),
        (["--checkpoint", "missing.h5"], "does not exist"),
    ],
)
def test_export_errors(tmp_path: Path, args: list[str], message: str) -> None:
    out = tmp_path / "out"
    assert _run("run", str(_case_file(tmp_path)), "-o", str(out), "--steps", "5").exit_code == 0
    result = _run("export", str(out), *args)
    assert result.exit_code == 2 and message in result.output, result.output
    assert _run("export", str(tmp_path / "nothing")).exit_code == 2


def test_thermal_example_heats_in_its_first_steps(tmp_path: Path) -> None:
    """examples/heated_bed.yaml: within 0.02 s of simulated time (about a second of wall time)
    the bed has taken heat from the plate and the hottest bead is 10 K above the start."""
    out = tmp_path / "out"
    example = ROOT / "examples" / "heated_bed.yaml"
    result = _run("run", str(example), "-o", str(out), "--end-time", "0.02", "--no-progress")
    assert result.exit_code == 0, result.output
    with (out / "timeseries.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) >= 40  # a row every 0.5 ms
    last = rows[-1]
    assert float(last["temperature_max"]) > 310.0
    assert float(last["heat_in_wall_direct_conduction"]) > 0.0
    walls = sorted((out / "vtk").glob("walls_*.vtu"))
    import meshio

    from thermodem.io.vtk_read import read_name_table

    mesh = meshio.read(walls[-1])
    names = read_name_table(mesh.field_data, "wall_id")
    assert names[0] == "hot_plate"
    plate = mesh.cell_data["wall_id"][0] == 0
    assert np.all(mesh.cell_data["temperature"][0][plate] == 600.0)
    assert np.all(np.isnan(mesh.cell_data["temperature"][0][~plate]))  # adiabatic walls
    assert not math.isnan(float(last["temperature_mean"]))


def test_validate_announces_a_cold_cache_on_stderr(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setattr(kernel_cache, "cold_parts", lambda heat: ["mechanics"])
    result = CliRunner().invoke(app, ["validate", str(_case_file(tmp_path))])
    assert result.exit_code == 0, result.output
    seconds = kernel_cache.COMPILE_SECONDS_MECHANICS
    assert f"# compiling kernels (first run only, ~{seconds:.0f} s" in result.stderr
    assert "compiling" not in result.stdout  # stdout stays the resolved case (valid YAML)
    yaml.safe_load(result.stdout)
