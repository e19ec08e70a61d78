"""The case file: pydantic models of every section (unknown keys are errors).

A case is YAML; :func:`thermodem.config.load.load_case` reads it into :class:`Case`. Model
choices are ``{model: NAME, <parameters of that model>}``: the name is checked against the
registry (with a "did you mean") and the remaining keys against that model's own schema.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    Field,
    PrivateAttr,
    ValidationInfo,
    field_validator,
    model_validator,
)

from thermodem.config.base import StrictModel
from thermodem.config.case_checks import CaseChecks, fluid_probe_samples  # noqa: F401
from thermodem.config.insertion import InsertionEntry
from thermodem.config.planar import Vec3, box_axes, is_planar
from thermodem.config.thermal import Selection, ThermalSettings
from thermodem.geometry.walls import Wall
from thermodem.models import registry
from thermodem.state.materials import InteractionOverride, Material

#: Gravity when the case gives none: along -z in 3D, along -y in 2D (the plane is x-y).
DEFAULT_GRAVITY_3D = (0.0, 0.0, -9.81)
DEFAULT_GRAVITY_2D = (0.0, -9.81, 0.0)


class ModelChoice(StrictModel):
    """A model of one family and its validated parameters."""

    family: str
    model: str
    params: BaseModel

    @property
    def spec(self) -> registry.ModelSpec:
        return registry.get(self.family, self.model)


#: Registry family -> the case-file key that selects its model.
MODEL_KEYS: dict[str, str] = {
    "normal": "contact.normal",
    "tangential": "contact.tangential",
    "rolling": "contact.rolling",
    "contact_radius": "thermal.contact_radius",
    "direct_conduction": "thermal.direct_conduction",
    "indirect_conduction": "thermal.indirect_conduction",
    "convection": "thermal.convection",
    "radiation": "thermal.radiation",
    "heat_generation": "thermal.heat_generation",
}


def null_model_message(family: str, key: str, default: str) -> str:
    """The refusal of ``KEY: null`` (an empty key), which used to select the default model
    silently: the key, the value, how to say "off" where the family can, and the names."""
    from thermodem.config.planar_case import DISC_CONTACT_DEFAULTS

    choices = registry.names(family)
    word = key.rsplit(".", 1)[-1]
    disc = DISC_CONTACT_DEFAULTS.get(family)
    shown = f"{default}; {disc} for 2D discs" if disc else default
    if "none" in choices:
        how = f"write none for no {family} model, a model name, or leave the key out"
    else:
        how = f"{family} has no model none: write a model name, or leave the key out"
    return (
        f"{key}: null (an empty '{word}:' key) is not a model name; {how} for the default "
        f"({shown}); allowed: {', '.join(choices)}"
    )


def parse_model_choice(family: str, value: Any, default: str) -> ModelChoice:
    """``"hertz"`` or ``{model: hertz, ...params}`` -> ModelChoice (raises ValueError).

    ``null`` (an empty key), or ``model: null`` in the mapping, is refused: it selected the
    default model silently, where the user more likely meant "off" or left a value out. A
    mapping without ``model`` selects ``default``."""
    if isinstance(value, ModelChoice):
        return value
    key = MODEL_KEYS.get(family, family)
    if value is None:
        raise ValueError(null_model_message(family, key, default))
    if isinstance(value, str):
        value = {"model": value}
    if not isinstance(value, dict):
        raise ValueError(f"expected a model name or a mapping with 'model', got {value!r}")
    data = dict(value)
    name = data.pop("model", default)
    if name is None:
        raise ValueError(null_model_message(family, f"{key}.model", default))
    try:
        spec = registry.get(family, str(name))
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None
    return ModelChoice(family=family, model=spec.name, params=spec.params(**data))


class ContactModels(StrictModel):
    """Mechanical contact laws: ``normal``, ``tangential``, ``rolling``."""

    normal: ModelChoice = Field(
        default_factory=lambda: parse_model_choice("normal", "hertz", "hertz")
    )
    tangential: ModelChoice = Field(
        default_factory=lambda: parse_model_choice("tangential", "mindlin", "mindlin")
    )
    rolling: ModelChoice = Field(
        default_factory=lambda: parse_model_choice("rolling", "none", "none")
    )

    @field_validator("normal", mode="before")
    @classmethod
    def _normal(cls, v: Any) -> ModelChoice:
        return parse_model_choice("normal", v, "hertz")

    @field_validator("tangential", mode="before")
    @classmethod
    def _tangential(cls, v: Any) -> ModelChoice:
        return parse_model_choice("tangential", v, "mindlin")

    @field_validator("rolling", mode="before")
    @classmethod
    def _rolling(cls, v: Any) -> ModelChoice:
        return parse_model_choice("rolling", v, "none")


class Domain(StrictModel):
    """Simulation box: the cell grid spans it; particles leaving a non-periodic side are an
    error."""

    lower: Vec3
    upper: Vec3
    periodic: tuple[bool, bool, bool] = (False, False, False)

    @field_validator("periodic", mode="before")
    @classmethod
    def _periodic_2d(cls, v: Any, info: ValidationInfo) -> Any:
        if is_planar(info) and isinstance(v, list | tuple) and len(v) == 2:
            return (v[0], v[1], False)
        return v

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> Domain:
        axes = box_axes(info)  # 2D: the z extent is not used (the plane z = 0)
        for axis, lo, hi in zip("xyz", self.lower, self.upper, strict=True):
            if axis in axes and not lo < hi:
                raise ValueError(
                    f"lower must be < upper on every axis; on {axis}: lower={lo}, upper={hi}"
                )
        return self


class Neighbors(StrictModel):
    """Neighbour list settings."""

    skin: float | None = Field(
        default=None,
        ge=0,
        description="Verlet skin [m]; default 0.1 × the largest particle diameter",
    )
    extra_distance: float = Field(
        default=0.0, ge=0, description="interaction distance beyond contact (near pairs) [m]"
    )
    rebuild_every_step: bool = Field(default=False, description="ignore the skin criterion")


class TimeStepCheck(StrictModel):
    """Time step criteria checked before the run (docs/time-step.md).

    Rayleigh time (Li et al. 2005): warn above ``rayleigh_warn_fraction``, refuse above 1.
    Hertz collision time t_c at ``impact_velocity`` (spec appendix A): warn when a collision
    lasts fewer than ``collision_warn_steps`` steps, refuse below ``collision_min_steps``.
    ``allow_unstable: true`` turns refusals into warnings.
    """

    rayleigh_warn_fraction: float = Field(default=0.3, gt=0, le=1)
    collision_warn_steps: float = Field(default=30.0, gt=0)
    collision_min_steps: float = Field(default=10.0, gt=0)
    impact_velocity: float | None = Field(
        default=None,
        gt=0,
        description="characteristic impact speed [m/s]; default: max(1, sqrt(2 g H), "
        "initial and wall speeds)",
    )
    allow_unstable: bool = False


class SimulationSettings(StrictModel):
    time_step: float = Field(gt=0, description="[s]")
    end_time: float = Field(gt=0, description="[s]")
    dimension: Literal[2, 3] = Field(
        default=3, description="3: spheres in space; 2: discs (or spheres) in the x-y plane"
    )
    thickness: float = Field(
        default=1.0,
        gt=0,
        description="2D: thickness b of the discs [m] (mass ρ π R² b, heat rates of a disc of "
        "that thickness; 1 m: per unit thickness)",
    )
    particle_shape: Literal["disc", "sphere"] = Field(
        default="disc", description="2D: discs of the thickness, or spheres kept in the plane"
    )
    gravity: Vec3 = DEFAULT_GRAVITY_3D
    seed: int = Field(default=12345, ge=0)
    initial_temperature: float = Field(default=293.15, gt=0, description="[K]")
    time_step_check: TimeStepCheck = Field(default_factory=TimeStepCheck)
    max_overlap_ratio: float = Field(
        default=0.2,
        gt=0,
        le=1,
        description="stop when an overlap exceeds this fraction of the smaller radius",
    )

    @model_validator(mode="before")
    @classmethod
    def _gravity_2d(cls, data: Any) -> Any:
        """Default gravity of a 2D case: -9.81 m/s² along y. A dimension written as a string
        (``dimension: "2"``) is the number, as every other number written as a string is
        (pydantic refused it with the misleading ``Input should be 2 or 3 (got '2')``)."""
        dim = data.get("dimension") if isinstance(data, dict) else None
        if isinstance(dim, str) and dim.strip() in ("2", "3"):
            data = {**data, "dimension": int(dim.strip())}
        if isinstance(data, dict) and data.get("dimension") == 2 and "gravity" not in data:
            data = {**data, "gravity": DEFAULT_GRAVITY_2D}
        return data

    @model_validator(mode="after")
    def _only_2d(self) -> SimulationSettings:
        if self.dimension == 3:
            for key in ("thickness", "particle_shape"):
                if key in self.model_fields_set:
                    raise ValueError(
                        f"{key}: {getattr(self, key)!r} is a key of 2D cases only; set "
                        "dimension: 2 or remove it"
                    )
        elif self.particle_shape == "sphere" and "thickness" in self.model_fields_set:
            raise ValueError(
                f"thickness: {self.thickness!r} is the length of discs; with particle_shape: "
                "sphere the particles are spheres (no thickness): remove it"
            )
        elif self.gravity[2] != 0.0:
            raise ValueError(
                f"gravity: {list(self.gravity)} has a z component in a 2D case (the particles "
                "move in the x-y plane): give [gx, gy] or [gx, gy, 0]"
            )
        return self

    @property
    def planar(self) -> bool:
        """A two-dimensional case (``dimension: 2``)."""
        return self.dimension == 2

    @property
    def disc_thickness(self) -> float:
        """The disc thickness b [m] of a 2D case of discs, else 0 (3D, spheres in a plane):
        what the models with a 2D form read (``PairContext.thickness``)."""
        return float(self.thickness) if self.planar and self.particle_shape == "disc" else 0.0


class Output(StrictModel):
    interval: float | None = Field(default=None, gt=0, description="VTU interval [s]")
    vtu: bool = True
    contacts: bool = Field(
        default=False,
        description="also write the touching contacts (lines with forces, contact radii, "
        "conductances and heat rates) as vtk/contacts_*.vtu with contacts.pvd",
    )
    wall_extent: float | None = Field(
        default=None, gt=0, description="half size drawn for infinite walls [m]"
    )
    timeseries_interval: float | None = Field(
        default=None, gt=0, description="timeseries.csv row interval [s]; default end_time / 1000"
    )
    checkpoint_interval: float | None = Field(
        default=None, gt=0, description="HDF5 checkpoint interval [s]; default end_time / 10"
    )
    checkpoint_keep: int | None = Field(
        default=2, ge=1, description="newest periodic checkpoints kept; null: keep all"
    )

    @model_validator(mode="after")
    def _frame_keys_need_frames(self, info: ValidationInfo) -> Output:
        # contacts, interval and wall_extent are the frames' keys: with vtu false no frame is
        # written and each would be ignored (contacts: true wrote no contact at all, silently).
        # A checkpoint's stored case is read as an earlier version wrote it.
        from thermodem.state.materials import STORED_CASE_KEY

        if self.vtu or (info.context and info.context.get(STORED_CASE_KEY)):
            return self
        given = [
            f"{key}: {str(value).lower() if isinstance(value, bool) else f'{value:g}'}"
            for key in ("contacts", "interval", "wall_extent")
            if (value := getattr(self, key)) not in (None, False)
        ]
        if given:
            keys = [g.split(":")[0] for g in given]
            listed = keys[0] if len(keys) == 1 else f"{', '.join(keys[:-1])} and {keys[-1]}"
            raise ValueError(
                f"vtu: false writes no VTU frame, so {', '.join(given)} would be ignored "
                "(settings of the frames); allowed: vtu: true to write the frames, or leave "
                f"{listed} out"
            )
        return self


FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


class ExternalForce(StrictModel):
    """A constant force and torque on every selected particle, applied at every step
    (docs/case-file.md, ``external_force``).

    ``select`` is a :class:`~thermodem.config.thermal.Selection` (material, box region, global
    ids: every given criterion must hold), evaluated once per particle when it is added to the
    simulation (construction or pouring): the region on its position then. Entries add up.
    """

    select: Selection
    force: tuple[FiniteFloat, FiniteFloat, FiniteFloat] = Field(
        default=(0.0, 0.0, 0.0), description="[N] on each selected particle"
    )
    torque: tuple[FiniteFloat, FiniteFloat, FiniteFloat] = Field(
        default=(0.0, 0.0, 0.0), description="[N m] on each selected particle"
    )

    @model_validator(mode="after")
    def _something(self) -> ExternalForce:
        if "force" not in self.model_fields_set and "torque" not in self.model_fields_set:
            raise ValueError("give force [fx, fy, fz] (N) and/or torque [tx, ty, tz] (N m)")
        if self.select.ids is not None and any(i < 0 for i in self.select.ids):
            ids = self.select.ids
            raise ValueError(f"select.ids must be >= 0 (global particle ids), got {ids}")
        return self


class Case(CaseChecks, StrictModel):
    """A whole case file."""

    simulation: SimulationSettings
    domain: Domain
    materials: dict[str, Material]
    interactions: list[InteractionOverride] = Field(default_factory=list)
    contact: ContactModels = Field(default_factory=ContactModels)
    neighbors: Neighbors = Field(default_factory=Neighbors)
    walls: list[Wall] = Field(default_factory=list)
    insertion: list[InsertionEntry] = Field(default_factory=list)
    output: Output = Field(default_factory=Output)
    thermal: ThermalSettings | None = Field(
        default=None, description="heat transfer; absent = mechanics only"
    )
    external_force: list[ExternalForce] = Field(
        default_factory=list, description="constant force/torque on selected particles"
    )
    #: set by ``thermodem run --steps N`` / ``--end-time T``: (the option as given, the case
    #: file's own ``simulation.end_time``), so that messages about the end of the run name
    #: the option, not the case's key (:func:`thermodem.engine.case_warnings.end_time_text`)
    _shortened: tuple[str, float] | None = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _pairs_once(self, info: ValidationInfo) -> Case:
        # a pair named by two interactions entries: the last replaced the first whole, and
        # the first entry's coefficients were lost silently (a checkpoint's stored case is
        # read as an earlier version wrote it)
        from thermodem.state.materials import STORED_CASE_KEY

        if not (info.context and info.context.get(STORED_CASE_KEY)):
            self._check_interaction_pairs()
        return self

    @model_validator(mode="after")
    def _names(self) -> Case:
        if not self.materials:
            raise ValueError("materials: at least one material is needed")
        for name in self.materials:
            if name != name.strip() or not name:
                # ('glass ' is not 'glass': the walls and entries naming it were refused
                # with "unknown material 'glass'; allowed: glass ", the space unseen)
                raise ValueError(
                    f"materials.{name}: a material name with a space at its start or end, or "
                    f"empty (got {name!r}); allowed: a name without outer spaces, e.g. "
                    f"{name.strip() or 'glass'!r}"
                )
        if self.simulation.planar:
            from thermodem.config.planar_case import check_planar_case

            check_planar_case(self)  # 2D: in-plane vectors, walls as lines, models with a 2D form
        else:
            from thermodem.config.planar_case import check_not_planar

            check_not_planar(self)  # 3D: no 2D-only law
        known = set(self.materials)
        allowed = ", ".join(sorted(known))
        for k, w in enumerate(self.walls):
            if w.material not in known:
                raise ValueError(
                    f"walls.{k}.material: unknown material {w.material!r}; allowed: {allowed}"
                )
        self._check_wall_names()
        for k, e in enumerate(self.insertion):
            if e.material not in known:
                raise ValueError(
                    f"insertion.{k}.material: unknown material {e.material!r}; allowed: {allowed}"
                )
            self._check_region_in_domain(k, e)
        for k, o in enumerate(self.interactions):
            for m in o.materials:
                if m not in known:
                    raise ValueError(
                        f"interactions.{k}.materials: unknown material {m!r}; allowed: {allowed}"
                    )
        for k, entry in enumerate(self.external_force):
            m = entry.select.material
            if m is not None and m not in known:
                raise ValueError(
                    f"external_force.{k}.select.material: unknown material {m!r}; "
                    f"allowed: {allowed}"
                )
        th = self.thermal
        if th is not None:
            for key in ("fixed_temperature", "heat_flux", "volumetric_source"):
                for k, entry in enumerate(getattr(th, key)):
                    m = entry.select.material
                    if m is not None and m not in known:
                        raise ValueError(
                            f"thermal.{key}.{k}.select.material: unknown material {m!r}; "
                            f"allowed: {allowed}"
                        )
            self._check_thermal_selections(th)
            self._check_conductance_reuse(th)
            self._check_voronoi_reuse(th)
            self._probe_temperature_expressions(th)
            rule = th.initial_temperature
            if rule is not None and rule.kind == "per_material":
                for m in rule.values:
                    if m not in known:
                        raise ValueError(
                            f"thermal.initial_temperature.values: unknown material {m!r}; "
                            f"allowed: {allowed}"
                        )
        return self
