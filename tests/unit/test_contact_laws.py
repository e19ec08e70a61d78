"""Contact-law kernels (models/mechanics) at a few points against hand evaluations written here
with plain math: the Hertz force and its Tsuji damping (spec appendix A: F_n = K_HZ δ^{3/2},
K_HZ = (4/3) E* sqrt(R*), δ_n = (9/16 F_n²/(R* E*²))^{1/3}), the Mindlin no-slip tangential
stiffness 8 G* sqrt(R* δ), and the two rolling resistance laws of Ai et al. (2011).
Effective moduli from E and ν by hand (appendix A: E* = [(1 - ν_i²)/E_i + (1 - ν_j²)/E_j]^-1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from thermodem.models.mechanics import normal, rolling, tangential
from thermodem.state.materials import Material, resolve_pair

E_I, NU_I, E_J, NU_J = 7.0e10, 0.3, 2.0e11, 0.28
R_I, R_J = 1.0e-3, 3.0e-3
R_EFF = R_I * R_J / (R_I + R_J)  # 7.5e-4
M_EFF = 2.0e-6


def pair():
    mi = Material(density=2500.0, youngs_modulus=E_I, poisson_ratio=NU_I, restitution=0.7,
                  sliding_friction=0.4, rolling_friction=0.02)  # fmt: skip
    mj = Material(density=7800.0, youngs_modulus=E_J, poisson_ratio=NU_J, restitution=0.5,
                  sliding_friction=0.2, rolling_friction=0.04)  # fmt: skip
    return resolve_pair(mi, mj)


def e_star() -> float:
    return 1.0 / ((1.0 - NU_I**2) / E_I + (1.0 - NU_J**2) / E_J)


def g_star() -> float:
    g_i = E_I / (2.0 * (1.0 + NU_I))
    g_j = E_J / (2.0 * (1.0 + NU_J))
    return 1.0 / ((2.0 - NU_I) / g_i + (2.0 - NU_J) / g_j)


def test_hertz_force_damping_and_energy_by_hand():
    p = normal.pack_hertz(normal.HertzParams(), pair())
    assert p[normal.HERTZ_E_STAR] == pytest.approx(e_star(), rel=1e-14)
    alpha = p[normal.HERTZ_ALPHA]
    assert 0.0 < alpha < 4.0
    delta, rate = 2.0e-6, 0.3
    f_el, f_d, secant, gamma, energy, _, plastic = normal.hertz_force(
        p, delta, rate, R_EFF, M_EFF, 0.0
    )
    k_hz = 4.0 / 3.0 * e_star() * math.sqrt(R_EFF)
    assert f_el == pytest.approx(k_hz * delta**1.5, rel=1e-14)
    assert secant == pytest.approx(k_hz * math.sqrt(delta), rel=1e-14)
    # Tsuji et al. (1992): η_n = α sqrt(m* K_HZ) δ^{1/4}
    assert gamma == pytest.approx(alpha * math.sqrt(M_EFF * k_hz) * delta**0.25, rel=1e-14)
    assert f_d == pytest.approx(gamma * rate, rel=1e-15)
    assert energy == pytest.approx(0.4 * k_hz * delta**2.5, rel=1e-14)  # ∫ F dδ
    assert plastic == 0.0
    # the spec's static overlap at that force: (9/16 F²/(R* E*²))^{1/3} = δ
    static = (9.0 / 16.0 * f_el**2 / (R_EFF * e_star() ** 2)) ** (1.0 / 3.0)
    assert static == pytest.approx(delta, rel=1e-13)


def test_hertz_quasi_static_maximum_overlap_by_hand():
    """Appendix A: δ_max = (15/16 m* v² / (sqrt(R*) E*))^{2/5} = (R_c^max)²/R*."""
    v = 0.8
    d_max = normal.hertz_max_overlap(M_EFF, R_EFF, e_star(), v)
    hand = (15.0 / 16.0 * M_EFF * v * v / (math.sqrt(R_EFF) * e_star())) ** 0.4
    assert d_max == pytest.approx(hand, rel=1e-14)
    r_max = (15.0 / 16.0 * M_EFF * R_EFF**2 / e_star() * v * v) ** 0.2
    assert d_max == pytest.approx(r_max**2 / R_EFF, rel=1e-13)


def _mindlin(p, k_n, gamma_n, delta, f_n, v, s, dt):
    return tangential.mindlin(p, k_n, gamma_n, R_EFF, delta, f_n, *v, *s, dt)


def test_mindlin_stiffness_and_coulomb_cap_by_hand():
    p = tangential.pack_mindlin(tangential.MindlinParams(), pair())
    assert p[tangential.MINDLIN_G_STAR] == pytest.approx(g_star(), rel=1e-14)
    mu = 0.5 * (0.4 + 0.2)  # arithmetic mean of the two materials
    assert p[tangential.MINDLIN_FRICTION] == pytest.approx(mu, rel=1e-15)
    delta, dt = 2.0e-6, 1.0e-7
    k_t = 8.0 * g_star() * math.sqrt(R_EFF * delta)
    k_n, gamma_n = 4.0e5, 0.05
    gamma_t = gamma_n * math.sqrt(k_t / k_n)
    v = np.array([1e-3, -2e-3, 0.5e-3])
    s = np.array([1e-9, 0.0, -2e-9])
    out = _mindlin(p, k_n, gamma_n, delta, 10.0, v, s, dt)  # far below the cap
    trial = s + v * dt
    assert np.allclose(out[:3], -k_t * trial - gamma_t * v, rtol=1e-13, atol=0)
    assert np.allclose(out[3:6], trial, rtol=1e-15, atol=0)
    assert out[6] == pytest.approx(k_t, rel=1e-14)
    assert out[7] == pytest.approx(gamma_t * float(v @ v) * dt, rel=1e-13)
    assert out[8] == 0.0
    # sliding: |F_t| = μ F_n, opposite to the trial force's direction
    f_n = 1e-4
    out = _mindlin(p, k_n, gamma_n, delta, f_n, 1e3 * v, s, dt)
    force = np.array(out[:3])
    assert np.linalg.norm(force) == pytest.approx(mu * f_n, rel=1e-13)
    free = -k_t * (s + 1e3 * v * dt) - gamma_t * 1e3 * v
    assert np.allclose(force / np.linalg.norm(force), free / np.linalg.norm(free), rtol=1e-12)


def test_rolling_laws_by_hand():
    """Ai et al. (2011) model A: |M| = μ_r R* F_n against ω; model C (EPSD): k_r = 2.25 k_n
    μ_r² R*², viscous torque η_r 2 sqrt(I_r k_r) ω below the limit μ_r R* F_n."""
    pr = pair()
    mu_r = 0.5 * (0.02 + 0.04)
    w = np.array([3.0, -4.0, 0.0])  # |ω| = 5
    f_n, dt = 2.0, 1e-6
    p = rolling.pack_constant(rolling.ConstantTorqueParams(), pr)
    out = rolling.constant_torque(p, 1e5, R_EFF, 1e-9, f_n, *w, 0.0, 0.0, 0.0, dt)
    assert np.allclose(out[:3], -mu_r * R_EFF * f_n * w / 5.0, rtol=1e-14, atol=0)
    assert out[7] == pytest.approx(mu_r * R_EFF * f_n * 5.0 * dt, rel=1e-14)
    k_n, i_r, eta = 4.0e5, 3.0e-12, 0.3
    p = rolling.pack_epsd(rolling.EPSDParams(damping_ratio=eta), pr)
    k_r = 2.25 * k_n * mu_r**2 * R_EFF**2
    c_r = eta * 2.0 * math.sqrt(i_r * k_r)
    m0 = np.array([1e-9, 2e-9, 0.0])
    small = 1e-3 * w
    out = rolling.epsd(p, k_n, R_EFF, i_r, f_n, *small, *m0, dt)
    spring = m0 - k_r * small * dt
    assert np.allclose(out[:3], spring - c_r * small, rtol=1e-13, atol=0)
    assert out[6] == pytest.approx(k_r, rel=1e-14)
    assert out[7] == pytest.approx(c_r * float(small @ small) * dt, rel=1e-13)
    # at the limit (no plastic damping by default): |M| = μ_r R* F_n
    out = rolling.epsd(p, k_n, R_EFF, i_r, 1e-6, *(1e4 * w), *m0, dt)
    assert np.linalg.norm(out[:3]) == pytest.approx(mu_r * R_EFF * 1e-6, rel=1e-13)


def test_sustained_sliding_heat_is_the_specs_coulomb_power():
    """Spec 5, sliding friction: Q_g = χ |μ F_n δ̇_t|. In steady sliding (the spring held at the
    cap, with or without the tangential dashpot) the energy the kernel books as sliding in a
    step is μ F_n |v_t| Δt, and nothing as damping."""
    p = tangential.pack_mindlin(tangential.MindlinParams(), pair())
    mu = p[tangential.MINDLIN_FRICTION]
    delta, dt, f_n = 2.0e-6, 1.0e-7, 0.05
    v = np.array([0.3, 0.0, -0.4])  # |v_t| = 0.5 m/s
    for gamma_n in (0.0, 0.02):
        s = np.zeros(3)
        for _ in range(200):  # from first touch to steady sliding
            out = _mindlin(p, 4.0e5, gamma_n, delta, f_n, v, s, dt)
            s = np.array(out[3:6])
        out = _mindlin(p, 4.0e5, gamma_n, delta, f_n, v, s, dt)
        assert np.linalg.norm(out[:3]) == pytest.approx(mu * f_n, rel=1e-13)
        assert out[8] == pytest.approx(mu * f_n * 0.5 * dt, rel=1e-12)
        assert abs(out[7]) < 1e-12 * out[8]


def test_linear_dashpot_power_is_richard2008s_formula():
    """Spec 5 (Richard et al. 2008): Q_g = F_n^vis δ̇_n = 2 μ sqrt(K_n m̄) δ̇_n², μ the damping
    ratio of the linear law, -ln e / sqrt(π² + ln² e) for the restitution e."""
    pr = pair()
    e = 0.5 * (0.7 + 0.5)
    zeta = -math.log(e) / math.sqrt(math.pi**2 + math.log(e) ** 2)
    k_n, rate = 3.0e4, 0.7
    p = normal.pack_linear(normal.LinearParams(stiffness=k_n), pr)
    f_el, f_d, k, gamma, energy, _, _ = normal.linear_force(p, 1e-6, rate, R_EFF, M_EFF, 0.0)
    assert (f_el, k) == (k_n * 1e-6, k_n) and energy == pytest.approx(0.5 * k_n * 1e-12)
    assert f_d * rate == pytest.approx(2 * zeta * math.sqrt(k_n * M_EFF) * rate**2, rel=1e-14)
