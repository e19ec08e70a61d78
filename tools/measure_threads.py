"""Measure the cost of a step against the particle count, on 1 and 2 threads, heat off and on.

A jammed cubic bed of N spheres (R = 1 mm, spacing 1.99 R, radii 0.97-1 R: about six contacts
per particle, like a settled bed) in a box, Hertz-Mindlin; with ``--heat`` the floor is held at
400 K and the bed conducts (geometric contact radius, batchelor_obrien_simple, heat every
step). For each N the same simulation is timed on 1 and 2 threads in turn (results do not
depend on the thread count, so switching is legitimate), ``--rounds`` times, and the median
milliseconds per step are printed with a least-squares fit ``t = a + b N`` per thread count
(the per-step overhead ``a`` and the per-particle cost ``b`` that the run time estimate of
``thermodem.engine.validation`` uses) and the smallest N at which 2 threads are faster.

    python tools/measure_threads.py [--heat] [--sizes 125,250,...] [--steps 300] [--rounds 3]

Run it on an idle machine: a neighbouring process on one of the two cores makes 2 threads
look worse than they are.
"""

from __future__ import annotations

import argparse
import math
import statistics
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.geometry.insertion import InsertedParticles, save_particle_file

R0 = 1e-3
SPACING = 1.99 * R0


def shape_for(n: int) -> tuple[int, int, int]:
    side = max(2, int(round(n ** (1 / 3))))
    return side, side, max(1, int(round(n / side**2)))


def build(n: int, heat: bool, directory: Path) -> Simulation:
    shape = shape_for(n)
    rng = np.random.default_rng(7)
    grid = np.stack(np.meshgrid(*(np.arange(k) for k in shape), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * SPACING
    pos += rng.uniform(-0.01, 0.01, pos.shape) * R0
    rad = rng.uniform(0.97 * R0, R0, len(pos))
    vel = rng.normal(0.0, 0.05, pos.shape)
    path = directory / f"bed_{n}.txt"
    save_particle_file(path, InsertedParticles(pos, rad, vel, None, "grain"))
    upper = [shape[0] * SPACING, shape[1] * SPACING, shape[2] * SPACING + 0.01]
    grain = {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": 0.5,
        "sliding_friction": 0.5,
    }
    case = {
        "simulation": {"time_step": 5e-6, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
        "domain": {"lower": [-0.001] * 3, "upper": [u + 0.001 for u in upper]},
        "materials": {"grain": grain},
        "contact": {"normal": "hertz", "tangential": "mindlin"},
        "walls": [
            {
                "kind": "box",
                "material": "grain",
                "lower": [0, 0, 0],
                "upper": upper,
                "open_top": True,
            }
        ],  # fmt: skip
        "insertion": [{"kind": "file", "material": "grain", "path": str(path)}],
    }
    if heat:
        grain.update(thermal_conductivity=50.0, specific_heat=800.0)
        case["walls"][0]["thermal"] = {"kind": "fixed", "temperature": 400.0}
        case["thermal"] = {
            "contact_radius": "geometric",
            "direct_conduction": "batchelor_obrien_simple",
            "substeps": 1,
        }
    return Simulation(case_from_dict(case), threads=1)


def fit(ns: list[int], ts: list[float]) -> tuple[float, float]:
    b, a = np.polyfit(np.asarray(ns, float), np.asarray(ts, float), 1)
    return float(a), float(b)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--heat", action="store_true")
    parser.add_argument("--sizes", default="125,250,500,1000,2000,4000,8000,16000")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", default="1,2", help="thread counts to time (1,2 or 1)")
    args = parser.parse_args()
    counts = [int(t) for t in args.threads.split(",")]
    sizes = [int(s) for s in args.sizes.split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            sim = build(n, args.heat, Path(tmp))
            sim.run(steps=50)
            times: dict[int, list[float]] = {k: [] for k in (1, 2)}
            for _ in range(args.rounds):
                for threads in counts:
                    sim.set_threads(threads)  # (run() applies the simulation's count)
                    t0 = time.perf_counter()
                    sim.run(steps=args.steps)
                    times[threads].append(1e3 * (time.perf_counter() - t0) / args.steps)
            t1, t2 = (statistics.median(times[k] or [math.nan]) for k in (1, 2))
            rows.append((sim.particles.count, sim.pairs.count, sim.contact_count, t1, t2))
            print(
                f"N = {sim.particles.count:6d}  pairs {sim.pairs.count:7d}  contacts "
                f"{sim.contact_count:7d}  1 thread {t1:8.3f} ms/step  2 threads {t2:8.3f} "
                f"ms/step  ({t1 / t2:.2f}x)",
                flush=True,
            )
    ns = [r[0] for r in rows]
    for k, col in ((1, 3), (2, 4)):
        if k not in counts:
            continue
        a, b = fit(ns, [r[col] for r in rows])
        rate = 1e3 / max(b, 1e-12)
        print(f"{k} thread(s): t = {a:.4f} ms + {1e3 * b:.4f} µs × N ({rate:.3g} particle-steps/s)")
    # the smallest N from which 2 threads are faster at every larger N measured
    first = None
    for r in reversed(rows):
        if not r[4] < r[3]:
            break
        first = r[0]
    print(f"layer {numba.threading_layer()}; 2 threads faster from N = {first}")


if __name__ == "__main__":
    main()
