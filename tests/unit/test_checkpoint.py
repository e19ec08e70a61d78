"""Checkpoints: a run stopped, written to HDF5, restored in a new Simulation and continued is
bit-identical to the uninterrupted run (pouring, rotating and translating walls, rolling
history, periodic axes, the thermal engine)."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from thermodem.config.dump import resolved_case_yaml
from thermodem.config.load import case_from_dict, load_case
from thermodem.engine.restart import check_complete
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.io.checkpoint import (
    checkpoint_name,
    list_checkpoints,
    read_checkpoint,
    write_checkpoint,
)
from thermodem.state.heat import M_INDIRECT

EXAMPLES = sorted((Path(__file__).parents[2] / "examples").glob("*.yaml"))

GLASS = {
    "density": 2500.0,
    "youngs_modulus": 1.0e7,
    "poisson_ratio": 0.3,
    "restitution": 0.6,
    "sliding_friction": 0.4,
    "rolling_friction": 0.05,
    "thermal_conductivity": 1.0,
    "specific_heat": 800.0,
}


def drum_case() -> dict:
    """Particles and a pour in a rotating drum with end caps, EPSD rolling, a moving lid."""
    return {
        "simulation": {"time_step": 5.0e-6, "end_time": 1.0, "seed": 7},
        "domain": {"lower": [-0.012, -0.012, -0.012], "upper": [0.012, 0.012, 0.012]},
        "materials": {"glass": dict(GLASS), "steel": dict(GLASS, restitution=0.5)},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        "walls": [
            {
                "kind": "cylinder",
                "center": [0, 0, 0],
                "axis": [1, 0, 0],
                "radius": 0.01,
                "length": 0.016,
                "angular_velocity": 20.0,
                "material": "steel",
            },
            {"kind": "plane", "point": [-0.008, 0, 0], "normal": [1, 0, 0], "material": "steel"},
            {"kind": "plane", "point": [0.008, 0, 0], "normal": [-1, 0, 0], "material": "steel"},
            {
                "kind": "rectangle",
                "center": [0, 0, 0.0099],
                "normal": [0, 0, -1],
                "u_axis": [1, 0, 0],
                "half_extents": [0.004, 0.004],
                "velocity": [0, 0, -0.01],
                "material": "steel",
            },
        ],
        "insertion": [
            {
                "kind": "random_cylinder",
                "material": "glass",
                "distribution": {"kind": "uniform", "min_radius": 0.0008, "max_radius": 0.0011},
                "base_centre": [-0.007, 0, 0],
                "axis": [1, 0, 0],
                "radius": 0.008,
                "length": 0.014,
                "count": 80,
                "velocity": [0.4, 0.1, -0.4],
            },
            {  # a second set moving the other way: particle-particle collisions at once
                "kind": "random_cylinder",
                "material": "glass",
                "distribution": {"kind": "mono", "radius": 0.0009},
                "base_centre": [-0.007, 0, 0],
                "axis": [1, 0, 0],
                "radius": 0.008,
                "length": 0.014,
                "count": 60,
                "velocity": [-0.4, -0.1, 0.4],
            },
            {
                "kind": "pour",
                "material": "glass",
                "distribution": {"kind": "mono", "radius": 0.0009},
                "region": {
                    "kind": "box",
                    "lower": [-0.006, -0.004, -0.004],
                    "upper": [0.006, 0.004, 0.004],
                },
                "rate": 4000.0,
                "interval": 0.0005,
                "end_time": 0.003,
                "velocity": [0, 0, -0.2],
            },
        ],
    }


def periodic_thermal_case() -> dict:
    """A periodic shear-free bed with heat conduction and a fixed-temperature floor."""
    return {
        "simulation": {"time_step": 5.0e-6, "end_time": 1.0, "seed": 3},
        "domain": {
            "lower": [0, 0, 0],
            "upper": [0.008, 0.008, 0.01],
            "periodic": [True, True, False],
        },
        "materials": {"glass": dict(GLASS), "steel": dict(GLASS, thermal_conductivity=20.0)},
        # no rolling resistance: the drum case restarts EPSD's rolling history, and the
        # thermal cases share the pair pass variants of other tests (compile time)
        "contact": {"rolling": "none"},
        "walls": [
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal": [0, 0, 1],
                "material": "steel",
                "thermal": {"kind": "fixed", "temperature": 350.0},
            }
        ],
        "insertion": [
            {
                "kind": "lattice",
                "material": "glass",
                "distribution": {"kind": "mono", "radius": 0.0009},
                "lower": [0, 0, 0.0],
                "upper": [0.008, 0.008, 0.008],
                "spacing": 0.002,
                "jitter": 0.0001,
                "velocity": [0.05, 0.02, -0.2],
            }
        ],
        "thermal": {"direct_conduction": "batchelor_obrien_simple", "substeps": 3},
    }


def reuse_thermal_case() -> dict:
    """The periodic bed with the resistance network and the conductance reuse (its state is
    in the contact history)."""
    case = periodic_thermal_case()
    surface = {"microhardness": 3e7, "surface_roughness": 1e-7, "surface_slope": 0.1,
               "thermal_accommodation": 0.8}  # fmt: skip
    for material in case["materials"].values():
        material.update(surface)
    case["thermal"].update(
        direct_conduction="resistance_network", conductance_force_tolerance=0.02, substeps=1
    )
    return case


def range_thermal_case() -> dict:
    """The periodic bed with gap conduction on the range pair set (Batchelor & O'Brien's
    separated pairs): its pair order fixes the sums, so it is part of the checkpoint."""
    case = periodic_thermal_case()
    case["thermal"].update(
        direct_conduction={"model": "batchelor_obrien_complete", "cutoff_gap_ratio": 1.0},
        substeps=2,
        range_skin=5e-5,
    )
    return case


def indirect_case(indirect: dict) -> Callable[[], dict]:
    """The periodic bed with an indirect_conduction model next to the contact conduction
    (the range set's models; Vargas & McCarthy on the touching pairs)."""

    def make() -> dict:
        case = periodic_thermal_case()
        for material in case["materials"].values():
            material["thermal_accommodation"] = 0.8
        case["thermal"].update(indirect_conduction=indirect, substeps=2, range_skin=5e-5)
        return case

    return make


def implicit_thermal_case() -> dict:
    """The range-set bed frozen, Crank-Nicolson (engine/implicit.py): the restarted run
    recomputes the start-of-step rates that the uninterrupted one kept from its last step."""
    case = range_thermal_case()
    case["thermal"].pop("substeps")
    case["thermal"].update(frozen_mechanics=True, time_step=2e-3, scheme="crank_nicolson")
    return case


def exponential_thermal_case() -> dict:
    """The range-set bed frozen, the Krylov exponential (engine/exponential.py) with steps of
    1 s: the basis started at t = 0 has 10 vectors after the first step and 15 from the
    third; the run restarted after step 1 rebuilds the 10 from the saved origin and extends
    them as the uninterrupted run did."""
    case = implicit_thermal_case()
    case["thermal"].update(time_step=1.0, scheme="exponential")
    return case


def trbdf2_thermal_case() -> dict:
    """The range-set bed frozen, adaptive TR-BDF2 (engine/adaptive.py): the proposed internal
    step and the last step's change (the predictor) are part of the checkpoint."""
    case = implicit_thermal_case()
    case["thermal"].update(time_step=0.5, scheme="tr_bdf2", implicit={"error_tolerance": 1e-4})
    return case


def _assert_same(a: Simulation, b: Simulation) -> None:
    for name, arr in a.particles.arrays().items():
        assert np.array_equal(arr, getattr(b.particles, name)), name
    for buf in ("pairs", "walls"):
        pa, pb = getattr(a, buf), getattr(b, buf)
        assert pa.count == pb.count
        for name in ("i", "j", "history", "normal_force", "state"):
            assert np.array_equal(getattr(pa, name)[: pa.count], getattr(pb, name)[: pb.count])
        assert np.array_equal(pa.group_start, pb.group_start)
    assert np.array_equal(a.wall_rows, b.wall_rows)
    assert a.energies() == b.energies()
    assert a.energy_balance_error() == b.energy_balance_error()
    assert a.report() == b.report()
    assert (a.time, a.step_count, a.rebuild_count) == (b.time, b.step_count, b.rebuild_count)
    assert a.rng.bit_generator.state == b.rng.bit_generator.state


@pytest.mark.parametrize(
    ("make", "stop", "total"),
    [
        (drum_case, 230, 700),
        (periodic_thermal_case, 101, 400),
        (reuse_thermal_case, 101, 400),
        (range_thermal_case, 101, 400),
        (indirect_case({"model": "batchelor_obrien_separated"}), 101, 300),
        (indirect_case({"model": "rong_horio1999", "contact_term": True}), 101, 300),
        (indirect_case({"model": "musser2011"}), 101, 300),
        (
            indirect_case(
                {"model": "vargas_mccarthy2002", "filling_angle": 0.2, "liquid_conductivity": 0.6}
            ),
            101,
            300,
        ),  # fmt: skip
        (implicit_thermal_case, 7, 15),
        (exponential_thermal_case, 1, 15),
        (trbdf2_thermal_case, 3, 8),
    ],
    ids=[
        "drum-pour-epsd-moving-wall",
        "periodic-thermal",
        "periodic-conductance-reuse",
        "periodic-range-set",
        "periodic-bob-separated",
        "periodic-rong-horio",
        "periodic-musser",
        "periodic-vargas-mccarthy",
        "frozen-crank-nicolson",
        "frozen-exponential",
        "frozen-tr-bdf2",
    ],
)
def test_restart_is_bit_identical(tmp_path: Path, make, stop: int, total: int) -> None:
    case = case_from_dict(make())
    reference = Simulation(case)
    reference.run(steps=total)
    assert reference.particles.count > 0
    frozen = reference.thermal is not None and reference.thermal.settings.frozen_mechanics
    if frozen:  # the lattice does not touch: heat through the gaps of the range set
        assert reference.thermal.range_set.count > 0
        assert np.ptp(reference.particles.temperature) > 0.0
    else:
        assert reference.contact_count > 0
    if case.thermal is not None and case.thermal.indirect_conduction.model != "none":
        # the gas carries heat between the particles
        assert np.abs(reference.particles.heat_rate_by_mechanism[:, M_INDIRECT]).max() > 0.0

    first = Simulation(case_from_dict(make()))
    first.run(steps=stop)
    path = write_checkpoint(first, tmp_path / checkpoint_name(first.step_count))
    del first
    second = Simulation.from_checkpoint(path)
    assert second.step_count == stop
    second.run(steps=total - stop)
    _assert_same(reference, second)
    if reference.thermal is not None and reference.thermal.range_set is not None and not frozen:
        ra, rb = reference.thermal.range_set, second.thermal.range_set
        assert ra.builds > 1 and ra.count > 0  # rebuilt during the run, pairs in range
        assert (ra.count, ra.builds) == (rb.count, rb.builds)
        assert np.array_equal(ra.i[: ra.count], rb.i[: rb.count])


def test_drum_case_exercises_pouring_and_rolling_history() -> None:
    sim = Simulation(case_from_dict(drum_case()))
    n0 = sim.particles.count
    sim.run(steps=700)
    assert sim.particles.count > n0  # pour batches arrived, one of them after step 230
    assert sim.pourers[0].inserted > 0
    touching = sim.pairs.history[: sim.pairs.count, 6:9]
    assert np.any(touching != 0.0)  # rolling springs carry history
    assert sim.wall_rows[3, 2] < 0.0099  # the lid moved


def test_every_simulation_attribute_is_saved_or_declared_derived() -> None:
    sim = Simulation(case_from_dict(periodic_thermal_case()))
    sim.run(steps=5)
    assert check_complete(sim) == []


def test_checkpoint_file_contents_and_atomic_write(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(drum_case()))
    sim.run(steps=20)
    path = write_checkpoint(sim, tmp_path / "c" / checkpoint_name(20), kind="interrupted")
    assert not list(path.parent.glob("*.tmp"))
    ckpt = read_checkpoint(path)
    assert (ckpt.kind, ckpt.step, ckpt.time) == ("interrupted", 20, sim.time)
    assert ckpt.case() == sim.case
    assert np.array_equal(ckpt.state["particles"]["global_id"], sim.particles.global_id)
    assert list_checkpoints(path.parent) == [path]
    # a failed-state file is for inspection only
    failed = write_checkpoint(sim, tmp_path / "failed.h5", kind="failed")
    with pytest.raises(ConfigError, match="cannot be continued"):
        Simulation.from_checkpoint(failed)


def test_bad_checkpoint_files_give_one_line_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="does not exist"):
        read_checkpoint(tmp_path / "missing.h5")
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    with pytest.raises(ConfigError, match="not a readable HDF5"):
        read_checkpoint(junk)


