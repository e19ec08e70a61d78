"""``mpiexec -n 2 thermodem run CASE --restart CKPT`` with a changed case, as the serial run
(tests/run/test_restart_changes.py): heat that starts at the restart of a run settled without
heat agrees with the serial run to round-off (its line in the log, the heat columns from zero,
the balance closed), and a case whose walls or t = 0 particles differ from the checkpoint's
is refused before anything is written (mpi/runner.py: run_distributed calls
run_checks.check_restart_start; before, the run went on with the checkpoint's walls)."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "run"))

from test_mpi import _assert_same_ledgers, _run, needs_mpi  # noqa: E402
from test_restart_changes import SETTLE, _particles, _write  # noqa: E402


@needs_mpi
def test_heat_starts_at_a_restart_on_2_ranks_as_serially(tmp_path: Path) -> None:
    settle = _write(tmp_path / "settle.yaml", SETTLE)
    res = _run(["run", str(settle), "-o", str(tmp_path / "s"), "--no-progress"])
    assert res.returncode == 0, res.stderr
    ckpt = tmp_path / "s" / "checkpoints" / "checkpoint_000000020.h5"
    heat = copy.deepcopy(SETTLE)
    heat["simulation"]["end_time"] = 6.0e-4
    heat["insertion"][1]["temperature"] = 400.0
    heat["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 350.0}
    heat["thermal"] = {"initial_temperature": {"kind": "uniform", "value": 300.0}}
    case = _write(tmp_path / "heat.yaml", heat)
    for ranks in (1, 2):
        out = tmp_path / f"h{ranks}"
        res = _run(["run", str(case), "--restart", str(ckpt), "-o", str(out), "--no-progress"],
                   ranks)  # fmt: skip
        assert res.returncode == 0, res.stderr
        assert "heat starts at t = 0.0002 s (step 20)" in res.stdout, res.stdout
        assert "changed from the checkpoint's case: thermal (none) -> (a section)" in res.stdout
        # output.vtu: false: the last line names no particles.pvd (none was written)
        assert "no VTU frames were written (output.vtu: false)" in res.stdout, res.stdout
        assert "particles.pvd" not in res.stdout
    first = _particles(tmp_path / "h2" / "checkpoints" / "checkpoint_000000020.h5")
    np.testing.assert_array_equal(first["temperature"], [300.0, 300.0, 400.0, 400.0])
    serial = _particles(tmp_path / "h1" / "checkpoints" / "checkpoint_000000060.h5")
    parallel = _particles(tmp_path / "h2" / "checkpoints" / "checkpoint_000000060.h5")
    assert serial["temperature"][0] > 300.001
    np.testing.assert_allclose(parallel["temperature"], serial["temperature"], rtol=1e-12)
    _assert_same_ledgers(tmp_path / "h1", tmp_path / "h2")

    # a moved wall, another static entry: refused on 2 ranks as serially, nothing written
    moved = copy.deepcopy(heat)
    moved["walls"][0]["upper"] = [0.004, 0.004, 0.02]
    other = copy.deepcopy(heat)
    other["insertion"][0]["positions"][0][0] = 0.0021
    for name, changed, key in (("moved", moved, "walls.0.upper.2"),
                               ("other", other, "insertion.0.positions.0.0")):  # fmt: skip
        out = tmp_path / name
        res = _run(["run", str(_write(tmp_path / f"{name}.yaml", changed)), "--restart",
                    str(ckpt), "-o", str(out), "--no-progress"], 2)  # fmt: skip
        assert res.returncode == 2, res.stderr
        assert f"{key} differs from the case stored in the checkpoint" in res.stderr
        assert res.stderr.count("error:") == 1, res.stderr  # (rank 0 only)
        assert not out.exists()


@needs_mpi
def test_restart_of_a_run_that_never_started_on_2_ranks(tmp_path: Path) -> None:
    """``mpiexec -n 2 thermodem restart DIR`` of a refused run: rank 0 says it never started,
    with the refusal and the mpiexec command to run it again."""
    bad = copy.deepcopy(SETTLE)
    bad["simulation"]["time_step"] = 1.0e-3
    out = tmp_path / "out"
    res = _run(["run", str(_write(tmp_path / "bad.yaml", bad)), "-o", str(out), "--no-progress"])
    assert res.returncode == 2, res.stderr
    res = _run(["restart", str(out), "--no-progress"], 2)
    assert res.returncode == 2, res.stderr
    assert "never started (status.json: its input was refused: simulation.end_time" in res.stderr
    assert f"run it again: mpiexec -n 2 thermodem run CASE --output {out}" in res.stderr
    assert res.stderr.count("error:") == 1, res.stderr
