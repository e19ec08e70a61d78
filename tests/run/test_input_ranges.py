"""Inputs of a demanding user (third round): thermal parameters out of their physical range,
property and time tables, restarts with a changed case, output settings that contradict each
other. Each through the command line (run_cases.cli), as a user runs it."""

from __future__ import annotations

import json
from pathlib import Path

import yaml
from run_cases import cli

CASE = {
    "simulation": {"time_step": 1.0e-5, "end_time": 1.0e-4},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {
        "glass": {
            "density": 2500,
            "youngs_modulus": 1.0e7,
            "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0,
            "specific_heat": 800,
        }
    },
    "walls": [
        {
            "kind": "plane",
            "point": [0, 0, 0],
            "normal": [0, 0, 1],
            "material": "glass",
            "thermal": {"kind": "fixed", "temperature": 350.0},
        }
    ],
    "insertion": [
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.0008},
            "lower": [0, 0, 0],
            "upper": [0.004, 0.004, 0.004],
            "spacing": 0.002,
        }
    ],
    "thermal": {},
}


def _case(tmp_path: Path, name: str = "case", **sections) -> Path:  # noqa: ANN003
    data = json.loads(json.dumps(CASE))
    for key, value in sections.items():
        data[key] = value
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _glass(**changes) -> dict:  # noqa: ANN003
    glass = {**CASE["materials"]["glass"], **changes}
    return {"glass": {k: v for k, v in glass.items() if v != "-"}}


def test_an_explicit_null_constant_beside_a_table_is_the_table_alone(tmp_path: Path) -> None:
    """``thermal_conductivity: null`` next to ``thermal_conductivity_table`` (a user who keeps
    every key and empties the one not used) ended in a TypeError traceback."""
    table = [[300.0, 1.0], [400.0, 2.0]]
    for name in ("thermal_conductivity", "specific_heat"):
        glass = _glass(**{name: None, f"{name}_table": table})
        res = cli("validate", _case(tmp_path, materials=glass))
        assert res.returncode == 0, res.stdout + res.stderr
        assert f"{name}_table:" in res.stdout
    # a value beside the table is still refused
    glass = _glass(thermal_conductivity=1.0, thermal_conductivity_table=table)
    res = cli("validate", _case(tmp_path, materials=glass))
    assert res.returncode == 2
    assert "thermal_conductivity: 1 W/(m K) is given together with" in res.stderr


def test_frame_settings_with_vtu_false_are_refused(tmp_path: Path) -> None:
    """``vtu: false`` with ``contacts: true`` ran and wrote no contact (nor any frame) without
    a word; the frame interval and wall extent were ignored the same way."""
    output = {"vtu": False, "contacts": True, "interval": 2.0e-5}
    case = _case(tmp_path, output=output)
    res = cli("run", case, "--output", tmp_path / "out", "--no-progress")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "output.vtu: false writes no VTU frame, so contacts: true, interval: 2e-05 would be "
        "ignored (settings of the frames); allowed: vtu: true to write the frames, or leave "
        "contacts and interval out"
    ) in res.stderr
    assert not (tmp_path / "out" / "timeseries.csv").exists()
    # vtu: false alone, and frames with contacts, are fine
    assert cli("validate", _case(tmp_path, output={"vtu": False})).returncode == 0
    both = {"vtu": True, "contacts": True}
    assert cli("validate", _case(tmp_path, output=both)).returncode == 0


