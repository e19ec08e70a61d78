"""``mpiexec -n 2 thermodem run CASE --restart CKPT`` with a changed case, as the serial run
(tests/run/test_restart_changes.py): heat (also heat generation) that starts at the restart of a
run settled without heat agrees with the serial run to round-off (its line in the log, the heat
columns from zero, the balance closed), and a case whose walls or t = 0 particles differ from
the checkpoint's is refused before anything is written (mpi/runner.py: run_distributed calls
run_checks.check_restart_start; before, the run went on with the checkpoint's walls). A periodic
case continues on 2 ranks, and one whose changed domain is too short for the restored particles'
lists is refused while the ranks set up; a run that starts without particles (all poured) runs
on 2 ranks as serially."""

from __future__ import annotations

import copy
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1] / "run"))

from test_input_at_build import PERIODIC, _periodic  # noqa: E402
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

    # heat generation starting at the restart too: the energy dissipated from the restart on
    # becomes heat on 2 ranks as serially (its columns from zero, the ledgers equal)
    generating = copy.deepcopy(heat)
    generating["thermal"]["heat_generation"] = {"model": "mechanical_dissipation"}
    case = _write(tmp_path / "generation.yaml", generating)
    for ranks in (1, 2):
        res = _run(["run", str(case), "--restart", str(ckpt), "-o", str(tmp_path / f"g{ranks}"),
                    "--no-progress"], ranks)  # fmt: skip
        assert res.returncode == 0, res.stderr
    from thermodem.io.run_files import read_timeseries

    # (the generation ledger counts from the heat's start: it counted the settle's damping,
    # never turned into heat, so generated - in - walls - pending was off by that energy)
    series = read_timeseries(tmp_path / "g1" / "timeseries.csv")
    generated = series["generated_normal_damping"]
    assert generated[0] == 0.0 and generated[-1] > 0.0
    assert np.abs(series["generation_balance_error"]).max() <= 1e-12 * generated[-1]
    _assert_same_ledgers(tmp_path / "g1", tmp_path / "g2")
    serial = _particles(tmp_path / "g1" / "checkpoints" / "checkpoint_000000060.h5")
    parallel = _particles(tmp_path / "g2" / "checkpoints" / "checkpoint_000000060.h5")
    np.testing.assert_allclose(parallel["temperature"], serial["temperature"], rtol=1e-12)

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


@needs_mpi
def test_a_periodic_restart_on_2_ranks_and_one_whose_lists_cannot_be_built(
    tmp_path: Path,
) -> None:
    """A restart of a periodic case on 2 ranks was refused whenever the periodic axis was
    shorter than twice the domain's longest edge: the empty start's rebuild (no particles yet)
    checked the axis against a cell of that edge ('2 R_max 0 m', exit 1). It continues now, as
    serially; a changed case whose periodic axis is shorter than two neighbour cells of the
    restored particles is refused while the ranks set up (exit 2, once, the key named, a
    refused record), as serially (tests/run/test_input_at_build.py)."""
    base = _write(tmp_path / "base.yaml", PERIODIC)
    res = _run(["run", str(base), "-o", str(tmp_path / "s"), "--no-progress"])
    assert res.returncode == 0, res.stderr
    ckpt = tmp_path / "s" / "checkpoints" / "checkpoint_000000020.h5"
    longer = _periodic(tmp_path, "longer")
    res = _run(["run", str(longer), "--restart", str(ckpt), "-o", str(tmp_path / "p"),
                "--no-progress"], 2)  # fmt: skip
    assert res.returncode == 0, res.stderr
    res = _run(["restart", str(tmp_path / "p"), "--end-time", "0.0006", "--no-progress"], 2)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "p" / "checkpoints" / "checkpoint_000000060.h5").exists()
    short = _periodic(tmp_path, "short", upper_x=0.004)
    out = tmp_path / "short"
    res = _run(["run", str(short), "--restart", str(ckpt), "-o", str(out), "--no-progress"], 2)
    assert res.returncode == 2, res.stderr
    message = (
        "domain.periodic: axis x is periodic, but the domain is 0.004 m long along it "
        "(domain.upper - domain.lower), shorter than twice the neighbour cell 0.0022 m (2 R_max "
        "0.002 m + neighbors.skin 0.0002 m); the minimum image needs >= 0.0044 m: a longer "
        "periodic axis, smaller particles or a smaller neighbors.skin (met while the restart "
        f"from {ckpt} was set up, before any step)"
    )
    assert res.stderr.count(f"error: {message}") == 1, res.stderr
    status = json.loads((out / "status.json").read_text())
    assert status["refused_input"] is True and status["message"] == message
    assert not any((out / "checkpoints").glob("*.h5"))


@needs_mpi
@pytest.mark.parametrize("periodic", [True, False])
def test_a_run_that_starts_empty_and_pours_on_2_ranks(tmp_path: Path, periodic: bool) -> None:
    """The same empty start in a fresh run, a case whose particles are all poured: refused on
    2 ranks with a periodic axis ('2 R_max 0 m', as above), and with none the ranks stopped at
    the first step without a pour (TypeError: no skin before the first particle is listed;
    engine/neighbor_list.py: rebuild_due). Now both run as serially, to the same particles."""
    case = copy.deepcopy(PERIODIC)
    case["domain"] = {"lower": [0, 0, 0], "upper": [0.008, 0.008, 0.02],
                      "periodic": [periodic, periodic, False]}  # fmt: skip
    case["insertion"] = [
        {"kind": "pour", "material": "glass", "rate": 1.0e5, "interval": 5.0e-5,
         "end_time": 1.0e-4, "distribution": {"kind": "mono", "radius": 5.0e-4},
         "region": {"kind": "box", "lower": [0, 0, 0.01], "upper": [0.008, 0.008, 0.02]}}
    ]  # fmt: skip
    path = _write(tmp_path / "pour.yaml", case)
    finals = []
    for ranks in (1, 2):
        out = tmp_path / f"o{ranks}"
        res = _run(["run", str(path), "-o", str(out), "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
        finals.append(_particles(out / "checkpoints" / "checkpoint_000000020.h5"))
    serial, parallel = finals
    assert serial["global_id"].shape[0] == 10
    np.testing.assert_array_equal(serial["global_id"], parallel["global_id"])
    np.testing.assert_allclose(parallel["position"], serial["position"], rtol=0, atol=1e-12)
