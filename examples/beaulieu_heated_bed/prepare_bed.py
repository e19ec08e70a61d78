"""Make the packing of the Beaulieu heated bed (run once; writes bed.txt).

The packing is not poured here (that takes hours of DEM): it is the shared settled bed of
50,000 equal spheres (``/work/shared/beds/bed50k.txt``, R = 1 mm, 0.09 m square box), scaled
by 3.2 to d = 6.4 mm, cropped to the experiment's 0.105 × 0.1 m footprint away from the old
walls, then settled again for 0.3 s under gravity with the steel's (softened) mechanical
parameters in a box of that footprint, so that the contact forces are those of the steel bed.
The floor it rests on becomes the heated wall: the bed is mirrored in z so that the face
carrying the bed's weight is the top, z = 0 at the wall, the bed below it (README: this is a
choice, the experiment's lid load is not published with the set-up).

    python examples/beaulieu_heated_bed/prepare_bed.py [--bed PATH] [--threads 2]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import FOOTPRINT, HERE, RADIUS, STEEL  # noqa: E402

SCALE = RADIUS / 1e-3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bed", default="/work/shared/beds/bed50k.txt")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--settle", type=float, default=0.3, help="settling time [s]")
    args = ap.parse_args()
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.geometry.insertion import InsertedParticles
    from thermodem.io.particle_file import save_particle_file

    data = np.loadtxt(args.bed, comments="#")
    pos = data[:, :3] * SCALE
    lo = np.array([0.09 * SCALE / 2 - FOOTPRINT[0] / 2, 0.09 * SCALE / 2 - FOOTPRINT[1] / 2])
    inside = np.all((pos[:, :2] - RADIUS >= lo) & (pos[:, :2] + RADIUS <= lo + FOOTPRINT), axis=1)
    pos = pos[inside]
    pos[:, :2] -= lo
    height = float(pos[:, 2].max() + RADIUS)
    tmp = HERE / "_crop.txt"
    save_particle_file(tmp, InsertedParticles(pos, np.full(len(pos), RADIUS),
                                              np.zeros_like(pos), None, "steel"))  # fmt: skip
    case = {
        "simulation": {"time_step": 2e-5, "end_time": args.settle, "gravity": [0, 0, -9.81]},
        "domain": {"lower": [0, 0, 0], "upper": [FOOTPRINT[0], FOOTPRINT[1], height + 0.02]},
        "materials": {"steel": dict(STEEL)},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "constant_torque"},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [FOOTPRINT[0], FOOTPRINT[1], height + 0.02],
                "open_top": True,
                "material": "steel",
            }
        ],  # fmt: skip
        "insertion": [{"kind": "file", "material": "steel", "path": str(tmp)}],
        "output": {"vtu": False},
    }
    sim = Simulation(case_from_dict(case), threads=args.threads)
    sim.run(until=args.settle)
    p = sim.particles
    speed = float(np.linalg.norm(p.velocity, axis=1).max())
    x = p.position.copy()
    overlap = float(RADIUS - x[:, 2].min())  # the deepest particle-floor overlap
    x[:, 2] = -x[:, 2]  # mirrored about the floor z = 0: the heated wall, the bed below it
    order = np.argsort(p.global_id)
    out = HERE / "bed.txt"
    with open(out, "w") as f:
        head = (f"# Beaulieu heated bed: {len(x)} spheres d = {2 * RADIUS} m, heated wall z = 0;"
                f" made by prepare_bed.py (settled {args.settle} s, largest speed {speed:.2e} "
                f"m/s at the end, largest wall overlap {overlap:.3e} m)")  # fmt: skip
        f.write(head + "\nx y z radius\n")
        for i in order:
            f.write(f"{x[i, 0]:.7e} {x[i, 1]:.7e} {x[i, 2]:.7e} {RADIUS!r}\n")
    tmp.unlink()
    depth = float(-x[:, 2].min() + RADIUS)
    phi = 1.0 - len(x) * 4 / 3 * np.pi * RADIUS**3 / (FOOTPRINT[0] * FOOTPRINT[1] * depth)
    print(f"{out}: {len(x)} particles, bed depth {depth:.4f} m, porosity {phi:.4f}, "
          f"largest speed {speed:.2e} m/s")  # fmt: skip


if __name__ == "__main__":
    main()
