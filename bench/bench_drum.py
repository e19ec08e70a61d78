"""Rotating-drum benchmark: the cost of heat generation (issue 12) on a flowing bed.

N spheres (R = 1 mm, ρ = 2500 kg/m³, E = 1e7 Pa, ν = 0.3, e = 0.5, μ = 0.5, μ_r = 0.05,
Hertz–Mindlin with EPSD rolling resistance, dt = 5e-6 s) in a horizontal drum (radius 60 mm,
length 100 mm for 50,000 spheres; scaled as N^(1/3) otherwise) turning at 2 rad/s about x,
with two end caps. The spheres start on a simple cubic lattice (spacing 2.05 mm) in the lower
part of the drum and flow for ``--settle`` seconds while the drum turns; that state is cached in
``bench/.cache``. Then, in a fresh process per case, S steps are timed:

- ``mechanics``: no thermal section;
- ``generation``: ``heat_generation: mechanical_dissipation`` (all five mechanisms, the
  conductivity partition on friction only), ``direct_conduction: none``, heat every
  ``--substeps`` steps;
- ``conduction``: ``direct_conduction: batchelor_obrien_simple`` without generation, and
  ``conduction+generation`` with it (the generation's cost on top of conduction).

    python bench/bench_drum.py --n 50000 --steps 300 --threads 1 2 \\
        [--cases mechanics generation conduction conduction+generation] [--substeps 1] \\
        [--rounds 3] [--json]

Prints particle-steps per second (wall clock, and per CPU second of the process, which is less
sensitive to other processes on a shared machine) and the peak memory above the interpreter's
baseline per particle, with the load average.

``--paired`` (issue 12's measure): mechanics and ``generation`` built in one process from the
same bed, warmed up, then timed in alternating blocks of ``--block`` steps (mechanics,
generation, generation, mechanics, ...; both advance in step, so they see the same flow),
each block timed by the process's CPU time (and wall clock); prints the overhead of generation
over mechanics (the ratio of the summed CPU times - 1; the wall-clock one too) and the median
and quartiles of the per-pair block ratios, with the load average, for each thread count of
``--threads``. Short blocks read higher: each switch refills the caches with the other case's
arrays (100 blocks of 10 steps: +1.5 % over 20 blocks of 100 in back-to-back runs).

    python bench/bench_drum.py --paired --threads 1 2 [--blocks 20] [--block 100] [--warmup 100]
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
SPACING = 2.05e-3
BASE = 50000
CASES = ("mechanics", "generation", "conduction", "conduction+generation")


def geometry(n: int) -> tuple[float, float]:
    """(drum radius, drum length) [m] for n spheres (60 mm × 100 mm at 50,000)."""
    scale = (n / BASE) ** (1.0 / 3.0)
    return 0.06 * scale, 0.1 * scale


def lattice(n: int) -> np.ndarray:
    """n lattice sites inside the drum, lowest first (the bed fills the bottom)."""
    radius, length = geometry(n)
    inner = radius - 1.5 * RADIUS
    xs = np.arange(-length / 2 + 1.5 * RADIUS, length / 2 - 1.5 * RADIUS, SPACING)
    ys = np.arange(-inner, inner, SPACING)
    grid = np.array(np.meshgrid(xs, ys, ys, indexing="ij")).reshape(3, -1).T
    grid = grid[grid[:, 1] ** 2 + grid[:, 2] ** 2 < inner**2]
    grid = grid[np.argsort(grid[:, 2], kind="stable")]
    if grid.shape[0] < n:
        raise SystemExit(f"the drum holds only {grid.shape[0]} lattice sites for n = {n}")
    return grid[:n]


def case_dict(n: int, particles: str, case: str, substeps: int, end_time: float = 1.0) -> dict:
    radius, length = geometry(n)
    material = {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": 0.5,
        "sliding_friction": 0.5,
        "rolling_friction": 0.05,
        "thermal_conductivity": 1.0,
        "specific_heat": 800.0,
    }
    margin = 2 * RADIUS
    data = {
        "simulation": {"time_step": 5e-6, "end_time": end_time, "gravity": [0, 0, -9.81],
                       "seed": 3},
        "domain": {"lower": [-length / 2 - margin, -radius - margin, -radius - margin],
                   "upper": [length / 2 + margin, radius + margin, radius + margin]},
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        "walls": [
            {"kind": "cylinder", "center": [0, 0, 0], "axis": [1, 0, 0], "radius": radius,
             "length": length, "angular_velocity": 2.0, "material": "glass"},
            {"kind": "plane", "point": [-length / 2, 0, 0], "normal": [1, 0, 0],
             "material": "glass"},
            {"kind": "plane", "point": [length / 2, 0, 0], "normal": [-1, 0, 0],
             "material": "glass"},
        ],
        "insertion": [{"kind": "file", "material": "glass", "path": particles}],
        "output": {"vtu": False},
    }  # fmt: skip
    if case != "mechanics":
        data["thermal"] = {
            "direct_conduction": "batchelor_obrien_simple"
            if case.startswith("conduction")
            else "none",
            "substeps": substeps,
            "initial_temperature": {"kind": "uniform", "value": 300.0},
        }
        if case.endswith("generation"):
            data["thermal"]["heat_generation"] = {
                "model": "mechanical_dissipation",
                "partition": "conductivity",
                "partition_scope": "friction",
            }
    return data


def settle(n: int, seconds: float) -> Path:
    """The drum after ``seconds`` of flow from the lattice (cached)."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation
    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    path = CACHE / f"drum_{n}_{seconds:g}.txt"
    if path.exists():
        return path
    CACHE.mkdir(parents=True, exist_ok=True)
    start = CACHE / f"drum_{n}_lattice.txt"
    pos = lattice(n)
    save_particle_file(
        start, InsertedParticles(pos, np.full(n, RADIUS), np.zeros_like(pos), None, "glass")
    )
    sim = Simulation(case_from_dict(case_dict(n, str(start), "mechanics", 1)))
    t0 = time.perf_counter()
    while sim.time < seconds - 1e-12:
        sim.run(steps=min(2000, int(round((seconds - sim.time) / sim.dt))))
        v = np.sqrt((sim.particles.velocity**2).sum(axis=1))
        elapsed = time.perf_counter() - t0
        print(f"settling: t = {sim.time:.3f} s, mean speed {v.mean():.3g} m/s, "
              f"{sim.contact_count} contacts ({elapsed:.0f} s)", flush=True)  # fmt: skip
    p = sim.particles
    save_particle_file(
        path, InsertedParticles(p.position.copy(), p.radius.copy(), p.velocity.copy(), None,
                                "glass"),
    )  # fmt: skip
    return path


def rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def timed(n: int, steps: int, threads: int, case: str, substeps: int, bed: Path) -> dict:
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    tiny_bed = CACHE / "drum_tiny.txt"
    if not tiny_bed.exists():
        from thermodem.geometry.insertion import InsertedParticles, save_particle_file

        pos = lattice(n)[:200]
        tiny_particles = InsertedParticles(pos, np.full(200, RADIUS), np.zeros_like(pos), None,
                                           "glass")  # fmt: skip
        save_particle_file(tiny_bed, tiny_particles)
    tiny = Simulation(case_from_dict(case_dict(n, str(tiny_bed), case, substeps)), threads=threads)
    tiny.run(steps=2 * substeps + 5)  # every kernel of the case compiled or loaded
    baseline = rss_bytes()
    sim = Simulation(case_from_dict(case_dict(n, str(bed), case, substeps)), threads=threads)
    sim.run(steps=20)
    sim.rebuild()  # a rebuild's temporaries in the peak
    r0 = sim.rebuild_count
    c0, t0 = time.process_time(), time.perf_counter()
    sim.run(steps=steps)
    c1, t1 = time.process_time(), time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return {
        "n": n,
        "case": case,
        "substeps": substeps if case != "mechanics" else None,
        "steps": steps,
        "threads": threads,
        "particle_steps_per_s": n * steps / (t1 - t0),
        "particle_steps_per_cpu_s": n * steps / (c1 - c0),
        "seconds": t1 - t0,
        "rebuilds": sim.rebuild_count - r0,
        "contacts_per_particle": 2 * sim.contact_count / n,
        "peak_rss_mb": peak / 2**20,
        "bytes_per_particle_above_baseline": (peak - baseline) / n,
        "load": os.getloadavg()[0],
    }


