"""Normal contact laws (family ``normal``), with damping from the coefficient of restitution.

Kernel signature (all float64)::

    kernel(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap)
        -> (force_elastic, force_damping, ref_stiffness, damping_coeff, elastic_energy,
            max_overlap, plastic_energy)

``overlap`` δ > 0 in contact; ``overlap_rate`` dδ/dt > 0 while approaching. Forces are
positive when repulsive; the damping force is ``damping_coeff * overlap_rate`` so the power it
dissipates is ``damping_coeff * overlap_rate**2 >= 0``. ``ref_stiffness`` is the stiffness the
damping coefficient is scaled with (the tangential laws reuse the same damping ratio).
The normal force is not clipped at zero: a damped contact may pull briefly before it opens,
which is what makes the restitution coefficient exact (see the docs page).

``max_overlap`` is the law's history value (the largest overlap of the contact so far, 0 at the
first touch) for a law that registers ``history_width=1`` (the elasto-plastic law; the others
return it unchanged and the contact keeps no column for them); the kernel returns its new value
and the energy dissipated plastically in this step [J] (0 for elastic laws), so that the
elastic energy plus the plastic dissipation account for the work of the elastic-plastic force
along the overlap.

The damping family of the architecture is folded into this one: the map from the coefficient of
restitution to a damping coefficient depends on the elastic law, so each law owns it.
"""

from __future__ import annotations

import json
import math
import os
from functools import lru_cache

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.state.materials import PairContext

HERTZ = 1
LINEAR = 2
HERTZ_2D = 3

#: Parameter row columns (named; ``register(columns=...)`` sets the row width).
HERTZ_COLUMNS = ("effective_youngs_modulus", "damping_factor")
HERTZ_E_STAR, HERTZ_ALPHA = 0, 1
LINEAR_COLUMNS = ("stiffness", "damping_ratio")
LINEAR_STIFFNESS, LINEAR_DAMPING_RATIO = 0, 1
HERTZ_2D_COLUMNS = ("effective_youngs_modulus", "thickness", "damping_ratio")
HERTZ_2D_E_STAR, HERTZ_2D_THICKNESS, HERTZ_2D_DAMPING_RATIO = 0, 1, 2
WALTON_BRAUN = 4
WALTON_BRAUN_COLUMNS = ("loading_stiffness", "restitution_squared")
WB_LOADING_STIFFNESS, WB_RESTITUTION_SQUARED = 0, 1


# ----------------------------------------------------------------------------------- Hertz
class HertzParams(StrictModel):
    """Hertz (1882) elastic normal force with the viscous damping of Tsuji, Tanaka & Ishida (1992).

    F = (4/3) E* sqrt(R*) δ^{3/2} + α sqrt(m* (4/3) E* sqrt(R*)) δ^{1/4} dδ/dt

    Tsuji, Y., Tanaka, T., Ishida, T. (1992) Lagrangian numerical simulation of plug flow of
    cohesionless particles in a horizontal pipe, Powder Technol. 71, 239-250. With damping
    proportional to δ^{1/4} the restitution coefficient does not depend on the impact velocity
    (Antypov & Elliott 2011, EPL 94, 50004); α is found here for the requested restitution by
    integrating the dimensionless contact equation x'' + α x^{1/4} x' + x^{3/2} = 0 and solving
    e(α) = e_target (so e is reproduced exactly, not through a fitted approximation).
    No parameters: E*, R*, m* and e come from the materials and the pair.
    """


@lru_cache(maxsize=256)
def hertz_restitution_of_alpha(alpha: float) -> float:
    """Restitution of the dimensionless Hertz–Tsuji contact for damping factor α."""
    from scipy.integrate import solve_ivp  # (imported when needed: ~0.3 s)

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x = max(y[0], 0.0)
        return [y[1], -alpha * x**0.25 * y[1] - x**1.5]

    def opened(_t: float, y: np.ndarray) -> float:
        return y[0]

    opened.terminal = True  # type: ignore[attr-defined]
    opened.direction = -1  # type: ignore[attr-defined]
    sol = solve_ivp(
        rhs, (0.0, 60.0), [0.0, 1.0], events=opened, rtol=1e-11, atol=1e-14, max_step=0.01
    )
    if sol.t_events[0].size == 0:
        return 0.0
    return float(-sol.y_events[0][0][1])


