"""Implicit against explicit heat on the frozen 50k bed (issue 14).

The bed of ``../shared/beds/bed50k.txt`` (50,000 spheres, R = 1 mm, loaded as in
``bench/bench_shared_bed.py``: the same mechanics, so the frozen contact forces are those of
the settled bed), glass-like k = 1 W/(m K), c = 800 J/(kg K), the stagnant-gas resistance
network in air with the roughness, microhardness and accommodation of Lethe's steel heated-bed
example, the particles with centre z < 1.5 mm held at 400 K, the rest starting at 300 K,
adiabatic walls, 4000 s of physical time. Accuracy measure: the mean temperature of the free
particles at 4000 s against a reference (Crank–Nicolson at 20 s and 10 s, Richardson-
extrapolated). For each scheme the time step is halved until that error is below 1e-3 K;
explicit Euler runs at its stability limit and below it.

    python bench/bench_implicit.py [--threads 1] [--end 4000] [--json]

Prints the wall-clock time of each run split into assembly (network, COO → CSR),
preconditioner (AMG setup), solve (CG) and evaluation (the engine's passes), the error, and
the speed-up at equal accuracy. The machine is shared: figures are noisy (±10 %).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from bench_shared_bed import HEIGHT, HOT_Z, SIDE, particle_files  # noqa: E402

TOLERANCE = 1e-3  # K, on the mean temperature


SOLVER = {"preconditioner": "amg", "tolerance": 1e-10, "startup_steps": 0}


def case(scheme: str, dt: float, end: float) -> dict:
    all_path, _, _ = particle_files()
    material = {
        "density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3, "restitution": 0.5,
        "sliding_friction": 0.5, "thermal_conductivity": 1.0, "specific_heat": 800.0,
        "microhardness": 3e9, "surface_roughness": 19e-9, "surface_slope": 0.056,
        "thermal_accommodation": 0.7,
    }  # fmt: skip
    box = {"lower": [-1.0, -1.0, -1.0], "upper": [1.0, 1.0, HOT_Z]}
    return {
        "simulation": {"time_step": 5e-6, "end_time": end, "gravity": [0, 0, -9.81]},
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
        ],  # fmt: skip
        "insertion": [{"kind": "file", "material": "glass", "path": str(all_path)}],
        "output": {"vtu": False},
        "thermal": {
            "direct_conduction": "resistance_network",
            "gas": {
                "thermal_conductivity": 0.027,
                "specific_heat": 1006.0,
                "dynamic_viscosity": 1.85e-5,
                "heat_capacity_ratio": 1.0,
                "mean_free_path": 68e-9,
            },  # fmt: skip
            "frozen_mechanics": True,
            "time_step": dt,
            "scheme": scheme,
            "implicit": dict(SOLVER),
            "initial_temperature": {"kind": "uniform", "value": 300.0},
            "fixed_temperature": [{"select": {"region": box}, "temperature": 400.0}],
            "stability": {"allow_unstable": False},
        },
    }


THREADS = {"n": 1}


def run(scheme: str, dt: float, end: float) -> dict:
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    t0 = time.perf_counter()
    sim = Simulation(case_from_dict(case(scheme, dt, end)), threads=THREADS["n"])
    build = time.perf_counter() - t0
    th = sim.thermal
    t1 = time.perf_counter()
    sim.run(until=end)
    wall = time.perf_counter() - t1
    free = ~th.fixed
    out = {
        "scheme": scheme, "dt": dt, "steps": sim.step_count, "seconds": wall, "build": build,
        "mean": float(sim.particles.temperature[free].mean()), "limit": th.limit,
    }  # fmt: skip
    if th.implicit is not None:
        tm = th.implicit.timings
        out.update(assembly=tm.assembly, preconditioner=tm.preconditioner, solve=tm.solve,
                   evaluation=tm.evaluation, setups=tm.setups, cg=tm.cg_iterations,
                   solves=tm.solves)  # fmt: skip
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--end", type=float, default=4000.0)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--schemes", nargs="+",
                    default=["explicit", "backward_euler", "crank_nicolson"])  # fmt: skip
    ap.add_argument("--preconditioner", default="amg", choices=["amg", "jacobi"])
    ap.add_argument("--tolerance", type=float, default=1e-10, help="CG relative residual")
    ap.add_argument("--startup", type=int, default=0, help="CN: Rannacher startup steps")
    ap.add_argument("--cn-dt", type=float, nargs="+", default=[160.0, 80.0, 40.0])
    ap.add_argument(
        "--reference",
        type=float,
        default=None,
        help="the reference mean temperature [K] of an earlier run (skips it)",
    )
    args = ap.parse_args()
    THREADS["n"] = args.threads
    SOLVER.update(preconditioner=args.preconditioner, tolerance=args.tolerance,
                  startup_steps=args.startup)  # fmt: skip
    end = args.end
    rows = []
    # warm the compiled kernels (not timed) and find the explicit limit
    probe = run("explicit", 1e-3, 2e-3)
    limit = probe["limit"]
    print(f"explicit stability limit m c/ΣH = {limit:.4g} s", flush=True)
    # reference: CN at 20 s and 10 s, Richardson-extrapolated (CN is second order)
    if args.reference is not None:
        reference = args.reference
        print(f"reference mean {reference:.9f} K (given)", flush=True)
    else:
        ref_a = run("crank_nicolson", 20.0, end)
        ref_b = run("crank_nicolson", 10.0, end)
        reference = (4.0 * ref_b["mean"] - ref_a["mean"]) / 3.0
        print(f"reference mean {reference:.9f} K (CN 20 s {ref_a['mean']:.9f}, 10 s "
              f"{ref_b['mean']:.9f})", flush=True)  # fmt: skip
    for scheme, dts in (
        ("explicit", [0.9 * limit, 0.45 * limit, 0.225 * limit]),
        ("backward_euler", [40.0, 20.0]),
        ("crank_nicolson", args.cn_dt),
    ):
        if scheme not in args.schemes:
            continue
        for dt in dts:
            r = run(scheme, dt, end)
            r["error"] = abs(r["mean"] - reference)
            rows.append(r)
            extra = ""
            if "solve" in r:
                extra = (f" assembly {r['assembly']:.2f} s, AMG setup {r['preconditioner']:.2f}"
                         f" s ({r['setups']}), CG {r['solve']:.2f} s ({r['cg']} it / "
                         f"{r['solves']} solves), passes {r['evaluation']:.2f} s")  # fmt: skip
            print(f"{scheme:15s} dt {dt:9.4g} s  {r['steps']:6d} steps  {r['seconds']:8.2f} s  "
                  f"error {r['error']:.3e} K{extra}", flush=True)  # fmt: skip
            if r["error"] < TOLERANCE:
                break
    best = {}
    for r in rows:
        if r["error"] < TOLERANCE:
            s = r["scheme"]
            best[s] = min(best.get(s, np.inf), r["seconds"])
    # explicit error is first order: if no explicit run reached the tolerance, extrapolate the
    # time of the run that would (error ∝ dt, cost ∝ 1/dt)
    exp_rows = [r for r in rows if r["scheme"] == "explicit"]
    if "explicit" not in best and exp_rows:
        last = exp_rows[-1]
        factor = last["error"] / TOLERANCE
        best["explicit (extrapolated)"] = last["seconds"] * factor
    print("time to 1e-3 K on the mean temperature:", {k: round(v, 2) for k, v in best.items()})
    exp_t = best.get("explicit", best.get("explicit (extrapolated)"))
    for s in ("backward_euler", "crank_nicolson"):
        if s in best and exp_t:
            print(f"  speed-up of {s}: {exp_t / best[s]:.1f}x")
    if args.json:
        print(json.dumps({"reference": reference, "rows": rows, "best": best}))


if __name__ == "__main__":
    main()
