"""Runs on several MPI ranks (docs/mpi.md): ``mpiexec -n P thermodem run`` against the serial run.

The multi-rank runs are subprocesses started with the venv's own ``mpiexec`` (the ``mpich``
wheel of the test extras). The reference is the serial run of the same case: the settled bed
of tests/data (500 spheres, Hertz-Mindlin with EPSD rolling, walls, the contact conduction,
a fixed-temperature bottom layer) over 1000 steps must agree on 2 and 4 ranks to 1e-10 of
the domain size in positions and 1e-10 relative in temperatures, with the energy and heat
ledgers equal to round-off. The pair sums of a particle are added in another order on
several ranks, so the runs agree to round-off, not to the bit.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from mpi_cases import DATA, HEIGHT, SIDE, bed_case  # noqa: E402

BIN = Path(sys.executable).parent
MPIEXEC = BIN / "mpiexec"
THERMODEM = BIN / "thermodem"
STEPS = 1000
DT = 5e-6


def _have_mpi() -> bool:
    try:
        import mpi4py  # noqa: F401
    except ImportError:
        return False
    return MPIEXEC.exists()


needs_mpi = pytest.mark.skipif(
    not _have_mpi(), reason="mpi4py and the mpich wheel (test extras) are not installed"
)


def _env(ranks: int) -> dict[str, str]:
    env = dict(os.environ)
    # more ranks than cores (the 4-rank runs on a 2-core machine): MPICH's busy polling
    # would keep a descheduled rank's partner spinning; yield instead
    if ranks > (os.cpu_count() or 1):
        env["MPIR_CVAR_ENABLE_HEAVY_YIELD"] = "1"
    for name in ("PMI_SIZE", "PMI_RANK", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"):
        env.pop(name, None)  # (pytest itself may run under a launcher)
    return env


def _run(args: list[str], ranks: int = 1, timeout: float = 900) -> subprocess.CompletedProcess:
    """``thermodem ARGS`` on ``ranks`` MPI ranks (1: the plain serial command)."""
    cmd = [str(THERMODEM), *args]
    if ranks > 1:
        cmd = [str(MPIEXEC), "-n", str(ranks), *cmd]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=_env(ranks), start_new_session=True)  # fmt: skip
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # (the whole job: mpiexec and its ranks)
        out, err = proc.communicate()
        pytest.fail(f"{' '.join(cmd)} did not finish in {timeout} s:\n{out}\n{err}")
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def _write_case(path: Path, case: dict) -> Path:
    path.write_text(yaml.safe_dump(case))
    return path


def _box_case(tmp: Path, **output: float) -> Path:
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=STEPS * DT)
    case["output"] = {
        "vtu": True,
        "interval": 500 * DT,
        "timeseries_interval": 100 * DT,
        "checkpoint_interval": 500 * DT,
        "checkpoint_keep": None,
        **output,
    }
    return _write_case(tmp / "box.yaml", case)


def _final(directory: Path, step: int = STEPS) -> dict[str, np.ndarray]:
    from thermodem.io.checkpoint import read_checkpoint

    state = read_checkpoint(directory / "checkpoints" / f"checkpoint_{step:09d}.h5").state
    p = state["particles"]
    order = np.argsort(p["global_id"])
    return {k: np.asarray(v)[order] for k, v in p.items()}


def _assert_same_state(serial: dict, parallel: dict) -> None:
    np.testing.assert_array_equal(serial["global_id"], parallel["global_id"])
    dx = np.abs(serial["position"] - parallel["position"]).max()
    assert dx <= 1e-10 * SIDE, f"positions differ by {dx:.3g} m"
    rel_t = np.abs(serial["temperature"] / parallel["temperature"] - 1.0).max()
    assert rel_t <= 1e-10, f"temperatures differ by {rel_t:.3g} relative"


def _assert_same_ledgers(serial_dir: Path, parallel_dir: Path) -> None:
    """Every time-series column equal to round-off: relative to its own scale (the largest
    magnitude of the column), the balance errors relative to the energies they balance."""
    from thermodem.io.run_files import read_timeseries

    a = read_timeseries(serial_dir / "timeseries.csv")
    b = read_timeseries(parallel_dir / "timeseries.csv")
    assert list(a) == list(b), "the columns differ"
    np.testing.assert_array_equal(a["step"], b["step"])
    scale = {
        "energy_balance_error": np.abs(a["gravitational"]).max(),
        "heat_balance_error": np.abs(a["thermal_energy"]).max(),
    }
    generated = [np.abs(a[k]).max() for k in a if k.startswith("generated_")]
    if generated:  # (relative to the heat generated, as the other balance errors)
        scale["generation_balance_error"] = max(generated)
    for name in a:
        finite = np.isfinite(a[name])
        np.testing.assert_array_equal(finite, np.isfinite(b[name]), err_msg=name)
        np.testing.assert_array_equal(a[name][~finite], b[name][~finite], err_msg=name)
        if not finite.any():
            continue
        ref = scale.get(name, np.abs(a[name][finite]).max())
        if ref == 0.0:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)
            continue
        worst = np.abs(a[name][finite] - b[name][finite]).max() / ref
        assert worst <= 1e-9, f"{name}: differs by {worst:.3g} of its scale"


def _serial_and_2_ranks(path: Path, out: Path, steps: int) -> tuple[dict, dict]:
    """The case ``path`` run serially into ``out``1 and on 2 ranks into ``out``2; their final
    states (checked equal) and ledgers (checked equal to round-off)."""
    for ranks in (1, 2):
        res = _run(["run", str(path), "-o", f"{out}{ranks}", "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
    serial, parallel = _final(Path(f"{out}1"), steps), _final(Path(f"{out}2"), steps)
    _assert_same_state(serial, parallel)
    _assert_same_ledgers(Path(f"{out}1"), Path(f"{out}2"))
    return serial, parallel


def _continued_serially(checkpoint: Path, out: Path, steps: int) -> dict:
    """The final state of a serial run continuing from ``checkpoint`` to step ``steps``."""
    res = _run(["run", "--restart", str(checkpoint), "-o", str(out), "--no-progress"], 1)
    assert res.returncode == 0, res.stderr
    return _final(out, steps)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The settled bed over 1000 steps: serially and on 2 ranks (shared by the tests)."""
    if not _have_mpi():
        pytest.skip("mpi4py and the mpich wheel (test extras) are not installed")
    tmp = tmp_path_factory.mktemp("mpi")
    case = _box_case(tmp)
    out = {"case": case}
    for ranks in (1, 2):
        directory = tmp / f"ranks{ranks}"
        res = _run(["run", str(case), "-o", str(directory), "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
        out[ranks] = directory
    return out


# ----------------------------------------------------------------------------- no MPI
def test_plain_run_does_not_import_mpi4py(tmp_path: Path) -> None:
    """Without mpiexec the run is the serial one: mpi4py is never imported."""
    case = _write_case(tmp_path / "c.yaml", bed_case(DATA / "mpi_bed_box.txt", heat=None,
                                                     end_time=5 * DT))  # fmt: skip
    code = textwrap.dedent(f"""
        import sys
        from thermodem.cli import app
        try:
            app(["run", {str(case)!r}, "-o", {str(tmp_path / "out")!r}, "--no-progress"])
        except SystemExit as exc:
            assert not exc.code, exc.code
        assert "mpi4py" not in sys.modules, "mpi4py was imported by a serial run"
    """)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=_env(1), timeout=600)  # fmt: skip
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (lambda c: c["thermal"].update(frozen_mechanics=True, time_step=1e-3,
                                       scheme="backward_euler"), "thermal.scheme"),
        # the Voronoi porosity (cell, shell and global run under MPI)
        (lambda c: c["thermal"].update(convection="gunn1978", fluid={"temperature": 300.0},
                                       porosity={"kind": "voronoi"}),
         "thermal.porosity.kind = 'voronoi'"),
        (lambda c: c["thermal"].update(indirect_conduction="voronoi_a",
                                       gas={"thermal_conductivity": 0.026}),
         "thermal.indirect_conduction"),
    ],
)  # fmt: skip
def test_refused_under_mpi(change, key: str) -> None:  # noqa: ANN001
    """What MPI does not support yet is refused before the run, naming the key."""
    from thermodem.config.load import case_from_dict
    from thermodem.errors import ConfigError
    from thermodem.mpi.support import check_case

    case = bed_case(DATA / "mpi_bed_box.txt")
    change(case)
    with pytest.raises(ConfigError, match="MPI does not support it yet") as info:
        check_case(case_from_dict(case))
    assert key in str(info.value)
    if "porosity" in key:  # (what runs instead)
        assert "porosity cell, shell and global run under MPI" in str(info.value)