def test_lengths_in_another_unit_are_refused_before_the_run(tmp_path: Path) -> None:
    """A roughness of 10 mm on 0.8 mm beads (the resistance network) and a minimum conduction
    distance of 2.75 m (Rong & Horio, S meant as 2.75e-8 m) ran without a word."""
    surface = {"microhardness": 1.0e9, "surface_slope": 0.1, "thermal_accommodation": 0.9}
    glass = _glass(surface_roughness=0.01, **surface)
    thermal = {"direct_conduction": "resistance_network"}
    res = cli("run", _case(tmp_path, materials=glass, thermal=thermal), "--output",
               tmp_path / "a", "--no-progress")  # fmt: skip
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: materials.glass.surface_roughness = 0.01 m is not below the radius of the "
        "smallest particle it touches, 0.0008 m"
    ) in res.stderr
    assert not (tmp_path / "a" / "timeseries.csv").exists()
    # the pair's equivalent roughness of an interactions entry, a poured smaller particle
    region = {"kind": "box", "lower": [0, 0, 0.006], "upper": [0.01, 0.01, 0.01]}
    pour = {"kind": "pour", "material": "glass", "distribution": {"kind": "mono",
            "radius": 0.0002}, "rate": 1.0e5, "interval": 1.0e-5, "region": region}  # fmt: skip
    insertion = [CASE["insertion"][0], pour]
    pair = [{"materials": ["glass", "glass"], "surface_roughness": 0.0005}]
    case = _case(tmp_path, materials=_glass(surface_roughness=1e-7, **surface),
                 thermal=thermal, interactions=pair, insertion=insertion)  # fmt: skip
    res = cli("validate", case)
    assert res.returncode == 2, res.stdout + res.stderr
    assert "interactions.0.surface_roughness = 0.0005 m is not below the radius" in res.stderr
    assert "0.0002 m" in res.stderr
    # S of a surrounding layer model
    thermal = {"indirect_conduction": {"model": "musser2011", "min_separation": 2.75}}
    res = cli("validate", _case(tmp_path, thermal=thermal))
    assert res.returncode == 2
    assert (
        "thermal.indirect_conduction.min_separation = 2.75 m is not below the fluid layer of "
        "the smallest particles, layer_thickness_ratio 0.4 × radius 0.0008 m (glass) = "
        "0.00032 m"
    ) in res.stderr
    # values in range run
    thermal = {"indirect_conduction": {"model": "musser2011", "min_separation": 1e-7}}
    assert cli("validate", _case(tmp_path, thermal=thermal)).returncode == 0


def test_tables_in_another_unit_are_warned_about(tmp_path: Path) -> None:
    """A k(T) table in °C ([[20, 1.0], [100, 1.2]]: the particles at 293 K read its last row)
    and a wall temperature table whose first change comes after the end (times in ms) ran
    without a word."""
    glass = _glass(thermal_conductivity="-", thermal_conductivity_table=[[20, 1.0], [100, 1.2]])
    wall = {**CASE["walls"][0], "thermal": {"kind": "fixed", "temperature": [[0, 350], [2, 400]]}}
    case = _case(tmp_path, materials=glass, walls=[wall])
    res = cli("run", case, "--output", tmp_path / "out", "--no-progress")
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: materials.glass.thermal_conductivity_table (row 0, its lowest temperature): "
        "20 K is below 200 K"
    ) in res.stdout + res.stderr
    assert (
        "warning: walls.0.thermal.temperature: the table's first change is at t = 2 s (row 1), "
        "after simulation.end_time = 0.0001 s: the value of row 0, 350 K, holds for the whole "
        "run; table times are simulated seconds"
    ) in res.stdout + res.stderr
    # a table that changes within the run, in kelvin: nothing said
    glass = _glass(thermal_conductivity="-", thermal_conductivity_table=[[293, 1.0], [400, 2]])
    wall["thermal"]["temperature"] = [[0, 350], [5.0e-5, 400]]
    res = cli("validate", _case(tmp_path, materials=glass, walls=[wall]))
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: materials" not in res.stdout + res.stderr
        and "first change" not in res.stdout + res.stderr
    )


def test_a_restart_with_other_particles_of_t0_is_refused(tmp_path: Path) -> None:
    """run CASE --restart CKPT with a larger lattice in CASE ran on with the checkpoint's 8
    particles, not the 27 the case describes, without a word; a changed material value still
    restarts (a case may change its properties)."""
    first = _case(tmp_path, "first")
    out = tmp_path / "first_out"
    assert cli("run", first, "--output", out, "--no-progress").returncode == 0
    ckpt = sorted((out / "checkpoints").glob("*.h5"))[-1]
    lattice = {**CASE["insertion"][0], "upper": [0.006, 0.006, 0.006]}
    larger = _case(tmp_path, "larger", insertion=[lattice])
    again = tmp_path / "again"
    res = cli("run", larger, "--restart", ckpt, "--output", again, "--end-time", "2e-4")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: insertion.0.upper.0 differs from the case stored in the checkpoint "
        f"{ckpt}: the particles of t = 0 (lattice, random, list, file entries) are not "
        "inserted again on a restart, so the run would continue the checkpoint's 8 particles"
    ) in res.stderr
    assert not again.exists()
    denser = _case(tmp_path, "denser", materials=_glass(density=3000))
    res = cli("run", denser, "--restart", ckpt, "--output", again, "--end-time", "2e-4",
               "--no-progress")  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr


