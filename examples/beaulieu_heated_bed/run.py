"""Beaulieu (2020) heated steel bed: run implicitly, compare with the measurement.

The case (built here from common.py and bed.txt, also written as beaulieu.yaml for
``thermodem run``) is Lethe's "heated packed bed" example set-up (chaos-polymtl/lethe,
examples/dem-mp/3d-heated-packed-bed: steel spheres d = 6.4 mm, the stagnant-gas resistance
network with Lethe's material, wall and gas parameters, the heated wall raised from 20 °C to
53 °C at t = 0), with frozen mechanics and backward Euler. Probes as in Lethe's
post-processing: the mean temperature of the particles whose centres are within 2 d of the
bed's axis in x and y and within d of the probe depth (4.0, 6.0 and 7.3 cm below the heated
wall). The measured curves (reference/, from the same Lethe example, digitised from
Beaulieu 2020) are compared at their own times: RMS deviation per depth.

    python examples/beaulieu_heated_bed/run.py              # Δt = 10 s, 400 steps
    python examples/beaulieu_heated_bed/run.py --reduced    # Δt = 80 s, 50 steps (the suite)

Writes ``beaulieu.png`` (or ``beaulieu_reduced.png``) and prints the RMS deviations.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (  # noqa: E402
    DEPTHS,
    DIAMETER,
    DURATION,
    FOOTPRINT,
    GAS,
    HERE,
    RADIUS,
    STEEL,
    T_COLD,
    T_HOT,
    WALL,
)  # fmt: skip

REDUCED_DT = 80.0  # s: the suite's version (50 steps instead of 400)


def bed() -> Path:
    return HERE / "bed.txt"


def case(dt: float = 10.0, scheme: str = "backward_euler") -> dict:
    path = bed()
    data = np.loadtxt(path, comments="#", skiprows=2)
    lo = data[:, :3].min(axis=0) - RADIUS - 1e-3
    hi = data[:, :3].max(axis=0) + RADIUS + 1e-3
    hi[2] = 0.005
    return {
        "simulation": {
            "time_step": 1e-5,
            "end_time": DURATION,
            "gravity": [0, 0, 9.81],
            "initial_temperature": T_COLD,
        },  # fmt: skip
        "domain": {"lower": lo.tolist(), "upper": hi.tolist()},
        "materials": {"steel": dict(STEEL), "lid": dict(WALL)},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "constant_torque"},
        "walls": [
            {
                "kind": "plane",
                "name": "heated_wall",
                "point": [0, 0, 0],
                "normal": [0, 0, -1],
                "material": "lid",
                "thermal": {"kind": "fixed", "temperature": T_HOT},
            }
        ],  # fmt: skip
        "insertion": [{"kind": "file", "material": "steel", "path": str(path)}],
        "thermal": {
            "contact_radius": "geometric",
            "direct_conduction": {"model": "resistance_network", "maximum_pressure": "overlap"},
            "gas": dict(GAS),
            "frozen_mechanics": True,
            "time_step": dt,
            "scheme": scheme,
        },
        "output": {"vtu": False},
    }


def probes(sim) -> list[np.ndarray]:  # noqa: ANN001
    x = sim.particles.position
    centre = np.array(FOOTPRINT) / 2.0
    near = np.all(np.abs(x[:, :2] - centre) < 2.0 * DIAMETER, axis=1)
    return [near & (np.abs(x[:, 2] + h) < DIAMETER) for h in DEPTHS]


def measured(depth: float) -> np.ndarray:
    return np.loadtxt(HERE / "reference" / f"steel_Beaulieu_{depth:.3f}_experiment.csv",
                      delimiter=",", skiprows=1)  # fmt: skip


def simulate(dt: float = 10.0, scheme: str = "backward_euler", threads: int | None = None) -> dict:
    """Run the case; return times, probe temperatures [°C], RMS per depth and the timings
    (``threads``: Numba threads, None: chosen by thermodem)."""
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    sim = Simulation(case_from_dict(case(dt, scheme)), threads=threads)
    sel = probes(sim)
    times = [0.0]
    curves = [[float(sim.particles.temperature[s].mean()) - 273.15 for s in sel]]

    def record(s) -> None:  # noqa: ANN001
        times.append(s.time)
        curves.append([float(s.particles.temperature[m].mean()) - 273.15 for m in sel])

    sim.run(until=DURATION, callback=record)
    times = np.array(times)
    curves = np.array(curves)
    rms = []
    for k, h in enumerate(DEPTHS):
        m = measured(h)
        model = np.interp(m[:, 0], times, curves[:, k])
        rms.append(float(np.sqrt(np.mean((model - m[:, 1]) ** 2))))
    tm = sim.thermal.implicit.timings
    return {"times": times, "curves": curves, "rms": rms, "particles": sim.particles.count,
            "probe_counts": [int(s.sum()) for s in sel], "timings": tm,
            "balance_error": sim.thermal.balance_error(),
            "energy": sim.thermal.thermal_energy()}  # fmt: skip


def plot(result: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, h in enumerate(DEPTHS):
        m = measured(h)
        label = f"thermodem, {h * 100:.1f} cm (RMS {result['rms'][k]:.2f} K)"
        line = ax.plot(result["times"], result["curves"][:, k], label=label)
        ax.plot(m[:, 0], m[:, 1], ".", color=line[0].get_color(),
                label=f"Beaulieu (2020) measured, {h * 100:.1f} cm")  # fmt: skip
    ax.set_xlabel("time after the wall was raised to 53 °C [s]")
    ax.set_ylabel("temperature [°C]")
    ax.set_title(f"Heated steel bed ({result['particles']} spheres, d = 6.4 mm), implicit")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--reduced",
        action="store_true",
        help=f"the suite's version: Δt = {REDUCED_DT:g} s instead of --dt",
    )
    ap.add_argument("--dt", type=float, default=10.0, help="thermal time step [s]")
    ap.add_argument("--scheme", default="backward_euler")
    ap.add_argument("--threads", type=int, default=None, help="Numba threads (default: chosen)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument(
        "--write-case",
        action="store_true",
        help="write beaulieu.yaml (the full case for 'thermodem run') and stop",
    )
    args = ap.parse_args()
    if args.write_case:
        import yaml

        full = case(args.dt, args.scheme)
        full["insertion"][0]["path"] = "bed.txt"
        text = ("# Beaulieu (2020) heated steel bed, written by run.py --write-case (README.md)\n"
                + yaml.safe_dump(full, sort_keys=False))  # fmt: skip
        (HERE / "beaulieu.yaml").write_text(text)
        print(HERE / "beaulieu.yaml")
        return
    result = simulate(REDUCED_DT if args.reduced else args.dt, args.scheme, args.threads)
    tm = result["timings"]
    print(f"{result['particles']} particles, probes {result['probe_counts']}; assembly "
          f"{tm.assembly:.2f} s, AMG setup {tm.preconditioner:.2f} s, solve {tm.solve:.2f} s, "
          f"passes {tm.evaluation:.2f} s; heat balance error {result['balance_error']:.3g} J "
          f"of {result['energy']:.4g} J")  # fmt: skip
    for h, r in zip(DEPTHS, result["rms"], strict=True):
        print(f"depth {h * 100:.1f} cm: RMS deviation from the measurement {r:.3f} K")
    if not args.no_plot:
        name = "beaulieu_reduced.png" if args.reduced else "beaulieu.png"
        plot(result, HERE / name)
        print(f"figure: {HERE / name}")


if __name__ == "__main__":
    main()