def test_checkpoint_refuses_an_incompatible_case(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(drum_case()))
    path = write_checkpoint(sim, tmp_path / "c.h5")
    other = drum_case()
    other["contact"]["rolling"] = "none"
    with pytest.raises(ConfigError, match="contact history layout"):
        Simulation.from_checkpoint(path, case=case_from_dict(other))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_resolved_case_round_trips(path: Path) -> None:
    case = load_case(path)
    text = resolved_case_yaml(case)
    again = case_from_dict(yaml.safe_load(text))
    assert again == case
    assert resolved_case_yaml(again) == text


def test_resolved_case_round_trips_thermal_and_model_parameters() -> None:
    data = copy.deepcopy(periodic_thermal_case())
    data["contact"]["rolling"] = {"model": "epsd", "damping_ratio": 0.25}
    case = case_from_dict(data)
    text = resolved_case_yaml(case)
    assert "damping_ratio: 0.25" in text
    assert case_from_dict(yaml.safe_load(text)) == case


def test_restore_with_another_time_step_keeps_the_time(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(drum_case()))
    sim.run(steps=230)
    path = write_checkpoint(sim, tmp_path / "c.h5")
    half = drum_case()
    half["simulation"]["time_step"] = 2.5e-6
    again = Simulation.from_checkpoint(path, case=case_from_dict(half))
    assert again.step_count == 460 and again.time == sim.time
    again.run(steps=10)
    assert again.time == pytest.approx(sim.time + 10 * 2.5e-6, rel=1e-12)
    odd = drum_case()
    odd["simulation"]["time_step"] = 3.0e-6
    with pytest.raises(ConfigError, match="not a whole number of steps"):
        Simulation.from_checkpoint(path, case=case_from_dict(odd))


