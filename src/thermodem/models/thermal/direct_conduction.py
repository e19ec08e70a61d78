"""Direct (particle-particle contact) conduction models (family ``direct_conduction``).

This module: the conventions of the family, ``none``, the thermal pipes (``thermal_pipe``,
``quintana_ruiz_campello2020``, ``rojek2014``), the collisional models (``sun_chen1988``,
``zhou2008``) and the dispatchers. Batchelor & O'Brien (``batchelor_obrien_simple``,
``_complete``, ``_modified``) are in ``batchelor_obrien_contact.py``, the resistance network
in ``resistance_network.py``, the row head and registration helper they share in
``direct_conduction_family.py``.

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
j — temperatures, radii and the row columns listed in ``swap_pairs`` (see
``direct_conduction_family.swap_row``) — negates the result bit for bit, and it is 0 at equal
temperatures.

Row layout shared by the family: the named columns ``k_i, k_j, rhoc_i, rhoc_j`` first
(``HEAD``, indices ``K_I``, ``K_J``, ``RHOC_I``, ``RHOC_J`` of ``direct_conduction_family``),
then each model's own symmetric columns, named in its ``register(columns=...)`` and indexed by
module constants; ``swap_pairs = ((0, 1), (2, 3))``. The static kernels read only ``k_i`` and
``k_j``, which is what lets the collisional models call them with their own row, and the
k(T)/ρc(T) override of the engine replaces exactly these four columns.

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
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed
from thermodem.models.thermal.batchelor_obrien_contact import (
    BATCHELOR_OBRIEN_COMPLETE,
    BATCHELOR_OBRIEN_MODIFIED,
    BATCHELOR_OBRIEN_SIMPLE,
    bob_complete_rate,
    bob_modified_rate,
    bob_simple_rate,
)
from thermodem.models.thermal.contact_radius import (
    effective_radius,
    hertz_collision_time,
    hertz_max_contact_radius,
)
from thermodem.models.thermal.direct_conduction_family import (
    FAMILY,
    HEAD,
    K_I,
    K_J,
    RHOC_I,
    RHOC_J,
    conductivities,
    head_values,
    heat_capacities,
    register_model,
)
from thermodem.models.thermal.resistance_network import (
    RESISTANCE_NETWORK,
    resistance_network_rate,
)
from thermodem.state.materials import PairContext

NONE = 0
# BATCHELOR_OBRIEN_SIMPLE, _COMPLETE, _MODIFIED = 1, 2, 3 are defined in
# batchelor_obrien_contact.py
THERMAL_PIPE = 4
QUINTANA_RUIZ_CAMPELLO2020 = 5
ROJEK2014 = 6
SUN_CHEN1988 = 7
ZHOU2008 = 8
# RESISTANCE_NETWORK = 9 is defined in resistance_network.py

#: Collisional models (Sun & Chen, Zhou).
COLLISIONAL_COLUMNS = (*HEAD, "e_star", "correction_factor", "static_model")
COL_E_STAR, COL_CORRECTION, COL_STATIC_MODEL = 4, 5, 6


# --------------------------------------------------------------------------------- none
class NoneParams(StrictModel):
    """No direct conduction."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed(HEAD, head_values([0.0, 0.0]))


@njit(cache=True, error_model="numpy")
def none_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    return 0.0


# ------------------------------------------------------------------------- thermal pipes
#: Rows of the two models with a 2D form: the head, then the disc thickness b [m] of a 2D
#: case of discs (0: the 3D form, also for spheres kept in a plane).
PIPE_COLUMNS = (*HEAD, "thickness")
PIPE_THICKNESS = 4


def pack_pipe(params: StrictModel, pair: PairContext, model: str) -> np.ndarray:
    """[k_i, k_j, 0, 0, b]: b = ``pair.thickness`` (0 in 3D and for spheres in a plane)."""
    values = head_values(conductivities(pair, model)) | {"thickness": pair.thickness}
    return packed(PIPE_COLUMNS, values)


class ThermalPipeParams(StrictModel):
    """Generic thermal pipe Q = k A_p / d_ij (T_j - T_i) (spec 2.4; Jebahi et al. 2015; Hahn
    et al. 2011), A_p = π R_c² (3D: a circular pipe of the contact radius). k: two equal half
    pipes in series, i.e. the harmonic mean 2 k_i k_j/(k_i + k_j). Wall: the particle's pipe
    from its centre to the wall plane, Q = k_i A_p / (R_i - δ) ΔT.

    2D discs of thickness b (``simulation.dimension: 2``): the pipe is a strip of the contact
    length 2 R_c across the thickness, A_p = 2 R_c b (as Rojek (2014)'s 2D bar, A_p = 2 r̃ b,
    with the contact half length R_c in place of r̃; R_c from the ``contact_radius`` model, the
    chord of the overlapping circles with ``geometric``). Row: [k_i, k_j, 0, 0, b].
    """