def test_etc_of_a_packing_that_touches_nowhere_names_the_packing(tmp_path: Path) -> None:
    """thermodem etc of a lattice whose spacing is the diameter (no contact at t = 0) said
    'steady state: ... exchange heat with no fixed temperature (a thermal.walls kind fixed,
    thermal.fixed_temperature, ...)': advice etc itself refuses; --axes zz measured z twice."""
    lattice = {**CASE["insertion"][0], "upper": [0.01, 0.01, 0.01], "spacing": 0.0016}
    case = _case(tmp_path, walls=[], insertion=[lattice])
    res = cli("etc", case, "--axes", "z")
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "error: effective conductivity along z: 108 particles in 9 clusters are linked to "
        "neither boundary layer of 0.0016 m by conducting pairs, so the packing does not "
        "conduct from one layer to the other"
    ) in res.stderr
    assert "thermal.walls kind fixed" not in res.stderr
    res = cli("etc", case, "--axes", "zz")
    assert res.returncode == 2
    assert "axes = 'zz'; allowed: letters of 'xyz', each once" in res.stderr


def test_export_and_plot_of_a_run_that_never_started_say_why(tmp_path: Path) -> None:
    """export and plot of the record a refused run leaves said 'no checkpoints ...; give
    --frame N or --checkpoint PATH' and 'is it a thermodem output?' (it is: its status.json
    holds the refusal)."""
    glass = _glass(surface_roughness=0.01, microhardness=1.0e9, surface_slope=0.1,
                   thermal_accommodation=0.9)  # fmt: skip
    case = _case(tmp_path, "rough", materials=glass,
                 thermal={"direct_conduction": "resistance_network"})  # fmt: skip
    out = tmp_path / "out"
    assert cli("run", case, "--output", out, "--no-progress").returncode == 2
    for command in ("export", "plot"):
        res = cli(command, out)
        assert res.returncode == 2, res.stdout + res.stderr
        assert (
            f"the run in '{out}' never started (status.json: its input was refused: "
            "materials.glass.surface_roughness = 0.01 m" in res.stderr
        )
        assert (
            f"after fixing the case (rough) run it again: thermodem run CASE --output {out}"
            in res.stderr
        )
    assert "give --frame N" in cli("export", tmp_path).stderr  # (not a run record)


def test_a_heat_capacity_ratio_no_gas_has_is_refused(tmp_path: Path) -> None:
    """thermal.gas.heat_capacity_ratio: 40 ran (the Smoluchowski parameter read 2γ/(1 + γ));
    5/3 written as 1.67 still runs."""
    glass = _glass(thermal_accommodation=0.9)
    for gamma, status in ((40, 2), (1.67, 0)):
        thermal = {"indirect_conduction": "vargas_mccarthy2002",
                   "gas": {"heat_capacity_ratio": gamma}}  # fmt: skip
        res = cli("validate", _case(tmp_path, materials=glass, thermal=thermal))
        assert res.returncode == status, res.stdout + res.stderr
    assert ("thermal.gas.heat_capacity_ratio: above 5/3, the largest c_p/c_v of a gas") in cli(
        "validate", _case(tmp_path, thermal={"gas": {"heat_capacity_ratio": 40}})
    ).stderr


