"""Make the packing of the Beaulieu heated bed by DEM (run once; writes bed.txt).

As in Lethe's example, 8849 steel spheres of d = 6.4 mm fill the 0.105 × 0.1 m box: here a
random (non-overlapping, fixed seed) fill of a tall region of that footprint at a volume
fraction of 0.25, at rest, which then falls and settles under gravity with the steel's
(softened, E = 50 MPa) mechanical parameters of common.py, in a box whose walls are of the
same steel. The run goes on in slices of ``--check`` s until the largest speed is below
``--speed`` and the kinetic energy below ``--energy`` (1e-7 J: the criterion for a stable bed
that Lethe's example quotes from Beaulieu); if that does not happen within ``--max-time`` it
stops without writing bed.txt.
The floor the bed rests on becomes the heated wall: the bed is mirrored in z so that the
face carrying the bed's weight is the top, z = 0 at the wall, the bed below it (README: this
is a choice, the experiment's lid load is not published with the set-up).

    python examples/beaulieu_heated_bed/prepare_bed.py [--threads 1]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import FOOTPRINT, HERE, RADIUS, STEEL  # noqa: E402

COUNT = 8849  # spheres in Lethe's example
SEED = 20200  # the random fill's seed (simulation.seed)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--count", type=int, default=COUNT)
    ap.add_argument("--fill", type=float, default=0.25,
                    help="volume fraction of the random fill before the fall")  # fmt: skip
    ap.add_argument("--check", type=float, default=0.05, help="settling checked every [s]")
    ap.add_argument("--min-time", type=float, default=0.4, help="settle at least [s]")
    ap.add_argument("--max-time", type=float, default=3.0, help="give up after [s]")
    ap.add_argument("--speed", type=float, default=1e-2, help="at rest: largest speed [m/s]")
    ap.add_argument("--energy", type=float, default=1e-7, help="at rest: kinetic energy [J]")
    args = ap.parse_args()
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    volume = args.count * 4.0 / 3.0 * np.pi * RADIUS**3
    area = FOOTPRINT[0] * FOOTPRINT[1]
    gap = 1e-4  # m between the fill region and the walls (insertion does not see walls)
    top = gap + volume / (area * args.fill)
    height = top + 0.01
    case = {
        "simulation": {
            "time_step": 2e-5,
            "end_time": args.max_time,
            "gravity": [0, 0, -9.81],
            "seed": SEED,
        },
        "domain": {"lower": [0, 0, 0], "upper": [FOOTPRINT[0], FOOTPRINT[1], height]},
        "materials": {"steel": dict(STEEL)},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "constant_torque"},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [FOOTPRINT[0], FOOTPRINT[1], height],
                "open_top": True,
                "material": "steel",
            }
        ],  # fmt: skip
        "insertion": [
            {
                "kind": "random_box",
                "material": "steel",
                "distribution": {"kind": "mono", "radius": RADIUS},
                "lower": [gap, gap, gap],
                "upper": [FOOTPRINT[0] - gap, FOOTPRINT[1] - gap, top],
                "count": args.count,
            }
        ],
        "output": {"vtu": False},
    }
    wall0 = time.perf_counter()
    sim = Simulation(case_from_dict(case), threads=args.threads)
    p = sim.particles
    built = time.perf_counter() - wall0
    g = 9.81
    pot0 = float(np.sum(p.mass * p.position[:, 2])) * g
    print(f"{p.count} spheres inserted in {built:.1f} s (fill {args.fill}, region height "
          f"{top:.3f} m)", flush=True)  # fmt: skip
    while True:
        sim.run(until=sim.time + args.check)
        p = sim.particles
        speed = float(np.linalg.norm(p.velocity, axis=1).max())
        ke = 0.5 * float(np.sum(p.mass * np.sum(p.velocity**2, axis=1)))
        released = pot0 - float(np.sum(p.mass * p.position[:, 2])) * g
        print(f"t = {sim.time:.3f} s: largest speed {speed:.2e} m/s, kinetic energy "
              f"{ke:.3e} J (the fall released {released:.3g} J), top "
              f"{float(p.position[:, 2].max() + RADIUS):.4f} m, wall time "
              f"{time.perf_counter() - wall0:.0f} s", flush=True)  # fmt: skip
        at_rest = speed < args.speed and ke < args.energy
        if sim.time >= args.min_time - 1e-9 and at_rest:
            break
        if sim.time >= args.max_time - 1e-9:
            sys.exit(f"not at rest after {sim.time:.2f} s (largest speed {speed:.2e} m/s): "
                     "bed.txt not written")  # fmt: skip
    wall = time.perf_counter() - wall0
    x = p.position.copy()
    overlap = float(RADIUS - x[:, 2].min())  # the deepest particle-floor overlap
    x[:, 2] = -x[:, 2]  # mirrored about the floor z = 0: the heated wall, the bed below it
    order = np.argsort(p.global_id)
    out = HERE / "bed.txt"
    with open(out, "w") as f:
        head = (f"# Beaulieu heated bed: {len(x)} spheres d = {2 * RADIUS} m, heated wall z = 0;"
                f" made by prepare_bed.py (random fill at {args.fill}, seed {SEED}, settled "
                f"{sim.time:.2f} s, largest speed {speed:.2e} m/s at the end, largest wall "
                f"overlap {overlap:.3e} m)")  # fmt: skip
        f.write(head + "\nx y z radius\n")
        for i in order:
            f.write(f"{x[i, 0]:.7e} {x[i, 1]:.7e} {x[i, 2]:.7e} {RADIUS!r}\n")
    # porosity by the formula of Lethe's post-processing: 1 - sphere volume / (footprint ×
    # bed depth), the depth here from the heated wall to the bottom of the deepest sphere (the
    # settled bed's top, where a plate would rest; Lethe: the height of its heated top plate);
    # and the porosity of the slab 3-15 cm from the wall (exact sphere-slab volumes), away
    # from the wall's and the surface's layers
    depth = float(-x[:, 2].min() + RADIUS)
    phi = 1.0 - volume / (area * depth)
    a, b = 0.03, 0.15
    h = -x[:, 2]
    cap = lambda s: np.pi * (RADIUS**2 * s - s**3 / 3.0)  # noqa: E731
    inside = cap(np.clip(b - h, -RADIUS, RADIUS)) - cap(np.clip(a - h, -RADIUS, RADIUS))
    bulk = 1.0 - float(inside.sum()) / (area * (b - a))
    print(f"{out}: {len(x)} particles, bed depth {depth:.4f} m, porosity {phi:.4f} "
          f"({bulk:.4f} {a * 100:g}-{b * 100:g} cm from the wall), "
          f"settled {sim.time:.2f} s in {wall:.0f} s of wall time ({sim.step_count} steps), "
          f"largest speed {speed:.2e} m/s, kinetic energy {ke:.2e} J")  # fmt: skip


if __name__ == "__main__":
    main()
