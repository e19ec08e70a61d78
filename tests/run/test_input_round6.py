"""Inputs of a demanding user (sixth round): numbers in another unit that earlier rounds did
not look at (a Young's modulus in GPa, a friction angle, gravity in mm/s²), settings the case
leaves unused (temperatures without heat, a gas no model reads, a zero load), a pair of
materials named twice, a time step that gives more steps than any run makes, and an
``export --out`` onto the run's own files. Each through the command line (run_cases.cli), as
a user runs it."""

from __future__ import annotations

import shutil
from pathlib import Path

import yaml
from run_cases import BASE_CASE, base_case, cli

GLASS = BASE_CASE["materials"]["glass"]
SIM = BASE_CASE["simulation"]
FLOOR = BASE_CASE["walls"][0]
LATTICE = BASE_CASE["insertion"][0]


def _write(tmp_path: Path, case: dict, name: str = "case") -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def _validate(tmp_path: Path, **sections: object):  # noqa: ANN202
    return cli("validate", _write(tmp_path, base_case(**sections)))


def _warnings(res) -> list[str]:  # noqa: ANN001
    return [line for line in (res.stdout + res.stderr).splitlines() if line.startswith("warning")]


def test_a_pair_of_materials_named_twice_is_refused(tmp_path: Path) -> None:
    """Two ``interactions`` entries of one pair: the later replaced the earlier whole, so the
    earlier's coefficients were lost without a word (also written [a, b] and [b, a])."""
    steel = {**GLASS, "density": 7800}
    res = _validate(
        tmp_path,
        materials={"glass": GLASS, "steel": steel},
        interactions=[
            {"materials": ["glass", "steel"], "restitution": 0.9},
            {"materials": ["steel", "glass"], "sliding_friction": 0.3},
        ],
    )
    assert res.returncode == 2, res.stdout
    assert "interactions.1.materials: names the pair steel-glass again" in res.stderr
    assert "interactions.0 names it too, with restitution" in res.stderr
    assert "this entry gives sliding_friction" in res.stderr
    # one entry per pair (and a pair of a material with itself) is fine
    res = _validate(
        tmp_path,
        materials={"glass": GLASS, "steel": steel},
        interactions=[
            {"materials": ["glass", "steel"], "restitution": 0.9, "sliding_friction": 0.3},
            {"materials": ["glass", "glass"], "restitution": 0.8},
        ],
    )
    assert res.returncode == 0, res.stderr


def test_a_dimension_written_as_a_string_is_the_number(tmp_path: Path) -> None:
    """``dimension: "2"`` was refused with ``Input should be 2 or 3 (got '2')``, a message
    that names the allowed value as the one given; every other number may be a string."""
    sim = {**SIM, "dimension": "3"}
    res = _validate(tmp_path, simulation=sim)
    assert res.returncode == 0, res.stderr
    sim = {**SIM, "dimension": "2"}
    res = _validate(tmp_path, simulation=sim)
    assert res.returncode == 2
    assert "should be 2 or 3" not in res.stderr
    assert "walls.0.normal: [0, 0, 1] has a z component; in a 2D case" in res.stderr


def test_a_time_step_that_gives_more_steps_than_any_run_is_refused(tmp_path: Path) -> None:
    """``time_step: 1e-300`` (an exponent mistyped) was valid, with an estimate of 1e290 hours,
    and ``run`` started a run that never ends."""
    sim = {**SIM, "time_step": 1.0e-300}
    res = _validate(tmp_path, simulation=sim)
    assert res.returncode == 2, res.stdout
    assert "simulation.time_step: 1e-300 s gives 1e+297 steps" in res.stderr
    assert "allowed: at most 9.01e+15 steps" in res.stderr
    res = cli("run", _write(tmp_path, base_case(simulation=sim)), "--output", tmp_path / "out")
    assert res.returncode == 2
    assert "gives 1e+297 steps" in res.stderr
    assert not (tmp_path / "out" / "checkpoints").exists()


