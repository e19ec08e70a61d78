"""A validated case back to plain data / YAML, with every default filled in.

Model choices (``contact.normal``, ``thermal.direct_conduction``, ...) become
``{model: NAME, <every parameter>}``, the form the case file accepts, so
``case_from_dict(yaml.safe_load(resolved_case_yaml(case)))`` gives the same case back.
Floats are written exactly (YAML uses ``repr``), including ``.inf``.
"""

from __future__ import annotations

from pathlib import PurePath
from typing import Any

import yaml
from pydantic import BaseModel


def case_to_dict(value: Any) -> Any:
    """Plain data (dicts, lists, scalars) of a case or any part of it."""
    from thermodem.config.schema import ModelChoice

    if isinstance(value, ModelChoice):
        return {"model": value.model, **case_to_dict(value.params)}
    if isinstance(value, BaseModel):
        names = [n for n in type(value).model_fields if n not in _omitted(value)]
        return {name: case_to_dict(getattr(value, name)) for name in names}
    if isinstance(value, dict):
        return {str(k): case_to_dict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [case_to_dict(v) for v in value]
    if isinstance(value, PurePath):
        return str(value)
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)


#: Keys of 2D cases only (``simulation.dimension: 2``): left out of a 3D case, which refuses
#: them.
_PLANAR_ONLY = ("thickness", "particle_shape")


def _omitted(value: BaseModel) -> tuple[str, ...]:
    from thermodem.config.insertion import ListInsertion
    from thermodem.config.schema import Case, SimulationSettings
    from thermodem.state.materials import Material

    if isinstance(value, SimulationSettings) and not value.planar:
        return _PLANAR_ONLY
    if isinstance(value, ListInsertion) and value.velocities is not None:
        return ("velocity",)  # (one per position given: the entry refuses both)
    if isinstance(value, Case) and value.thermal is None:
        return ("thermal",)  # absent: mechanics only (an explicit null is warned about)
    if isinstance(value, Material):  # a table's first value, filled in as the reference
        return tuple(
            name
            for name in ("thermal_conductivity", "specific_heat")
            if getattr(value, f"{name}_table") and name not in value.model_fields_set
        )
    return ()


def resolved_case_yaml(case: BaseModel) -> str:
    """The case with every default filled in, as YAML."""
    return yaml.safe_dump(case_to_dict(case), sort_keys=False, allow_unicode=True)