@pytest.mark.parametrize(
    "model", ["mechanical_dissipation", "rojek2014", "richard2008", "al_arkawazi2017"]
)
def test_heat_generation_runs_under_mpi(model: str) -> None:
    """Heat generation is no longer refused (every model: the deposits of the contact passes,
    docs/mpi.md; tests/mpi/test_mpi_thermal_paths.py compares it with the serial run)."""
    from thermodem.config.load import case_from_dict
    from thermodem.mpi.support import REFUSED, check_case

    case = bed_case(DATA / "mpi_bed_box.txt")
    case["thermal"]["heat_generation"] = {"model": model}
    check_case(case_from_dict(case))
    assert not any("heat_generation" in key for key, _ in REFUSED)


def test_two_dimensional_case_accepted_under_mpi() -> None:
    """A disc simulation (simulation.dimension: 2) is no longer refused under MPI."""
    from thermodem.config.load import load_case
    from thermodem.mpi.support import REFUSED, check_case

    check_case(load_case(Path(__file__).parents[2] / "examples" / "drum_2d.yaml"))
    assert not any("dimension" in key for key, _ in REFUSED)


@needs_mpi
def test_two_dimensional_drum_on_2_ranks(tmp_path: Path) -> None:
    """The 2D drum example (a turning, hot mantle; thermal pipe conduction) with a bed of
    touching discs at 300-350 K in its lower part instead of its random fill, 1500 steps on
    2 ranks against the serial run: the bisection cuts x and y only and each rank's grid has
    one cell layer along z, as the serial list; the discs stay in the plane (z = 0, v_z = 0)
    and heat flows (from the mantle and between the discs)."""
    steps = 1500
    case = yaml.safe_load((Path(__file__).parents[2] / "examples" / "drum_2d.yaml").read_text())
    case["simulation"]["end_time"] = steps * 4e-6
    radius, spacing = 2e-3, 3.99e-3  # (a hexagonal bed, each disc pressed by 1 % of R)
    centres = [
        (col * spacing + (row % 2) * spacing / 2, -0.036 + row * spacing * np.sqrt(3) / 2)
        for row in range(6) for col in range(-10, 11)
    ]  # fmt: skip
    centres = [(x, y) for x, y in centres if np.hypot(x, y) <= 0.04 - radius + 1e-5]
    rng = np.random.default_rng(1)
    temperatures = rng.uniform(300, 350, len(centres)).tolist()
    case["insertion"] = [{"kind": "list", "material": "glass", "radius": radius,
                          "positions": [[float(x), float(y)] for x, y in centres],
                          "temperatures": temperatures}]  # fmt: skip
    case["output"] = {"vtu": False, "timeseries_interval": 300 * 4e-6,
                      "checkpoint_interval": 1500 * 4e-6, "checkpoint_keep": None}  # fmt: skip
    case["neighbors"] = {"skin": 1e-4}  # (rebuilds and migration while the discs fall)
    path = _write_case(tmp_path / "drum2d.yaml", case)
    serial, parallel = _serial_and_2_ranks(path, tmp_path / "d", steps)
    assert np.abs(parallel["position"][:, 2]).max() == 0.0
    assert np.abs(parallel["velocity"][:, 2]).max() == 0.0
    start = _final(tmp_path / "d2", 0)["temperature"]
    assert len(centres) > 70 and np.abs(parallel["temperature"] - start).max() > 1e-3