@pytest.fixture(scope="module")
def good_checkpoint(tmp_path_factory: pytest.TempPathFactory) -> Path:
    sim = Simulation(case_from_dict(periodic_thermal_case()))
    sim.run(steps=3)
    assert sim.pairs.count > 0
    return write_checkpoint(sim, tmp_path_factory.mktemp("ckpt") / "good.h5")


def _damaged(src: Path, dst: Path, change) -> Path:  # noqa: ANN001
    import h5py

    dst.write_bytes(src.read_bytes())
    with h5py.File(dst, "a") as f:
        change(f)
    return dst


def _replace(f, name: str, value) -> None:  # noqa: ANN001
    import h5py

    del f[name]
    dtype = h5py.string_dtype() if isinstance(value, str) else None
    f.create_dataset(name, data=value, dtype=dtype)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda f: f.attrs.__delitem__("kind"), "attribute(s) kind missing"),
        (lambda f: f.__delitem__("walls"), "it has no walls"),
        (lambda f: _replace(f, "scalars_json", "{not json"), "scalars are not valid JSON"),
        (lambda f: _replace(f, "case_yaml", "a: [1,"), "stored case is not valid YAML"),
        (lambda f: _replace(f, "case_yaml", "- just\n- a list\n"), "not a mapping of sections"),
        (lambda f: _replace(f, "scalars_json", '{"time": 0.0}'), "scalar(s) step_count"),
        (lambda f: _replace(f, "particles/velocity", np.zeros((3, 3))), "'velocity' has shape"),
        (lambda f: _replace(f, "pairs/history", np.zeros((0, 6))), "'history' has 0 rows"),
        (lambda f: _replace(f, "pairs/group_start", np.array([0, 5, 2])), "out of order"),
        (lambda f: f.__delitem__("thermal/arrays"), "it has no thermal/arrays"),
        (lambda f: f["particles/type_id"].__setitem__(0, 5),
         "particle 0 has material index 5, but there are 2 materials (glass, steel)"),
        (lambda f: f["particles/global_id"].__setitem__(1, f["particles/global_id"][0]),
         "is held by two particles"),
        (lambda f: f["particles/global_id"].__setitem__(0, 10**6), "(next_global_id)"),
        (lambda f: f["particles/temperature"].__setitem__(2, np.nan),
         "particle array 'temperature': the value of particle 2"),
        (lambda f: f["particles/position"].__setitem__((1, 0), np.inf),
         "particle array 'position': the value of particle 1"),
        (lambda f: f["particles/radius"].__setitem__(0, 0.0), "it must be finite and > 0"),
    ],
    ids=["attr", "group", "json", "yaml", "yaml-list", "scalar", "short", "pairs", "groups",
         "thermal", "type-id", "duplicate-id", "id-range", "nan-temperature", "inf-position",
         "zero-radius"],
)  # fmt: skip
def test_damaged_checkpoints_are_refused_when_read(
    tmp_path: Path, good_checkpoint: Path, change, expected
) -> None:
    """Every kind of damage is one ConfigError naming the file (before anything is built)."""
    read_checkpoint(good_checkpoint)  # the undamaged file passes
    bad = _damaged(good_checkpoint, tmp_path / "bad.h5", change)
    with pytest.raises(ConfigError, match="damaged or incomplete") as err:
        read_checkpoint(bad)
    assert expected in str(err.value) and str(bad) in str(err.value)


