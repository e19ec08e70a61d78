"""The run layer: output directory, time series, checkpoints, restart bit-identity, info, plot."""

from __future__ import annotations

import copy
import csv
import io
import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.config.load import case_from_dict
from thermodem.engine.restarted_runs import restart_run, run_from_checkpoint
from thermodem.engine.runner import TimeseriesWriter, read_timeseries, run_case
from thermodem.errors import RunInterrupted
from thermodem.io.checkpoint import list_checkpoints, read_checkpoint
from thermodem.io.vtk import PVDWriter

GLASS = {
    "density": 2500.0,
    "youngs_modulus": 1.0e7,
    "poisson_ratio": 0.3,
    "restitution": 0.6,
    "sliding_friction": 0.4,
    "rolling_friction": 0.05,
    "thermal_conductivity": 1.0,
    "specific_heat": 800.0,
}


def pour_case(thermal: bool = False) -> dict:
    """A few particles on a hot floor plus a pour, in an open box; 600 steps."""
    case = {
        "simulation": {"time_step": 1.0e-5, "end_time": 0.006, "seed": 5},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.02]},
        "materials": {"glass": dict(GLASS), "steel": dict(GLASS)},
        "contact": {"rolling": "epsd"},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [0.01, 0.01, 0.02],
                "open_top": True,
                "material": "steel",
            }
        ],
        "insertion": [
            {
                "kind": "lattice",
                "material": "glass",
                "distribution": {"kind": "mono", "radius": 0.0009},
                "lower": [0, 0, 0],
                "upper": [0.01, 0.01, 0.004],
                "spacing": 0.00195,
                "velocity": [0.0, 0.0, -0.2],
            },
            {
                "kind": "pour",
                "material": "glass",
                "distribution": {"kind": "uniform", "min_radius": 0.0007, "max_radius": 0.0009},
                "region": {
                    "kind": "box",
                    "lower": [0.001, 0.001, 0.01],
                    "upper": [0.009, 0.009, 0.018],
                },
                "rate": 5000.0,
                "interval": 0.001,
                "end_time": 0.005,
                "velocity": [0.0, 0.0, -0.5],
            },
        ],
        "output": {
            "interval": 0.001,
            "timeseries_interval": 0.0002,
            "checkpoint_interval": 0.002,
            "checkpoint_keep": 2,
        },
    }
    if thermal:
        case["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 400.0}
        case["thermal"] = {"substeps": 2}
    return case


class _StopAt:
    """A callback raising KeyboardInterrupt at one step (what Ctrl-C does between steps)."""

    def __init__(self, step: int) -> None:
        self.step = step

    def __call__(self, sim) -> None:  # noqa: ANN001
        if sim.step_count == self.step:
            raise KeyboardInterrupt


def _quiet(**kw):  # noqa: ANN003, ANN202
    return dict(log=io.StringIO(), progress=False, **kw)


def test_run_writes_the_output_directory(tmp_path: Path) -> None:
    out = tmp_path / "out"
    console = io.StringIO()
    sim = run_case(case_from_dict(pour_case()), out, log=console, progress=False, case_name="p")
    assert sim.step_count == 600
    for name in ("run.log", "case.resolved.yaml", "status.json", "timeseries.csv"):
        assert (out / name).is_file(), name
    log = (out / "run.log").read_text()
    assert "done: 600 steps" in log and "estimated memory" in log
    assert "done: 600 steps" in console.getvalue()
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "finished" and status["step"] == 600 and status["case"] == "p"
    series = read_timeseries(out / "timeseries.csv")
    assert np.array_equal(series["step"], np.arange(0, 601, 20))
    for column in ("time", "kinetic_translational", "dissipated_normal_damping",
                   "energy_balance_error", "particle_count", "contact_count",
                   "max_overlap_ratio"):  # fmt: skip
        assert column in series, column
    assert series["particle_count"][-1] > series["particle_count"][0]  # the pour arrived
    assert series["contact_count"].max() > 0
    # checkpoints: the newest two periodic ones (step 0, 200, 400 written) and the final one
    names = [p.name for p in list_checkpoints(out / "checkpoints")]
    assert names == ["checkpoint_000000400.h5", "checkpoint_000000600.h5"]
    assert read_checkpoint(out / "checkpoints" / names[-1]).kind == "final"
    times = [t for t, _, _ in PVDWriter.read(out / "particles.pvd")]
    assert times == pytest.approx([0, 0.001, 0.002, 0.003, 0.004, 0.005, 0.006])


def test_interrupt_and_restart_reproduce_the_uninterrupted_run(tmp_path: Path) -> None:
    """Stopped at step 333 (between checkpoints), restarted: every output is the same."""
    whole, parts = tmp_path / "whole", tmp_path / "parts"
    ref = run_case(case_from_dict(pour_case()), whole, **_quiet())
    with pytest.raises(RunInterrupted) as info:
        run_case(case_from_dict(pour_case()), parts, **_quiet(callback=_StopAt(333)))
    assert info.value.exit_code == 130
    assert "thermodem restart" in str(info.value)
    assert info.value.checkpoint.endswith("checkpoint_000000333.h5")
    status = json.loads((parts / "status.json").read_text())
    assert status["status"] == "interrupted" and status["step"] == 333
    sim = restart_run(parts, **_quiet())
    assert (parts / "timeseries.csv").read_text() == (whole / "timeseries.csv").read_text()
    assert PVDWriter.read(parts / "particles.pvd") == PVDWriter.read(whole / "particles.pvd")
    last = "vtk/particles_000000600.vtu"
    assert (parts / last).read_bytes() == (whole / last).read_bytes()
    a = read_checkpoint(whole / "checkpoints" / "checkpoint_000000600.h5").state
    b = read_checkpoint(parts / "checkpoints" / "checkpoint_000000600.h5").state
    for group in ("particles", "pairs", "walls", "arrays"):
        for name in a[group]:
            assert np.array_equal(a[group][name], b[group][name]), (group, name)
    assert a["scalars"] == b["scalars"]
    assert sim.energies() == ref.energies()
    assert "restart from" in (parts / "run.log").read_text()


def test_restart_after_a_hard_kill_drops_rows_beyond_the_checkpoint(tmp_path: Path) -> None:
    """A run killed without a checkpoint (simulated: rows and frames written after the last
    checkpoint) continues from that checkpoint, rewriting the later rows and frames."""
    whole, parts = tmp_path / "whole", tmp_path / "parts"
    run_case(case_from_dict(pour_case()), whole, **_quiet())
    run_case(case_from_dict(pour_case()), parts, **_quiet())
    # pretend the run died at step 500: drop the final checkpoint, mark it running
    (parts / "checkpoints" / "checkpoint_000000600.h5").unlink()
    status = json.loads((parts / "status.json").read_text())
    status.update(status="running", pid=2**22 + 12345)
    (parts / "status.json").write_text(json.dumps(status))
    result = CliRunner().invoke(app, ["info", str(parts)])
    assert result.exit_code == 0
    assert "stopped without a final status" in result.output
    restart_run(parts, **_quiet())
    assert (parts / "timeseries.csv").read_text() == (whole / "timeseries.csv").read_text()
    assert PVDWriter.read(parts / "particles.pvd") == PVDWriter.read(whole / "particles.pvd")


def test_run_from_checkpoint_into_a_new_directory_with_a_later_end_time(tmp_path: Path) -> None:
    out = tmp_path / "out"
    run_case(case_from_dict(pour_case()), out, **_quiet())
    data = pour_case()
    data["simulation"]["end_time"] = 0.008
    ckpt = out / "checkpoints" / "checkpoint_000000600.h5"
    sim = run_from_checkpoint(ckpt, tmp_path / "more", case_from_dict(data), **_quiet())
    assert sim.step_count == 800
    series = read_timeseries(tmp_path / "more" / "timeseries.csv")
    assert series["step"][0] == 600 and series["step"][-1] == 800
    # restart DIR with --end-time extends a finished run in place
    result = CliRunner().invoke(app, ["restart", str(out), "--end-time", "0.007", "--no-progress"])
    assert result.exit_code == 0, result.output
    assert read_timeseries(out / "timeseries.csv")["step"][-1] == 700
    again = CliRunner().invoke(app, ["restart", str(out), "--no-progress"])
    assert again.exit_code == 0 and "nothing to do" in again.output


def test_thermal_columns_and_plots(tmp_path: Path) -> None:
    out = tmp_path / "hot"
    run_case(case_from_dict(pour_case(thermal=True)), out, **_quiet())
    series = read_timeseries(out / "timeseries.csv")
    for column in (
        "temperature_mean",
        "temperature_max",
        "heat_in_wall_direct_conduction",
        "heat_balance_error",
    ):
        assert column in series, column
    assert series["temperature_max"][-1] > series["temperature_max"][0]
    result = CliRunner().invoke(app, ["plot", str(out)])
    assert result.exit_code == 0, result.output
    for name in ("energies.png", "contacts.png", "temperature.png", "heat.png"):
        png = out / "plots" / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    info = CliRunner().invoke(app, ["info", str(out)])
    assert info.exit_code == 0
    for text in ("status: finished", "time: 0.006 s of 0.006 s", "frames: 7", "temperature_mean"):
        assert text in info.output, text
    assert "gas (thermal.gas): k_g = 0.0263 W/(m K)" in info.output  # the default, air


def test_heat_generation_columns_and_plot(tmp_path: Path) -> None:
    """A generation mechanism has its rate and ledger columns and its curve in
    generation.png; the columns the mechanics ledger gives match the generation's."""
    data = pour_case(thermal=True)
    data["thermal"]["heat_generation"] = {"model": "mechanical_dissipation",
                                          "partition": "conductivity"}  # fmt: skip
    out = tmp_path / "gen"
    run_case(case_from_dict(data), out, **_quiet())
    series = read_timeseries(out / "timeseries.csv")
    for name in ("sliding_friction", "rolling_friction", "normal_damping", "tangential_damping",
                 "plastic_deformation"):  # fmt: skip
        for prefix in ("heat_rate_generation_", "heat_in_generation_", "generated_",
                       "heat_to_walls_generation_", "heat_pending_generation_"):  # fmt: skip
            assert prefix + name in series, prefix + name
    assert "heat_rate_generation_collision" not in series  # not selected
    last = {k: v[-1] for k, v in series.items()}
    assert last["generated_normal_damping"] == last["dissipated_normal_damping"]
    assert last["heat_in_generation_normal_damping"] > 0.0
    assert last["heat_to_walls_generation_normal_damping"] > 0.0  # the floor is hot: its share
    result = CliRunner().invoke(app, ["plot", str(out)])
    assert result.exit_code == 0, result.output
    assert (out / "plots" / "generation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_timeseries_gains_columns_when_the_engine_reports_more(tmp_path: Path) -> None:
    class Fake:
        def __init__(self, step: int, report: dict) -> None:
            self.step_count, self.time, self._report = step, step * 0.5, report

        def report(self) -> dict:
            return self._report

    path = tmp_path / "ts.csv"
    w = TimeseriesWriter(path)
    w.write(Fake(0, {"a": 1.0}))
    w.write(Fake(1, {"a": 2.0, "heat_rate_radiation": 3.5}))
    w.write(Fake(2, {"a": 0.1}))
    rows = list(csv.reader(path.open()))
    assert rows == [
        ["time", "step", "a", "heat_rate_radiation"],
        ["0.0", "0", "1.0", ""],
        ["0.5", "1", "2.0", "3.5"],
        ["1.0", "2", "0.1", ""],
    ]
    resumed = TimeseriesWriter(path, resume_step=1)
    assert resumed.last_step == 1 and len(list(csv.reader(path.open()))) == 3


def test_info_and_plot_refuse_non_output_directories(tmp_path: Path) -> None:
    runner = CliRunner()
    for command in ("info", "plot", "restart"):
        result = runner.invoke(app, [command, str(tmp_path / "nowhere")])
        assert result.exit_code == 2, (command, result.output)
        assert "Traceback" not in result.output


def test_resolved_case_written_by_run_loads_again(tmp_path: Path) -> None:
    out = tmp_path / "out"
    data = copy.deepcopy(pour_case())
    data["simulation"]["end_time"] = 0.0002
    run_case(case_from_dict(data), out, **_quiet())
    result = CliRunner().invoke(app, ["validate", str(out / "case.resolved.yaml")])
    assert result.exit_code == 0, result.output


def test_restart_refuses_a_directory_another_live_process_writes(tmp_path: Path) -> None:
    out = tmp_path / "out"
    data = copy.deepcopy(pour_case())
    data["simulation"]["end_time"] = 0.0002
    run_case(case_from_dict(data), out, **_quiet())
    status = json.loads((out / "status.json").read_text())
    status.update(status="running", pid=os.getppid())  # alive, and not this process
    (out / "status.json").write_text(json.dumps(status))
    result = CliRunner().invoke(app, ["restart", str(out)])
    assert result.exit_code == 2
    assert "still being written by a running process" in result.output
