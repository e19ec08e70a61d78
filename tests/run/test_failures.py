"""Failure paths: each gives the documented exit code, a message naming step, time, particle,
quantity and likely cause, and leaves readable checkpoints (last good state + failed.h5)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.engine.simulation import Simulation
from thermodem.io.checkpoint import list_checkpoints, read_checkpoint

BOX = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.004, "seed": 2},
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
            "spacing": 0.002,
        }
    ],
    "output": {"interval": 0.001, "checkpoint_interval": 0.001},
}


def _case(tmp_path: Path, **changes) -> Path:  # noqa: ANN003
    data = json.loads(json.dumps(BOX))
    for dotted, value in changes.items():
        *parents, key = dotted.split("__")
        target = data
        for p in parents:
            target = target[int(p)] if p.isdigit() else target[p]
        target[key] = value
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _run(case: Path, out: Path):  # noqa: ANN202
    return CliRunner().invoke(app, ["run", str(case), "--output", str(out), "--no-progress"])


def _assert_failure_leaves_state(out: Path, message: str) -> None:
    assert (out / "failed.h5").is_file()
    failed = read_checkpoint(out / "failed.h5")
    assert failed.kind == "failed" and failed.message
    m = re.search(r"last good state: (\S+\.h5) \(step (\d+)", message)
    assert m, message
    good = read_checkpoint(m.group(1))
    assert good.kind in ("checkpoint", "final") and good.step == int(m.group(2))
    assert Simulation.from_checkpoint(good.path).step_count == good.step  # it can be continued
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "failed"
    assert "error:" in (out / "run.log").read_text()


def test_nan_injected_between_steps(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    original = Simulation.step

    def step(self: Simulation, complete: bool = True) -> None:
        if self.step_count == 150:
            self.particles.velocity[7, 1] = np.nan
        original(self, complete)

    monkeypatch.setattr(Simulation, "step", step)
    out = tmp_path / "out"
    result = _run(_case(tmp_path), out)
    assert result.exit_code == 1, result.output
    text = result.output
    gid = None
    for token in ("non-finite position or velocity of particle", "at step 151", "t = 0.00151 s"):
        assert token in text, token
    gid = int(re.search(r"particle (\d+)", text).group(1))
    assert gid >= 0
    assert "likely cause: not the time step alone" in text and "Rayleigh time" in text
    assert "last good state:" in text and "checkpoint_000000100.h5" in text
    _assert_failure_leaves_state(out, text)


def test_huge_time_step_allowed_unstable(tmp_path: Path) -> None:
    case = _case(
        tmp_path,
        simulation__time_step=2.0e-4,
        simulation__end_time=0.2,
        simulation__time_step_check={"allow_unstable": True},
        insertion__0__velocity=[0.3, -0.2, -0.5],
        output={"checkpoint_interval": 0.002},
    )
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 1, result.output
    text = result.output
    assert "warning: simulation.time_step" in text  # the refusal turned into a warning
    assert re.search(r"at step \d+ \(t = [0-9.e-]+ s\)", text)
    assert re.search(r"particle \d+", text)
    assert "likely cause: time step 0.0002 s too large" in text
    assert "steps (at least 10 needed" in text
    _assert_failure_leaves_state(out, text)
    # continue from the last good state with a smaller time step, as the message says
    good = re.search(r"last good state: (\S+\.h5)", text).group(1)
    fixed = _case(tmp_path, simulation__end_time=0.0005, insertion__0__velocity=[0.3, -0.2, -0.5])
    again = CliRunner().invoke(
        app, ["run", str(fixed), "--restart", good, "--output", str(tmp_path / "again")]
    )
    assert again.exit_code == 0, again.output
    assert json.loads((tmp_path / "again" / "status.json").read_text())["status"] == "finished"


def test_particle_thrown_out_of_the_box(tmp_path: Path) -> None:
    case = _case(
        tmp_path,
        insertion__0__velocity=[1000.0, 0.0, 0.0],
        simulation__time_step_check={"impact_velocity": 1.0},
    )
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 1, result.output
    text = result.output
    assert re.search(r"particle \d+ left the domain at step 1 \(t = 1e-05 s\)", text), text
    assert "velocity [1000.0" in text
    assert "likely cause: it moves |v| Δt = 0.01 m per step" in text
    assert "checkpoint_000000000.h5 (step 0" in text
    _assert_failure_leaves_state(out, text)


def test_excessive_overlap_names_the_pair(tmp_path: Path) -> None:
    case = _case(
        tmp_path,
        simulation__max_overlap_ratio=0.01,
        insertion__0__velocity=[0.0, 0.0, -1.0],
    )
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 1, result.output
    m = re.search(
        r"overlap of ([0-9.]+) × the smaller radius \(particle (\d+) and (\S+)", result.output
    )
    assert m, result.output
    assert float(m.group(1)) > 0.01
    assert "likely cause: contact stiffness (youngs_modulus) too low" in result.output
    _assert_failure_leaves_state(out, result.output)


def test_sigint_writes_a_checkpoint_and_restart_finishes(tmp_path: Path) -> None:
    case = _case(tmp_path, simulation__end_time=2.0, output={"interval": 1.0})
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
        while time.monotonic() < deadline:  # wait until it is stepping
            status = out / "status.json"
            if status.exists() and json.loads(status.read_text()).get("status") == "running":
                break
            time.sleep(0.2)
        time.sleep(1.0)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, stdout + stderr
    assert "SIGINT received" in stdout
    assert "continue with: thermodem restart" in stderr
    assert "Traceback" not in stderr
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "interrupted"
    ckpt = read_checkpoint(list_checkpoints(out / "checkpoints")[-1])
    assert ckpt.kind == "interrupted" and ckpt.step == status["step"] > 0
    # continue (with a shorter end time so the test stays fast)
    end = (ckpt.step + 20) * 1.0e-5
    result = CliRunner().invoke(
        app, ["restart", str(out), "--end-time", repr(end), "--no-progress"]
    )
    assert result.exit_code == 0, result.output
    assert json.loads((out / "status.json").read_text())["status"] == "finished"


def test_thermal_blow_up_names_the_step_after_the_last_good_state(tmp_path: Path) -> None:
    """An explicit heat update that fails ran in step k + 1 from the state of step k; the
    message said 'at step k', the step of the checkpoint it offered as the last good state."""
    case = _case(
        tmp_path,
        simulation__end_time=0.0005,
        simulation__initial_temperature=300.0,
        materials={
            "glass": {
                "density": 2500,
                "youngs_modulus": 1.0e7,
                "poisson_ratio": 0.3,
                "thermal_conductivity": 100.0,
                "specific_heat": 0.001,
            }
        },
        walls__0__thermal={"kind": "fixed", "temperature": 600.0},
        insertion=[
            {
                "kind": "list",
                "material": "glass",
                "radius": 0.0008,
                "positions": [[0.005, 0.005, 0.00079], [0.005, 0.005, 0.00237]],
            }
        ],
        thermal={"stability": {"allow_unstable": True}},
        output={"checkpoint_interval": 1.0e-5},  # every step: the last good one is k
    )
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 1, result.output
    text = result.output
    m = re.search(r"temperature of particle \d+ became \S+ K at step (\d+) \(t = (\S+) s\)", text)
    assert m, text
    good = re.search(r"last good state: \S+ \(step (\d+), t = (\S+) s\)", text)
    assert int(m.group(1)) == int(good.group(1)) + 1, text
    assert float(m.group(2)) > float(good.group(2))
    assert "likely cause: thermal time step 1e-05 s against the limit" in text
    _assert_failure_leaves_state(out, text)


def test_a_signal_while_the_run_is_set_up_is_reported_and_the_directory_reused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while the simulation was built (a large bed, the first compile) exited 130
    without a word, SIGTERM killed the process; both left run.log and case.resolved.yaml, and
    the same command then refused the directory as 'exists and is not empty'."""
    import thermodem.engine.runner as runner

    original = runner.pre_run_checks

    def checks(sim: Simulation) -> list[str]:
        os.kill(os.getpid(), signal.SIGTERM)
        return original(sim)

    monkeypatch.setattr(runner, "pre_run_checks", checks)
    case = _case(tmp_path)
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 143, result.output
    assert "interrupted (SIGTERM) while the run was being set up, before its first step" in (
        result.output
    )
    assert "to start it: the same command" in result.output
    assert "Traceback" not in result.output
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "interrupted" and status["not_started"] is True
    assert not (out / "run.lock").exists()
    monkeypatch.setattr(runner, "pre_run_checks", original)
    again = _run(case, out)  # no --overwrite needed: nothing was computed
    assert again.exit_code == 0, again.output
    assert json.loads((out / "status.json").read_text())["status"] == "finished"