def test_a_contact_radius_with_another_contact_law_is_refused(tmp_path: Path) -> None:
    """lu2017 / morris2016_area_time take the normal law and k_n as their own parameters:
    a normal_stiffness of 5000 N/m beside normal: linear of 1000 N/m, lu2017 on a Hertz law,
    and morris2016_area_time's default contact_law 'hertz' on a linear law ran silently."""
    glass = _glass(youngs_modulus_real=6.0e10)
    linear = {"normal": {"model": "linear", "stiffness": 1000.0}}
    cases = [
        (linear, {"model": "lu2017", "normal_stiffness": 5000.0},
         "thermal.contact_radius.normal_stiffness = 5000 N/m but contact.normal.stiffness = "
         "1000 N/m: 'lu2017' needs the k_n of the simulation's linear spring"),
        ({}, {"model": "lu2017", "normal_stiffness": 1000.0},
         "thermal.contact_radius: 'lu2017' is the correction of a linear spring contact law "
         "(normal_stiffness k_n), but contact.normal is 'hertz'"),
        (linear, {"model": "morris2016_area_time"},
         "thermal.contact_radius.contact_law: 'hertz' (the default) but contact.normal is "
         "'linear': the collision time t_c of morris2016_area_time would be that of another "
         "contact law than the one the simulation runs; allowed: contact_law: linear with "
         "normal_stiffness: 1000 (contact.normal.stiffness)"),
    ]  # fmt: skip
    for contact, radius, message in cases:
        case = _case(tmp_path, materials=glass, contact=contact,
                     thermal={"contact_radius": radius})  # fmt: skip
        res = cli("run", case, "--output", tmp_path / "out", "--no-progress")
        assert res.returncode == 2, res.stdout + res.stderr
        assert message in res.stderr
        assert not (tmp_path / "out" / "timeseries.csv").exists()
    # the same law and k_n: runs
    radius = {"model": "morris2016_area_time", "contact_law": "linear", "normal_stiffness": 1e3}
    case = _case(tmp_path, materials=glass, contact=linear, thermal={"contact_radius": radius})
    assert cli("validate", case).returncode == 0


def test_a_restart_runs_the_changed_wall_values_and_refuses_a_moved_wall(tmp_path: Path) -> None:
    """run CASE --restart CKPT with the wall at 400 K instead of 350 K (or a new wall speed)
    kept the checkpoint's whole wall row: 350 K, at rest, without a word; a wall moved in
    the case stayed where the checkpoint had it."""
    import h5py

    out = tmp_path / "first_out"
    assert cli("run", _case(tmp_path, "first"), "--output", out).returncode == 0
    ckpt = sorted((out / "checkpoints").glob("*.h5"))[-1]
    wall = {**CASE["walls"][0], "velocity": [0.0, 0.0, 0.1]}
    wall["thermal"] = {"kind": "fixed", "temperature": 400.0}
    hotter = _case(tmp_path, "hotter", walls=[wall])
    again = tmp_path / "again"
    res = cli("run", hotter, "--restart", ckpt, "--output", again, "--end-time", "2e-4")
    assert res.returncode == 0, res.stdout + res.stderr
    final = sorted((again / "checkpoints").glob("*.h5"))[-1]
    with h5py.File(final) as f:
        row = f["arrays"]["wall_rows"][0]
    assert row[18] == 400.0 and list(row[6:9]) == [0.0, 0.0, 0.1]
    assert abs(row[2] - 0.1 * 1.0e-4) < 1e-12  # moved from the checkpoint's place
    moved = {**CASE["walls"][0], "point": [0.0, 0.0, -0.001]}
    res = cli("run", _case(tmp_path, "moved", walls=[moved]), "--restart", ckpt, "--output",
               tmp_path / "moved_out", "--end-time", "2e-4")  # fmt: skip
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        f"error: walls.0.point.2 differs from the case stored in the checkpoint {ckpt}: a "
        "wall's place comes from the checkpoint on a restart"
    ) in res.stderr