@njit(cache=True, inline="always", error_model="numpy")
def _pipe(k_i, k_j, t_i, t_j, r_i, r_j, overlap, r_c, thickness):
    """Thermal pipe rate; ``thickness`` > 0: the 2D strip A_p = 2 R_c b, else π R_c²."""
    if overlap <= 0.0 or r_c <= 0.0:
        return 0.0
    if thickness > 0.0:
        area = 2.0 * r_c * thickness
    else:
        area = math.pi * r_c * r_c
    if math.isinf(r_j):
        return k_i * area / (r_i - overlap) * (t_j - t_i)
    k_h = 2.0 * k_i * k_j / (k_i + k_j)
    return k_h * area / ((r_i + r_j) - overlap) * (t_j - t_i)


@njit(cache=True, error_model="numpy")
def thermal_pipe_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    return _pipe(p[K_I], p[K_J], t_i, t_j, r_i, r_j, overlap, r_c, p[PIPE_THICKNESS])


class QuintanaRuizCampello2020Params(StrictModel):
    """Quintana-Ruiz & Campello (2020) J. Braz. Soc. Mech. Sci. Eng. 42, 387 (spec 2.4):
    Q = k̃ π R_c² / d_ij ΔT, k̃ = (R_i + R_j)(R_i/k_i + R_j/k_j)^-1 (segments proportional to
    the radii). Wall: the wall segment is dropped and the particle's segment tends to R_i,
    Q = k_i π R_c² / R_i ΔT. Row: [k_i, k_j]. 3D only (the source's pipe is circular; refused
    for 2D discs)."""


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
    """Rojek (2014) Comput. Part. Mech. 1, 71-84 (spec 2.4): a bar between the centres,
    Q = k_p A_p / d_ij ΔT with A_p = 2 r̃ b and d_ij = 2 r̃, so Q = k_p b ΔT; r̃ = (R_i + R_j)/2;
    two half bars in series give k_p = the harmonic mean of k_i, k_j. Independent of the
    contact radius (only of touching).

    3D: b = r̃ (Q = k_p r̃ ΔT); wall: the particle's half bar (r̃ = R_i), Q = 2 k_i R_i ΔT.
    2D discs: b is the thickness of the discs (``simulation.thickness``; "b is assumed as
    unity" in the paper, the default 1 m), Q = k_p b ΔT; wall: the half bar of length R_i and
    section 2 R_i b, Q = 2 k_i b ΔT. Row: [k_i, k_j, 0, 0, b] (b = 0: the 3D form).
    """


@njit(cache=True, inline="always", error_model="numpy")
def _rojek(k_i, k_j, t_i, t_j, r_i, r_j, overlap, thickness):
    """Rojek's bar; ``thickness`` > 0: the 2D bar of that thickness, else the 3D one."""
    if overlap <= 0.0:
        return 0.0
    if math.isinf(r_j):
        b = thickness if thickness > 0.0 else r_i
        return 2.0 * k_i * b * (t_j - t_i)
    k_h = 2.0 * k_i * k_j / (k_i + k_j)
    b = thickness if thickness > 0.0 else 0.5 * (r_i + r_j)
    return k_h * b * (t_j - t_i)


@njit(cache=True, error_model="numpy")
def rojek2014_rate(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):
    return _rojek(p[K_I], p[K_J], t_i, t_j, r_i, r_j, overlap, p[PIPE_THICKNESS])


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
    """The static model a collisional model switches to after t_c (reads row columns 0-1;
    the 3D forms)."""
    args = (t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff)
    if static_id == BATCHELOR_OBRIEN_SIMPLE:
        return bob_simple_rate(p, *args)
    elif static_id == THERMAL_PIPE:  # (the 3D forms: the collisional models are 3D only)
        return _pipe(p[K_I], p[K_J], t_i, t_j, r_i, r_j, overlap, r_c, 0.0)
    elif static_id == QUINTANA_RUIZ_CAMPELLO2020:
        return qrc2020_rate(p, *args)
    elif static_id == ROJEK2014:
        return _rojek(p[K_I], p[K_J], t_i, t_j, r_i, r_j, overlap, 0.0)
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
    values = head_values(conductivities(pair, model), heat_capacities(pair, model))
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
def _separated_form(rate):  # noqa: ANN001, ANN202
    """The separated-pair form H(p, r_i, r_j, dist) of a model's heat-rate kernel ``rate``
    (ΔT = 1 K): 0 when the pair touches (see :func:`separated_conductance`)."""

    @njit(inline="always", error_model="numpy")
    def form(p, r_i, r_j, dist):  # noqa: ANN001, ANN202
        overlap = (r_i - dist) if math.isinf(r_j) else (r_i + r_j) - dist
        if overlap >= 0.0:
            return 0.0
        return rate(p, 0.0, 1.0, r_i, r_j, dist, overlap, 0.0, 0.0, 0.0, 0.0, 0.0)

    return form


