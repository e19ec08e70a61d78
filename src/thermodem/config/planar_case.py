"""The checks of a two-dimensional case (``simulation.dimension: 2``), run when the case is read.

The particles are discs (or spheres, ``particle_shape: sphere``) in the plane z = 0 and must
stay there: every direction, velocity and load the case gives must lie in the plane (so the
out-of-plane components stay exactly zero), walls are lines (planes whose normal lies in the
plane, rectangles as segments, boxes as their four sides) and circles (cylinders along z), and
every selected model must support the particle shape in 2D (the registry's ``planar`` flag:
a model with no 2D form is refused here, before the run, naming it). Defaults that are 3D laws
change in 2D discs: ``contact.normal`` defaults to ``hertz_2d`` and ``contact.tangential`` to
``linear`` when the case does not name them. See ``docs/two-dimensional.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from thermodem.models import registry

if TYPE_CHECKING:
    from thermodem.config.schema import Case, ModelChoice

#: ``contact`` defaults of a 2D case of discs (Hertz and Mindlin are point-contact laws of
#: spheres).
DISC_CONTACT_DEFAULTS = {"normal": "hertz_2d", "tangential": "linear"}

_TOL = 1e-12


def _vec(v: Any) -> str:
    return "[" + ", ".join(f"{float(c):g}" for c in v) + "]"


def _in_plane(key: str, v: Any, what: str) -> None:
    """A direction or velocity of the plane: z component 0."""
    if abs(float(v[2])) > _TOL * max(1.0, max(abs(float(c)) for c in v)):
        raise ValueError(
            f"{key}: {_vec(v)} has a z component; in a 2D case {what} must lie in the x-y "
            "plane: give [x, y] or [x, y, 0]"
        )


def _along_z(key: str, v: Any, what: str) -> None:
    """An axis normal to the plane: x and y components 0."""
    if abs(float(v[0])) > _TOL or abs(float(v[1])) > _TOL:
        raise ValueError(
            f"{key}: {_vec(v)}; in a 2D case {what} must be the z axis [0, 0, 1] (a circle in "
            "the x-y plane)"
        )


def _check_walls(case: Case) -> None:
    for k, w in enumerate(case.walls):
        key = f"walls.{k}"
        _in_plane(f"{key}.velocity", w.velocity, "a wall velocity")
        if w.kind == "plane":
            _in_plane(f"{key}.normal", w.normal, "the normal of a plane (a line)")
        elif w.kind == "rectangle":
            _in_plane(f"{key}.normal", w.normal, "the normal of a rectangle (a segment)")
            u = w.u_axis
            in_plane = abs(float(u[2])) <= _TOL * max(abs(float(c)) for c in u)
            if not in_plane:
                try:
                    _along_z(f"{key}.u_axis", u, "")
                except ValueError:
                    raise ValueError(
                        f"{key}.u_axis: {_vec(u)}; in a 2D case a rectangle is a segment in the "
                        "x-y plane: u_axis must lie in the plane (the segment's direction, "
                        "half_extents[0] its half length) or be the z axis (half_extents[1] "
                        "the half length)"
                    ) from None
        elif w.kind == "cylinder":
            _along_z(f"{key}.axis", w.axis, "the axis of a cylinder wall")


def _check_insertion(case: Case) -> None:
    for k, e in enumerate(case.insertion):
        key = f"insertion.{k}"
        _in_plane(f"{key}.velocity", e.velocity, "an initial velocity")
        if e.kind == "random_cylinder":
            _along_z(f"{key}.axis", e.axis, "the axis of a random_cylinder region")
        elif e.kind == "pour" and e.region.kind == "cylinder":
            _along_z(f"{key}.region.axis", e.region.axis, "the axis of a cylinder region")
        elif e.kind == "lattice" and e.count is not None and e.count[2] != 1:
            raise ValueError(
                f"{key}.count: {list(e.count)}; a 2D lattice has one layer: give [nx, ny]"
            )
        elif e.kind == "list":
            for i, x in enumerate(e.positions):
                if float(x[2]) != 0.0:
                    raise ValueError(
                        f"{key}.positions.{i}: {_vec(x)}; in a 2D case particles lie in the "
                        "plane z = 0: give [x, y] or [x, y, 0]"
                    )
            for i, v in enumerate(e.velocities or ()):
                _in_plane(f"{key}.velocities.{i}", v, "an initial velocity")


def _check_external_force(case: Case) -> None:
    for k, entry in enumerate(case.external_force):
        _in_plane(f"external_force.{k}.force", entry.force, "a force")
        t = entry.torque
        if abs(float(t[0])) > 0.0 or abs(float(t[1])) > 0.0:
            raise ValueError(
                f"external_force.{k}.torque: {_vec(t)}; in a 2D case a torque turns the "
                "particles about z: give [0, 0, tz]"
            )


def selected_models(case: Case) -> list[tuple[str, ModelChoice]]:
    """(key, choice) of every model the case selects (contact laws and thermal families)."""
    from thermodem.config.schema import ModelChoice

    out: list[tuple[str, ModelChoice]] = [
        (f"contact.{name}", getattr(case.contact, name))
        for name in ("normal", "tangential", "rolling")
    ]
    th = case.thermal
    if th is not None:
        for name in type(th).model_fields:
            value = getattr(th, name)
            if isinstance(value, ModelChoice):
                out.append((f"thermal.{name}", value))
    return out


def _check_models(case: Case) -> None:
    from thermodem.config.schema import parse_model_choice

    shape = case.simulation.particle_shape
    if shape == "disc":
        for name, model in DISC_CONTACT_DEFAULTS.items():
            if name not in case.contact.model_fields_set:
                setattr(case.contact, name, parse_model_choice(name, model, model))
    words = {"disc": "discs", "sphere": "spheres kept in the plane"}
    for key, choice in selected_models(case):
        spec = choice.spec
        if shape in spec.planar:
            continue
        allowed = [
            m.name for m in registry.all_models() if m.family == spec.family and shape in m.planar
        ]
        other = [s for s in spec.planar if s != shape]
        hint = (
            f" (it runs with simulation.particle_shape: {other[0]})"
            if other
            else " (it has no 2D form: 3D only)"
        )
        section, _, field = key.partition(".")
        given = getattr(case, section).model_fields_set
        default = "" if field in given else " (the default: name a model of 2D)"
        raise ValueError(
            f"{key}: model {choice.model!r}{default} is not available in a 2D case of "
            f"{words[shape]}{hint}; allowed with simulation.dimension: 2 and particle_shape: "
            f"{shape}: {', '.join(allowed)} (docs/two-dimensional.md)"
        )


def check_planar_case(case: Case) -> None:
    """All checks of a 2D case (raise ValueError naming the key); sets the 2D contact
    defaults of discs."""
    if case.domain.periodic[2]:
        raise ValueError(
            f"domain.periodic: {list(case.domain.periodic)}; a 2D case has no z axis to be "
            "periodic: give [px, py]"
        )
    _check_walls(case)
    _check_insertion(case)
    _check_external_force(case)
    _check_models(case)


def check_not_planar(case: Case) -> None:
    """A 3D case must not select a 2D-only law (``hertz_2d``)."""
    for key, choice in selected_models(case):
        if choice.spec.only_2d:
            raise ValueError(
                f"{key}: model {choice.model!r} is a law of 2D cases (discs); set "
                "simulation.dimension: 2 or choose a 3D model"
            )