def test_bisection_balances_and_tiles() -> None:
    """Recursive bisection of 1000 points among P boxes: counts within one of N/P, boxes
    tiling the domain, each point inside its box (comm None: one process)."""
    from thermodem.mpi.decomposition import bisect, point_box_distance

    rng = np.random.default_rng(5)
    upper = np.array([3.0, 1.0, 0.5])
    x = rng.random((1000, 3)) * upper
    for size in (2, 3, 4, 5, 7, 8):
        d = bisect(None, x, np.zeros(3), upper, size)
        owner = d.owner(x)
        counts = np.bincount(owner, minlength=size)
        assert counts.max() - counts.min() <= 1, counts
        assert np.isclose(np.prod(d.boxes[:, 1] - d.boxes[:, 0], axis=1).sum(), upper.prod())
        for r in range(size):
            inside = point_box_distance(x[owner == r], *d.boxes[r], upper, np.zeros(3, bool))
            assert np.all(inside == 0.0)
        moved = d.rotated(1).owner(x)
        np.testing.assert_array_equal(moved, (owner + 1) % size)


def test_bisection_of_discs_cuts_the_plane_only() -> None:
    """Discs (planar) in a domain whose z slab is the longest side (1 m for zero thickness,
    engine/simulation.py): the boxes are cut along x and y only, and balanced."""
    from thermodem.mpi.decomposition import bisect

    rng = np.random.default_rng(6)
    lower, upper = np.array([0.0, 0.0, -0.5]), np.array([0.2, 0.1, 0.5])
    x = rng.random((999, 3)) * (upper - lower) + lower
    x[:, 2] = 0.0
    for size in (2, 3, 4):
        d = bisect(None, x, lower, upper, size, planar=True)
        assert np.all(d.axis != 2), d.axis
        np.testing.assert_array_equal(d.boxes[:, 0, 2], lower[2])
        np.testing.assert_array_equal(d.boxes[:, 1, 2], upper[2])
        counts = np.bincount(d.owner(x), minlength=size)
        assert counts.max() - counts.min() <= 1, counts
    assert np.any(bisect(None, x, lower, upper, 2).axis == 2)  # (3D: the longest side)


# ----------------------------------------------------------------------- several ranks
@needs_mpi
def test_settled_bed_matches_serial_on_2_ranks(runs: dict[str, Path]) -> None:
    serial, parallel = runs[1], runs[2]
    _assert_same_state(_final(serial), _final(parallel))
    _assert_same_ledgers(serial, parallel)
    # one checkpoint and one frame per output time, the frames with every particle once
    from thermodem.io.vtk_read import read_vtu

    names = sorted(p.name for p in (parallel / "checkpoints").iterdir())
    assert names == [f"checkpoint_{k:09d}.h5" for k in (0, 500, 1000)]
    frames = sorted((parallel / "vtk").glob("particles_*.vtu"))
    assert [f.name for f in frames] == [f"particles_{k:09d}.vtu" for k in (0, 500, 1000)]
    mesh = read_vtu(frames[-1])
    np.testing.assert_array_equal(np.sort(mesh.point_data["global_id"]), np.arange(500))
    log = (parallel / "run.log").read_text()
    assert "MPI: 2 ranks" in log and "gathered in" in log


