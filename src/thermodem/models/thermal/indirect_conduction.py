"""Conduction through the interstitial fluid (family ``indirect_conduction``): ``none``, the
Batchelor & O'Brien (1977) model for separated particles, and the family dispatcher.

Kernel signature (all float64 scalars, ``p`` the packed row of the type pair)::

    kernel(p, r_i, r_j, dist, r_c, f_n) -> conductance H [W/K] >= 0

i.e. (p, radius_i, radius_j, distance, contact_radius, normal_force). The heat rate into
particle i is H (T_j - T_i). ``dist`` is the centre distance; a flat wall is ``r_j = inf``
with ``dist`` the distance from the particle centre to the wall plane (the wall material is
``mat_j`` in ``pack``). ``r_c`` is the contact radius where the bodies overlap (> 0; on a
``range`` pair set the geometric radius R_c^geo, on a ``contacts`` set the case's
contact_radius model), else 0; ``f_n`` the normal force (0 where not known). A kernel
returns 0 beyond its model's interaction range, never raises (``error_model="numpy"``), and
builds H from exactly commutative operations of the two sides (a + b, a * b, min, max,
|a - b|), so that swapping i and j — radii and the row columns in ``swap_pairs`` — gives the
same H bit for bit.

Registration metadata (``register(**extra)``): ``columns`` (the row's column names; ``pack``
returns exactly that many values), ``swap_pairs`` and ``target``: ``"range"`` (every pair
within the interaction range, touching included, geometry only) or ``"contacts"`` (touching
pairs, with r_c from the contact radius model and f_n).

Models: ``batchelor_obrien_separated`` (here), ``rong_horio1999`` and ``musser2011``
(``surrounding_layer.py``), ``vargas_mccarthy2002`` (``vargas_mccarthy.py``). Formulas,
choices and their reasons: ``docs/models/indirect_conduction-*.md``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field, field_validator

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
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
from thermodem.models.thermal.contact_radius import effective_radius, require
from thermodem.models.thermal.surrounding_layer import (
    MUSSER2011,
    RONG_HORIO1999,
    musser2011_conductance,
    rong_horio1999_conductance,
    rong_horio1999_spheres,
)
from thermodem.models.thermal.vargas_mccarthy import (
    VARGAS_MCCARTHY2002,
    vargas_mccarthy2002_conductance,
)
from thermodem.state.materials import PairContext

FAMILY = "indirect_conduction"

NONE = 0
BATCHELOR_OBRIEN_SEPARATED = 1
# RONG_HORIO1999 = 2 and MUSSER2011 = 3 are defined in surrounding_layer.py,
# VARGAS_MCCARTHY2002 = 4 in vargas_mccarthy.py

# ---------------------------------------------------------------------------------- none
NONE_COLUMNS: tuple[str, ...] = ()


class NoneParams(StrictModel):
    """No conduction through the interstitial fluid."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def none_conductance(p, r_i, r_j, dist, r_c, f_n):
    return 0.0


# ------------------------------------------------------- Batchelor & O'Brien, separated
BOB_K_I = 0
BOB_K_J = 1
BOB_K_F = 2
BOB_REGIME = 3
BOB_CYLINDER = 4
BOB_CUTOFF = 5
BOB_COLUMNS = ("k_i", "k_j", "k_f", "regime", "cylinder_ratio", "cutoff_gap_ratio")
BOB_SWAP_PAIRS = ((BOB_K_I, BOB_K_J),)


class BatchelorOBrienSeparatedParams(StrictModel):
    """Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333, conduction through the
    fluid between separated particles (spec "Static Contact Models – particles separated").

    λ = k_pf² d_s/(2R̄), d_s = d - R_i - R_j, R̄ = R_i R_j/(R_i + R_j); H = 2π R̄ k_f X with
    X_near = ln k_pf² (λ ≪ 1) or X_far = ln(1 + r̄²/(2 R̄ d_s)) (λ ≫ 1), chosen by ``regime``:
    ``dai2019`` (λ < 0.01 near, λ > 100 far, min(near, far) between: Dai, Hanaor & Gan 2019),
    ``moscardini2018`` (λ < 0.1 near, else far: Moscardini et al. 2018) or ``minimum``.
    k_p = 2 k_i k_j/(k_i + k_j) (wall: with the wall material's k), k_f =
    ``thermal.gas.thermal_conductivity``. Conducts for 0 < d_s < ``cutoff_gap_ratio`` R̄;
    touching pairs are the direct conduction model's (H = 0 here). A wall: R̄ = R_i, d_s =
    d - R_i. Row: [k_i, k_j, k_f, regime, r̄/R̄, d_s,max/R̄].
    """

    regime: RegimeName = regime_field()
    cylinder_radius: float | CylinderName = Field(default="dai2019", description=CYLINDER_HELP)
    cutoff_gap_ratio: float = Field(
        default=1.0, gt=0, description="largest conducting gap d_s / R̄ [-] (Yun & Evans 2010)"
    )

    @field_validator("cylinder_radius")
    @classmethod
    def _positive_ratio(cls, v: float | str) -> float | str:
        return check_cylinder(v)

    def cylinder_ratio(self) -> float:
        """r̄ / R̄ [-] of the selected conduction cylinder."""
        return cylinder_ratio(self.cylinder_radius)


