"""MPI benchmark: the settled bed on 1 and 2 ranks (strong scaling, share of communication).

The bed is bench_packed_bed.py's settled 50,000-sphere bed, tiled 2 x 2 for n = 200,000 (its
cache, ``bench/.cache``); the case is bench_packed_bed.py's (R = 1 mm, Hertz-Mindlin, dt =
5e-6 s) with Batchelor & O'Brien simple conduction every step (``--heat none``: mechanics
only). One Numba thread per rank. Each run: 20 untimed steps, then ``--steps`` timed steps;
then, on the same state, the costs the weak-scaling model of docs/mpi.md is made of:

- the halo exchange of this decomposition alone (median of 50 exchanges: the latency and
  bandwidth part without waiting for a slower rank), per ghost;
- an ``Allreduce`` of a few numbers (median of 200);
- gathering one frame and one checkpoint to rank 0 (the output cost) and writing them.

    python bench/bench_mpi.py [--n 200000] [--steps 300] [--ranks 1 2] [--heat MODEL]
        [--bed packed|shared] [--json]

``--bed shared``: the bed settled by another code instead (``../shared/beds/bed50k.txt``,
tiled k x k side by side for n = 50,000 k^2, in a box k times as wide) with that bed's
standard comparison case (bench_shared_bed.py: contact radius from the overlap, the particles
below z = 1.5 mm held at 400 K; ``--heat none``: mechanics only).

The ranks are launched with the venv's own ``mpiexec`` (``pip install mpi4py mpich``).
Timings depend on the load of the machine: the script prints ``uptime`` with them.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def child(args: argparse.Namespace) -> None:
    import bench_packed_bed as bp

    from thermodem.config.load import case_from_dict
    from thermodem.mpi import make_simulation, under_mpi

    heat = None if args.heat == "none" else args.heat
    if args.bed == "shared":
        case = case_from_dict(shared_case(args.n, heat))
    else:
        bed = bp.settle(args.n)
        case = case_from_dict(bp.case_dict(args.n, str(bed), 5e-6, 0.5, 1.0, heat))
    t_build = time.perf_counter()
    sim = make_simulation(case, threads=1)
    t_build = time.perf_counter() - t_build
    sim.run(steps=20)
    mpi = under_mpi()
    comm = sim.comm if mpi else None
    if mpi:
        sim.halo.seconds = sim.reduce_seconds = sim.rebuild_seconds = 0.0
        comm.Barrier()
    r0 = sim.rebuild_count
    t0 = time.perf_counter()
    sim.run(steps=args.steps)
    if mpi:
        comm.Barrier()
    elapsed = time.perf_counter() - t0
    # one neighbour rebuild (a serial one, or migration + ghosts + lists), median of 3
    times = []
    kept = sim.rebuild_seconds if mpi else 0.0  # (the timed steps' share, not these)
    for _ in range(3):
        if mpi:
            comm.Barrier()
        t = time.perf_counter()
        sim.rebuild()
        times.append(time.perf_counter() - t)
    rebuild_s = float(np.median(times))
    if mpi:
        sim.rebuild_seconds = kept
    out = {
        "rebuild_s": rebuild_s,
        "ranks": sim.size if mpi else 1,
        "n": args.n,
        "heat": heat,
        "steps": args.steps,
        "seconds": elapsed,
        "build_seconds": t_build,
        "particle_steps_per_s": args.n * args.steps / elapsed,
        "rebuilds": sim.rebuild_count - r0,
    }
    if mpi:
        summary = sim.halo_summary()
        out.update(summary)
        out["halo_share"] = summary["halo_seconds_mean"] / elapsed
        out["reduce_share"] = summary["reduce_seconds_mean"] / elapsed
        out["rebuild_share"] = summary["rebuild_seconds_mean"] / elapsed
        # the halo exchange alone (no waiting for a slower rank before it)
        times = []
        for _ in range(50):
            comm.Barrier()
            t = time.perf_counter()
            sim.halo.exchange(comm, sim.particles)
            times.append(time.perf_counter() - t)
        ghosts = np.array(comm.allgather(sim.ghost_count))
        out["halo_exchange_s"] = float(np.median(times))
        out["ghosts_per_rank"] = float(ghosts.mean())
        out["halo_s_per_ghost"] = out["halo_exchange_s"] / max(float(ghosts.max()), 1.0)
        times = []
        value, result = np.zeros(3), np.zeros(3)
        from mpi4py import MPI

        for _ in range(200):
            t = time.perf_counter()
            comm.Allreduce(value, result, op=MPI.MAX)
            times.append(time.perf_counter() - t)
        out["allreduce_s"] = float(np.median(times))
        # outputs: one frame and one checkpoint gathered to rank 0, and written
        from thermodem.io.checkpoint import write_checkpoint
        from thermodem.io.vtk import write_particle_frame
        from thermodem.mpi.gather import gathered_view

        with tempfile.TemporaryDirectory() as tmp:
            comm.Barrier()
            t = time.perf_counter()
            view = gathered_view(sim)
            out["gather_frame_s"] = time.perf_counter() - t
            t = time.perf_counter()
            state = sim.state_dict()
            out["gather_checkpoint_s"] = time.perf_counter() - t
            if sim.rank == 0:
                t = time.perf_counter()
                write_particle_frame(Path(tmp) / "frame.vtu", view)
                out["write_frame_s"] = time.perf_counter() - t
                t = time.perf_counter()
                write_checkpoint(sim, Path(tmp) / "c.h5", state=state)
                out["write_checkpoint_s"] = time.perf_counter() - t
        if sim.rank != 0:
            return
    else:
        out["pairs"] = sim.pairs.count
        out["contacts_per_particle"] = 2 * sim.contact_count / args.n
        # the force evaluation alone (force reset, pair passes with the conduction, wall pass,
        # heat terms): the pair-pass cost of the model, per listed pair
        times = []
        for _ in range(5):
            t = time.perf_counter()
            sim._compute_forces(kick=False, contact_dt=0.0)
            times.append(time.perf_counter() - t)
        out["force_s"] = float(np.median(times))
        out["force_s_per_pair"] = out["force_s"] / max(sim.pairs.count, 1)
        out["seconds_per_particle_step"] = elapsed / (args.n * args.steps)
    print(json.dumps(out), flush=True)


def shared_case(n: int, heat: str | None) -> dict:
    """The shared bed tiled k x k (n = 50,000 k^2) and its comparison case, the box k times
    as wide; heat: that case's (BOB simple, bottom layer at 400 K) unless ``heat`` is None."""
    import bench_shared_bed as sb

    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    base = np.loadtxt(sb.BED, comments="#")
    tiles = int(round(np.sqrt(n / len(base))))
    if tiles * tiles * len(base) != n:
        raise SystemExit(f"--bed shared: --n must be {len(base)} k^2, got {n}")
    path = sb.CACHE / f"shared_bed50k_tiled_{tiles}.txt"
    if not path.exists():
        sb.CACHE.mkdir(parents=True, exist_ok=True)
        shifts = [(a * sb.SIDE, b * sb.SIDE, 0.0) for a in range(tiles) for b in range(tiles)]
        pos = np.concatenate([base[:, :3] + shift for shift in shifts])
        rad = np.tile(base[:, 3], tiles * tiles)
        save_particle_file(path, InsertedParticles(pos, rad, np.zeros_like(pos), None, "glass"))
    case = sb.case_dict("region" if heat else "mechanics", None, 1)
    if heat:
        case["thermal"]["direct_conduction"] = heat
    side = tiles * sb.SIDE
    case["domain"]["upper"][:2] = [side, side]
    case["walls"][0]["upper"][:2] = [side, side]
    case["insertion"] = [{"kind": "file", "material": "glass", "path": str(path)}]
    return case