#: α(e) found by earlier processes, in ``hertz_alpha.json`` of the cache root: the root
#: finding integrates the contact equation ~14 times in Python (~1 s at every run start); the
#: stored value is the one this function computes, to the last bit (JSON keeps doubles).
_ALPHA_FILE = "hertz_alpha.json"


@lru_cache(maxsize=256)
def hertz_alpha_of_restitution(restitution: float) -> float:
    """Damping factor α of the Hertz–Tsuji law that gives the coefficient of restitution e."""
    from thermodem._numba_cache import cache_root

    path = cache_root() / _ALPHA_FILE
    key = repr(float(restitution))
    try:
        known = json.loads(path.read_text())
    except (OSError, ValueError):
        known = {}
    value = known.get(key)
    if isinstance(value, float):
        return value
    alpha = _alpha_of_restitution(restitution)
    known[key] = alpha
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(known))
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache: computed again next time
    return alpha


def _alpha_of_restitution(restitution: float) -> float:
    from scipy.optimize import brentq

    if restitution >= 1.0:
        return 0.0
    if restitution <= 0.0:
        restitution = 0.0
        # smallest α with no rebound: bisect on e(α) > 0
        lo, hi = 1.0, 4.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if hertz_restitution_of_alpha(mid) > 0.0:
                lo = mid
            else:
                hi = mid
        return hi
    return float(
        brentq(
            lambda a: hertz_restitution_of_alpha(a) - restitution, 0.0, 4.0, xtol=1e-13, rtol=1e-13
        )
    )


def pack_hertz(params: HertzParams, pair: PairContext) -> np.ndarray:
    return packed(
        HERTZ_COLUMNS,
        {
            "effective_youngs_modulus": pair.effective_youngs_modulus,
            "damping_factor": hertz_alpha_of_restitution(pair.restitution),
        },
    )


@njit(cache=True, error_model="numpy")
def hertz_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap):
    e_star = p[HERTZ_E_STAR]
    alpha = p[HERTZ_ALPHA]
    k_hz = 4.0 / 3.0 * e_star * math.sqrt(eff_radius)
    root = math.sqrt(overlap)
    secant = k_hz * root  # F_el / δ
    f_el = secant * overlap
    gamma = alpha * math.sqrt(eff_mass * secant)
    energy = 0.4 * f_el * overlap  # ∫ k δ^{3/2} dδ = (2/5) k δ^{5/2}
    return f_el, gamma * overlap_rate, secant, gamma, energy, max_overlap, 0.0


# ---------------------------------------------------------------------------------- linear
class LinearParams(StrictModel):
    """Linear spring–dashpot: F = k δ + γ dδ/dt (Cundall & Strack 1979).

    γ = 2 ζ sqrt(m* k) with ζ = -ln e / sqrt(π² + ln² e): the exact relation of the damped
    linear oscillator, so the restitution coefficient equals the input for every impact
    velocity (contact ends when δ returns to zero). e = 0 gives critical damping (ζ = 1).
    """

    stiffness: float = Field(gt=0, description="normal spring stiffness k [N/m]")


def linear_damping_ratio(restitution: float) -> float:
    """ζ(e) of the linear spring–dashpot (exact)."""
    if restitution <= 0.0:
        return 1.0
    if restitution >= 1.0:
        return 0.0
    log_e = math.log(restitution)
    return -log_e / math.sqrt(math.pi**2 + log_e**2)


def pack_linear(params: LinearParams, pair: PairContext) -> np.ndarray:
    return packed(
        LINEAR_COLUMNS,
        {"stiffness": params.stiffness, "damping_ratio": linear_damping_ratio(pair.restitution)},
    )


@njit(cache=True, error_model="numpy")
def linear_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap):
    k = p[LINEAR_STIFFNESS]
    gamma = 2.0 * p[LINEAR_DAMPING_RATIO] * math.sqrt(eff_mass * k)
    u = 0.5 * k * overlap * overlap
    return k * overlap, gamma * overlap_rate, k, gamma, u, max_overlap, 0.0


