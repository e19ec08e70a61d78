"""Thermal conditions of a case: initial temperatures, wall temperatures, fixed-temperature
particles and the heat sources (flux, volumetric, external).

Selections (``thermal.fixed_temperature``, ``heat_flux``, ``volumetric_source``) hold by
material, global ids and a box region; every given criterion must hold. They are not
evaluated over all particles at every step. At each neighbour-list build (and after an
insertion or a restart) one compiled parallel pass classifies every particle
(``kernels/conditions.py: classify_conditions``): the material and id criteria depend on the
particle only, and until the next build no particle moves farther than half the Verlet skin
from its position at the build (``Simulation.reference``; the build comes first otherwise),
so a region holds a particle surely, or surely not, unless the particle is within half a skin
of the region's faces. Fixed particles and sources are set there; the held (surely fixed)
particles take their bath temperature at the first evaluation after it, and then per thermal
step only the few candidates near a region face (evaluated at their current position) are
visited (``apply_listed``): no thermal update changes a fixed particle's temperature, and code
that writes temperatures directly calls :meth:`ThermalConditions.invalidate`. A material or id
selection has no candidates. External sources (a power shared by the particles in a box,
uniform or Gaussian) take a compiled parallel pass over the particles at every thermal step.
Nothing here loops over particles in Python.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.config.thermal import Selection
from thermodem.engine.expressions import compile_expression
from thermodem.geometry import wall_layout as wall_cols
from thermodem.geometry.walls import row_count
from thermodem.kernels.conditions import (
    CANDIDATE,
    CHUNK,
    FIXED,
    FLUX,
    VOLUMETRIC,
    add_weighted,
    apply_listed,
    classify_conditions,
    external_weights,
)

if TYPE_CHECKING:
    from thermodem.config.thermal import ThermalSettings
    from thermodem.engine.simulation import Simulation


def wall_temperature_function(spec: Any) -> Any:
    """t -> T of a fixed-temperature wall (constant, table or expression)."""
    value = spec.temperature
    if isinstance(value, int | float):
        return lambda t: float(value)
    if isinstance(value, list):
        times = np.array([a for a, _ in value])
        temps = np.array([b for _, b in value])
        return lambda t: float(np.interp(t, times, temps))
    expr = compile_expression(value, ("t",))
    return lambda t: float(expr(t))


def box_bounds(box: Any, planar: bool) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) of a selection box as float arrays; in a 2D case (``planar``) the z
    extent is ignored (-inf .. inf): the particles live in the plane z = 0, and a box copied
    from a 3D case whose z range misses 0 still selects in the plane (docs/two-dimensional.md).
    """
    lo = np.array(box.lower, np.float64)
    hi = np.array(box.upper, np.float64)
    if planar:
        lo[2], hi[2] = -np.inf, np.inf
    return lo, hi


def in_box(position: np.ndarray, box: Any, planar: bool = False) -> np.ndarray:
    """Mask of positions inside an axis-aligned box (bounds included; 2D: z ignored)."""
    lo, hi = box_bounds(box, planar)
    return np.all((position >= lo) & (position <= hi), axis=1)


