"""Geometry checks before a run: the particles placed at the start and the pour regions
against the walls at their start positions (a particle overlapping a wall by more than
``simulation.max_overlap_ratio``, a one-sided plane or a cylinder facing the wrong way, a pour
region a wall passes through or that lies outside the walls). Called by
:func:`thermodem.engine.validation.pre_run_checks`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation


def wall_row_owners(case: Case) -> list[int]:
    """The index in ``case.walls`` of every run-time wall row (a box gives several)."""
    from thermodem.geometry.walls import row_count

    planar = case.simulation.planar
    return [k for k, w in enumerate(case.walls) for _ in range(row_count(w, planar))]


def wall_distances(kind: int, row: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Distance of the centres ``x`` (n, 3) to one wall row, as the contact kernel measures
    it (``kernels/neighbors.py: wall_distance``): signed along a plane's normal, unsigned to a
    rectangle, signed towards the particles' side of a cylinder's mantle, inf beyond the ends
    of a finite cylinder."""
    from thermodem.geometry import wall_layout as WL

    p = row[WL.COL_POINT : WL.COL_POINT + 3]
    r = x - p
    if kind == WL.PLANE:
        return r @ row[WL.COL_NORMAL : WL.COL_NORMAL + 3]
    if kind == WL.RECTANGLE:
        n = row[WL.COL_NORMAL : WL.COL_NORMAL + 3]
        u = row[WL.COL_U : WL.COL_U + 3]
        v = np.cross(n, u)
        a = np.clip(r @ u, -row[WL.COL_HALF_U], row[WL.COL_HALF_U])
        b = np.clip(r @ v, -row[WL.COL_HALF_V], row[WL.COL_HALF_V])
        q = p + a[:, None] * u + b[:, None] * v
        return np.linalg.norm(x - q, axis=1)
    if kind == WL.CYLINDER:
        axis = row[WL.COL_AXIS : WL.COL_AXIS + 3]
        h = r @ axis
        rho = np.linalg.norm(r - h[:, None] * axis, axis=1)
        d = row[WL.COL_RADIUS] - rho if row[WL.COL_SIDE] > 0.0 else rho - row[WL.COL_RADIUS]
        return np.where(np.abs(h) > row[WL.COL_HALF_LENGTH], np.inf, d)
    return np.full(x.shape[0], np.inf)


def check_wall_overlaps(sim: Simulation) -> None:
    """Refuse a start where a particle overlaps a wall by more than
    ``simulation.max_overlap_ratio`` of its radius (the run would stop at its first step with
    an overlap error blaming the stiffness): the insertion does not screen walls, so this is a
    wall placed across the particles, or a one-sided plane or a cylinder facing away from
    them. ConfigError naming the wall, the particle and the likely cause."""
    from thermodem.geometry import wall_layout as WL

    p = sim.particles
    n = sim.owned_count  # (on several MPI ranks: this rank's particles, not its ghosts)
    if n == 0 or sim.wall_rows.shape[0] == 0:
        return
    case = sim.case
    limit = case.simulation.max_overlap_ratio
    owners = wall_row_owners(case)
    x, radius = p.position[:n], p.radius[:n]
    for w in range(sim.wall_rows.shape[0]):
        kind, row = int(sim.wall_kind[w]), sim.wall_rows[w]
        d = wall_distances(kind, row, x)
        ratio = (radius - d) / radius
        bad = np.flatnonzero(ratio > limit)
        if bad.size == 0:
            continue
        i = int(bad[np.argmax(ratio[bad])])
        k = owners[w] if w < len(owners) else w
        label = sim.wall_labels[w]
        if kind == WL.PLANE and d[i] < 0.0:
            normal = [float(c) for c in row[WL.COL_NORMAL : WL.COL_NORMAL + 3]]
            why = (
                f"its centre lies {-d[i]:.6g} m behind the plane, which is one-sided: its "
                f"normal {normal} must point towards the particles (is it flipped?)"
            )
        elif kind == WL.CYLINDER and d[i] < 0.0:
            inside = row[WL.COL_SIDE] > 0.0
            why = (
                f"its centre lies {'outside' if inside else 'inside'} the mantle of radius "
                f"{row[WL.COL_RADIUS]:.6g} m (inside: {'true' if inside else 'false'} holds the "
                f"particles {'inside' if inside else 'outside'} it)"
            )
        else:
            why = "the wall passes through it"
        more = f" ({bad.size - 1} more particle(s) too)" if bad.size > 1 else ""
        position = [round(float(c), 9) for c in x[i]]
        raise ConfigError(
            f"walls.{k} ({label}): particle {int(p.global_id[i])} at {position} (radius "
            f"{float(radius[i]):.6g} m) overlaps it by {float(ratio[i]):.3g} × its radius at "
            f"the start{more}, more than simulation.max_overlap_ratio = {limit:g}, so the run "
            f"would stop at its first step: {why}. The insertion does not keep particles clear "
            "of walls: move the wall or the insertion region"
        )


