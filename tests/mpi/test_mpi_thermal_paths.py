"""The heat of a 2-rank run against the serial run on every thermal path MPI supports
(docs/mpi.md), in one ``mpiexec`` launch: explicit Euler with the heat every step (fused with
the contact pass), every 3rd step, ``substeps: auto``, the range set (rong_horio1999) with
fixed-temperature particles, a heat flux and a volumetric source, and three restarts whose
first thermal step is not fused with a contact pass; the per-particle terms (convection with
a uniform / expression / grid / table fluid and a global porosity, radiation to the
surroundings and the walls in view) and external sources, with a serial checkpoint continued
on 2 ranks and a 2-rank checkpoint continued serially; heat generation (mechanical_dissipation,
al_arkawazi2017) with the spheres moving across the ranks' cut, its ledger and balances. The
convection's validity-range warnings are said once (by rank 0), and the quantities warned
travel in checkpoints.

Before the fix (mpi/gather.py: load_distributed) the restarts went wrong on 2 ranks:

- a checkpoint between two thermal steps continued with another time step (the steps are
  renumbered, engine/restart.py: _adapt_step_length, so a thermal step falls on the first
  step): its rates came from the heat-only passes after the distributing rebuild, which
  leaves every pair unset until the next contact pass; that thermal step added no contact
  heat (limit inf, ``substeps: auto`` kept the old count): temperatures 4e-4 (substeps 3)
  and 1e-2 (auto) relative off;
- heat that starts at a restart (engine/heat_start.py) computed its first rates while the
  rank owned none of the particles (the owned count of the empty start): the range set was
  built empty and its heat left out of the first thermal step (2e-4 relative off).

The 54-sphere column of mpi_cases.column_case, 140 steps (restarts: 70 serial steps, then
100 more). The runs agree to the bit today; the test allows 1e-12 relative in temperatures
(the pair sums of a particle may be added in another order on several ranks: round-off,
~1e-16), far below what a pair's heat missing for one step gives (> 1e-6), and 1e-9 of its
scale in each heat column of the report.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from mpi_cases import column_case  # noqa: E402
from test_mpi import BIN, MPIEXEC, _env, _run, _write_case, needs_mpi  # noqa: E402

DT = 5e-6
RANGE = {"indirect_conduction": "rong_horio1999", "gas": {"thermal_conductivity": 0.026}}
W, H = 6e-3, 12e-3
CONDITIONS = {
    "fixed_temperature": [{"temperature": 450.0, "select": {"region": {
        "lower": [0, 0, 0], "upper": [W, W, 1.5e-3]}}}],
    "heat_flux": [{"flux": 2e4, "select": {"region": {
        "lower": [0, 0, 8e-3], "upper": [W, W, H]}}}],
    "volumetric_source": [{"power_density": 1e7, "select": {"region": {
        "lower": [0, 0, 4e-3], "upper": [W, W, 8e-3]}}}],
}  # fmt: skip

#: per-particle terms (the column's material gets an emissivity of 0.9 when radiation is on;
#: GRID: a fluid temperature on a grid file written by the test); Re of ranz_marshall1952
#: below 1 and Pr of the gas below whitaker1972's 0.71 are warned at the first evaluation
CONVECTION = {
    "convection": "ranz_marshall1952",
    "fluid": {"temperature": 500.0, "velocity": [0.0, 0.0, 0.002]},
    "radiation": {"model": "surroundings", "environment_temperature": 800.0, "walls": True},
}
GUNN = {
    "convection": "gunn1978",
    "fluid": {"temperature": "400 + 20000 * z", "velocity": ["0", "0", "0.5 + 20 * z"]},
    "porosity": {"kind": "global", "value": 0.4},
    "radiation": {
        "model": "surroundings",
        "environment_temperature": 700.0,
        "exposure": "threshold",
        "threshold": 0.3,
    },
}
GRID = {
    "convection": "whitaker1972",
    "fluid": {
        "temperature": {"file": "GRID", "field": "T"},
        "velocity": [[0.0, 0, 0, 0.3], [1e-3, 0, 0, 1.5]],
    },
}
EXTERNAL = {
    "external_source": [
        {
            "power": 2.0,
            "region": {"lower": [0, 0, 3e-3], "upper": [W, W, 9e-3]},
            "profile": "gaussian",
            "sigma": 2e-3,
            "axis": [0, 0, 1],
        },
        {"power": 0.5, "region": {"lower": [0, 0, 0], "upper": [W, W, H]}},
    ]
}

#: heat generation (every mechanism of mechanical_dissipation; al_arkawazi2017's kinetic energy
#: lost in collisions): the spheres of these cases start moving (_case: MOVING), so that they
#: slide, roll and collide across the ranks' cut
DISSIPATION = {"heat_generation": {"model": "mechanical_dissipation", "partition": "conductivity"}}
COLLISION = {"heat_generation": {"model": "al_arkawazi2017"}}

#: name -> (thermal section, thermal section of the run that wrote the checkpoint at step 70
#: or "fresh" for a run from t = 0, time step after the restart)
CONFIGURATIONS: dict[str, tuple[dict[str, Any], Any, float]] = {
    "substeps_1": ({"substeps": 1}, "fresh", DT),
    "substeps_3": ({"substeps": 3}, "fresh", DT),
    "substeps_auto": ({"substeps": "auto"}, "fresh", DT),
    "range_fixed_flux_source": ({**RANGE, "substeps": 2, **CONDITIONS}, "fresh", DT),
    # restarts whose first thermal step is not fused with a contact pass
    "substeps_3_restart_half_time_step": ({"substeps": 3}, {"substeps": 3}, DT / 2),
    "substeps_auto_restart_half_time_step": ({"substeps": "auto"}, {"substeps": "auto"}, DT / 2),
    "range_heat_starts_at_restart": (
        {**RANGE, "direct_conduction": "none", "substeps": 2}, None, DT),
    # per-particle terms and external sources
    "convection_radiation_walls": (CONVECTION, "fresh", DT),
    "gunn_expression_global_porosity": ({**GUNN, "substeps": 2}, "fresh", DT),
    "whitaker_grid_table": (GRID, "fresh", DT),
    "external_source": (EXTERNAL, "fresh", DT),
    "convection_restart_half_time_step": (
        {**CONVECTION, "substeps": 3}, {**CONVECTION, "substeps": 3}, DT / 2),
    # heat generation: each rank keeps its own particles' deposits of the pairs across the cut
    "generation_dissipation": ({**DISSIPATION, "substeps": 2}, "fresh", DT),
    "generation_collision": ({**COLLISION, "substeps": 3}, "fresh", DT),
    "generation_restart_half_time_step": (DISSIPATION, DISSIPATION, DT / 2),
}  # fmt: skip
#: configurations whose 2-rank run also writes a checkpoint at step 70, continued serially
CONTINUED_SERIALLY = ("gunn_expression_global_porosity", "whitaker_grid_table",
                      "generation_dissipation", "generation_collision")  # fmt: skip

SCRIPT = """
import json, sys, warnings
import numpy as np
from thermodem.config.load import case_from_dict
from thermodem.io.checkpoint import write_checkpoint
from thermodem.mpi import make_simulation
from thermodem.mpi.gather import gathered_view
from thermodem.mpi.simulation import DistributedSimulation

