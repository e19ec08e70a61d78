"""Heat generation by mechanical dissipation (family ``heat_generation``), spec section 5.

A fraction χ (the conversion coefficient, 0 ≤ χ ≤ 1) of the mechanical energy a contact
dissipates becomes heat, Q_g = χ P, and is shared between the two bodies by a partition
coefficient ψ: body i receives ψ_i Q_g, body j (1 - ψ_i) Q_g (spec: "Partition coefficient").
The mechanisms (``thermodem.state.heat.GENERATION``) are the dissipations the contact laws
report: sliding friction (the Coulomb work of the capped tangential force along the slip,
Q_g = χ |μ F_n δ̇_t| in sustained sliding), rolling friction (χ |τ ω_r|), the normal and
tangential dashpots (χ (F_n^vis δ̇_n + F_t^vis δ̇_t)), plastic deformation of an elasto-plastic
normal law (χ F_n^pl δ̇_n; the tangential laws have no plastic part besides the Coulomb slip),
and the kinetic energy a pair loses in a collision (Al-Arkawazi 2017, ΔU / t_c).

The contact pass adds, at every mechanical step, each contact's dissipated energy per
mechanism into its two particles' accumulators (ψ and 1 - ψ; the share of a wall with a fixed
temperature goes to the wall ledger, an adiabatic wall takes nothing), and the thermal step
turns the accumulated energy into heat rates χ E / Δt_th and clears it: no joule is lost or
counted twice, whatever the sub-cycling (``kernels/generation.py``,
``docs/models/heat_generation-*.md``).

Every model packs the same row (:data:`COLUMNS`): χ, a 0/1 selection per mechanism and the two
partition coefficients of body i (friction mechanisms, and the others). The kernel
:func:`partition_share` returns body i's share for one mechanism; the partition formulas are
:func:`partition_coefficient`.

The partition formulas (spec: "Partition coefficient"), ψ_i the share of body i:

* ``equal``: ψ_i = 1/2;
* ``conductivity``, Váradi, Néder & Friedrich (1996): ψ_i = k_i / (k_i + k_j);
* ``effusivity``, Vernotte (1956), Rojek (2014): ψ_i = e_i / (e_i + e_j), e = sqrt(ρ c k);
* ``mokrani_bourouga2005``, Mokrani & Bourouga (2005):
  ψ_i = ½ (k_i / (k_i + k_j) + ρ̂_i / (ρ̂_i + ρ̂_j)), ρ̂ the electrical resistivity.

Two bodies of the same material get 1/2 from every formula.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, field_validator

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.state.heat import FRICTION, GENERATION
from thermodem.state.materials import Material, PairContext

NONE = 0
MECHANICAL_DISSIPATION = 1
AL_ARKAWAZI2017 = 2
ROJEK2014 = 3
RICHARD2008 = 4

#: Partition formulas, by name and id (the ids are the first argument of
#: :func:`partition_coefficient`).
PARTITIONS: tuple[str, ...] = ("equal", "conductivity", "effusivity", "mokrani_bourouga2005")
EQUAL, CONDUCTIVITY, EFFUSIVITY, MOKRANI_BOUROUGA = range(len(PARTITIONS))

#: Columns of the packed row.
COLUMNS: tuple[str, ...] = (
    "conversion_fraction",
    *(f"select_{g}" for g in GENERATION),
    "psi_friction",
    "psi_other",
)
C_CHI = 0
C_SELECT = 1  # + mechanism index
C_PSI_FRICTION = C_SELECT + len(GENERATION)
C_PSI_OTHER = C_PSI_FRICTION + 1

#: The mechanisms the force-based model may select (the collision kinetic energy is the
#: al_arkawazi2017 model's: it contains the force-based dissipations of a collision, so
#: selecting both would count those joules twice).
FORCE_MECHANISMS: tuple[str, ...] = GENERATION[:-1]
Mechanism = Literal[
    "sliding_friction",
    "rolling_friction",
    "normal_damping",
    "tangential_damping",
    "plastic_deformation",
]
PartitionName = Literal["equal", "conductivity", "effusivity", "mokrani_bourouga2005"]


@njit(cache=True, error_model="numpy")
def partition_coefficient(kind, k_i, k_j, e_i, e_j, rho_i, rho_j):
    """ψ_i, the share of body i of the heat generated at its contact with body j, by the
    formula ``kind`` (:data:`PARTITIONS`); k thermal conductivities, e thermal effusivities
    sqrt(ρ c k), ρ̂ electrical resistivities (only the ones the formula reads matter)."""
    if kind == CONDUCTIVITY:
        return k_i / (k_i + k_j)
    if kind == EFFUSIVITY:
        return e_i / (e_i + e_j)
    if kind == MOKRANI_BOUROUGA:
        return 0.5 * (k_i / (k_i + k_j) + rho_i / (rho_i + rho_j))
    return 0.5


@njit(cache=True, error_model="numpy")
def partition_share(p, mechanism):
    """Share of body i of the heat of ``mechanism`` (index in GENERATION) at a contact with
    row ``p``: 0 for a mechanism the model does not select."""
    if p[C_SELECT + mechanism] == 0.0:
        return 0.0
    if mechanism == 0 or mechanism == 1:  # FRICTION: sliding, rolling
        return p[C_PSI_FRICTION]
    return p[C_PSI_OTHER]


assert FRICTION == (0, 1)


def _property(material: Material, name: str, partition: str) -> float:
    value = getattr(material, name)
    if value is None:
        raise ValueError(
            f"the {partition} partition coefficient needs the material's {name} (missing)"
        )
    return float(value)


def pair_partition(partition: str, pair: PairContext) -> float:
    """ψ_i of the pair's body i (``mat_i``) for the named formula."""
    kind = PARTITIONS.index(partition)
    if kind == EQUAL:
        return 0.5
    mi, mj = pair.mat_i, pair.mat_j
    k_i = _property(mi, "thermal_conductivity", partition)
    k_j = _property(mj, "thermal_conductivity", partition)
    e_i = e_j = rho_i = rho_j = 0.0
    if kind == EFFUSIVITY:
        e_i = math.sqrt(mi.density * _property(mi, "specific_heat", partition) * k_i)
        e_j = math.sqrt(mj.density * _property(mj, "specific_heat", partition) * k_j)
    if kind == MOKRANI_BOUROUGA:
        rho_i = _property(mi, "electrical_resistivity", partition)
        rho_j = _property(mj, "electrical_resistivity", partition)
    return float(partition_coefficient(kind, k_i, k_j, e_i, e_j, rho_i, rho_j))