def paired(n: int, bed: Path, threads: int, substeps: int, blocks: int, block: int,
           warmup: int) -> None:  # fmt: skip
    """Mechanics and generation in one process, timed in alternating blocks (``--paired``)."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    sims = {
        case: Simulation(case_from_dict(case_dict(n, str(bed), case, substeps)), threads=threads)
        for case in ("mechanics", "generation")
    }
    for sim in sims.values():
        sim.run(steps=warmup)
    load = os.getloadavg()[0]
    cpu: dict[str, list[float]] = {case: [] for case in sims}
    wall: dict[str, list[float]] = {case: [] for case in sims}
    for b in range(blocks):
        order = list(sims.items()) if b % 2 == 0 else list(sims.items())[::-1]  # (ABBA...)
        for case, sim in order:
            c0, t0 = time.process_time(), time.perf_counter()
            sim.run(steps=block)
            cpu[case].append(time.process_time() - c0)
            wall[case].append(time.perf_counter() - t0)
    mech, gen = np.array(cpu["mechanics"]), np.array(cpu["generation"])
    q1, med, q3 = np.percentile(gen / mech - 1.0, [25, 50, 75])
    wall_over = sum(wall["generation"]) / sum(wall["mechanics"]) - 1.0
    steps = blocks * block
    print(f"threads {threads}, {n} particles, {blocks} blocks of {block} steps, load "
          f"{load:.2f} -> {os.getloadavg()[0]:.2f}: mechanics {1e3 * mech.sum() / steps:.3f} "
          f"ms/step, generation {1e3 * gen.sum() / steps:.3f} ms/step (CPU); generation "
          f"overhead {gen.sum() / mech.sum() - 1.0:+.1%} per CPU s (block ratios: median "
          f"{med:+.1%}, quartiles {q1:+.1%} .. {q3:+.1%}), {wall_over:+.1%} wall clock",
          flush=True)  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=BASE)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--threads", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--cases", nargs="*", default=list(CASES), choices=CASES)
    ap.add_argument("--substeps", type=int, default=1)
    ap.add_argument("--settle", type=float, default=0.1, help="seconds of flow before timing")
    ap.add_argument(
        "--rounds",
        type=int,
        default=1,
        help="rounds of every case in turn; medians and per-round overheads",
    )
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--paired", action="store_true", help="mechanics vs generation, one process")
    ap.add_argument("--blocks", type=int, default=20, help="--paired: timed blocks of each case")
    ap.add_argument("--block", type=int, default=100, help="--paired: steps per block")
    ap.add_argument("--warmup", type=int, default=100, help="--paired: steps before timing")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    bed = settle(args.n, args.settle)
    if args.paired:
        for th in args.threads:
            paired(args.n, bed, th, args.substeps, args.blocks, args.block, args.warmup)
        return
    if args.child:
        res = timed(args.n, args.steps, args.threads[0], args.cases[0], args.substeps, bed)
        print(json.dumps(res))
        return
    rounds = []
    for _ in range(args.rounds):  # interleaved: a slow spell of the machine hits every case
        results = []
        for case in args.cases:
            for th in args.threads:
                env = dict(os.environ, NUMBA_NUM_THREADS=str(th))
                cmd = [sys.executable, __file__, "--child", "--n", str(args.n), "--steps",
                       str(args.steps), "--threads", str(th), "--cases", case, "--substeps",
                       str(args.substeps), "--settle", str(args.settle)]  # fmt: skip
                out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
                results.append(json.loads(out.stdout.strip().splitlines()[-1]))
        rounds.append(results)
        if args.rounds > 1 and not args.json:
            print(f"round {len(rounds)}:")
            report(results)
    if args.json:
        print(json.dumps(rounds if args.rounds > 1 else rounds[0], indent=2))
        return
    if args.rounds == 1:
        report(rounds[0])
        return
    print(f"median of {args.rounds} rounds:")
    median = []
    for k, r in enumerate(rounds[0]):
        row = dict(r)
        for key in ("particle_steps_per_s", "particle_steps_per_cpu_s", "load",
                    "bytes_per_particle_above_baseline"):  # fmt: skip
            row[key] = float(np.median([rnd[k][key] for rnd in rounds]))
        median.append(row)
    report(median)


def report(results: list[dict]) -> None:
    """One line per case and thread count, with the overhead against mechanics."""
    mech = {r["threads"]: r for r in results if r["case"] == "mechanics"}
    for r in results:
        ref = mech.get(r["threads"])
        over = ""
        if ref is not None and r is not ref:
            cost = ref["particle_steps_per_cpu_s"] / r["particle_steps_per_cpu_s"] - 1.0
            over = f"  {100 * cost:+.1f} % per CPU s against mechanics"
        wall = r["particle_steps_per_s"] / 1e6
        cpu = r["particle_steps_per_cpu_s"] / 1e6
        memory = r["bytes_per_particle_above_baseline"]
        contacts = r["contacts_per_particle"]
        print(f"{r['case']:>22} threads {r['threads']}: {wall:.2f} M p-steps/s "
              f"({cpu:.2f} M per CPU s), {memory:.0f} B/particle, "
              f"{contacts:.2f} contacts/particle, load {r['load']:.1f}{over}")  # fmt: skip


if __name__ == "__main__":
    main()