def test_a_restart_that_swaps_a_heat_mechanism_runs_the_new_one(tmp_path: Path) -> None:
    """A checkpoint of a case with radiation continued with a case with convection instead
    kept the checkpoint's summed mechanism columns: the convection heat was left out (the
    temperatures did not move) without a word; an adiabatic wall made fixed at the restart
    was refused as 'the checkpoint is damaged or belongs to another case'."""
    import h5py

    rad = {"radiation": {"model": "surroundings", "environment_temperature": 300.0}}
    glass = _glass(emissivity=0.8)
    out = tmp_path / "rad"
    res = cli("run", _case(tmp_path, "rad", materials=glass, thermal=rad), "--output", out)
    assert res.returncode == 0, res.stdout + res.stderr
    ckpt = sorted((out / "checkpoints").glob("*.h5"))[-1]
    conv = {"convection": "stagnant", "fluid": {"temperature": 400.0}}
    again = tmp_path / "conv"
    res = cli("run", _case(tmp_path, "conv", materials=glass, thermal=conv), "--restart", ckpt,
               "--output", again, "--end-time", "2e-4")  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    with h5py.File(ckpt) as f:
        before = f["particles"]["temperature"][:]
    with h5py.File(sorted((again / "checkpoints").glob("*.h5"))[-1]) as f:
        after = f["particles"]["temperature"][:]
    assert (after - before).min() > 1e-6  # heated by the 400 K gas
    header = (again / "timeseries.csv").read_text().splitlines()[0]
    assert "heat_in_convection" in header and "heat_in_radiation" not in header
    adiabatic = {**CASE["walls"][0], "thermal": {"kind": "adiabatic"}}
    out = tmp_path / "adiabatic"
    res = cli("run", _case(tmp_path, "adiabatic", walls=[adiabatic]), "--output", out)
    assert res.returncode == 0, res.stdout + res.stderr
    ckpt = sorted((out / "checkpoints").glob("*.h5"))[-1]
    res = cli("run", _case(tmp_path, "fixed"), "--restart", ckpt, "--output",
               tmp_path / "fixed_out", "--end-time", "2e-4")  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr


def test_material_values_in_another_unit_are_warned_about(tmp_path: Path) -> None:
    """specific_heat: 0.8 (kJ/(kg K)), density: 2.5 (g/cm³) and youngs_modulus_real below
    youngs_modulus (the two swapped) ran without a word (in a bed the first two make the
    thermal or the mechanical step refused, blaming the step)."""
    glass = _glass(specific_heat=0.8, density=2.5, youngs_modulus_real=1.0e5)
    simulation = {"time_step": 1.0e-7, "end_time": 1.0e-6}
    thermal = {"contact_radius": "zhou2010"}
    res = cli("validate", _case(tmp_path, materials=glass, simulation=simulation,
                                 thermal=thermal))  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    out = res.stdout + res.stderr
    for message in (
        "warning: materials.glass.density: 2.5 kg/m³ is below 30 kg/m³, lighter than any "
        "solid: is it in g/cm³? (2.5 g/cm³ = 2500 kg/m³)",
        "warning: materials.glass.specific_heat: 0.8 J/(kg K) is below 20 J/(kg K), less than "
        "any solid near room temperature (lead: 129): is it in kJ/(kg K)?",
        "warning: materials.glass.youngs_modulus_real: 100000 Pa is below youngs_modulus 1e+07 Pa",
    ):
        assert message in out
    assert "materials.glass" not in cli("validate", _case(tmp_path)).stdout


def test_thermal_settings_the_case_makes_unused_are_refused_or_told(tmp_path: Path) -> None:
    """thermal.time_step without frozen_mechanics and max_substeps beside a fixed substeps ran
    ignored; a fluid section no model reads was said as Python's '.../thermal.py:140:
    RuntimeWarning: ...' line."""
    for thermal, message in (
        ({"time_step": 1.0e-3}, "thermal: time_step = 0.001 s is the step of the heat with "
         "frozen mechanics, but frozen_mechanics is false"),
        ({"substeps": 3, "max_substeps": 10}, "thermal: max_substeps = 10 caps substeps: auto, "
         "but substeps is 3; allowed: substeps: auto, or leave max_substeps out"),
    ):  # fmt: skip
        res = cli("run", _case(tmp_path, thermal=thermal), "--output", tmp_path / "o")
        assert res.returncode == 2, res.stdout + res.stderr
        assert message in res.stderr
    auto = {"substeps": "auto", "max_substeps": 10}
    assert cli("validate", _case(tmp_path, thermal=auto)).returncode == 0
    res = cli("validate", _case(tmp_path, thermal={"fluid": {"temperature": 300.0}}))
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: thermal.fluid is given but no selected model reads it (thermal.convection = "
        "'none', thermal.radiation = 'none'): it has no effect"
    ) in res.stderr
    assert "RuntimeWarning" not in res.stderr