def _radius_range(dist: Any) -> tuple[float, float]:
    """(smallest, largest) radius a (bounded) distribution can draw [m]; 0 for a smallest
    radius without a bound (a lognormal without min_radius)."""
    if dist.kind == "mono":
        return float(dist.radius), float(dist.radius)
    if dist.kind == "discrete":
        radii = [r for r, f in zip(dist.radii, dist.fractions, strict=True) if f > 0]
        return float(min(radii)), float(max(radii))
    return float(getattr(dist, "min_radius", None) or 0.0), float(dist.max_radius_bound)


def _pour_centres(region: Any, r: float, planar: bool) -> np.ndarray:
    """Where the centre of a poured particle of radius ``r`` may be: points spanning the
    region shrunk by ``r`` (its corners and a grid of 9 per axis; a cylinder: rings of 36
    angles at 5 radii and 9 heights), as the pour samples them (geometry/random_fill.py)."""
    from thermodem.geometry.random_fill import _Box, _Circle, _region_of

    shape = _region_of(region, planar)
    if isinstance(shape, _Box):  # (and the 2D rectangle)
        axes = [
            np.linspace(lo + r, hi - r, 9) for lo, hi in zip(shape.lower, shape.upper, strict=True)
        ]
        if planar:
            axes[2] = np.zeros(1)
        grid = np.meshgrid(*axes, indexing="ij")
        return np.column_stack([g.ravel() for g in grid])
    theta = np.linspace(0.0, 2.0 * np.pi, 36, endpoint=False)
    rho = np.linspace(0.0, max(shape.radius - r, 0.0), 5)
    ring = (rho[:, None] * np.cos(theta)).ravel(), (rho[:, None] * np.sin(theta)).ravel()
    if isinstance(shape, _Circle):
        out = np.zeros((ring[0].size, 3))
        out[:, 0] = shape.centre[0] + ring[0]
        out[:, 1] = shape.centre[1] + ring[1]
        return out
    h = np.linspace(r, max(shape.length - r, r), 9)
    pts = (
        shape.base
        + h[:, None, None] * shape.axis
        + ring[0][None, :, None] * shape.e1
        + ring[1][None, :, None] * shape.e2
    )
    return pts.reshape(-1, 3)


