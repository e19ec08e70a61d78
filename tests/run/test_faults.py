"""Faults around the run directory (issue 17, section 7): each is refused with a message naming
what is wrong before anything in the directory changes, or repaired with a message.

Output path under a file, --threads above the core count, --overwrite or restart of a directory
a live process writes (run.lock), restart with a bad end time, damaged checkpoints (a missing
group, bad JSON or YAML, short arrays), a checkpoint of another run copied in, a truncated last
row of timeseries.csv, and VTU frames of an empty bed."""

from __future__ import annotations

import copy
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.config.load import case_from_dict
from thermodem.engine.runner import LOCK_FILE, process_start, read_timeseries, run_case
from thermodem.engine.simulation import Simulation
from thermodem.io.checkpoint import list_checkpoints, write_checkpoint
from thermodem.io.vtk import write_particles_vtu, write_walls_vtu
from thermodem.io.vtk_read import read_vtu

BOX = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.0002, "seed": 2},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {"glass": {"density": 2500, "youngs_modulus": 1.0e7, "poisson_ratio": 0.3}},
    "walls": [
        {"kind": "box", "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01], "material": "glass"}
    ],
    "insertion": [
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.0008},
            "lower": [0.0, 0.0, 0.0],
            "upper": [0.01, 0.01, 0.01],
            "spacing": 0.0017,  # gaps of 0.1 mm < the skin: near pairs are listed
        }
    ],
    "output": {"interval": 0.0001, "checkpoint_interval": 0.0001, "timeseries_interval": 5e-5},
}