def _row(
    chi: float, mechanisms: tuple[str, ...], psi_friction: float, psi_other: float
) -> np.ndarray:
    values = {"conversion_fraction": chi, "psi_friction": psi_friction, "psi_other": psi_other}
    values.update({f"select_{g}": float(g in mechanisms) for g in GENERATION})
    return packed(COLUMNS, values)


def _requires(partition: str) -> tuple[str, ...]:
    return {
        "equal": (),
        "conductivity": ("thermal_conductivity",),
        "effusivity": ("thermal_conductivity", "density", "specific_heat"),
        "mokrani_bourouga2005": ("thermal_conductivity", "electrical_resistivity"),
    }[partition]


# ------------------------------------------------------------------------------------ none
class NoneParams(StrictModel):
    """No heat generation: the mechanical dissipation is ledgered but not turned into heat."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return _row(0.0, (), 0.5, 0.5)


# ------------------------------------------------------------------ mechanical_dissipation
class MechanicalDissipationParams(StrictModel):
    """Heat from the dissipative forces and torques of the contact laws (spec 5: sliding and
    rolling friction, normal and tangential damping, plastic deformation): Q_g = χ P per
    mechanism, shared by a partition coefficient.

    The set-ups of the spec's sources: Hu, Zhu & Hua (2021) and Sun, Zhu & Hua (2018): sliding
    and rolling friction and the normal and tangential damping, the partition coefficient on
    the friction heat only (``partition_scope: friction``); Sun et al. (2022): sliding and
    rolling friction and plastic deformation, χ = 0.9 (Hodowany et al. 2000); Nguyen et al.
    (2009): sliding friction only. Archard (1959): nearly all the energy dissipated by
    friction appears as heat, hence the default χ = 1.
    """

    mechanisms: list[Mechanism] = Field(
        default_factory=lambda: list(FORCE_MECHANISMS),
        description="dissipation mechanisms turned into heat",
    )
    conversion_fraction: float = Field(
        default=1.0, ge=0.0, le=1.0, description="χ, fraction of the dissipation that is heat [-]"
    )
    partition: PartitionName = Field(
        default="equal", description="partition coefficient ψ between the two bodies"
    )
    partition_scope: Literal["all", "friction"] = Field(
        default="all",
        description="mechanisms the partition coefficient applies to; 'friction': sliding and "
        "rolling friction only, the other heat split equally",
    )

    @field_validator("mechanisms")
    @classmethod
    def _mechanisms(cls, v: list[str]) -> list[str]:
        if not v:
            raise ValueError(
                f"give at least one mechanism ({', '.join(FORCE_MECHANISMS)}), or use "
                "heat_generation: none"
            )
        if len(set(v)) != len(v):
            raise ValueError(f"a mechanism is listed twice: {v}")
        return v


def pack_mechanical_dissipation(
    params: MechanicalDissipationParams, pair: PairContext
) -> np.ndarray:
    psi = pair_partition(params.partition, pair)
    other = psi if params.partition_scope == "all" else 0.5
    return _row(params.conversion_fraction, tuple(params.mechanisms), psi, other)


# -------------------------------------------------------------------------- al_arkawazi2017
class AlArkawazi2017Params(StrictModel):
    """Heat from the kinetic energy a pair loses in a collision, Al-Arkawazi (2017/2018).

    ΔU = ΔU_i + ΔU_j, ΔU_i = ½ (m_i (v_i'² - v_i²) + I_i (ω_i'² - ω_i²)) between the start of
    the contact and its end (t_c later), Q_g = ΔU / t_c over the collision. Al-Arkawazi, S.
    (2018) Modeling the heat transfer between fluid-granular medium, Appl. Therm. Eng. 128,
    696-705. The source adds friction heat; the kinetic energy lost in a collision already
    contains the friction work of that collision, so it is counted once here.
    """

    conversion_fraction: float = Field(
        default=1.0, ge=0.0, le=1.0, description="χ, fraction of the energy that is heat [-]"
    )
    partition: PartitionName = Field(
        default="equal", description="partition coefficient ψ between the two bodies"
    )


def pack_al_arkawazi(params: AlArkawazi2017Params, pair: PairContext) -> np.ndarray:
    psi = pair_partition(params.partition, pair)
    return _row(params.conversion_fraction, ("collision",), psi, psi)


# ------------------------------------------------------------------------------- rojek2014
class Rojek2014Params(StrictModel):
    """Sliding friction heat only, χ = 0.85, shared by the thermal effusivities (Rojek 2014).

    Rojek, J. (2014) Discrete element thermomechanical modelling of rock cutting with
    valuation of tool wear, Comput. Part. Mech. 1, 71-84; the partition of Vernotte (1956)
    that the spec attributes to Rojek (2014), ψ_i = e_i / (e_i + e_j), e = sqrt(ρ c k).
    """

    conversion_fraction: float = Field(
        default=0.85, ge=0.0, le=1.0, description="χ [-] (0.85 in the source)"
    )
    partition: PartitionName = Field(
        default="effusivity", description="partition coefficient ψ between the two bodies"
    )


def pack_rojek(params: Rojek2014Params, pair: PairContext) -> np.ndarray:
    psi = pair_partition(params.partition, pair)
    return _row(params.conversion_fraction, ("sliding_friction",), psi, psi)


# ----------------------------------------------------------------------------- richard2008
class Richard2008Params(StrictModel):
    """Heat from the viscous component of the normal force only, all of it, split equally:
    Q_g = F_n^vis δ̇_n = 2 μ sqrt(K_n m̄) δ̇_n², Q_g,i = Q_g,j = Q_g / 2.

    Richard, D., Iordanoff, I., Renouf, M., Berthier, Y. (2008) Thermal study of the dry
    sliding contact with third body presence, J. Tribol. 130, 031404; Terreros et al. (2009)
    Int. J. Mater. Form. 2, 573-576; the formula is on the spec's Rojek (2014) slide. μ is the
    damping ratio and K_n the normal stiffness: the normal dashpot of the linear law exactly
    (μ = ζ), of Hertz–Tsuji with K_n its secant stiffness and μ = α/2.
    """


def pack_richard(params: Richard2008Params, pair: PairContext) -> np.ndarray:
    return _row(1.0, ("normal_damping",), 0.5, 0.5)


# -------------------------------------------------------------------------------- register
def required_properties(params: StrictModel) -> tuple[str, ...]:
    """Material properties the partition of these parameters reads (all bodies that meet)."""
    return _requires(getattr(params, "partition", "equal"))


#: 2D (``planar``): every model converts the energy the contact laws report as dissipated,
#: whatever the law (``hertz_2d`` for discs included); ψ reads material properties only. So
#: the models hold for discs and for spheres in a plane as written.
_COMMON = dict(
    family="heat_generation",
    kernel=partition_share,
    columns=COLUMNS,
    requires_of=required_properties,
    planar=("disc", "sphere"),
)
register(
    name="none",
    model_id=NONE,
    params=NoneParams,
    pack=pack_none,
    summary="no heat generation (the dissipation stays in the mechanical ledger)",
    reference="-",
    **_COMMON,
)
register(
    name="mechanical_dissipation",
    model_id=MECHANICAL_DISSIPATION,
    params=MechanicalDissipationParams,
    pack=pack_mechanical_dissipation,
    summary="χ × the dissipation of the contact laws (sliding/rolling friction, damping, "
    "plasticity), shared by a partition coefficient",
    reference="spec 5; Hu et al. (2021); Sun et al. (2018, 2022); Váradi et al. (1996); "
    "Vernotte (1956); Mokrani & Bourouga (2005)",
    **_COMMON,
)
register(
    name="al_arkawazi2017",
    model_id=AL_ARKAWAZI2017,
    params=AlArkawazi2017Params,
    pack=pack_al_arkawazi,
    summary="χ × the kinetic energy a pair loses in a collision (ΔU / t_c)",
    reference="Al-Arkawazi (2018) Appl. Therm. Eng. 128, 696-705",
    history_width=1,
    history_flip=(False,),
    **_COMMON,
)
register(
    name="rojek2014",
    model_id=ROJEK2014,
    params=Rojek2014Params,
    pack=pack_rojek,
    summary="sliding friction heat, χ = 0.85, effusivity partition",
    reference="Rojek (2014) Comput. Part. Mech. 1, 71-84; Vernotte (1956)",
    **_COMMON,
)
register(
    name="richard2008",
    model_id=RICHARD2008,
    params=Richard2008Params,
    pack=pack_richard,
    summary="viscous normal force heat 2 μ sqrt(K_n m̄) δ̇_n², split equally",
    reference="Richard et al. (2008) J. Tribol. 130, 031404; Terreros et al. (2009)",
    **_COMMON,
)