def test_values_in_another_unit_of_the_mechanics_are_warned_about(tmp_path: Path) -> None:
    """A Young's modulus of 70 (GPa), a friction of 30 (an angle in degrees) and gravity of
    9810 (mm/s²) ran without a word."""
    glass = {**GLASS, "youngs_modulus": 70.0, "sliding_friction": 30.0, "rolling_friction": 8.0}
    sim = {**SIM, "gravity": [0, 0, -9810.0], "time_step_check": {"allow_unstable": True}}
    res = _validate(tmp_path, materials={"glass": glass}, simulation=sim)
    assert res.returncode == 0, res.stderr
    text = "\n".join(_warnings(res))
    assert "materials.glass.youngs_modulus: 70 Pa is below 1000 Pa" in text
    assert "is it in GPa or MPa?" in text
    assert "materials.glass.sliding_friction: 30 is above 5" in text
    assert "tan 30° = 0.577" in text
    assert "materials.glass.rolling_friction: 8 is above 5" in text
    assert "simulation.gravity: [0.0, 0.0, -9810.0] has the magnitude 9810 m/s²" in text
    # an interactions entry's friction too
    res = _validate(
        tmp_path, interactions=[{"materials": ["glass", "glass"], "sliding_friction": 45.0}]
    )
    assert "interactions.0.sliding_friction: 45 is above 5" in res.stdout + res.stderr
    # the base case's values are not warned about
    res = _validate(tmp_path)
    assert not [w for w in _warnings(res) if "above 5" in w or "gravity" in w], res.stderr


def test_temperatures_in_a_case_without_heat_are_told(tmp_path: Path) -> None:
    """``simulation.initial_temperature`` and an entry's ``temperature`` / ``temperatures``
    in a case without a thermal section (mechanics only) were never used, silently (a wall's
    fixed temperature already was told)."""
    sim = {**SIM, "initial_temperature": 400.0}
    listed = {
        "kind": "list",
        "material": "glass",
        "radius": 0.001,
        "positions": [[0.008, 0.008, 0.008]],
        "temperatures": [350.0],
    }
    res = _validate(tmp_path, simulation=sim, insertion=[{**LATTICE, "temperature": 300.0}, listed])
    assert res.returncode == 0, res.stderr
    text = "\n".join(_warnings(res))
    assert "simulation.initial_temperature: 400 K is given, but the case has no thermal" in text
    assert "insertion.0.temperature: 300 K is given" in text
    assert "insertion.1.temperatures: [350] K are given" in text
    assert "add thermal: {}" in text
    # with heat they are used, and not told
    res = _validate(tmp_path, simulation=sim, thermal={})
    assert not [w for w in _warnings(res) if "is given, but the case has no thermal" in w]


def test_a_gas_that_no_selected_model_reads_is_told(tmp_path: Path) -> None:
    """``thermal.gas`` with the default conduction (batchelor_obrien_simple reads no gas):
    a pressure or a gas conductivity typed there changed nothing, silently."""
    res = _validate(tmp_path, thermal={"gas": {"pressure": 1.0}})
    assert res.returncode == 0, res.stderr
    text = "\n".join(_warnings(res))
    assert "thermal.gas is given but no selected model reads it" in text
    assert "direct_conduction = 'batchelor_obrien_simple'" in text
    # the default gas (no key) is not told
    res = _validate(tmp_path, thermal={})
    assert not [w for w in _warnings(res) if "thermal.gas" in w]


def test_zero_loads_and_a_huge_extra_distance_are_told(tmp_path: Path) -> None:
    """An external force and torque of zero, a heat flux of 0 W/m² (each does nothing), and an
    ``extra_distance`` of a domain's size (every pair listed) ran without a word."""
    res = _validate(
        tmp_path,
        external_force=[{"select": {"ids": [0]}, "force": [0, 0, 0]}],
        neighbors={"extra_distance": 1.0},
        thermal={
            "heat_flux": [{"select": {"ids": [0]}, "flux": 0.0}],
            "external_source": [
                {"region": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]}, "power": 0.0}
            ],
        },
    )
    assert res.returncode == 0, res.stderr
    text = "\n".join(_warnings(res))
    assert (
        "external_force.0: force [0.0, 0.0, 0.0] and torque [0.0, 0.0, 0.0] are both zero" in text
    )
    assert "thermal.heat_flux.0.flux: 0 W/m² gives no heat" in text
    assert "thermal.external_source.0.power: 0 W gives no heat" in text
    assert "neighbors.extra_distance = 1 m is 500 times the largest particle diameter" in text