# ---------------------------------------------------------------------------- Walton–Braun
class WaltonBraunParams(StrictModel):
    """Elasto-plastic (hysteretic) linear law of Walton & Braun (1986).

    Loading (the overlap beyond its largest value so far, δ ≥ δ_max): F = k1 δ.
    Unloading and reloading below δ_max: F = k2 (δ - δ0), δ0 = δ_max (1 - k1/k2), and F = 0
    for δ ≤ δ0 (the permanent deformation). k2 = k1 / e², so the coefficient of restitution is
    e = sqrt(k1/k2) for every impact velocity. No viscous damping: the energy a collision loses
    is the plastic work ½ k1 (1 - k1/k2) δ_max², dissipated while the contact loads.

    Walton, O.R., Braun, R.L. (1986) Viscosity, granular-temperature, and stress calculations
    for shearing assemblies of inelastic, frictional disks, J. Rheol. 30, 949-980. The tangential
    and rolling laws scale with the loading stiffness k1 (``ref_stiffness``).
    """

    loading_stiffness: float = Field(gt=0, description="k1, loading stiffness [N/m]")


def pack_walton_braun(params: WaltonBraunParams, pair: PairContext) -> np.ndarray:
    if not pair.restitution > 0.0:
        raise ValueError(
            f"walton_braun needs a restitution > 0 (k2 = k1 / e²); the pair's restitution is "
            f"{pair.restitution}"
        )
    return packed(
        WALTON_BRAUN_COLUMNS,
        {
            "loading_stiffness": params.loading_stiffness,
            "restitution_squared": pair.restitution * pair.restitution,
        },
    )


@njit(cache=True, error_model="numpy")
def walton_braun_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap):
    """One evaluation of the Walton–Braun law. The stored elastic energy is that of the
    unloading spring, ½ k2 (δ - δ0)² (at δ = δ_max: ½ k1 e² δ_max²); a step that raises δ_max
    from a to b dissipates the loading work minus the stored energy gained,
    ½ k1 (1 - e²) (b² - a²)."""
    k1 = p[WB_LOADING_STIFFNESS]
    r = p[WB_RESTITUTION_SQUARED]  # k1 / k2
    if overlap >= max_overlap:  # loading: a new largest overlap
        plastic = 0.5 * k1 * (1.0 - r) * (overlap * overlap - max_overlap * max_overlap)
        return k1 * overlap, 0.0, k1, 0.0, 0.5 * k1 * r * overlap * overlap, overlap, plastic
    x = overlap - max_overlap * (1.0 - r)  # δ - δ0
    if x <= 0.0:
        return 0.0, 0.0, k1, 0.0, 0.0, max_overlap, 0.0
    k2 = k1 / r
    return k2 * x, 0.0, k1, 0.0, 0.5 * k2 * x * x, max_overlap, 0.0


# ------------------------------------------------------------------- 2D Hertz (line contact)
class Hertz2DParams(StrictModel):
    """Line contact of two discs (2D), F = (π/4) E* b δ + γ dδ/dt, b the disc thickness.

    A disc of a 2D case is a cylinder of length b (``simulation.thickness``) and two discs
    touch along a line: Hertz's theory of two parallel cylinders (Johnson, K.L. (1985) Contact
    Mechanics, CUP, ch. 4-5) gives the contact half width a = sqrt(4 F R*/(π b E*)), but the
    approach of the centres is only defined up to the size of the bodies (the displacement
    of a half-plane under a line load grows logarithmically with distance), so there is no
    closed-form δ(F). The law chosen here is the stiffness F = (π/4) E* b δ of two parallel
    cylinders used as the 2D Hertz law of Kratos DEM (Celigueta & Latorre, CIMNE,
    ``DEM_D_Hertz_viscous_Coulomb2D``: K_n = π/4 E* per unit thickness): linear in δ and
    independent of the radii. E* = [(1-ν_i²)/E_i + (1-ν_j²)/E_j]^-1 as for spheres; a wall is
    the same body of infinite radius.

    Damping: a linear law, so γ = 2 ζ sqrt(m* k) with ζ = -ln e / sqrt(π² + ln² e) gives the
    restitution coefficient e exactly for every impact velocity, and the contact time is
    π / (ω_0 sqrt(1 - ζ²)), ω_0 = sqrt(k/m*) (docs/models/normal-hertz_2d.md; tested).
    No parameters: E*, e, m* from the materials and the pair, b from the case.
    """


