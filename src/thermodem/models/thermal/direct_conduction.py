"""Direct (particle-particle contact) conduction models (family ``direct_conduction``).

Kernel signature (all float64 scalars, ``p`` the packed row of the type pair)::

    kernel(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
        -> heat rate INTO particle i [W]

i.e. (p, temperature_i, temperature_j, radius_i, radius_j, distance, overlap, contact_radius,
normal_force, contact_duration, impact_velocity, mass_eff). ``r_c`` comes from the selected
``contact_radius`` model; ``overlap`` δ is negative for separated pairs (gap -δ), and the
centre distance is taken as R_i + R_j - δ (``dist`` is not used). A wall is ``r_j = inf``
with the wall material as ``mat_j`` in ``pack``.

Antisymmetry: every kernel returns H (T_j - T_i) with a conductance H built only from
exactly commutative operations (a + b, a * b, min) of the two sides' terms, so swapping i and
j — temperatures, radii and the row columns listed in ``swap_pairs`` (see :func:`swap_row`) —
negates the result bit for bit, and it is 0 at equal temperatures.

Row layout shared by the family: the named columns ``k_i, k_j, rhoc_i, rhoc_j`` first
(:data:`HEAD`, indices :data:`K_I`, :data:`K_J`, :data:`RHOC_I`, :data:`RHOC_J`), then each
model's own symmetric columns, named in its ``register(columns=...)`` and indexed by module
constants; ``swap_pairs = ((0, 1), (2, 3))``. The static kernels read only ``k_i`` and ``k_j``,
which is what lets the collisional models call them with their own row, and the k(T)/ρc(T)
override of the engine replaces exactly these four columns.

Kernels are compiled with ``error_model="numpy"``: they never raise (a division by zero gives
inf/NaN, which the NaN flag of the pair loop catches), as the architecture asks of kernels.

Walls: where a formula has a finite R_j -> inf limit it is used (R* = R_i). Pipe and network
models have a wall-side resistance ∝ R_j whose formal limit cuts conduction off: there the wall
is isothermal at its surface and only the particle's segment remains (see each docs page).
"""

from __future__ import annotations

import math
from typing import Literal

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
from thermodem.models.thermal.contact_radius import (
    effective_radius,
    hertz_collision_time,
    hertz_max_contact_radius,
    require,
)
from thermodem.models.thermal.resistance_network import (
    RESISTANCE_NETWORK,
    resistance_network_rate,
)
from thermodem.state.materials import PairContext

NONE = 0
BATCHELOR_OBRIEN_SIMPLE = 1
BATCHELOR_OBRIEN_COMPLETE = 2
BATCHELOR_OBRIEN_MODIFIED = 3
THERMAL_PIPE = 4
QUINTANA_RUIZ_CAMPELLO2020 = 5
ROJEK2014 = 6
SUN_CHEN1988 = 7
ZHOU2008 = 8
# RESISTANCE_NETWORK = 9 is defined in resistance_network.py

FAMILY = "direct_conduction"
SWAP_PAIRS = ((0, 1), (2, 3))

#: The columns every row of the family starts with (the override replaces them).
HEAD = ("k_i", "k_j", "rhoc_i", "rhoc_j")
K_I, K_J, RHOC_I, RHOC_J = 0, 1, 2, 3
#: Batchelor & O'Brien complete (and modified: one column more).
BOB_COLUMNS = (*HEAD, "k_f", "blend", "cylinder_ratio", "cutoff_gap_ratio", "regime")
BOB_K_F, BOB_BLEND, BOB_CYLINDER_RATIO, BOB_CUTOFF_RATIO, BOB_REGIME = 4, 5, 6, 7, 8
BOB_MODIFIED_COLUMNS = (*BOB_COLUMNS, "dai2019_correlation")
BOB_DAI2019 = 9
#: Collisional models (Sun & Chen, Zhou).
COLLISIONAL_COLUMNS = (*HEAD, "e_star", "correction_factor", "static_model")
COL_E_STAR, COL_CORRECTION, COL_STATIC_MODEL = 4, 5, 6

