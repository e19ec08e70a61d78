"""Indirect conduction models (family ``indirect_conduction``): heat through the fluid between
near or touching particles.

Kernel signature (float64 scalars, ``p`` the packed row of the type pair)::

    kernel(p, r_i, r_j, dist, r_c, f_n) -> conductance H [W/K], heat into i = H (T_j - T_i)

``r_j = inf`` for a flat wall (``dist``: centre to wall plane); ``r_c`` the contact radius when
the bodies overlap, else 0; ``f_n`` the normal force (0 where unknown).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.state.materials import PairContext

NONE = 0

FAMILY = "indirect_conduction"


class NoneParams(StrictModel):
    """No indirect conduction."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def none_conductance(p, r_i, r_j, dist, r_c, f_n):
    return 0.0


@njit(cache=True, inline="always", error_model="numpy")
def indirect_conduction_dispatch(model_id, p, r_i, r_j, dist, r_c, f_n):
    """Conductance of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    if model_id == NONE:
        return 0.0
    return np.nan


register(
    family=FAMILY,
    name="none",
    model_id=NONE,
    kernel=none_conductance,
    params=NoneParams,
    pack=pack_none,
    summary="no indirect conduction",
    reference="-",
    columns=(),
    target="range",
)