def test_export_never_replaces_the_runs_own_files(tmp_path: Path) -> None:
    """``export DIR --out DIR/timeseries.csv --overwrite`` replaced the run's time series with
    particles (and ``plot`` then failed with a ValueError traceback); a time series that is
    not one is now named by plot with its line and column."""
    out = tmp_path / "out"
    res = cli("run", _write(tmp_path, base_case()), "--output", out, "--steps", 2, "--no-progress")
    assert res.returncode == 0, res.stderr
    series = (out / "timeseries.csv").read_text()
    for name in ("timeseries.csv", "case.resolved.yaml", "particles.pvd"):
        res = cli("export", out, "--out", out / name, "--overwrite")
        assert res.returncode == 2, res.stdout
        assert f"--out {out / name}: is a file of the run in {out}" in res.stderr
        assert "never replaced (not even with --overwrite)" in res.stderr
    assert (out / "timeseries.csv").read_text() == series
    res = cli("export", out, "--out", out / "mine.csv")
    assert res.returncode == 0, res.stderr
    # a time series written over by another file: plot names it, without a traceback
    damaged = tmp_path / "damaged"
    shutil.copytree(out, damaged)
    shutil.copy(out / "mine.csv", damaged / "timeseries.csv")
    res = cli("plot", damaged)
    assert res.returncode == 2
    assert f"{damaged / 'timeseries.csv'}, line 2, column" in res.stderr
    assert "is not a number" in res.stderr


def test_threads_lowered_to_the_cores_are_not_logged_as_requested(tmp_path: Path) -> None:
    """``--threads 4096`` is lowered to the cores with a warning, but run.log said
    ``threads: 2 (as requested)``."""
    out = tmp_path / "out"
    case = _write(tmp_path, base_case())
    res = cli("run", case, "--output", out, "--steps", 2, "--no-progress", "--threads", 4096)
    assert res.returncode == 0, res.stderr
    log = (out / "run.log").read_text()
    assert "(--threads 4096 lowered to the" in log
    assert "as requested" not in log


def test_particles_vanishing_for_the_domain_are_an_input_error(tmp_path: Path) -> None:
    """A lognormal of sigma 50 without min_radius draws radii of 1e-9 m and less: the
    neighbour grid of the first build asked NumPy for 1e18 cells, a ValueError traceback."""
    lognormal = {"kind": "lognormal", "sigma": 50.0, "median": 0.0008, "max_radius": 0.001}
    res = _validate(tmp_path, insertion=[{**LATTICE, "distribution": lognormal}])
    assert res.returncode == 2, res.stdout
    assert "the neighbour grid would have" in res.stderr
    assert "a lognormal of a large sigma: give min_radius" in res.stderr
    assert "before any step" in res.stderr
    # a radius in another unit in a list entry: 1e-300 m
    tiny = {"kind": "list", "material": "glass", "radius": 1e-300, "positions": [[0.005] * 3]}
    res = _validate(tmp_path, insertion=[tiny])
    assert res.returncode == 2
    assert "the neighbour grid would have more than 1e308 cells" in res.stderr
    assert "radii in another unit (a particle file's or a list's)" in res.stderr
    # a domain of 10 km for 1 mm particles (lengths in mm?): NumPy could not allocate the grid
    res = _validate(tmp_path, domain={"lower": [0, 0, 0], "upper": [1.0e4, 1.0e4, 1.0e4]})
    assert res.returncode == 2
    assert "allowed: a domain (domain.lower, domain.upper) at most about" in res.stderr
    assert "a domain in another unit (mm: 10 for 10 mm)" in res.stderr


def test_friction_coefficients_the_contact_laws_do_not_read_are_told(tmp_path: Path) -> None:
    """``rolling_friction: 0.1`` with the default ``rolling: none`` (LIGGGHTS and EDEM switch
    rolling resistance on by the coefficient) and ``sliding_friction`` with ``tangential:
    none`` were not read, silently; a rolling model with every coefficient 0 gives no torque.
    (The laws other than the base case's are checked on a case refused before it is built,
    its warnings told with the refusal: no kernel of a new combination is compiled.)"""
    unbuilt = {k: v for k, v in GLASS.items() if k != "specific_heat"}

    def told(glass: dict, contact: dict, **sections: object) -> str:
        res = _validate(tmp_path, materials={"glass": glass}, contact=contact, thermal={},
                        **sections)  # fmt: skip
        assert res.returncode == 2 and "specific_heat: missing" in res.stderr, res.stderr
        return res.stderr

    text = told({**unbuilt, "sliding_friction": 0.8}, {"tangential": "none"})
    assert "materials.glass.sliding_friction = 0.8 given, but contact.tangential is 'none'" in text
    text = told(unbuilt, {"rolling": "constant_torque"})
    assert "contact.rolling = 'constant_torque', but every material's rolling_friction is 0" in text
    # a rolling law with a coefficient (here of the pair) is not told
    pair = [{"materials": ["glass", "glass"], "rolling_friction": 0.05}]
    text = told(unbuilt, {"rolling": "constant_torque"}, interactions=pair)
    assert "rolling" not in text
    # the base case's laws, built
    res = _validate(tmp_path, materials={"glass": {**GLASS, "rolling_friction": 0.1}})
    assert res.returncode == 0, res.stderr
    assert (
        "materials.glass.rolling_friction = 0.1 given, but contact.rolling is 'none' (the "
        "default)" in "\n".join(_warnings(res))
    )