@needs_mpi
def test_settled_bed_matches_serial_on_4_ranks(runs: dict[str, Path], tmp_path: Path) -> None:
    """Four ranks (oversubscribed on a 2-core machine)."""
    res = _run(["run", str(runs["case"]), "-o", str(tmp_path / "r4"), "--no-progress"], 4)
    assert res.returncode == 0, res.stderr
    _assert_same_state(_final(runs[1]), _final(tmp_path / "r4"))
    _assert_same_ledgers(runs[1], tmp_path / "r4")


@needs_mpi
def test_checkpoints_continue_on_another_rank_count(runs: dict[str, Path], tmp_path: Path) -> None:
    """The checkpoint written by 2 ranks at step 500 continues serially (the gathered file has
    the serial layout), and the serial run's directory continues on 2 ranks (`thermodem
    restart DIR` from its step-500 checkpoint): both reach the uninterrupted run's state."""
    reference = _final(runs[1])
    checkpoint = runs[2] / "checkpoints" / "checkpoint_000000500.h5"
    out = tmp_path / "from2on1"
    res = _run(["run", "--restart", str(checkpoint), "-o", str(out), "--no-progress"], 1)
    assert res.returncode == 0, res.stderr
    _assert_same_state(reference, _final(out))
    directory = tmp_path / "serial_copy"
    shutil.copytree(runs[1], directory)
    (directory / "checkpoints" / f"checkpoint_{STEPS:09d}.h5").unlink()  # newest: step 500
    res = _run(["restart", str(directory), "--no-progress"], 2)
    assert res.returncode == 0, res.stderr
    _assert_same_state(reference, _final(directory))
    _assert_same_ledgers(runs[1], directory)


@needs_mpi
def test_pouring_and_external_loads_on_2_ranks(tmp_path: Path) -> None:
    """A pour entry over the bed (batches every 40 steps, falling onto it: the new particles
    join the ranks whose boxes hold them) and constant external loads (a push and a torque on
    ten particles, a small side force on every glass particle, the poured ones included):
    400 steps on 2 ranks against the serial run, particle for particle and ledger for ledger
    (external work, inserted energy and heat included); the 2-rank checkpoint of step 200
    (with the pour's state and random generator) continues serially to the same end."""
    steps = 400
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=steps * DT)
    case["insertion"].append(
        {"kind": "pour", "material": "glass", "rate": 50000.0, "interval": 40 * DT,
         "distribution": {"kind": "uniform", "min_radius": 0.8e-3, "max_radius": 1.0e-3},
         "region": {"kind": "box", "lower": [0, 0, 0.021], "upper": [SIDE, SIDE, 0.026]},
         "velocity": [0.0, 0.0, -2.0], "temperature": 350.0}
    )  # fmt: skip
    case["external_force"] = [
        {"select": {"ids": list(range(10))}, "force": [0.0, 0.0, -5e-4],
         "torque": [1e-7, 0.0, 0.0]},
        {"select": {"material": "glass"}, "force": [1e-5, 0.0, 0.0]},
    ]  # fmt: skip
    case["output"] = {"vtu": False, "timeseries_interval": 50 * DT,
                      "checkpoint_interval": 200 * DT, "checkpoint_keep": None}  # fmt: skip
    path = _write_case(tmp_path / "pour.yaml", case)
    serial, _ = _serial_and_2_ranks(path, tmp_path / "o", steps)
    poured = serial["global_id"].shape[0] - 500
    assert poured >= 80, poured  # (10 batches of 10 requested)
    from thermodem.io.run_files import read_timeseries

    ledger = read_timeseries(tmp_path / "o2" / "timeseries.csv")
    assert ledger["external_work"][-1] != 0.0
    assert ledger["inserted_energy"][-1] != 0.0
    checkpoint = tmp_path / "o2" / "checkpoints" / "checkpoint_000000200.h5"
    _assert_same_state(serial, _continued_serially(checkpoint, tmp_path / "from2on1", steps))