def pack_bob_separated(params: BatchelorOBrienSeparatedParams, pair: PairContext) -> np.ndarray:
    model = f"{FAMILY}.batchelor_obrien_separated"
    k_i = require(pair.mat_i, "thermal_conductivity", model)
    k_j = require(pair.mat_j, "thermal_conductivity", model)
    k_f = pair.gas.thermal_conductivity
    k_p = 2.0 * k_i * k_j / (k_i + k_j)
    if k_p <= k_f:
        raise ValueError(
            f"{model} needs particle conductivity above the gas's (k_p/k_f > 1, ln k_pf² > 0): "
            f"k_p = 2 k_i k_j/(k_i + k_j) = {k_p:g} W/(m K), "
            f"thermal.gas.thermal_conductivity = {k_f:g} W/(m K)"
        )
    values = [k_i, k_j, k_f, REGIMES[params.regime], params.cylinder_ratio()]
    return np.array([*values, params.cutoff_gap_ratio], dtype=np.float64)


def bob_separated_range(
    params: BatchelorOBrienSeparatedParams, radius_i: float, radius_j: float
) -> float:
    """Largest surface gap [m] at which H > 0: cutoff_gap_ratio × R̄ (wall: R̄ = R_i)."""
    r_eff = radius_i if math.isinf(radius_j) else radius_i * radius_j / (radius_i + radius_j)
    return params.cutoff_gap_ratio * r_eff


@njit(cache=True, inline="always", error_model="numpy")
def bob_separated_conductance(p, r_i, r_j, dist, r_c, f_n):
    """H = 2π R̄ k_f X(λ) for 0 < d_s < cutoff R̄, else 0 (see the params' docstring)."""
    r_eff = effective_radius(r_i, r_j)
    if math.isinf(r_j):
        gap = dist - r_i
    else:
        gap = dist - (r_i + r_j)
    gap_ratio = gap / r_eff
    if not (gap_ratio > 0.0 and gap_ratio < p[BOB_CUTOFF]):
        return 0.0
    k_i = p[BOB_K_I]
    k_j = p[BOB_K_J]
    k_p = 2.0 * (k_i * k_j) / (k_i + k_j)
    return gap_conductance(k_p, p[BOB_K_F], r_eff, gap, p[BOB_CYLINDER], p[BOB_REGIME])


# ---------------------------------------------------------------------------- dispatcher
@njit(cache=True, inline="always", error_model="numpy")
def indirect_conduction_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n):
    """Conductance H [W/K] of model ``model_id`` (NaN for an unknown id: the NaN flag)."""
    if model_id == BATCHELOR_OBRIEN_SEPARATED:
        return bob_separated_conductance(p, r_i, r_j, dist, r_c, f_n)
    elif model_id == RONG_HORIO1999:
        return rong_horio1999_conductance(p, r_i, r_j, dist, r_c, f_n)
    elif model_id == MUSSER2011:
        return musser2011_conductance(p, r_i, r_j, dist, r_c, f_n)
    elif model_id == VARGAS_MCCARTHY2002:
        return vargas_mccarthy2002_conductance(p, r_i, r_j, dist, r_c, f_n)
    elif model_id == NONE:
        return 0.0
    return np.nan


#: Models whose sphere form (indirect_sphere_dispatch) is branch-free and calls no library
#: function, so that the range pass computes it in a loop LLVM vectorises (kernels/range_pass.py)
VECTORISED_SPHERE_FORMS = frozenset({RONG_HORIO1999})


@njit(cache=True, inline="always", error_model="numpy")
def indirect_sphere_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n):
    """:func:`indirect_conduction_dispatch` for two spheres (``r_j`` finite; the range pair
    pass): a model with a branch-free sphere form is called without its wall branch, so that
    the pass's conductance loop vectorises (``kernels/range_pass.py``); others: their kernel."""
    if model_id == RONG_HORIO1999:
        return rong_horio1999_spheres(p, r_i, r_j, dist, r_c, f_n)
    return indirect_conduction_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n)


# --------------------------------------------------------------------------- registration
_BOB = "Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333"

register(
    family=FAMILY,
    name="none",
    model_id=NONE,
    kernel=none_conductance,
    params=NoneParams,
    pack=pack_none,
    summary="no conduction through the interstitial fluid",
    reference="-",
    antisymmetric=False,
    symmetric=True,
    columns=NONE_COLUMNS,
    swap_pairs=(),
    target="contacts",
    planar=("disc", "sphere"),
)
register(
    family=FAMILY,
    name="batchelor_obrien_separated",
    model_id=BATCHELOR_OBRIEN_SEPARATED,
    kernel=bob_separated_conductance,
    params=BatchelorOBrienSeparatedParams,
    pack=pack_bob_separated,
    summary="Batchelor & O'Brien conduction through the gas gap of separated particles",
    reference=_BOB + "; Dai, Hanaor & Gan (2019) Int. J. Therm. Sci. 142, 266-279; Moscardini "
    "et al. (2018) Fusion Eng. Des. 127, 192-201; Yun & Evans (2010) Comput. Geotech. 37, "
    "991-998; Kanuparthi et al. (2008) IEEE Trans. Compon. Packag. Technol. 31, 611-621",
    requires=("thermal_conductivity",),
    uses_gas=("thermal_conductivity",),
    interaction_range=bob_separated_range,
    range_parameter="cutoff_gap_ratio",
    uses_contact_radius=False,
    antisymmetric=False,
    symmetric=True,
    columns=BOB_COLUMNS,
    swap_pairs=BOB_SWAP_PAIRS,
    target="range",
    planar=("sphere",),
)
