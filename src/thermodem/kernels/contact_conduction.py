"""Contact conduction of one touching pair inside the contact passes, with the conductance
reuse of ``thermal.conductance_force_tolerance`` (docs/models/conductance_reuse.md).

:func:`_pp_conductance` (particle pairs) and :func:`_pw_conductance` (particle-wall pairs)
return the conductance H of :func:`thermodem.kernels.conduction.pair_conductance`, or, with a
tolerance, its reuse from the contact's ``reuse`` history block (state/history.py). Used by the
fused contact pass (``kernels/pair_pass.py``) and the heat-only conduction passes
(``kernels/thermal.py``).
"""

from __future__ import annotations

import math

from numba import njit

from thermodem.kernels.conduction import pair_conductance
from thermodem.kernels.contact import H_DURATION, H_IMPACT_VELOCITY
from thermodem.models import registry


@njit(cache=True, inline="always", error_model="numpy")
def _reused_conductance(k, history, col, f_n, tolerance):
    """(H, True) from the stored evaluations of pair k when its normal force f_n > 0 is close
    to the last evaluated one, else (0, False): the conductance reuse of
    ``thermal.conductance_force_tolerance`` (docs/models/conductance_reuse.md). ``col``: the
    first history column of the reuse block (reference normal force, negative while there is
    no slope; conductance there; slope dH/dF_n of the secant through the last two
    evaluations; state/history.py).

    With a slope: H = H_ref + S (f_n - F_ref) while |f_n - F_ref| <= tol F_ref. Without one
    (a single evaluation so far, or a jump): H = H_ref while |f_n - F_ref| <= tol² F_ref.
    """
    f_ref = history[k, col]
    df = f_n - abs(f_ref)
    if f_ref > 0.0:
        if abs(df) <= tolerance * f_ref:
            return history[k, col + 1] + history[k, col + 2] * df, True
    elif f_ref < 0.0 and abs(df) <= -tolerance * tolerance * f_ref:
        return history[k, col + 1], True
    return 0.0, False


@njit(cache=True, inline="always", error_model="numpy")
def _store_evaluation(k, history, col, f_n, h, tolerance):
    """Keep the evaluation (f_n, H) of pair k, with the secant slope from the previous one when
    the two forces are within 2 tol f_n of each other (else: no slope)."""
    f_ref = abs(history[k, col])
    df = f_n - f_ref
    if f_ref > 0.0 and df != 0.0 and abs(df) <= 2.0 * tolerance * f_n:
        history[k, col + 2] = (h - history[k, col + 1]) / df
        history[k, col] = f_n
    else:
        history[k, col + 2] = 0.0
        history[k, col] = -f_n
    history[k, col + 1] = h


@njit(cache=True, inline="always", error_model="numpy")
def _conductance(
    k, history, reuse_col, tolerance, ri, rj, dist, overlap, eff_mass, f_n, radius_id, p_radius,
    conduction_id, p_conduction, override, ki, kj, ci, cj, srow,
):  # fmt: skip
    """:func:`pair_conductance` of pair k, or its reuse (``tolerance`` > 0, touching pairs;
    ``reuse_col``: the reuse block's first history column, state/history.py)."""
    reuse = tolerance > 0.0 and f_n > 0.0
    if reuse:
        h, found = _reused_conductance(k, history, reuse_col, f_n, tolerance)
        if found:
            return h
    h = pair_conductance(
        ri, rj, dist, overlap, eff_mass, f_n, history[k, H_DURATION],
        history[k, H_IMPACT_VELOCITY], radius_id, p_radius, conduction_id, p_conduction,
        override, ki, kj, ci, cj, srow,
    )  # fmt: skip
    if reuse:
        _store_evaluation(k, history, reuse_col, f_n, h, tolerance)
    return h


@njit(cache=True, inline="always", error_model="numpy")
def _pp_conductance(
    k, i, j, ri, rj, dist, overlap, eff_mass, type_id, history, normal_force, radius_id,
    radius_table, conduction_id, conduction_table, override, k_particle, rhoc_particle, srow,
    reuse_col, tolerance,
):  # fmt: skip
    ti = type_id[i]
    tj = type_id[j]
    ki = kj = ci = cj = 0.0
    if override > 0:
        ki = k_particle[i]
        kj = k_particle[j]
        if override > 1:
            ci = rhoc_particle[i]
            cj = rhoc_particle[j]
    return _conductance(
        k, history, reuse_col, tolerance, ri, rj, dist, overlap, eff_mass, normal_force[k],
        radius_id, radius_table[ti, tj], conduction_id, conduction_table[ti, tj], override, ki,
        kj, ci, cj, srow,
    )  # fmt: skip


@njit(cache=True, inline="always", error_model="numpy")
def _pw_conductance(
    k, i, w, ri, d, overlap, mass, type_id, wall_material, history, normal_force, radius_id,
    radius_table, conduction_id, conduction_table, override, k_particle, rhoc_particle, k_wall,
    rhoc_wall, srow, reuse_col, tolerance,
):  # fmt: skip
    ti = type_id[i]
    tw = wall_material[w]
    ki = kw = ci = cw = 0.0
    if override > 0:
        ki = k_particle[i]
        kw = k_wall[w]
        if override > 1:
            ci = rhoc_particle[i]
            cw = rhoc_wall[w]
    return _conductance(
        k, history, reuse_col, tolerance, ri, math.inf, d, overlap, mass[i], normal_force[k],
        radius_id, radius_table[ti, tw], conduction_id, conduction_table[ti, tw], override, ki,
        kw, ci, cw, srow,
    )  # fmt: skip


def reusable(conduction_id: int) -> bool:
    """Whether the direct-conduction model of this id allows the conductance reuse."""
    specs = [m for m in registry.all_models() if m.family == "direct_conduction"]
    return any(m.model_id == conduction_id and m.conductance_from_force for m in specs)