@needs_mpi
def test_contact_frames_on_2_ranks(tmp_path: Path) -> None:
    """``output.contacts`` on 2 ranks: every touching contact once (a pair across the cut is
    written by the owner of its lower id), with the serial run's geometry, force and heat
    (Batchelor & O'Brien complete: the contact term and the range set's gap term on the
    contacts; a hot wall)."""
    from thermodem.io.vtk_read import read_vtu

    steps = 200
    case = bed_case(DATA / "mpi_bed_box.txt", heat="range", end_time=steps * DT)
    case["output"] = {"vtu": True, "contacts": True, "interval": 100 * DT}
    path = _write_case(tmp_path / "contacts.yaml", case)
    data = {}
    for ranks in (1, 2):
        out = tmp_path / f"c{ranks}"
        res = _run(["run", str(path), "-o", str(out), "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
        frames = sorted((out / "vtk").glob("contacts_*.vtu"))
        assert [f.name for f in frames] == [f"contacts_{k:09d}.vtu" for k in (0, 100, 200)]
        mesh = read_vtu(frames[-1])
        cells = {k: np.asarray(v[0]) for k, v in mesh.cell_data.items()}
        order = np.lexsort((cells["wall"], cells["id_j"], cells["id_i"]))
        data[ranks] = {k: v[order] for k, v in cells.items()}
    a, b = data[1], data[2]
    assert a["id_i"].shape[0] > 500 and np.count_nonzero(a["wall"] >= 0) > 50
    assert set(a) == set(b) and "heat_rate_indirect_conduction" in a, sorted(a)
    for key in ("id_i", "id_j", "wall"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    for key in a:
        scale = np.abs(a[key]).max()
        assert np.abs(a[key] - b[key]).max() <= 1e-9 * scale, key


@needs_mpi
@pytest.mark.parametrize("heat", ["contact", "range"])
def test_frozen_mechanics_on_2_ranks(tmp_path: Path, heat: str) -> None:
    """``thermal.frozen_mechanics`` (the heat-only passes over the list and the mirror list,
    the ghosts' temperatures exchanged every step): the settled bed heated from its bottom
    layer (contact: Batchelor & O'Brien simple; range: complete, its gap term on the range
    set, a hot wall) over 100 thermal steps of 0.05 s on 2 ranks against the serial run, and
    the 2-rank checkpoint of step 50 continued serially."""
    steps, time_step = 100, 0.05
    case = bed_case(DATA / "mpi_bed_box.txt", heat=heat, end_time=steps * time_step)
    case["thermal"].update(frozen_mechanics=True, time_step=time_step)
    case["output"] = {"vtu": False, "timeseries_interval": 10 * time_step,
                      "checkpoint_interval": 50 * time_step, "checkpoint_keep": None}  # fmt: skip
    path = _write_case(tmp_path / "frozen.yaml", case)
    serial, _ = _serial_and_2_ranks(path, tmp_path / "f", steps)
    heated = serial["temperature"] - _final(tmp_path / "f1", 0)["temperature"]
    assert np.count_nonzero(heated > 1e-3) > 100  # (the heat has spread over the bed)
    checkpoint = tmp_path / "f2" / "checkpoints" / "checkpoint_000000050.h5"
    _assert_same_state(serial, _continued_serially(checkpoint, tmp_path / "from2on1", steps))


@needs_mpi
@pytest.mark.parametrize("frozen", [False, True])
def test_contact_list_heat_term_on_2_ranks(tmp_path: Path, frozen: bool) -> None:
    """Vargas & McCarthy (2002) indirect conduction, a heat term on the contact lists outside
    the fused pass (over the list and the mirror list on several ranks), with Batchelor &
    O'Brien simple: 300 steps of the settled bed on 2 ranks against the serial run; with
    frozen mechanics (its conductances stored and reused) 60 thermal steps of 0.05 s."""
    steps = 60 if frozen else 300
    time_step = 0.05 if frozen else DT
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=steps * time_step)
    case["materials"]["glass"]["thermal_accommodation"] = 0.8
    case["thermal"].update(indirect_conduction="vargas_mccarthy2002",
                           gas={"thermal_conductivity": 0.026})  # fmt: skip
    if frozen:
        case["thermal"].update(frozen_mechanics=True, time_step=time_step)
    case["output"] = {"vtu": False, "timeseries_interval": 20 * time_step,
                      "checkpoint_interval": steps * time_step}  # fmt: skip
    path = _write_case(tmp_path / "vm.yaml", case)
    serial, _ = _serial_and_2_ranks(path, tmp_path / "v", steps)
    from thermodem.io.run_files import read_timeseries

    ledger = read_timeseries(tmp_path / "v2" / "timeseries.csv")
    assert ledger["heat_rate_indirect_conduction"].min() > 1.0  # [W] (the term carries heat)


#: per-particle terms whose fields sum over each particle's neighbours (the ghosts reach as
#: far as the neighbourhoods: mpi/simulation.py: halo_width)
NEIGHBOURHOODS = {
    "gunn_cell_porosity": {"convection": "gunn1978", "porosity": {"kind": "cell"},
                           "fluid": {"temperature": 500.0, "velocity": [0.0, 0.0, 0.5]}},
    "surroundings_shell_porosity": {
        "radiation": {"model": "surroundings", "environment_temperature": 800.0,
                      "exposure": "fraction"},
        "porosity": {"kind": "shell", "radius_ratio": 3.0}},
    "zhou2009": {"radiation": {"model": "zhou2009"}, "porosity": {"kind": "shell"},
                 "fluid": {"temperature": 500.0}},
    "krause2017": {"radiation": {"model": "krause2017", "environment_temperature": 800.0}},
}  # fmt: skip


@needs_mpi
@pytest.mark.parametrize("name", sorted(NEIGHBOURHOODS))
def test_neighbourhood_fields_on_2_ranks(tmp_path: Path, name: str) -> None:
    """Cell and shell porosities and the continuum radiation models (Zhou et al. 2009,
    Krause et al. 2017) sum over the neighbours of each particle, which may be other ranks'
    particles: the settled bed with the contact conduction over 200 steps on 2 ranks against
    the serial run (the cut runs through the bed), and the 2-rank checkpoint of step 100 (its
    neighbourhood set and listing emptied: they hold a rank's indices) continued serially."""
    steps = 200
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=steps * DT)
    case["materials"]["glass"]["emissivity"] = 0.9
    case["thermal"].update(NEIGHBOURHOODS[name])
    case["output"] = {"vtu": False, "timeseries_interval": 50 * DT,
                      "checkpoint_interval": 100 * DT, "checkpoint_keep": None}  # fmt: skip
    path = _write_case(tmp_path / "nb.yaml", case)
    serial, _ = _serial_and_2_ranks(path, tmp_path / "n", steps)
    from thermodem.io.run_files import read_timeseries

    ledger = read_timeseries(tmp_path / "n2" / "timeseries.csv")
    column = "heat_in_convection" if "convection" in NEIGHBOURHOODS[name] else "heat_in_radiation"
    assert abs(ledger[column][-1]) > 0.0
    checkpoint = tmp_path / "n2" / "checkpoints" / "checkpoint_000000100.h5"
    _assert_same_state(serial, _continued_serially(checkpoint, tmp_path / "from2on1", steps))


@needs_mpi
def test_periodic_bed_with_range_set_on_2_ranks(tmp_path: Path) -> None:
    """Periodic x and y, Batchelor & O'Brien complete (separated pairs on the range set) and
    a hot floor: 400 steps on 2 ranks against the serial run."""
    case = bed_case(DATA / "mpi_bed_periodic.txt", periodic=True, heat="range",
                    end_time=400 * DT)  # fmt: skip
    case["output"] = {"vtu": False, "timeseries_interval": 100 * DT}
    path = _write_case(tmp_path / "periodic.yaml", case)
    for ranks in (1, 2):
        res = _run(["run", str(path), "-o", str(tmp_path / f"p{ranks}"), "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
    _assert_same_state(_final(tmp_path / "p1", 400), _final(tmp_path / "p2", 400))
    _assert_same_ledgers(tmp_path / "p1", tmp_path / "p2")


@needs_mpi
def test_a_restart_with_a_range_set_on_2_ranks_reports_as_serially(tmp_path: Path) -> None:
    """The range set's first time-series row after a restart on 2 ranks counted the pairs of
    the stale set through the old particle numbers (2796 against 2599 serially): the set is
    built for the row. The serial run from the same checkpoint and the whole serial run give
    the same ledgers."""
    case = bed_case(DATA / "mpi_bed_periodic.txt", periodic=True, heat="range",
                    end_time=200 * DT)  # fmt: skip
    case["output"] = {"vtu": False, "timeseries_interval": 50 * DT,
                      "checkpoint_interval": 100 * DT, "checkpoint_keep": None}  # fmt: skip
    path = _write_case(tmp_path / "range.yaml", case)
    res = _run(["run", str(path), "-o", str(tmp_path / "full"), "--no-progress"], 1)
    assert res.returncode == 0, res.stderr
    middle = tmp_path / "full" / "checkpoints" / "checkpoint_000000100.h5"
    for ranks in (1, 2):
        res = _run(["run", "--restart", str(middle), "-o", str(tmp_path / f"r{ranks}"),
                    "--no-progress"], ranks)  # fmt: skip
        assert res.returncode == 0, res.stderr
    _assert_same_ledgers(tmp_path / "r1", tmp_path / "r2")
    _assert_same_state(_final(tmp_path / "r1", 200), _final(tmp_path / "r2", 200))


@needs_mpi
def test_thermal_options_and_a_moving_plate_on_2_ranks(tmp_path: Path) -> None:
    """A c(T) table, the resistance network with the conductance reuse (its columns in
    the contact history), substeps 'auto', a heat flux into the
    top layer and a plate pressing the bed down (the particles move: rebuilds, migration):
    300 steps on 2 ranks against the serial run."""
    steps = 300
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=steps * DT)
    glass = case["materials"]["glass"]
    del glass["specific_heat"]  # (the table replaces it)
    glass["specific_heat_table"] = [[300.0, 800.0], [400.0, 900.0]]
    glass.update(microhardness=3e9, surface_roughness=1e-6, surface_slope=0.1,
                 thermal_accommodation=0.8, youngs_modulus_real=7e10)  # fmt: skip
    case["thermal"].update(direct_conduction="resistance_network", substeps="auto",
                           conductance_force_tolerance=0.01)  # fmt: skip
    case["thermal"]["heat_flux"] = [{"flux": 2e4, "select": {"region": {
        "lower": [0, 0, 8e-3], "upper": [SIDE, SIDE, HEIGHT]}}}]  # fmt: skip
    top = float(np.loadtxt(DATA / "mpi_bed_box.txt", skiprows=1)[:, 2].max()) + 1e-3
    case["walls"].append({"kind": "plane", "point": [0, 0, top], "normal": [0, 0, -1],
                          "velocity": [0, 0, -0.2], "material": "glass"})  # fmt: skip
    case["neighbors"] = {"skin": 5e-5}  # (rebuilds every few steps)
    case["output"] = {"vtu": False, "timeseries_interval": 50 * DT}
    path = _write_case(tmp_path / "options.yaml", case)
    for ranks in (1, 2):
        res = _run(["run", str(path), "-o", str(tmp_path / f"o{ranks}"), "--no-progress"], ranks)
        assert res.returncode == 0, res.stderr
    _assert_same_state(_final(tmp_path / "o1", steps), _final(tmp_path / "o2", steps))
    _assert_same_ledgers(tmp_path / "o1", tmp_path / "o2")
    log = (tmp_path / "o2" / "run.log").read_text()
    assert "MPI: 2 ranks" in log


MIGRATION_SCRIPT = """
import sys, numpy as np, yaml
from thermodem.config.load import case_from_dict
from thermodem.mpi import make_simulation, under_mpi
case = case_from_dict(yaml.safe_load(open(sys.argv[1])))
case.neighbors.rebuild_every_step = True
sim = make_simulation(case)
if under_mpi():
    sim.rotate_owners = True  # every box to the next rank at every rebuild
sim.run(steps=int(sys.argv[3]))
report = sim.report()
particles = sim.particles
if under_mpi():
    from thermodem.mpi.gather import gathered_view
    view = gathered_view(sim)
    particles = view.particles if view is not None else None
    migrated = sim.comm.allreduce(sim.migrated)
else:
    migrated = 0
if particles is not None:
    order = np.argsort(particles.global_id)
    np.savez(sys.argv[2], position=particles.position[order],
             temperature=particles.temperature[order], migrated=migrated,
             **{k: np.array(v) for k, v in report.items()})
"""


@needs_mpi
def test_migration_carries_the_whole_state(tmp_path: Path) -> None:
    """Every particle changes rank at every step (rebuild every step, boxes handed on): the
    contact and rolling histories, temperatures and accumulators travel with the particles,
    so the run still matches the serial one."""
    steps = 60
    case = bed_case(DATA / "mpi_bed_box.txt", heat="contact", end_time=steps * DT)
    path = _write_case(tmp_path / "m.yaml", case)
    script = tmp_path / "migrate.py"
    script.write_text(MIGRATION_SCRIPT)
    results = {}
    for ranks in (1, 2):
        cmd = [str(BIN / "python"), str(script), str(path), str(tmp_path / f"m{ranks}.npz"),
               str(steps)]  # fmt: skip
        if ranks > 1:
            cmd = [str(MPIEXEC), "-n", str(ranks), *cmd]
        res = subprocess.run(cmd, capture_output=True, text=True, env=_env(ranks), timeout=900)
        assert res.returncode == 0, res.stderr
        results[ranks] = np.load(tmp_path / f"m{ranks}.npz")
    a, b = results[1], results[2]
    assert int(b["migrated"]) >= 500 * steps  # every particle, at every step
    assert np.abs(a["position"] - b["position"]).max() <= 1e-10 * SIDE
    assert np.abs(a["temperature"] / b["temperature"] - 1).max() <= 1e-10
    for key in ("dissipated_sliding_friction", "dissipated_rolling_friction", "elastic_rolling",
                "elastic_tangential", "thermal_energy", "fixed_absorbed"):  # fmt: skip
        assert abs(float(a[key]) - float(b[key])) <= 1e-9 * abs(float(a[key])), key


@needs_mpi
def test_failure_stops_every_rank_with_one_message(tmp_path: Path) -> None:
    """A time step 60 times too large (the check overridden): a particle leaves the domain on
    one rank; every rank stops, the message is printed once with the last good checkpoint,
    and the state at the failure is gathered to failed.h5."""
    case = bed_case(DATA / "mpi_bed_box.txt", heat=None, time_step=3e-4, end_time=0.06)
    case["simulation"]["time_step_check"] = {"allow_unstable": True}
    path = _write_case(tmp_path / "bad.yaml", case)
    res = _run(["run", str(path), "-o", str(tmp_path / "bad"), "--no-progress"], 2, timeout=300)
    assert res.returncode == 1, res.stderr
    assert res.stderr.count("error:") == 1, res.stderr
    assert "last good state:" in res.stderr and "left the domain" in res.stderr
    assert (tmp_path / "bad" / "failed.h5").exists()


@needs_mpi
def test_unsupported_key_refused_by_mpiexec(tmp_path: Path) -> None:
    case = bed_case(DATA / "mpi_bed_box.txt", end_time=10 * DT)
    case["thermal"].update(frozen_mechanics=True, time_step=1e-3, scheme="backward_euler")
    path = _write_case(tmp_path / "c.yaml", case)
    res = _run(["run", str(path), "-o", str(tmp_path / "o"), "--no-progress"], 2, timeout=300)
    assert res.returncode == 2
    assert res.stderr.count("MPI does not support it yet") == 1, res.stderr
    assert "thermal.scheme" in res.stderr


@needs_mpi
def test_a_failure_while_the_case_is_built_is_an_input_error_under_mpi(tmp_path: Path) -> None:
    """A periodic axis shorter than two neighbour cells, met by the distributing rebuild while
    the ranks build the simulation, is an input error on 2 ranks too: exit 2, the message
    (naming domain.periodic, as the serial one) said once."""
    case = bed_case(None, heat=None, periodic=True, end_time=10 * DT)
    case["domain"]["upper"][0] = 3.5e-3
    case["walls"] = []
    entry = case["insertion"][0]
    entry.update(count=20)
    entry["upper"][0] = 3.5e-3
    path = _write_case(tmp_path / "short.yaml", case)
    res = _run(["run", str(path), "-o", str(tmp_path / "o"), "--no-progress"], 2, timeout=300)
    assert res.returncode == 2, res.stderr
    assert res.stderr.count("domain.periodic: axis x is periodic") == 1, res.stderr
    assert "(met while the case was built, before any step)" in res.stderr


DISK_FULL_SCRIPT = """
import errno
import sys

from thermodem.cli import app
from thermodem.io.run_files import TimeseriesWriter

original = TimeseriesWriter.write


def full(self, sim):
    if sim.step_count >= 10:
        sim.report()  # (the collective part comes first, as in the real writer)
        raise OSError(errno.ENOSPC, "No space left on device")
    original(self, sim)


TimeseriesWriter.write = full
app(["run", sys.argv[1], "-o", sys.argv[2], "--no-progress"])
"""


@needs_mpi
def test_an_output_refused_stops_every_rank_with_one_message(tmp_path: Path) -> None:
    """A full disk on rank 0 in the middle of a run: every rank stops with rank 0's message
    (before, rank 0 printed an OSError traceback and aborted the job), status.json says
    'failed' and the message names the last checkpoint and the mpiexec restart."""
    import json

    case = bed_case(DATA / "mpi_bed_box.txt", heat=None, end_time=40 * DT)
    case["output"] = {"timeseries_interval": 5 * DT, "checkpoint_interval": 5 * DT}
    path = _write_case(tmp_path / "full.yaml", case)
    script = tmp_path / "full.py"
    script.write_text(DISK_FULL_SCRIPT)
    out = tmp_path / "full"
    cmd = [str(MPIEXEC), "-n", "2", str(BIN / "python"), str(script), str(path), str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True, env=_env(2), timeout=300)
    assert res.returncode == 1, res.stderr
    assert res.stderr.count("error:") == 1, res.stderr
    assert "Traceback" not in res.stderr, res.stderr
    assert f"the run directory {out} cannot be written at step 10" in res.stderr, res.stderr
    assert "No space left on device" in res.stderr
    assert f"continue with: mpiexec -n 2 thermodem restart {out}" in res.stderr, res.stderr
    assert json.loads((out / "status.json").read_text())["status"] == "failed"


@needs_mpi
def test_commands_that_run_no_case_run_on_rank_0_only(tmp_path: Path) -> None:
    """validate, info, export (and etc, plot, models) under mpiexec -n 2 ran on every rank:
    every line twice, and export -o FILE raced (one rank failed with 'file exists', exit 2).
    Rank 0 runs them alone, the other ranks exit with its code."""
    case = bed_case(DATA / "mpi_bed_box.txt", heat=None, end_time=2 * DT)
    path = _write_case(tmp_path / "c.yaml", case)
    out = tmp_path / "o"
    assert _run(["run", str(path), "-o", str(out), "--no-progress"]).returncode == 0
    res = _run(["validate", str(path)], 2, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.count(": valid (schema") == 1, res.stdout
    res = _run(["info", str(out)], 2, timeout=120)
    assert res.returncode == 0 and res.stdout.count("status: finished") == 1, res.stdout
    res = _run(["export", str(out), "-o", str(tmp_path / "p.csv")], 2, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.count("p.csv") == 1 and (tmp_path / "p.csv").exists()
    res = _run(["export", str(out), "-o", str(tmp_path / "p.csv")], 2, timeout=120)
    assert res.returncode == 2 and res.stderr.count("error:") == 1, res.stderr  # (it exists)
    case["simulation"]["end_time"] = 0.0
    res = _run(["validate", str(_write_case(tmp_path / "bad.yaml", case))], 2, timeout=120)
    assert res.returncode == 2 and res.stderr.count("error:") == 1, res.stderr
