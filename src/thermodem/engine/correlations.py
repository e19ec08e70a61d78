"""Effective-conductivity correlations of packed beds of spheres (stagnant fluid).

Zehner, P. & Schlünder, E. U. (1970), Wärmeleitfähigkeit von Schüttungen bei mäßigen
Temperaturen, Chemie Ingenieur Technik 42, 933-941; with the contact flattening of Bauer, R. &
Schlünder, E. U. (1978), Effective radial thermal conductivity of packings in gas flow,
Int. Chem. Eng. 18, 189-204 ("Zehner–Bauer–Schlünder", ZBS; radiation and the Smoluchowski
gas-pressure effect left out: a stagnant gas at ordinary pressure and temperature).

    k_e/k_f = (1 - √(1-ε)) + √(1-ε) [φ κ + (1 - φ) k_c/k_f]

    k_c/k_f = 2/N [ (κ - 1) B / (N² κ) ln(κ/B) - (B + 1)/2 - (B - 1)/N ],  N = 1 - B/κ,
    B = C ((1 - ε)/ε)^(10/9),  C = 1.25 (spheres),  κ = k_p/k_f

φ = 0 is the Zehner–Schlünder model (point contacts). Their stated scatter against the
measurements they were fitted to is about ±25 %.
"""

from __future__ import annotations

import numpy as np

#: shape factor C of spheres (Zehner & Schlünder 1970)
SPHERE_SHAPE = 1.25
#: contact flattening coefficient for spheres used with ZBS (Bauer & Schlünder 1978; the value
#: quoted for spheres in the VDI Heat Atlas). A fit parameter of the correlation: a choice.
SPHERE_FLATTENING = 0.0077


def zehner_schlunder(
    kappa: np.ndarray | float, porosity: float, flattening: float = 0.0
) -> np.ndarray:
    """k_e/k_f of a bed of spheres of porosity ε and conductivity ratio κ = k_p/k_f."""
    kappa = np.asarray(kappa, float)
    b = SPHERE_SHAPE * ((1.0 - porosity) / porosity) ** (10.0 / 9.0)
    n = 1.0 - b / kappa
    core = 2.0 / n * ((kappa - 1.0) * b / (n * n * kappa) * np.log(kappa / b)
                      - 0.5 * (b + 1.0) - (b - 1.0) / n)  # fmt: skip
    root = np.sqrt(1.0 - porosity)
    return (1.0 - root) + root * (flattening * kappa + (1.0 - flattening) * core)


def zehner_bauer_schlunder(kappa: np.ndarray | float, porosity: float) -> np.ndarray:
    """ZBS without radiation, with the sphere flattening coefficient SPHERE_FLATTENING."""
    return zehner_schlunder(kappa, porosity, SPHERE_FLATTENING)
