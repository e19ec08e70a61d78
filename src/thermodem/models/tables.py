"""Parameter tables: one packed row per material pair for a selected model."""

from __future__ import annotations

import numpy as np

from thermodem.config.schema import Case, ModelChoice
from thermodem.models import registry
from thermodem.state.materials import resolve_pair


def pair_table(choice: ModelChoice, case: Case, names: list[str]) -> np.ndarray:
    """[nmat, nmat, PARAM_WIDTH] parameter rows of one model for every material pair."""
    spec = choice.spec
    n = len(names)
    table = np.zeros((n, n, registry.PARAM_WIDTH))
    overrides = {frozenset(o.materials): o for o in case.interactions}
    gas = case.thermal.gas if case.thermal is not None else None  # None: default air
    for a in range(n):
        for b in range(n):
            ma = case.materials[names[a]]
            mb = case.materials[names[b]]
            override = overrides.get(frozenset((names[a], names[b])))
            pair = resolve_pair(ma, mb, override, gas=gas)
            table[a, b] = spec.pack(choice.params, pair)
    return table
