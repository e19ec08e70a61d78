"""The per-particle fields that sum over each particle's neighbours: the continuum
radiation's sphere of influence (kernels/neighbourhood.py), the shell porosity and the cell
porosity (kernels/porosity.py), and how far they reach (several MPI ranks: the halo width).
A mixin of :class:`~thermodem.engine.fields.FieldProvider`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from thermodem.config.fluid import CellPorosity
from thermodem.errors import ConfigError
from thermodem.geometry import wall_layout as wall_cols
from thermodem.kernels import heat_terms
from thermodem.kernels import neighbourhood as nh
from thermodem.kernels import porosity as pk

#: The border entries' classes hold while BORDER_MARGIN × the largest displacement since
#: their classification is at most their band (2 would be exact: a distance changes by at most
#: twice the displacement).
BORDER_MARGIN = 2.2


class NeighbourhoodFields:
    """Neighbourhood sums, shell and cell porosities of the field provider."""

    sim: Any
    porosity: Any
    radiation: Any

    # ----------------------------------------------------------------- neighbourhood
    def check_neighbourhood_range(self, r_max: float) -> None:
        """A sphere of influence (continuum radiation) or a porosity shell of ``radius_ratio``
        × ``r_max`` larger than the domain's smallest extent averages over the whole domain,
        not a neighbourhood: a ConfigError naming the key, the value, the sphere's radius and
        the domain (as the conduction ranges, engine/thermal_terms.py: check_ranges)."""
        sim = self.sim
        length = (sim.upper - sim.lower)[: 2 if sim.planar else 3]
        extent = float(np.min(length))
        if not r_max > 0.0:
            return
        spheres = [("thermal.porosity.radius_ratio", self.shell_ratio, "the porosity shell")]
        if self.radiation is not None:
            spheres.append(
                ("thermal.radiation.radius_ratio", self.radiation_ratio,
                 f"the sphere of radiative influence of {self.radiation.choice.model!r}")
            )  # fmt: skip
        for key, ratio, what in spheres:
            if ratio > 0.0 and ratio * r_max > extent:
                raise ConfigError(
                    f"{key} = {ratio!r}: {what} around a particle of radius {r_max:.6g} m has "
                    f"the radius {ratio * r_max:.6g} m, more than the domain's smallest extent "
                    f"{extent:.6g} m (domain edges {', '.join(f'{v:.6g}' for v in length)} m): "
                    "it would average over the whole domain, not a neighbourhood; allowed: "
                    f"radius_ratio below {extent / r_max:.6g} (or a larger domain)"
                )

    def _neighbourhood_gap(self) -> float:
        r = self.sim.particles.radius
        r_max, r_min = float(r.max()), float(r.min())
        self.check_neighbourhood_range(r_max)  # (particle files and lists: once inserted)
        gap = 0.0
        if self.radiation_ratio > 0.0:
            gap = max(gap, self.radiation_ratio * r_max - 2.0 * r_min)
        if self.shell_ratio > 0.0:
            gap = max(gap, (self.shell_ratio - 1.0) * r_max)
        return gap

    def _neighbourhood(self, fields: np.ndarray) -> None:
        sim = self.sim
        p = sim.particles
        ns = self.neighbourhood
        if ns.due(sim):
            ns.build(sim, self._neighbourhood_gap(), 0.0)
        n = p.count
        if self.radiation_ratio > 0.0:
            relist = ns.builds != self.members_builds or self.members[0].shape[0] != n + 1
            moved = math.inf if relist else self._border_moved()
            if relist or self._listing_expired(moved):
                self._list_members()
                self._classify_border(0.0)
            elif BORDER_MARGIN * moved > self.border_band:
                self._classify_border(None)
            if self.member_sums[0].shape[0] != n:
                self._member_constants()
            area, emission, member_area, member_count = self.member_sums
            if self.radiation_mode & nh.NB_KRAUSE:  # (the areas hold with the listing)
                nh.neighbourhood_emission(area, p.temperature, emission)
            # the rows of the owned particles (all; on several MPI ranks not the ghosts, whose
            # rows lack the neighbours beyond the halo: their owners sum theirs)
            offsets, border, index = self.members
            nh.neighbourhood_sums(p.position, p.radius, p.temperature,
                                  offsets[: sim.owned_count + 1], border, index,
                                  *self.border_weights, area, emission, member_area,
                                  member_count, sim.lower, sim.upper, sim.periodic,
                                  self.radiation_ratio, self.radiation_mode,
                                  fields)  # fmt: skip
        if self.shell_ratio > 0.0:
            if self.sums.shape[0] != n:
                self.sums = np.zeros((n, 4))
            pk.zero_rows(self.sums)
            pk.shell_pass(p.position, p.radius, ns.i, ns.j, ns.group_start, sim.lower,
                          sim.upper, sim.periodic, self.shell_ratio, self.sums)  # fmt: skip
            width = 4 * max(sim.wall_kind.shape[0], 1)
            if self.scratch.shape[0] < self._chunks() or self.scratch.shape[1] < width:
                self.scratch = np.zeros((self._chunks(), width))
            own = sim.owned_count  # (as above: the owned particles' shells)
            pk.shell_porosity(p.position[:own], p.radius[:own], sim.wall_kind, sim.wall_rows,
                              self.shell_ratio, self.lattice, self.sums[:own], self.scratch,
                              fields)  # fmt: skip

    def _list_members(self) -> None:
        """List each particle's neighbours in (or near) its sphere of radiative influence
        from the neighbourhood set at the current positions (kernels/neighbourhood.py): the
        band is a quarter of the set's skin (at least 1e-9 R_min), so a listing lasts until
        the particles have moved an eighth of the skin, a quarter as long as the set itself
        (the border entries, tested at every step, are ~7 % of the listed neighbours in a
        packed bed)."""
        sim = self.sim
        p = sim.particles
        ns = self.neighbourhood
        n = p.count
        band = max(0.25 * ns.skin, 1e-9 * float(p.radius.min()))
        counts = np.zeros(n, np.int64)
        nh.member_counts(p.position, p.radius, ns.i, ns.j, ns.count, sim.lower, sim.upper,
                         sim.periodic, self.radiation_ratio, band, counts)  # fmt: skip
        offsets = np.zeros(n + 1, np.int64)
        np.cumsum(counts, out=offsets[1:])
        border = np.zeros(n, np.int64)
        index = np.zeros(int(offsets[-1]), np.int32)
        nh.member_fill(p.position, p.radius, ns.i, ns.j, ns.count, sim.lower, sim.upper,
                       sim.periodic, self.radiation_ratio, band, offsets, border,
                       index)  # fmt: skip
        self.members = (offsets, border, index)
        self._member_constants()
        self.members_builds = ns.builds
        self.members_reference = p.position.copy()
        self.members_offset = ns.moved  # the set's displacement at the listing
        self.members_band = band
        self.members_listings += 1

    def _listing_expired(self, border_moved: float) -> bool:
        """Whether a particle may have moved more than band / 2 since the listing. First the
        bound |x - x_list| <= |x - x_set| + |x_list - x_set| from the range set's own
        displacement (found by its due() this step) and the one at the listing: no pass of
        its own while a bed hardly moves; then the same through the border entries'
        classification (``border_moved`` since it, plus the displacement since the listing
        at it); then, if both bounds are too large, the displacement since the listing
        itself (parallel, by chunks: the same for any thread count)."""
        ns = self.neighbourhood
        if 2.0 * (ns.moved + self.members_offset) <= self.members_band:
            return False
        if 2.0 * (border_moved + self.border_listing_moved) <= self.members_band:
            return False
        return 2.0 * self._moved_since(self.members_reference) > self.members_band

    def _moved_since(self, reference: np.ndarray) -> float:
        sim = self.sim
        return float(heat_terms.largest_displacement(sim.particles.position, reference,
                                                     sim.lower, sim.upper, sim.periodic,
                                                     self._part()))  # fmt: skip

    def _border_moved(self) -> float:
        """A bound on how far a particle moved since the border entries were classified
        (inf if they were not, for this listing): the range set's displacement now and at
        the classification, or, if that is too large to keep the classes, the displacement
        since the classification itself."""
        if (
            self.border_listing != self.members_listings
            or self.border_weights[0].shape[0] != self.members[2].shape[0]
            or self.border_reference.shape != self.sim.particles.position.shape
            or self.border_owned != self.sim.owned_count
        ):
            return math.inf
        bound = self.neighbourhood.moved + self.border_offset
        if BORDER_MARGIN * bound <= self.border_band:
            return bound
        return self._moved_since(self.border_reference)

    def _classify_border(self, since_listing: float | None) -> None:
        """Classify the border entries at the current positions with a band of a quarter of
        the listing's (kernels/neighbourhood.py: border_classes): inside, outside, or tested
        at every step, ~a quarter of them; list those that can add to a sum (inside or
        tested) in row order for the sums' flat loop (border_lists). The classes change no
        sum: they say which outcomes are known (the same 0/1 weights in the same order; an
        outside entry added 0), so the sums stay bit-identical and nothing goes into
        checkpoints. On the 50k bed (~1 border entry per particle, 1 thread) the border
        entries took ~0.45 ms per step, most of it the mispredicted end of each row's loop
        over its 0-3 border entries, not the distances. The classes hold while no particle
        moved more than border_band / BORDER_MARGIN (a distance changes by at most twice
        that: a margin of ~10 % of the band for the round-off); ``since_listing``: the
        displacement since the listing (None: found here)."""
        sim = self.sim
        p = sim.particles
        offsets, border, index = self.members
        own = sim.owned_count
        weight = np.zeros(index.shape[0], np.int8)
        band = 0.25 * self.members_band
        nh.border_classes(p.position, p.radius, offsets[: own + 1], border, index, sim.lower,
                          sim.upper, sim.periodic, self.radiation_ratio, band,
                          weight)  # fmt: skip
        size = int((offsets[1 : own + 1] - border[:own]).sum()) if own else 0
        lists = [np.zeros(size, np.int64) for _ in range(4)]
        starts = np.zeros(own // nh.CHUNK + 2, np.int64)
        listed, tested = nh.border_lists(offsets[: own + 1], border, weight, lists[0],
                                         lists[1], starts, lists[2], lists[3])  # fmt: skip
        self.border_weights = (weight, lists[0][:listed], lists[1][:listed], starts,
                               lists[2][:tested], lists[3][:tested], int(tested))  # fmt: skip
        self.border_band = band
        self.border_offset = self.neighbourhood.moved
        self.border_reference = p.position.copy()
        self.border_owned = own
        if since_listing is None:
            since_listing = self._moved_since(self.members_reference)
        self.border_listing_moved = since_listing
        self.border_listing = self.members_listings
        self.border_classifications += 1
        self.border_tested += int(tested)

    def _member_constants(self) -> None:
        """ε A / 2 of every particle and the members' count and Σ ε A / 2 of every row."""
        p = self.sim.particles
        n = p.count
        area, emission = np.zeros(n), np.zeros(n)
        nh.neighbourhood_weights(p.radius, p.temperature, p.type_id, self.emissivity, area,
                                 emission)  # fmt: skip
        member_area, member_count = np.zeros(n), np.zeros(n)
        nh.member_constants(*self.members, area, member_area, member_count)
        self.member_sums = (area, emission, member_area, member_count)

    def default_cell_size(self, r_max: float) -> float:
        """Edge asked for the porosity cells: ``cell_size``, else 6 R_max [m]."""
        return float(self.porosity.cell_size or 6.0 * r_max)

    def halo_reach(self, r_max: float) -> float:
        """The largest centre distance [m] at which another particle enters a particle's
        fields (several MPI ranks: the ghosts must hold these neighbours): q R_max for the
        continuum radiation's sphere, (q + 1) R_max for a porosity shell (the neighbours
        that cut it), and the largest cell edge (at most 1.5 × the size asked, rounded to
        tile the domain) for the cell porosity; 0 without such a field."""
        reach = self.radiation_ratio * r_max
        if self.shell_ratio > 0.0:
            reach = max(reach, (self.shell_ratio + 1.0) * r_max)
        if isinstance(self.porosity, CellPorosity) and r_max > 0.0:
            size = self.default_cell_size(r_max) if self.cell_size == 0.0 else self.cell_size
            length = self.sim.upper - self.sim.lower
            dims = np.maximum(np.round(length / size), 1.0)
            reach = max(reach, float(np.max(length / dims)))
        return reach

    # ------------------------------------------------------------------ cell porosity
    def _cell_grid(self, size: float) -> None:
        """Cells of edge ``size`` (rounded to tile the domain)."""
        sim = self.sim
        self.cell_size = float(size)
        dims = np.empty(3, np.int64)
        for a in range(3):
            dims[a] = max(int(round(float(sim.upper[a] - sim.lower[a]) / self.cell_size)), 1)
        self.cell_dims = dims
        self.cell_edge = np.ascontiguousarray((sim.upper - sim.lower) / dims, np.float64)
        self.cell_fluid = np.zeros(int(dims.prod()))
        self.cell_solid = np.zeros(int(dims.prod()))
        self._cell_walls = np.zeros((0, wall_cols.WALL_WIDTH))

    def _cell_porosity(self, fields: np.ndarray) -> None:
        sim = self.sim
        p = sim.particles
        if self.cell_fluid.shape[0] == 0:
            # (R_max of every rank: each rank must make the same cells)
            self._cell_grid(self.default_cell_size(sim.radius_max()))
        geometry = np.concatenate([sim.wall_rows[:, :6], sim.wall_rows[:, 9:15]], axis=1)
        if self._cell_walls.shape != geometry.shape or not np.array_equal(
            self._cell_walls, geometry
        ):
            pk.cell_fluid_volume(sim.lower, self.cell_edge, self.cell_dims, sim.wall_kind,
                                 sim.wall_rows, 4, self.cell_fluid)  # fmt: skip
            self._cell_walls = geometry
            self.cells_valid = False
        if self.cell_of.shape[0] != p.count:
            self.cell_of = np.zeros(p.count, np.int64)
            self.cells_valid = False
        # the porosities change only when a particle changes cell (or the cells, the order
        # of the particles or the array change): a pass over the cell indices, not the sums
        if (
            self.cells_valid
            and fields is self._porosity_for
            and pk.cell_moves(p.position, sim.lower, self.cell_edge, self.cell_dims,
                              self.cell_of, self._part()) == 0
        ):  # fmt: skip
            return
        self.cells_valid = True
        self._porosity_for = fields
        pk.cell_porosity(p.position, p.radius, sim.lower, self.cell_edge, self.cell_dims,
                         self.cell_fluid, self.cell_solid, self.cell_of, fields)  # fmt: skip
