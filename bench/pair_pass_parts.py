"""What the heat adds to the particle pair pass, timed alone on one state.

Runs a case a few hundred steps, captures the arguments of one call of the particle pair
pass, then times that pass (the histories restored before every call, so every call sees the
same state) with and without its heat and against the mechanics-only compiled variant:

- ``--case region``: the shared bed (``bench_shared_bed.py``, Batchelor & O'Brien simple,
  geometric radius, fixed particles): "heat" = the contact conduction in the pass;
- ``--case drum``: the rotating drum (``bench_drum.py``, its cached bed; run that benchmark
  once first): "heat" = the heat generation deposits.

    python bench/pair_pass_parts.py --case region --threads 1 2 [--calls 200] [--rounds 3]

Prints per thread count the median milliseconds per call of (pass with heat, the same
compiled pass with the heat switched off, the mechanics-only pass) and the throughput of
each in particle-steps per second (N / seconds per call); each thread count runs in a fresh
process; then the process's peak memory per particle.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent


def build(case: str, threads: int):  # noqa: ANN201
    """(simulation, captured pair-pass arguments, where the switchable part starts, the
    arguments that switch it off) after a short run."""
    sys.path.insert(0, str(HERE))
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    if case == "region":
        from bench_shared_bed import case_dict

        sim = Simulation(case_from_dict(case_dict("region", None, 1, False)), threads=threads)
    else:
        from bench_drum import case_dict

        bed = HERE / ".cache" / "drum_50000_0.1.txt"
        if not bed.exists():
            raise SystemExit(f"{bed} is missing: run bench/bench_drum.py once first")
        sim = Simulation(case_from_dict(case_dict(50000, str(bed), "generation", 1)),
                         threads=threads)  # fmt: skip
    sim.run(steps=300)
    conducts = sim.thermal.contact.active
    pair_pass, wall_pass = sim._contact_passes(conducts)
    calls: list[tuple] = []

    def spy(*args: object) -> None:
        calls.append(args)
        pair_pass(*args)

    sim._passes[conducts] = (spy, wall_pass)
    sim.run(steps=1)
    sim._passes[conducts] = (pair_pass, wall_pass)
    args = list(calls[-1])
    if case == "region":  # the 13 heat arguments after the ledger rows
        start = next(k for k, a in enumerate(args) if a is True)
        off = list(sim._no_heat)
    else:  # the 4 generation arguments at the end
        start = len(args) - 4
        off = [False, *sim._no_generation]
    return sim, pair_pass, args, start, off


def measure(case: str, threads: int, calls: int, rounds: int) -> None:
    from thermodem.kernels import pair_pass as PP

    sim, pair_pass, args, start, off = build(case, threads)
    switched_off = args[:start] + off + args[start + len(off) :]
    mech_pass, _ = PP.passes_for(False, 0, 0, 0, sim.history_layout.offsets, False,
                                 sim.model_ids)  # fmt: skip
    history = sim.pairs.history.copy()
    n = sim.particles.count

    def timed(fn: object, a: list) -> float:
        times = []
        for _ in range(calls):
            sim.pairs.history[:] = history
            t0 = time.perf_counter()
            fn(*a)  # type: ignore[operator]
            times.append(time.perf_counter() - t0)
        return float(np.median(times))

    for r in range(rounds):
        on = timed(pair_pass, args)
        without = timed(pair_pass, switched_off)
        mech = timed(mech_pass, switched_off)
        print(f"{case} {threads} thread(s) round {r}: heat {1e3 * on:.3f} ms "
              f"({n / on / 1e6:.2f} M p-steps/s), heat off {1e3 * without:.3f} ms, "
              f"mechanics pass {1e3 * mech:.3f} ms ({n / mech / 1e6:.2f} M p-steps/s): "
              f"heat +{1e3 * (on - without):.3f} ms", flush=True)  # fmt: skip
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(f"peak memory of the process {peak / n:.0f} B/particle")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", choices=("region", "drum"), default="region")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--child", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        measure(args.case, args.child, args.calls, args.rounds)
        return
    for threads in args.threads:
        subprocess.run([sys.executable, __file__, "--case", args.case, "--calls",
                        str(args.calls), "--rounds", str(args.rounds), "--child",
                        str(threads)], check=True)  # fmt: skip


if __name__ == "__main__":
    main()
