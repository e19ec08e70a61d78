"""The conductance of one pair, shared by the fused contact pass and the heat-only passes.

The contact radius and direct-conduction models are called through :func:`radius_of` and
:func:`rate_of`. Where the model id is a compile-time constant (the pair passes compiled per
model combination, :func:`thermodem.kernels.pair_pass.passes_for`), they resolve to an inlined
copy of that one model's kernel: a real call per contact cost the simple models ~8 ns per
particle-step (50,000-sphere bed, Batchelor & O'Brien simple with the geometric radius: pair
pass 153-160 -> 144-146 ns), and only the selected model is compiled into the loop. Where the
id is a run-time value (the generic wall passes, the unit tests) they are the families'
integer-switch dispatchers. A kernel should call :func:`pair_conductance` at one place only:
Numba's SSA pass warns (an internal pedantic check) when the inlined selection appears twice
in one function.
"""

from __future__ import annotations

from typing import Any

from numba import njit, types
from numba.extending import overload

from thermodem.models import registry
from thermodem.models.thermal.contact_radius import contact_radius_dispatch
from thermodem.models.thermal.direct_conduction import direct_conduction_dispatch
from thermodem.models.thermal.direct_conduction_family import K_I, K_J, RHOC_I, RHOC_J

_INLINE: dict[tuple[str, int], Any] = {}


def _inline_kernel(family: str, model_id: int) -> Any:
    """The registered kernel of (family, model id), compiled to be inlined into its caller."""
    key = (family, model_id)
    if key not in _INLINE:
        (spec,) = [m for m in registry.all_models() if (m.family, m.model_id) == key]
        _INLINE[key] = njit(inline="always", error_model="numpy")(spec.kernel.py_func)
    return _INLINE[key]


def radius_of(model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN201
    """Contact radius of model ``model_id`` (compiled code only: see the module docstring)."""


def rate_of(model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN201
    """Heat rate into i of model ``model_id`` (compiled code only: see the module docstring)."""


@overload(radius_of, inline="always", prefer_literal=True)
def _radius_of(model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN202
    if isinstance(model_id, types.IntegerLiteral):
        kernel = _inline_kernel("contact_radius", model_id.literal_value)

        def selected(model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN202
            return kernel(p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff)

        return selected

    def switch(model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN202
        return contact_radius_dispatch(
            model_id, p, r_i, r_j, dist, overlap, f_n, t_contact, v_impact, m_eff
        )

    return switch


@overload(rate_of, inline="always", prefer_literal=True)
def _rate_of(model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff):  # noqa: ANN001, ANN202, E501
    if isinstance(model_id, types.IntegerLiteral):
        kernel = _inline_kernel("direct_conduction", model_id.literal_value)

        def selected(
            model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
        ):  # noqa: ANN001, ANN202
            return kernel(
                p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
            )

        return selected

    def switch(
        model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
    ):  # noqa: ANN001, ANN202
        return direct_conduction_dispatch(
            model_id, p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v_impact, m_eff
        )

    return switch


@njit(cache=True, inline="always", error_model="numpy")
def pair_conductance(
    ri, rj, dist, overlap, m_eff, f_n, duration, v_imp, radius_id, p_radius, conduction_id,
    p_conduction, override, k_i, k_j, rhoc_i, rhoc_j, row,
):  # fmt: skip
    """Conductance H [W/K] of a pair: the direct-conduction model at T_i = 0, T_j = 1.

    Every direct-conduction model of the spec is linear in T_j - T_i, so Q = H (T_j - T_i).
    The contact radius model is evaluated for touching pairs only (r_c = 0 otherwise). With
    ``override`` > 0 the conductivity columns (``k_i``, ``k_j``) of the model's row are replaced
    by the current k(T) of the two bodies, with ``override`` > 1 also the heat capacity columns
    (``rhoc_i``, ``rhoc_j``) by ρ c(T); ``row`` is the scratch row used for that.
    """
    r_c = 0.0
    if overlap > 0.0:
        r_c = radius_of(radius_id, p_radius, ri, rj, dist, overlap, f_n, duration, v_imp, m_eff)
    p = p_conduction
    if override > 0:
        for q in range(p_conduction.shape[0]):
            row[q] = p_conduction[q]
        row[K_I] = k_i
        row[K_J] = k_j
        if override > 1:
            row[RHOC_I] = rhoc_i
            row[RHOC_J] = rhoc_j
        p = row
    return rate_of(conduction_id, p, 0.0, 1.0, ri, rj, dist, overlap, r_c, f_n, duration, v_imp,
                   m_eff)  # fmt: skip