def test_a_material_name_with_outer_spaces_is_refused_by_name(tmp_path: Path) -> None:
    """``'glass ':`` as the material's key: the walls naming ``glass`` were refused with
    ``unknown material 'glass'; allowed: glass`` (the space unseen)."""
    res = _validate(tmp_path, materials={"glass ": GLASS})
    assert res.returncode == 2
    assert "a material name with a space at its start or end, or empty (got 'glass ')" in (
        res.stderr
    )
    assert "unknown material" not in res.stderr


def test_yaml_11_numbers_read_silently_as_others_are_refused(tmp_path: Path) -> None:
    """YAML 1.1 reads ``end_time: 1:30`` as 90 (base 60: a run 90 000 times longer) and
    ``seed: 010`` as 8 (octal); a list as a key (``? [a, b]``) ended in a TypeError
    traceback."""
    text = yaml.safe_dump(base_case(), sort_keys=False)
    cases = {
        "sexagesimal": text.replace("end_time: 0.001", "end_time: 1:30"),
        "octal": text.replace("time_step: 1.0e-05", "time_step: 1.0e-05\n  seed: 010"),
        "list_key": text + "? [a, b]\n: 3\n",
    }
    expected = {
        "sexagesimal": "'1:30' is read by YAML as the base-60 number 90",
        "octal": "'010' is read by YAML as the octal number 8 (a leading zero); allowed: the "
        "number without its leading zero, 10",
        "list_key": "a key that is a list ('? [...]' or '? {...}'); allowed: keys that are names",
    }
    for name, body in cases.items():
        path = tmp_path / f"{name}.yaml"
        path.write_text(body)
        res = cli("validate", path)
        assert res.returncode == 2, (name, res.stdout)
        assert expected[name] in res.stderr, res.stderr
        assert "line " in res.stderr
    # the decimal, exponent, hexadecimal and '_' forms are read as before
    path = tmp_path / "plain.yaml"
    path.write_text(text.replace("density: 2500", "density: 2_500").replace("0.001", "1e-3"))
    assert cli("validate", path).returncode == 0


def test_a_run_directory_given_as_the_checkpoint_is_named_as_one(tmp_path: Path) -> None:
    """``run --restart DIR`` (the run's directory, not its checkpoint) said the checkpoint
    ``does not exist or is not a file``, though it exists."""
    out = tmp_path / "out"
    res = cli("run", _write(tmp_path, base_case()), "--output", out, "--steps", 2, "--no-progress")
    assert res.returncode == 0, res.stderr
    res = cli("run", "--restart", out, "--output", tmp_path / "next", "--steps", 2)
    assert res.returncode == 2
    assert f"checkpoint '{out}' is a directory; allowed: a checkpoint file (e.g. its newest, " in (
        res.stderr
    )
    assert "does not exist" not in res.stderr
    assert not (tmp_path / "next").exists()


def test_simulation_initial_temperature_beside_a_rule_is_told(tmp_path: Path) -> None:
    """``simulation.initial_temperature: 350`` with ``thermal.initial_temperature: {kind:
    per_material, values: {}}``: every particle started at the rule's default 293.15 K, the
    350 K given was not used, silently."""
    sim = {**SIM, "initial_temperature": 350.0}
    rule = {"kind": "per_material", "values": {}}
    res = _validate(tmp_path, simulation=sim, thermal={"initial_temperature": rule})
    assert res.returncode == 0, res.stderr
    assert (
        "simulation.initial_temperature: 350 K is given, but thermal.initial_temperature (kind "
        "per_material) gives every particle its temperature (its default, 293.15 K, for the "
        "particles it does not name), so it is not used" in "\n".join(_warnings(res))
    )
    # a rule alone is not told
    res = _validate(tmp_path, thermal={"initial_temperature": rule})
    assert not [w for w in _warnings(res) if "initial_temperature" in w]


