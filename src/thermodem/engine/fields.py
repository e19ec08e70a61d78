"""Per-particle fields: the fluid at each particle, the local porosity, the neighbourhood.

The per-particle heat terms (convection, radiation) read a field array ``fields``
(``NFIELDS``, n: a row per field) whose rows are defined in ``kernels/fields.py``.
:class:`FieldProvider` fills the rows the case's terms need, at every thermal step, before
those terms run
(``ThermalEngine.evaluate_terms``):

- **fluid temperature** T_f and **velocity** u_f (``thermal.fluid``): uniform, a table of
  time, an expression of (t, x, y, z), or a grid file interpolated trilinearly to the
  particles (``io/grid_field.py``); the relative speed |u_f − v_p|;
- **fluid properties** k_f, ρ_f, c_f, μ_f at T_f and μ_fs at the particle temperature, Pr and
  Pr^⅓: from ``thermal.gas`` (constant) or a liquid with temperature tables;
- **local porosity** (``thermal.porosity``): global value, cell count, shell count, or a
  provider registered for ``voronoi`` (:data:`POROSITY_PROVIDERS`, the hook of the Voronoi
  tessellation);
- **neighbourhood sums** of the continuum radiation models (particles whose centre lies in the
  sphere of radiative influence) and the shell porosity, over a range pair set of their own
  (``engine/range_set.py``: slab groups, rebuilt lazily, saved in checkpoints);
- **walls in view** of the particle–wall radiation.

The fluid rows (T_f, u_f, |u_f − v_p|, the fluid properties) are filled by the methods of
its mixin :class:`~thermodem.engine.fluid_sources.FluidSources` (``engine/fluid_sources.py``).

It also evaluates the convection correlation's dimensionless numbers and warns once (a
``RuntimeWarning``, logged by the runner) when a run leaves the correlation's validity range,
naming the particle, the value, the range, the step and the time.

The fluid is one-way coupled: the heat the particles exchange does not change it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from thermodem.config.fluid import (
    CellPorosity,
    GlobalPorosity,
    ShellPorosity,
    VoronoiPorosity,
)
from thermodem.engine.fluid_sources import FluidSources
from thermodem.engine.neighbourhood_fields import NeighbourhoodFields
from thermodem.engine.range_set import RangePairSet
from thermodem.errors import ConfigError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import fields as fk
from thermodem.kernels import neighbourhood as nh
from thermodem.kernels import porosity as pk
from thermodem.models.thermal import convection as conv
from thermodem.models.thermal import radiation as rad

if TYPE_CHECKING:
    from thermodem.config.thermal import ThermalSettings
    from thermodem.engine.simulation import Simulation
    from thermodem.engine.terms import HeatTerm

#: Prefix of the neighbourhood set's arrays in the engine's checkpoint.
STATE_PREFIX = "fields__"
#: Arrays of the neighbour listing of the continuum radiation models in checkpoints.
MEMBER_ARRAYS = ("members_offsets", "members_border", "members_index")
#: The correlation validity ranges are checked at every this many-th field update.
RANGE_CHECK_INTERVAL = 10


class PorosityProvider(Protocol):
    """Fills ``fields[F_POROSITY]`` for the current particles (the Voronoi hook)."""

    def update(self, sim: Simulation, fields: np.ndarray) -> None: ...


#: Porosity providers by ``thermal.porosity.kind`` registered from outside (the Voronoi
#: tessellation registers ``voronoi``: a factory (sim, settings) -> PorosityProvider).
POROSITY_PROVIDERS: dict[str, Callable[[Simulation, Any], PorosityProvider]] = {}


class FieldProvider(FluidSources, NeighbourhoodFields):
    """Fills the per-particle field columns the terms need (see the module docstring)."""

    def __init__(self, sim: Simulation, settings: ThermalSettings, terms: list[HeatTerm]) -> None:
        self.sim = sim
        self.settings = settings
        self.fluid = settings.fluid
        self.convection = next((t for t in terms if t.key == "thermal.convection"), None)
        self.radiation = next((t for t in terms if t.key == "thermal.radiation"), None)
        self.active = self.convection is not None or self.radiation is not None
        self.needs_temperature = self.needs_velocity = self.needs_properties = False
        self.needs_porosity = False
        self.radiation_ratio = 0.0
        self.walls: rad.WallRadiation | None = None
        users: dict[str, list[str]] = {"fluid": [], "porosity": []}
        if self.convection is not None:
            name = self.convection.choice.model
            who = f"thermal.convection = {name!r}"
            self.needs_temperature = self.needs_properties = True
            self.needs_velocity = name != "stagnant"
            users["fluid"].append(who)
            params = self.convection.params
            if name in conv.USES_POROSITY or getattr(params, "reynolds_velocity", "") == (
                "superficial"
            ):
                self.needs_porosity = True
                users["porosity"].append(who)
        if self.radiation is not None:
            name = self.radiation.choice.model
            params = self.radiation.params
            who = f"thermal.radiation = {name!r}"
            if name == "surroundings" and params.exposure != "all":
                self.needs_porosity = True
                users["porosity"].append(f"{who} (exposure: {params.exposure})")
            if name == "zhou2009":
                self.needs_temperature = True
                self.needs_porosity = True
                users["fluid"].append(who)
                users["porosity"].append(who)
            if name in rad.NEIGHBOURHOOD_MODELS:
                self.radiation_ratio = float(params.radius_ratio)
            if params.walls:
                self.walls = params
        # a Voronoi model with the porosity closure (Zhou et al. 2009) reads ε of each particle
        self.closure = next(
            (t for t in terms
             if t.target == "external" and getattr(t.params, "geometry", "") == "porosity"),
            None,
        )  # fmt: skip
        if self.closure is not None:
            self.active = True
            self.needs_porosity = True
            users["porosity"].append(
                f"{self.closure.key} = {self.closure.choice.model!r} (geometry: porosity)"
            )
        if users["fluid"] and self.fluid is None:
            raise ConfigError(
                f"thermal.fluid: missing; required by {', '.join(users['fluid'])} (the fluid "
                "temperature, velocity and properties), e.g. fluid: {temperature: 300.0, "
                "velocity: [0.0, 0.0, 0.5]}"
            )
        self.porosity = settings.porosity
        if users["porosity"] and self.porosity is None:
            raise ConfigError(
                f"thermal.porosity: missing; required by {', '.join(users['porosity'])} (the "
                "local porosity), e.g. porosity: {kind: cell} or {kind: shell, radius_ratio: "
                "3.0} or {kind: global, value: 0.4}"
            )
        for key, given, used in (("fluid", self.fluid, users["fluid"]),
                                 ("porosity", self.porosity, users["porosity"])):  # fmt: skip
            if given is not None and not used:
                warnings.warn(
                    f"thermal.{key} is given but no selected model reads it (thermal.convection "
                    f"= {settings.convection.model!r}, thermal.radiation = "
                    f"{settings.radiation.model!r}): it has no effect",
                    RuntimeWarning,
                    stacklevel=2,
                )
        if not self.needs_porosity:
            self.porosity = None
        self.shell_ratio = (
            float(self.porosity.radius_ratio) if isinstance(self.porosity, ShellPorosity) else 0.0
        )
        self.external_porosity: PorosityProvider | None = None
        tessellated = isinstance(self.porosity, VoronoiPorosity) or any(
            t.target == "external" and getattr(t.params, "geometry", "") == "tessellation"
            for t in terms
        )
        if settings.tessellation is not None and not tessellated:
            # (as the fluid and porosity above: a Voronoi model switched off, its settings kept)
            warnings.warn(
                "thermal.tessellation is given but nothing tessellates (thermal."
                f"indirect_conduction = {settings.indirect_conduction.model!r}; the Voronoi "
                "models voronoi_a / voronoi_b with geometry: tessellation and porosity: {kind: "
                "voronoi} read it): it has no effect",
                RuntimeWarning,
                stacklevel=2,
            )
        if isinstance(self.porosity, VoronoiPorosity):
            factory = POROSITY_PROVIDERS.get("voronoi")
            if factory is None:
                raise ConfigError(
                    "thermal.porosity.kind = 'voronoi': needs the Voronoi tessellation "
                    "(thermodem.engine.voronoi), which is not loaded; use kind cell, shell or "
                    "global"
                )
            self.external_porosity = factory(sim, self.porosity)
        # the fluid
        self._sources: dict[str, Any] = {}
        if self.needs_temperature:
            self._sources["temperature"] = self._source(self.fluid.temperature, "temperature", 1)
        if self.needs_velocity:
            self._sources["velocity"] = self._source(self.fluid.velocity, "velocity", 3)
        self._constant_properties: dict[int, float] = {}
        self._property_tables: list[tuple[int, np.ndarray, np.ndarray, bool]] = []
        self.beta_mode, self.beta = 0, 0.0
        if self.needs_properties:
            self._properties_setup()
        # neighbourhood (continuum radiation, shell porosity)
        self.neighbourhood = (
            RangePairSet(settings.range_skin)
            if self.radiation_ratio > 0.0 or self.shell_ratio > 0.0
            else None
        )
        if self.neighbourhood is not None:
            # before the run: the largest particles the insertions can bring (pours too)
            bounds = [
                getattr(getattr(e, "distribution", None), "max_radius_bound", None)
                for e in sim.case.insertion
            ]
            self.check_neighbourhood_range(max([float(b) for b in bounds if b] + [0.0]))
        self.emissivity = (
            np.ascontiguousarray(self.radiation.table[:, 0], np.float64)
            if self.radiation is not None and self.radiation.table.ndim == 2
            else np.zeros(1)
        )
        self.lattice = pk.unit_ball_points()
        self.sums = np.zeros((0, 4))
        # the continuum radiation's neighbours of each particle (kernels/neighbourhood.py):
        # listed from range-set build ``members_builds`` at the positions
        # ``members_reference``, valid while no particle moved more than members_band / 2
        self.members = nh.empty_members(0)
        self.member_sums = tuple(np.zeros(0) for _ in range(4))
        self.radiation_mode = 0
        if self.radiation is not None and self.radiation.choice.model == "krause2017":
            self.radiation_mode = nh.NB_KRAUSE
        elif self.radiation is not None and self.radiation.choice.model == "zhou2009":
            self.radiation_mode = nh.NB_ZHOU
        self.members_builds = -1
        self.members_reference = np.zeros((0, 3))
        self.members_offset = 0.0
        self.members_band = 0.0
        self.members_listings = 0
        # the classes of the listing's border entries (inside, outside, tested at every
        # step; kernels/neighbourhood.py: border_classes, border_lists): (weights, listed
        # rows, entries, chunk starts, tested rows, entries, count), valid while no particle
        # moved more than border_band / BORDER_MARGIN since the classification
        empty = np.zeros(0, np.int64)
        self.border_weights = (np.zeros(0, np.int8), empty, empty, np.zeros(2, np.int64),
                               empty, empty, 0)  # fmt: skip
        self.border_band = 0.0
        self.border_offset = 0.0
        self.border_reference = np.zeros((0, 3))  # the positions at the classification
        self.border_owned = -1  # the rows classified (owned particles)
        self.border_listing_moved = 0.0  # the displacement since the listing at it
        self.border_listing = -1
        self.border_classifications = 0
        self.border_tested = 0  # TESTED entries summed over the classifications
        self.scratch = np.zeros((1, 4))
        # cell porosity (the grid is set up at the first evaluation: its default size)
        self.cell_size = 0.0
        self.cell_dims = np.ones(3, np.int64)
        self.cell_edge = np.ones(3)
        self.cell_fluid = np.zeros(0)
        self.cell_solid = np.zeros(0)
        self.cell_of = np.zeros(0, np.int64)
        #: cell_of and the porosity column of ``_porosity_for`` hold for the current cells
        self.cells_valid = False
        self._porosity_for: np.ndarray | None = None
        self._cell_walls = np.zeros((0, wall_cols.WALL_WIDTH))
        # validity ranges of the convection correlation
        self.ranges: list[tuple[str, float, float]] = []
        if self.convection is not None:
            self.ranges = list(conv.VALIDITY[self.convection.choice.model])
            if self.beta_mode == 0:
                self.ranges = [r for r in self.ranges if r[0] != "Ra"]
        self.warned: list[str] = []
        self.updates = 0  # field updates so far (the range checks run on every 10th)
        self.numbers_buffer = np.zeros((0, len(conv.NUMBER_NAMES)))
        self.velocity_buffer = np.zeros((3, 1))  # u_f: (3, n), or (3, 1) if uniform
        self.part = np.zeros(1)
        self._constants_for: np.ndarray | None = None

    # ---------------------------------------------------------------------- set-up
    def _constant_columns(self) -> dict[int, float]:
        """Columns that are the same for every particle at every step."""
        out = dict(self._constant_properties)
        if isinstance(self.porosity, GlobalPorosity):
            out[fk.F_POROSITY] = float(self.porosity.value)
        source = self._sources.get("temperature")
        if source is not None and source[0] == "uniform":
            out[fk.F_FLUID_TEMPERATURE] = float(source[1][0])
        return out

    # ---------------------------------------------------------------------- update
    def invalidate(self) -> None:
        """The particles were reordered or inserted (the neighbourhood set and the cells of
        the cell porosity hold indices)."""
        self.cells_valid = False
        if self.neighbourhood is not None:
            self.neighbourhood.invalidate()

    def update(self, time: float, fields: np.ndarray) -> None:
        """Fill the columns the terms need for the current state at ``time``, for the
        particles this process owns (all of them; on several MPI ranks the first
        ``owned_count``, not the ghosts: ``fields`` has a column per owned particle)."""
        sim = self.sim
        p = sim.particles
        if not self.active or (p.count == 0 and getattr(sim, "comm", None) is None):
            # (on several MPI ranks a rank without particles still takes part in the
            # agreements of the warnings and failures below: they are collective)
            return
        n = sim.owned_count
        if fields is not self._constants_for:  # a new array: its constant columns
            for col, value in self._constant_columns().items():
                fk.fill_column(fields, col, value)
            self._constants_for = fields
        if self.needs_temperature:
            self._temperature(time, fields)
        for col, nodes, values, at_particle in self._property_tables:
            fk.table_column(fields, col, nodes, values, at_particle, p.temperature[:n])
        if self._property_tables:
            fk.prandtl_columns(fields)
        if self.needs_velocity:
            self._velocity(time, fields)
        if self.neighbourhood is not None:
            self._neighbourhood(fields)
        if isinstance(self.porosity, CellPorosity):
            self._cell_porosity(fields)
        elif self.external_porosity is not None:
            self.external_porosity.update(sim, fields)
        if self.walls is not None:
            fk.wall_view(p.position[:n], p.radius[:n], sim.wall_kind, sim.wall_rows,
                         float(self.walls.wall_range), float(self.walls.wall_view_factor),
                         fields)  # fmt: skip
        if self.ranges and len(self.warned) < len(self.ranges):
            # Re, Pr, ε against the correlation's ranges: at the first update and every
            # RANGE_CHECK_INTERVAL-th one after it (a full pass of its own; an excursion
            # shorter than that between two checks goes unreported)
            if self.updates % RANGE_CHECK_INTERVAL == 0:
                self._check_ranges(time, fields)
        self.updates += 1

    def _chunks(self) -> int:
        return self.sim.particles.count // fk.CHUNK + 1

    def _part(self) -> np.ndarray:
        rows = self._chunks()
        if self.part.shape[0] < rows:
            self.part = np.zeros(rows)
        return self.part

    # --------------------------------------------------------------- validity ranges
    def numbers(self, fields: np.ndarray, nusselt: bool = True) -> dict[str, np.ndarray]:
        """Re, Pr, Nu, μ_f/μ_fs, ε and Ra of every particle at the last update (copies)."""
        if self.convection is None:
            return {}
        self._numbers(fields, nusselt)
        return {name: self.numbers_buffer[:, k].copy()
                for k, name in enumerate(conv.NUMBER_NAMES)}  # fmt: skip

    def _numbers(self, fields: np.ndarray, nusselt: bool) -> None:
        p = self.sim.particles
        n = fields.shape[1]  # (the owned particles)
        if self.numbers_buffer.shape[0] != n:
            self.numbers_buffer = np.zeros((n, len(conv.NUMBER_NAMES)))
        term = self.convection
        gravity = float(np.linalg.norm(self.sim.gravity))
        conv.convection_numbers(fields, p.radius[:n], p.temperature[:n], p.type_id[:n],
                                term.model_id,
                                term.table, gravity, self.beta_mode, self.beta, nusselt,
                                self.numbers_buffer)  # fmt: skip

    def _check_ranges(self, time: float, fields: np.ndarray) -> None:
        """Warn once per quantity of the first particle outside the correlation's range (on
        several MPI ranks: of the lowest rank that has one, said by rank 0 only, and every
        rank marks the quantity warned, so that the ranks check the same quantities)."""
        sim = self.sim
        self._numbers(fields, False)
        p = sim.particles
        model = self.convection.choice.model
        for name, lo, hi in self.ranges:
            if name in self.warned:
                continue
            col = conv.NUMBER_NAMES.index(name)
            k = conv.first_outside(self.numbers_buffer, col, lo, hi)
            message = None
            if k >= 0:
                value = float(self.numbers_buffer[k, col])
                others = ", ".join(
                    f"{n} = {self.numbers_buffer[k, conv.NUMBER_NAMES.index(n)]:.4g}"
                    for n in ("Re", "Pr", "porosity")
                    if n != name
                )
                message = (
                    f"thermal.convection = {model!r}: {name} = {value:.4g} of particle "
                    f"{int(p.global_id[k])} at step {sim.step_count} (t = {time:.6g} s) is "
                    f"outside the correlation's range {lo:g}–{hi:g} ({others}); the correlation "
                    "is extrapolated (reported once per quantity)"
                )
            message = sim.agree_message(message)
            if message is None:
                continue
            self.warned.append(name)
            if sim.says_warnings:
                warnings.warn(message, RuntimeWarning, stacklevel=3)

    # ---------------------------------------------------------------- checkpoints
    def state_dict(self) -> dict[str, Any]:
        """Scalars and arrays to save (the neighbourhood set: its order fixes the sums)."""
        scalars: dict[str, Any] = {"warned": list(self.warned), "cell_size": self.cell_size}
        arrays: dict[str, np.ndarray] = {}
        if self.neighbourhood is not None:
            sub = self.neighbourhood.state_dict()
            scalars["neighbourhood"] = sub["scalars"]
            arrays.update(sub["arrays"])
        if self.radiation_ratio > 0.0:  # the listing fixes the order of the sums
            scalars["members"] = [self.members_builds, self.members_band, self.members_listings,
                                  self.members_offset]  # fmt: skip
            for name, values in zip(MEMBER_ARRAYS, self.members, strict=True):
                arrays[name] = values.copy()
            arrays["members_reference"] = self.members_reference.copy()
        return {"scalars": scalars, "arrays": arrays}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        scalars, arrays = state["scalars"], state["arrays"]
        self.warned = [str(w) for w in scalars.get("warned", [])]
        cell_size = float(scalars.get("cell_size", 0.0))
        if cell_size and isinstance(self.porosity, CellPorosity):
            self._cell_grid(cell_size)  # the grid of the saved run (its default size)
        if self.neighbourhood is not None and "neighbourhood" in scalars:
            self.neighbourhood.load_state_dict(
                {"scalars": scalars["neighbourhood"], "arrays": arrays}
            )
        if self.radiation_ratio > 0.0 and "members" in scalars:
            builds, band, listings, offset = scalars["members"]
            self.members_builds, self.members_listings = int(builds), int(listings)
            self.members_band, self.members_offset = float(band), float(offset)
            self.members_reference = np.array(arrays["members_reference"], np.float64).reshape(
                -1, 3
            )
            offsets, border, index = (arrays[name] for name in MEMBER_ARRAYS)
            self.members = (np.array(offsets, np.int64), np.array(border, np.int64),
                            np.array(index, np.int32))  # fmt: skip
            self.member_sums = tuple(np.zeros(0) for _ in range(4))  # recomputed at first use
            self.border_listing = -1  # (and the border entries' classes)
        self._constants_for = None


__all__ = ["FieldProvider", "POROSITY_PROVIDERS", "PorosityProvider"]
