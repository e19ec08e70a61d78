"""Materials (per type) and the resolved properties of a pair of materials that meet.

A material is a row of properties indexed by ``type_id``; walls have materials too. Every model's
``pack`` receives a :class:`PairContext`, which holds both materials, the pair-resolved
mechanical coefficients and the case's interstitial gas, and turns them into a float64
parameter row for that type pair.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pydantic import Field, ValidationInfo, field_validator, model_validator

from thermodem.config.base import StrictModel
from thermodem.state.gas import GasProperties

#: Validation context key of a case stored in a checkpoint (``Checkpoint.case``): read as it
#: was written (the resolved case of earlier versions gave a table's constant too).
STORED_CASE_KEY = "stored_case"


class Material(StrictModel):
    """Bulk and surface properties of one particle or wall material (SI units)."""

    density: float = Field(gt=0, description="density [kg/m^3]")
    youngs_modulus: float = Field(gt=0, description="Young's modulus used by the contact law [Pa]")
    poisson_ratio: float = Field(gt=-1.0, lt=0.5, description="Poisson ratio [-]")
    restitution: float = Field(
        default=0.5, ge=0.0, le=1.0, description="normal coefficient of restitution [-]"
    )
    sliding_friction: float = Field(default=0.5, ge=0.0, description="Coulomb coefficient [-]")
    rolling_friction: float = Field(
        default=0.0, ge=0.0, description="rolling resistance coefficient [-]"
    )
    # Thermal bulk properties (required only when a model that uses them is selected).
    thermal_conductivity: float | None = Field(default=None, gt=0, description="[W/(m K)]")
    specific_heat: float | None = Field(default=None, gt=0, description="[J/(kg K)]")
    emissivity: float | None = Field(default=None, ge=0.0, le=1.0, description="[-]")
    electrical_resistivity: float | None = Field(
        default=None, gt=0, description="[Ω m] (heat generation: Mokrani & Bourouga partition)"
    )
    # Surface properties for the stagnant-gas resistance network (Beaulieu 2020).
    microhardness: float | None = Field(default=None, gt=0, description="[Pa]")
    surface_roughness: float | None = Field(default=None, gt=0, description="RMS roughness [m]")
    surface_slope: float | None = Field(default=None, gt=0, description="RMS asperity slope [-]")
    thermal_accommodation: float | None = Field(default=None, gt=0, le=1.0, description="[-]")
    # Real (physical) Young's modulus for low-stiffness corrections of the contact radius.
    youngs_modulus_real: float | None = Field(default=None, gt=0, description="[Pa]")
    # Temperature-dependent properties: [[T (K), value], ...], linear in T between the nodes
    # and held constant outside them. When given, they replace the constants at run time.
    thermal_conductivity_table: list[tuple[float, float]] | None = Field(
        default=None, description="[[T (K), k (W/(m K))], ...]"
    )
    specific_heat_table: list[tuple[float, float]] | None = Field(
        default=None, description="[[T (K), c (J/(kg K))], ...]"
    )

    @field_validator("thermal_conductivity_table", "specific_heat_table")
    @classmethod
    def _table(cls, v: list[tuple[float, float]] | None) -> list[tuple[float, float]] | None:
        if v is None:
            return v
        if len(v) < 1:
            raise ValueError("a table needs at least one [T, value] row")
        temps = [row[0] for row in v]
        if any(b <= a for a, b in zip(temps, temps[1:], strict=False)):
            raise ValueError(f"table temperatures must increase strictly, got {temps}")
        if any(row[0] <= 0 or row[1] <= 0 for row in v):
            raise ValueError("table temperatures and values must be > 0")
        return v

    @model_validator(mode="after")
    def _reference_values(self, info: ValidationInfo) -> Material:
        # a constant and a table of one property: the table replaces the constant at run time,
        # so one of the two would be ignored (a case stored by an earlier version, which wrote
        # the table's first value as the constant, is read as it was)
        stored = bool(info.context and info.context.get(STORED_CASE_KEY))
        for name, unit in (("thermal_conductivity", "W/(m K)"), ("specific_heat", "J/(kg K)")):
            table = getattr(self, f"{name}_table")
            # (an explicit null is the key left out: the table alone)
            given = name in self.model_fields_set and getattr(self, name) is not None
            if table and given and not stored:
                rows = [list(row) for row in table]
                raise ValueError(
                    f"{name}: {getattr(self, name):g} {unit} is given together with "
                    f"{name}_table {rows}; the table replaces the constant at run time ({name} "
                    f"of T), so one of them would be ignored: give {name}_table alone for a "
                    f"temperature-dependent {name}, or {name} alone for a constant one"
                )
        # the constant is the reference a model's parameter row is packed with; at run time
        # the conductivity / heat capacity columns of the row are replaced by table values
        if self.thermal_conductivity_table and self.thermal_conductivity is None:
            self.__dict__["thermal_conductivity"] = self.thermal_conductivity_table[0][1]
        if self.specific_heat_table and self.specific_heat is None:
            self.__dict__["specific_heat"] = self.specific_heat_table[0][1]
        return self

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))


class InteractionOverride(StrictModel):
    """Pair-specific coefficients that replace the mixing rule for one pair of materials.

    Mechanical: ``restitution``, ``sliding_friction``, ``rolling_friction`` (replace the mean
    of the two materials). Surface of the pair for the resistance network (Beaulieu 2020):
    ``surface_roughness`` σ and ``surface_slope`` τ are the pair's *equivalent* values, which
    otherwise are σ = √(σ_i² + σ_j²) and τ = √(τ_i² + τ_j²) of the materials (Bahrami et al.
    2006); a source that gives equivalent values (Lethe's tests: σ = 25 nm, τ = 0.078) puts them
    here, and the materials then need not give their own.
    """

    materials: tuple[str, str]
    restitution: float | None = Field(default=None, ge=0.0, le=1.0)
    sliding_friction: float | None = Field(default=None, ge=0.0)
    rolling_friction: float | None = Field(default=None, ge=0.0)
    surface_roughness: float | None = Field(
        default=None, gt=0, description="equivalent RMS roughness σ of the pair [m]"
    )
    surface_slope: float | None = Field(
        default=None, gt=0, description="equivalent RMS asperity slope τ of the pair [-]"
    )

    @model_validator(mode="after")
    def _some_coefficient(self, info: ValidationInfo) -> InteractionOverride:
        # an entry naming the pair and nothing else changes nothing (a coefficient left out
        # or misplaced); a checkpoint's stored case is read as it was written
        if self.model_fields_set - {"materials"} or (
            info.context and info.context.get(STORED_CASE_KEY)
        ):
            return self
        keys = ", ".join(k for k in type(self).model_fields if k != "materials")
        a, b = self.materials
        raise ValueError(
            f"names the pair {a}-{b} but gives no coefficient, so it would change nothing; "
            f"allowed: one or more of {keys}, or remove the entry"
        )


def effective_youngs_modulus(mi: Material, mj: Material, real: bool = False) -> float:
    """E* = [(1 - nu_i^2)/E_i + (1 - nu_j^2)/E_j]^-1 (spec, appendix A)."""
    ei = (mi.youngs_modulus_real or mi.youngs_modulus) if real else mi.youngs_modulus
    ej = (mj.youngs_modulus_real or mj.youngs_modulus) if real else mj.youngs_modulus
    return 1.0 / ((1.0 - mi.poisson_ratio**2) / ei + (1.0 - mj.poisson_ratio**2) / ej)


def effective_shear_modulus(mi: Material, mj: Material) -> float:
    """G* = [(2 - nu_i)/G_i + (2 - nu_j)/G_j]^-1 (Mindlin; Di Renzo & Di Maio 2004)."""
    return 1.0 / (
        (2.0 - mi.poisson_ratio) / mi.shear_modulus + (2.0 - mj.poisson_ratio) / mj.shear_modulus
    )


@dataclass(frozen=True)
class PairContext:
    """The two materials that meet and their pair-resolved coefficients.

    Mixing rule (when no ``interactions`` override names the pair): the arithmetic mean of the
    two materials' restitution, sliding and rolling friction coefficients. For a particle-wall
    pair ``mat_j`` is the wall material and ``is_wall`` is true (the wall is a body of infinite
    radius and mass).

    ``gas`` is the case's interstitial gas (``thermal.gas``), the same for every pair; models
    that need a gas read it here. Default: air at 300 K, 1 atm, as the case-file default.

    ``surface_roughness`` and ``surface_slope``: the pair's equivalent σ and τ when an
    ``interactions`` entry gives them, else None (a model combines the materials' values).

    ``thickness``: the disc thickness b [m] of a two-dimensional case of discs
    (``simulation.dimension: 2``, ``particle_shape: disc``); 0 in 3D and for spheres kept in a
    plane. The models with a 2D form read it (docs/two-dimensional.md).
    """

    mat_i: Material
    mat_j: Material
    restitution: float
    sliding_friction: float
    rolling_friction: float
    is_wall: bool = False
    gas: GasProperties = field(default_factory=GasProperties)
    surface_roughness: float | None = None
    surface_slope: float | None = None
    thickness: float = 0.0

    @property
    def effective_youngs_modulus(self) -> float:
        return effective_youngs_modulus(self.mat_i, self.mat_j)

    @property
    def effective_shear_modulus(self) -> float:
        return effective_shear_modulus(self.mat_i, self.mat_j)


def resolve_pair(
    mi: Material,
    mj: Material,
    override: InteractionOverride | None = None,
    is_wall: bool = False,
    gas: GasProperties | None = None,
    thickness: float = 0.0,
) -> PairContext:
    """Pair coefficients from the mixing rule, replaced where an override gives them; ``gas``
    None: the default gas (air at 300 K, 1 atm); ``thickness`` the disc thickness of a 2D case
    of discs (0 otherwise)."""

    def pick(attr: str) -> float:
        if override is not None and getattr(override, attr) is not None:
            return float(getattr(override, attr))
        return 0.5 * (getattr(mi, attr) + getattr(mj, attr))

    return PairContext(
        mat_i=mi,
        mat_j=mj,
        restitution=pick("restitution"),
        sliding_friction=pick("sliding_friction"),
        rolling_friction=pick("rolling_friction"),
        is_wall=is_wall,
        gas=gas if gas is not None else GasProperties(),
        surface_roughness=None if override is None else override.surface_roughness,
        surface_slope=None if override is None else override.surface_slope,
        thickness=float(thickness),
    )