def test_particle_file_paths_empty_or_from_home(tmp_path: Path, monkeypatch) -> None:  # noqa: ANN001
    """``path: ''`` was read as the case's directory (``... is a directory``); ``path:
    ~/beds/bed.txt`` was joined to the case's directory; ``$HOME/...`` is told unexpanded."""
    home = tmp_path / "home"
    (home / "beds").mkdir(parents=True)
    (home / "beds" / "bed.txt").write_text("x y z radius\n0.005 0.005 0.005 0.001\n")
    entry = {"kind": "file", "material": "glass"}
    res = _validate(tmp_path, insertion=[{**entry, "path": ""}])
    assert res.returncode == 2
    assert "insertion.0.path: an empty path (got '')" in res.stderr
    monkeypatch.setenv("HOME", str(home))
    res = _validate(tmp_path, insertion=[{**entry, "path": "~/beds/bed.txt"}])
    assert res.returncode == 0, res.stderr
    res = _validate(tmp_path, insertion=[{**entry, "path": "$HOME/beds/bed.txt"}])
    assert res.returncode == 2
    assert "environment variables such as $HOME are not expanded" in res.stderr


def test_thermal_inputs_nothing_reads_are_told(tmp_path: Path) -> None:
    """``contact_radius: none`` (R_c = 0) under batchelor_obrien_simple (Q = 4 k R_c ΔT)
    conducted nothing, and an ``interactions`` entry's ``surface_roughness`` without the
    resistance network was not read, both silently."""
    pair = [{"materials": ["glass", "glass"], "surface_roughness": 1.0e-6}]
    # (refused before it is built, the warnings told with the refusal: no kernel of the
    # contact_radius none combination is compiled)
    unbuilt = {k: v for k, v in GLASS.items() if k != "specific_heat"}
    res = _validate(tmp_path, materials={"glass": unbuilt}, thermal={"contact_radius": "none"},
                    interactions=pair)  # fmt: skip
    assert res.returncode == 2 and "specific_heat: missing" in res.stderr, res.stderr
    text = res.stderr
    assert (
        "thermal.contact_radius = 'none' gives the contact radius R_c = 0, so "
        "thermal.direct_conduction = 'batchelor_obrien_simple'" in text
    )
    assert (
        "interactions.0: surface_roughness = 1e-06 given, but only thermal.direct_conduction "
        "= 'resistance_network' reads them (selected: 'batchelor_obrien_simple')" in text
    )


def test_pour_warnings_write_the_time_as_a_number(tmp_path: Path) -> None:
    """A full pour region was told at ``t=3.0000000000000004e-05 s`` (the float's repr)."""
    pour = {
        "kind": "pour",
        "material": "glass",
        "distribution": {"kind": "mono", "radius": 0.001},
        "region": {"kind": "box", "lower": [0, 0, 0.007], "upper": [0.01, 0.01, 0.01]},
        "rate": 1.0e6,
        "interval": 1.0e-5,
    }
    case = _write(tmp_path, base_case(insertion=[pour]))
    res = cli("run", case, "--output", tmp_path / "out", "--steps", 4, "--no-progress")
    assert res.returncode == 0, res.stderr
    assert "pour insertion at t=3e-05 s placed" in res.stdout + res.stderr
    assert "t=3.0000000000000004e-05" not in res.stdout + res.stderr


def test_etc_of_a_poured_bed_names_the_pour(tmp_path: Path) -> None:
    """``etc`` of a case whose particles are all poured said ``the case has no particles``,
    which the case file seems to contradict."""
    pour = {
        "kind": "pour",
        "material": "glass",
        "distribution": {"kind": "mono", "radius": 0.001},
        "region": {"kind": "box", "lower": [0, 0, 0.007], "upper": [0.01, 0.01, 0.01]},
        "rate": 1.0e4,
        "interval": 1.0e-4,
    }
    res = cli("etc", _write(tmp_path, base_case(insertion=[pour], thermal={})))
    assert res.returncode == 2
    assert "the case has no particles at t = 0: insertion.0 pour(s) them during a run" in (
        res.stderr
    )


