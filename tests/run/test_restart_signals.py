"""A signal while a restart is being set up (engine/restarted_runs.py: restart_run,
run_from_checkpoint; engine/run_signals.py: restart_not_started, not_started): a message
that the restart stopped before its first step and which checkpoint the next one continues
from, exit code 130 (143), the run directory's checkpoints, status.json and
case.resolved.yaml as they were, and the same command works. Before, Ctrl-C there exited 130
without a word and SIGTERM killed the process (leaving run.lock and, with --end-time, a
case.resolved.yaml with the new end time)."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from thermodem.cli import app
from thermodem.io.checkpoint import list_checkpoints

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.0005, "seed": 2},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {"glass": {"density": 2500, "youngs_modulus": 1.0e7, "poisson_ratio": 0.3}},
    "walls": [
        {"kind": "box", "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01], "material": "glass"}
    ],
    "insertion": [
        {
            "kind": "list",
            "material": "glass",
            "radius": 0.0008,
            "positions": [[0.003, 0.003, 0.003], [0.007, 0.007, 0.003]],
        }
    ],
    "output": {"vtu": False},
}

# the CLI with the signal sent by the process to itself from inside a step of the set-up:
# restored_simulation (the checkpoint rebuilt and compiled, before the directory is touched)
# or _header (after the directory's run.log is opened)
SCRIPT = """
import os
import signal
import sys

import thermodem.engine.restarted_runs as runner  # (the restarts set up there)
from thermodem.cli import app

signum = getattr(signal, sys.argv[1])
original = getattr(runner, sys.argv[2])


def slow(*args, **kwargs):
    os.kill(os.getpid(), signum)
    return original(*args, **kwargs)


setattr(runner, sys.argv[2], slow)
app(sys.argv[3:])
"""


@pytest.fixture
def finished(tmp_path: Path) -> Path:
    """A finished run of 50 steps (checkpoints at 45 and 50)."""
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(CASE))
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["run", str(case), "-o", str(out), "--no-progress"])
    assert result.exit_code == 0, result.output
    return out


def _signalled(tmp_path: Path, signum: int, where: str, args: list[str]):  # noqa: ANN202
    script = tmp_path / "restart.py"
    script.write_text(SCRIPT)
    name = signal.Signals(signum).name
    return subprocess.run([sys.executable, str(script), name, where, *args],
                          capture_output=True, text=True, timeout=300)  # fmt: skip


@pytest.mark.parametrize(
    ("signum", "where"),
    [(signal.SIGINT, "restored_simulation"), (signal.SIGTERM, "_header")],
    ids=["SIGINT-rebuilding", "SIGTERM-directory-opened"],
)
def test_a_signal_while_a_restart_is_set_up(
    tmp_path: Path, finished: Path, signum: int, where: str
) -> None:
    out = finished
    before = {name: (out / name).read_bytes() for name in ("status.json", "case.resolved.yaml")}
    checkpoints = list_checkpoints(out / "checkpoints")
    args = ["restart", str(out), "--end-time", "0.001", "--no-progress"]
    res = _signalled(tmp_path, signum, where, args)
    text = res.stdout + res.stderr
    name = signal.Signals(signum).name
    assert res.returncode == 128 + signum, text
    assert (
        f"interrupted ({name}) while the restart was being set up, before its first step: "
        "nothing was computed, the run's checkpoints are unchanged" in res.stderr
    ), text
    newest = out / "checkpoints" / "checkpoint_000000050.h5"
    assert f"to continue: the same command, from {newest} (step 50, t = 0.0005 s)" in res.stderr
    assert "Traceback" not in text and "not_started" not in text, text
    # the earlier run's record as it was: finished at step 50, not 'not_started'
    for name_, content in before.items():
        assert (out / name_).read_bytes() == content, name_
    assert list_checkpoints(out / "checkpoints") == checkpoints
    assert not (out / "run.lock").exists()
    if where == "_header":  # (run.log was open: the line is in it)
        assert "while the restart was being set up" in (out / "run.log").read_text()
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 0, again.output
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "finished" and status["step"] == 100, status


def test_a_signal_while_a_run_from_a_checkpoint_is_set_up(tmp_path: Path, finished: Path) -> None:
    """``run --restart CKPT --output NEWDIR`` stopped while the checkpoint is rebuilt: NEWDIR
    is not created, the checkpoint is named as unchanged, the same command runs."""
    ckpt = finished / "checkpoints" / "checkpoint_000000050.h5"
    new = tmp_path / "new"
    args = ["run", "--restart", str(ckpt), "--end-time", "0.001", "-o", str(new), "--no-progress"]
    res = _signalled(tmp_path, signal.SIGINT, "restored_simulation", args)
    text = res.stdout + res.stderr
    assert res.returncode == 130, text
    assert (
        "interrupted (SIGINT) while the run was being set up, before its first step: nothing "
        f"was computed and {new} was not touched; to start it: the same command (from {ckpt}, "
        "which is unchanged)" in res.stderr
    ), text
    assert "Traceback" not in text and not new.exists()
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 0, again.output
    assert json.loads((new / "status.json").read_text())["status"] == "finished"


# the CLI with the signal sent while cli.py reads the case or the checkpoint (for --end-time),
# before the runner's own handlers are in place
EARLY = """
import os
import signal
import sys

import thermodem.config.load as load
import thermodem.io.checkpoint as checkpoint
from thermodem.cli import app

signum = getattr(signal, sys.argv[1])
module = {"load_case": load, "read_checkpoint": checkpoint}[sys.argv[2]]
original = getattr(module, sys.argv[2])


def slow(*args, **kwargs):
    os.kill(os.getpid(), signum)
    return original(*args, **kwargs)


setattr(module, sys.argv[2], slow)
app(sys.argv[3:])
"""


@pytest.mark.parametrize(
    ("signum", "where"),
    [(signal.SIGINT, "load_case"), (signal.SIGTERM, "read_checkpoint")],
    ids=["SIGINT-case-read", "SIGTERM-checkpoint-read"],
)
def test_a_signal_while_the_cli_reads_the_case(
    tmp_path: Path, finished: Path, signum: int, where: str
) -> None:
    """``run CASE --restart CKPT --end-time T`` stopped while cli.py reads the case or the
    checkpoint: the runner's not-started message, exit 130 (143), NEWDIR not created (before:
    Ctrl-C exited 130 and SIGTERM killed the process without a word)."""
    ckpt = finished / "checkpoints" / "checkpoint_000000050.h5"
    new = tmp_path / "new"
    script = tmp_path / "early.py"
    script.write_text(EARLY)
    args = ["run", str(tmp_path / "case.yaml"), "--restart", str(ckpt), "--end-time", "0.001",
            "-o", str(new), "--no-progress"]  # fmt: skip
    name = signal.Signals(signum).name
    res = subprocess.run([sys.executable, str(script), name, where, *args],
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    text = res.stdout + res.stderr
    assert res.returncode == 128 + signum, text
    assert (
        f"interrupted ({name}) while the run was being set up, before its first step: nothing "
        f"was computed and {new} was not touched; to start it: the same command (from {ckpt}, "
        "which is unchanged)" in res.stderr
    ), text
    assert "Traceback" not in text and not new.exists()
