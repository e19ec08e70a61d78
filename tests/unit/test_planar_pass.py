"""The planar pair pass of 2D cases (kernels/planar_pass.py, docs/two-dimensional.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.kernels import planar_pass
from thermodem.models.mechanics import normal, rolling, tangential

pytestmark = pytest.mark.usefixtures("one_thread")


def agitated_bed(tmp_path: Path) -> dict:
    """20 × 20 discs on a lattice with random velocities in a box (hertz_2d, friction, EPSD
    rolling)."""
    rng = np.random.default_rng(4)
    side, spacing = 20, 0.00505
    xy = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) + 1.0
    xy = xy * spacing
    r = rng.uniform(0.002, 0.0025, len(xy))
    v = rng.uniform(-0.35, 0.35, xy.shape)
    path = tmp_path / "bed.txt"
    np.savetxt(path, np.column_stack([xy, r, v]), header="x y radius vx vy", comments="")
    top = (side + 1) * spacing
    glass = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
             "restitution": 0.5, "sliding_friction": 0.4, "rolling_friction": 0.05}  # fmt: skip
    return {
        "simulation": {"time_step": 4e-6, "end_time": 1.0, "dimension": 2, "thickness": 0.002},
        "domain": {"lower": [0.0, 0.0], "upper": [top, 2.0 * top]},
        "materials": {"glass": glass},
        "contact": {"normal": "hertz_2d", "tangential": "linear", "rolling": "epsd"},
        "walls": [{"kind": "box", "lower": [0, 0], "upper": [top, 2.0 * top],
                   "material": "glass"}],
        "insertion": [{"kind": "file", "material": "glass", "path": str(path)}],
        "output": {"vtu": False},
    }  # fmt: skip


def test_the_planar_pass_gives_the_bits_of_the_3d_pass(tmp_path, monkeypatch) -> None:
    """The planar pass drops the z components, which are exact zeros in the 3D pass: the two
    give the same bits (a colliding bed with friction and rolling resistance)."""
    case = case_from_dict(agitated_bed(tmp_path))
    flat = Simulation(case)
    flat.run(steps=300)
    assert flat._passes[False][0] is planar_pass.planar_pair_pass
    monkeypatch.setattr(planar_pass, "covers", lambda *args: False)
    full = Simulation(case)
    full.run(steps=300)
    assert full._passes[False][0] is not planar_pass.planar_pair_pass
    assert flat.contact_count > 20
    assert flat.energies()["dissipated_rolling_friction"] > 0.0
    a, b = flat.particles, full.particles
    for name in ("position", "velocity", "angular_velocity", "force", "torque"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    n = flat.pairs.count
    assert np.array_equal(flat.pairs.history[:n], full.pairs.history[:n])
    assert flat.energies() == full.energies()


def test_the_planar_pass_covers_the_mechanics_of_discs() -> None:
    discs = (normal.HERTZ_2D, tangential.LINEAR, rolling.EPSD)
    assert planar_pass.covers(False, False, discs)
    assert planar_pass.covers(False, False, (normal.LINEAR, tangential.NONE, rolling.NONE))
    # contact conduction, heat generation, spheres in a plane with their 3D laws: 3D pass
    assert not planar_pass.covers(True, False, discs)
    assert not planar_pass.covers(False, True, discs)
    assert not planar_pass.covers(False, False, (normal.HERTZ, tangential.MINDLIN, 0))
    assert not planar_pass.covers(False, False, (normal.LINEAR, tangential.MINDLIN, 0))