def test_the_resolved_case_gets_none_of_these_warnings(tmp_path: Path) -> None:
    """case.resolved.yaml writes every default (``initial_temperature: 293.15``, the air of
    ``thermal.gas``, ``sliding_friction: 0.5``): read again, none of them is a value given."""
    mine = ("is given, but", "thermal.gas is given", "given, but contact.")
    for sections in ({}, {"thermal": {}}):
        res = _validate(tmp_path, **sections)
        assert res.returncode == 0, res.stderr
        resolved = tmp_path / "resolved.yaml"
        resolved.write_text(res.stdout)
        res = cli("validate", resolved)
        assert res.returncode == 0, res.stderr
        assert not [w for w in _warnings(res) if any(m in w for m in mine)], _warnings(res)
    # sliding_friction: 0.5 (the default, as resolved) with tangential: none (refused before
    # it is built: no kernel of that combination is compiled; its warnings told with it)
    unbuilt = {k: v for k, v in GLASS.items() if k != "specific_heat"}
    res = _validate(tmp_path, materials={"glass": {**unbuilt, "sliding_friction": 0.5}},
                    contact={"tangential": "none"}, thermal={})  # fmt: skip
    assert res.returncode == 2 and "specific_heat: missing" in res.stderr, res.stderr
    assert "given, but contact." not in res.stderr


def test_several_particles_written_as_one_flat_list_is_one_message(tmp_path: Path) -> None:
    """``positions: [x1, y1, z1, x2, y2, z2]`` gave one message per number (a single flat
    [x, y, z] already had one)."""
    flat = [0.002, 0.002, 0.002, 0.005, 0.005, 0.005]
    entry = {"kind": "list", "material": "glass", "radius": 0.001, "positions": flat}
    res = _validate(tmp_path, insertion=[entry])
    assert res.returncode == 2
    told = "insertion.0.positions: a list of vectors, one [x, y, z] per particle; got 6 numbers"
    assert told in res.stderr
    assert "e.g. [[0.002, 0.002, 0.002], [0.005, 0.005, 0.005]]" in res.stderr
    assert "positions.1" not in res.stderr


def test_a_lattice_over_an_earlier_entry_is_told(tmp_path: Path) -> None:
    """A lattice entry given twice (a copied entry): every site of the second overlapped the
    first's particles and was skipped, so it inserted nothing, silently."""
    res = _validate(tmp_path, insertion=[LATTICE, LATTICE])
    assert res.returncode == 0, res.stderr
    assert (
        "insertion.1: 8 of 8 lattice sites overlap particles of earlier insertion entries and "
        "are skipped (the entry inserts 0)" in "\n".join(_warnings(res))
    )
    # a single entry is not told
    assert not [w for w in _warnings(_validate(tmp_path)) if "lattice sites" in w]


def test_keys_yaml_reads_as_booleans_or_numbers_are_named(tmp_path: Path) -> None:
    """A material named ``on`` (or ``1``): YAML 1.1 reads the key as True (1), and the message
    was ``materials.1.[key]: Input should be a valid string (got True)``."""
    text = yaml.safe_dump(base_case(), sort_keys=False).replace("glass", "placeholder")
    for name, told in (("on", "the boolean True"), ("1", "the number 1")):
        path = tmp_path / f"key_{name}.yaml"
        path.write_text(text.replace("placeholder", name))
        res = cli("validate", path)
        assert res.returncode == 2
        assert f"the key '{name}' is read by YAML as {told}, not a name; allowed: a name, " in (
            res.stderr
        )
        assert "[key]" not in res.stderr
        path.write_text(text.replace("placeholder", f"'{name}'"))  # quoted: a name
        assert cli("validate", path).returncode == 0


def test_a_material_nothing_uses_is_told(tmp_path: Path) -> None:
    """``steel`` defined for the walls while the walls still name ``glass``: the walls ran with
    glass's values, silently."""
    res = _validate(tmp_path, materials={"glass": GLASS, "steel": {**GLASS, "density": 7800}})
    assert res.returncode == 0, res.stderr
    assert (
        "materials.steel: defined, but no wall and no insertion entry uses it, so its values "
        "take part in nothing (the walls and entries use glass)" in "\n".join(_warnings(res))
    )