for job in json.load(open(sys.argv[1])):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        case = case_from_dict(job["case"])
        if job["checkpoint"]:
            sim = DistributedSimulation.from_checkpoint(job["checkpoint"], case=case)
        else:
            sim = make_simulation(case)
        if job["write"]:  # a checkpoint of this run at step 70 (rank 0 writes it)
            sim.run(steps=70)
            state = sim.state_dict()
            if sim.rank == 0:
                write_checkpoint(sim, job["write"], state=state)
            sim.run(steps=job["steps"] - 70)
        else:
            sim.run(steps=job["steps"])
        report = sim.report()
    said = [str(w.message) for w in caught]
    warned = list(sim.thermal.field_provider.warned) if sim.thermal else []
    with open(f"{job['out']}.rank{sim.rank}.json", "w") as f:
        json.dump({"said": said, "warned": warned}, f)
    view = gathered_view(sim)
    if view is not None:
        p = view.particles
        order = np.argsort(p.global_id)
        np.savez(job["out"], temperature=p.temperature[order], report=json.dumps(report))
"""


def _jobs(tmp: Path) -> list[dict[str, Any]]:
    """The cases, checkpoints (written serially at step 70) and step counts of every
    configuration."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.io.checkpoint import write_checkpoint

    grid = tmp / "fluid.npz"  # T from 350 K at z = 0 to 550 K at the domain's top
    np.savez(
        grid,
        x=np.linspace(0, W, 4),
        y=np.linspace(0, W, 4),
        z=np.linspace(0, 2 * H, 7),
        T=350.0 + 200.0 * np.linspace(0, 1, 7)[None, None, :] * np.ones((4, 4, 1)),
    )
    jobs = []
    for name, (thermal, before, dt) in CONFIGURATIONS.items():
        checkpoint = None
        steps = 140
        if before != "fresh":
            first = Simulation(case_from_dict(_case(before)), threads=1)
            first.run(steps=70)
            checkpoint = str(write_checkpoint(first, tmp / f"{name}.h5"))
            steps = int(round(70 * DT / dt)) + 100
        case = json.loads(
            json.dumps(_case(thermal, steps=steps, time_step=dt)).replace(
                '"GRID"', json.dumps(str(grid))
            )
        )
        write = str(tmp / f"{name}_2_ranks.h5") if name in CONTINUED_SERIALLY else None
        jobs.append({"name": name, "case": case, "checkpoint": checkpoint,
                     "steps": 100 if checkpoint else steps, "write": write,
                     "out": str(tmp / f"{name}.npz")})  # fmt: skip
    return jobs


