"""2D benchmark (issue 16): a settled bed of N discs against bench_packed_bed's 3D bed of N
spheres, particle-steps per second and memory, each in a fresh process, 2D and 3D in turn.

2D bed: discs of R = 0.8-1.2 mm (uniform), 1 mm thick, ρ = 2500 kg/m³, E = 1e7 Pa, ν = 0.3,
e = 0.5, μ = 0.5, the 2D defaults hertz_2d + linear tangential, no rolling resistance, gravity
along -y, Δt = 5e-6 s, in a box open at the top. N/4 discs are settled in a box of a quarter
of the width (e = 0.1, Δt = 1e-5 s, cached in ``bench/.cache``) and the settled bed is tiled
4 times side by side (as bench_packed_bed tiles its 3D bed above 50,000). 3D bed: the one of
``bench/bench_packed_bed.py`` (Hertz–Mindlin, R = 1 mm), mechanics only.

    python bench/bench_2d.py --n 50000 --steps 500 --threads 1 [--rounds 2] [--json]

The target of the issue: 2D throughput >= 2 × 3D per particle at equal N. Figures depend on
the machine's load: ``uptime`` is printed with them; rerun on a quiet machine.
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
R_MIN, R_MAX = 0.0008, 0.0012
THICKNESS = 0.001
TILES = 4
AREA_FRACTION_BED = 0.82  # of a settled polydisperse disc bed (about)


def geometry(n: int) -> tuple[float, float, float]:
    """(tile width, box height, fill height) of the 2D bed of n discs (n/TILES per tile)."""
    per_tile = n // TILES
    mean_area = np.pi * (R_MIN**2 + R_MIN * R_MAX + R_MAX**2) / 3.0
    bed_area = per_tile * mean_area / AREA_FRACTION_BED
    width = float(np.sqrt(bed_area / 0.5))  # the bed about half as high as wide
    fill = per_tile * mean_area / 0.42 / width  # random insertion at an area fraction 0.42
    return width, fill + 0.02, fill


def case_2d(
    n: int, path: str | None, dt: float, restitution: float, width: float, count: int = 0
) -> dict:
    """The 2D case of the bed of ``n`` discs in a box ``width`` wide: ``count`` discs inserted
    at random (settling), or the discs of the file ``path``."""
    _, height, fill = geometry(n)
    material = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
                "restitution": restitution, "sliding_friction": 0.5}  # fmt: skip
    case = {
        "simulation": {"time_step": dt, "end_time": 1.0, "seed": 7, "dimension": 2,
                       "thickness": THICKNESS},
        "domain": {"lower": [0.0, 0.0], "upper": [width, height]},
        "materials": {"glass": material},
        "contact": {"normal": "hertz_2d", "tangential": "linear", "rolling": "none"},
        "walls": [{"kind": "box", "lower": [0, 0], "upper": [width, height], "open_top": True,
                   "material": "glass"}],
        "output": {"vtu": False},
    }  # fmt: skip
    if path is None:
        case["insertion"] = [
            {"kind": "random_box", "material": "glass", "count": count, "lower": [0, 0],
             "upper": [width, fill],
             "distribution": {"kind": "uniform", "min_radius": R_MIN, "max_radius": R_MAX}}
        ]  # fmt: skip
    else:
        case["insertion"] = [{"kind": "file", "material": "glass", "path": path}]
    return case


def settle(n: int) -> Path:
    """The settled 2D bed of n discs (cached): n/TILES settled, tiled TILES times along x."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    path = CACHE / f"bed2d_{n}.txt"
    if path.exists():
        return path
    CACHE.mkdir(parents=True, exist_ok=True)
    width, _, _ = geometry(n)
    per_tile = n // TILES
    sim = Simulation(case_from_dict(case_2d(n, None, 1e-5, 0.1, width, per_tile)))
    t0 = time.perf_counter()
    while True:
        sim.run(steps=2000)
        v = np.sqrt((sim.particles.velocity**2).sum(axis=1))
        print(
            f"settling {sim.particles.count} discs: t = {sim.time:.3f} s, max speed "
            f"{v.max():.3g} m/s ({time.perf_counter() - t0:.0f} s)",
            flush=True,
        )
        if (v.max() < 0.02 and sim.time > 0.1) or sim.time > 1.5:
            break
    p = sim.particles
    pos = np.concatenate([p.position + [k * width, 0.0, 0.0] for k in range(TILES)])
    rad = np.tile(p.radius, TILES)
    tiled = CACHE / f"bed2d_{n}_tiled.txt"
    np.savetxt(tiled, np.column_stack([pos[:, :2], rad]), header="x y r", comments="")
    # the tiles' sides had walls: let the tiled bed settle at the seams too
    sim = Simulation(case_from_dict(case_2d(n, str(tiled), 1e-5, 0.1, TILES * width)))
    while True:
        sim.run(steps=1000)
        v = np.sqrt((sim.particles.velocity**2).sum(axis=1))
        print(f"settling the tiled bed: t = {sim.time:.3f} s, max speed {v.max():.3g} m/s ("
              f"{time.perf_counter() - t0:.0f} s)", flush=True)  # fmt: skip
        if v.max() < 0.005 or sim.time > 0.3:
            break
    p = sim.particles
    np.savetxt(path, np.column_stack([p.position[:, :2], p.radius]), header="x y r", comments="")
    tiled.unlink()
    return path


def rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def timed_2d(n: int, steps: int, threads: int) -> dict:
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    bed = settle(n)
    width, _, _ = geometry(n)
    tiny = Simulation(case_from_dict(case_2d(n, None, 5e-6, 0.5, 0.02, 50)), threads=threads)
    tiny.run(steps=5)
    baseline = rss_bytes()
    sim = Simulation(case_from_dict(case_2d(n, str(bed), 5e-6, 0.5, TILES * width)), threads)
    sim.run(steps=20)  # warm-up
    sim.rebuild()  # the peak memory includes a rebuild's temporaries
    r0 = sim.rebuild_count
    t0 = time.perf_counter()
    sim.run(steps=steps)
    elapsed = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    count = sim.particles.count
    return {
        "dimension": 2,
        "n": count,
        "steps": steps,
        "threads": threads,
        "particle_steps_per_s": count * steps / elapsed,
        "seconds": elapsed,
        "rebuilds": sim.rebuild_count - r0,
        "contacts_per_particle": 2 * sim.contact_count / count,
        "pairs_per_particle": sim.pairs.count / count,
        "peak_rss_mb": peak / 2**20,
        "bytes_per_particle_above_baseline": (peak - baseline) / count,
    }


def child(cmd: list[str], threads: int) -> dict:
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=50000)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--threads", type=int, nargs="*", default=[1])
    ap.add_argument("--rounds", type=int, default=1, help="2D/3D pairs per thread count")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(timed_2d(args.n, args.steps, args.threads[0])))
        return
    settle(args.n)
    bench3d = str(Path(__file__).parent / "bench_packed_bed.py")
    subprocess.run([sys.executable, bench3d, "--n", str(args.n), "--steps", "1", "--threads",
                    "1"], check=True, capture_output=True)  # (settles the 3D bed once)  # fmt: skip
    results = []
    for th in args.threads:
        for _ in range(args.rounds):
            load = uptime()
            two = child([sys.executable, __file__, "--child", "--n", str(args.n), "--steps",
                         str(args.steps), "--threads", str(th)], th)  # fmt: skip
            three = child([sys.executable, bench3d, "--child", "--n", str(args.n), "--steps",
                           str(args.steps), "--threads", str(th)], th)  # fmt: skip
            ratio = two["particle_steps_per_s"] / three["particle_steps_per_s"]
            results.append({"uptime": load, "2d": two, "3d": three, "ratio_2d_3d": ratio})
            if not args.json:
                print(load)
                for res in (two, three):
                    dim = res.get("dimension", 3)
                    print(
                        f"{dim}D N = {res['n']}, threads = {th}: "
                        f"{res['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s "
                        f"({res['steps']} steps, {res['rebuilds']} rebuilds, "
                        f"{res['contacts_per_particle']:.2f} contacts/particle, "
                        f"{res['pairs_per_particle']:.2f} listed pairs/particle); peak RSS "
                        f"{res['peak_rss_mb']:.0f} MB, "
                        f"{res['bytes_per_particle_above_baseline']:.0f} B/particle above "
                        "baseline"
                    )
                print(f"2D / 3D per particle: {ratio:.2f} (target >= 2)", flush=True)
    if args.json:
        print(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
