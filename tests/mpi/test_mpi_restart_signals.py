"""Signals while ``mpiexec -n 2 thermodem restart DIR`` is being set up (mpi/runner.py:
restart_distributed, engine/run_signals.py: StartingTogether, restart_not_started): every
rank stops at the same point with rank 0's message naming the checkpoint the next restart
continues from, exit code 130 (143), the earlier run's status.json and checkpoints as they
were, and the same command continues the run. Before, Ctrl-C exited 130 without a word and
a SIGTERM that reached one rank ended the job with hydra's 'BAD TERMINATION ... EXIT CODE:
15' (one rank stopping alone could leave the others waiting in a collective)."""

from __future__ import annotations

import json
import signal
import sys
import time
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from mpi_cases import DATA, bed_case  # noqa: E402
from test_mpi import BIN, needs_mpi  # noqa: E402
from test_mpi_signals import _finish, _mpiexec  # noqa: E402

from thermodem.io.checkpoint import list_checkpoints  # noqa: E402

# the CLI with the rebuild of the checkpoint (_build, a collective set-up) slowed on every
# rank, a marker file written when a rank is in it ("slow"), or with rank 1 sending itself
# the signal there (a signal that reached one rank only, e.g. a batch system's)
SCRIPT = """
import os
import signal
import sys
import time
from pathlib import Path

import thermodem.mpi.runner as runner
from thermodem.cli import app

mode, marker = sys.argv[1], sys.argv[2]
original = runner._build


def build(*args, **kwargs):
    rank = runner._comm().Get_rank()
    if mode == "slow":
        Path(f"{marker}{rank}").touch()
        time.sleep(3.0)
    elif rank == 1:
        os.kill(os.getpid(), getattr(signal, mode))
    return original(*args, **kwargs)


runner._build = build
app(sys.argv[3:])
"""


@needs_mpi
@pytest.mark.parametrize(
    ("signum", "to"),
    [(signal.SIGINT, "mpiexec"), (signal.SIGTERM, "rank1")],
    ids=["SIGINT-mpiexec", "SIGTERM-one-rank"],
)
def test_a_signal_while_the_ranks_set_up_a_restart(tmp_path: Path, signum: int, to: str) -> None:
    case = tmp_path / "bed.yaml"
    case.write_text(yaml.safe_dump(bed_case(DATA / "mpi_bed_box.txt", heat=None,
                                            end_time=5 * 5e-6)))  # fmt: skip
    out = tmp_path / "out"
    first = _mpiexec([str(BIN / "thermodem"), "run", str(case), "-o", str(out), "--no-progress"])
    stdout, stderr = _finish(first)
    assert first.returncode == 0, stdout + stderr
    status_before = (out / "status.json").read_bytes()
    checkpoints = list_checkpoints(out / "checkpoints")
    script = tmp_path / "restart.py"
    script.write_text(SCRIPT)
    marker = tmp_path / "in_build"
    mode = "slow" if to == "mpiexec" else signal.Signals(signum).name
    args = ["restart", str(out), "--end-time", repr(10 * 5e-6), "--no-progress"]
    proc = _mpiexec([str(BIN / "python"), str(script), mode, str(marker), *args])
    if to == "mpiexec":  # (as Ctrl-C in the terminal): once both ranks rebuild the checkpoint
        deadline = time.monotonic() + 120
        while not all(Path(f"{marker}{r}").exists() for r in (0, 1)):
            assert time.monotonic() < deadline and proc.poll() is None, "no rank reached _build"
            time.sleep(0.05)
        time.sleep(0.3)
        proc.send_signal(signum)
    stdout, stderr = _finish(proc)
    name = signal.Signals(signum).name
    assert proc.returncode == 128 + signum, stdout + stderr
    message = (
        f"interrupted ({name}) while the restart was being set up, before its first step: "
        "nothing was computed, the run's checkpoints are unchanged"
    )
    assert stderr.count(message) == 1, stderr  # (rank 0's, once)
    newest = out / "checkpoints" / "checkpoint_000000005.h5"
    assert f"to continue: the same command, from {newest} (step 5, t = 2.5e-05 s)" in stderr
    assert "Traceback" not in stdout + stderr and "BAD TERMINATION" not in stdout, stdout + stderr
    assert (out / "status.json").read_bytes() == status_before  # (not 'not_started')
    assert list_checkpoints(out / "checkpoints") == checkpoints
    assert not (out / "run.lock").exists()
    # the same command (without the slowed build) continues the run
    again = _mpiexec([str(BIN / "thermodem"), *args])
    stdout, stderr = _finish(again)
    assert again.returncode == 0, stdout + stderr
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "finished" and status["step"] == 10, status
