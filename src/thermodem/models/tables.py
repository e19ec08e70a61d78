"""Parameter tables: one packed row per material pair for a selected model.

One builder for every family (mechanics and thermal): it resolves each material pair with the
mixing rules and the case's ``interactions`` overrides (``state/materials.py``) and the case
gas, and calls the model's ``pack``. The row width comes from the model's registered columns
(``ModelSpec.width``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from thermodem.config.schema import Case, ModelChoice
from thermodem.errors import ConfigError
from thermodem.state.materials import resolve_pair


def pair_table(
    choice: ModelChoice,
    case: Case,
    names: list[str],
    meets: Callable[[str, str], bool] | None = None,
    is_wall: Callable[[str, str], bool] | None = None,
    key: str | None = None,
) -> np.ndarray:
    """[nmat, nmat, width] parameter rows of one model for every material pair.

    ``meets(a, b)``: whether materials a and b can meet (rows of the others stay zero, and
    their properties are not required); ``is_wall(a, b)``: whether b is met as a wall only.
    A ``pack`` that refuses a pair (ValueError) becomes a ConfigError naming ``key``.
    """
    spec = choice.spec
    n = len(names)
    table = np.zeros((n, n, spec.width))
    overrides = {frozenset(o.materials): o for o in case.interactions}
    gas = case.thermal.gas if case.thermal is not None else None  # None: default air
    thickness = case.simulation.disc_thickness  # 2D discs: b; else 0
    for a in range(n):
        for b in range(n):
            if meets is not None and not meets(names[a], names[b]):
                continue
            ma = case.materials[names[a]]
            mb = case.materials[names[b]]
            override = overrides.get(frozenset((names[a], names[b])))
            wall = is_wall(names[a], names[b]) if is_wall is not None else False
            pair = resolve_pair(ma, mb, override, is_wall=wall, gas=gas, thickness=thickness)
            try:
                row = spec.pack(choice.params, pair)
            except ValueError as exc:
                where = key or f"{choice.family}"
                raise ConfigError(
                    f"{where} = {choice.model!r} cannot be set up for materials {names[a]!r} "
                    f"and {names[b]!r}: {exc}"
                ) from None
            if row.shape != (spec.width,):
                raise AssertionError(
                    f"{choice.family}.{choice.model}: pack returned {row.shape[0]} values for "
                    f"the {spec.width} columns {spec.columns}"
                )
            table[a, b] = row
    return table


def material_table(
    choice: ModelChoice, case: Case, names: list[str], used: Callable[[str], bool], key: str
) -> np.ndarray:
    """[nmat, width] rows of a per-particle model, one per material (``used(name)``: the
    materials particles are made of; the others stay zero). ``pack`` receives the material
    as both sides of a PairContext, with the case gas."""
    spec = choice.spec
    table = np.zeros((len(names), spec.width))
    gas = case.thermal.gas if case.thermal is not None else None
    for a, name in enumerate(names):
        if not used(name):
            continue
        material = case.materials[name]
        try:
            table[a] = spec.pack(choice.params, resolve_pair(material, material, gas=gas))
        except ValueError as exc:
            raise ConfigError(
                f"{key} = {choice.model!r} cannot be set up for material {name!r}: {exc}"
            ) from None
    return table
