"""Paired heat-overhead benchmark on the shared bed: mechanics and heat in one process.

``bench_shared_bed.py`` runs each case in a fresh process; on this kind of VM the same case
moves by 15-25 % between processes and between minutes, more than the ≤ 15 % margins of
issues 17 §5 and 12. Here the mechanics case and a heat case (``region`` or ``material``:
the bottom layer held at 400 K) are built in one process from the same bed
(``bench_shared_bed.case_dict``), warmed up, and then timed in alternating blocks of
``--block`` steps (mechanics, heat, mechanics, ...), so that both see the same machine at
nearly the same moment; the overhead is the ratio of the summed times, and the spread of the
per-pair block ratios (median, lower and upper quartile) says how far to trust it.

    python bench/bench_paired.py [--threads 1] [--heat region] [--blocks 20] [--block 100]
        [--warmup 300]
    python bench/bench_paired.py --drum [--threads 1] ...
    python bench/bench_paired.py --heat region --convection gunn1978 --porosity cell
        --radiation krause2017 [--threads 1] ...

``--indirect MODEL [--indirect-param KEY=VALUE ...]`` (issue 10 §3): a third case, the heat
case with that indirect conduction model on the range set (e.g. ``--indirect
rong_horio1999 --indirect-param layer_thickness_ratio=0.5``: a gap cut-off of 0.5 R̄),
timed in the same rotation; its overhead over mechanics and the gap term's own cost (its
time over the heat case's, in units of the mechanics time) are printed too. ``--substeps N``
gives the heat cases N mechanical steps per thermal step (issue 10 §3's ``substeps: 10``).

``--convection MODEL`` / ``--radiation MODEL`` [``--porosity cell|shell|global``] (issue 13):
the heat case against the same case with these per-particle terms
(``bench_shared_bed.case_dict``'s ``terms``: air at 300 K flowing up at 0.5 m/s, emissivity
0.9), no mechanics case; prints the terms' overhead over the heat case (the issue's "≤ 25 %
over BOB simple" with ``--heat region --convection gunn1978 --porosity cell --radiation
krause2017``).

``--drum``: the same pairing on ``bench_drum.py``'s rotating drum (50,000 spheres after 0.1 s
of flow, cached in bench/.cache): mechanics against ``generation`` (heat generation every
step, issue 12); both advance in step, so they see the same flow.

Prints particle-steps per second of both, the heat overhead (heat time / mechanics time - 1)
and the quartiles of the block ratios, with the load average. Run it once per thread count
(``--threads 1``, ``--threads 2``): the 2-thread speed-up of each case is the ratio of its
throughputs in the two runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import bench_shared_bed as shared  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--heat", default="region", choices=["region", "material", "heat"])
    ap.add_argument("--blocks", type=int, default=20, help="timed blocks of each case")
    ap.add_argument("--block", type=int, default=100, help="steps per block")
    ap.add_argument("--warmup", type=int, default=300)
    ap.add_argument("--drum", action="store_true", help="the drum: mechanics vs generation")
    ap.add_argument("--indirect", default=None, help="a third case: heat + this range model")
    ap.add_argument("--indirect-param", nargs="*", default=[], help="KEY=VALUE parameters")
    ap.add_argument("--convection", default=None, help="issue 13: heat vs heat + terms")
    ap.add_argument("--porosity", default="cell", choices=["cell", "shell", "global"])
    ap.add_argument("--radiation", default=None, help="issue 13: heat vs heat + terms")
    ap.add_argument("--substeps", type=int, default=1, help="thermal substeps of the heat cases")
    args = ap.parse_args()
    if args.convection or args.radiation:
        terms_main(args)
        return

    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    if args.drum:
        import bench_drum as drum

        args.heat = "generation"
        bed = str(drum.settle(drum.BASE, 0.1))
        cases = {
            kind: drum.case_dict(drum.BASE, bed, kind, 1) for kind in ("mechanics", "generation")
        }
    else:
        shared.particle_files()
        cases = {
            kind: shared.case_dict(kind, None, args.substeps) for kind in ("mechanics", args.heat)
        }
        if args.indirect:
            indirect: dict = {"model": args.indirect}
            for kv in args.indirect_param:
                key, value = kv.split("=", 1)
                indirect[key] = float(value)
            cases["gap"] = shared.case_dict(args.heat, indirect, args.substeps)
    sims = {
        kind: Simulation(case_from_dict(case), threads=args.threads) for kind, case in cases.items()
    }
    for sim in sims.values():
        sim.run(steps=args.warmup)
    load_before = shared.load_average()
    seconds = {kind: [] for kind in sims}
    for _ in range(args.blocks):
        for kind, sim in sims.items():
            t0 = time.perf_counter()
            sim.run(steps=args.block)
            seconds[kind].append(time.perf_counter() - t0)
    mech = np.array(seconds["mechanics"])
    heat = np.array(seconds[args.heat])
    n = sims["mechanics"].particles.count
    steps = args.blocks * args.block
    ratios = heat / mech - 1.0
    q1, med, q3 = np.percentile(ratios, [25, 50, 75])
    print(
        f"threads {args.threads}, {n} particles, {args.blocks} blocks of {args.block} steps, "
        f"load {load_before:.2f} -> {shared.load_average():.2f}"
    )
    print(f"mechanics     {n * steps / mech.sum() / 1e6:6.2f} M particle-steps/s")
    print(f"{args.heat:<13} {n * steps / heat.sum() / 1e6:6.2f} M particle-steps/s")
    print(
        f"heat overhead {heat.sum() / mech.sum() - 1.0:+.1%} (block ratios: median {med:+.1%}, "
        f"quartiles {q1:+.1%} .. {q3:+.1%})"
    )
    if "gap" in seconds:
        gap = np.array(seconds["gap"])
        ratios = gap / mech - 1.0
        q1, med, q3 = np.percentile(ratios, [25, 50, 75])
        print(f"+ {args.indirect:<11} {n * steps / gap.sum() / 1e6:6.2f} M particle-steps/s")
        print(
            f"heat + gap over mechanics {gap.sum() / mech.sum() - 1.0:+.1%} (block ratios: "
            f"median {med:+.1%}, quartiles {q1:+.1%} .. {q3:+.1%}); the gap term alone "
            f"{(gap.sum() - heat.sum()) / mech.sum():+.1%} of mechanics"
        )


def terms_main(args: argparse.Namespace) -> None:
    """Issue 13: the heat case against the heat case with convection and/or radiation."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    shared.particle_files()
    terms = (args.convection, args.porosity, args.radiation)
    cases = {"heat": shared.case_dict(args.heat, None, 1),
             "terms": shared.case_dict(args.heat, None, 1, False, terms)}  # fmt: skip
    sims = {k: Simulation(case_from_dict(c), threads=args.threads) for k, c in cases.items()}
    for sim in sims.values():
        sim.run(steps=args.warmup)
    load_before = shared.load_average()
    seconds: dict[str, list[float]] = {kind: [] for kind in sims}
    for _ in range(args.blocks):
        for kind, sim in sims.items():
            t0 = time.perf_counter()
            sim.run(steps=args.block)
            seconds[kind].append(time.perf_counter() - t0)
    heat, extra = np.array(seconds["heat"]), np.array(seconds["terms"])
    n = sims["heat"].particles.count
    steps = args.blocks * args.block
    q1, med, q3 = np.percentile(extra / heat - 1.0, [25, 50, 75])
    what = " + ".join(t for t in (args.convection, args.radiation) if t)
    print(
        f"threads {args.threads}, {n} particles, {args.blocks} blocks of {args.block} steps, "
        f"load {load_before:.2f} -> {shared.load_average():.2f}"
    )
    print(f"{args.heat:<13} {n * steps / heat.sum() / 1e6:6.2f} M particle-steps/s")
    print(f"+ {what} ({args.porosity} porosity) {n * steps / extra.sum() / 1e6:6.2f} M "
          "particle-steps/s")  # fmt: skip
    print(
        f"terms overhead {extra.sum() / heat.sum() - 1.0:+.1%} over {args.heat} (block "
        f"ratios: median {med:+.1%}, quartiles {q1:+.1%} .. {q3:+.1%}; worst block "
        f"{(extra / heat).max() - 1.0:+.1%})"
    )


if __name__ == "__main__":
    main()
