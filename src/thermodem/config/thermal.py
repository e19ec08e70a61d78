"""Case-file section ``thermal``: the heat transfer models, time integration and conditions.

Example::

    thermal:
      contact_radius: geometric
      direct_conduction: batchelor_obrien_simple
      indirect_conduction: none    # e.g. {model: rong_horio1999, layer_thickness_ratio: 0.4}
      convection: none             # e.g. gunn1978, with thermal.fluid and thermal.porosity
      radiation: none              # e.g. {model: krause2017, radius_ratio: 3.0}
      heat_generation: none        # e.g. {model: mechanical_dissipation, partition: effusivity}
      gas: {thermal_conductivity: 0.0263}   # the interstitial gas (default: air, 300 K, 1 atm)
      substeps: 1                  # solve heat every n mechanical steps, or "auto"
      conductance_force_tolerance: 0   # resistance_network: reuse H while F_n is within tol
      initial_temperature: {kind: uniform, value: 293.15}
      fixed_temperature: [{select: {material: heater}, temperature: 400.0}]
      heat_flux: [{select: {region: {lower: [...], upper: [...]}}, flux: 1000.0}]

Walls take part through their own ``thermal`` key (adiabatic by default).

The interstitial gas is one section, ``thermal.gas`` (:class:`thermodem.state.gas.GasProperties`),
read by every model that needs a gas (through ``PairContext.gas``), not a parameter of those
models; it is always present, with the defaults of air at 300 K and 101325 Pa.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from thermodem.config.base import StrictModel
from thermodem.config.fluid import FluidSettings, PorositySettings, parse_porosity
from thermodem.config.planar import Vec3, box_axes
from thermodem.state.gas import GasProperties


def parse_thermal_choice(family: str, value: Any, default: str):  # noqa: ANN201
    from thermodem.config.schema import parse_model_choice

    return parse_model_choice(family, value, default)


class Box(StrictModel):
    """Axis-aligned box region."""

    lower: Vec3
    upper: Vec3

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> Box:
        axes = box_axes(info)  # 2D: [x, y] corners are read with z = 0 (faces included)
        for axis, lo, hi in zip("xyz", self.lower, self.upper, strict=True):
            if axis in axes and not lo < hi:
                raise ValueError(
                    f"lower must be < upper on every axis; on {axis}: lower={lo}, upper={hi}"
                )
        return self


class Selection(StrictModel):
    """Which particles: every given criterion must hold (material, box region, global ids).

    The selection is evaluated on the particles present when the simulation is built and on
    particles inserted later (material and ids), except ``region``, which is evaluated at each
    thermal step on the current positions.
    """

    material: str | None = None
    region: Box | None = None
    ids: list[int] | None = None

    @model_validator(mode="after")
    def _some(self) -> Selection:
        if self.material is None and self.region is None and self.ids is None:
            raise ValueError("give at least one of material, region, ids")
        return self


class UniformTemperature(StrictModel):
    kind: Literal["uniform"] = "uniform"
    value: float = Field(gt=0, description="[K]")


class PerMaterialTemperature(StrictModel):
    kind: Literal["per_material"] = "per_material"
    values: dict[str, float] = Field(description="material name -> temperature [K]")
    default: float = Field(default=293.15, gt=0, description="[K] for materials not listed")

    @field_validator("values")
    @classmethod
    def _positive(cls, v: dict[str, float]) -> dict[str, float]:
        for name, temp in v.items():
            if not temp > 0:
                raise ValueError(f"temperature of {name!r} must be > 0 K, got {temp}")
        return v


class RegionTemperature(StrictModel):
    """Temperature per box region (the last region containing a particle wins)."""

    kind: Literal["regions"] = "regions"
    regions: list[tuple[Box, float]] = Field(description="[(box, temperature [K]), ...]")
    default: float = Field(default=293.15, gt=0, description="[K] outside every region")

    @field_validator("regions")
    @classmethod
    def _positive(cls, v: list[tuple[Box, float]]) -> list[tuple[Box, float]]:
        for k, (_, temp) in enumerate(v):
            if not temp > 0:
                raise ValueError(f"temperature of region {k} must be > 0 K, got {temp}")
        return v


class ExpressionTemperature(StrictModel):
    """T = expression of x, y, z [m] (numpy functions allowed: sin, exp, ...)."""

    kind: Literal["expression"] = "expression"
    expression: str

    @field_validator("expression")
    @classmethod
    def _compiles(cls, v: str) -> str:
        from thermodem.engine.expressions import compile_expression

        compile_expression(v, ("x", "y", "z"))
        return v


InitialTemperature = Annotated[
    UniformTemperature | PerMaterialTemperature | RegionTemperature | ExpressionTemperature,
    Field(discriminator="kind"),
]


class FixedTemperature(StrictModel):
    """Particles held at a temperature (a heat bath); the heat they absorb is ledgered."""

    select: Selection
    temperature: float = Field(gt=0, description="[K]")


class HeatFlux(StrictModel):
    """Surface heat flux q [W/m²] applied as q × 4πR² to the selected particles."""

    select: Selection
    flux: float = Field(description="[W/m^2], positive heats")


class VolumetricSource(StrictModel):
    """Volumetric source s [W/m³] applied as s × 4/3πR³ to the selected particles."""

    select: Selection
    power_density: float = Field(description="[W/m^3], positive heats")


class ExternalSource(StrictModel):
    """External source Q_e (a beam, a burner): total power shared by the particles in a region.

    ``profile: uniform`` gives every particle in the region the same share of the power in
    proportion to its cross-section πR²; ``gaussian`` weights the share by
    exp(-r²/(2σ²)) with r the distance from the region's axis line through its centre along
    ``axis``. Active for ``start_time <= t < end_time``.
    """

    power: float = Field(description="total power [W]")
    region: Box
    profile: Literal["uniform", "gaussian"] = "uniform"
    axis: Vec3 = (0.0, 0.0, 1.0)
    sigma: float | None = Field(default=None, gt=0, description="[m], gaussian profile")
    start_time: float = Field(default=0.0, ge=0)
    end_time: float = Field(
        default=float("inf"), gt=0, allow_inf_nan=True, description="[s]; .inf: never ends"
    )

    @model_validator(mode="after")
    def _check(self) -> ExternalSource:
        if self.profile == "gaussian" and self.sigma is None:
            raise ValueError("profile 'gaussian' needs sigma [m]")
        if not sum(a * a for a in self.axis) > 0.0:
            raise ValueError(f"axis must be a non-zero vector, got {list(self.axis)}")
        if self.end_time <= self.start_time:
            raise ValueError(f"end_time {self.end_time} must be after start_time {self.start_time}")
        return self


class ThermalStability(StrictModel):
    """Explicit Euler stability: Δt_th <= m c / ΣH per particle, and ρ c R² / k (spec 1.4)."""

    warn_fraction: float = Field(default=0.5, gt=0, le=1)
    allow_unstable: bool = False


class TessellationSettings(StrictModel):
    """The Voronoi tessellation of the Voronoi conduction models and of ``porosity: {kind:
    voronoi}`` (``engine/voronoi.py``; docs/models/indirect_conduction-voronoi_a.md).

    The tessellation is made at the first thermal step and again when ``every_steps``
    mechanical steps have passed since the last one, or when a particle has moved more than
    ``displacement_ratio`` × R_min since the last one (like a neighbour skin); with neither
    (or frozen mechanics) it is made once. Non-periodic domain faces and plane walls clip the
    cells; the cell faces on walls are the particle-wall faces.
    """

    method: Literal["plain", "radical"] = Field(
        default="plain",
        description="plain: Voronoi; radical: the radical (Laguerre, power) tessellation of "
        "the spheres, for polydisperse beds",
    )
    backend: Literal["compiled", "library"] = Field(
        default="compiled",
        description="compiled: thermodem's clipped cells in double precision (the library "
        "when a check fails, said in run.log); library: freud (plain) or pyvoro2 (radical) "
        "with mirror particles",
    )
    every_steps: int | None = Field(
        default=None, ge=1, description="re-tessellate every this many mechanical steps"
    )
    displacement_ratio: float | None = Field(
        default=0.1,
        gt=0,
        description="re-tessellate when a particle moved more than this × R_min since the "
        "last tessellation; null: never for that reason",
    )
    conductance_gap_tolerance: float = Field(
        default=0.0,
        ge=0,
        le=0.1,
        description="reuse a Voronoi pair's conductance while its centre distance stays within "
        "this × its surface gap (or overlap) of the last evaluation, on the same side of "
        "touching and of the cut-off (secant in between); 0: evaluate every pair at every "
        "thermal step",
    )


class ImplicitSettings(StrictModel):
    """Solver settings of the implicit schemes (docs/implicit.md)."""

    tolerance: float = Field(
        default=1e-10, gt=0, lt=1, description="relative residual of the conjugate gradients"
    )
    max_iterations: int = Field(default=1000, ge=1, description="conjugate-gradient iterations")
    preconditioner: Literal["auto", "amg", "jacobi"] = Field(
        default="auto",
        description="preconditioner of the conjugate gradients: smoothed-aggregation algebraic "
        "multigrid (pyamg) or the diagonal (Jacobi); auto: the diagonal for a time step whose "
        "capacity term bounds the condition number by 1000, else multigrid",
    )
    picard_tolerance: float = Field(
        default=1e-8,
        gt=0,
        description="Picard iteration on k(T), c(T) and the per-particle terms: largest "
        "temperature change between iterates [K]",
    )
    picard_iterations: int = Field(default=50, ge=1, description="largest Picard iterations")
    startup_steps: int = Field(
        default=0,
        ge=0,
        description="crank_nicolson: the first n steps as two backward-Euler half steps each "
        "(Rannacher start; damps the stiff modes of a non-smooth start)",
    )
    error_tolerance: float = Field(
        default=1e-3,
        gt=0,
        description="tr_bdf2: RMS over the free particles of the estimated local error of an "
        "internal step [K]",
    )
    initial_step: float | None = Field(
        default=None,
        gt=0,
        description="tr_bdf2: first internal step [s]; null: the explicit limit m c/ΣH",
    )
    krylov_tolerance: float = Field(
        default=1e-6,
        gt=0,
        description="exponential: estimated RMS temperature error of the Krylov approximation "
        "over the free particles [K]",
    )
    krylov_dimension: int = Field(
        default=200,
        ge=10,
        le=5000,
        description="exponential: largest number of Lanczos vectors kept (memory: 8 bytes x "
        "particles x (this + 1)); beyond it a new basis starts, or the step is divided",
    )


#: Implicit settings read by one scheme only (thermal.implicit.KEY -> thermal.scheme).
SCHEME_SETTINGS = {
    "startup_steps": "crank_nicolson",
    "error_tolerance": "tr_bdf2",
    "initial_step": "tr_bdf2",
    "krylov_tolerance": "exponential",
    "krylov_dimension": "exponential",
}


class ThermalSettings(StrictModel):
    """Heat transfer between particles (explicit Euler, spec section 1.2)."""

    contact_radius: Any = Field(
        default="geometric", validate_default=True, description="contact_radius model"
    )
    direct_conduction: Any = Field(
        default="batchelor_obrien_simple",
        validate_default=True,
        description="direct_conduction model",
    )
    indirect_conduction: Any = Field(
        default="none",
        validate_default=True,
        description="indirect_conduction model (conduction through the fluid between near "
        "particles, evaluated on the range pair set)",
    )
    radiation: Any = Field(
        default="none",
        validate_default=True,
        description="radiation model (per-particle term)",
    )
    convection: Any = Field(
        default="none",
        validate_default=True,
        description="convection model: particle-fluid heat transfer (per-particle term)",
    )
    heat_generation: Any = Field(
        default="none",
        validate_default=True,
        description="heat generation model: the mechanical dissipation of the contacts turned "
        "into heat (conversion fraction, partition between the two bodies)",
    )
    fluid: FluidSettings | None = Field(
        default=None,
        description="the fluid around the particles (temperature, velocity, properties), "
        "read by convection and by radiation.zhou2009",
    )
    porosity: PorositySettings | None = Field(
        default=None,
        description="local porosity of each particle (global, cell, shell, voronoi), read by "
        "the porosity-based correlations and radiation models",
    )
    tessellation: TessellationSettings | None = Field(
        default=None,
        description="the Voronoi tessellation (method, update policy) of the Voronoi models "
        "and of porosity kind voronoi; null: the defaults",
    )
    range_skin: float | None = Field(
        default=None,
        gt=0,
        description="Verlet skin of the range pair set [m]; null: the contact list's skin",
    )
    gas: GasProperties = Field(
        default_factory=GasProperties,
        description="interstitial gas read by every model that needs one; default: air at "
        "300 K, 101325 Pa",
    )
    substeps: int | Literal["auto"] = Field(
        default=1, description="solve heat every n mechanical steps, or 'auto' from the limit"
    )
    max_substeps: int = Field(default=1000, ge=1)
    conductance_force_tolerance: float = Field(
        default=0.0,
        ge=0,
        le=0.1,
        description="reuse a contact's conductance while its normal force stays within this "
        "relative change of the last evaluation (secant in between); 0: evaluate every step",
    )
    frozen_mechanics: bool = Field(
        default=False, description="positions and contacts fixed; heat only"
    )
    time_step: float | None = Field(
        default=None, gt=0, description="thermal time step with frozen mechanics [s]"
    )
    scheme: Literal["explicit", "backward_euler", "crank_nicolson", "tr_bdf2", "exponential"] = (
        Field(
            default="explicit",
            description="time scheme of the heat: explicit Euler, or (frozen mechanics only) the "
            "implicit backward Euler / Crank-Nicolson solve of the conductance network, adaptive "
            "TR-BDF2 with error control, or the Krylov exponential of a linear network (exact in "
            "time, constant properties)",
        )
    )
    implicit: ImplicitSettings = Field(
        default_factory=lambda: ImplicitSettings(),
        description="linear solver and Picard iteration of the implicit schemes",
    )
    initial_temperature: InitialTemperature | None = None
    fixed_temperature: list[FixedTemperature] = Field(default_factory=list)
    heat_flux: list[HeatFlux] = Field(default_factory=list)
    volumetric_source: list[VolumetricSource] = Field(default_factory=list)
    external_source: list[ExternalSource] = Field(default_factory=list)
    stability: ThermalStability = Field(default_factory=ThermalStability)

    @field_validator("contact_radius", mode="before")
    @classmethod
    def _cr(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("contact_radius", v, "geometric")

    @field_validator("direct_conduction", mode="before")
    @classmethod
    def _dc(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("direct_conduction", v, "batchelor_obrien_simple")

    @field_validator("indirect_conduction", mode="before")
    @classmethod
    def _ic(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("indirect_conduction", v, "none")

    @field_validator("radiation", mode="before")
    @classmethod
    def _rad(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("radiation", v, "none")

    @field_validator("convection", mode="before")
    @classmethod
    def _conv(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("convection", v, "none")

    @field_validator("heat_generation", mode="before")
    @classmethod
    def _gen(cls, v: Any):  # noqa: ANN206
        return parse_thermal_choice("heat_generation", v, "none")

    @field_validator("porosity", mode="before")
    @classmethod
    def _porosity(cls, v: Any) -> Any:
        return parse_porosity(v)

    @field_validator("substeps")
    @classmethod
    def _positive(cls, v: int | str) -> int | str:
        if isinstance(v, int) and v < 1:
            raise ValueError(f"substeps must be >= 1 or 'auto', got {v}")
        return v

    @model_validator(mode="after")
    def _frozen(self, info: ValidationInfo) -> ThermalSettings:
        from thermodem.state.materials import STORED_CASE_KEY

        stored = bool(info.context and info.context.get(STORED_CASE_KEY))
        ignored = []  # settings that the case's other keys make unused (they ran ignored)
        if self.time_step is not None and not self.frozen_mechanics:
            ignored.append(
                f"time_step = {self.time_step:g} s is the step of the heat with frozen "
                "mechanics, but frozen_mechanics is false: the heat runs at "
                "simulation.time_step (× substeps); allowed: frozen_mechanics: true, or leave "
                "time_step out (substeps: n solves the heat every n mechanical steps)"
            )
        if self.max_substeps != 1000 and self.substeps != "auto":
            ignored.append(
                f"max_substeps = {self.max_substeps} caps substeps: auto, but substeps is "
                f"{self.substeps}; allowed: substeps: auto, or leave max_substeps out"
            )
        # the settings of one implicit scheme given with another (a scheme switched, its
        # settings kept); tolerance, max_iterations, preconditioner and the Picard settings
        # are read by several schemes and by etc's steady solve
        defaults = ImplicitSettings()
        for key, owner in SCHEME_SETTINGS.items():
            value = getattr(self.implicit, key)
            if self.scheme != owner and value != getattr(defaults, key):
                ignored.append(
                    f"implicit.{key} = {value!r} is read by scheme {owner!r} only, but scheme "
                    f"is {self.scheme!r}; allowed: scheme: {owner}, or leave implicit.{key} out"
                )
        generation = getattr(self.heat_generation, "model", "none")
        if self.frozen_mechanics and generation != "none":
            ignored.append(
                f"heat_generation = {generation!r} turns the dissipation of moving contacts "
                "into heat, but frozen_mechanics is true: nothing moves, so no heat would be "
                "generated; allowed: heat_generation: none, or frozen_mechanics: false"
            )
        from thermodem.models.thermal.radiation import WallRadiation

        walls = getattr(self.radiation, "params", None)
        if isinstance(walls, WallRadiation) and not walls.walls:
            for key in ("wall_view_factor", "wall_range"):
                value = getattr(walls, key)
                if value != WallRadiation.model_fields[key].default:
                    ignored.append(
                        f"radiation.{key} = {value:g} sets the radiation with the walls in "
                        f"view, but radiation.walls is false; allowed: walls: true, or leave "
                        f"{key} out"
                    )
        if ignored and not stored:
            raise ValueError("; ".join(ignored) + " (the value would be ignored)")
        if self.frozen_mechanics and self.time_step is None:
            raise ValueError(
                "frozen_mechanics needs thermal.time_step [s] (missing): the step of the heat "
                "with the mechanics frozen, e.g. time_step: 1.0e-3"
            )
        if self.scheme != "explicit" and not self.frozen_mechanics:
            raise ValueError(
                f"thermal.scheme = {self.scheme!r} needs thermal.frozen_mechanics: true (the "
                "implicit schemes solve the conductance network of a bed that does not move); "
                "allowed with moving mechanics: 'explicit'"
            )
        return self


class WallThermal(StrictModel):
    """Thermal condition of a wall: adiabatic, or a fixed temperature.

    ``temperature`` is a constant [K], a table ``[[t, T], ...]`` interpolated linearly in time
    (held constant outside), or an expression of ``t`` [s] (e.g. ``"300 + 50 * (t > 1)"``).
    """

    kind: Literal["adiabatic", "fixed"] = "adiabatic"
    temperature: float | list[tuple[float, float]] | str | None = None

    @field_validator("temperature")
    @classmethod
    def _expression(cls, v: object) -> object:
        """An expression is compiled here, so that its error names the key
        ``walls.K.thermal.temperature``; ``"inf"``/``"nan"`` are told to be non-finite."""
        if isinstance(v, str):
            try:
                number = float(v)
            except ValueError:
                number = None
            if number is not None and not math.isfinite(number):
                raise ValueError(f"Input should be a finite number (got {v!r})")
            from thermodem.config.messages import unit_hint

            unit = unit_hint(v)
            if unit:  # '300K', '25 °C': read as an expression of t, refused as bad syntax
                raise ValueError(f"should be a number in K (got {v!r}){unit}")
            from thermodem.engine.expressions import compile_expression

            compile_expression(v, ("t",))
        return v

    @model_validator(mode="after")
    def _check(self) -> WallThermal:
        if self.kind == "fixed" and self.temperature is None:
            raise ValueError("a fixed-temperature wall needs temperature")
        if self.kind == "adiabatic" and self.temperature is not None:
            raise ValueError(
                "temperature is given but kind is 'adiabatic' (the default): set kind: fixed"
            )
        if isinstance(self.temperature, int | float) and not self.temperature > 0:
            raise ValueError(f"temperature must be > 0 K, got {self.temperature}")
        if isinstance(self.temperature, list):
            times = [t for t, _ in self.temperature]
            if not times:
                raise ValueError(
                    "temperature table is empty; give rows [t [s], T [K]], e.g. "
                    "[[0.0, 300.0], [1.0, 400.0]], or a number"
                )
            for k, (a, b) in enumerate(zip(times, times[1:], strict=False)):
                if not b > a:
                    raise ValueError(
                        f"temperature table times must increase strictly; row {k + 1} has "
                        f"t = {b:g} s after t = {a:g} s in row {k} (got times {times})"
                    )
            for k, (t, temp) in enumerate(self.temperature):
                if not temp > 0:
                    raise ValueError(
                        f"temperature table values must be > 0 K; row {k} [t = {t:g} s] has "
                        f"T = {temp:g}"
                    )
        return self
