"""Effective conductivity of a random packed bed against Zehner–Schlünder / ZBS.

The bed: ``tests/data/random_bed_crop.txt`` (1660 spheres, R = 1 mm, cut from the shared
settled 50k bed; 30 × 20 × 20 mm). k_eff along x (``engine/etc.py``) for k_p = κ k_f, with
k_f = 0.0263 W/(m K) (air), against Zehner & Schlünder (1970, ZS) and Zehner–Bauer–Schlünder
(ZBS) at the porosity of the bed's interior (volume fraction by 200,000 sample points). The
band: from 0.75 × the lower to 1.25 × the upper of the two correlations (their ±25 %
scatter); both correlations are also compared alone.

The pair models (``--model``, combinations of the code's registered models with their
default parameters, only the blend of Batchelor & O'Brien chosen: the monotonic Hermite one):

- ``bob_modified_zhou`` (default): Batchelor & O'Brien in series with the particles' inner
  resistances (Yun & Evans 2010, ``batchelor_obrien_modified``; near separated pairs on the
  range set) with Zhou et al. (2010)'s contact radius from the real modulus (63 GPa, glass);
- ``bob_modified_morris``: the same with Morris et al. (2016)'s real-modulus radius at the
  simulated force (``morris2016_area``);
- ``bob_complete_zhou``: Batchelor & O'Brien complete (isothermal particles);
- ``bob_simple_voronoi_a``: the contact circle (BOB simple) plus Cheng et al. (1999)'s
  Voronoi model A for the gas;
- ``bob_simple_rong_horio``: the contact circle plus Rong & Horio (1999)'s fluid layer.

    python tools/random_bed_etc.py [--kappa 10 100 1000 10000] [--model NAME ...]
        [--figure PATH]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BED = ROOT / "tests" / "data" / "random_bed_crop.txt"
K_GAS = 0.0263
KAPPAS = [10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0]
HERMITE = {"blend": "hermite"}
#: name -> (direct_conduction, indirect_conduction, contact_radius, label)
MODELS = {
    "bob_modified_zhou": ({"model": "batchelor_obrien_modified", **HERMITE}, "none", "zhou2010",
                          "BOB modified (Yun & Evans) + Zhou 2010 radius"),
    "bob_modified_morris": ({"model": "batchelor_obrien_modified", **HERMITE}, "none",
                            "morris2016_area", "BOB modified + Morris 2016 radius"),
    "bob_complete_zhou": ({"model": "batchelor_obrien_complete", **HERMITE}, "none", "zhou2010",
                          "BOB complete + Zhou 2010 radius"),
    "bob_simple_voronoi_a": ("batchelor_obrien_simple", "voronoi_a", "zhou2010",
                             "BOB simple + Voronoi A (gas), Zhou radius"),
    "bob_simple_rong_horio": ("batchelor_obrien_simple", "rong_horio1999", "zhou2010",
                              "BOB simple + Rong & Horio layer, Zhou radius"),
}  # fmt: skip
DEFAULT = "bob_modified_zhou"


def case(kappa: float, model: str = DEFAULT) -> dict:
    from thermodem.config.load import case_from_dict

    direct, indirect, radius, _ = MODELS[model]
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
            "contact_radius": radius,
            "direct_conduction": direct,
            "indirect_conduction": indirect,
            "gas": {"thermal_conductivity": K_GAS},
            "frozen_mechanics": True,
            "time_step": 1.0,
        },
    })  # fmt: skip


def band(kappa: np.ndarray | float, porosity: float) -> tuple[np.ndarray, np.ndarray]:
    """(0.75 × min, 1.25 × max) of ZS and ZBS: the correlations with their ±25 %."""
    from thermodem.engine.correlations import zehner_bauer_schlunder, zehner_schlunder

    zs, zbs = zehner_schlunder(kappa, porosity), zehner_bauer_schlunder(kappa, porosity)
    return 0.75 * np.minimum(zs, zbs), 1.25 * np.maximum(zs, zbs)


def interior_porosity(margin: float = 4e-3, samples: int = 200_000) -> float:
    """Void fraction of the box ``margin`` inside the particles' extent (sample points)."""
    from scipy.spatial import cKDTree

    data = np.loadtxt(BED, comments="#", skiprows=2)
    x, r = data[:, :3], float(data[0, 3])
    lo, hi = x.min(axis=0) + margin, x.max(axis=0) - margin
    pts = np.random.default_rng(0).uniform(lo, hi, (samples, 3))
    dist, _ = cKDTree(x).query(pts)
    return float(np.mean(dist > r))