class ThermalConditions:
    """The initial temperatures, wall temperatures, fixed particles and sources of a case."""

    def __init__(self, sim: Simulation, settings: ThermalSettings) -> None:
        self.sim = sim
        self.settings = settings
        self.wall_functions: list[Any] = []
        constant = True
        for w in sim.case.walls:
            fn = wall_temperature_function(w.thermal) if w.thermal.kind == "fixed" else None
            count = row_count(w, bool(getattr(sim, "planar", False)))
            self.wall_functions.extend([fn] * count)
            constant &= not isinstance(getattr(w.thermal, "temperature", None), list | str)
        #: no wall temperature depends on time: the rows are written once
        self.walls_constant = constant
        self._walls_written = False
        entries: list[tuple[int, float, Selection]] = []
        entries += [(FIXED, f.temperature, f.select) for f in settings.fixed_temperature]
        entries += [(FLUX, h.flux, h.select) for h in settings.heat_flux]
        entries += [(VOLUMETRIC, v.power_density, v.select) for v in settings.volumetric_source]
        self.selections = [sel for _, _, sel in entries]
        self.kinds = np.array([k for k, _, _ in entries], np.int64)
        self.values = np.array([v for _, v, _ in entries], np.float64)
        self.has_region = np.array([sel.region is not None for sel in self.selections], np.bool_)
        self.boxes = np.zeros((len(entries), 6))
        for e, sel in enumerate(self.selections):
            if sel.region is not None:
                self.boxes[e, :3], self.boxes[e, 3:] = box_bounds(sel.region, sim.planar)
        self.static_mask = np.zeros((0, len(entries)), np.bool_)
        self.static_valid = False
        self.fixed = np.zeros(0, np.bool_)
        self.source = np.zeros(0)
        #: the flux/volumetric part of the sources (``source`` adds the external sources)
        self.base_source = np.zeros(0)
        self.bath = np.zeros(0)
        self.code = np.zeros(0, np.int8)
        #: indices of the held and candidate particles (kernels/conditions.py)
        self.listed = np.zeros(0, np.int64)
        #: indices of the candidate particles only
        self.candidates = np.zeros(0, np.int64)
        #: the held particles have not taken their bath temperature since the classification
        self.hold_pending = True
        #: the displacement from Simulation.reference up to which the classification holds
        self.margin = -1.0
        self._moved = 0.0  # Simulation.moved when the particles were classified
        self.classifications = 0
        self._weight = np.zeros(0)
        self._part = np.zeros(1)
        self.active = bool(entries or settings.external_source)
        #: some entry or external source gives heat (else the source column stays zero)
        self.has_sources = bool(np.any(self.kinds != FIXED) or settings.external_source)

    def invalidate(self) -> None:
        """The particles were reordered or inserted (a neighbour-list build, a pour, a
        restart), or temperatures were written from outside the thermal update: classify
        them again at the next evaluation (which sets every held particle to its bath)."""
        self.static_valid = False

    def _static_masks(self) -> None:
        p = self.sim.particles
        mask = np.ones((p.count, len(self.selections)), np.bool_)
        for e, sel in enumerate(self.selections):
            if sel.material is not None:
                mask[:, e] &= p.type_id == self.sim.material_index[sel.material]
            if sel.ids is not None:
                mask[:, e] &= np.isin(p.global_id, np.asarray(sel.ids, np.int64))
        self.static_mask = mask

    def _classify(self) -> None:
        """Static masks and the classification of every particle for the selections, valid
        while no particle is farther than ``margin`` from ``Simulation.reference``."""
        sim = self.sim
        p = sim.particles
        n = p.count
        self._static_masks()
        reference = sim.reference
        margin = 0.5 * float(sim.skin or 0.0)  # Simulation.rebuild_due: moved <= skin / 2
        self._moved = sim.moved
        if reference.shape != p.position.shape:
            # no build since particles came in: valid for the current positions only
            reference, margin = p.position, 0.0
            self.margin = -1.0
        elif sim.moved <= margin or np.array_equal(reference, p.position):
            # (right after a build `moved` is still the displacement that caused it; the
            # positions are the reference then, and nothing moves before the next drift,
            # which computes `moved` again)
            self.margin = margin
        else:
            reference, margin = p.position, 0.0
            self.margin = -1.0
        # a relative allowance for the rounding of the displacement and of the bounds
        extent = float(np.max(np.abs(np.concatenate([sim.lower, sim.upper])))) if n else 0.0
        allowance = margin + 1e-12 * extent
        if self.bath.shape[0] != n:
            self.bath = np.zeros(n)
            self.code = np.zeros(n, np.int8)
        classify_conditions(
            reference, p.radius, self.static_mask, self.kinds, self.values, self.has_region,
            self.boxes, allowance, sim.lower, sim.upper, sim.periodic, self.fixed,
            self.base_source, self.bath, self.code, float(getattr(sim, "disc_thickness", 0.0)),
            2 if getattr(sim, "planar", False) else 3,
        )  # fmt: skip
        self.listed = np.flatnonzero(self.code).astype(np.int64)
        self.candidates = self.listed[self.code[self.listed] == CANDIDATE]
        self.hold_pending = True
        self.static_valid = True
        self.classifications += 1

    def apply(
        self, time: float, specific_heat_by_type: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, float]:
        """(fixed mask, source powers [W], energy added by resetting fixed particles [J]).

        Fixed particles take their bath temperature; the reset energy is m c (T_bath - T)
        with the constant specific heats (a tabulated c is handled by the caller).
        """
        p = self.sim.particles
        n = p.count
        if self.fixed.shape[0] != n:
            self.fixed = np.zeros(n, np.bool_)
            self.base_source = np.zeros(n)
            self.source = self.base_source
            self._weight = np.zeros(n)
            self.static_valid = False
        if not self.active:
            return self.fixed, self.source, 0.0
        moved = self.sim.moved
        if (
            not self.static_valid
            or self.static_mask.shape[0] != n
            or self.margin < 0.0
            or not (moved <= self.margin or moved == self._moved)
        ):
            self._classify()
        # a held particle takes its bath temperature once after the classification: no
        # thermal update changes a fixed particle's temperature (they skip the fixed ones),
        # so after that only the candidates are evaluated per step (scattered through the
        # arrays, the held particles of a bed's bottom layer cost more than the update of
        # all particles when the caches hold other data)
        listed = self.listed if self.hold_pending else self.candidates
        self.hold_pending = False
        rows = listed.shape[0] // CHUNK + 1
        if self._part.shape[0] < rows:
            self._part = np.zeros(rows)
        own = self.sim.owned_count
        if own == n:
            parts = (listed,)
        else:
            # on several MPI ranks the ghosts (after the owned particles) get the same
            # conditions as on their owners, but only the owned particles' reset energy enters
            # this rank's ledger (thermodem.mpi); `listed` is sorted
            split = int(np.searchsorted(listed, own))
            parts = (listed[:split], listed[split:])
        reset = 0.0
        thickness = float(getattr(self.sim, "disc_thickness", 0.0))  # 2D discs
        for k, listed in enumerate(parts):
            r = apply_listed(
                listed, self.code, p.position, p.radius, p.mass, p.type_id, p.temperature,
                specific_heat_by_type, self.static_mask, self.kinds, self.values,
                self.has_region, self.boxes, self.fixed, self.base_source, self.bath, self._part,
                thickness,
            )  # fmt: skip
            reset = r if k == 0 else reset
        active = [e for e in self.settings.external_source if e.start_time <= time < e.end_time]
        if not active:
            self.source = self.base_source
            return self.fixed, self.source, reset
        if self.source is self.base_source or self.source.shape[0] != n:
            self.source = np.empty(n)
        self.source[:] = self.base_source
        # the weights of the particles this process owns, summed over the MPI ranks (the
        # ghosts take no share here: their owners give them theirs)
        self._weight[own:] = 0.0
        rows = own // CHUNK + 1
        if self._part.shape[0] < rows:
            self._part = np.zeros(rows)
        for e in active:
            lower, upper = box_bounds(e.region, self.sim.planar)
            axis = np.asarray(e.axis, np.float64) / np.linalg.norm(e.axis)
            centre = 0.5 * (np.asarray(e.region.lower) + np.asarray(e.region.upper))
            if self.sim.planar:
                centre[2] = 0.0  # (the plane of the discs)
            gaussian = e.profile == "gaussian"
            total = external_weights(
                p.position[:own], p.radius[:own], lower, upper, gaussian, centre, axis,
                float(e.sigma or 1.0), self._weight[:own], self._part,
            )  # fmt: skip
            total = self.sim.sum_over_ranks(total)  # (collective on several MPI ranks)
            if total > 0.0:
                add_weighted(self.source, self._weight, e.power / total)
        return self.fixed, self.source, reset

    def update_walls(self, time: float) -> None:
        """Wall rows: thermal kind and temperature at ``time`` (once if none depends on t)."""
        if self.walls_constant and self._walls_written:
            return
        self._walls_written = True
        rows = self.sim.wall_rows
        for w, fn in enumerate(self.wall_functions):
            if fn is None:
                rows[w, wall_cols.COL_THERMAL_KIND] = 0.0
            else:
                rows[w, wall_cols.COL_THERMAL_KIND] = 1.0
                rows[w, wall_cols.COL_TEMPERATURE] = fn(time)

    def initial_temperature(self, position: np.ndarray, type_id: np.ndarray) -> np.ndarray:
        """Initial temperatures [K] of new particles from ``thermal.initial_temperature``."""
        rule = self.settings.initial_temperature
        n = position.shape[0]
        default = self.sim.case.simulation.initial_temperature
        if rule is None:
            return np.full(n, default)
        if rule.kind == "uniform":
            return np.full(n, rule.value)
        if rule.kind == "per_material":
            names = self.sim.material_names
            values = np.array([rule.values.get(m, rule.default) for m in names])
            return values[type_id]
        if rule.kind == "regions":
            out = np.full(n, rule.default)
            for box, temp in rule.regions:
                out[in_box(position, box, self.sim.planar)] = temp
            return out
        fn = compile_expression(rule.expression, ("x", "y", "z"))
        return np.broadcast_to(fn(position[:, 0], position[:, 1], position[:, 2]), (n,)).copy()
