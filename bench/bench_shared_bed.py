"""Benchmark on the bed settled by another code (``../shared/beds/bed50k.txt``).

The standard comparison case of ``shared/beds/README.md``: 50,000 spheres of R = 1 mm in a
0.09 × 0.09 m open box (floor and four side walls), Hertz–Mindlin, E = 1e7 Pa, ν = 0.3,
e = 0.5, μ = 0.5, ρ = 2500 kg/m³, no rolling resistance, gravity, Δt = 5e-6 s, Verlet skin
0.2 mm; with heat: k = 1 W/(m K), c = 800 J/(kg K), Batchelor & O'Brien simple with the
geometric contact radius, the particles with centre z < 1.5 mm held at 400 K (selected by a
region or by their material), the rest at 300 K, adiabatic walls, heat every step (case
``heat``: no fixed particles, T = 300 K + 1000 K/m × z instead). ``--indirect`` adds an
indirect_conduction model on the range pair set (the issue-10 benchmark: rong_horio1999
with layer_thickness_ratio 0.5 and 1.0, i.e. conducting gaps up to δ_f = 0.5 R̄ and 1.0 R̄
for these equal spheres: Rong & Horio's range is 2 R_p + δ_f > d). 500
untimed steps, then the timed steps; throughput = N × steps / loop seconds.

    python bench/bench_shared_bed.py [--threads 1 2] [--steps 1000] [--warmup 500]
        [--cases mechanics heat region material] [--rounds N] [--phases]
        [--indirect MODEL [--indirect-param KEY=VALUE ...]]
        [--substeps N] [--convection MODEL] [--porosity cell|shell|global]
        [--radiation MODEL] [--frozen DT] [--gap-tolerance TOL] [--json]

``--frozen DT`` freezes the mechanics (every step a thermal step of DT seconds): with
``--indirect voronoi_a`` the 50k bed's tessellation time and the heat pass time per thermal
step (issue 11); the tessellation counts and seconds are printed when a Voronoi model runs.
``--gap-tolerance TOL`` sets ``thermal.tessellation.conductance_gap_tolerance`` (the Voronoi
conductance reuse of a moving bed; the share of the pair evaluations is printed).

``--convection`` adds convection to air at 300 K flowing upwards at 0.5 m/s (uniform) with
the local porosity of ``--porosity`` (default cell), ``--radiation`` a radiation model (e.g.
krause2017; emissivity 0.9), both per-particle terms on top of the heat cases (issue 13:
``--cases region --convection gunn1978 --radiation krause2017`` against ``--cases region``).

Each (case, thread count) runs in a fresh process; prints particle-steps per second (of the
loop's wall time; ``cpu`` is the same figure from the process's CPU time, the steadier one for
1 thread on a machine shared with other work), the peak memory above the interpreter's
baseline per particle and the load average (``/proc/loadavg``, 1 min) before and after. With
``--rounds N`` the cases are run N times interleaved (mechanics, region, material, mechanics,
...); a summary gives per thread count the median throughput of each case, the heat overhead
against mechanics (mechanics throughput / heat throughput - 1) and the 2-thread speed-ups.
``--phases`` prints the per-phase timing of ``Simulation.step`` (``bench/step_phases.py``)
for each run.

The issue-17 target (heat on with fixed particles at most 15 % over mechanics, with the same
2-thread speed-up as mechanics) is read from that summary:

    python bench/bench_shared_bed.py --rounds 3 --steps 1000
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

BED = Path(__file__).resolve().parents[2] / "shared" / "beds" / "bed50k.txt"
CACHE = Path(__file__).parent / ".cache"
SIDE = 0.09
HEIGHT = 0.1
HOT_Z = 1.5e-3


def particle_files(tiny: bool = False) -> tuple[Path, Path, Path]:
    """(all, hot, cold) particle files converted from the shared bed (cached); ``tiny``: the
    same for every 125th particle, 400 over the bed's height, hot and cold ones (the kernels
    are loaded on it before the baseline)."""
    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    CACHE.mkdir(parents=True, exist_ok=True)
    tag = "tiny" if tiny else "bed50k"
    paths = tuple(CACHE / f"shared_{tag}_{k}.txt" for k in ("all", "hot", "cold"))
    if all(p.exists() for p in paths):
        return paths
    data = np.loadtxt(BED, comments="#")
    if tiny:
        data = data[::125]
    pos, rad = data[:, :3], data[:, 3]
    hot = pos[:, 2] < HOT_Z
    for path, sel in zip(paths, (np.ones(len(pos), bool), hot, ~hot), strict=True):
        save_particle_file(
            path, InsertedParticles(pos[sel], rad[sel], np.zeros((sel.sum(), 3)), None, "glass")
        )
    return paths


Terms = tuple[str | None, str, str | None]  # (convection, porosity kind, radiation)


FROZEN = {"dt": 0.0}  # --frozen: the thermal time step of frozen mechanics (0: off)
GAP_TOLERANCE = {"tol": 0.0}  # --gap-tolerance: the Voronoi conductance reuse (0: off)


def case_dict(kind: str, indirect: dict | None, substeps: int, tiny: bool = False,
              terms: Terms = (None, "cell", None)) -> dict:  # fmt: skip
    all_path, hot_path, cold_path = particle_files(tiny)
    material = {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": 0.5,
        "sliding_friction": 0.5,
    }
    heat = kind != "mechanics"
    if heat:
        material.update(thermal_conductivity=1.0, specific_heat=800.0)
    case = {
        "simulation": {"time_step": 5e-6, "end_time": 1.0, "gravity": [0, 0, -9.81]},
        "domain": {"lower": [0, 0, 0], "upper": [SIDE, SIDE, HEIGHT]},
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "none"},
        "neighbors": {"skin": 2e-4},
        "walls": [
            {
                "kind": "box",
                "lower": [0, 0, 0],
                "upper": [SIDE, SIDE, HEIGHT],
                "open_top": True,
                "material": "glass",
            }
        ],
        "insertion": [{"kind": "file", "material": "glass", "path": str(all_path)}],
        "output": {"vtu": False},
    }
    if not heat:
        return case
    thermal = {
        "direct_conduction": "batchelor_obrien_simple",
        "contact_radius": "geometric",
        "substeps": substeps,
        "initial_temperature": {"kind": "uniform", "value": 300.0},
    }
    if kind == "heat":  # no fixed particles: a temperature gradient over the height
        thermal["initial_temperature"] = {"kind": "expression", "expression": "300 + 1000 * z"}
    elif kind == "region":
        box = {"lower": [-1.0, -1.0, -1.0], "upper": [1.0, 1.0, HOT_Z]}
        thermal["fixed_temperature"] = [{"select": {"region": box}, "temperature": 400.0}]
    elif kind == "material":
        case["materials"]["hot"] = dict(material)
        case["insertion"] = [
            {"kind": "file", "material": "hot", "path": str(hot_path)},
            {"kind": "file", "material": "glass", "path": str(cold_path)},
        ]
        thermal["fixed_temperature"] = [{"select": {"material": "hot"}, "temperature": 400.0}]
    if indirect is not None:
        thermal["indirect_conduction"] = indirect
        if GAP_TOLERANCE["tol"] > 0.0:
            thermal["tessellation"] = {"conductance_gap_tolerance": GAP_TOLERANCE["tol"]}
    if FROZEN["dt"] > 0.0:
        thermal.update(frozen_mechanics=True, time_step=FROZEN["dt"])
        thermal.pop("substeps")
    convection, porosity, radiation = terms
    if convection:
        thermal["convection"] = convection
        thermal["fluid"] = {"temperature": 300.0, "velocity": [0.0, 0.0, 0.5]}
    if convection or radiation:
        kinds = {"global": {"kind": "global", "value": 0.4}, "cell": {"kind": "cell"},
                 "shell": {"kind": "shell"}}  # fmt: skip
        thermal["porosity"] = kinds[porosity]
    if radiation:
        for m in case["materials"].values():
            m["emissivity"] = 0.9
        thermal["radiation"] = {"model": radiation}
        if radiation == "surroundings":
            thermal["radiation"]["environment_temperature"] = 300.0
    case["thermal"] = thermal
    return case


def load_average() -> float:
    """The 1-minute load average of the machine."""
    try:
        return float(Path("/proc/loadavg").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return float("nan")


def rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def timed(kind: str, threads: int, steps: int, warmup: int, indirect: dict | None,
          substeps: int, terms: tuple = (None, "cell", None),
          phases: bool = False) -> dict:  # fmt: skip
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    if phases:
        sys.path.insert(0, str(Path(__file__).parent))
        import step_phases

        step_phases.instrument()

    # baseline: interpreter, libraries and the compiled kernels, loaded on a tiny bed
    Simulation(case_from_dict(case_dict(kind, indirect, substeps, True, terms)),
               threads=threads).run(steps=5)  # fmt: skip
    baseline = rss_bytes()
    sim = Simulation(case_from_dict(case_dict(kind, indirect, substeps, False, terms)),
                     threads=threads)  # fmt: skip
    sim.run(steps=warmup)
    if phases:
        step_phases.reset()
    load_before = load_average()
    t0, c0 = time.perf_counter(), time.process_time()
    sim.run(steps=steps)
    elapsed = time.perf_counter() - t0
    cpu = time.process_time() - c0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    n = sim.particles.count
    out = {
        "case": kind,
        "threads": threads,
        "n": n,
        "steps": steps,
        "particle_steps_per_s": n * steps / elapsed,
        "cpu_particle_steps_per_s": n * steps / cpu,
        "seconds": elapsed,
        "cpu_seconds": cpu,
        "load_before": load_before,
        "load_after": load_average(),
        "contacts_per_particle": 2 * sim.contact_count / n,
        "bytes_per_particle_above_baseline": (peak - baseline) / n,
    }
    if sim.thermal is not None:
        out["fixed"] = int(sim.thermal.fixed.sum())
        out["temperature_max"] = float(sim.particles.temperature.max())
        if sim.thermal.range_set is not None:
            out["range_pairs_per_particle"] = sim.thermal.range_set.count / n
        ns = sim.thermal.field_provider.neighbourhood
        if ns is not None:
            out["neighbourhood_pairs_per_particle"] = ns.count / n
        vor = sim.thermal.voronoi
        if vor is not None:
            out["tessellations"] = vor.count
            out["tessellation_seconds"] = vor.seconds
            out["last_tessellation_seconds"] = vor.last_seconds
            out["voronoi_pairs_per_particle"] = sim.thermal.external.count / n
            out["voronoi_evaluated_fraction"] = sim.thermal.summary()["voronoi_evaluated_fraction"]
    out["seconds_per_step"] = elapsed / steps
    if phases:
        out["phases"] = step_phases.report(steps, n)
    return out


def summary(results: list[dict]) -> list[str]:
    """Median throughput per case and thread count, heat overheads and speed-ups."""
    med: dict[tuple[str, int], float] = {}
    for key in {(r["case"], r["threads"]) for r in results}:
        med[key] = float(np.median([r["particle_steps_per_s"] for r in results
                                    if (r["case"], r["threads"]) == key]))  # fmt: skip
    lines = []
    threads = sorted({t for _, t in med})
    for t in threads:
        mech = med.get(("mechanics", t))
        for (case, tt), value in sorted(med.items()):
            if tt != t:
                continue
            line = f"median {case:10s} {t} thread(s): {value / 1e6:6.2f} M particle-steps/s"
            if mech and case != "mechanics":
                line += f", heat overhead {mech / value - 1.0:+.1%} over mechanics"
            one = med.get((case, 1))
            if t > 1 and one:
                line += f", speed-up {value / one:.2f}x over 1 thread"
            lines.append(line)
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--warmup", type=int, default=500)
    ap.add_argument("--cases", nargs="*", default=["mechanics", "region", "material"])
    ap.add_argument("--indirect", default=None, help="an indirect_conduction model")
    ap.add_argument("--indirect-param", nargs="*", default=[], help="KEY=VALUE parameters")
    ap.add_argument("--substeps", type=int, default=1)
    ap.add_argument("--convection", default=None, help="a convection model")
    ap.add_argument("--porosity", default="cell", choices=["cell", "shell", "global"])
    ap.add_argument("--radiation", default=None, help="a radiation model")
    ap.add_argument("--frozen", type=float, default=0.0, help="frozen mechanics, thermal dt [s]")
    ap.add_argument(
        "--gap-tolerance",
        type=float,
        default=0.0,
        help="thermal.tessellation.conductance_gap_tolerance (Voronoi conductance reuse)",
    )
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--rounds", type=int, default=1, help="interleaved repetitions")
    ap.add_argument("--phases", action="store_true", help="per-phase timing of a step")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    FROZEN["dt"] = args.frozen
    GAP_TOLERANCE["tol"] = args.gap_tolerance
    indirect = None
    if args.indirect:
        indirect = {"model": args.indirect}
        for kv in args.indirect_param:
            key, value = kv.split("=", 1)
            indirect[key] = float(value)
    if args.child:
        kind, threads = args.child.split(":")
        terms = (args.convection, args.porosity, args.radiation)
        result = timed(kind, int(threads), args.steps, args.warmup, indirect, args.substeps,
                       terms, args.phases)  # fmt: skip
        print(json.dumps(result))
        return
    particle_files()
    particle_files(tiny=True)
    results = []
    runs = [(k, t) for _ in range(args.rounds) for k in args.cases for t in args.threads]
    for kind, threads in runs:
        cmd = [sys.executable, __file__, "--child", f"{kind}:{threads}",
               "--steps", str(args.steps), "--warmup", str(args.warmup),
               "--substeps", str(args.substeps)]  # fmt: skip
        if args.indirect:
            cmd += ["--indirect", args.indirect, "--indirect-param", *args.indirect_param]
        if args.convection:
            cmd += ["--convection", args.convection]
        if args.radiation:
            cmd += ["--radiation", args.radiation]
        cmd += ["--porosity", args.porosity, "--frozen", str(args.frozen)]
        cmd += ["--gap-tolerance", str(args.gap_tolerance)]
        if args.phases:
            cmd += ["--phases"]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=True)
        result = json.loads(proc.stdout.strip().splitlines()[-1])
        results.append(result)
        if not args.json:
            extra = ""
            if "range_pairs_per_particle" in result:
                extra = f", {result['range_pairs_per_particle']:.2f} range pairs/particle"
            if "tessellations" in result:
                extra += (
                    f", {result['tessellations']} tessellations "
                    f"({result['tessellation_seconds']:.3g} s, last "
                    f"{result['last_tessellation_seconds']:.3g} s), "
                    f"{result['voronoi_pairs_per_particle']:.2f} Voronoi "
                    f"pairs/particle ({100 * result['voronoi_evaluated_fraction']:.1f} % "
                    f"evaluated), {1e3 * result['seconds_per_step']:.3g} ms/step"
                )
            if "neighbourhood_pairs_per_particle" in result:
                extra += (f", {result['neighbourhood_pairs_per_particle']:.2f} "
                          "neighbourhood pairs/particle")  # fmt: skip
            print(
                f"{kind:10s} {threads} thread(s): "
                f"{result['particle_steps_per_s'] / 1e6:6.2f} M particle-steps/s "
                f"(cpu {result['cpu_particle_steps_per_s'] / 1e6:.2f}), "
                f"{result['bytes_per_particle_above_baseline']:.0f} B/particle{extra}, "
                f"load {result['load_before']:.2f} -> {result['load_after']:.2f}",
                flush=True,
            )
            if "phases" in result:
                print(result["phases"], flush=True)
    if args.json:
        print(json.dumps(results, indent=1))
    else:
        for line in summary(results):
            print(line)


if __name__ == "__main__":
    main()
