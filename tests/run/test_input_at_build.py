"""Inputs whose fault shows only once the case is built, through the command line
(run_cases.cli) as a user runs it: a failure met while the simulation is built (before step 0)
is an input error (exit 2, the key named), not a failed run (exit 1), and so is a restart whose
(changed) case the restored particles' lists cannot be built with; a heat generation mechanism
that the material values switch off for every pair that can meet is warned about."""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import yaml
from run_cases import base_case, cli

from thermodem.io.checkpoint import read_checkpoint

CASE = base_case()


def _write(tmp_path: Path, name: str = "case", **sections) -> Path:  # noqa: ANN003
    data = json.loads(json.dumps(CASE))
    data.update(sections)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _glass(**changes: float) -> dict:
    return {"glass": {**CASE["materials"]["glass"], **changes}}


def test_a_failure_while_the_case_is_built_is_an_input_error(tmp_path: Path) -> None:
    """A periodic axis shorter than two neighbour cells of the inserted particles raised a
    SimulationError while the simulation was built: validate and run exited 1 (a failed
    simulation), run left no status.json and nothing in run.log, and the message named no
    key. Now exit 2 naming domain.periodic, recorded as a refused input; a failure met while
    the run steps (particles given overlapping, overlap_check: false) still exits 1."""
    lattice = {**CASE["insertion"][0], "upper": [0.0025, 0.006, 0.006], "count": [1, 2, 2]}
    domain = {"lower": [0, 0, 0], "upper": [0.0025, 0.01, 0.01], "periodic": [True, False, False]}
    case = _write(tmp_path, domain=domain, insertion=[lattice])
    message = (
        "error: domain.periodic: axis x is periodic, but the domain is 0.0025 m long along it "
        "(domain.upper - domain.lower), shorter than twice the neighbour cell 0.0022 m (2 R_max "
        "0.002 m + neighbors.skin 0.0002 m); the minimum image needs >= 0.0044 m: a longer "
        "periodic axis, smaller particles or a smaller neighbors.skin (met while the case was "
        "built, before any step)"
    )
    res = cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert message in res.stderr
    out = tmp_path / "out"
    for _ in range(2):  # (the refusal's record counts as empty: the same error again)
        res = cli("run", case, "--output", out, "--no-progress")
        assert res.returncode == 2, res.stdout + res.stderr
        assert message in res.stderr
    status = json.loads((out / "status.json").read_text())
    assert status["status"] == "failed" and status["refused_input"] is True
    assert message in (out / "run.log").read_text()
    assert not (out / "checkpoints").exists() or not any((out / "checkpoints").iterdir())
    # a failure of the run itself: exit 1 as before
    given = {"kind": "list", "material": "glass", "radius": 0.001, "overlap_check": False,
             "positions": [[0.005, 0.005, 0.005], [0.0055, 0.005, 0.005]]}  # fmt: skip
    case = _write(tmp_path, "overlapping", insertion=[given])
    assert cli("validate", case).returncode == 0
    res = cli("run", case, "--output", tmp_path / "o2", "--no-progress")
    assert res.returncode == 1, res.stdout + res.stderr
    assert "error: overlap of 1.41 × the smaller radius (particle 0 and particle 1) at step 1" in (
        res.stderr
    )


def test_a_tessellation_the_start_cannot_make_is_an_input_error(tmp_path: Path) -> None:
    """A Voronoi case with a plane wall across the bed: the tessellation made while the
    simulation is built failed with exit 1; it is an input error naming thermal.tessellation,
    the wall as the case does (walls.K and its name; before: 'plane wall 5', a wall row) and
    the particle by its global id (before: its array index, 2 here, after the cell sort)."""
    data = yaml.safe_load((Path(__file__).parents[2] / "examples" / "voronoi_bed.yaml").read_text())
    data["simulation"]["end_time"] = 1.0e-4
    data["walls"].append({"kind": "plane", "point": [0, 0, 0.004], "normal": [0, 0, -1],
                          "material": "steel", "name": "lid"})  # fmt: skip
    case = tmp_path / "voronoi.yaml"
    case.write_text(yaml.safe_dump(data))
    res = cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "error: thermal.tessellation (plain): particle 50 (centre [0.0018999999" in res.stderr
    assert (
        "0.0051] m) is not on the particles' side of the plane walls.1 (lid): its cell cannot "
        "be clipped by it (step 0, t = 0 s, 125 particles) (met while the case was built, before "
        "any step)"
    ) in res.stderr
    del data["walls"][1]["name"]  # (without a name: its kind and index, as the other messages)
    case.write_text(yaml.safe_dump(data))
    res = cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "is not on the particles' side of the plane walls.1 (plane1): its cell" in res.stderr