# ------------------------------------------------------------------------ weak-scaling model
def ghosts_per_rank(n: float, halo: float, radius: float, solid_fraction: float, k: int) -> float:
    """Ghosts of the fullest rank of a cube split into k^3 cubes of n particles: an interior
    rank (k >= 3) has all six faces shared, n ((1 + 2h/L)^3 - 1); a corner rank of k = 2
    three, n ((1 + h/L)^3 - 1)."""
    density = solid_fraction / (4.0 / 3.0 * np.pi * radius**3)
    side = (n / density) ** (1.0 / 3.0)
    grow = 2.0 if k >= 3 else 1.0
    return n * ((1.0 + grow * halo / side) ** 3 - 1.0)


def weak_scaling(
    n: float,
    step_per_particle: float,
    pair_cost: float,
    mirror_per_ghost: float,
    halo_per_ghost: float,
    latency: float,
    halo: float = 2.2e-3,
    radius: float = 1e-3,
    solid_fraction: float = 0.6,
    reductions: int = 3,
    ks: tuple[int, ...] = (1, 2, 4, 5, 8, 10),
) -> list[dict]:
    """Time per step of the fullest rank, n particles per rank on P = k^3 ranks (docs/mpi.md):

    T(P) = n c_p                  the serial step of its own particles
         + m c_pair               the mirror pairs, evaluated on both sides (m = m_g g)
         + g b + 2 k_n α          the halo: per ghost, and a send and a receive per neighbour
         + r α log2(P)            r reductions per step (a tree of depth log2 P)

    g: ghosts (ghosts_per_rank), k_n: neighbours (26 for k >= 3, 7 for k = 2)."""
    rows = []
    base = n * step_per_particle
    for k in ks:
        p = k**3
        if p == 1:
            rows.append({"ranks": 1, "ghosts": 0.0, "step_s": base, "efficiency": 1.0})
            continue
        g = ghosts_per_rank(n, halo, radius, solid_fraction, k)
        neighbours = 26 if k >= 3 else 7
        parts = {
            "mirror_s": mirror_per_ghost * g * pair_cost,
            "halo_s": g * halo_per_ghost + 2 * neighbours * latency,
            "reduce_s": reductions * latency * np.log2(p),
        }
        t = base + sum(parts.values())
        rows.append({"ranks": p, "ghosts": g, "step_s": t, "efficiency": base / t, **parts})
    return rows


