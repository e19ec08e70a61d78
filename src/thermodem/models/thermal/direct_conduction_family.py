"""What every ``direct_conduction`` model shares: the family name, the row head (``k_i, k_j,
rhoc_i, rhoc_j``: :data:`HEAD`, indices :data:`K_I`, :data:`K_J`, :data:`RHOC_I`,
:data:`RHOC_J`), the swap pairs of antisymmetry and :func:`register_model`.

The family's conventions (kernel signature, antisymmetry, row layout) are written in the
docstring of ``direct_conduction.py``; the models are in ``direct_conduction.py``,
``batchelor_obrien_contact.py`` and ``resistance_network.py``. Not a model: no
``register()`` call here.
"""

from __future__ import annotations

import numpy as np

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.models.thermal.contact_radius import require
from thermodem.state.materials import PairContext

FAMILY = "direct_conduction"
SWAP_PAIRS = ((0, 1), (2, 3))

#: The columns every row of the family starts with (the override replaces them).
HEAD = ("k_i", "k_j", "rhoc_i", "rhoc_j")
K_I, K_J, RHOC_I, RHOC_J = 0, 1, 2, 3

#: 2D (``planar``) default of :func:`register_model`: the conduction between spheres (the 3D
#: form holds for spheres kept in a plane, refused for discs).
_SPHERE = ("sphere",)


def swap_row(row: np.ndarray, swap_pairs: tuple[tuple[int, int], ...] = SWAP_PAIRS) -> np.ndarray:
    """The row of the swapped pair (j, i): columns of each pair in ``swap_pairs`` exchanged."""
    out = np.array(row, dtype=np.float64, copy=True)
    for a, b in swap_pairs:
        out[a], out[b] = row[b], row[a]
    return out


def conductivities(pair: PairContext, model: str) -> list[float]:
    return [require(m, "thermal_conductivity", model) for m in (pair.mat_i, pair.mat_j)]


def heat_capacities(pair: PairContext, model: str) -> list[float]:
    return [m.density * require(m, "specific_heat", model) for m in (pair.mat_i, pair.mat_j)]


def head_values(k: list[float], rhoc: tuple[float, float] = (0.0, 0.0)) -> dict[str, float]:
    """The family's head columns from the two conductivities (and heat capacities)."""
    return {"k_i": k[0], "k_j": k[1], "rhoc_i": rhoc[0], "rhoc_j": rhoc[1]}


def register_model(name, model_id, kernel, params, summary, reference, pack=None, **kw):
    """register() with this family's swap pairs; default pack: [k_i, k_j]."""

    def pack_k(params: StrictModel, pair: PairContext) -> np.ndarray:
        return packed(HEAD, head_values(conductivities(pair, f"{FAMILY}.{name}")))

    kw.setdefault("requires", ("thermal_conductivity",))
    kw.setdefault("columns", HEAD)
    kw.setdefault("planar", _SPHERE)
    register(family=FAMILY, name=name, model_id=model_id, kernel=kernel, params=params,
             pack=pack or pack_k, summary=summary, reference=reference, swap_pairs=SWAP_PAIRS,
             **kw)  # fmt: skip