#: a periodic x axis 0.006 m long (twice the neighbour cell, 2.2 mm, is 4.4 mm), four spheres
#: of 1 mm; 20 steps, checkpoints at steps 10 and 20
PERIODIC = {
    **CASE,
    "simulation": {"time_step": 1.0e-5, "end_time": 2.0e-4},
    "domain": {"lower": [0, 0, 0], "upper": [0.006, 0.01, 0.01], "periodic": [True, False, False]},
    "insertion": [{**CASE["insertion"][0], "upper": [0.0025, 0.006, 0.006], "count": [1, 2, 2]}],
    "output": {"vtu": False, "checkpoint_interval": 1.0e-4, "checkpoint_keep": None},
}


def _periodic(tmp_path: Path, name: str, upper_x: float = 0.006, **neighbors: float) -> Path:
    data = json.loads(json.dumps(PERIODIC))
    data["simulation"]["end_time"] = 4.0e-4
    data["domain"]["upper"][0] = upper_x
    if neighbors:
        data["neighbors"] = neighbors
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _files(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


def test_a_restart_whose_lists_cannot_be_built_is_refused_before_any_step(tmp_path: Path) -> None:
    """run CASE --restart CKPT with a changed case whose periodic axis is shorter than two
    neighbour cells of the restored particles (a shorter domain; a larger neighbors.skin) ran
    on until the first rebuild and failed there (exit 1, a half-written run). Now refused while
    the restart is set up: exit 2, the key named, nothing written. The skin of the changed case
    is the one run (before, the checkpoint's was kept, silently) and the lists are built with
    it at the first step. ``thermodem restart DIR`` of a directory whose newest checkpoint
    stores such a case (continued before this check) is refused, the directory unchanged."""
    base = tmp_path / "base.yaml"
    base.write_text(yaml.safe_dump(PERIODIC))
    res = cli("run", base, "--output", tmp_path / "out", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    ckpt = tmp_path / "out" / "checkpoints" / "checkpoint_000000020.h5"
    set_up = f"(met while the restart from {ckpt} was set up, before any step; nothing was changed)"
    short = _periodic(tmp_path, "short", upper_x=0.004)
    res = cli("run", short, "--restart", ckpt, "--output", tmp_path / "new", "--no-progress")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: domain.periodic: axis x is periodic, but the domain is 0.004 m long along it "
        "(domain.upper - domain.lower), shorter than twice the neighbour cell 0.0022 m (2 R_max "
        "0.002 m + neighbors.skin 0.0002 m); the minimum image needs >= 0.0044 m: a longer "
        f"periodic axis, smaller particles or a smaller neighbors.skin {set_up}"
    ) in res.stderr
    assert not (tmp_path / "new").exists()
    wide = _periodic(tmp_path, "wide", skin=0.002)
    res = cli("run", wide, "--restart", ckpt, "--output", tmp_path / "new", "--no-progress")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: domain.periodic: axis x is periodic, but the domain is 0.006 m long along it "
        "(domain.upper - domain.lower), shorter than twice the neighbour cell 0.004 m (2 R_max "
        "0.002 m + neighbors.skin 0.002 m); the minimum image needs >= 0.008 m"
    ) in res.stderr
    assert set_up in res.stderr
    assert not (tmp_path / "new").exists()
    # a skin that fits: run, and the lists built with it at the first step
    fits = _periodic(tmp_path, "fits", skin=0.0003)
    res = cli("run", fits, "--restart", ckpt, "--output", tmp_path / "new", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    assert "changed from the checkpoint's case: neighbors.skin (none) -> 0.0003" in res.stdout
    assert read_checkpoint(ckpt).state["scalars"]["skin"] == 0.0002  # (the default 0.2 R)
    last = read_checkpoint(tmp_path / "new" / "checkpoints" / "checkpoint_000000040.h5")
    assert last.state["scalars"]["skin"] == 0.0003
    assert (
        last.state["scalars"]["rebuild_count"]
        == read_checkpoint(ckpt).state["scalars"]["rebuild_count"] + 1
    )
    # restart DIR: the newest checkpoint (and case.resolved.yaml) with the short domain
    out = tmp_path / "out"
    stored = yaml.safe_load(read_checkpoint(ckpt).case_yaml)
    stored["domain"]["upper"][0] = 0.004
    text = yaml.safe_dump(stored)
    with h5py.File(ckpt, "a") as f:
        del f["case_yaml"]
        f.create_dataset("case_yaml", data=text, dtype=h5py.string_dtype("utf-8"))
    (out / "case.resolved.yaml").write_text(text)
    before = _files(out)
    res = cli("restart", out, "--end-time", "0.0004", "--no-progress")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: domain.periodic: axis x is periodic, but the domain is 0.004 m long along it "
    ) in res.stderr
    assert set_up in res.stderr
    assert _files(out) == before
    assert json.loads((out / "status.json").read_text())["status"] == "finished"


