"""Shared pydantic base for every case-file section: unknown keys are errors, and every float
must be finite (``.inf``, ``.nan`` and the strings ``"inf"``/``"nan"`` are refused with the key
path) unless a field allows infinity explicitly (``ExternalSource.end_time``). A boolean
(``true``, and YAML 1.1's ``yes``/``on``) is refused where a number is expected: pydantic's
lax mode would read it as 1 (``density: true`` became 1 kg/m³, ``count: [true, 2, 2]`` one
site)."""

from __future__ import annotations

import types
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel, ConfigDict, model_validator


def _members(tp: Any) -> list[Any]:
    """The members of a union (``Annotated`` and ``Optional`` unwrapped), or [tp]."""
    while get_origin(tp) is Annotated:
        tp = get_args(tp)[0]
    if get_origin(tp) in (Union, types.UnionType):
        out: list[Any] = []
        for arg in get_args(tp):
            out += _members(arg)
        return out
    return [tp]


def _takes_bool(members: list[Any]) -> bool:
    """Whether one of the types takes a boolean as itself (bool, Any, a literal true/false),
    or takes no number at all (then pydantic's own error applies)."""
    numbers = False
    for tp in members:
        if tp is bool or tp is Any or tp is object:
            return True
        if get_origin(tp) is Literal and any(isinstance(a, bool) for a in get_args(tp)):
            return True
        if tp is int or tp is float:
            numbers = True
    return not numbers


def misplaced_bool(tp: Any, value: Any, path: str = "") -> str | None:
    """Where ``value`` holds a boolean that type ``tp`` would read as a number: '' for the
    value itself, ``.1`` for item 1 of a list, None when there is none. Nested sections
    (models) check their own keys."""
    members = _members(tp)
    if isinstance(value, bool):
        return None if _takes_bool(members) else path
    if isinstance(value, list | tuple):
        found: str | None = None
        for member in members:
            origin, args = get_origin(member), get_args(member)
            if origin in (list, set, frozenset) and args:
                where = [misplaced_bool(args[0], v, f"{path}.{k}") for k, v in enumerate(value)]
            elif origin is tuple and args:
                if len(args) == 2 and args[1] is Ellipsis:
                    item_types = [args[0]] * len(value)
                else:
                    item_types = list(args[: len(value)])
                where = [
                    misplaced_bool(t, v, f"{path}.{k}")
                    for k, (t, v) in enumerate(zip(item_types, value, strict=False))
                ]
            else:
                continue
            bad = [w for w in where if w is not None]
            if not bad:
                return None  # a member that takes the list as it is
            found = found if found is not None else bad[0]
        return found
    if isinstance(value, dict):
        for member in members:
            if get_origin(member) is dict and len(get_args(member)) == 2:
                value_type = get_args(member)[1]
                for key, v in value.items():
                    where = misplaced_bool(value_type, v, f"{path}.{key}")
                    if where is not None:
                        return where
        return None
    return None


class StrictModel(BaseModel):
    """A case-file section: unknown keys are rejected, floats must be finite, booleans are
    not numbers, values validated on assignment."""

    model_config = ConfigDict(
        extra="forbid", validate_assignment=True, frozen=False, allow_inf_nan=False
    )

    @model_validator(mode="before")
    @classmethod
    def _no_boolean_numbers(cls, data: Any) -> Any:
        """``KEY: a boolean where a number is expected`` (a model validator: the discriminator
        ``kind`` of a tagged union may not have a field validator)."""
        if not isinstance(data, dict):
            return data
        for key, value in data.items():
            if not isinstance(value, bool | list | tuple | dict):
                continue
            field = cls.model_fields.get(key) if isinstance(key, str) else None
            if field is None:
                continue
            where = misplaced_bool(field.annotation, value)
            if where is not None:
                item = value
                for part in where.split(".")[1:]:
                    item = item[int(part)] if isinstance(item, list | tuple) else item[part]
                raise ValueError(
                    f"{key}{where}: a boolean where a number is expected (got {item!r}); "
                    "write the number (true/false, yes/no and on/off are booleans in YAML)"
                )
        return data
