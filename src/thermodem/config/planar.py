"""Two-dimensional cases (``simulation.dimension: 2``): the validation context and the vectors
that may be given with two components.

A 2D case is read with the pydantic validation context ``{"dimension": 2}``
(:func:`thermodem.config.load.case_from_dict` reads ``simulation.dimension`` first). In that
context

- a vector of the case (:data:`Vec3`: points, directions, velocities, box corners) may be
  given as ``[x, y]``; it is read as ``[x, y, 0]``;
- the checks of boxes that need ``lower < upper`` on every axis skip z (:func:`box_axes`):
  the particles live in the plane z = 0, a box's z extent means nothing there.

Outside that context (3D cases, models built directly in Python) nothing changes: a vector
needs three components and boxes are checked on every axis. The 2D physics is described in
``docs/two-dimensional.md``.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, FiniteFloat, ValidationInfo

DIMENSION_KEY = "dimension"


def is_planar(info: ValidationInfo | None) -> bool:
    """Whether the case being validated is two-dimensional (from the validation context)."""
    if info is None:
        return False
    context = info.context
    return isinstance(context, dict) and context.get(DIMENSION_KEY) == 2


def _pad_planar(value: Any, info: ValidationInfo) -> Any:
    """``[x, y]`` -> ``[x, y, 0]`` in a 2D case (anything else is left to the type check)."""
    if is_planar(info) and isinstance(value, list | tuple) and len(value) == 2:
        return (value[0], value[1], 0.0)
    return value


Vec3 = Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], BeforeValidator(_pad_planar)]
"""Three finite floats; in a 2D case also ``[x, y]`` (read as ``[x, y, 0]``)."""


def box_axes(info: ValidationInfo | None) -> str:
    """The axes on which a box must have ``lower < upper``: ``"xy"`` in 2D, else ``"xyz"``."""
    return "xy" if is_planar(info) else "xyz"


def validation_context(data: Any) -> dict[str, Any] | None:
    """The validation context of a raw case mapping: ``{"dimension": 2}`` for a 2D case, else
    None (a malformed ``simulation.dimension`` is reported by the schema itself)."""
    if isinstance(data, dict):
        sim = data.get("simulation")
        if isinstance(sim, dict) and sim.get("dimension") == 2:
            return {DIMENSION_KEY: 2}
    return None