def pack_hertz_2d(params: Hertz2DParams, pair: PairContext) -> np.ndarray:
    """[E*, b, ζ(e)]; b = ``pair.thickness`` (1 m, per unit thickness, when a pair is packed
    outside a 2D case of discs, e.g. by the conformance tests)."""
    thickness = pair.thickness if pair.thickness > 0.0 else 1.0
    zeta = linear_damping_ratio(pair.restitution)
    values = {"effective_youngs_modulus": pair.effective_youngs_modulus, "thickness": thickness,
              "damping_ratio": zeta}  # fmt: skip
    return packed(HERTZ_2D_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def hertz_2d_force(p, overlap, overlap_rate, eff_radius, eff_mass, max_overlap):
    k = 0.25 * math.pi * p[HERTZ_2D_E_STAR] * p[HERTZ_2D_THICKNESS]
    gamma = 2.0 * p[HERTZ_2D_DAMPING_RATIO] * math.sqrt(eff_mass * k)
    u = 0.5 * k * overlap * overlap
    return k * overlap, gamma * overlap_rate, k, gamma, u, max_overlap, 0.0


register(
    family="normal",
    name="hertz",
    model_id=HERTZ,
    kernel=hertz_force,
    params=HertzParams,
    pack=pack_hertz,
    columns=HERTZ_COLUMNS,
    summary="Hertz elastic force with Tsuji (1992) δ^1/4 damping calibrated to the restitution",
    reference="Hertz (1882); Tsuji, Tanaka & Ishida (1992) Powder Technol. 71, 239-250",
    requires=("youngs_modulus", "poisson_ratio", "restitution"),
    planar=("sphere",),
)
register(
    family="normal",
    name="linear",
    model_id=LINEAR,
    kernel=linear_force,
    params=LinearParams,
    pack=pack_linear,
    columns=LINEAR_COLUMNS,
    summary="linear spring-dashpot with the exact restitution-damping relation",
    reference="Cundall & Strack (1979) Geotechnique 29, 47-65",
    requires=("restitution",),
    planar=("disc", "sphere"),
)
register(
    family="normal",
    name="hertz_2d",
    model_id=HERTZ_2D,
    kernel=hertz_2d_force,
    params=Hertz2DParams,
    pack=pack_hertz_2d,
    columns=HERTZ_2D_COLUMNS,
    summary="2D line contact of discs F = (π/4) E* b δ, damping exact for the restitution",
    reference="Johnson (1985) Contact Mechanics ch. 4-5 (parallel cylinders); Kratos DEM 2D "
    "Hertz law (Celigueta & Latorre, CIMNE)",
    requires=("youngs_modulus", "poisson_ratio", "restitution"),
    planar=("disc",),
    only_2d=True,
)
register(
    family="normal",
    name="walton_braun",
    model_id=WALTON_BRAUN,
    kernel=walton_braun_force,
    params=WaltonBraunParams,
    pack=pack_walton_braun,
    columns=WALTON_BRAUN_COLUMNS,
    summary="elasto-plastic hysteretic spring: k1 loading, k2 = k1/e² unloading, plastic "
    "dissipation",
    reference="Walton & Braun (1986) J. Rheol. 30, 949-980",
    requires=("restitution",),
    history_width=1,
    history_flip=(False,),
)


# ------------------------------------------------------------------- closed forms (tests, docs)
def linear_collision_time(eff_mass: float, stiffness: float, restitution: float) -> float:
    """Contact time of the linear spring-dashpot (and of hertz_2d, k = π/4 E* b):
    π / (ω_0 sqrt(1 - ζ²)), ω_0 = sqrt(k/m*), ζ = ζ(e); infinite for e = 0 (critical)."""
    zeta = linear_damping_ratio(restitution)
    if zeta >= 1.0:
        return math.inf
    return math.pi / (math.sqrt(stiffness / eff_mass) * math.sqrt(1.0 - zeta * zeta))


def hertz_2d_stiffness(e_star: float, thickness: float) -> float:
    """k = (π/4) E* b of the 2D line contact [N/m]."""
    return 0.25 * math.pi * e_star * thickness


def hertz_collision_time(eff_mass: float, eff_radius: float, e_star: float, speed: float) -> float:
    """Total elastic Hertz collision time, t_c = 2.87 (m*²/(R* E*² v))^{1/5} (spec, appendix A)."""
    return 2.87 * (eff_mass**2 / (eff_radius * e_star**2 * speed)) ** 0.2


def hertz_max_overlap(eff_mass: float, eff_radius: float, e_star: float, speed: float) -> float:
    """δ_max = (15/16 m* v² / (sqrt(R*) E*))^{2/5} (spec, appendix A)."""
    return (15.0 / 16.0 * eff_mass * speed**2 / (math.sqrt(eff_radius) * e_star)) ** 0.4
