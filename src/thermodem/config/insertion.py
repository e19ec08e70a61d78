"""Case-file section ``insertion``: where particles come from (SI units throughout).

The section is a list of entries, each selected by its ``kind``:

``lattice``
    A regular grid of sites filling an axis-aligned box, given by a spacing or a count per axis,
    optionally jittered.
``random_box`` / ``random_cylinder``
    Random sequential addition of non-overlapping spheres inside a box or a cylinder.
``pour``
    A continuous feed: batches of particles are inserted into a box or cylinder region at a fixed
    interval, at a given rate [particles/s], between a start and an end time.
``file``
    Positions and radii (optionally velocities and temperatures) read from a text/CSV file.
``list``
    Positions and radii (optionally velocities and temperatures) given in the case itself.

Every entry names a ``material`` (a key of the case's ``materials`` section) and, except ``file``
and ``list``, a radius ``distribution`` (selected by its own ``kind``: ``mono``, ``uniform``,
``truncated_normal``, ``lognormal`` or ``discrete``). Entries may also set an initial
``velocity`` [m/s] and ``temperature`` [K]; when ``temperature`` is omitted the engine applies
its default initial temperature.

The radius distributions are :mod:`thermodem.config.radius_distributions`; the algorithms live
in :mod:`thermodem.geometry.insertion`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    Field,
    PositiveInt,
    TypeAdapter,
    ValidationInfo,
    field_validator,
    model_validator,
)

from thermodem.config.base import StrictModel
from thermodem.config.planar import Vec3, box_axes, is_planar
from thermodem.config.radius_distributions import (  # noqa: F401 (re-exported)
    FRACTION_SUM_TOLERANCE,
    DiscreteRadius,
    LognormalRadius,
    MonoRadius,
    PositiveLength,
    RadiusDistribution,
    TruncatedNormalRadius,
    UniformRadius,
)

# Vec3: three finite floats (a point or a vector) [m] or [m/s]; [x, y] in a 2D case

_AXES = ("x", "y", "z")


def _check_box(lower: Vec3, upper: Vec3, what: str = "region", axes: str = "xyz") -> None:
    """Raise ValueError unless ``lower < upper`` on every axis of ``axes`` (2D: "xy")."""
    for axis, lo, hi in zip(_AXES, lower, upper, strict=True):
        if axis in axes and not lo < hi:
            raise ValueError(
                f"{what}: lower corner must be < upper corner on every axis, but on the "
                f"{axis} axis lower={lo!r} and upper={hi!r}"
            )


def _normalise_axis(value: Vec3) -> Vec3:
    """Return ``value`` scaled to unit length; a zero vector is an error."""
    norm = math.sqrt(sum(c * c for c in value))
    if not norm > 1e-300:
        raise ValueError(f"axis must be a non-zero vector, got {tuple(value)!r}")
    return (value[0] / norm, value[1] / norm, value[2] / norm)


# --------------------------------------------------------------------------------------------
# Regions (used by ``pour``)
# --------------------------------------------------------------------------------------------


class BoxRegion(StrictModel):
    """Axis-aligned box between ``lower`` and ``upper`` corners [m]."""

    kind: Literal["box"] = "box"
    lower: Vec3 = Field(description="lower corner (x, y, z) [m]")
    upper: Vec3 = Field(description="upper corner (x, y, z) [m]")

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> BoxRegion:
        _check_box(self.lower, self.upper, "box region", box_axes(info))
        return self


class CylinderRegion(StrictModel):
    """Solid cylinder from ``base_centre`` along the unit ``axis`` over ``length`` [m].

    ``axis`` is normalised on validation (it must be non-zero).
    """

    kind: Literal["cylinder"] = "cylinder"
    base_centre: Vec3 = Field(description="centre of the base disc [m]")
    axis: Vec3 = Field(description="direction from the base to the top (normalised) [-]")
    radius: PositiveLength = Field(description="cylinder radius [m]")
    length: PositiveLength = Field(description="cylinder length along the axis [m]")

    @field_validator("axis")
    @classmethod
    def _unit_axis(cls, value: Vec3) -> Vec3:
        return _normalise_axis(value)


Region = Annotated[BoxRegion | CylinderRegion, Field(discriminator="kind")]
"""A box or cylinder region, selected by ``kind``."""


# --------------------------------------------------------------------------------------------
# Insertion entries
# --------------------------------------------------------------------------------------------


class _EntryBase(StrictModel):
    """Fields shared by every insertion entry."""

    material: str = Field(min_length=1, description="name of a material in 'materials'")
    velocity: Vec3 = Field(default=(0.0, 0.0, 0.0), description="initial velocity [m/s]")
    temperature: float | None = Field(
        default=None,
        gt=0,
        allow_inf_nan=False,
        description="initial temperature [K]; None: the engine's default initial temperature",
    )


class LatticeInsertion(_EntryBase):
    """A regular lattice of sites filling the box ``[lower, upper]``.

    Give exactly one of ``spacing`` (centre-to-centre distance, one value or one per axis) or
    ``count`` (number of sites per axis). Sites keep a margin of ``r_max + jitter`` from every
    face, where ``r_max`` is the distribution's largest radius, so every particle lies fully in
    the box; with ``spacing`` the lattice is centred in the box. ``jitter`` displaces each site
    by a uniform random amount in ``[-jitter, jitter]`` per axis; the spacing must be at least
    ``2 (r_max + jitter)`` so that no two particles overlap. Sites that would overlap an
    existing particle are skipped.
    """

    kind: Literal["lattice"] = "lattice"
    distribution: RadiusDistribution
    lower: Vec3 = Field(description="lower corner of the box (x, y, z) [m]")
    upper: Vec3 = Field(description="upper corner of the box (x, y, z) [m]")
    spacing: PositiveLength | tuple[PositiveLength, PositiveLength, PositiveLength] | None = Field(
        default=None, description="site spacing, one value or one per axis [m]"
    )
    count: tuple[PositiveInt, PositiveInt, PositiveInt] | None = Field(
        default=None, description="number of sites along x, y and z (2D: [nx, ny])"
    )
    jitter: float = Field(
        default=0.0, ge=0, allow_inf_nan=False, description="maximum random displacement [m]"
    )

    @field_validator("count", "spacing", mode="before")
    @classmethod
    def _per_axis_2d(cls, value: Any, info: ValidationInfo) -> Any:
        """2D: ``[nx, ny]`` is one layer (z count 1); ``[sx, sy]`` gets an unused z spacing."""
        if is_planar(info) and isinstance(value, list | tuple) and len(value) == 2:
            return (value[0], value[1], 1 if info.field_name == "count" else value[0])
        return value

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> LatticeInsertion:
        axes = box_axes(info)  # 2D: one layer of sites at z = 0, the z extent is not used
        _check_box(self.lower, self.upper, "lattice insertion", axes)
        if (self.spacing is None) == (self.count is None):
            raise ValueError(
                "lattice insertion: give exactly one of 'spacing' or 'count', got "
                f"spacing={self.spacing!r} and count={self.count!r}"
            )
        r_max = self.distribution.max_radius_bound
        if r_max is None:
            raise ValueError(
                "lattice insertion needs a bounded radius distribution: set max_radius on the "
                f"{self.distribution.kind} distribution"
            )
        margin = r_max + self.jitter
        for a, axis in enumerate(_AXES):
            if axis not in axes:
                continue
            extent = self.upper[a] - self.lower[a]
            if extent < 2.0 * margin:
                raise ValueError(
                    f"lattice insertion: the box is {extent!r} m wide along {axis}, smaller than "
                    f"2 (r_max + jitter) = {2.0 * margin!r} m; enlarge the box or reduce the "
                    "radius or jitter"
                )
            spacing = self.axis_spacing(a)
            if spacing is not None and spacing < 2.0 * margin * (1.0 - 1e-12):
                raise ValueError(
                    f"lattice insertion: spacing along {axis} is {spacing!r} m but must be at "
                    f"least 2 (r_max + jitter) = {2.0 * margin!r} m so particles do not overlap; "
                    "increase the spacing, reduce count, or reduce the radius or jitter"
                )
        return self

    @property
    def region(self) -> BoxRegion:
        """The lattice box as a :class:`BoxRegion` (validated with the entry)."""
        return BoxRegion.model_construct(lower=self.lower, upper=self.upper)

    def axis_spacing(self, axis: int) -> float | None:
        """Site spacing along ``axis`` (0, 1, 2) [m]; None if there is a single site on it."""
        if self.spacing is not None:
            return float(self.spacing if isinstance(self.spacing, float) else self.spacing[axis])
        assert self.count is not None
        n = self.count[axis]
        if n == 1:
            return None
        r_max = self.distribution.max_radius_bound
        assert r_max is not None
        span = self.upper[axis] - self.lower[axis] - 2.0 * (r_max + self.jitter)
        return span / (n - 1)


class RandomBoxInsertion(_EntryBase):
    """Random sequential addition of non-overlapping spheres inside the box ``[lower, upper]``.

    Give exactly one of ``count`` or ``volume_fraction`` (radii are drawn until the summed sphere
    volume reaches ``volume_fraction`` times the box volume). Random sequential addition of
    equal spheres jams near a volume fraction of 0.38 (less near walls); denser packings need a
    compaction stage. ``max_attempts`` is the number of candidate positions tried for one
    particle before the insertion fails.
    """

    kind: Literal["random_box"] = "random_box"
    distribution: RadiusDistribution
    lower: Vec3 = Field(description="lower corner of the box (x, y, z) [m]")
    upper: Vec3 = Field(description="upper corner of the box (x, y, z) [m]")
    count: PositiveInt | None = Field(default=None, description="number of particles")
    volume_fraction: float | None = Field(
        default=None, gt=0, lt=0.74, description="solid volume fraction of the box [-]"
    )
    max_attempts: PositiveInt = Field(
        default=1000, description="candidate positions tried per particle before giving up"
    )

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> RandomBoxInsertion:
        _check_box(self.lower, self.upper, "random_box insertion", box_axes(info))
        if (self.count is None) == (self.volume_fraction is None):
            raise ValueError(
                "random_box insertion: give exactly one of 'count' or 'volume_fraction', got "
                f"count={self.count!r} and volume_fraction={self.volume_fraction!r}"
            )
        return self

    @property
    def region(self) -> BoxRegion:
        """The box as a :class:`BoxRegion` (validated with the entry)."""
        return BoxRegion.model_construct(lower=self.lower, upper=self.upper)


class RandomCylinderInsertion(_EntryBase):
    """Random sequential addition of ``count`` non-overlapping spheres inside a cylinder.

    The cylinder starts at ``base_centre`` and extends ``length`` along the unit ``axis``
    (normalised on validation).
    """

    kind: Literal["random_cylinder"] = "random_cylinder"
    distribution: RadiusDistribution
    base_centre: Vec3 = Field(description="centre of the base disc [m]")
    axis: Vec3 = Field(description="direction from the base to the top (normalised) [-]")
    radius: PositiveLength = Field(description="cylinder radius [m]")
    length: PositiveLength = Field(description="cylinder length along the axis [m]")
    count: PositiveInt = Field(description="number of particles")
    max_attempts: PositiveInt = Field(
        default=1000, description="candidate positions tried per particle before giving up"
    )

    @field_validator("axis")
    @classmethod
    def _unit_axis(cls, value: Vec3) -> Vec3:
        return _normalise_axis(value)

    @property
    def region(self) -> CylinderRegion:
        """The cylinder as a :class:`CylinderRegion`."""
        return CylinderRegion.model_construct(
            base_centre=self.base_centre, axis=self.axis, radius=self.radius, length=self.length
        )


class PourInsertion(_EntryBase):
    """A continuous feed of particles into a box or cylinder ``region``.

    From ``start_time`` to ``end_time`` (None: until the run ends), every ``interval`` seconds a
    batch is inserted containing the particles due since the previous batch, so that after time
    ``t`` a total of ``floor(rate (t - start_time))`` particles has been requested. Each batch is
    placed by random sequential addition without overlapping particles already in the region or
    each other; particles that cannot be placed in ``max_attempts`` tries are skipped with a
    warning (they are not carried over to the next batch). A batch tries at most as many
    particles as would fill half the region (more cannot be placed at random); the rest of it
    is skipped at once, so the work of a batch is bounded whatever the rate.
    """

    kind: Literal["pour"] = "pour"
    distribution: RadiusDistribution
    region: Region
    rate: float = Field(gt=0, allow_inf_nan=False, description="particles per second [1/s]")
    start_time: float = Field(default=0.0, ge=0, allow_inf_nan=False, description="[s]")
    end_time: float | None = Field(default=None, allow_inf_nan=False, description="[s]")
    interval: float = Field(gt=0, allow_inf_nan=False, description="time between batches [s]")
    max_attempts: PositiveInt = Field(
        default=200, description="candidate positions tried per particle before skipping it"
    )

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> PourInsertion:
        if self.end_time is not None and not self.end_time > self.start_time:
            raise ValueError(
                f"pour insertion: end_time={self.end_time!r} must be > "
                f"start_time={self.start_time!r} (or omitted to pour until the end of the run)"
            )
        self._check_region_fits(box_axes(info))
        return self

    def _check_region_fits(self, axes: str) -> None:
        """The largest particle fits in the region (else the first batch would fail in the
        middle of the run)."""
        r_max = self.distribution.max_radius_bound
        if r_max is None:
            dist = self.distribution
            median = math.exp(dist.mu)
            cut = median * math.exp(3.0 * dist.sigma)
            raise ValueError(
                f"distribution.max_radius: missing; a pour needs a largest radius, but the "
                f"{dist.kind} distribution (median {median:.6g} m, sigma {dist.sigma:g}) is "
                "unbounded, so a batch could draw a particle larger than the region in the "
                "middle of the run. Set max_radius, the cut-off of the distribution (as DEM codes "
                f"cut size distributions off), e.g. max_radius: {cut:.3g} (the median × "
                "e^(3 sigma): 99.87 % of an uncut distribution lies below it); min_radius "
                "optional"
            )
        region = self.region
        if region.kind == "box":
            for a, axis in enumerate(_AXES):
                extent = region.upper[a] - region.lower[a]
                if axis in axes and extent < 2.0 * r_max:
                    raise ValueError(
                        f"region: the box is {extent:.6g} m wide along {axis}, smaller than the "
                        f"diameter 2 r_max = {2.0 * r_max:.6g} m of the largest particle, so no "
                        "particle can be poured; enlarge the region or use smaller radii"
                    )
            return
        planar = axes == "xy"  # a circle in the plane: its length is not used
        if region.radius < r_max or (not planar and region.length < 2.0 * r_max):
            raise ValueError(
                f"region: a particle of radius r_max = {r_max:.6g} m does not fit in the "
                f"cylinder of radius {region.radius:.6g} m and length {region.length:.6g} m, so "
                "no particle can be poured; enlarge the region or use smaller radii"
            )


class FileInsertion(_EntryBase):
    """Particles read from a whitespace- or comma-separated text file.

    The first non-blank line is a header naming the columns (a leading ``#`` is allowed):
    ``x y z radius`` are required; ``vx vy vz`` (all three) and ``temperature`` are optional
    and override the entry's ``velocity``/``temperature``. Later lines starting with ``#`` are
    comments; aliases (``r`` for ``radius``, ...) and header comments are described in
    :func:`thermodem.io.particle_file.load_particle_file`. A relative ``path`` is resolved by
    the caller (normally against the case file's directory). Positions are checked when the
    particles are inserted: every centre inside the domain, no two particles coincident or
    overlapping by more than ``simulation.max_overlap_ratio`` of the smaller radius.
    """

    kind: Literal["file"] = "file"
    path: Path = Field(description="path of the particle file")
    overlap_check: bool = Field(
        default=True,
        description="false: given particles may overlap deeply (the run still stops at its "
        "first step when an overlap exceeds simulation.max_overlap_ratio); coincident "
        "particles and centres outside the domain are refused regardless",
    )

    @field_validator("path", mode="before")
    @classmethod
    def _given_path(cls, v: Any) -> Any:
        # '' was read as '.', the case's directory ("... is a directory"); '~/beds/bed.txt'
        # was joined to the case's directory ('/case/dir/~/beds/...': "does not exist")
        if isinstance(v, str):
            if not v.strip():
                raise ValueError(
                    f"an empty path (got {v!r}); allowed: the path of a particle file, "
                    "absolute or relative to the case file's directory"
                )
            if v.startswith("~"):
                return str(Path(v).expanduser())
        return v


PositiveTemperature = Annotated[float, Field(gt=0, allow_inf_nan=False)]
"""A strictly positive, finite temperature [K]."""


class ListInsertion(_EntryBase):
    """Particles given one by one in the case (the 1-, 2- and 10-particle cases).

    ``positions`` are the centres [m]; give ``radius`` (one for all) or ``radii`` (one per
    position). ``velocities`` [m/s] and ``temperatures`` [K] optionally give one value per
    position; without them the entry's ``velocity``/``temperature`` apply to all. Like a
    particle file, the positions are checked when the particles are inserted: every centre
    inside the domain, no two particles coincident or overlapping by more than
    ``simulation.max_overlap_ratio`` of the smaller radius (nor with particles of earlier
    entries).
    """

    kind: Literal["list"] = "list"
    positions: list[Vec3] = Field(min_length=1, description="particle centres [m]")
    radius: PositiveLength | None = Field(default=None, description="radius of every particle")
    radii: list[PositiveLength] | None = Field(default=None, description="one radius each [m]")
    velocities: list[Vec3] | None = Field(default=None, description="one velocity each [m/s]")
    temperatures: list[PositiveTemperature] | None = Field(
        default=None, description="one temperature each [K]"
    )
    overlap_check: bool = Field(
        default=True,
        description="false: given particles may overlap deeply (the run still stops at its "
        "first step when an overlap exceeds simulation.max_overlap_ratio); coincident "
        "particles and centres outside the domain are refused regardless",
    )

    @field_validator("positions", "velocities", mode="before")
    @classmethod
    def _flat_numbers(cls, value: Any) -> Any:
        """A flat list of numbers where vectors are expected (``positions: [x, y, z]``, one
        particle without its outer brackets, or several particles in one list) gave one
        message per number; one message, with the vectors it meant."""
        numbers = (
            isinstance(value, list)
            and len(value) >= 2
            and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
        )
        if numbers and len(value) <= 3:
            raise ValueError(
                f"a list of vectors, one [x, y, z] per particle; got the numbers {value}: for "
                f"one particle write [{value}]"
            )
        if numbers:  # (several particles written as one flat list: one message per number)
            size = 3 if len(value) % 3 == 0 else 2 if len(value) % 2 == 0 else 3
            rows = [value[k : k + size] for k in range(0, len(value), size)]
            shown = ", ".join(str(r) for r in rows[:3]) + (", ..." if len(rows) > 3 else "")
            raise ValueError(
                f"a list of vectors, one [x, y, z] per particle; got {len(value)} numbers in one "
                f"flat list (got {value[:6]}{' ...' if len(value) > 6 else ''}): write one "
                f"bracketed vector per particle, e.g. [{shown}]"
            )
        return value

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> ListInsertion:
        from thermodem.state.materials import STORED_CASE_KEY

        # a checkpoint's stored case holds every key, the unused default 'velocity' too
        stored = bool(info.context and info.context.get(STORED_CASE_KEY))
        n = len(self.positions)
        if (self.radius is None) == (self.radii is None):
            raise ValueError(
                "radius: give exactly one of 'radius' (one for every particle) or 'radii' "
                f"(one per position), got radius={self.radius!r} and radii={self.radii!r}"
            )
        for key in ("radii", "velocities", "temperatures"):
            values = getattr(self, key)
            if values is not None and len(values) != n:
                raise ValueError(
                    f"{key}: {len(values)} value(s) for {n} position(s); give one per position"
                )
        if self.velocities is not None and "velocity" in self.model_fields_set and not stored:
            raise ValueError(
                "velocities: give 'velocity' (one for all) or 'velocities' (one per position), "
                "not both"
            )
        if self.temperatures is not None and self.temperature is not None:
            raise ValueError(
                "temperatures: give 'temperature' (one for all) or 'temperatures' (one per "
                "position), not both"
            )
        return self

    def radius_array(self) -> np.ndarray:
        """(n,) radii [m]."""
        if self.radii is not None:
            return np.asarray(self.radii, dtype=np.float64)
        return np.full(len(self.positions), float(self.radius or 0.0))


InsertionEntry = Annotated[
    LatticeInsertion
    | RandomBoxInsertion
    | RandomCylinderInsertion
    | PourInsertion
    | FileInsertion
    | ListInsertion,
    Field(discriminator="kind"),
]
"""One entry of the ``insertion`` section, selected by ``kind``."""

InsertionSection = list[InsertionEntry]
"""The ``insertion`` section: a list of entries."""

_SECTION_ADAPTER: TypeAdapter[list[Any]] = TypeAdapter(InsertionSection)


def parse_insertion_section(data: Any) -> list[Any]:
    """Validate the raw ``insertion`` section (a list of mappings) into entry models."""
    return _SECTION_ADAPTER.validate_python(data)


__all__ = [
    "BoxRegion",
    "CylinderRegion",
    "DiscreteRadius",
    "FileInsertion",
    "InsertionEntry",
    "InsertionSection",
    "LatticeInsertion",
    "ListInsertion",
    "LognormalRadius",
    "MonoRadius",
    "PourInsertion",
    "RadiusDistribution",
    "RandomBoxInsertion",
    "RandomCylinderInsertion",
    "Region",
    "TruncatedNormalRadius",
    "UniformRadius",
    "parse_insertion_section",
    "Vec3",
]