def test_a_generation_mechanism_the_material_values_switch_off_is_told(tmp_path: Path) -> None:
    """rojek2014 with sliding_friction 0, richard2008 with restitution 1 (no damping), a listed
    rolling_friction with the default rolling friction 0 gave zero heat without a word; told
    once before the run (validate, run and run.log), only when every pair that can meet gives
    zero."""
    glass = _glass(sliding_friction=0.0)
    case = _write(tmp_path, materials=glass, thermal={"heat_generation": "rojek2014"})
    told = (
        "warning: thermal.heat_generation = 'rojek2014': 'sliding_friction' gives zero heat with "
        "these material values: every pair of materials that can meet has sliding friction 0 "
        "(the Coulomb cap μ F_n holds no tangential force): materials.glass.sliding_friction = "
        "0; remove it, or give values that dissipate that way"
    )
    res = cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert res.stderr.count(told) == 1, res.stderr
    out = tmp_path / "out"
    res = cli("run", case, "--output", out, "--steps", "2", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    assert (res.stdout + res.stderr).count(told) == 1
    assert (out / "run.log").read_text().count(told[len("warning: ") :]) == 1
    # a steel wall with friction: the glass-steel pair dissipates, nothing to tell
    steel = {**CASE["materials"]["glass"], "density": 7800, "sliding_friction": 0.4}
    wall = {**CASE["walls"][0], "material": "steel"}
    case = _write(tmp_path, "steel", materials={**glass, "steel": steel}, walls=[wall],
                  thermal={"heat_generation": "rojek2014"})  # fmt: skip
    res = cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "gives zero heat" not in res.stderr
    # ... unless an interactions entry sets that pair's friction to 0
    override = [{"materials": ["glass", "steel"], "sliding_friction": 0.0}]
    case = _write(tmp_path, "override", materials={**glass, "steel": steel}, walls=[wall],
                  interactions=override, thermal={"heat_generation": "rojek2014"})  # fmt: skip
    res = cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "sliding friction 0 (the Coulomb cap μ F_n holds no tangential force): "
        "materials.glass.sliding_friction = 0, interactions.0.sliding_friction = 0; remove it"
    ) in res.stderr
    # restitution 1: no normal damping; a listed rolling friction with the default 0
    listed = ["normal_damping", "rolling_friction", "sliding_friction"]
    generation = {"model": "mechanical_dissipation", "mechanisms": listed}
    case = _write(tmp_path, "elastic", materials=_glass(restitution=1.0),
                  contact={"rolling": "epsd"}, thermal={"heat_generation": generation})  # fmt: skip
    res = cli("validate", case)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: thermal.heat_generation.mechanisms: 'normal_damping' gives zero heat with "
        "these material values: every pair of materials that can meet has restitution 1 "
        "(perfectly elastic: no damping, no plastic work): materials.glass.restitution = 1;"
    ) in res.stderr
    assert (
        "'rolling_friction' gives zero heat with these material values: every pair of "
        "materials that can meet has rolling friction 0 (no rolling torque): "
        "materials.glass.rolling_friction = 0 (the default);"
    ) in res.stderr
    assert "'sliding_friction' gives zero" not in res.stderr  # (the default 0.5)
    case = _write(tmp_path, "richard", materials=_glass(restitution=1.0),
                  thermal={"heat_generation": "richard2008"})  # fmt: skip
    res = cli("validate", case)
    assert "thermal.heat_generation = 'richard2008': 'normal_damping' gives zero heat" in (
        res.stderr
    )