BLEND_SPEC_LINEAR = 0
BLEND_HERMITE = 1
_BLENDS = {"spec_linear": BLEND_SPEC_LINEAR, "hermite": BLEND_HERMITE}


def swap_row(row: np.ndarray, swap_pairs: tuple[tuple[int, int], ...] = SWAP_PAIRS) -> np.ndarray:
    """The row of the swapped pair (j, i): columns of each pair in ``swap_pairs`` exchanged."""
    out = np.array(row, dtype=np.float64, copy=True)
    for a, b in swap_pairs:
        out[a], out[b] = row[b], row[a]
    return out


def _conductivities(pair: PairContext, model: str) -> list[float]:
    return [require(m, "thermal_conductivity", model) for m in (pair.mat_i, pair.mat_j)]


def _heat_capacities(pair: PairContext, model: str) -> list[float]:
    return [m.density * require(m, "specific_heat", model) for m in (pair.mat_i, pair.mat_j)]


def head_values(k: list[float], rhoc: tuple[float, float] = (0.0, 0.0)) -> dict[str, float]:
    """The family's head columns from the two conductivities (and heat capacities)."""
    return {"k_i": k[0], "k_j": k[1], "rhoc_i": rhoc[0], "rhoc_j": rhoc[1]}


# --------------------------------------------------------------------------------- none
class NoneParams(StrictModel):
    """No direct conduction."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed(HEAD, head_values([0.0, 0.0]))


@njit(cache=True, error_model="numpy")
def none_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    return 0.0


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


class BatchelorOBrienCompleteParams(StrictModel):
    """Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333: contact through the
    contact circle and the surrounding fluid, and near (separated) particles (spec 2.3).

    Total conduction (direct + through the fluid near the contact): do not combine it with an
    indirect_conduction model. k_f is the conductivity of the case's gas (``thermal.gas``,
    ``pair.gas``). k_p = 2 k_i k_j/(k_i + k_j) (harmonic mean, so that the large-η limit is
    batchelor_obrien_simple), k_pf = k_p/k_f must exceed 1. The 1 <= η <= 100 blend
    of the spec is not monotonic (see bob_contact_h); ``blend="hermite"`` is a monotonic one.
    Separated pairs conduct up to a gap ``cutoff_gap_ratio`` R* (Yun & Evans 2010: d_s < R̄),
    through a cylinder of radius ``cylinder_radius`` R* (a number, or a named choice of the
    spec: dai2019 = 2.00, Dai et al. 2019; for equal spheres R* = R/2, so 2.00 is a cylinder of
    the particle radius), with the λ rule ``regime`` (as batchelor_obrien_separated).
    Row: [k_i, k_j, 0, 0, k_f, blend, r̄/R*, d_s,max/R*, regime].
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

    @field_validator("cylinder_radius")
    @classmethod
    def _cylinder(cls, v: float | str) -> float | str:
        return check_cylinder(v)


def _check_kpf(k_i: float, k_j: float, k_f: float, model: str) -> None:
    k_p = 2.0 * k_i * k_j / (k_i + k_j)
    if k_p <= k_f:
        raise ValueError(
            f"{model} needs particle conductivity above the gas's (k_p/k_f > 1): "
            f"k_p = {k_p:g} W/(m K), thermal.gas.thermal_conductivity = {k_f:g} W/(m K)"
        )