def test_a_failed_state_with_non_finite_values_is_still_readable(
    tmp_path: Path, good_checkpoint: Path
) -> None:
    """failed.h5 holds the state that stopped a run (NaN included): readable for inspection
    (export), never continued."""
    import h5py

    def failed(f) -> None:  # noqa: ANN001
        f.attrs["kind"] = "failed"
        f["particles/temperature"][0] = np.nan

    bad = _damaged(good_checkpoint, tmp_path / "failed.h5", failed)
    assert np.isnan(read_checkpoint(bad).state["particles"]["temperature"][0])
    with pytest.raises(ConfigError, match="cannot be continued"):
        Simulation.from_checkpoint(bad)
    with h5py.File(bad) as f:
        assert f.attrs["kind"] == "failed"


def test_a_short_stored_conductance_array_is_refused(tmp_path: Path, good_checkpoint: Path) -> None:
    """The stored per-pair conductances (frozen mechanics reuses them) must cover the pair
    list: a short array would be read past its end by the heat-only pass."""
    bad = _damaged(
        good_checkpoint,
        tmp_path / "bad.h5",
        lambda f: _replace(f, "thermal/arrays/pair_conductance", np.zeros(3)),
    )
    with pytest.raises(ConfigError, match="thermal array 'pair_conductance' has shape"):
        Simulation.from_checkpoint(bad)


