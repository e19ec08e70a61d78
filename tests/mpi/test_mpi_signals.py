"""Signals while ``mpiexec -n 2 thermodem run`` is being set up (mpi/runner.py:
run_distributed, engine/run_signals.py: StartingTogether): every rank stops at the same point
with one message, exit code 130 (143), ``status.json`` 'interrupted' with ``not_started``, and
the same command runs in the directory. Before, Ctrl-C exited 130 without a word, SIGTERM
ended the job with hydra's 'BAD TERMINATION ... EXIT CODE: 15', a signal sent to the ranks
themselves could hang the job; each left run.log and case.resolved.yaml, and the same command
refused the directory ('exists and is not empty')."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from mpi_cases import DATA, bed_case  # noqa: E402
from test_mpi import BIN, MPIEXEC, _env, needs_mpi  # noqa: E402

# the run as the CLI runs it, with the checks before the first step slowed on every rank, so
# that the signal comes while the run is being set up; "rank1": that rank sends itself the
# signal there (a signal that reached one rank only, e.g. a batch system's)
SCRIPT = """
import os
import signal
import sys
import time

import thermodem.mpi.runner as runner
from thermodem.cli import app

mode = sys.argv[3]
original = runner.pre_run_checks


def checks(sim):
    if mode == "slow":
        time.sleep(3.0)
    elif sim.rank == 1:
        os.kill(os.getpid(), getattr(signal, mode))
    return original(sim)


runner.pre_run_checks = checks
app(["run", sys.argv[1], "-o", sys.argv[2], "--no-progress"])
"""


def _mpiexec(args: list[str]) -> subprocess.Popen:
    return subprocess.Popen([str(MPIEXEC), "-n", "2", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=_env(2),
                            start_new_session=True)  # fmt: skip


def _finish(proc: subprocess.Popen) -> tuple[str, str]:
    try:
        return proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # (the whole job: mpiexec and its ranks)
        out, err = proc.communicate()
        pytest.fail(f"the job did not end after the signal:\n{out}\n{err}")


@needs_mpi
@pytest.mark.parametrize(
    ("signum", "to"),
    [(signal.SIGINT, "mpiexec"), (signal.SIGTERM, "mpiexec"), (signal.SIGTERM, "rank1")],
    ids=["SIGINT-mpiexec", "SIGTERM-mpiexec", "SIGTERM-one-rank"],
)
def test_a_signal_while_the_ranks_are_set_up(tmp_path: Path, signum: int, to: str) -> None:
    case = tmp_path / "bed.yaml"
    case.write_text(yaml.safe_dump(bed_case(DATA / "mpi_bed_box.txt", heat=None,
                                            end_time=5 * 5e-6)))  # fmt: skip
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    out = tmp_path / "out"
    mode = "slow" if to == "mpiexec" else signal.Signals(signum).name
    proc = _mpiexec([str(BIN / "python"), str(script), str(case), str(out), mode])
    if to == "mpiexec":  # (as Ctrl-C in the terminal, or kill of the job's mpiexec)
        deadline = time.monotonic() + 120
        while not (out / "run.log").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)
        proc.send_signal(signum)
    stdout, stderr = _finish(proc)
    name = signal.Signals(signum).name
    assert proc.returncode == 128 + signum, stdout + stderr
    message = f"interrupted ({name}) while the run was being set up, before its first step"
    assert stderr.count(message) == 1, stderr  # (rank 0's, once)
    assert "to start it: the same command" in stderr
    assert "Traceback" not in stdout + stderr and "BAD TERMINATION" not in stdout, stdout + stderr
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "interrupted" and status["not_started"] is True, status
    assert not (out / "run.lock").exists()
    # the same command (without the slowed checks) runs in the directory
    again = _mpiexec([str(BIN / "thermodem"), "run", str(case), "-o", str(out), "--no-progress"])
    stdout, stderr = _finish(again)
    assert again.returncode == 0, stdout + stderr
    assert json.loads((out / "status.json").read_text())["status"] == "finished"
