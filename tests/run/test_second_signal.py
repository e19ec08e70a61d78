"""A second signal while the interrupt checkpoint is being written (engine/run_signals.py:
StopRequest.finish): noted with a line, not obeyed; the checkpoint is finished and
status.json says 'interrupted'. Before, a second SIGINT there was reported as 'interrupted
while the run was being set up, before its first step: nothing was computed' and a second
SIGTERM killed the process without a word, status.json saying 'running'."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from thermodem.io.checkpoint import list_checkpoints, read_checkpoint

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.004, "seed": 2},
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

# the run as the CLI runs it; the first SIGINT at step 5 (as from Ctrl-C), the second signal
# while the interrupt checkpoint is being written
SCRIPT = """
import os
import signal
import sys

import thermodem.engine.runner as runner
from thermodem.cli import app

second = getattr(signal, sys.argv[3])


class Progress(runner.Progress):
    def update(self, sim):
        super().update(sim)
        if sim.step_count == 5:
            os.kill(os.getpid(), signal.SIGINT)


def write_checkpoint(sim, path, kind="checkpoint", **options):
    if kind == "interrupted":
        os.kill(os.getpid(), second)
    return original(sim, path, kind=kind, **options)


original = runner.write_checkpoint
runner.Progress = Progress
runner.write_checkpoint = write_checkpoint
app(["run", sys.argv[1], "--output", sys.argv[2], "--no-progress"])
"""


@pytest.mark.parametrize("second", ["SIGINT", "SIGTERM"])
def test_a_second_signal_while_the_interrupt_checkpoint_is_written(
    tmp_path: Path, second: str
) -> None:
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(CASE))
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    out = tmp_path / "out"
    res = subprocess.run(
        [sys.executable, str(script), str(case), str(out), second],
        capture_output=True,
        text=True,
        timeout=300,
    )
    text = res.stdout + res.stderr
    assert res.returncode == 128 + signal.SIGINT, text  # (the first signal's code)
    assert (
        f"{second} received while writing the interrupt checkpoint: finishing it first"
        in res.stdout
    ), text
    assert "interrupted at step 5 (t = 5e-05 s): state saved to" in res.stderr, text
    assert f"continue with: thermodem restart {out}" in res.stderr, text
    assert "before its first step" not in text and "Traceback" not in text, text
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "interrupted" and status["step"] == 5, status
    assert "not_started" not in status, status
    newest = read_checkpoint(list_checkpoints(out / "checkpoints")[-1])
    assert newest.kind == "interrupted" and newest.step == 5
    assert status["last_checkpoint"] == str(newest.path)
