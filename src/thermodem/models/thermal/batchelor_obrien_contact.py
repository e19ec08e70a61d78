"""Batchelor & O'Brien (1977) models of the ``direct_conduction`` family: ``simple`` (the
large-η limit), ``complete`` (the contact circle and the surrounding fluid, and separated
pairs) and ``modified`` (in series with the particles' inner resistances, Yun & Evans 2010).

Kernel signature, antisymmetry and row layout: the docstring of ``direct_conduction.py``
(whose dispatchers call these kernels); the family's row head and registration helper:
``direct_conduction_family.py``; the separated-particle pieces shared with
``indirect_conduction.batchelor_obrien_separated``: ``batchelor_obrien.py``.

Kernels are compiled with ``error_model="numpy"``: they never raise (a division by zero gives
inf/NaN, which the NaN flag of the pair loop catches), as the architecture asks of kernels.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, field_validator

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed
from thermodem.models.thermal.batchelor_obrien import (
    CYLINDER_HELP,
    REGIMES,
    CylinderName,
    RegimeName,
    check_cylinder,
    cylinder_ratio,
    gap_conductance,
    regime_field,
)
from thermodem.models.thermal.contact_radius import effective_radius
from thermodem.models.thermal.direct_conduction_family import (
    HEAD,
    K_I,
    K_J,
    conductivities,
    head_values,
    register_model,
)
from thermodem.state.materials import PairContext

BATCHELOR_OBRIEN_SIMPLE = 1
BATCHELOR_OBRIEN_COMPLETE = 2
BATCHELOR_OBRIEN_MODIFIED = 3

#: Batchelor & O'Brien complete (and modified: one column more).
BOB_COLUMNS = (
    *HEAD, "k_f", "blend", "cylinder_ratio", "cutoff_gap_ratio", "regime", "conductivity_mean"
)  # fmt: skip
BOB_K_F, BOB_BLEND, BOB_CYLINDER_RATIO, BOB_CUTOFF_RATIO, BOB_REGIME = 4, 5, 6, 7, 8
BOB_MEAN = 9
BOB_MODIFIED_COLUMNS = (*BOB_COLUMNS, "dai2019_correlation")
BOB_DAI2019 = 10

#: k_p of two materials: the harmonic mean 2 k_i k_j/(k_i + k_j) (the default) or the
#: arithmetic (k_i + k_j)/2 (Kratos ThermalDEM's reading); a runtime column, one kernel.
MEAN_HARMONIC = 0
MEAN_ARITHMETIC = 1
_MEANS = {"harmonic": MEAN_HARMONIC, "arithmetic": MEAN_ARITHMETIC}

BLEND_SPEC_LINEAR = 0
BLEND_HERMITE = 1
_BLENDS = {"spec_linear": BLEND_SPEC_LINEAR, "hermite": BLEND_HERMITE}


# ------------------------------------------------------------ Batchelor & O'Brien, simple
class BatchelorOBrienSimpleParams(StrictModel):
    """Q = 4 k̄ R_c (T_j - T_i), k̄ = k_i k_j / (k_i + k_j) (spec 2.3 and appendix A).

    Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333, large-η limit Q = 2 k_p R_c
    ΔT, generalised to two materials with the effective conductivity of Cheng et al. (1999):
    k̄ is the *series* combination (half the harmonic mean), so equal materials give 2 k R_c;
    each body contributes the constriction resistance 1/(4 k a) of a half space. A wall is the
    half space k_j. Row: [k_i, k_j].
    """


@njit(cache=True, error_model="numpy")
def bob_simple_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0 or r_c <= 0.0:
        return 0.0
    k_bar = p[K_I] * p[K_J] / (p[K_I] + p[K_J])
    return 4.0 * k_bar * r_c * (t_j - t_i)


# --------------------------------------------------------- Batchelor & O'Brien, complete
@njit(cache=True, error_model="numpy")
def bob_contact_h(eta, blend):
    """H̃_c + H̃_f of Batchelor & O'Brien (1977) for the contact parameter η (spec 2.3).

    η < 1: 0.17 η²;  η > 100: 2η/π - 2 ln η;  1 <= η <= 100: ``spec_linear`` blends the two
    formulas with weight w = (η - 1)/99 (continuous but NOT monotonic: it peaks at ≈ 277.8 near
    η ≈ 68.8 and falls to 54.45 at η = 100); ``hermite`` is the cubic Hermite curve that matches
    both regimes' values and slopes at η = 1 and η = 100 (C¹ and monotonic).
    """
    if eta < 1.0:
        return 0.17 * eta * eta
    if eta > 100.0:
        return 2.0 * eta / math.pi - 2.0 * math.log(eta)
    if blend == BLEND_HERMITE:
        y0, m0 = 0.17, 0.34
        y1, m1 = 200.0 / math.pi - 2.0 * math.log(100.0), 2.0 / math.pi - 0.02
        t = (eta - 1.0) / 99.0
        t2 = t * t
        t3 = t2 * t
        return (
            (2.0 * t3 - 3.0 * t2 + 1.0) * y0
            + (t3 - 2.0 * t2 + t) * 99.0 * m0
            + (3.0 * t2 - 2.0 * t3) * y1
            + (t3 - t2) * 99.0 * m1
        )
    w = (eta - 1.0) / 99.0
    return (1.0 - w) * 0.17 * eta * eta + w * (2.0 * eta / math.pi - 2.0 * math.log(eta))


@njit(cache=True, error_model="numpy")
def bob_conductance(k_p, k_f, r_eff, r_c, overlap, blend, r_cyl, cutoff_gap, regime):
    """Batchelor & O'Brien (1977) conductance H [W/K] between two surfaces (spec 2.3).

    Contact (δ >= 0): 2π R* k_f (H̃_c + H̃_f + ln k_pf²), η = k_pf R_c/(2R*).
    Separated (gap d_s = -δ < cutoff): 2π R* k_f X(λ), X = ln k_pf² or ln(1 + r̄²/(2 R* d_s))
    by the λ rule ``regime`` (models/thermal/batchelor_obrien.py). 0 beyond the cut-off.
    """
    kpf = k_p / k_f
    if overlap >= 0.0:
        eta = kpf * r_c / (2.0 * r_eff)
        return 2.0 * math.pi * r_eff * k_f * (bob_contact_h(eta, blend) + 2.0 * math.log(kpf))
    gap = -overlap
    if gap >= cutoff_gap:
        return 0.0
    return gap_conductance(k_p, k_f, r_eff, gap, r_cyl / r_eff, regime)


@njit(cache=True, error_model="numpy")
def particle_conductivity(k_i, k_j, mean):
    """k_p of the pair: harmonic 2 k_i k_j/(k_i + k_j) (mean 0) or arithmetic (k_i + k_j)/2
    (mean 1); equal for equal conductivities."""
    if mean == MEAN_ARITHMETIC:
        return 0.5 * (k_i + k_j)
    return 2.0 * k_i * k_j / (k_i + k_j)


class BatchelorOBrienCompleteParams(StrictModel):
    """Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333: contact through the
    contact circle and the surrounding fluid, and near (separated) particles (spec 2.3).

    Total conduction (direct + through the fluid near the contact): do not combine it with an
    indirect_conduction model. k_f is the conductivity of the case's gas (``thermal.gas``,
    ``pair.gas``). k_p = 2 k_i k_j/(k_i + k_j) (harmonic mean, so that the large-η limit is
    batchelor_obrien_simple; ``conductivity_mean="arithmetic"``: (k_i + k_j)/2, Kratos
    ThermalDEM's reading), k_pf = k_p/k_f must exceed 1. The 1 <= η <= 100 blend
    of the spec is not monotonic (see bob_contact_h); ``blend="hermite"`` is a monotonic one.
    Separated pairs conduct up to a gap ``cutoff_gap_ratio`` R* (Yun & Evans 2010: d_s < R̄),
    through a cylinder of radius ``cylinder_radius`` R* (a number, or a named choice of the
    spec: dai2019 = 2.00, Dai et al. 2019; for equal spheres R* = R/2, so 2.00 is a cylinder of
    the particle radius), with the λ rule ``regime`` (as batchelor_obrien_separated).
    Row: [k_i, k_j, 0, 0, k_f, blend, r̄/R*, d_s,max/R*, regime, 0 harmonic | 1 arithmetic].
    """

    blend: Literal[tuple(_BLENDS)] = Field(
        default="spec_linear", description="H̃ for 1 <= η <= 100: spec's blend or monotonic"
    )
    regime: RegimeName = regime_field()
    cylinder_radius: float | CylinderName = Field(default=2.0, description=CYLINDER_HELP)
    cutoff_gap_ratio: float = Field(
        default=1.0,
        ge=0,
        allow_inf_nan=False,
        description="largest conducting gap d_s / R* [-] of separated pairs",
    )
    conductivity_mean: Literal[tuple(_MEANS)] = Field(
        default="harmonic",
        description="k_p of two materials: harmonic 2 k_i k_j/(k_i + k_j) (the large-η limit "
        "is batchelor_obrien_simple) or arithmetic (k_i + k_j)/2 (Kratos ThermalDEM)",
    )

    @field_validator("cylinder_radius")
    @classmethod
    def _cylinder(cls, v: float | str) -> float | str:
        return check_cylinder(v)


def _check_kpf(k_i: float, k_j: float, k_f: float, model: str, mean: str) -> None:
    k_p = 0.5 * (k_i + k_j) if mean == "arithmetic" else 2.0 * k_i * k_j / (k_i + k_j)
    if k_p <= k_f:
        raise ValueError(
            f"{model} needs particle conductivity above the gas's (k_p/k_f > 1): "
            f"k_p = {k_p:g} W/(m K), thermal.gas.thermal_conductivity = {k_f:g} W/(m K)"
        )


def pack_bob_complete(params: BatchelorOBrienCompleteParams, pair: PairContext) -> np.ndarray:
    model = "direct_conduction.batchelor_obrien_complete"
    k_i, k_j = conductivities(pair, model)
    k_f = pair.gas.thermal_conductivity
    _check_kpf(k_i, k_j, k_f, model, params.conductivity_mean)
    mean = _MEANS[params.conductivity_mean]
    values = head_values([k_i, k_j]) | {"k_f": k_f, "blend": _BLENDS[params.blend],
                                        "cylinder_ratio": cylinder_ratio(params.cylinder_radius),
                                        "cutoff_gap_ratio": params.cutoff_gap_ratio,
                                        "regime": REGIMES[params.regime],
                                        "conductivity_mean": mean}  # fmt: skip
    return packed(BOB_COLUMNS, values)


def bob_interaction_range(params: StrictModel, radius_i: float, radius_j: float) -> float:
    """Largest surface gap [m] at which a separated pair conducts: cutoff_gap_ratio × R*."""
    r_eff = radius_i if math.isinf(radius_j) else radius_i * radius_j / (radius_i + radius_j)
    return params.cutoff_gap_ratio * r_eff


@njit(cache=True, error_model="numpy")
def bob_complete_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    r_eff = effective_radius(r_i, r_j)
    k_p = particle_conductivity(p[K_I], p[K_J], p[BOB_MEAN])
    r_cyl = p[BOB_CYLINDER_RATIO] * r_eff
    cutoff = p[BOB_CUTOFF_RATIO] * r_eff
    h = bob_conductance(
        k_p, p[BOB_K_F], r_eff, max(r_c, 0.0), overlap, p[BOB_BLEND], r_cyl, cutoff, p[BOB_REGIME]
    )
    return h * (t_j - t_i)


# --------------------------------------------------------- Batchelor & O'Brien, modified
class BatchelorOBrienModifiedParams(BatchelorOBrienCompleteParams):
    """Yun & Evans (2010) Comput. Geotech. 37, 991-998: BOB in series with the two particles'
    inner resistances, H = (1/H_i + 1/H_j + 1/H_BOB)^-1, H_i = k_i π r̄² / R_i (spec 2.4),
    for touching and separated pairs (the spec's "resistance of the interaction type").

    H_BOB is batchelor_obrien_complete's conductance (same parameters). ``cylinder_radius`` is
    r̄/R*, a named choice of the spec (as complete), or ``"dai2019_correlation"``: r̄ = 1.3121
    k_pf^-0.19 min(R_i, R_j) (Dai, Hanaor & Gan 2019, Int. J. Therm. Sci. 142, 266-279; fitted
    for k_pf < 1e3). A wall is isothermal: 1/H_j is dropped.
    Row: [k_i, k_j, 0, 0, k_f, blend, r̄/R*, d_s,max/R*, regime, mean, 1 if dai2019_correlation].
    """

    cylinder_radius: float | CylinderName | Literal["dai2019_correlation"] = Field(
        default=2.0,
        description=CYLINDER_HELP + ", or dai2019_correlation: r̄ = 1.3121 k_pf^-0.19 "
        "min(R_i, R_j) (Dai et al. 2019)",
    )

    @field_validator("cylinder_radius")
    @classmethod
    def _cylinder(cls, v: float | str) -> float | str:
        return check_cylinder(v, ("dai2019_correlation",))


def pack_bob_modified(params: BatchelorOBrienModifiedParams, pair: PairContext) -> np.ndarray:
    model = "direct_conduction.batchelor_obrien_modified"
    k_i, k_j = conductivities(pair, model)
    k_f = pair.gas.thermal_conductivity
    _check_kpf(k_i, k_j, k_f, model, params.conductivity_mean)
    dai = params.cylinder_radius == "dai2019_correlation"
    ratio = 0.0 if dai else cylinder_ratio(params.cylinder_radius)
    values = head_values([k_i, k_j]) | {"k_f": k_f, "blend": _BLENDS[params.blend],
                                        "cylinder_ratio": ratio,
                                        "cutoff_gap_ratio": params.cutoff_gap_ratio,
                                        "regime": REGIMES[params.regime],
                                        "conductivity_mean": _MEANS[params.conductivity_mean],
                                        "dai2019_correlation": 1.0 if dai else 0.0}  # fmt: skip
    return packed(BOB_MODIFIED_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def bob_modified_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    r_eff = effective_radius(r_i, r_j)
    k_p = particle_conductivity(p[K_I], p[K_J], p[BOB_MEAN])
    k_f = p[BOB_K_F]
    if p[BOB_DAI2019] == 1.0:
        r_cyl = 1.3121 * (k_p / k_f) ** -0.19 * min(r_i, r_j)
    else:
        r_cyl = p[BOB_CYLINDER_RATIO] * r_eff
    cutoff = p[BOB_CUTOFF_RATIO] * r_eff
    h_bob = bob_conductance(
        k_p, k_f, r_eff, max(r_c, 0.0), overlap, p[BOB_BLEND], r_cyl, cutoff, p[BOB_REGIME]
    )
    if h_bob <= 0.0:
        return 0.0
    area = math.pi * r_cyl * r_cyl
    res_i = r_i / (p[K_I] * area)
    res_j = 0.0 if math.isinf(r_j) else r_j / (p[K_J] * area)
    return (t_j - t_i) / ((res_i + res_j) + 1.0 / h_bob)


# --------------------------------------------------------------------------- registration
_BOB = "Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333"

register_model(
    "batchelor_obrien_simple", BATCHELOR_OBRIEN_SIMPLE, bob_simple_rate,
    BatchelorOBrienSimpleParams,
    "Q = 4 k̄ R_c ΔT, k̄ = k_i k_j/(k_i + k_j) (large-η Batchelor & O'Brien)",
    _BOB + "; Cheng, Yu & Zulli (1999) Chem. Eng. Sci. 54, 4199-4209",
)  # fmt: skip
register_model(
    "batchelor_obrien_complete", BATCHELOR_OBRIEN_COMPLETE, bob_complete_rate,
    BatchelorOBrienCompleteParams,
    "Batchelor & O'Brien contact (η regimes) and separated-particle conduction",
    _BOB + "; Dai, Hanaor & Gan (2019); Moscardini et al. (2018)",
    pack_bob_complete, interaction_range=bob_interaction_range, columns=BOB_COLUMNS,
    range_parameter="cutoff_gap_ratio",
    uses_gas=("thermal_conductivity",),
)  # fmt: skip
register_model(
    "batchelor_obrien_modified", BATCHELOR_OBRIEN_MODIFIED, bob_modified_rate,
    BatchelorOBrienModifiedParams,
    "Batchelor & O'Brien in series with the particles' inner resistances (Yun & Evans)",
    "Yun & Evans (2010) Comput. Geotech. 37, 991-998; Dai, Hanaor & Gan (2019) Int. J. Therm. "
    "Sci. 142, 266-279",
    pack_bob_modified, interaction_range=bob_interaction_range, columns=BOB_MODIFIED_COLUMNS,
    range_parameter="cutoff_gap_ratio",
    uses_gas=("thermal_conductivity",),
)  # fmt: skip