def test_an_overlap_present_at_the_start_is_named_as_the_cause(tmp_path: Path) -> None:
    """Two particles given overlapping (overlap_check: false) stopped the run at step 1 with
    'likely cause: contact stiffness (youngs_modulus) too low for the loads'."""
    case = _case(
        tmp_path,
        insertion=[
            {
                "kind": "list",
                "material": "glass",
                "radius": 0.001,
                "positions": [[0.005, 0.005, 0.005], [0.005, 0.005, 0.0066]],
                "overlap_check": False,
            }
        ],
    )
    out = tmp_path / "out"
    result = _run(case, out)
    assert result.exit_code == 1, result.output
    text = result.output
    assert "(particle 0 and particle 1) at step 1 (t = 1e-05 s)" in text
    assert "likely cause: particles inserted overlapping: at the first step" in text
    assert "raise simulation.max_overlap_ratio (at most 1) above 0.3" in text
    assert "youngs_modulus" not in text
    _assert_failure_leaves_state(out, text)


def test_a_failure_is_reported_when_the_last_checkpoint_cannot_be_read(tmp_path: Path) -> None:
    """The last checkpoint damaged or removed by the time the run fails: the report said only
    that the checkpoint could not be read (an input error, exit 2), hiding the failure."""
    from thermodem.config.load import load_case
    from thermodem.engine.runner import run_case
    from thermodem.errors import SimulationError

    out = tmp_path / "out"

    def damage_then_throw(sim: Simulation) -> None:
        if sim.step_count == 5:
            (checkpoint,) = list_checkpoints(out / "checkpoints")
            Path(checkpoint).write_bytes(b"not a checkpoint")
            sim.particles.velocity[0] = [1.0e4, 0.0, 0.0]  # leaves the domain in the next step

    with pytest.raises(SimulationError) as failed:
        run_case(load_case(_case(tmp_path)), out, log=None, progress=False,
                 callback=damage_then_throw)  # fmt: skip
    text = str(failed.value)
    assert re.search(r"particle \d+ left the domain at step 6", text), text
    assert "the last checkpoint" in text and "cannot be read" in text, text
    assert (out / "failed.h5").is_file()
    assert json.loads((out / "status.json").read_text())["status"] == "failed"