def test_a_name_refused_where_a_number_fits_too_says_both(tmp_path: Path) -> None:
    """cylinder_radius: dai2018 said "Input should be 'kanuparthi2008', ... or 'dai2019'",
    as if only a name were allowed (a number r̄/R̄ > 0 is too)."""
    thermal = {"indirect_conduction": {"model": "batchelor_obrien_separated",
                                       "cylinder_radius": "dai2018"}}  # fmt: skip
    res = cli("validate", _case(tmp_path, thermal=thermal))
    assert res.returncode == 2, res.stdout + res.stderr
    assert (
        "thermal.indirect_conduction.cylinder_radius: should be a number or one of "
        "'kanuparthi2008', 'yun_evans2010', 'moscardini2018' or 'dai2019' (got 'dai2018'; did "
        "you mean 'dai2019'?)"
    ) in res.stderr


def test_etc_of_a_2d_case_measures_the_plane_and_refuses_ignored_options(tmp_path: Path) -> None:
    """``thermodem etc`` of a 2D case without --axes was refused for the default 'xyz' (an
    axis the user never gave); --periodic with --layer/--temperature/--difference ignored
    them without a word; a bed whose interior (between the layers and their margins) was one
    column of particles ended in a ZeroDivisionError traceback."""
    s = 0.00158
    case = {
        "simulation": {"dimension": 2, "thickness": 0.001, "time_step": 1.0e-6, "end_time": 1e-5},
        "domain": {"lower": [0, 0], "upper": [0.02, 0.02]},
        "materials": _glass(),
        "insertion": [
            {
                "kind": "list",
                "material": "glass",
                "radius": 0.0008,
                "positions": [[0.001 + i * s, 0.001 + j * s] for i in range(9) for j in range(9)],
            }
        ],
        "thermal": {"direct_conduction": "rojek2014", "contact_radius": "geometric"},
    }
    path = tmp_path / "disc.yaml"
    path.write_text(yaml.safe_dump(case))
    res = cli("etc", path, "--json")
    assert res.returncode == 0, res.stdout + res.stderr
    assert [r["axis"] for r in json.loads(res.stdout)] == ["x", "y"]
    res = cli("etc", path, "--axes", "x", "--layer", "0.0048")  # one column in between
    assert res.returncode == 2, res.stdout + res.stderr
    assert "too thin for boundary layers of 0.0048 m" in res.stderr
    res = cli("etc", path, "--axes", "z")
    assert res.returncode == 2 and "axes = 'z'; allowed: letters of 'xy'" in res.stderr
    res = cli("etc", path, "--periodic", "--layer", "0.001", "--temperature", "350")
    assert res.returncode == 2
    assert "--layer 0.001, --temperature 350.0: not used with --periodic" in res.stderr


def test_a_tessellation_that_nothing_reads_is_told(tmp_path: Path) -> None:
    """thermal.tessellation without a Voronoi model (the model switched, its settings kept)
    ran without a word, like the fluid and porosity sections before they were warned about."""
    path = _case(tmp_path, thermal={"tessellation": {"method": "radical", "every_steps": 5}})
    res = cli("validate", path)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "warning: thermal.tessellation is given but nothing tessellates" in res.stderr
    assert "thermal.indirect_conduction = 'none'" in res.stderr
    res = cli("validate", _case(tmp_path, "voronoi", thermal={
        "indirect_conduction": "voronoi_a", "tessellation": {"every_steps": 5}}))  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    assert "nothing tessellates" not in res.stderr
    # the tessellation's statistics are information, not a warning (they were
    # 'warning: tessellation 1 (plain) ...')
    assert "\ntessellation 1 (" in "\n" + res.stderr and "warning: tessellation" not in res.stderr