@pytest.mark.parametrize("frozen", [False, True], ids=["moving", "frozen"])
def test_restart_with_a_changed_conductivity_uses_the_new_case(tmp_path: Path, frozen) -> None:
    """``thermodem run CASE --restart CKPT`` with another thermal conductivity: the model
    tables are the new case's (not the checkpoint's), and the conductances a frozen run kept
    are evaluated again. Batchelor & O'Brien's H = 4 k r_c: every contact heat rate × 50."""
    data = {
        "simulation": {"time_step": 5.0e-6, "end_time": 1.0, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {"glass": dict(GLASS), "steel": dict(GLASS, thermal_conductivity=20.0)},
        "walls": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1],
                   "material": "steel", "thermal": {"kind": "fixed", "temperature": 350.0}}],
        "insertion": [{"kind": "list", "material": "glass", "radius": 0.001,
                       "positions": [[0.005, 0.005, 0.00099], [0.005, 0.005, 0.00297]],
                       "temperatures": [300.0, 320.0]}],
        "thermal": {"direct_conduction": "batchelor_obrien_simple", "contact_radius": "geometric"},
    }  # fmt: skip
    if frozen:
        data["thermal"].update(frozen_mechanics=True, time_step=1e-3)
    sim = Simulation(case_from_dict(data))
    sim.run(steps=3)
    path = write_checkpoint(sim, tmp_path / "c.h5")
    if frozen:
        assert sim.thermal.conductance_ready
    faster = copy.deepcopy(data)
    for material in faster["materials"].values():
        material["thermal_conductivity"] *= 50.0
    same = Simulation.from_checkpoint(path)
    changed = Simulation.from_checkpoint(path, case=case_from_dict(faster))
    fresh = Simulation(case_from_dict(faster))
    assert np.array_equal(changed.thermal.conduction_table, fresh.thermal.conduction_table)
    assert not np.array_equal(same.thermal.conduction_table, fresh.thermal.conduction_table)
    same.run(steps=1)
    changed.run(steps=1)
    from thermodem.state import heat

    for column in (heat.M_DIRECT, heat.M_WALL_DIRECT):
        a = same.particles.heat_rate_by_mechanism[:, column]
        b = changed.particles.heat_rate_by_mechanism[:, column]
        assert np.any(a != 0.0)
        assert b == pytest.approx(50.0 * a, rel=1e-12, abs=1e-300)
