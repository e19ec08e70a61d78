"""Per-contact output (engine/contacts.py, ``sim.contacts()``, ``output.contacts``) against
the closed forms it reports: the Hertz force of a static overlap, the geometric contact
radius, Batchelor & O'Brien's contact conductance and the heat rate, for a particle pair and
a particle on a hot wall; the VTU frame reads back with the same arrays."""

from __future__ import annotations

import math
from pathlib import Path

import meshio
import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.runner import run_case
from thermodem.engine.simulation import Simulation

R, E, NU, K = 1e-3, 1e7, 0.3, 2.0
D_PAIR, D_WALL = 2e-5, 1e-5


def _case(tmp_path: Path) -> dict:
    rows = [
        (0.005, 0.005, 0.005, 300.0),
        (0.005 + 2 * R - D_PAIR, 0.005, 0.005, 350.0),
        (0.002, 0.002, R - D_WALL, 320.0),
    ]
    path = tmp_path / "three.txt"
    path.write_text(
        "x y z radius temperature\n" + "".join(f"{x} {y} {z} {R} {t}\n" for x, y, z, t in rows)
    )
    glass = {"density": 2500.0, "youngs_modulus": E, "poisson_ratio": NU, "restitution": 0.5,
             "thermal_conductivity": K, "specific_heat": 800.0}  # fmt: skip
    return {
        "simulation": {"time_step": 1e-6, "end_time": 1e-5, "gravity": [0, 0, 0]},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {"glass": glass},
        "walls": [
            {
                "kind": "plane",
                "point": [0, 0, 0],
                "normal": [0, 0, 1],
                "material": "glass",
                "thermal": {"kind": "fixed", "temperature": 400.0},
            }
        ],
        "insertion": [{"kind": "file", "material": "glass", "path": str(path)}],
        "thermal": {"direct_conduction": "batchelor_obrien_simple", "contact_radius": "geometric"},
        "output": {"contacts": True, "interval": 2e-6},
    }


def test_contacts_report_forces_radii_conductances_and_heat(tmp_path: Path) -> None:
    sim = Simulation(case_from_dict(_case(tmp_path)))
    c = sim.contacts()
    assert c["id_i"].tolist() == [0, 2] and c["id_j"].tolist() == [1, -1]
    assert c["wall"].tolist() == [-1, 0]
    e_star = E / (2 * (1 - NU**2))
    for row, r_eff, delta in ((0, R / 2, D_PAIR), (1, R, D_WALL)):
        assert c["overlap"][row] == pytest.approx(delta, rel=1e-9)
        hertz = 4 / 3 * e_star * math.sqrt(r_eff) * delta**1.5
        assert c["normal_force"][row] == pytest.approx(hertz, rel=1e-9)
    d = 2 * R - D_PAIR
    a_pair = math.sqrt(R**2 - (d / 2) ** 2)  # equal spheres: the circle at mid-distance
    a_wall = math.sqrt(R**2 - (R - D_WALL) ** 2)
    assert c["contact_radius"] == pytest.approx([a_pair, a_wall], rel=1e-9)
    h = 4 * (K * K / (K + K)) * np.array([a_pair, a_wall])  # Batchelor & O'Brien simple
    assert c["conductance_direct_conduction"] == pytest.approx(h, rel=1e-12)
    dt = np.array([350.0 - 300.0, 400.0 - 320.0])
    assert c["heat_rate_direct_conduction"] == pytest.approx(h * dt, rel=1e-12)
    assert c["point"][0] == pytest.approx([0.005 + R - D_PAIR / 2, 0.005, 0.005])
    assert c["point"][1] == pytest.approx([0.002, 0.002, 0.0])
    assert c["normal"][1] == pytest.approx([0.0, 0.0, -1.0])
    # the engine's own heat rates are these contacts' sums
    p = sim.particles
    order = np.argsort(p.global_id)
    assert p.heat_rate_by_mechanism[order[0], 0] == pytest.approx(h[0] * 50.0, rel=1e-12)


def test_contact_frames_read_back(tmp_path: Path) -> None:
    out = tmp_path / "run"
    run_case(case_from_dict(_case(tmp_path)), out, overwrite=True, progress=False)
    frames = sorted((out / "vtk").glob("contacts_*.vtu"))
    assert len(frames) >= 3 and (out / "contacts.pvd").exists()
    mesh = meshio.read(frames[0])
    assert mesh.cells_dict["line"].shape == (2, 2)
    force = mesh.cell_data_dict["normal_force"]["line"]
    assert np.all(force > 0.0)
    assert set(mesh.cell_data_dict) >= {
        "id_i",
        "conductance_direct_conduction",
        "heat_rate_direct_conduction",
    }