def test_2d_region_selections_ignore_z(tmp_path: Path) -> None:
    """A 2D case's boxes copied from a 3D case whose z range misses the plane z = 0: the
    external source heated nothing and the initial-temperature regions took nobody (their z
    was tested as in 3D, docs/two-dimensional.md says z is ignored); the fixed temperature
    held only by a classification on x, y. Now every selection ignores z in 2D."""
    import h5py

    away = [0.01, 0.02]  # the z range of every box: misses z = 0

    def box(x0: float, x1: float) -> dict:
        return {"lower": [x0, 0, away[0]], "upper": [x1, 0.01, away[1]]}

    case = {
        "simulation": {
            "dimension": 2,
            "thickness": 0.001,
            "time_step": 1.0e-6,
            "end_time": 2.0e-5,
            "gravity": [0, 0],
        },  # fmt: skip
        "domain": {"lower": [0, 0], "upper": [0.01, 0.01]},
        "materials": _glass(),
        "insertion": [
            {
                "kind": "list",
                "material": "glass",
                "radius": 0.0008,
                "positions": [[0.002 * (i + 1), 0.002] for i in range(4)],
            }
        ],  # fmt: skip
        "external_force": [{"select": {"region": box(0, 0.0045)}, "force": [1.0e-3, 0, 0]}],
        "thermal": {
            "direct_conduction": "rojek2014",
            "contact_radius": "geometric",
            "initial_temperature": {
                "kind": "regions",
                "regions": [[box(0, 0.003), 350]],
                "default": 300,
            },  # fmt: skip
            "fixed_temperature": [{"select": {"region": box(0.0075, 0.01)}, "temperature": 400}],
            "external_source": [{"power": 1.0, "region": box(0.0035, 0.0065)}],
        },
    }
    path = tmp_path / "disc.yaml"
    path.write_text(yaml.safe_dump(case))
    res = cli("run", path, "--output", tmp_path / "out")
    assert res.returncode == 0, res.stdout + res.stderr
    ckpt = sorted((tmp_path / "out" / "checkpoints").glob("*.h5"))[-1]
    with h5py.File(ckpt) as f:
        order = f["particles/global_id"][...].argsort()
        temperature = f["particles/temperature"][...][order]
        force = f["particles/external_force"][...][order]
    assert temperature[0] == 350.0 and temperature[3] == 400.0
    assert temperature[1] > 300.0 and temperature[2] > 300.0  # the source's share
    assert force[:, 0].tolist() == [1.0e-3, 1.0e-3, 0.0, 0.0]


def test_a_heat_generation_mechanism_the_contact_laws_cannot_produce_is_told(
    tmp_path: Path,
) -> None:
    """rolling_friction with rolling: none, plastic_deformation with an elastic normal law
    (rojek2014's sliding friction without a tangential law...) gave zero heat without a word."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.case_warnings import generation_mechanism_warnings

    listed = ["rolling_friction", "plastic_deformation", "normal_damping"]
    generation = {"model": "mechanical_dissipation", "mechanisms": listed}
    path = _case(tmp_path, thermal={"heat_generation": generation})
    res = cli("validate", path)
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: thermal.heat_generation.mechanisms: 'rolling_friction' gives zero heat with "
        "these contact laws: contact.rolling is 'none'"
    ) in res.stderr
    assert (
        "'plastic_deformation' gives zero heat with these contact laws: contact.normal is "
        "'hertz', an elastic law"
    ) in res.stderr
    assert "'normal_damping' gives zero" not in res.stderr

    def told(contact: dict, generation: dict | str) -> list[str]:
        data = json.loads(json.dumps(CASE))
        data["materials"]["glass"]["rolling_friction"] = 0.1  # (the default 0 gives no heat)
        data["contact"] = contact
        data["thermal"] = {"heat_generation": generation}
        return generation_mechanism_warnings(case_from_dict(data))

    (text,) = told({"tangential": "none"}, "rojek2014")
    assert text.startswith("thermal.heat_generation = 'rojek2014': 'sliding_friction' gives zero")
    walton_braun = {"model": "walton_braun", "loading_stiffness": 1e4}
    (text,) = told({"normal": walton_braun, "rolling": "epsd"}, generation)
    assert "'normal_damping' gives zero heat" in text  # plastic_deformation is produced
    assert told({"rolling": "none"}, "mechanical_dissipation") == []  # the default list


def test_a_porosity_cell_larger_than_the_domain_is_told(tmp_path: Path) -> None:
    """porosity: {kind: cell, cell_size: 0.5} in a 1 cm domain ran with one cell (the
    domain's mean porosity for every particle) without a word. (A shell or a sphere of
    radiative influence larger than the domain is refused: the broken-case corpus.)"""
    thermal = {"convection": "gunn1978", "fluid": {"temperature": 300.0},
               "porosity": {"kind": "cell", "cell_size": 0.5}}  # fmt: skip
    res = cli("validate", _case(tmp_path, thermal=thermal))
    assert res.returncode == 0, res.stdout + res.stderr
    assert (
        "warning: thermal.porosity.cell_size: 0.5 m is larger than the domain (edges 0.01, "
        "0.01, 0.01 m)"
    ) in res.stderr