def check_pour_walls(sim: Simulation) -> None:
    """Refuse a pour whose region reaches through a wall or lies behind it: a poured particle
    would start overlapping the wall (the run would stop blaming the stiffness, or throw it
    out at speed), or on the far side of it. Checked against the walls at their start
    positions, for the smallest and the largest radius of the distribution (the points of
    :func:`_pour_centres`; exact for planes, whose distance is linear). ConfigError naming
    the entry, the wall, a point and the cause."""
    from thermodem.geometry import wall_layout as WL

    rows = sim.wall_rows.shape[0]
    if rows == 0:
        return
    case = sim.case
    owners = wall_row_owners(case)
    span = float(np.max(np.subtract(case.domain.upper, case.domain.lower)))
    for k, entry in enumerate(case.insertion):
        if entry.kind != "pour":
            continue
        for r in sorted(set(_radius_range(entry.distribution))):
            x = _pour_centres(entry.region, r, sim.planar)
            for w in range(rows):
                kind, row = int(sim.wall_kind[w]), sim.wall_rows[w]
                d = wall_distances(kind, row, x)
                depth = r - d
                i = int(np.argmax(depth))
                if not depth[i] > 1e-9 * span:
                    continue
                wall = owners[w] if w < len(owners) else w
                where = [round(float(c), 9) for c in x[i]]
                if kind == WL.PLANE and d[i] < 0.0:
                    normal = [float(c) for c in row[WL.COL_NORMAL : WL.COL_NORMAL + 3]]
                    why = (
                        f"that point lies {-d[i]:.6g} m behind the plane, which is one-sided "
                        f"(its normal {normal} points to the particles' side)"
                    )
                elif kind == WL.CYLINDER and d[i] < 0.0:
                    inside = row[WL.COL_SIDE] > 0.0
                    why = (
                        f"that point lies {'outside' if inside else 'inside'} the mantle of "
                        f"radius {row[WL.COL_RADIUS]:.6g} m, on the side without particles"
                    )
                else:
                    why = f"the wall passes {max(float(d[i]), 0.0):.6g} m from that centre"
                raise ConfigError(
                    f"insertion.{k}.region: a particle of radius {r:.6g} m poured with its "
                    f"centre at {where} would overlap walls.{wall} ({sim.wall_labels[w]}) at "
                    f"the start: {why}. Poured particles must start clear of every wall (the "
                    "region is checked against the walls at their start positions): move the "
                    "region inside the walls, or move the wall"
                )
            _check_pour_in_boxes(case, k, x, r, span)


def _check_pour_in_boxes(case: Case, k: int, x: np.ndarray, r: float, span: float) -> None:
    """A box wall holds particles inside: its faces are two-sided rectangles, so a particle
    poured outside the box (on its lid, beside it) stays outside. Refuse centres ``x`` of
    pour entry ``k`` outside a box (above an ``open_top`` box is inside: they fall in)."""
    axes = "xy" if case.simulation.planar else "xyz"
    top = len(axes) - 1
    for b, wall in enumerate(case.walls):
        if wall.kind != "box":
            continue
        for a, axis in enumerate(axes):
            below = wall.lower[a] - x[:, a]
            above = x[:, a] - wall.upper[a]
            if wall.open_top and a == top:
                above = np.zeros_like(above)
            out = np.maximum(below, above)
            i = int(np.argmax(out))
            if out[i] > 1e-9 * span:
                where = [round(float(c), 9) for c in x[i]]
                side = "below" if below[i] > 0 else "above"
                raise ConfigError(
                    f"insertion.{k}.region: a particle of radius {r:.6g} m poured with its "
                    f"centre at {where} would start outside the box walls.{b} "
                    f"({wall.name or f'box{b}'}), {side} its {axis} range {wall.lower[a]:g} .. "
                    f"{wall.upper[a]:g} m: a box holds the particles inside it (its faces are "
                    "two-sided), so move the region into the box (above an open_top box is "
                    "fine: the particles fall in)"
                )


def largest_radius(sim: Simulation) -> float:
    """The largest radius of the particles present and of the pour distributions (every
    rank's) [m]; 0 when there is none."""
    n = sim.owned_count
    largest = float(np.max(sim.particles.radius[:n])) if n else 0.0
    for entry in sim.case.insertion:
        if entry.kind == "pour":
            largest = max(largest, float(entry.distribution.max_radius_bound or 0.0))
    comm = getattr(sim, "comm", None)
    if comm is not None:
        largest = max(comm.allgather(largest))
    return largest


def _reach(sim: Simulation) -> float:
    """How far beyond the domain a particle can touch a wall [m]: the largest diameter
    (:func:`largest_radius`), plus ``neighbors.extra_distance``; generous on purpose, so that
    only a wall far from the domain is refused."""
    return 2.0 * largest_radius(sim) + float(sim.case.neighbors.extra_distance)