def _case_file(tmp_path: Path, data: dict | None = None, name: str = "case.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data or BOX))
    return path


def _invoke(*args: str):  # noqa: ANN202
    return CliRunner().invoke(app, [*args])


def _snapshot(directory: Path) -> dict[str, str]:
    """Every file of a directory tree -> hash of its bytes (what 'nothing changed' means)."""
    return {
        str(p.relative_to(directory)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished run (20 steps, checkpoints at 10 and 20), copied by the tests that damage it."""
    out = tmp_path_factory.mktemp("finished") / "out"
    run_case(case_from_dict(BOX), out, log=None, progress=False)
    return out


def _copy(src: Path, dst: Path) -> Path:
    import shutil

    shutil.copytree(src, dst)
    return dst


# ------------------------------------------------------------------------ output path, threads
def test_output_path_under_a_file_is_refused(tmp_path: Path) -> None:
    case = _case_file(tmp_path)
    blocker = tmp_path / "results.txt"
    blocker.write_text("not a directory")
    result = _invoke("run", str(case), "--output", str(blocker / "out"), "--no-progress")
    assert result.exit_code == 2, result.output
    assert "is a file, not a directory" in result.output and "Traceback" not in result.output
    assert blocker.read_text() == "not a directory"


def test_output_path_the_system_refuses_is_an_error_not_a_traceback(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A name too long (OSError from the path check) and a directory the file system will not
    create (read-only, /proc: mkdir fails although the parent looks writable) ended in a
    traceback."""
    import errno

    case = _case_file(tmp_path)
    result = _invoke("run", str(case), "--output", str(tmp_path / ("a" * 300)), "--no-progress")
    assert result.exit_code == 2, result.output
    assert "cannot be used: File name too long; choose another --output" in result.output
    assert "Traceback" not in result.output

    def refuse(self: Path, *args: object, **kwargs: object) -> None:
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(Path, "mkdir", refuse)
    result = _invoke("run", str(case), "--output", str(tmp_path / "out"), "--no-progress")
    assert result.exit_code == 2, result.output
    assert "the directory cannot be created: Read-only file system" in result.output
    assert "Traceback" not in result.output


def test_export_and_plot_paths_the_system_refuses_are_errors_not_tracebacks(
    tmp_path: Path, finished: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """export --out /proc/x.csv (a file the file system will not create), a name too long, and
    plot --out into such a directory ended in a FileNotFoundError / OSError traceback."""
    import errno

    long = str(tmp_path / ("a" * 300))
    for args, expected in (
        (("export", str(finished), "--out", "/proc/x.csv"),
         "error: --out '/proc/x.csv': the file cannot be written: No such file or directory; "
         "choose another --out"),
        (("export", str(finished), "--frame", "0", "--out", long + ".csv"),
         "the file cannot be written: File name too long; choose another --out"),
        (("plot", str(finished), "--out", long),
         "cannot be used: File name too long; choose another --out"),
        (("plot", str(finished), "--out", "/proc/self"),
         "error: --out '/proc/self': energies.png cannot be written: No such file or directory; "
         "choose another --out"),
    ):  # fmt: skip
        result = _invoke(*args)
        assert result.exit_code == 2, result.output
        assert expected in result.output, result.output
        assert "Traceback" not in result.output

    def refuse(self: Path, *args: object, **kwargs: object) -> None:
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(Path, "write_text", refuse)
    result = _invoke("export", str(finished), "--out", str(tmp_path / "p.csv"))
    assert result.exit_code == 2, result.output
    assert "the file cannot be written: Read-only file system; choose another --out" in (
        result.output
    )
    assert not list(tmp_path.glob(".p.csv.*"))


def test_threads_above_the_core_count_are_clamped_with_a_message(tmp_path: Path) -> None:
    case = _case_file(tmp_path)
    cores = len(os.sched_getaffinity(0))
    result = _invoke("validate", str(case), "--threads", str(cores + 7))
    assert result.exit_code == 0, result.output
    assert f"--threads {cores + 7} is more than the {cores} core(s)" in result.output
    assert f"using {cores}" in result.output
    assert f"on {cores} thread(s)" in result.output  # the estimate uses the clamped count


def test_a_refused_input_leaves_a_record_the_next_run_may_reuse(tmp_path: Path) -> None:
    """The input is refused while the simulation is built (a particle file that is missing):
    the directory keeps the refusal (run.log, status.json 'failed'), running the same command
    again tells the same error (not 'exists and is not empty'), and once the case is fixed the
    same command runs without --overwrite. A directory holding anything else is still refused."""
    data = copy.deepcopy(BOX)
    data["insertion"] = [{"kind": "file", "material": "glass", "path": "beads.txt"}]
    case = _case_file(tmp_path, data)
    out = tmp_path / "out"
    for _ in range(2):
        result = _invoke("run", str(case), "--output", str(out), "--no-progress")
        assert result.exit_code == 2, result.output
        assert "insertion.0.path: particle file" in result.output
        assert "does not exist" in result.output and "not empty" not in result.output
        assert json.loads((out / "status.json").read_text())["refused_input"] is True
    (tmp_path / "beads.txt").write_text("x y z r\n0.005 0.005 0.005 0.001\n")
    result = _invoke("run", str(case), "--output", str(out), "--no-progress")
    assert result.exit_code == 0, result.output
    assert json.loads((out / "status.json").read_text())["status"] == "finished"
    # a finished run's directory, or a refusal record beside a user's file, needs --overwrite
    result = _invoke("run", str(case), "--output", str(out), "--no-progress")
    assert result.exit_code == 2 and "exists and is not empty" in result.output
    (tmp_path / "beads.txt").unlink()
    other = tmp_path / "other"
    assert _invoke("run", str(case), "--output", str(other)).exit_code == 2
    (other / "notes.txt").write_text("mine")
    result = _invoke("run", str(case), "--output", str(other), "--no-progress")
    assert result.exit_code == 2 and "exists and is not empty" in result.output
    assert (other / "notes.txt").read_text() == "mine"


# ------------------------------------------------------------------------------- run.lock
def test_overwrite_of_a_directory_a_live_process_writes_is_refused(
    tmp_path: Path, finished: Path
) -> None:
    """A lock naming a live process (a stand-in: `sleep`) refuses --overwrite and restart
    without changing anything; once that process is gone the stale lock is taken over."""
    out = _copy(finished, tmp_path / "out")
    holder = subprocess.Popen(["sleep", "60"])
    try:
        lock = {"pid": holder.pid, "host": os.uname().nodename, "started": "now"}
        lock["start"] = process_start(holder.pid)
        (out / LOCK_FILE).write_text(json.dumps(lock))
        before = _snapshot(out)
        case = _case_file(tmp_path)
        result = _invoke("run", str(case), "--output", str(out), "--overwrite", "--no-progress")
        assert result.exit_code == 2, result.output
        assert f"is being written by a running thermodem process (pid {holder.pid}" in result.output
        assert "--overwrite refused" in result.output
        again = _invoke("restart", str(out), "--end-time", "0.0003", "--no-progress")
        assert again.exit_code == 2 and "restart refused" in again.output
        assert _snapshot(out) == before
    finally:
        holder.kill()
        holder.wait()
    result = _invoke("run", str(case), "--output", str(out), "--overwrite", "--no-progress")
    assert result.exit_code == 0, result.output
    assert not (out / LOCK_FILE).exists()  # released at the end


def test_a_reused_pid_is_not_a_live_writer(tmp_path: Path, finished: Path) -> None:
    """A lock whose pid now belongs to another process (other start time) is stale."""
    out = _copy(finished, tmp_path / "out")
    lock = {"pid": os.getppid(), "host": os.uname().nodename, "start": "1", "started": "x"}
    (out / LOCK_FILE).write_text(json.dumps(lock))
    case = _case_file(tmp_path)
    result = _invoke("run", str(case), "--output", str(out), "--overwrite", "--no-progress")
    assert result.exit_code == 0, result.output


def test_a_real_second_run_into_a_running_directory_is_refused(tmp_path: Path) -> None:
    """Two processes: the second `run --overwrite` and `restart` are refused while the first
    one steps; the first finishes cleanly after SIGINT, its time series in order."""
    data = copy.deepcopy(BOX)
    data["simulation"]["end_time"] = 2.0
    data["output"] = {"interval": 1.0}
    case = _case_file(tmp_path, data)
    out = tmp_path / "out"
    exe = Path(sys.executable).with_name("thermodem")
    proc = subprocess.Popen(
        [str(exe), "run", str(case), "--output", str(out), "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            status = out / "status.json"
            if status.exists() and json.loads(status.read_text()).get("status") == "running":
                break
            time.sleep(0.2)
        assert (out / LOCK_FILE).exists()
        second = _invoke("run", str(case), "--output", str(out), "--overwrite", "--no-progress")
        assert second.exit_code == 2, second.output
        assert f"(pid {proc.pid} on" in second.output
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, stdout + stderr
    assert not (out / LOCK_FILE).exists()
    steps = read_timeseries(out / "timeseries.csv")["step"]
    assert np.all(np.diff(steps) > 0)


# ------------------------------------------------------------------------------- restart
@pytest.mark.parametrize("end", ["-1", "nan", "inf", "0"])
def test_restart_with_a_bad_end_time_changes_nothing(tmp_path: Path, finished: Path, end) -> None:
    out = _copy(finished, tmp_path / "out")
    before = _snapshot(out)
    result = _invoke("restart", str(out), f"--end-time={end}", "--no-progress")
    assert result.exit_code == 2, result.output
    assert "--end-time:" in result.output and "finite end time > 0" in result.output
    assert _snapshot(out) == before


def test_restart_with_an_end_time_before_the_checkpoint(tmp_path: Path, finished: Path) -> None:
    out = _copy(finished, tmp_path / "out")
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--end-time", "0.0001", "--no-progress")
    assert result.exit_code == 2 and "is before the time of the newest checkpoint" in result.output
    assert _snapshot(out) == before


def _drop_group(path: Path) -> None:
    with h5py.File(path, "a") as f:
        del f["pairs"]


def _bad_json(path: Path) -> None:
    with h5py.File(path, "a") as f:
        del f["scalars_json"]
        f.create_dataset("scalars_json", data='{"time": 0.0002,', dtype=h5py.string_dtype())


def _bad_yaml(path: Path) -> None:
    with h5py.File(path, "a") as f:
        del f["case_yaml"]
        f.create_dataset("case_yaml", data="simulation: {time_step: [", dtype=h5py.string_dtype())


def _short_array(path: Path) -> None:
    with h5py.File(path, "a") as f:
        radius = f["particles/radius"][()]
        del f["particles/radius"]
        f.create_dataset("particles/radius", data=radius[:-3])


def _bad_pair_index(path: Path) -> None:
    with h5py.File(path, "a") as f:
        assert f["pairs/i"].shape[0] > 0
        f["pairs/i"][0] = 10**6


@pytest.mark.parametrize(
    ("damage", "expected"),
    [
        (_drop_group, "it has no pairs"),
        (_bad_json, "its scalars are not valid JSON"),
        (_bad_yaml, "the stored case is not valid YAML"),
        (_short_array, "particle array 'radius' has shape (122,), but there are 125 particles"),
        (_bad_pair_index, "pair indices outside"),
    ],
    ids=["missing-group", "bad-json", "bad-yaml", "short-array", "bad-index"],
)
def test_restart_refuses_a_damaged_checkpoint_before_touching_anything(
    tmp_path: Path, finished: Path, damage, expected: str
) -> None:
    out = _copy(finished, tmp_path / "out")
    newest = list_checkpoints(out / "checkpoints")[-1]
    damage(newest)
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--end-time", "0.0003", "--no-progress")
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert str(newest) in result.output and expected in result.output
    assert "nothing was changed" in result.output
    assert "thermodem run --restart" in result.output  # the older checkpoint is offered
    assert _snapshot(out) == before
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "finished"


def test_restart_refuses_a_checkpoint_of_another_run(tmp_path: Path, finished: Path) -> None:
    """A checkpoint of another case copied into DIR: refused by the run id; one without a run
    id (written through the API) by the stored case; nothing changed either way."""
    other = copy.deepcopy(BOX)
    other["materials"]["glass"]["density"] = 2600
    elsewhere = tmp_path / "elsewhere"
    run_case(case_from_dict(other), elsewhere, log=None, progress=False)
    out = _copy(finished, tmp_path / "out")
    foreign = list_checkpoints(elsewhere / "checkpoints")[-1]
    target = out / "checkpoints" / "checkpoint_000000999.h5"
    target.write_bytes(foreign.read_bytes())
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--no-progress")
    assert result.exit_code == 2, result.output
    assert "was written by another run (run_id" in result.output
    assert _snapshot(out) == before
    # no run id: the stored case decides (density differs)
    sim = Simulation.from_checkpoint(str(foreign))
    target.unlink()
    write_checkpoint(sim, target)
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--no-progress")
    assert result.exit_code == 2, result.output
    assert "holds another case than" in result.output
    assert "materials.glass.density" in result.output
    assert _snapshot(out) == before


def test_truncated_last_timeseries_row_is_dropped_with_a_message(
    tmp_path: Path, finished: Path
) -> None:
    out = _copy(finished, tmp_path / "out")
    path = out / "timeseries.csv"
    text = path.read_text()
    path.write_text(text + text.splitlines()[-1][:25])  # a half-written row, no line end
    result = _invoke("restart", str(out), "--end-time", "0.0003", "--no-progress")
    assert result.exit_code == 0, result.output
    assert "its last row (line" in result.output and "was incomplete (no line end" in result.output
    series = read_timeseries(path)
    assert np.all(np.diff(series["step"]) > 0) and series["step"][-1] == 30
    assert not np.any(np.isnan(series["kinetic_translational"]))


def test_a_damaged_middle_row_of_the_timeseries_is_refused(tmp_path: Path, finished: Path) -> None:
    out = _copy(finished, tmp_path / "out")
    path = out / "timeseries.csv"
    lines = path.read_text().splitlines()
    lines[2] = "garbage"
    path.write_text("\n".join(lines) + "\n")
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--end-time", "0.0003", "--no-progress")
    assert result.exit_code == 2 and "line 3: damaged row" in result.output
    assert _snapshot(out) == before


# ---------------------------------------------------------------------------- empty frames
def _vtk_reader():  # noqa: ANN202
    vtk = pytest.importorskip("vtk", reason="VTK (the vtk wheel) is not installed")
    return vtk


def test_an_empty_particle_frame_is_a_valid_vtu(tmp_path: Path) -> None:
    """No particles: VTK reads the file with every array (0 tuples, right components);
    read_vtu does too (meshio 5.3 itself fails on any VTU without cells, meshio #1412)."""
    path = tmp_path / "particles.vtu"
    fields = {
        "radius": np.zeros(0),
        "velocity": np.zeros((0, 3)),
        "type_id": np.zeros(0, np.int32),
        "global_id": np.zeros(0, np.int64),
    }
    write_particles_vtu(path, np.zeros((0, 3)), fields)
    mesh = read_vtu(path)
    assert mesh.points.shape == (0, 3)
    assert {k: (v.shape, v.dtype) for k, v in mesh.point_data.items()} == {
        "radius": ((0,), np.float64),
        "velocity": ((0, 3), np.float64),
        "type_id": ((0,), np.int32),
        "global_id": ((0,), np.int64),
    }
    vtk = _vtk_reader()
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    assert reader.GetErrorCode() == 0
    assert (grid.GetNumberOfPoints(), grid.GetNumberOfCells()) == (0, 0)
    data = grid.GetPointData()
    names = {data.GetArrayName(k): data.GetArray(k) for k in range(data.GetNumberOfArrays())}
    assert set(names) == set(fields)
    assert names["velocity"].GetNumberOfComponents() == 3


def test_a_run_that_starts_empty_writes_readable_frames(tmp_path: Path) -> None:
    """Walls only until a pour starts: every particle frame and wall frame reads back."""
    data = copy.deepcopy(BOX)
    data["simulation"]["end_time"] = 0.001
    data["insertion"] = [
        {
            "kind": "pour",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.0008},
            "region": {"kind": "box", "lower": [0.001, 0.001, 0.005], "upper": [0.009] * 3},
            "rate": 20000.0,
            "interval": 0.0002,
            "start_time": 0.0005,
        }
    ]
    data["output"] = {"interval": 0.0002}
    out = tmp_path / "out"
    run_case(case_from_dict(data), out, log=None, progress=False)
    counts = [read_vtu(p).points.shape[0] for p in sorted((out / "vtk").glob("particles_*"))]
    assert counts[0] == 0 and counts[-1] > 0
    for p in sorted((out / "vtk").glob("walls_*")):
        assert read_vtu(p).cells[0].data.shape[0] > 0
    vtk = _vtk_reader()
    for p in sorted((out / "vtk").glob("*.vtu")):
        reader = vtk.vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(p))
        reader.Update()
        assert reader.GetErrorCode() == 0, p


def test_walls_vtu_without_walls_reads_back(tmp_path: Path) -> None:
    from thermodem.geometry.wall_layout import WALL_WIDTH

    path = tmp_path / "walls.vtu"
    write_walls_vtu(path, np.zeros(0, np.int64), np.zeros((0, WALL_WIDTH)), {"t": np.zeros(0)})
    mesh = read_vtu(path)
    assert mesh.points.shape == (0, 3) and mesh.cells[0].type == "triangle"
    assert set(mesh.cell_data) == {"wall_id", "t"}


def test_a_broken_pvd_index_is_refused_before_the_restart_touches_anything(
    tmp_path: Path, finished: Path
) -> None:
    out = _copy(finished, tmp_path / "out")
    (out / "particles.pvd").write_text("<VTKFile type='Collection'><Collection>")  # cut off
    before = _snapshot(out)
    result = _invoke("restart", str(out), "--end-time", "0.0003", "--no-progress")
    assert result.exit_code == 2 and "particles.pvd cannot be read" in result.output
    assert _snapshot(out) == before


def test_read_vtu_keeps_the_field_data_of_an_empty_frame(tmp_path: Path) -> None:
    """Name tables stored as FieldData (ascii Int32 arrays, one per name) come back for an
    empty frame as meshio gives them for a non-empty one."""
    table = (
        '<FieldData><DataArray type="Int32" Name="material_id 0 = glass" NumberOfTuples="1" '
        'format="ascii">0</DataArray><DataArray type="Int32" Name="material_id 1 = steel" '
        'NumberOfTuples="1" format="ascii">1</DataArray></FieldData>'
    )
    meshes = []
    for n in (0, 2):
        path = tmp_path / f"p{n}.vtu"
        write_particles_vtu(path, np.zeros((n, 3)), {"radius": np.ones(n)})
        text = path.read_text().replace("<UnstructuredGrid>", "<UnstructuredGrid>" + table, 1)
        path.write_text(text)
        meshes.append(read_vtu(path))
    empty, full = meshes
    assert (
        empty.field_data.keys()
        == full.field_data.keys()
        == {
            "material_id 0 = glass",
            "material_id 1 = steel",
        }
    )
    for key, value in full.field_data.items():
        assert (
            np.array_equal(empty.field_data[key], value)
            and empty.field_data[key].dtype == value.dtype
        )


# ------------------------------------------------------------- outputs refused during the run
def test_an_output_refused_mid_run_stops_with_a_message_and_restart_continues(
    tmp_path: Path, finished: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A disk filling up (or a read-only remount) in the middle of a run ended in an OSError
    traceback and left status.json saying 'running'; the run directory removed, the same."""
    import errno
    import shutil

    from thermodem.engine.runner import TimeseriesWriter

    original = TimeseriesWriter.write

    def full(self: TimeseriesWriter, sim: Simulation) -> None:
        if sim.step_count == 15:
            raise OSError(errno.ENOSPC, "No space left on device")
        original(self, sim)

    monkeypatch.setattr(TimeseriesWriter, "write", full)
    case = _case_file(tmp_path)
    out = tmp_path / "out"
    result = _invoke("run", str(case), "--output", str(out), "--no-progress")
    assert result.exit_code == 1, result.output
    assert (
        f"error: the run directory {out} cannot be written at step 15 (t = 0.00015 s): No "
        "space left on device; the run stopped" in result.output
    )
    ckpt = out / "checkpoints" / "checkpoint_000000010.h5"
    assert f"last checkpoint on disk: {ckpt}; once the directory can be written again, " in (
        result.output
    )
    assert "Traceback" not in result.output
    assert json.loads((out / "status.json").read_text())["status"] == "failed"
    assert not (out / LOCK_FILE).exists()
    # space again: the restart the message names finishes as an uninterrupted run
    monkeypatch.setattr(TimeseriesWriter, "write", original)
    again = _invoke("restart", str(out), "--no-progress")
    assert again.exit_code == 0, again.output
    final = "checkpoints/checkpoint_000000020.h5"
    with h5py.File(out / final) as a, h5py.File(finished / final) as b:
        for name in ("position", "velocity", "angular_velocity"):
            assert np.array_equal(a["particles"][name][()], b["particles"][name][()])
    assert (out / "timeseries.csv").read_bytes() == (finished / "timeseries.csv").read_bytes()

    def removed(self: TimeseriesWriter, sim: Simulation) -> None:
        if sim.step_count == 15:
            shutil.rmtree(self.path.parent)
        original(self, sim)

    monkeypatch.setattr(TimeseriesWriter, "write", removed)
    gone = tmp_path / "gone"
    result = _invoke("run", str(case), "--output", str(gone), "--no-progress")
    assert result.exit_code == 1, result.output
    assert f"the run directory {gone} cannot be written at step 15" in result.output
    assert "No such file or directory" in result.output
    assert f"no checkpoint of this run is left in {gone}: start it again" in result.output
    assert "Traceback" not in result.output