def _case(thermal: dict[str, Any] | None, **kw: Any) -> dict[str, Any]:
    case = column_case(thermal, **kw)
    if thermal is not None and "radiation" in thermal:
        case["materials"]["glass"]["emissivity"] = 0.9
    if thermal is not None and "heat_generation" in thermal:
        case["insertion"] = [MOVING]
    return case


def _moving() -> dict[str, Any]:
    """The column's lattice (the same order: layer by layer from the floor), each sphere with
    a velocity of ~0.2 m/s, mostly sideways: neighbours slide and roll on each other (across
    the ranks' cut between layers 3 and 4 too), hit each other and the walls."""
    k = np.arange(54)
    x, y, z = (1e-3 + 2e-3 * a for a in (k % 3, (k // 3) % 3, k // 9))
    velocity = 0.2 * np.stack([np.sin(2.3 * k), np.cos(1.3 * k), 0.5 * np.sin(0.7 * k)], 1)
    return {
        "kind": "list",
        "material": "glass",
        "radius": 1e-3,
        "overlap_check": False,
        "positions": np.stack([x, y, z], 1).tolist(),
        "velocities": velocity.tolist(),
    }


MOVING = _moving()


def _serial(job: dict[str, Any]) -> dict[str, Any]:
    """The serial run of ``job``: its final temperatures (by global id), report, warnings
    said and quantities warned; with ``continued``, the 2-rank run's checkpoint at step 70
    continued serially (its temperatures and quantities warned)."""
    import warnings

    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    case = case_from_dict(job["case"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        if job["checkpoint"]:
            sim = Simulation.from_checkpoint(job["checkpoint"], threads=1, case=case)
        else:
            sim = Simulation(case, threads=1)
        sim.run(steps=job["steps"])
    p = sim.particles
    out = {"temperature": p.temperature[np.argsort(p.global_id)], "report": sim.report(),
           "said": [str(w.message) for w in caught],
           "warned": list(sim.thermal.field_provider.warned)}  # fmt: skip
    if job["write"]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", RuntimeWarning)
            again = Simulation.from_checkpoint(job["write"], threads=1, case=case)
            assert list(again.thermal.field_provider.warned) == out["warned"]
            again.run(steps=job["steps"] - 70)
        q = again.particles
        out["continued"] = q.temperature[np.argsort(q.global_id)]
        out["continued_said"] = [str(w.message) for w in caught]
    return out


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Every configuration serially (in this process) and on 2 ranks (one launch)."""
    tmp = tmp_path_factory.mktemp("thermal_paths")
    jobs = _jobs(tmp)
    (tmp / "jobs.json").write_text(json.dumps(jobs))
    (tmp / "run.py").write_text(SCRIPT)
    cmd = ["timeout", "600", str(MPIEXEC), "-n", "2", str(BIN / "python"), str(tmp / "run.py"),
           str(tmp / "jobs.json")]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, env=_env(2), timeout=900)
    assert res.returncode == 0, res.stderr[-4000:]
    return {job["name"]: (job, _serial(job)) for job in jobs}


def _heat_columns(report: dict[str, float]) -> list[str]:
    return [k for k in report if k.startswith(("heat_", "temperature_", "fixed_", "thermal_",
                                                "inserted_heat", "range_pair"))]  # fmt: skip


def _agreed(said: list[str]) -> list[str]:
    """The warnings every rank agrees on (said once by rank 0): the convection's validity
    ranges and the fluid grid's outside count."""
    return [w for w in said if w.startswith(("thermal.convection", "thermal.fluid."))]


@needs_mpi
@pytest.mark.parametrize("name", list(CONFIGURATIONS))
def test_heat_on_2_ranks_matches_serial(runs: dict[str, Any], name: str) -> None:
    job, serial = runs[name]
    temperature, report = serial["temperature"], serial["report"]
    got = np.load(job["out"])
    parallel = json.loads(str(got["report"]))
    start = 300.0 + 5000.0 * np.linspace(1e-3, H - 1e-3, 6)  # (the layers at t = 0)
    assert np.abs(temperature - np.repeat(start, 9)).max() > 1.0, "the heat changed nothing"
    rel = np.abs(got["temperature"] / temperature - 1.0).max()
    assert rel <= 1e-12, f"temperatures differ by {rel:.3g} relative"
    columns = _heat_columns(report)
    assert columns == _heat_columns(parallel)
    for key in columns:
        scale = abs(report["thermal_energy"] if key == "heat_balance_error" else report[key])
        diff = abs(parallel[key] - report[key])
        assert diff <= 1e-9 * scale or diff == 0.0, f"{key}: {parallel[key]!r} / {report[key]!r}"
    assert abs(parallel["heat_balance_error"]) <= 1e-12 * parallel["thermal_energy"]
    if name.startswith("generation"):
        _check_generation(name, report, parallel)
    # validity-range warnings: said once (rank 0), the same quantities warned on every rank
    ranks = [json.loads(Path(f"{job['out']}.rank{r}.json").read_text()) for r in (0, 1)]
    assert len(_agreed(ranks[0]["said"])) == len(_agreed(serial["said"]))
    assert _agreed(ranks[1]["said"]) == []
    assert ranks[0]["warned"] == ranks[1]["warned"] == serial["warned"]
    if name in ("convection_radiation_walls", "whitaker_grid_table"):
        assert len(_agreed(serial["said"])) == 1, serial["said"]  # (Re, resp. Pr, at step 0)
    if job["write"]:  # the 2-rank checkpoint at step 70 continued serially
        rel = np.abs(serial["continued"] / temperature - 1.0).max()
        assert rel <= 1e-12, f"continued serially: temperatures differ by {rel:.3g} relative"
        assert _agreed(serial["continued_said"]) == []  # (warned before the checkpoint)


def _check_generation(name: str, report: dict[str, float], parallel: dict[str, float]) -> None:
    """The heat generation ledger of the 2-rank run against the serial run's (the heat
    columns are compared with the other heat columns): what the mechanics dissipated and its
    heat, the collision energy lost, the balances."""
    keys = [k for k in report if k.startswith(("generated_", "dissipated_"))
            or k in ("collision_energy_loss", "stiffness_work", "wall_work")]  # fmt: skip
    assert keys == [k for k in parallel if k in keys]
    generated = sum(report[k] for k in report if k.startswith("generated_"))
    into = sum(report[k] for k in report if k.startswith("heat_in_generation_"))
    assert into > 1e-6, f"{name}: no heat generated ({into:.3g} J)"
    if name == "generation_dissipation":  # (every mechanism but the plastic one)
        for g in ("sliding_friction", "rolling_friction", "normal_damping", "tangential_damping"):
            assert report[f"heat_in_generation_{g}"] > 1e-8 * into, g
    for key in keys:
        diff = abs(parallel[key] - report[key])
        assert diff <= 1e-9 * abs(report[key]) or diff == 0.0, f"{key}: {parallel[key]!r}"
    for rep in (report, parallel):
        assert abs(rep["generation_balance_error"]) <= 1e-12 * generated
    # the mechanical balance (its first-order error: the same on 2 ranks as serially)
    scale = sum(report[k] for k in report if k.startswith("dissipated_"))
    diff = abs(parallel["energy_balance_error"] - report["energy_balance_error"])
    assert diff <= 1e-9 * scale, (parallel["energy_balance_error"], report["energy_balance_error"])


@needs_mpi
def test_build_warnings_said_once_by_mpiexec(tmp_path: Path) -> None:
    """``mpiexec -n 2 thermodem run``: the convection's validity-range warning of the first
    evaluation (while the ranks build the simulation) is said once, on stdout and in
    run.log as in a serial run; before, every rank that met it printed it to stderr, and
    never to run.log."""
    case = _case(CONVECTION, steps=20)
    path = _write_case(tmp_path / "c.yaml", case)
    res = _run(["run", str(path), "-o", str(tmp_path / "o"), "--no-progress"], 2, timeout=180)
    assert res.returncode == 0, res.stderr
    assert res.stdout.count("Re = 0.255") == 1, res.stdout
    assert "Re = " not in res.stderr, res.stderr
    assert (tmp_path / "o" / "run.log").read_text().count("Re = 0.255") == 1