def measure(kappas: list[float], model: str = DEFAULT) -> list[dict]:
    import warnings

    from thermodem.engine.correlations import zehner_bauer_schlunder, zehner_schlunder
    from thermodem.engine.etc import effective_conductivity_of_case

    eps = interior_porosity()
    rows = []
    for kappa in kappas:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the tessellation's notice
            (res,) = effective_conductivity_of_case(case(kappa, model), "x")
        low, high = band(kappa, eps)
        ratio = res.conductivity / K_GAS
        rows.append({
            "model": model, "kappa": kappa, "porosity": eps, "k_eff": res.conductivity,
            "uncertainty": res.uncertainty, "ratio": ratio,
            "zs": float(zehner_schlunder(kappa, eps)),
            "zbs": float(zehner_bauer_schlunder(kappa, eps)),
            "band": (float(low), float(high)), "in_band": bool(low <= ratio <= high),
        })  # fmt: skip
    return rows


def figure(rows: list[dict], path: Path) -> None:
    """The band of the correlations and the network's points (every model in ``rows``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from thermodem.engine.correlations import zehner_bauer_schlunder, zehner_schlunder

    eps = rows[0]["porosity"]
    k = np.logspace(1, 4, 100)
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    low, high = band(k, eps)
    ax.fill_between(k, low, high, color="0.85", label="ZS/ZBS band (0.75 min … 1.25 max)")
    for f, name, style in ((zehner_schlunder, "Zehner–Schlünder", "--"),
                           (zehner_bauer_schlunder, "Zehner–Bauer–Schlünder", "-")):  # fmt: skip
        ax.plot(k, f(k, eps), "k" + style, lw=1, label=f"{name} (ε = {eps:.3f})")
    markers = iter("osD^v")
    for model in dict.fromkeys(r["model"] for r in rows):
        sel = [r for r in rows if r["model"] == model]
        ax.errorbar([r["kappa"] for r in sel], [r["ratio"] for r in sel],
                    yerr=[r["uncertainty"] / K_GAS for r in sel], fmt=next(markers) + "-",
                    ms=4, lw=0.8, label=MODELS[model][3])  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("k_p / k_f")
    ax.set_ylabel("k_eff / k_f")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kappa", type=float, nargs="+", default=KAPPAS)
    ap.add_argument("--model", nargs="+", default=[DEFAULT], choices=list(MODELS))
    ap.add_argument("--figure", type=Path, default=None)
    args = ap.parse_args()
    rows = []
    for model in args.model:
        print(f"{model}: {MODELS[model][3]}")
        for r in measure(args.kappa, model):
            rows.append(r)
            du = r["uncertainty"] / K_GAS
            lo, hi = r["band"]
            print(f"  κ = {r['kappa']:8.0f}: k_eff/k_f = {r['ratio']:.4g} ± {du:.2g}"
                  f"  ZS {r['zs']:.4g} ({r['ratio'] / r['zs'] - 1:+.1%})  ZBS {r['zbs']:.4g} "
                  f"({r['ratio'] / r['zbs'] - 1:+.1%})  band {lo:.3g}…{hi:.3g} "
                  f"{'in' if r['in_band'] else 'OUT'}  ε = {r['porosity']:.4f}",
                  flush=True)  # fmt: skip
    if args.figure:
        figure(rows, args.figure)


if __name__ == "__main__":
    main()