def print_model(title: str, rows: list[dict]) -> None:
    print(title)
    print("| ranks | ghosts per rank | step [ms] | mirror pairs [ms] | halo [ms] | reductions [ms] "
          "| efficiency |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['ranks']} | {r['ghosts']:.0f} | {1e3 * r['step_s']:.2f} | "
            f"{1e3 * r.get('mirror_s', 0):.3f} | {1e3 * r.get('halo_s', 0):.3f} | "
            f"{1e3 * r.get('reduce_s', 0):.3f} | {r['efficiency']:.3f} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200000)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--ranks", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--heat", default="batchelor_obrien_simple", help="direct conduction or none")
    ap.add_argument(
        "--bed",
        choices=("packed", "shared"),
        default="packed",
        help="bench_packed_bed's bed tiled, or the shared bed (another code's) tiled",
    )
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args)
        return
    if args.bed == "packed":
        import bench_packed_bed as bp

        bp.settle(args.n)  # (cached: the 50k bed, tiled)
    else:
        shared_case(args.n, None)  # (the tiled file, cached, before the ranks read it)
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    bin_dir = Path(sys.executable).parent
    results = []
    for ranks in args.ranks:
        cmd = [sys.executable, __file__, "--child", "--n", str(args.n), "--steps",
               str(args.steps), "--heat", args.heat, "--bed", args.bed]  # fmt: skip
        if ranks > 1:
            cmd = [str(bin_dir / "mpiexec"), "-n", str(ranks), *cmd]
        load = os.getloadavg()[0]
        res = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
        row = json.loads(res.stdout.strip().splitlines()[-1])
        row["load_before"] = load
        results.append(row)
    base = next((r for r in results if r["ranks"] == 1), None)
    for r in results:
        if base is not None:
            r["speedup"] = base["seconds"] / r["seconds"]
    if args.json:
        print(json.dumps(results, indent=1))
        return
    print(f"uptime: {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
    for r in results:
        line = (
            f"n = {r['n']}, {r['ranks']} rank(s), heat {r['heat']}: {r['seconds']:.2f} s for "
            f"{r['steps']} steps, {r['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s"
        )
        if "speedup" in r:
            line += f", speedup {r['speedup']:.2f}"
        if r["ranks"] > 1:
            line += (
                f"; halo {100 * r['halo_share']:.1f} %, reductions (incl. waiting) "
                f"{100 * r['reduce_share']:.1f} %, rebuilds {100 * r['rebuild_share']:.1f} %; "
                f"{r['ghosts_per_rank']:.0f} ghosts per rank, one exchange "
                f"{1e3 * r['halo_exchange_s']:.3g} ms ({1e9 * r['halo_s_per_ghost']:.3g} ns per "
                f"ghost), Allreduce {1e6 * r['allreduce_s']:.3g} us; gather frame "
                f"{r['gather_frame_s']:.3g} s + write {r['write_frame_s']:.3g} s, gather "
                f"checkpoint {r['gather_checkpoint_s']:.3g} s + write "
                f"{r['write_checkpoint_s']:.3g} s"
            )
        print(line + f"; one rebuild {r['rebuild_s']:.3g} s (load {r['load_before']:.1f})")
    two = next((r for r in results if r["ranks"] == 2), None)
    if base is None or two is None:
        return
    mirror_per_ghost = two["mirror_pairs"] / max(two["ghosts"], 1)
    print(
        f"model inputs (measured here): c_p = {1e9 * base['seconds_per_particle_step']:.0f} ns "
        f"per particle-step, force evaluation {1e9 * base['force_s_per_pair']:.1f} ns per listed "
        f"pair, {mirror_per_ghost:.2f} mirror pairs per ghost, halo "
        f"{1e9 * two['halo_s_per_ghost']:.0f} ns per ghost, latency (Allreduce) "
        f"{1e6 * two['allreduce_s']:.1f} us"
    )
    print_model(
        "weak scaling, 1e5 particles per rank, with the inputs measured here:",
        weak_scaling(1e5, base["seconds_per_particle_step"], base["force_s_per_pair"],
                     mirror_per_ghost, two["halo_s_per_ghost"], two["allreduce_s"]),
    )  # fmt: skip


if __name__ == "__main__":
    main()
