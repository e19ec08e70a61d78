"""The checks of a whole case that read several sections together (wall names, thermal
selections against the materials and the domain, regions that miss the domain, temperature
expressions probed over the run, the conductance reuse settings): :class:`CaseChecks`, a
mixin of :class:`thermodem.config.schema.Case`, whose validator calls them."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from thermodem.models import registry

if TYPE_CHECKING:
    from thermodem.config.thermal import ThermalSettings


def _cylinder_bbox(region: Any) -> tuple[list[float], list[float]]:
    """Axis-aligned bounding box of a (validated, unit-axis) cylinder region."""
    base = [float(c) for c in region.base_centre]
    axis = [float(c) for c in region.axis]
    top = [b + region.length * a for b, a in zip(base, axis, strict=True)]
    half = [region.radius * math.sqrt(max(0.0, 1.0 - a * a)) for a in axis]
    lower = [min(b, t) - h for b, t, h in zip(base, top, half, strict=True)]
    upper = [max(b, t) + h for b, t, h in zip(base, top, half, strict=True)]
    return lower, upper


def _fmt(values: list[float]) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


def fluid_probe_samples(case: Any) -> list[tuple[Any, Any, Any, Any]]:
    """Sample points (t, x, y, z) at which a fluid expression of t, x, y, z is evaluated before
    the run: 2001 times from 0 to end_time at the 27 points of a 3 × 3 × 3 grid spanning the
    domain, and the 21 × 21 × 21 grid at 11 times (2D: the plane z = 0)."""
    import numpy as np

    def grid(n: int) -> list[Any]:
        axes = [np.linspace(lo, hi, n) for lo, hi in zip(case.domain.lower, case.domain.upper,
                                                         strict=True)]  # fmt: skip
        if case.simulation.planar:
            axes[2] = np.zeros(1)
        return [a.ravel()[None, :] for a in np.meshgrid(*axes, indexing="ij")]

    end = case.simulation.end_time
    return [
        (np.linspace(0.0, end, 2001)[:, None], *grid(3)),
        (np.linspace(0.0, end, 11)[:, None], *grid(21)),
    ]


class CaseChecks:
    """The cross-section checks of :class:`~thermodem.config.schema.Case` (a mixin)."""

    def _check_wall_names(self) -> None:
        """Wall labels (``name``, else ``KINDINDEX``; a box's faces ``NAME.x-`` ...) are
        unique: they name the walls in walls.pvd, in ``thermodem export`` and in the failure
        messages ('particle 4 and wall lid')."""
        seen: dict[str, int] = {}
        axes = "xy" if self.simulation.planar else "xyz"
        for k, w in enumerate(self.walls):
            label = w.name or f"{w.kind}{k}"
            labels = [label]
            if w.kind == "box":
                labels = [f"{label}.{a}{side}" for a in axes for side in "-+"]
            for name in labels:
                if name in seen:
                    first = seen[name]
                    default = "" if self.walls[first].name else " (its default name)"
                    raise ValueError(
                        f"walls.{k}.name: {name!r} is also the name of walls.{first}{default}; "
                        "wall names label the walls in walls.pvd, exports and messages, so they "
                        "must be unique"
                    )
                seen[name] = k

    def _check_interaction_pairs(self) -> None:
        """Every pair of materials is named by one ``interactions`` entry at most: with two,
        the later replaced the earlier whole, so the earlier entry's coefficients were lost
        without a word (``[a, b]`` and ``[b, a]`` are the same pair)."""
        seen: dict[frozenset, int] = {}
        for k, entry in enumerate(self.interactions):
            pair = frozenset(entry.materials)
            if pair in seen:
                j = seen[pair]
                a, b = entry.materials
                keys = lambda e: sorted(e.model_fields_set - {"materials"})  # noqa: E731
                raise ValueError(
                    f"interactions.{k}.materials: names the pair {a}-{b} again (got "
                    f"{list(entry.materials)}; interactions.{j} names it too, with "
                    f"{', '.join(keys(self.interactions[j]))}; this entry gives "
                    f"{', '.join(keys(entry))}): one entry would replace the other; allowed: "
                    "one entry per pair of materials, with all of its coefficients"
                )
            seen[pair] = k

    def _region_misses_domain(self, region: Any) -> str | None:
        """The axis on which a box region lies wholly outside the domain (no particle can ever
        be in it: particles leaving the domain stop the run, periodic ones are wrapped), or
        None."""
        dom = self.domain
        for a, axis in enumerate("xy" if self.simulation.planar else "xyz"):
            if region.upper[a] < dom.lower[a] or region.lower[a] > dom.upper[a]:
                return (
                    f"on the {axis} axis ({region.lower[a]:g} .. {region.upper[a]:g} against "
                    f"{dom.lower[a]:g} .. {dom.upper[a]:g})"
                )
        return None

    def _check_thermal_selections(self, th: ThermalSettings) -> None:
        """A thermal condition that can never take a particle is refused: its material is
        that of no insertion entry, its region lies outside the domain, or an id is < 0;
        an external source's region outside the domain likewise."""
        particle_materials = sorted({e.material for e in self.insertion})
        dom = f"[{list(self.domain.lower)}, {list(self.domain.upper)}]"
        for key in ("fixed_temperature", "heat_flux", "volumetric_source"):
            for k, entry in enumerate(getattr(th, key)):
                sel, where = entry.select, f"thermal.{key}.{k}.select"
                if sel.ids is not None and any(i < 0 for i in sel.ids):
                    raise ValueError(
                        f"{where}.ids: must be >= 0 (global particle ids, numbered from 0 in "
                        f"insertion order), got {sel.ids}"
                    )
                if (
                    sel.material is not None
                    and particle_materials
                    and sel.material not in particle_materials
                ):
                    raise ValueError(
                        f"{where}.material: {sel.material!r} is the material of no particle, so "
                        f"the entry selects nothing (a selection takes particles, not walls: give "
                        f"a wall its own thermal key); particle materials: "
                        f"{', '.join(particle_materials)}"
                    )
                if sel.region is not None:
                    miss = self._region_misses_domain(sel.region)
                    if miss is not None:
                        raise ValueError(
                            f"{where}.region: [{list(sel.region.lower)}, "
                            f"{list(sel.region.upper)}] lies outside the domain {dom} {miss}, "
                            "so it can never hold a particle: move the region into the domain"
                        )
        for k, source in enumerate(th.external_source):
            miss = self._region_misses_domain(source.region)
            if miss is not None:
                raise ValueError(
                    f"thermal.external_source.{k}.region: [{list(source.region.lower)}, "
                    f"{list(source.region.upper)}] lies outside the domain {dom} {miss}, so "
                    f"no particle can receive its power ({source.power:g} W): move the region "
                    "into the domain"
                )

    def _check_region_in_domain(self, k: int, entry: Any) -> None:
        """The box or cylinder an entry fills must lie inside the domain (particles outside it
        would stop the run at its first step)."""
        kind = entry.kind
        if kind in ("lattice", "random_box"):
            key, lower, upper = f"insertion.{k}", entry.lower, entry.upper
            what = f"the {kind} box [{list(lower)}, {list(upper)}]"
        elif kind == "random_cylinder" or (kind == "pour" and entry.region.kind == "cylinder"):
            region = entry.region
            key = f"insertion.{k}" + (".region" if kind == "pour" else "")
            lower, upper = _cylinder_bbox(region)
            what = (
                f"the cylinder (base_centre {list(region.base_centre)}, axis "
                f"{list(region.axis)}, radius {region.radius}, length {region.length}), whose "
                f"bounding box is [{_fmt(lower)}, {_fmt(upper)}],"
            )
        elif kind == "pour":
            key, lower, upper = f"insertion.{k}.region", entry.region.lower, entry.region.upper
            what = f"the pour region [{list(lower)}, {list(upper)}]"
        else:
            return
        dom = self.domain
        for a, axis in enumerate("xy" if self.simulation.planar else "xyz"):
            tol = 1e-9 * (dom.upper[a] - dom.lower[a])
            if lower[a] < dom.lower[a] - tol or upper[a] > dom.upper[a] + tol:
                raise ValueError(
                    f"{key}: {what} reaches outside the domain [{list(dom.lower)}, "
                    f"{list(dom.upper)}] on the {axis} axis ({lower[a]:g} .. {upper[a]:g} "
                    f"against {dom.lower[a]:g} .. {dom.upper[a]:g}); particles must start "
                    "inside the domain: move the region or enlarge domain"
                )

    def _probe_temperature_expressions(self, th: ThermalSettings) -> None:
        """Temperature expressions evaluated before the run: the initial temperature on a
        21 × 21 × 21 grid spanning the domain, each wall temperature at 2001 times from 0 to
        end_time, the fluid's temperature and velocity expressions at the points of
        :func:`fluid_probe_samples`; every value must be finite and a temperature > 0 K."""
        import numpy as np

        from thermodem.engine.expressions import probe_expression

        rule = th.initial_temperature
        if rule is not None and rule.kind == "expression":
            axes = [
                np.linspace(lo, hi, 21)
                for lo, hi in zip(self.domain.lower, self.domain.upper, strict=True)
            ]
            x, y, z = np.meshgrid(*axes, indexing="ij")
            try:
                probe_expression(rule.expression, ("x", "y", "z"), (x, y, z), 0.0)
            except ValueError as exc:
                raise ValueError(
                    f"thermal.initial_temperature.expression: {exc} (an initial temperature "
                    "[K] of every point of the domain)"
                ) from None
        times = np.linspace(0.0, self.simulation.end_time, 2001)
        for k, wall in enumerate(self.walls):
            value = wall.thermal.temperature
            if wall.thermal.kind == "fixed" and isinstance(value, str):
                try:
                    probe_expression(value, ("t",), (times,), 0.0)
                except ValueError as exc:
                    raise ValueError(
                        f"walls.{k}.thermal.temperature: {exc} (a wall temperature [K] from "
                        "t = 0 to simulation.end_time)"
                    ) from None
        fluid = th.fluid
        for name, positive in (("temperature", True), ("velocity", False)):
            source = getattr(fluid, name) if fluid is not None else None
            if source is None or source.kind != "expression":
                continue
            for c, text in enumerate(source.expression):
                key = f"thermal.fluid.{name}" + (f".{c}" if len(source.expression) > 1 else "")
                try:
                    for samples in fluid_probe_samples(self):
                        probe_expression(text, ("t", "x", "y", "z"), samples,
                                         0.0 if positive else None)  # fmt: skip
                except ValueError as exc:
                    what = "a fluid temperature [K]" if positive else "a fluid velocity [m/s]"
                    raise ValueError(
                        f"{key}: {exc} ({what} at every point of the domain from t = 0 to "
                        "simulation.end_time)"
                    ) from None

    def _check_voronoi_reuse(self, th: ThermalSettings) -> None:
        """The Voronoi conductance reuse holds H for a pair geometry: a Voronoi model, and
        constant conductivities."""
        if th.tessellation is None or th.tessellation.conductance_gap_tolerance == 0.0:
            return
        tol = th.tessellation.conductance_gap_tolerance
        key = "thermal.tessellation.conductance_gap_tolerance"
        model = th.indirect_conduction.model
        if model not in ("voronoi_a", "voronoi_b"):
            raise ValueError(
                f"{key}: {tol} reuses the conductances of the Voronoi models, but "
                f"thermal.indirect_conduction is {model!r}: use voronoi_a or voronoi_b, or 0"
            )
        tabled = [n for n, m in self.materials.items() if m.thermal_conductivity_table]
        if tabled:
            raise ValueError(
                f"{key}: {tol} needs constant thermal conductivities, but materials "
                f"{', '.join(tabled)} have a thermal_conductivity_table: use 0"
            )

    def _check_conductance_reuse(self, th: ThermalSettings) -> None:
        """The reuse holds a conductance for a given normal force: the model must depend on
        the contact through the normal force only, and the conductivities must be constant."""
        tol = th.conductance_force_tolerance
        if tol == 0.0:
            return
        key = "thermal.conductance_force_tolerance"
        spec = th.direct_conduction.spec
        if not spec.conductance_from_force:
            allowed = [
                m.name
                for m in registry.all_models()
                if m.family == "direct_conduction" and m.conductance_from_force
            ]
            raise ValueError(
                f"{key}: {tol} needs a direct_conduction model whose conductance depends on "
                f"the contact through the normal force only ({', '.join(allowed)}); "
                f"{spec.name!r} also depends on the overlap, contact time or impact velocity: "
                "use 0"
            )
        refusal = spec.conductance_reuse_refusal  # a choice of the parameters
        reason = refusal(th.direct_conduction.params) if refusal is not None else None
        if reason:
            raise ValueError(f"{key}: {tol} {reason}")
        tabled = [n for n, m in self.materials.items() if m.thermal_conductivity_table]
        if tabled:
            raise ValueError(
                f"{key}: {tol} needs constant thermal conductivities, but materials "
                f"{', '.join(tabled)} have a thermal_conductivity_table: use 0"
            )
