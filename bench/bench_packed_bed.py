"""Packed-bed benchmark: particle-steps per second and peak memory on a settled bed.

N spheres (R = 1 mm, ρ = 2500 kg/m³, E = 1e7 Pa, ν = 0.3, e = 0.5, μ = 0.5, Hertz–Mindlin,
gravity, dt = 5e-6 s) are poured into an open box and settled; the settled bed is cached in
``bench/.cache``. Then, in a fresh process, S steps are timed on the settled bed.

    python bench/bench_packed_bed.py --n 50000 --steps 500 --threads 1 [--json]
    python bench/bench_packed_bed.py --heat batchelor_obrien_simple [--substeps 1|n|auto]

With ``--heat MODEL`` the bed conducts heat (contact radius: geometric) with that direct
conduction model, solved every ``--substeps`` mechanical steps (default 1: every step, the
spec's calculation cycle). ``--conductance-tolerance TOL`` sets
``thermal.conductance_force_tolerance`` (default 0: every contact evaluated at every step).
``--convection MODEL`` adds convection to air at 300 K flowing upwards at 0.5 m/s (uniform)
with the local porosity of ``--porosity`` (cell, shell or global; default cell), and
``--radiation MODEL`` a radiation model (e.g. krause2017), both per-particle terms on top of the
direct conduction (issue 13: gunn1978 + cell + krause2017 on top of batchelor_obrien_simple).

Settling uses the same materials with a softer damping (e = 0.1) and dt = 1e-5 s to get to rest
faster; the timed run uses exactly the parameters above.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

CACHE = Path(__file__).parent / ".cache"
RADIUS = 1e-3


TILE_BASE = 50000


def bed_geometry(n: int) -> tuple[float, float, float, int]:
    """(box side, box height, fill height, tiles per axis) of the bed of n spheres.

    Beds of k² × 50,000 spheres are the settled 50,000-sphere bed tiled k × k side by side
    (settling 200,000 spheres from scratch would take most of an hour on 2 cores).
    """
    tiles = int(round(np.sqrt(n / TILE_BASE))) if n > TILE_BASE else 1
    if tiles > 1 and tiles * tiles * TILE_BASE != n:
        tiles = 1
    base = n // (tiles * tiles)
    side = max((base * (2 * RADIUS) ** 3 / 0.6 / 0.5) ** (1 / 3), 20 * RADIUS)
    height_bed = base * (4 / 3 * np.pi * RADIUS**3) / 0.6 / side**2
    fill_height = 2.2 * height_bed + 4 * RADIUS  # random insertion at ~0.27 solid fraction
    return tiles * side, fill_height + 4 * RADIUS, fill_height, tiles


THERMAL_PROPERTIES = {
    "thermal_conductivity": 1.0, "specific_heat": 800.0, "microhardness": 3e9,
    "surface_roughness": 1e-6, "surface_slope": 0.1, "thermal_accommodation": 0.8,
    "youngs_modulus_real": 7e10,
}  # fmt: skip
# thermal.gas of the runs with these models (the others use the default, air at 300 K)
HEAT_GAS = {"batchelor_obrien_complete": {"thermal_conductivity": 0.026},
            "batchelor_obrien_modified": {"thermal_conductivity": 0.026}}  # fmt: skip


def case_dict(
    n: int,
    positions_file: str | None,
    dt: float,
    restitution: float,
    end_time: float,
    heat: str | None = None,
    substeps: str = "1",
    tolerance: float = 0.0,
    convection: str | None = None,
    porosity: str = "cell",
    radiation: str | None = None,
) -> dict:
    side, height, fill_height, _ = bed_geometry(n)
    material = {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": restitution,
        "sliding_friction": 0.5,
    }
    case = {
        "simulation": {"time_step": dt, "end_time": end_time, "seed": 7},
        "domain": {"lower": [0, 0, 0], "upper": [side, side, height]},
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "none"},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [side, side, height],
                "open_top": True,
                "material": "glass",
            }
        ],
        "output": {"vtu": False},
    }
    if heat is not None:
        material.update(THERMAL_PROPERTIES)
        case["thermal"] = {
            "direct_conduction": heat,
            "gas": HEAT_GAS.get(heat, {}),
            "contact_radius": "geometric",
            "substeps": substeps if substeps == "auto" else int(substeps),
            "conductance_force_tolerance": tolerance,
            "initial_temperature": {"kind": "expression", "expression": "300 + 1000 * z"},
        }
        if convection:
            case["thermal"]["convection"] = convection
            case["thermal"]["fluid"] = {"temperature": 300.0, "velocity": [0.0, 0.0, 0.5]}
        if convection or radiation:
            porosity_case = {"global": {"kind": "global", "value": 0.4},
                             "cell": {"kind": "cell"}, "shell": {"kind": "shell"}}  # fmt: skip
            case["thermal"]["porosity"] = porosity_case[porosity]
        if radiation:
            material["emissivity"] = 0.9
            case["thermal"]["radiation"] = {"model": radiation}
            if radiation == "surroundings":
                case["thermal"]["radiation"]["environment_temperature"] = 300.0
    if positions_file is None:
        case["insertion"] = [
            {
                "kind": "random_box",
                "material": "glass",
                "count": n,
                "distribution": {"kind": "mono", "radius": RADIUS},
                "lower": [0, 0, 0],
                "upper": [side, side, fill_height],
            }
        ]
    else:
        case["insertion"] = [{"kind": "file", "material": "glass", "path": positions_file}]
    return case


def settle(n: int) -> Path:
    """Settle N spheres under gravity (cached)."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    path = CACHE / f"bed_{n}.txt"
    if path.exists():
        return path
    CACHE.mkdir(parents=True, exist_ok=True)
    side, _, _, tiles = bed_geometry(n)
    if tiles > 1:
        from thermodem.geometry.insertion import load_particle_file

        base = load_particle_file(settle(n // (tiles * tiles)), "glass")
        step = side / tiles
        pos = np.concatenate(
            [base.position + [a * step, b * step, 0.0] for a in range(tiles) for b in range(tiles)]
        )
        rad = np.tile(base.radius, tiles * tiles)
        save_particle_file(path, InsertedParticles(pos, rad, np.zeros_like(pos), None, "glass"))
        return path
    case = case_from_dict(case_dict(n, None, 1e-5, 0.1, 1.0))
    sim = Simulation(case)
    t0 = time.perf_counter()
    while True:
        sim.run(steps=2000)
        v = np.sqrt((sim.particles.velocity**2).sum(axis=1))
        print(
            f"settling: t = {sim.time:.3f} s, max speed {v.max():.3g} m/s, mean "
            f"{v.mean():.3g} m/s, {sim.contact_count} contacts "
            f"({time.perf_counter() - t0:.0f} s)",
            flush=True,
        )
        if (v.max() < 0.02 and sim.time > 0.1) or sim.time > 1.0:
            break
    p = sim.particles
    save_particle_file(
        path,
        InsertedParticles(
            p.position.copy(), p.radius.copy(), np.zeros_like(p.velocity), None, "glass"
        ),
    )
    return path


def rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def timed(
    n: int, steps: int, threads: int, heat: str | None, substeps: str = "1", tolerance: float = 0.0,
    convection: str | None = None, porosity: str = "cell", radiation: str | None = None,
) -> dict:  # fmt: skip
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    bed = settle(n)
    # baseline: interpreter + libraries + compiled kernels on a tiny case
    tiny = Simulation(
        case_from_dict(
            case_dict(
                50, None, 5e-6, 0.5, 1.0, heat, substeps, tolerance, convection, porosity, radiation
            )
        ),  # fmt: skip
        threads=threads,
    )
    tiny.run(steps=5)
    baseline = rss_bytes()
    sim = Simulation(
        case_from_dict(
            case_dict(
                n,
                str(bed),
                5e-6,
                0.5,
                1.0,
                heat,
                substeps,
                tolerance,
                convection,
                porosity,
                radiation,
            )
        ),  # fmt: skip
        threads=threads,
    )
    sim.run(steps=20)  # warm-up
    # one neighbour rebuild of the full bed, so that the peak memory includes a rebuild's
    # temporaries (the settled bed itself rarely moves enough to need one)
    sim.rebuild()
    r0 = sim.rebuild_count
    t0 = time.perf_counter()
    sim.run(steps=steps)
    elapsed = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return {
        "n": n,
        "steps": steps,
        "threads": threads,
        "heat": heat,
        "substeps": substeps if heat else None,
        "conductance_force_tolerance": tolerance if heat else None,
        "convection": convection,
        "porosity": porosity if (convection or radiation) else None,
        "radiation": radiation,
        "particle_steps_per_s": n * steps / elapsed,
        "seconds": elapsed,
        "rebuilds": sim.rebuild_count - r0,
        "contacts_per_particle": 2 * sim.contact_count / n,
        "pairs_per_particle": sim.pairs.count / n,
        "peak_rss_mb": peak / 2**20,
        "baseline_rss_mb": baseline / 2**20,
        "bytes_per_particle_above_baseline": (peak - baseline) / n,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=50000)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--threads", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--heat", default=None, help="direct conduction model (thermal issue)")
    ap.add_argument("--substeps", default="1", help="thermal substeps: an integer or 'auto'")
    ap.add_argument(
        "--conductance-tolerance",
        type=float,
        default=0.0,
        help="thermal.conductance_force_tolerance (0: every contact evaluated at every step)",
    )
    ap.add_argument("--convection", default=None, help="convection model (with --heat)")
    ap.add_argument("--porosity", default="cell", choices=["cell", "shell", "global"])
    ap.add_argument("--radiation", default=None, help="radiation model (with --heat)")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        res = timed(
            args.n, args.steps, args.threads[0], args.heat, args.substeps,
            args.conductance_tolerance, args.convection, args.porosity, args.radiation,
        )  # fmt: skip
        print(json.dumps(res))
        return
    settle(args.n)  # in this process, so the timed child starts from the cached bed
    results = []
    for th in args.threads:
        env = dict(os.environ, NUMBA_NUM_THREADS=str(th))
        cmd = [
            sys.executable,
            __file__,
            "--child",
            "--n",
            str(args.n),
            "--steps",
            str(args.steps),
            "--threads",
            str(th),
        ]
        if args.heat:
            cmd += ["--heat", args.heat, "--substeps", args.substeps]
            cmd += ["--conductance-tolerance", str(args.conductance_tolerance)]
            if args.convection:
                cmd += ["--convection", args.convection]
            if args.radiation:
                cmd += ["--radiation", args.radiation]
            cmd += ["--porosity", args.porosity]
        out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
        res = json.loads(out.strip().splitlines()[-1])
        results.append(res)
        if not args.json:
            print(
                f"N = {res['n']}, threads = {th}"
                + (
                    f", heat {res['heat']} (substeps {res['substeps']}, conductance force "
                    f"tolerance {res['conductance_force_tolerance']:g}"
                    + (f", convection {res['convection']}" if res["convection"] else "")
                    + (f", radiation {res['radiation']}" if res["radiation"] else "")
                    + (f", porosity {res['porosity']}" if res["porosity"] else "")
                    + ")"
                    if res["heat"]
                    else ""
                )
                + f": {res['particle_steps_per_s'] / 1e6:.2f} M "
                f"particle-steps/s ({res['steps']} steps, {res['rebuilds']} rebuilds, "
                f"{res['contacts_per_particle']:.2f} contacts/particle, "
                f"{res['pairs_per_particle']:.2f} listed pairs/particle); peak RSS "
                f"{res['peak_rss_mb']:.0f} MB, {res['bytes_per_particle_above_baseline']:.0f}"
                f" B/particle above baseline {res['baseline_rss_mb']:.0f} MB",
                flush=True,
            )
    if args.json:
        print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