def test_the_default_mechanisms_are_told_only_when_none_gives_heat() -> None:
    """mechanical_dissipation's default list (all five): one mechanism switched off is not
    told (the others heat); all of them off is."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.case_warnings import generation_mechanism_warnings

    def told(**glass: float) -> list[str]:
        data = json.loads(json.dumps(CASE))
        data["materials"] = _glass(**glass)
        data["thermal"] = {"heat_generation": "mechanical_dissipation"}
        return generation_mechanism_warnings(case_from_dict(data))

    assert told(sliding_friction=0.0) == []
    (text,) = told(sliding_friction=0.0, restitution=1.0)
    assert text.startswith(
        "thermal.heat_generation = 'mechanical_dissipation' gives zero heat: none of its "
        "mechanisms (the default, all five) dissipates"
    )
    assert "'rolling_friction': contact.rolling is 'none'" in text


def test_a_restart_whose_range_set_cannot_be_built_is_refused(tmp_path: Path) -> None:
    """The thermal range pair set (a model that conducts across gaps) checks the periodic axes
    against its own cells when it is built; for particles of a list (no radius bound known
    before they are inserted) a restart met it at the set's first rebuild, in the run. Now
    while the restart is set up, as the contact lists' check above."""
    spheres = {
        "kind": "list",
        "material": "glass",
        "radius": 0.001,
        "positions": [[0.00125, y, z] for y in (0.002, 0.005) for z in (0.001, 0.004)],
    }
    data = {**json.loads(json.dumps(PERIODIC)), "insertion": [spheres],
            "thermal": {"indirect_conduction": "batchelor_obrien_separated"}}  # fmt: skip
    base = tmp_path / "base.yaml"
    base.write_text(yaml.safe_dump(data))
    res = cli("run", base, "--output", tmp_path / "out", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    ckpt = tmp_path / "out" / "checkpoints" / "checkpoint_000000020.h5"
    data["simulation"]["end_time"] = 4.0e-4
    data["domain"]["upper"][0] = 0.005  # (the contact lists need 0.0044 m, the range set 0.0054)
    short = tmp_path / "short.yaml"
    short.write_text(yaml.safe_dump(data))
    res = cli("run", short, "--restart", ckpt, "--output", tmp_path / "new", "--no-progress")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: thermal.indirect_conduction.cutoff_gap_ratio = 1.0: periodic axis x of length "
        "0.005 m is shorter than two cells of the range pair set (2 R_max 0.002 m + largest "
        "conducting gap 0.0005 m + thermal.range_skin 0.0002 m each); allowed: cutoff_gap_ratio "
        f"below 0.6 (or a larger domain) (met while the restart from {ckpt} was set up, before "
        "any step; nothing was changed)"
    ) in res.stderr
    assert not (tmp_path / "new").exists()
