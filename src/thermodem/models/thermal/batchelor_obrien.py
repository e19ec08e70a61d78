"""Batchelor & O'Brien (1977) for separated particles: the pieces shared by the models that
conduct across a gap with it (spec "Static Contact Models – Model by Batchelor & O'Brien
(1977) – Particles separated"): ``indirect_conduction.batchelor_obrien_separated`` and the
separated-pair part of ``direct_conduction.batchelor_obrien_complete`` / ``_modified``.

    λ = k_pf² d_s / (2 R̄),   H = 2π R̄ k_f X,
    X_near = ln k_pf²  (λ ≪ 1),   X_far = ln(1 + r̄² / (2 R̄ d_s))  (λ ≫ 1)

Where each form applies (``regime``): ``dai2019`` near for λ < 0.01, far for λ > 100 and
min(near, far) for 0.01 <= λ <= 100 (Dai, Hanaor & Gan 2019); ``moscardini2018`` near for
λ < 0.1, far for λ >= 0.1 (Moscardini et al. 2018); ``minimum`` min(near, far) everywhere.

The conduction cylinder r̄ / R̄ (``cylinder_radius``): a number > 0 or a named choice of the
spec, :data:`CYLINDER_RATIOS`. Not a model: no ``register()`` here.
"""

from __future__ import annotations

import math
from typing import Literal

from numba import njit
from pydantic import Field

REGIME_DAI2019 = 0
REGIME_MOSCARDINI2018 = 1
REGIME_MINIMUM = 2
REGIMES = {
    "dai2019": REGIME_DAI2019,
    "moscardini2018": REGIME_MOSCARDINI2018,
    "minimum": REGIME_MINIMUM,
}
RegimeName = Literal["dai2019", "moscardini2018", "minimum"]

#: r̄ / R̄ of the named conduction cylinders (spec, "Particles separated").
CYLINDER_RATIOS = {
    "kanuparthi2008": 1.00,  # Kanuparthi et al. 2008
    "yun_evans2010": 1.00,  # Yun & Evans 2010, calibrated for k_pf = 120
    "moscardini2018": 1.42,  # Moscardini et al. 2018, calibrated for k_pf = 10
    "dai2019": 2.00,  # Dai et al. 2019, calibrated for the modified BOB model
}
CylinderName = Literal["kanuparthi2008", "yun_evans2010", "moscardini2018", "dai2019"]
CYLINDER_HELP = (
    "r̄ / R̄ [-] (> 0), or kanuparthi2008 / yun_evans2010 (1.00), moscardini2018 (1.42), "
    "dai2019 (2.00)"
)


def regime_field() -> object:
    """The ``regime`` parameter of every model with a separated Batchelor & O'Brien part."""
    return Field(
        default="dai2019",
        description="which λ formula where: dai2019 (near λ < 0.01, far λ > 100, the minimum "
        "between), moscardini2018 (switch at λ = 0.1), minimum",
    )


def check_cylinder(value: float | str, extra: tuple[str, ...] = ()) -> float | str:
    """A finite r̄/R̄ > 0 or a known name (``extra``: names a model adds); ValueError else."""
    names = (*CYLINDER_RATIOS, *extra)
    if isinstance(value, str):
        if value not in names:
            raise ValueError(f"cylinder_radius must be a number > 0 or one of {', '.join(names)}")
        return value
    if not (value > 0.0 and math.isfinite(value)):
        raise ValueError(
            f"cylinder_radius must be a finite r̄/R̄ > 0 or one of {', '.join(names)}, got {value!r}"
        )
    return value


def cylinder_ratio(value: float | str) -> float:
    """r̄ / R̄ [-] of a ``cylinder_radius`` value (a number or a name of CYLINDER_RATIOS)."""
    if isinstance(value, str):
        return CYLINDER_RATIOS[value]
    return float(value)


@njit(cache=True, error_model="numpy")
def separated_factor(kpf, lam, r_cyl_ratio, gap_ratio, regime):
    """X of H = 2π R̄ k_f X for λ = k_pf² d_s/(2R̄), r̄/R̄ and d_s/R̄ (spec, BOB separated).

    near = ln k_pf² (λ ≪ 1), far = ln(1 + r̄²/(2 R̄ d_s)) = log1p((r̄/R̄)²/(2 d_s/R̄)).
    """
    near = 2.0 * math.log(kpf)
    far = math.log1p(r_cyl_ratio * r_cyl_ratio / (2.0 * gap_ratio))
    if regime == REGIME_MOSCARDINI2018:
        return near if lam < 0.1 else far
    if regime == REGIME_MINIMUM:
        return min(near, far)
    if lam < 0.01:
        return near
    if lam > 100.0:
        return far
    return min(near, far)


@njit(cache=True, error_model="numpy")
def gap_conductance(k_p, k_f, r_eff, gap, r_cyl_ratio, regime):
    """H = 2π R̄ k_f X [W/K] of a gap d_s = ``gap`` > 0 (no cut-off here)."""
    kpf = k_p / k_f
    gap_ratio = gap / r_eff
    lam = kpf * kpf * gap_ratio * 0.5
    return 2.0 * math.pi * r_eff * k_f * separated_factor(kpf, lam, r_cyl_ratio, gap_ratio, regime)
