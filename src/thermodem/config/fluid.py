"""Case-file sections ``thermal.fluid`` and ``thermal.porosity``.

The fluid around the particles, read by the convection models and the radiation models that
need a fluid temperature (``thermal.fluid``), and the local porosity of each particle
(``thermal.porosity``), read by the correlations with a porosity, the Zhou (2009) radiation
and the porosity-based exposure. Example::

    thermal:
      convection: gunn1978
      fluid:
        temperature: 300.0              # K; or [[t, T], ...]; or "300 + 50 * z"; or a grid:
        # temperature: {file: flow.vti, field: T}
        velocity: [0.0, 0.0, 0.5]       # m/s; or [[t, ux, uy, uz], ...]; or three expressions
        properties: gas                 # thermal.gas; or {kind: liquid, ...}
      porosity: {kind: cell, cell_size: 0.006}

One-way coupling: the fluid temperature and velocity are imposed (an infinite reservoir, or a
field from a CFD result); the heat the particles exchange with the fluid does not change it.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import Field, field_validator

from thermodem.config.base import StrictModel

FORMS = {
    1: "a number, a table [[t, value], ...] of time (strictly increasing), an expression of "
    "t, x, y, z (a string), or a grid file {file: PATH, field: NAME}",
    3: "three numbers [ux, uy, uz], a table [[t, ux, uy, uz], ...] of time (strictly "
    "increasing), three expressions of t, x, y, z (strings), or a grid file "
    "{file: PATH, field: NAME or [NAME_X, NAME_Y, NAME_Z]}",
}
GRID_SUFFIXES = (".npz", ".csv", ".vti", ".vtr", ".vts", ".vtk")


class UniformSource(StrictModel):
    """The same value everywhere, at every time."""

    kind: Literal["uniform"] = "uniform"
    value: tuple[float, ...]


class TableSource(StrictModel):
    """Rows [t, value...], linear in time, held at the first / last row outside."""

    kind: Literal["table"] = "table"
    table: list[tuple[float, ...]]


class ExpressionSource(StrictModel):
    """One expression of t [s], x, y, z [m] per component (safe: see engine/expressions.py)."""

    kind: Literal["expression"] = "expression"
    expression: tuple[str, ...]


class GridSource(StrictModel):
    """A field on a regular (rectilinear) grid read from a file, interpolated trilinearly to
    the particle positions; outside the grid the value at the nearest boundary point holds.

    ``file``: ``.npz`` (arrays ``x``, ``y``, ``z``: the grid axes; the field of shape
    (nx, ny, nz) or (nx, ny, nz, 3)), ``.csv`` (columns x, y, z and the field's columns, one
    row per grid point in any order), a VTK XML image data ``.vti``, rectilinear grid ``.vtr``
    or structured grid ``.vts`` (its points must form a rectilinear lattice), or a legacy
    ``.vtk`` structured points / rectilinear / structured grid. Point data are taken at the
    points, cell data at the cell centres (``location: auto``: point data when the file has
    the field there, else cell data)."""

    kind: Literal["grid"] = "grid"
    file: str = Field(description="path of the grid file (relative: to the case file)")
    field: str | tuple[str, str, str] = Field(
        description="array name (a vector array for the velocity, or three scalar arrays)"
    )
    location: Literal["auto", "point", "cell"] = "auto"

    @field_validator("file")
    @classmethod
    def _suffix(cls, v: str) -> str:
        if not v.lower().endswith(GRID_SUFFIXES):
            raise ValueError(
                f"grid file {v!r}: unknown format; allowed: {', '.join(GRID_SUFFIXES)}"
            )
        return v


FluidSource = UniformSource | TableSource | ExpressionSource | GridSource


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def parse_source(value: Any, components: int, positive: bool) -> FluidSource:
    """A fluid field from its case-file form (see ``FORMS``), ValueError if none fits."""
    from thermodem.engine.expressions import compile_expression

    forms = FORMS[components]
    if isinstance(value, UniformSource | TableSource | ExpressionSource | GridSource):
        source = value
    elif isinstance(value, dict):
        kind = value.get("kind", "grid" if "file" in value else None)
        classes = {
            "uniform": UniformSource,
            "table": TableSource,
            "expression": ExpressionSource,
            "grid": GridSource,
        }
        if kind not in classes:
            raise ValueError(f"expected {forms}; got the mapping {value!r}")
        source = classes[kind](**{**value, "kind": kind})
    elif components == 1 and _is_number(value):
        source = UniformSource(value=(float(value),))
    elif components == 1 and isinstance(value, str):
        source = ExpressionSource(expression=(value,))
    elif isinstance(value, list | tuple) and value and all(isinstance(v, str) for v in value):
        source = ExpressionSource(expression=tuple(value))
    elif isinstance(value, list | tuple) and value and all(_is_number(v) for v in value):
        source = UniformSource(value=tuple(float(v) for v in value))
    elif (
        isinstance(value, list | tuple)
        and value
        and all(isinstance(r, list | tuple) and all(_is_number(x) for x in r) for r in value)
    ):
        source = TableSource(table=[tuple(float(x) for x in r) for r in value])
    else:
        raise ValueError(f"expected {forms}; got {value!r}")
    # the number of components and the values
    if isinstance(source, UniformSource):
        if len(source.value) != components:
            raise ValueError(f"expected {forms}; got {len(source.value)} numbers")
        _check_values(source.value, positive)
    elif isinstance(source, TableSource):
        for k, row in enumerate(source.table):
            if len(row) != components + 1:
                raise ValueError(
                    f"table row {k} has {len(row)} numbers, expected {components + 1} "
                    f"([t, {'value' if components == 1 else 'ux, uy, uz'}])"
                )
            _check_values(row[1:], positive, f"table row {k}: ")
        times = [row[0] for row in source.table]
        if any(b <= a for a, b in zip(times, times[1:], strict=False)):
            raise ValueError(f"table times must increase strictly, got {times}")
    elif isinstance(source, ExpressionSource):
        if len(source.expression) != components:
            raise ValueError(f"expected {forms}; got {len(source.expression)} expressions")
        for text in source.expression:
            compile_expression(text, ("t", "x", "y", "z"))
    elif isinstance(source, GridSource):
        if components == 1 and not isinstance(source.field, str):
            raise ValueError(f"field: one array name for a scalar field, got {source.field!r}")
    return source


def _check_values(values: tuple[float, ...], positive: bool, where: str = "") -> None:
    for v in values:
        if not math.isfinite(v) or (positive and not v > 0):
            what = "finite and > 0 [K]" if positive else "finite"
            raise ValueError(f"{where}values must be {what}, got {v!r}")


PropertyValue = float | list[tuple[float, float]]


class GasFluid(StrictModel):
    """The fluid is the case's interstitial gas, ``thermal.gas``: its k, c_p, μ and density
    (``thermal.gas.density``, or the ideal gas P M / (R T) of its pressure, temperature and
    molar mass), constant."""

    kind: Literal["gas"] = "gas"


class LiquidFluid(StrictModel):
    """A fluid given here: each property a constant or a table [[T, value], ...] of
    temperature (linear, held outside), evaluated at the fluid temperature at the particle
    (μ also at the particle temperature: μ_fs of Whitaker's correlation)."""

    kind: Literal["liquid"] = "liquid"
    thermal_conductivity: PropertyValue = Field(description="k_f [W/(m K)]")
    density: PropertyValue = Field(description="ρ_f [kg/m³]")
    specific_heat: PropertyValue = Field(description="c_f [J/(kg K)]")
    dynamic_viscosity: PropertyValue = Field(description="μ_f [Pa s]")
    thermal_expansion: float | None = Field(
        default=None,
        gt=0,
        description="β [1/K], for the Rayleigh number of Gunn's validity "
        "range (null: Ra is not checked)",
    )

    @field_validator("thermal_conductivity", "density", "specific_heat", "dynamic_viscosity")
    @classmethod
    def _positive(cls, v: PropertyValue) -> PropertyValue:
        if isinstance(v, list):
            if not v:
                raise ValueError("a table needs at least one row [T, value]")
            temps = [t for t, _ in v]
            if any(b <= a for a, b in zip(temps, temps[1:], strict=False)):
                raise ValueError(f"table temperatures must increase strictly, got {temps}")
            for t, value in v:
                if not (t > 0 and value > 0 and math.isfinite(value)):
                    raise ValueError(f"table rows need T > 0 and value > 0, got [{t}, {value}]")
        elif not (v > 0 and math.isfinite(v)):
            raise ValueError(f"must be > 0, got {v!r}")
        return v


FluidProperties = Annotated[GasFluid | LiquidFluid, Field(discriminator="kind")]


class FluidSettings(StrictModel):
    """The fluid around the particles (one-way coupling: imposed, never heated by them)."""

    temperature: Any = Field(description="T_f [K]: " + FORMS[1])
    velocity: Any = Field(
        default_factory=lambda: UniformSource(value=(0.0, 0.0, 0.0)),
        description="u_f [m/s]: " + FORMS[3],
    )
    properties: FluidProperties = Field(default_factory=GasFluid)

    @field_validator("temperature", mode="before")
    @classmethod
    def _temperature(cls, v: Any) -> FluidSource:
        return parse_source(v, 1, positive=True)

    @field_validator("velocity", mode="before")
    @classmethod
    def _velocity(cls, v: Any) -> FluidSource:
        return parse_source(v, 3, positive=False)

    @field_validator("properties", mode="before")
    @classmethod
    def _properties(cls, v: Any) -> Any:
        if v == "gas":
            return {"kind": "gas"}
        if isinstance(v, str):
            raise ValueError(f"expected 'gas' or {{kind: liquid, ...}}, got {v!r}")
        return v


class GlobalPorosity(StrictModel):
    """The same porosity for every particle."""

    kind: Literal["global"] = "global"
    value: float = Field(ge=0, le=1, description="ε [-]")


class CellPorosity(StrictModel):
    """Porosity of the grid cell holding the particle's centre, every thermal step: 1 − (the
    volume of the particles whose centre is in the cell) / (the cell's volume on the
    particles' side of the walls). The cells tile the domain."""

    kind: Literal["cell"] = "cell"
    cell_size: float | None = Field(
        default=None,
        gt=0,
        description="cell edge [m] (rounded to tile the domain); null: three largest diameters",
    )


class ShellPorosity(StrictModel):
    """Porosity of the sphere of radius ``radius_ratio`` × R_i around each particle, every
    thermal step: 1 − (the volume of the particle and of the parts of its neighbours inside
    the sphere) / (the sphere's volume on the particles' side of the walls)."""

    kind: Literal["shell"] = "shell"
    radius_ratio: float = Field(default=3.0, gt=1, description="shell radius / R_i [-]")


class VoronoiPorosity(StrictModel):
    """Porosity of the particle's Voronoi cell, 1 − V_i / V_cell (from the tessellation of
    the Voronoi conduction models, when present)."""

    kind: Literal["voronoi"] = "voronoi"


PorositySettings = Annotated[
    GlobalPorosity | CellPorosity | ShellPorosity | VoronoiPorosity,
    Field(discriminator="kind"),
]


def parse_porosity(v: Any) -> Any:
    """``porosity: 0.4`` is ``{kind: global, value: 0.4}``."""
    if _is_number(v):
        return {"kind": "global", "value": float(v)}
    return v