def pack_bob_complete(params: BatchelorOBrienCompleteParams, pair: PairContext) -> np.ndarray:
    model = "direct_conduction.batchelor_obrien_complete"
    k_i, k_j = _conductivities(pair, model)
    k_f = pair.gas.thermal_conductivity
    _check_kpf(k_i, k_j, k_f, model)
    values = head_values([k_i, k_j]) | {"k_f": k_f, "blend": _BLENDS[params.blend],
                                        "cylinder_ratio": cylinder_ratio(params.cylinder_radius),
                                        "cutoff_gap_ratio": params.cutoff_gap_ratio,
                                        "regime": REGIMES[params.regime]}  # fmt: skip
    return packed(BOB_COLUMNS, values)


def bob_interaction_range(params: StrictModel, radius_i: float, radius_j: float) -> float:
    """Largest surface gap [m] at which a separated pair conducts: cutoff_gap_ratio × R*."""
    r_eff = radius_i if math.isinf(radius_j) else radius_i * radius_j / (radius_i + radius_j)
    return params.cutoff_gap_ratio * r_eff


@njit(cache=True, error_model="numpy")
def bob_complete_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    r_eff = effective_radius(r_i, r_j)
    k_p = 2.0 * p[K_I] * p[K_J] / (p[K_I] + p[K_J])
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
    Row: [k_i, k_j, 0, 0, k_f, blend, r̄/R*, d_s,max/R*, regime, 1 if dai2019_correlation].
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
    k_i, k_j = _conductivities(pair, model)
    k_f = pair.gas.thermal_conductivity
    _check_kpf(k_i, k_j, k_f, model)
    dai = params.cylinder_radius == "dai2019_correlation"
    ratio = 0.0 if dai else cylinder_ratio(params.cylinder_radius)
    values = head_values([k_i, k_j]) | {"k_f": k_f, "blend": _BLENDS[params.blend],
                                        "cylinder_ratio": ratio,
                                        "cutoff_gap_ratio": params.cutoff_gap_ratio,
                                        "regime": REGIMES[params.regime],
                                        "dai2019_correlation": 1.0 if dai else 0.0}  # fmt: skip
    return packed(BOB_MODIFIED_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def bob_modified_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    r_eff = effective_radius(r_i, r_j)
    k_p = 2.0 * p[K_I] * p[K_J] / (p[K_I] + p[K_J])
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


# ------------------------------------------------------------------------- thermal pipes
class ThermalPipeParams(StrictModel):
    """Generic thermal pipe Q = k A_p / d_ij (T_j - T_i), A_p = π R_c² (spec 2.4; Jebahi et al.
    2015; Hahn et al. 2011). k: two equal half pipes in series, i.e. the harmonic mean
    2 k_i k_j/(k_i + k_j). Wall: the particle's pipe from its centre to the wall plane,
    Q = k_i A_p / (R_i - δ) ΔT. Row: [k_i, k_j]."""


@njit(cache=True, error_model="numpy")
def thermal_pipe_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0 or r_c <= 0.0:
        return 0.0
    area = math.pi * r_c * r_c
    if math.isinf(r_j):
        return p[K_I] * area / (r_i - overlap) * (t_j - t_i)
    k_h = 2.0 * p[K_I] * p[K_J] / (p[K_I] + p[K_J])
    return k_h * area / ((r_i + r_j) - overlap) * (t_j - t_i)


class QuintanaRuizCampello2020Params(StrictModel):
    """Quintana-Ruiz & Campello (2020) J. Braz. Soc. Mech. Sci. Eng. 42, 387 (spec 2.4):
    Q = k̃ π R_c² / d_ij ΔT, k̃ = (R_i + R_j)(R_i/k_i + R_j/k_j)^-1 (segments proportional to
    the radii). Wall: the wall segment is dropped and the particle's segment tends to R_i,
    Q = k_i π R_c² / R_i ΔT. Row: [k_i, k_j]."""


@njit(cache=True, error_model="numpy")
def qrc2020_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0 or r_c <= 0.0:
        return 0.0
    area = math.pi * r_c * r_c
    if math.isinf(r_j):
        return p[K_I] * area / r_i * (t_j - t_i)
    k_tilde = (r_i + r_j) / (r_i / p[K_I] + r_j / p[K_J])
    return k_tilde * area / ((r_i + r_j) - overlap) * (t_j - t_i)


class Rojek2014Params(StrictModel):
    """Rojek (2014) Comput. Part. Mech. 1, 71-84, 3D bar (spec 2.4): Q = k_p b ΔT with
    A_p = 2 r̃ b, d_ij = 2 r̃, b = r̃ = (R_i + R_j)/2; two half bars in series give k_p = the
    harmonic mean of k_i, k_j. Independent of the contact radius (only of touching).
    Wall: the particle's half bar (r̃ = R_i), Q = 2 k_i R_i ΔT. Row: [k_i, k_j]."""


@njit(cache=True, error_model="numpy")
def rojek2014_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    if overlap <= 0.0:
        return 0.0
    if math.isinf(r_j):
        return 2.0 * p[K_I] * r_i * (t_j - t_i)
    k_h = 2.0 * p[K_I] * p[K_J] / (p[K_I] + p[K_J])
    return k_h * 0.5 * (r_i + r_j) * (t_j - t_i)


# ----------------------------------------------------------------------- collisional
_STATIC_MODELS = {
    "none": NONE,
    "batchelor_obrien_simple": BATCHELOR_OBRIEN_SIMPLE,
    "thermal_pipe": THERMAL_PIPE,
    "quintana_ruiz_campello2020": QUINTANA_RUIZ_CAMPELLO2020,
    "rojek2014": ROJEK2014,
}
StaticModel = Literal[tuple(_STATIC_MODELS)]


@njit(cache=True, error_model="numpy")
def static_rate(
    static_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
):
    """The static model a collisional model switches to after t_c (reads row columns 0-1)."""
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    if static_id == BATCHELOR_OBRIEN_SIMPLE:
        return bob_simple_rate(p, *args)
    elif static_id == THERMAL_PIPE:
        return thermal_pipe_rate(p, *args)
    elif static_id == QUINTANA_RUIZ_CAMPELLO2020:
        return qrc2020_rate(p, *args)
    elif static_id == ROJEK2014:
        return rojek2014_rate(p, *args)
    return 0.0


@njit(cache=True, error_model="numpy")
def zhou2008_coefficient(ratio, fourier):
    """C of Zhou, Yu & Horio (2008) for ρc ratio r = ρ_i c_i/ρ_j c_j and Fourier number Fo.

    C = 0.435 (sqrt(C2² - 4 C1 (C3 - Fo)) - C2) / C1 = 0.87 x, x the positive root of
    C1 x² + C2 x + C3 = Fo, evaluated without cancellation (conjugate form when C2 > 0).
    A negative discriminant (outside the fitted range) is taken as 0.
    """
    c1 = -2.300 * ratio * ratio + 8.909 * ratio - 4.235
    c2 = 8.169 * ratio * ratio - 33.770 * ratio + 24.885
    c3 = -5.758 * ratio * ratio + 24.464 * ratio - 20.511
    q = fourier - c3
    disc = max(c2 * c2 + 4.0 * c1 * q, 0.0)
    s = math.sqrt(disc)
    if c2 > 0.0:
        return 0.87 * 2.0 * q / (s + c2)
    return 0.435 * (s - c2) / c1


class SunChen1988Params(StrictModel):
    """Sun & Chen (1988) Int. J. Heat Mass Transf. 31, 969-975, collisional conduction
    (spec 2.2): Q = U/t_c = C 0.87 π (R_c^max)² t_c^-1/2 / ((ρ_i c_i k_i)^-1/2 +
    (ρ_j c_j k_j)^-1/2) ΔT, with R_c^max and t_c of an elastic Hertz impact at the recorded
    impact velocity (appendix A; simulation E*, R*, m*). While contact_duration < t_c the
    collisional rate is used, afterwards (and when no impact velocity is known) the static
    model (Zhou et al. 2009's suggestion). C is the paper's correction factor, read from its
    graphs; 1 is the semi-infinite media (small Fourier number) solution.
    Row: [k_i, k_j, (ρc)_i, (ρc)_j, E*, C, static model id].
    """

    correction_factor: float = Field(
        default=1.0, ge=0, description="C [-], Sun & Chen's correction factor (1: small Fo)"
    )
    static_model: StaticModel = Field(
        default="batchelor_obrien_simple", description="static model used after t_c"
    )


class Zhou2008Params(StrictModel):
    """Zhou, Yu & Horio (2008) Chem. Eng. J. 139, 510-516, collisional conduction (spec 2.2):
    Q = C π (R_c^max)² t_c^-1/2 / ((ρ_i c_i k_i)^-1/2 + (ρ_j c_j k_j)^-1/2) ΔT, C from the
    Fourier number Fo = k_i t_c / (ρ_i c_i (R_c^max)²) and the ratio ρ_i c_i/ρ_j c_j
    (:func:`zhou2008_coefficient`). The fit is written for particle i; to keep Q exactly
    antisymmetric C is the mean of the (i, j) and (j, i) evaluations (identical materials: the
    paper's C). C1 vanishes at ratios ≈ 0.555 and ≈ 3.32, so the symmetrised fit is only
    meaningful for ρc ratios within about (0.56, 1.8). Switch to ``static_model`` after t_c as
    sun_chen1988. Row: [k_i, k_j, (ρc)_i, (ρc)_j, E*, 0, static model id].
    """

    static_model: StaticModel = Field(
        default="batchelor_obrien_simple", description="static model used after t_c"
    )


def _pack_collisional(params: StrictModel, pair: PairContext, model: str, c: float) -> np.ndarray:
    values = head_values(_conductivities(pair, model), _heat_capacities(pair, model))
    values |= {"e_star": pair.effective_youngs_modulus, "correction_factor": c,
               "static_model": _STATIC_MODELS[params.static_model]}  # fmt: skip
    return packed(COLLISIONAL_COLUMNS, values)


def pack_sun_chen1988(params: SunChen1988Params, pair: PairContext) -> np.ndarray:
    return _pack_collisional(
        params, pair, "direct_conduction.sun_chen1988", params.correction_factor
    )


def pack_zhou2008(params: Zhou2008Params, pair: PairContext) -> np.ndarray:
    return _pack_collisional(params, pair, "direct_conduction.zhou2008", 0.0)


@njit(cache=True, error_model="numpy")
def collisional_rate(
    p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff, zhou
):
    """Sun & Chen (zhou False) or Zhou (zhou True) rate while t_contact < t_c of the Hertz
    impact at v_impact; the static model of column 6 otherwise (or without an impact)."""
    if overlap <= 0.0:
        return 0.0
    r_eff = effective_radius(r_i, r_j)
    if v_impact > 0.0 and m_eff > 0.0:
        e_star = p[COL_E_STAR]
        t_c = hertz_collision_time(m_eff, r_eff, e_star, v_impact)
        if t_contact < t_c:
            r_max = hertz_max_contact_radius(m_eff, r_eff, e_star, v_impact)
            if r_max <= 0.0:  # v_impact so small that R_c^max underflows: Q -> 0
                return 0.0
            k_i, k_j, rhoc_i, rhoc_j = p[K_I], p[K_J], p[RHOC_I], p[RHOC_J]
            effusivity = 1.0 / math.sqrt(rhoc_i * k_i) + 1.0 / math.sqrt(rhoc_j * k_j)
            if zhou:
                area = r_max * r_max
                c_i = zhou2008_coefficient(rhoc_i / rhoc_j, k_i * t_c / (rhoc_i * area))
                c_j = zhou2008_coefficient(rhoc_j / rhoc_i, k_j * t_c / (rhoc_j * area))
                c = 0.5 * (c_i + c_j)
            else:
                c = 0.87 * p[COL_CORRECTION]
            return c * math.pi * r_max * r_max / (math.sqrt(t_c) * effusivity) * (t_j - t_i)
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    return static_rate(int(p[COL_STATIC_MODEL]), p, *args)


@njit(cache=True, error_model="numpy")
def sun_chen1988_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    return collisional_rate(p, *args, False)


@njit(cache=True, error_model="numpy")
def zhou2008_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    return collisional_rate(p, *args, True)


# ----------------------------------------------------------- separated pairs (range set)
@njit(cache=True, inline="always", error_model="numpy")
def separated_conductance(model_id, p, r_i, r_j, dist):
    """Conductance H [W/K] of the *separated-pair* part of a direct model that conducts across
    a gap (those registered with an ``interaction_range``: Batchelor & O'Brien complete and
    modified), 0 for touching pairs and other models.

    The engine evaluates it on the range pair set (pairs within the model's largest gap), and
    the contact pass evaluates the same kernels on touching pairs only, so no pair is counted
    twice. A wall is ``r_j = inf`` with ``dist`` the centre-to-wall distance.
    """
    overlap = (r_i - dist) if math.isinf(r_j) else (r_i + r_j) - dist
    if overlap >= 0.0:
        return 0.0
    if model_id == BATCHELOR_OBRIEN_COMPLETE:
        return bob_complete_rate(p, 0.0, 1.0, r_i, r_j, dist, overlap, 0.0, 0.0, 0.0, 0.0, 0.0)
    elif model_id == BATCHELOR_OBRIEN_MODIFIED:
        return bob_modified_rate(p, 0.0, 1.0, r_i, r_j, dist, overlap, 0.0, 0.0, 0.0, 0.0, 0.0)
    return 0.0


# ---------------------------------------------------------------------------- dispatcher
@njit(cache=True, inline="always", error_model="numpy")
def direct_conduction_dispatch(
    model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
):
    """Heat rate into i of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    if model_id == BATCHELOR_OBRIEN_SIMPLE:
        return bob_simple_rate(p, *args)
    elif model_id == BATCHELOR_OBRIEN_COMPLETE:
        return bob_complete_rate(p, *args)
    elif model_id == BATCHELOR_OBRIEN_MODIFIED:
        return bob_modified_rate(p, *args)
    elif model_id == THERMAL_PIPE:
        return thermal_pipe_rate(p, *args)
    elif model_id == QUINTANA_RUIZ_CAMPELLO2020:
        return qrc2020_rate(p, *args)
    elif model_id == ROJEK2014:
        return rojek2014_rate(p, *args)
    elif model_id == SUN_CHEN1988:
        return sun_chen1988_rate(p, *args)
    elif model_id == ZHOU2008:
        return zhou2008_rate(p, *args)
    elif model_id == RESISTANCE_NETWORK:
        return resistance_network_rate(p, *args)
    elif model_id == NONE:
        return 0.0
    return np.nan


# --------------------------------------------------------------------------- registration
_BOB = "Batchelor & O'Brien (1977) Proc. R. Soc. Lond. A 355, 313-333"
_COLL = ("thermal_conductivity", "density", "specific_heat", "youngs_modulus", "poisson_ratio")


def _register(name, model_id, kernel, params, summary, reference, pack=None, **kw):
    """register() with this family's swap pairs; default pack: [k_i, k_j]."""

    def pack_k(params: StrictModel, pair: PairContext) -> np.ndarray:
        return packed(HEAD, head_values(_conductivities(pair, f"{FAMILY}.{name}")))

    kw.setdefault("requires", ("thermal_conductivity",))
    kw.setdefault("columns", HEAD)
    register(family=FAMILY, name=name, model_id=model_id, kernel=kernel, params=params,
             pack=pack or pack_k, summary=summary, reference=reference, swap_pairs=SWAP_PAIRS,
             **kw)  # fmt: skip


_register("none", NONE, none_rate, NoneParams, "no direct conduction", "-", pack_none, requires=())
_register(
    "batchelor_obrien_simple", BATCHELOR_OBRIEN_SIMPLE, bob_simple_rate,
    BatchelorOBrienSimpleParams,
    "Q = 4 k̄ R_c ΔT, k̄ = k_i k_j/(k_i + k_j) (large-η Batchelor & O'Brien)",
    _BOB + "; Cheng, Yu & Zulli (1999) Chem. Eng. Sci. 54, 4199-4209",
)  # fmt: skip
_register(
    "batchelor_obrien_complete", BATCHELOR_OBRIEN_COMPLETE, bob_complete_rate,
    BatchelorOBrienCompleteParams,
    "Batchelor & O'Brien contact (η regimes) and separated-particle conduction",
    _BOB + "; Dai, Hanaor & Gan (2019); Moscardini et al. (2018)",
    pack_bob_complete, interaction_range=bob_interaction_range, columns=BOB_COLUMNS,
    range_parameter="cutoff_gap_ratio",
    uses_gas=("thermal_conductivity",),
)  # fmt: skip
_register(
    "batchelor_obrien_modified", BATCHELOR_OBRIEN_MODIFIED, bob_modified_rate,
    BatchelorOBrienModifiedParams,
    "Batchelor & O'Brien in series with the particles' inner resistances (Yun & Evans)",
    "Yun & Evans (2010) Comput. Geotech. 37, 991-998; Dai, Hanaor & Gan (2019) Int. J. Therm. "
    "Sci. 142, 266-279",
    pack_bob_modified, interaction_range=bob_interaction_range, columns=BOB_MODIFIED_COLUMNS,
    range_parameter="cutoff_gap_ratio",
    uses_gas=("thermal_conductivity",),
)  # fmt: skip
_register(
    "thermal_pipe", THERMAL_PIPE, thermal_pipe_rate, ThermalPipeParams,
    "thermal pipe Q = k_h π R_c² / d ΔT between the centres",
    "Jebahi et al. (2015) DEM for 3D continuous materials, Wiley; Hahn et al. (2011)",
)  # fmt: skip
_register(
    "quintana_ruiz_campello2020", QUINTANA_RUIZ_CAMPELLO2020, qrc2020_rate,
    QuintanaRuizCampello2020Params,
    "thermal pipe with k̃ = (R_i + R_j)/(R_i/k_i + R_j/k_j), A = π R_c²",
    "Quintana-Ruiz & Campello (2020) J. Braz. Soc. Mech. Sci. Eng. 42, 387",
)  # fmt: skip
_register(
    "rojek2014", ROJEK2014, rojek2014_rate, Rojek2014Params,
    "3D bar Q = k_h r̃ ΔT, r̃ = (R_i + R_j)/2", "Rojek (2014) Comput. Part. Mech. 1, 71-84",
)  # fmt: skip
_register(
    "sun_chen1988", SUN_CHEN1988, sun_chen1988_rate, SunChen1988Params,
    "collisional conduction U/t_c of a Hertz impact, then a static model after t_c",
    "Sun & Chen (1988) Int. J. Heat Mass Transf. 31, 969-975; Zhou, Yu & Zulli (2009)",
    pack_sun_chen1988, requires=_COLL, columns=COLLISIONAL_COLUMNS,
)  # fmt: skip
_register(
    "zhou2008", ZHOU2008, zhou2008_rate, Zhou2008Params,
    "collisional conduction with Zhou's explicit C(Fo), then a static model after t_c",
    "Zhou, Yu & Horio (2008) Chem. Eng. J. 139, 510-516; Zhou, Yu & Zulli (2009)",
    pack_zhou2008, requires=_COLL, columns=COLLISIONAL_COLUMNS,
)  # fmt: skip
