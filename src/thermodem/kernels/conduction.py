"""The conductance of one pair, shared by the fused contact pass and the heat-only passes."""

from __future__ import annotations

from numba import njit

from thermodem.models.thermal.contact_radius import contact_radius_dispatch
from thermodem.models.thermal.direct_conduction import direct_conduction_dispatch


@njit(cache=True, inline="always", error_model="numpy")
def pair_conductance(
    ri, rj, dist, overlap, m_eff, f_n, duration, v_imp, radius_id, p_radius, conduction_id,
    p_conduction, override, k_i, k_j, rhoc_i, rhoc_j, row,
):  # fmt: skip
    """Conductance H [W/K] of a pair: the direct-conduction model at T_i = 0, T_j = 1.

    Every direct-conduction model of the spec is linear in T_j - T_i, so Q = H (T_j - T_i).
    The contact radius model is evaluated for touching pairs only (r_c = 0 otherwise). With
    ``override`` > 0 the conductivity columns (0, 1) of the model's row are replaced by the
    current k(T) of the two bodies, with ``override`` > 1 also the heat capacity columns (2, 3)
    by ρ c(T); ``row`` is the scratch row used for that.
    """
    r_c = 0.0
    if overlap > 0.0:
        r_c = contact_radius_dispatch(radius_id, p_radius, ri, rj, dist, overlap, f_n, duration,
                                      v_imp, m_eff)  # fmt: skip
    p = p_conduction
    if override > 0:
        for q in range(p_conduction.shape[0]):
            row[q] = p_conduction[q]
        row[0] = k_i
        row[1] = k_j
        if override > 1:
            row[2] = rhoc_i
            row[3] = rhoc_j
        p = row
    return direct_conduction_dispatch(conduction_id, p, 0.0, 1.0, ri, rj, dist, overlap, r_c,
                                      f_n, duration, v_imp, m_eff)  # fmt: skip
