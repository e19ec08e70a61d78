"""Make the settled beds of the multi-rank tests (tests/mpi/, tests/data/mpi_bed_*.txt).

500 glass spheres of R = 1 mm (E = 1e7 Pa, ν = 0.3, μ = 0.5, μ_r = 0.05, EPSD rolling,
Hertz-Mindlin), inserted at random in a 14 × 14 mm column and settled under gravity with a
soft damping (e = 0.1, Δt = 1e-5 s) until the fastest sphere is slower than 5 mm/s:

- ``mpi_bed_box.txt``: in an open box (floor and four side walls);
- ``mpi_bed_periodic.txt``: on a floor, periodic in x and y.

    python tools/mpi_test_beds.py [--out tests/data]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "mpi"))

from mpi_cases import bed_case  # noqa: E402


def settle(periodic: bool, out: Path) -> None:
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    case = bed_case(None, periodic=periodic, heat=None, time_step=1e-5, restitution=0.1)
    sim = Simulation(case_from_dict(case))
    speed = np.inf
    while sim.time < 0.1 or speed > 5e-3:
        sim.run(steps=1000)
        speed = float(np.sqrt((sim.particles.velocity**2).sum(axis=1)).max())
        print(f"t = {sim.time:.3f} s: fastest {speed:.3g} m/s, {sim.contact_count} contacts")
    p = sim.particles
    bed = InsertedParticles(p.position.copy(), p.radius.copy(), np.zeros_like(p.velocity), None,
                            "glass")  # fmt: skip
    save_particle_file(out, bed)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("tests/data"))
    args = ap.parse_args()
    for periodic, name in ((False, "mpi_bed_box.txt"), (True, "mpi_bed_periodic.txt")):
        settle(periodic, args.out / name)


if __name__ == "__main__":
    main()
