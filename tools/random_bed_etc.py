"""Effective conductivity of a random packed bed against Zehner–Schlünder / ZBS.

The bed: ``tests/data/random_bed_crop.txt`` (1660 spheres, R = 1 mm, cut from the shared
settled 50k bed; 30 × 20 × 20 mm). The network: Batchelor & O'Brien (1977) complete (contact
circle plus the fluid around it, and the near separated pairs on the range set), Hermite
blend, geometric contact radius, k_f = 0.0263 W/(m K) (air), k_p = κ k_f. k_eff along x
(``engine/etc.py``) against the correlations at the porosity of the bed's interior (volume
fraction by 200,000 sample points).

    python tools/random_bed_etc.py [--kappa 10 100 1000 10000] [--figure PATH]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BED = ROOT / "tests" / "data" / "random_bed_crop.txt"
K_GAS = 0.0263


def case(kappa: float) -> dict:
    from thermodem.config.load import case_from_dict

    data = np.loadtxt(BED, comments="#", skiprows=2)
    upper = (data[:, :3].max(axis=0) + 0.002).tolist()
    material = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
                "restitution": 0.5, "sliding_friction": 0.5,
                "thermal_conductivity": kappa * K_GAS, "specific_heat": 800.0,
                "youngs_modulus_real": 63e9}  # fmt: skip
    return case_from_dict({
        "simulation": {"time_step": 5e-6, "end_time": 1.0, "gravity": [0.0, 0.0, 0.0]},
        "domain": {"lower": [-0.002, -0.002, -0.002], "upper": upper},
        "materials": {"glass": material},
        "contact": {"normal": "hertz", "tangential": "mindlin", "rolling": "none"},
        "insertion": [{"kind": "file", "material": "glass", "path": str(BED)}],
        "thermal": {
            "contact_radius": "zhou2010",
            "direct_conduction": {"model": "batchelor_obrien_complete", "blend": "hermite"},
            "gas": {"thermal_conductivity": K_GAS},
            "frozen_mechanics": True,
            "time_step": 1.0,
        },
    })  # fmt: skip


def interior_porosity(margin: float = 4e-3, samples: int = 200_000) -> float:
    """Void fraction of the box ``margin`` inside the particles' extent (sample points)."""
    from scipy.spatial import cKDTree

    data = np.loadtxt(BED, comments="#", skiprows=2)
    x, r = data[:, :3], float(data[0, 3])
    lo, hi = x.min(axis=0) + margin, x.max(axis=0) - margin
    pts = np.random.default_rng(0).uniform(lo, hi, (samples, 3))
    dist, _ = cKDTree(x).query(pts)
    return float(np.mean(dist > r))


def measure(kappas: list[float]) -> list[dict]:
    from thermodem.engine.correlations import zehner_bauer_schlunder, zehner_schlunder
    from thermodem.engine.etc import effective_conductivity_of_case

    eps = interior_porosity()
    rows = []
    for kappa in kappas:
        (res,) = effective_conductivity_of_case(case(kappa), "x")
        rows.append({
            "kappa": kappa, "porosity": eps, "k_eff": res.conductivity,
            "uncertainty": res.uncertainty, "ratio": res.conductivity / K_GAS,
            "zs": float(zehner_schlunder(kappa, eps)),
            "zbs": float(zehner_bauer_schlunder(kappa, eps)),
        })  # fmt: skip
    return rows


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from thermodem.engine.correlations import zehner_bauer_schlunder, zehner_schlunder

    eps = rows[0]["porosity"]
    k = np.logspace(1, 4, 100)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for f, name in ((zehner_schlunder, "Zehner–Schlünder"), (zehner_bauer_schlunder, "ZBS")):
        v = f(k, eps)
        ax.fill_between(k, 0.75 * v, 1.25 * v, alpha=0.2)
        ax.plot(k, v, label=f"{name} (ε = {eps:.3f}), ±25 %")
    ax.errorbar([r["kappa"] for r in rows], [r["ratio"] for r in rows],
                yerr=[r["uncertainty"] / K_GAS for r in rows], fmt="ko",
                label="thermodem network (BOB complete)")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("k_p / k_f")
    ax.set_ylabel("k_eff / k_f")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kappa", type=float, nargs="+", default=[10.0, 100.0, 1000.0, 10000.0])
    ap.add_argument("--figure", type=Path, default=None)
    args = ap.parse_args()
    rows = measure(args.kappa)
    for r in rows:
        du = r["uncertainty"] / K_GAS
        print(f"κ = {r['kappa']:8.0f}: k_eff/k_f = {r['ratio']:.4g} ± {du:.2g}"
              f"  ZS {r['zs']:.4g} ({r['ratio'] / r['zs'] - 1:+.1%})  ZBS {r['zbs']:.4g} "
              f"({r['ratio'] / r['zbs'] - 1:+.1%})  ε = {r['porosity']:.4f}")  # fmt: skip
    if args.figure:
        figure(rows, args.figure)


if __name__ == "__main__":
    main()