def _wall_extent(wall: Any, planar: bool) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) of the axis-aligned box around a rectangle, box or cylinder wall
    (unbounded: +-inf; 2D: walls are lines and circles in the x-y plane)."""
    if wall.kind == "box":
        return np.asarray(wall.lower, float), np.asarray(wall.upper, float)
    c = np.asarray(wall.center, float)
    if wall.kind == "rectangle":
        n = np.asarray(wall.normal, float)
        u = np.asarray(wall.u_axis, float)
        n, u = n / np.linalg.norm(n), u / np.linalg.norm(u)
        v = np.cross(n, u)
        half = np.abs(u) * wall.half_extents[0] + np.abs(v) * wall.half_extents[1]
        return c - half, c + half
    a = np.asarray(wall.axis, float)
    a = a / np.linalg.norm(a)
    across = wall.radius * np.sqrt(np.clip(1.0 - a * a, 0.0, 1.0))
    if wall.length is None or planar:
        along = np.where(np.abs(a) > 1e-12, np.inf, 0.0)
    else:
        along = np.abs(a) * 0.5 * wall.length
    return c - across - along, c + across + along


def check_walls_in_domain(sim: Simulation) -> list[str]:
    """A wall that cannot touch any particle of the domain (particles stay inside it: leaving
    a closed side stops the run, periodic ones are wrapped) is a mistake: a plane lying
    outside the domain (a coordinate in mm, or a sign error), or one with the whole domain
    behind it; a rectangle, box or cylinder whose extent misses the domain, farther than a
    particle reaches (:func:`_reach`). Refused naming the key, the value and the domain;
    a wall with a ``velocity`` may move in: a warning. Touching the boundary is fine (the
    usual floor at z = lower). A cylinder's ``angular_velocity`` turns it about its own axis,
    which moves no part of it into the domain. Returns the warnings."""
    case = sim.case
    if not case.walls:
        return []
    planar = case.simulation.planar
    axes = "xy" if planar else "xyz"
    lo = np.asarray(case.domain.lower, float)
    hi = np.asarray(case.domain.upper, float)
    if planar:
        lo[2] = hi[2] = 0.0
    span = float(np.max((hi - lo)[: len(axes)]))
    reach = _reach(sim)
    domain = f"[{list(case.domain.lower)}, {list(case.domain.upper)}]"
    warnings: list[str] = []
    for k, wall in enumerate(case.walls):
        why = None
        if wall.kind == "plane":
            key, value = f"walls.{k}.point", list(wall.point)
            n = np.asarray(wall.normal, float)
            n = n / np.linalg.norm(n)
            corners = np.array(
                [[(lo, hi)[(c >> a) & 1][a] for a in range(3)] for c in range(8)], dtype=float
            )
            d = (corners - np.asarray(wall.point, float)) @ n
            normal = [float(c) for c in wall.normal]
            if d.min() > reach:
                why = (
                    f"(a plane with normal {normal}) lies {d.min():.6g} m outside the domain "
                    f"{domain}, facing it: no particle inside the domain reaches it (they reach at "
                    f"most {reach:.6g} m beyond it)"
                )
            elif d.max() <= 1e-9 * span:
                why = (
                    f"(a plane with normal {normal}) has the whole domain {domain} behind it: "
                    "the plane is one-sided, its normal must point towards the particles (is it "
                    "flipped?)"
                )
        else:
            key = f"walls.{k}.lower" if wall.kind == "box" else f"walls.{k}.center"
            value = list(wall.lower if wall.kind == "box" else wall.center)
            low, up = _wall_extent(wall, planar)
            for a, axis in enumerate(axes):
                gap = max(low[a] - hi[a], lo[a] - up[a])
                if gap > reach:
                    extent = f"{low[a]:g} .. {up[a]:g}"
                    if wall.kind == "box":
                        key, value = f"walls.{k}", f"[{list(wall.lower)}, {list(wall.upper)}]"
                    why = (
                        f"(a {wall.kind}) lies {gap:.6g} m outside the domain {domain} on the "
                        f"{axis} axis (the wall spans {extent} m, the domain "
                        f"{lo[a]:g} .. {hi[a]:g} m): no particle inside the domain reaches it "
                        f"(they reach at most {reach:.6g} m beyond it)"
                    )
                    break
        if why is None:
            continue
        if any(float(c) != 0.0 for c in wall.velocity):
            warnings.append(
                f"{key}: {value} {why}; it moves (velocity {list(wall.velocity)} m/s), so it "
                "may come in later, but it touches nothing until then"
            )
            continue
        still = "it does not move"
        if getattr(wall, "angular_velocity", 0.0):
            still += " (angular_velocity turns it about its own axis only)"
        raise ConfigError(
            f"{key}: {value} {why}, and {still}, so it would never act: particles "
            "stay inside the domain. Move the wall onto the domain's boundary or into the "
            "domain (a coordinate in mm instead of m, or a sign?), enlarge domain, or remove "
            "the wall"
        )
    return warnings


def smallest_radii(sim: Simulation) -> dict[str, float]:
    """The smallest radius [m] of each material's particles: those present at the start and
    those its pour entries can draw (a material of no particle is left out; every rank's)."""
    p = sim.particles
    n = sim.owned_count
    found: dict[str, float] = {}

    def add(name: str, r: float) -> None:
        if r > 0.0:
            found[name] = min(found.get(name, math.inf), r)

    for k, name in enumerate(sim.material_names):
        mine = p.radius[:n][p.type_id[:n] == k]
        if mine.size:
            add(name, float(mine.min()))
    for entry in sim.case.insertion:
        if entry.kind == "pour":
            add(entry.material, _radius_range(entry.distribution)[0])
    comm = getattr(sim, "comm", None)
    if comm is not None:
        merged: dict[str, float] = {}
        for part in comm.allgather(found):
            for name, r in part.items():
                merged[name] = min(merged.get(name, math.inf), r)
        found = merged
    return found


def check_length_scales(sim: Simulation) -> None:
    """Refuse a length of a thermal model that cannot be what it is meant to be beside the
    particles' radii (a value in mm or µm written as metres is the usual cause): a surface
    roughness σ (the resistance network) not below the radius of the smallest particle that
    surface touches, a minimum conduction distance S of a surrounding fluid layer model not
    below the layer δ_f = layer_thickness_ratio × R of the smallest particle (every path of the
    layer would be cut at S: S is a molecular distance, about the gas mean free path).
    ConfigError naming the key, the value, the radius and the bound."""
    case = sim.case
    th = case.thermal
    radii = smallest_radii(sim)
    if th is None or not radii:
        return
    r_all = min(radii.values())
    name, r_min = min(radii.items(), key=lambda kv: kv[1])
    if th.direct_conduction.model == "resistance_network":
        for mat, material in case.materials.items():
            sigma = material.surface_roughness
            # a particle material: its own particles; a wall's: every particle may touch it
            r = radii.get(mat, r_all)
            if sigma is not None and sigma >= r:
                raise ConfigError(
                    f"materials.{mat}.surface_roughness = {sigma:g} m is not below the radius "
                    f"of the smallest particle it touches, {r:g} m: an RMS roughness is a small "
                    "fraction of the radius (µm for mm particles); is it in another unit? "
                    f"allowed: surface_roughness below {r:g} m (thermal.direct_conduction: "
                    "resistance_network reads it)"
                )
        for k, entry in enumerate(case.interactions):
            sigma = entry.surface_roughness
            r = min(radii.get(m, r_all) for m in entry.materials)
            if sigma is not None and sigma >= r:
                raise ConfigError(
                    f"interactions.{k}.surface_roughness = {sigma:g} m is not below the radius "
                    f"of the smallest particle of the pair, {r:g} m: an RMS roughness is a "
                    "small fraction of the radius (µm for mm particles); is it in another "
                    f"unit? allowed: surface_roughness below {r:g} m"
                )
    choice = th.indirect_conduction
    if choice.model in ("rong_horio1999", "musser2011"):
        s = float(choice.params.min_separation)
        ratio = float(choice.params.layer_thickness_ratio)
        layer = ratio * r_min
        if s >= layer:
            raise ConfigError(
                f"thermal.indirect_conduction.min_separation = {s:g} m is not below the fluid "
                f"layer of the smallest particles, layer_thickness_ratio {ratio:g} × radius "
                f"{r_min:g} m ({name}) = {layer:g} m: every conduction path of the layer would "
                "be cut at S, which is a molecular distance (about the gas mean free path; "
                "2.75e-8 m in Morris et al. 2015); is it in another unit? allowed: "
                f"min_separation below {layer:g} m"
            )
