"""The threading layer is thermodem's choice, not whatever the machine has (issue 17 §1).

Numba, left to itself, takes Intel TBB when it can load ``libtbb.so.12``; a process that used
TBB can then spin in TBB's shutdown at exit (measured with Debian's libtbb12 2021.8: 40 s
after a SIGTERM'd run had written its checkpoint, against 1 s on OpenMP). The ``tbb`` wheel of
the test extras puts ``libtbb.so.12`` in the environment's ``lib`` directory, which the loader
does not search by itself; these tests add it to ``LD_LIBRARY_PATH`` so that TBB is as
present as on a machine with a system TBB, check that Numba alone would take it, and then run
thermodem the way a user does (the environment's ``thermodem`` executable, in a subprocess):
the layer must be OpenMP and the process must exit within seconds after a normal end, after
SIGINT and after SIGTERM (each writing its checkpoint), and after several Simulations.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import yaml

from thermodem.io.checkpoint import list_checkpoints, read_checkpoint

EXE = Path(sys.executable).with_name("thermodem")
EXIT_SECONDS = 5.0  # after the final status is on disk (OpenMP: 0.3-1.1 s on a loaded VM)

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 2.0, "seed": 2},
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
            "velocity": [0.1, -0.05, -0.2],
        }
    ],
    "output": {"interval": 1.0, "checkpoint_interval": 1.0},
}


def tbb_env() -> dict[str, str]:
    """The environment with the tbb wheel's library on the loader path, no layer chosen."""
    env = dict(os.environ)
    lib = str(Path(sys.prefix) / "lib")
    env["LD_LIBRARY_PATH"] = lib + (
        os.pathsep + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else ""
    )
    env.pop("NUMBA_THREADING_LAYER", None)
    return env


def python(code: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=env or tbb_env(),
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture
def case_file(tmp_path: Path) -> Path:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(CASE))
    return path


def _status(out: Path) -> str:
    try:
        return json.loads((out / "status.json").read_text()).get("status", "")
    except (OSError, ValueError):
        return ""


def _run_until(proc: subprocess.Popen, out: Path, states: tuple[str, ...]) -> float:
    """Wait until status.json shows one of ``states``; the monotonic time it was seen."""
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline:
        if _status(out) in states:
            return time.monotonic()
        if proc.poll() is not None:
            break
        time.sleep(0.02)
    raise AssertionError(f"status never became {states}: {_status(out)!r}, rc {proc.poll()}")


def _exit_delay(proc: subprocess.Popen, since: float) -> float:
    try:
        proc.wait(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        return float("inf")
    return time.monotonic() - since


def test_numba_alone_would_take_tbb() -> None:
    """Without thermodem, Numba picks TBB in this environment (the tests below mean it)."""
    r = python("import numba; numba.get_num_threads(); print(numba.threading_layer())")
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[-1] == "tbb", r.stdout + r.stderr


def test_thermodem_takes_openmp_with_tbb_present() -> None:
    r = python(
        """
        import numba, thermodem
        from thermodem.engine.threads import threading_layer
        from thermodem.kernels.integrate import reset_forces
        import numpy as np
        n = 8
        force, torque, mass = np.ones((n, 3)), np.ones((n, 3)), np.full(n, 2.0)
        reset_forces(force, torque, mass, np.array([0.0, 0.0, -10.0]), False,
                     np.zeros((1, 8)), np.zeros(0), np.zeros((n, 0)),
                     np.zeros((n, 0)))  # a parallel kernel
        assert (force[:, 2] == -20.0).all() and not torque.any()
        import os
        print(numba.threading_layer(), "|", threading_layer(), "|", os.environ["OMP_WAIT_POLICY"])
        """
    )
    assert r.returncode == 0, r.stderr
    # passive: a waiting OpenMP thread sleeps (spinning made 2 threads 50x slower on a busy VM)
    assert r.stdout.split("\n")[0].strip() == "omp | omp | passive", r.stdout


def test_workqueue_when_openmp_cannot_load() -> None:
    r = python(
        """
        import sys
        sys.modules["numba.np.ufunc.omppool"] = None  # as if libgomp were missing
        import numba, thermodem
        from thermodem.engine.threads import threading_layer
        print(threading_layer())
        """
    )
    assert r.returncode == 0, r.stderr
    line = r.stdout.strip().splitlines()[-1]
    assert line.startswith("workqueue (the OpenMP layer could not be loaded"), line
    assert "libgomp1" in line


def test_user_choice_of_layer_is_kept() -> None:
    env = tbb_env()
    env["NUMBA_THREADING_LAYER"] = "workqueue"
    env["OMP_WAIT_POLICY"] = "active"
    r = python(
        "import os, thermodem; from thermodem.engine.threads import threading_layer; "
        "print(threading_layer(), os.environ['OMP_WAIT_POLICY'])",
        env,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "workqueue (set by NUMBA_THREADING_LAYER=workqueue) active"


def test_cli_exits_at_once_after_a_normal_end(case_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [str(EXE), "run", str(case_file), "-o", str(out), "--no-progress", "--threads", "2",
         "--steps", "300"],
        env=tbb_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    finished = _run_until(proc, out, ("finished", "failed"))
    delay = _exit_delay(proc, finished)
    stdout, stderr = proc.communicate()
    assert proc.returncode == 0, stdout + stderr
    assert delay < EXIT_SECONDS, f"exit took {delay:.1f} s after the run finished"
    log = (out / "run.log").read_text()
    assert "threads: 2 (as requested); threading layer omp" in log


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_cli_exits_at_once_after_a_signal(case_file: Path, tmp_path: Path, signum: int) -> None:
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [str(EXE), "run", str(case_file), "-o", str(out), "--no-progress", "--threads", "2"],
        env=tbb_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        _run_until(proc, out, ("running",))
        time.sleep(1.0)
        proc.send_signal(signum)
        stopped = _run_until(proc, out, ("interrupted", "failed"))
        delay = _exit_delay(proc, stopped)
    finally:
        if proc.poll() is None:
            proc.kill()
    stdout, stderr = proc.communicate()
    assert proc.returncode == 128 + signum, stdout + stderr
    assert delay < EXIT_SECONDS, f"exit took {delay:.1f} s after the checkpoint"
    assert f"{signal.Signals(signum).name} received" in stdout
    assert "Traceback" not in stderr
    ckpt = read_checkpoint(list_checkpoints(out / "checkpoints")[-1])
    assert ckpt.kind == "interrupted" and ckpt.step > 0
    assert "threading layer omp" in (out / "run.log").read_text()


def test_several_simulations_do_not_slow_the_exit(case_file: Path) -> None:
    code = f"""
        import time, numba
        from thermodem.config.load import load_case
        from thermodem.engine.simulation import Simulation
        case = load_case({str(case_file)!r})
        for _ in range(6):
            Simulation(case, threads=2).run(steps=30)
        print(numba.threading_layer(), flush=True)
        print("DONE", flush=True)
    """
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)],
        env=tbb_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    lines = []
    done = None
    for line in proc.stdout:
        lines.append(line.strip())
        if line.startswith("DONE"):
            done = time.monotonic()
    assert done is not None, proc.stderr.read()
    delay = _exit_delay(proc, done)
    assert proc.returncode == 0, proc.stderr.read()
    assert lines[0] == "omp"
    assert delay < EXIT_SECONDS, f"exit took {delay:.1f} s after 6 simulations"
