"""Wall definitions of the case file and their run-time rows (see wall_layout)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from thermodem.config.base import StrictModel
from thermodem.config.planar import Vec3, box_axes
from thermodem.config.thermal import WallThermal
from thermodem.geometry import wall_layout as L


def _unit(v: Vec3, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    n = float(np.linalg.norm(a))
    if n == 0.0:
        raise ValueError(f"{name} must be a non-zero vector, got {list(v)}")
    return a / n


class _WallBase(StrictModel):
    material: str = Field(description="name of the wall material")
    velocity: Vec3 = Field(default=(0.0, 0.0, 0.0), description="translation velocity [m/s]")
    name: str | None = Field(default=None, description="label used in output")
    thermal: WallThermal = Field(default_factory=WallThermal, description="thermal condition")


class PlaneWall(_WallBase):
    """Infinite plane, one-sided: particles live on the side the normal points to."""

    kind: Literal["plane"] = "plane"
    point: Vec3
    normal: Vec3

    @field_validator("normal")
    @classmethod
    def _nonzero(cls, v: Vec3) -> Vec3:
        _unit(v, "normal")
        return v


class RectangleWall(_WallBase):
    """Bounded plane (a rectangle) acting on both faces and its edges."""

    kind: Literal["rectangle"] = "rectangle"
    center: Vec3
    normal: Vec3
    u_axis: Vec3 = Field(description="in-plane direction of the first side")
    half_extents: tuple[float, float] = Field(description="half lengths along u and normal x u")

    @model_validator(mode="after")
    def _check(self) -> RectangleWall:
        n = _unit(self.normal, "normal")
        u = _unit(self.u_axis, "u_axis")
        if abs(float(n @ u)) > 1e-9:
            raise ValueError(
                f"u_axis {list(self.u_axis)} must be perpendicular to normal {list(self.normal)}"
            )
        if min(self.half_extents) <= 0:
            raise ValueError(f"half_extents must be positive, got {list(self.half_extents)}")
        return self


class BoxWall(_WallBase):
    """Axis-aligned box holding particles inside (six rectangles, inward normals)."""

    kind: Literal["box"] = "box"
    lower: Vec3
    upper: Vec3
    open_top: bool = Field(
        default=False, description="omit the face at upper z (2D: the side at upper y)"
    )

    @model_validator(mode="after")
    def _check(self, info: ValidationInfo) -> BoxWall:
        axes = box_axes(info)  # 2D: the four sides x-, x+, y-, y+ (lines)
        pairs = zip("xyz", self.lower, self.upper, strict=True)
        if any(a in axes and u <= lo for a, lo, u in pairs):
            raise ValueError(
                f"lower {list(self.lower)} must be below upper {list(self.upper)} on every axis"
            )
        return self


class CylinderWall(_WallBase):
    """Cylinder mantle around an axis, particles inside or outside, optionally rotating."""

    kind: Literal["cylinder"] = "cylinder"
    center: Vec3 = Field(description="a point on the axis (the middle of a finite cylinder)")
    axis: Vec3
    radius: float = Field(gt=0)
    length: float | None = Field(default=None, gt=0, description="None = infinite")
    inside: bool = Field(default=True, description="particles inside the cylinder")
    angular_velocity: float = Field(default=0.0, description="rotation about the axis [rad/s]")

    @field_validator("axis")
    @classmethod
    def _nonzero(cls, v: Vec3) -> Vec3:
        _unit(v, "axis")
        return v


Wall = Annotated[PlaneWall | RectangleWall | BoxWall | CylinderWall, Field(discriminator="kind")]


def rectangle_separates(
    wall: RectangleWall, b: int, lower: Any, upper: Any, planar: bool = False
) -> bool:
    """Whether the rectangle ``wall`` separates the box ``lower``-``upper`` along axis ``b``:
    its normal has a component along ``b`` and its projection along ``b`` covers the box's
    cross-section (every corner of it; ``planar``: the segment covers the other in-plane
    axis, z is unbounded)."""
    n = np.asarray(wall.normal, float)
    n = n / np.linalg.norm(n)
    if abs(n[b]) <= 1e-9:
        return False
    u = np.asarray(wall.u_axis, float)
    u = u / np.linalg.norm(u)
    half_u = wall.half_extents[0] * u
    half_v = wall.half_extents[1] * np.cross(n, u)
    centre = np.asarray(wall.center, float)
    lower = np.asarray(lower, float)
    upper = np.asarray(upper, float)
    others = [c for c in range(2 if planar else 3) if c != b]
    tol = 1e-9 * float(np.max(upper - lower))
    if planar:  # a segment across the plane
        c = others[0]
        reach = abs(half_u[c]) + abs(half_v[c])
        return centre[c] - reach <= lower[c] + tol and centre[c] + reach >= upper[c] - tol
    # the parallelogram the rectangle projects to along b holds every corner
    edges = np.array([[2.0 * half_u[c] for c in others], [2.0 * half_v[c] for c in others]]).T
    origin = np.array([centre[c] - half_u[c] - half_v[c] for c in others])
    if abs(np.linalg.det(edges)) < 1e-300:
        return False
    for x in (lower[others[0]], upper[others[0]]):
        for y in (lower[others[1]], upper[others[1]]):
            s = np.linalg.solve(edges, np.array([x, y]) - origin)
            if (s < -1e-9).any() or (s > 1.0 + 1e-9).any():
                return False
    return True


def row_count(wall: _WallBase, planar: bool = False) -> int:
    """Rows :func:`wall_rows` makes of one wall: a box gives its faces (6, or 4 sides in 2D;
    one less with ``open_top``), every other wall one row."""
    if isinstance(wall, BoxWall):
        return (4 if planar else 6) - int(wall.open_top)
    return 1


def wall_rows(
    walls: list, material_index: dict[str, int], planar: bool = False
) -> tuple[np.ndarray, np.ndarray, list]:
    """Run-time (kinds, rows, labels) of every wall; a box expands to rectangles.

    ``planar`` (a 2D case): walls are lines in the x-y plane (z = 0). A rectangle is a segment:
    its extent along z is unbounded (inf) and its centre moves to z = 0; a box gives its four
    sides x-, x+, y-, y+ (``open_top`` omits y+); a cylinder (axis along z, checked with the
    case) is a circle: centre at z = 0, no length. The case checks (``config/planar_case.py``)
    have made sure that every normal and velocity lies in the plane.
    """
    kinds: list[int] = []
    rows: list[np.ndarray] = []
    labels: list[str] = []
    for w_index, w in enumerate(walls):
        label = w.name or f"{w.kind}{w_index}"
        mat = material_index[w.material]
        if isinstance(w, BoxWall):
            lo = np.asarray(w.lower, float)
            hi = np.asarray(w.upper, float)
            c = 0.5 * (lo + hi)
            h = 0.5 * (hi - lo)
            faces = []
            top = 1 if planar else 2  # the open top: upper y in 2D, upper z in 3D
            for axis in range(2 if planar else 3):
                for side in (-1.0, 1.0):
                    if axis == top and side > 0 and w.open_top:
                        continue
                    normal = np.zeros(3)
                    normal[axis] = -side  # inward
                    center = c.copy()
                    center[axis] = c[axis] + side * h[axis]
                    ua = (axis + 1) % 3
                    va = (axis + 2) % 3
                    u = np.zeros(3)
                    u[ua] = 1.0
                    h_face = h.copy()
                    if planar:  # a line: unbounded along z, in the plane z = 0
                        center[2] = 0.0
                        h_face[2] = np.inf
                    faces.append(
                        (
                            center,
                            normal,
                            u,
                            h_face[ua],
                            h_face[va],
                            f"{label}.{'xyz'[axis]}{'-' if side < 0 else '+'}",
                        )
                    )
            for center, normal, u, hu, hv, lab in faces:
                # v = normal x u must be the axis va (up to sign): use |hv| either way
                row = np.zeros(L.WALL_WIDTH)
                row[L.COL_POINT : L.COL_POINT + 3] = center
                row[L.COL_NORMAL : L.COL_NORMAL + 3] = normal
                row[L.COL_VELOCITY : L.COL_VELOCITY + 3] = w.velocity
                row[L.COL_U : L.COL_U + 3] = u
                row[L.COL_HALF_U] = hu
                row[L.COL_HALF_V] = hv
                row[L.COL_MATERIAL] = mat
                kinds.append(L.RECTANGLE)
                rows.append(row)
                labels.append(lab)
            continue
        row = np.zeros(L.WALL_WIDTH)
        row[L.COL_VELOCITY : L.COL_VELOCITY + 3] = w.velocity
        row[L.COL_MATERIAL] = mat
        if isinstance(w, PlaneWall):
            row[L.COL_POINT : L.COL_POINT + 3] = w.point
            row[L.COL_NORMAL : L.COL_NORMAL + 3] = _unit(w.normal, "normal")
            kinds.append(L.PLANE)
        elif isinstance(w, RectangleWall):
            row[L.COL_POINT : L.COL_POINT + 3] = w.center
            row[L.COL_NORMAL : L.COL_NORMAL + 3] = _unit(w.normal, "normal")
            row[L.COL_U : L.COL_U + 3] = _unit(w.u_axis, "u_axis")
            row[L.COL_HALF_U] = w.half_extents[0]
            row[L.COL_HALF_V] = w.half_extents[1]
            if planar:  # a segment: unbounded along z (u or v = normal x u is along z)
                row[L.COL_POINT + 2] = 0.0
                along_z = 0 if abs(row[L.COL_U + 2]) > 0.5 else 1
                row[L.COL_HALF_U + along_z] = np.inf
            kinds.append(L.RECTANGLE)
        elif isinstance(w, CylinderWall):
            row[L.COL_POINT : L.COL_POINT + 3] = w.center
            row[L.COL_AXIS : L.COL_AXIS + 3] = _unit(w.axis, "axis")
            row[L.COL_RADIUS] = w.radius
            row[L.COL_HALF_LENGTH] = np.inf if w.length is None else 0.5 * w.length
            row[L.COL_SIDE] = 1.0 if w.inside else -1.0
            row[L.COL_OMEGA] = w.angular_velocity
            if planar:  # a circle in the plane (the axis is along z)
                row[L.COL_POINT + 2] = 0.0
                row[L.COL_HALF_LENGTH] = np.inf
            kinds.append(L.CYLINDER)
        rows.append(row)
        labels.append(label)
    if not rows:
        return np.zeros(0, np.int64), np.zeros((0, L.WALL_WIDTH)), labels
    return np.asarray(kinds, np.int64), np.vstack(rows), labels