bob_complete_separated = _separated_form(bob_complete_rate)
bob_modified_separated = _separated_form(bob_modified_rate)

#: The separated-pair form H(p, r_i, r_j, dist) of each model that has one (a pass compiled
#: for one model calls its form alone: kernels/range_pass.py).
SEPARATED_FORMS = {
    BATCHELOR_OBRIEN_COMPLETE: bob_complete_separated,
    BATCHELOR_OBRIEN_MODIFIED: bob_modified_separated,
}


@njit(cache=True, inline="always", error_model="numpy")
def separated_conductance(model_id, p, r_i, r_j, dist):
    """Conductance H [W/K] of the *separated-pair* part of a direct model that conducts across
    a gap (those registered with an ``interaction_range``: Batchelor & O'Brien complete and
    modified), 0 for touching pairs and other models.

    The engine evaluates it on the range pair set (pairs within the model's largest gap), and
    the contact pass evaluates the same kernels on touching pairs only, so no pair is counted
    twice. A wall is ``r_j = inf`` with ``dist`` the centre-to-wall distance.
    """
    if model_id == BATCHELOR_OBRIEN_COMPLETE:
        return bob_complete_separated(p, r_i, r_j, dist)
    elif model_id == BATCHELOR_OBRIEN_MODIFIED:
        return bob_modified_separated(p, r_i, r_j, dist)
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
#: 2D (``planar``): rojek2014 and thermal_pipe have a 2D form for discs (a bar / strip of the
#: disc thickness); the other models are the conduction between spheres (their 3D form holds
#: for spheres kept in a plane, refused for discs: register_model's default); none needs no
#: form.
_BOTH = ("disc", "sphere")
_COLL = ("thermal_conductivity", "density", "specific_heat", "youngs_modulus", "poisson_ratio")


register_model(
    "none", NONE, none_rate, NoneParams, "no direct conduction", "-", pack_none, requires=(),
    planar=_BOTH,
)  # fmt: skip
register_model(
    "thermal_pipe", THERMAL_PIPE, thermal_pipe_rate, ThermalPipeParams,
    "thermal pipe Q = k_h A_p / d ΔT between the centres, A_p = π R_c² (2D: 2 R_c b)",
    "Jebahi et al. (2015) DEM for 3D continuous materials, Wiley; Hahn et al. (2011)",
    lambda params, pair: pack_pipe(params, pair, f"{FAMILY}.thermal_pipe"),
    columns=PIPE_COLUMNS, planar=_BOTH,
)  # fmt: skip
register_model(
    "quintana_ruiz_campello2020", QUINTANA_RUIZ_CAMPELLO2020, qrc2020_rate,
    QuintanaRuizCampello2020Params,
    "thermal pipe with k̃ = (R_i + R_j)/(R_i/k_i + R_j/k_j), A = π R_c²",
    "Quintana-Ruiz & Campello (2020) J. Braz. Soc. Mech. Sci. Eng. 42, 387",
)  # fmt: skip
register_model(
    "rojek2014", ROJEK2014, rojek2014_rate, Rojek2014Params,
    "bar Q = k_h b ΔT: 3D b = r̃ = (R_i + R_j)/2, 2D b = the disc thickness",
    "Rojek (2014) Comput. Part. Mech. 1, 71-84",
    lambda params, pair: pack_pipe(params, pair, f"{FAMILY}.rojek2014"),
    columns=PIPE_COLUMNS, planar=_BOTH,
)  # fmt: skip
register_model(
    "sun_chen1988", SUN_CHEN1988, sun_chen1988_rate, SunChen1988Params,
    "collisional conduction U/t_c of a Hertz impact, then a static model after t_c",
    "Sun & Chen (1988) Int. J. Heat Mass Transf. 31, 969-975; Zhou, Yu & Zulli (2009)",
    pack_sun_chen1988, requires=_COLL, columns=COLLISIONAL_COLUMNS,
)  # fmt: skip
register_model(
    "zhou2008", ZHOU2008, zhou2008_rate, Zhou2008Params,
    "collisional conduction with Zhou's explicit C(Fo), then a static model after t_c",
    "Zhou, Yu & Horio (2008) Chem. Eng. J. 139, 510-516; Zhou, Yu & Zulli (2009)",
    pack_zhou2008, requires=_COLL, columns=COLLISIONAL_COLUMNS,
)  # fmt: skip
