"""Mechanical model registry: every registered model of the families normal, tangential and
rolling agrees with its family dispatcher, and the laws have the properties they claim.

* conformance: for random inputs, ``<family>_dispatch(spec.model_id, ...)`` returns exactly what
  the model's own kernel returns (a missing or wrong branch of a dispatcher fails here);
* Hertz: the elastic force equals the closed form (4/3) E* sqrt(R*) δ^{3/2} and the derivative of
  the elastic energy it reports (central finite difference); the same for the linear law;
* tangential laws: |F_t| <= μ max(F_n, 0) for any history, velocity and normal force; the
  step's energies close: ΔU_t + damping + friction = the work of the force on the relative
  displacement with the spring force averaged over the step (docs/architecture.md, "Work of
  the tangential force"), damping >= 0, friction = 0 below the limit and >= 0 unless the step
  reverses the spring;
* EPSD rolling: the same closure for the rolling spring, dissipation >= 0 unless reversing;
* constant-torque rolling: |M| = μ_r R* F_n while rolling, opposing the relative rotation;
* Hertz damping calibration: e(α(e)) = e to 1e-9.
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from thermodem.models import registry
from thermodem.models.mechanics import dispatch, normal, rolling, tangential
from thermodem.models.mechanics.normal import (
    hertz_alpha_of_restitution,
    hertz_restitution_of_alpha,
)
from thermodem.state.materials import Material, resolve_pair

DISPATCH = {
    "normal": dispatch.normal_dispatch,
    "tangential": dispatch.tangential_dispatch,
    "rolling": dispatch.rolling_dispatch,
}
# the mechanical families of registry.FAMILIES; the thermal ones are checked by
# test_thermal_conformance.py, which also fails for a family with models and no dispatcher
FAMILIES = tuple(f for f in registry.FAMILIES if f in DISPATCH)
N_RANDOM = 200


def specs(family: str) -> list[registry.ModelSpec]:
    return [s for s in registry.all_models() if s.family == family]


def default_params(spec: registry.ModelSpec):
    """The model's parameters with defaults (a value for the required ones)."""
    required = {"stiffness": 3.0e4, "loading_stiffness": 3.0e4}  # normal.linear, walton_braun
    fields = spec.params.model_fields
    return spec.params(**{k: v for k, v in required.items() if k in fields})


def random_material(rng: np.random.Generator) -> Material:
    return Material(
        density=float(rng.uniform(500, 8000)),
        youngs_modulus=float(10 ** rng.uniform(5, 11)),
        poisson_ratio=float(rng.uniform(0.0, 0.49)),
        restitution=float(rng.choice([0.3, 0.5, 0.9, 1.0])),  # few values: α(e) is cached
        sliding_friction=float(rng.uniform(0, 1)),
        rolling_friction=float(rng.uniform(0, 0.3)),
    )


def parameter_rows(spec: registry.ModelSpec, rng: np.random.Generator) -> list[np.ndarray]:
    """Rows packed from random materials, and raw random rows (any finite values)."""
    params = default_params(spec)
    rows = [
        spec.pack(params, resolve_pair(random_material(rng), random_material(rng)))
        for _ in range(4)
    ]
    rows += [10 ** rng.uniform(-3, 3, spec.width) for _ in range(4)]
    return rows


def random_arguments(family: str, rng: np.random.Generator) -> tuple:
    """Arguments after the parameter row, physically shaped but random (signs included)."""
    u = rng.uniform
    if family == "normal":
        # overlap, overlap_rate, eff_radius, eff_mass, max_overlap (below or above the overlap)
        overlap = 10 ** u(-9, -3)
        return (overlap, u(-5, 5), 10 ** u(-4, -1), 10 ** u(-6, 1), overlap * u(0.0, 2.0))
    if family == "tangential":
        # ref_stiffness, normal_damping, eff_radius, overlap, normal_force, v_t, s, dt
        return (
            10 ** u(1, 8),
            10 ** u(-3, 2),
            10 ** u(-4, -1),
            10 ** u(-9, -3),
            u(-1, 100),
            u(-2, 2),
            u(-2, 2),
            u(-2, 2),
            u(-1e-4, 1e-4),
            u(-1e-4, 1e-4),
            u(-1e-4, 1e-4),
            10 ** u(-7, -4),
        )
    # rolling: ref_stiffness, eff_radius, rolling_inertia, normal_force, w, m, dt
    return (
        10 ** u(1, 8),
        10 ** u(-4, -1),
        10 ** u(-12, -6),
        u(-1, 100),
        u(-50, 50),
        u(-50, 50),
        u(-50, 50),
        u(-1e-3, 1e-3),
        u(-1e-3, 1e-3),
        u(-1e-3, 1e-3),
        10 ** u(-7, -4),
    )


# --------------------------------------------------------------------------- conformance
def test_every_family_has_models_with_unique_ids():
    for family in FAMILIES:
        models = specs(family)
        assert len(models) >= 2, family
        ids = [s.model_id for s in models]
        assert len(ids) == len(set(ids)), family
    assert registry.get("normal", "hertz").model_id == normal.HERTZ
    assert registry.get("normal", "linear").model_id == normal.LINEAR
    assert registry.get("tangential", "mindlin").model_id == tangential.MINDLIN
    assert registry.get("tangential", "linear").model_id == tangential.LINEAR
    assert registry.get("rolling", "constant_torque").model_id == rolling.CONSTANT_TORQUE
    assert registry.get("rolling", "epsd").model_id == rolling.EPSD


@pytest.mark.parametrize(
    "spec",
    [s for f in FAMILIES for s in specs(f)],
    ids=lambda s: f"{s.family}.{s.name}",
)
def test_dispatcher_equals_model_kernel(spec):
    rng = np.random.default_rng(zlib.crc32(f"{spec.family}.{spec.name}".encode()))
    fn = DISPATCH[spec.family]
    others = [s for s in specs(spec.family) if s.name != spec.name]
    distinguished = set()
    for p in parameter_rows(spec, rng):
        for _ in range(N_RANDOM // 8):
            args = random_arguments(spec.family, rng)
            own = np.array(spec.kernel(p, *args), dtype=np.float64)
            via = np.array(fn(spec.model_id, p, *args), dtype=np.float64)
            assert np.all(np.isfinite(own)), (spec.name, args, own)
            assert np.array_equal(own, via), (spec.name, p, args, own, via)
            # the inputs are rich enough to tell this model from every other of its family
            for other in others:
                if not np.array_equal(own, np.array(other.kernel(p, *args))):
                    distinguished.add(other.name)
    assert distinguished == {o.name for o in others}


def test_normal_dispatcher_rejects_unknown_id():
    p = np.ones(max(s.width for s in registry.all_models()))
    unknown = max(s.model_id for s in specs("normal")) + 1
    out = dispatch.normal_dispatch(unknown, p, 1e-6, 0.1, 1e-3, 1e-3, 0.0)
    assert all(math.isnan(x) for x in out)


# ---------------------------------------------------------------------------- properties
SETTINGS = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@SETTINGS
@given(
    e_star=st.floats(1e5, 1e11),
    eff_radius=st.floats(1e-5, 1.0),
    rel_overlap=st.floats(1e-8, 0.1),
    alpha=st.floats(0.0, 2.0),
    eff_mass=st.floats(1e-9, 10.0),
)
def test_hertz_force_is_energy_derivative(e_star, eff_radius, rel_overlap, alpha, eff_mass):
    p = np.zeros(len(normal.HERTZ_COLUMNS))
    p[normal.HERTZ_E_STAR] = e_star
    p[normal.HERTZ_ALPHA] = alpha
    delta = rel_overlap * eff_radius
    f_el, f_damp, _, _, _, _, plastic = normal.hertz_force(p, delta, 0.0, eff_radius, eff_mass, 0.0)
    assert plastic == 0.0
    assert f_damp == 0.0
    closed = 4.0 / 3.0 * e_star * math.sqrt(eff_radius) * delta**1.5
    assert f_el == pytest.approx(closed, rel=1e-12)
    h = 1e-4 * delta
    u_plus = normal.hertz_force(p, delta + h, 0.0, eff_radius, eff_mass, 0.0)[4]
    u_minus = normal.hertz_force(p, delta - h, 0.0, eff_radius, eff_mass, 0.0)[4]
    # truncation (h/δ)² / 8 ~ 1e-9, round-off ~ 1e-16 / 1e-4 = 1e-12
    assert (u_plus - u_minus) / (2.0 * h) == pytest.approx(f_el, rel=1e-7)


@SETTINGS
@given(stiffness=st.floats(1.0, 1e9), delta=st.floats(1e-9, 1e-2), zeta=st.floats(0.0, 1.0))
def test_linear_force_is_energy_derivative(stiffness, delta, zeta):
    p = np.zeros(len(normal.LINEAR_COLUMNS))
    p[normal.LINEAR_STIFFNESS] = stiffness
    p[normal.LINEAR_DAMPING_RATIO] = zeta
    f_el = normal.linear_force(p, delta, 0.0, 1e-3, 1e-3, 0.0)[0]
    assert f_el == pytest.approx(stiffness * delta, rel=1e-15)
    h = 1e-4 * delta
    u_plus = normal.linear_force(p, delta + h, 0.0, 1e-3, 1e-3, 0.0)[4]
    u_minus = normal.linear_force(p, delta - h, 0.0, 1e-3, 1e-3, 0.0)[4]
    assert (u_plus - u_minus) / (2.0 * h) == pytest.approx(f_el, rel=1e-7)


TANGENTIAL = [s.name for s in specs("tangential")]
component = st.floats(-10.0, 10.0)
spring = st.floats(-1e-3, 1e-3)


@SETTINGS
@given(
    name=st.sampled_from(TANGENTIAL),
    # mu = 0 or a physical value: for mu ~ 1e-164 the capped force components square into the
    # subnormal range and |F_t| loses its relative precision (seen with mu = 1.3e-164)
    mu=st.one_of(st.just(0.0), st.floats(1e-6, 2.0)),
    youngs=st.floats(1e5, 1e11),
    ref_stiffness=st.floats(1.0, 1e9),
    normal_damping=st.floats(0.0, 1e4),
    eff_radius=st.floats(1e-5, 0.1),
    overlap=st.floats(1e-10, 1e-3),
    normal_force=st.floats(-100.0, 1e4),
    v=st.tuples(component, component, component),
    s=st.tuples(spring, spring, spring),
    dt=st.floats(1e-8, 1e-3),
)
# subnormal caps found by hypothesis (the cap scale λ = cap/|F| was itself subnormal and lost
# its relative precision: the force exceeded the cap by 1.3e-12 of it)
@example(
    "mindlin",
    1.0,
    4224587554.0,
    1.0,
    0.0,
    0.0625,
    0.0007386816197748466,
    1.1125369292536007e-308,
    (0.0, 0.0, 0.0),
    (0.0, 0.0, 0.0003355735088290913),
    1e-3,
)
@example(
    "linear",
    1.0,
    1e5,
    5e4,
    0.0,
    0.0625,
    0.0009935677997822126,
    2.2250738585e-313,
    (0.0, 0.0, 1.0),
    (0.0, 0.0, 0.0),
    0.00013754590056443844,
)
def test_tangential_force_never_exceeds_coulomb(
    name, mu, youngs, ref_stiffness, normal_damping, eff_radius, overlap, normal_force, v, s, dt
):
    spec = registry.get("tangential", name)
    mat = Material(density=2500.0, youngs_modulus=youngs, poisson_ratio=0.3, sliding_friction=mu)
    pair = resolve_pair(mat, mat)
    assert pair.sliding_friction == pytest.approx(mu)
    p = spec.pack(default_params(spec), pair)
    out = dispatch.tangential_dispatch(
        spec.model_id,
        p,
        ref_stiffness,
        normal_damping,
        eff_radius,
        overlap,
        normal_force,
        *v,
        *s,
        dt,
    )
    f_t = math.hypot(out[0], out[1], out[2])  # (squares of 1e-157 forces are subnormal)
    limit = pair.sliding_friction * max(normal_force, 0.0)
    # (+ a few units of the last place of subnormal numbers, 4.9e-324: a cap below ~2e-308
    # has an absolute, not a relative, precision)
    assert f_t <= limit * (1.0 + 1e-12) + 1e-322
    # energies of the step, recomputed here from the returned force and displacement
    force, s_new, k_t = np.array(out[:3]), np.array(out[3:6]), out[6]
    damping, friction = out[7], out[8]
    s0, vel = np.array(s), np.array(v)
    du = vel * dt
    d_stored = 0.5 * k_t * (s_new @ s_new - s0 @ s0)
    # work on the contact: minus the force, its spring part averaged over the step, along du
    work = -(force + 0.5 * k_t * (s_new - s0)) @ du
    scale = abs(d_stored) + abs(damping) + abs(friction) + abs(work)
    scale += 0.5 * k_t * (s0 + du) @ (s0 + du) + abs(force @ du)
    assert d_stored + damping + friction == pytest.approx(work, abs=1e-10 * scale + 1e-300)
    assert damping >= 0.0
    # no slip (the spring took the whole displacement): no sliding energy. (Not decided from
    # |F_t| < limit: a limit near 1e-262 squares to 0 in |F_t|.)
    if k_t > 0.0 and np.array_equal(s_new, s0 + du):
        assert friction == 0.0
    if k_t > 0.0 and f_t < limit * (1.0 - 1e-9) and f_t > 1e-150:  # below the limit: stick
        np.testing.assert_array_equal(s_new, s0 + du)
        assert friction == 0.0
    if s0 @ vel >= 0.0:  # no reversal of the spring: sliding never gives energy back
        assert friction >= -1e-10 * scale


@SETTINGS
@given(
    mu_r=st.floats(1e-4, 1.0),
    ref_stiffness=st.floats(1.0, 1e9),
    eff_radius=st.floats(1e-5, 0.1),
    rolling_inertia=st.floats(1e-14, 1e-4),
    normal_force=st.floats(-100.0, 1e4),
    w=st.tuples(component, component, component),
    m=st.tuples(spring, spring, spring),
    dt=st.floats(1e-8, 1e-3),
    plastic=st.floats(0.0, 1.0),
)
def test_epsd_rolling_energies_close(
    mu_r, ref_stiffness, eff_radius, rolling_inertia, normal_force, w, m, dt, plastic
):
    spec = registry.get("rolling", "epsd")
    mat = Material(density=2500.0, youngs_modulus=1e7, poisson_ratio=0.3, rolling_friction=mu_r)
    params = spec.params(plastic_damping_factor=plastic)
    p = spec.pack(params, resolve_pair(mat, mat))
    out = dispatch.rolling_dispatch(
        spec.model_id, p, ref_stiffness, eff_radius, rolling_inertia, normal_force, *w, *m, dt
    )
    torque, m_new, k_r, dissipated = np.array(out[:3]), np.array(out[3:6]), out[6], out[7]
    m0, omega = np.array(m), np.array(w)
    limit = mu_r * eff_radius * max(normal_force, 0.0)
    assert math.hypot(*m_new) <= limit * (1.0 + 1e-12) + 1e-300  # (subnormal squares)
    d_stored = 0.5 * (m_new @ m_new - m0 @ m0) / k_r
    # work on the contact: minus the torque, its spring part averaged over the step, along ω dt
    work = -(torque + 0.5 * (m0 - m_new)) @ omega * dt
    scale = abs(d_stored) + abs(dissipated) + abs(work) + 0.5 * (m0 @ m0) / k_r
    scale += abs(torque @ omega) * dt
    assert d_stored + dissipated == pytest.approx(work, abs=1e-10 * scale + 1e-300)
    if m0 @ omega <= 0.0:  # the spring is not reversed by the step
        assert dissipated >= -1e-10 * scale


@SETTINGS
@given(
    mu_r=st.floats(0.0, 1.0),
    eff_radius=st.floats(1e-5, 0.1),
    normal_force=st.floats(-100.0, 1e4),
    w=st.tuples(component, component, component),
)
def test_constant_torque_magnitude_and_direction(mu_r, eff_radius, normal_force, w):
    spec = registry.get("rolling", "constant_torque")
    mat = Material(density=2500.0, youngs_modulus=1e7, poisson_ratio=0.3, rolling_friction=mu_r)
    p = spec.pack(default_params(spec), resolve_pair(mat, mat))
    out = dispatch.rolling_dispatch(
        spec.model_id, p, 1e5, eff_radius, 1e-8, normal_force, *w, 0.0, 0.0, 0.0, 1e-5
    )
    torque = np.array(out[:3])
    w_mag = math.sqrt(sum(c * c for c in w))
    if w_mag <= p[1] or normal_force <= 0.0:
        assert not torque.any()
        return
    expected = mu_r * eff_radius * normal_force
    assert math.hypot(*torque) == pytest.approx(expected, rel=1e-12, abs=1e-300)
    assert torque @ np.array(w) <= 0.0
    assert out[7] == pytest.approx(expected * w_mag * 1e-5, rel=1e-12, abs=1e-300)


@settings(max_examples=6, deadline=None)
@given(e=st.floats(0.01, 1.0))
@example(e=1.0)
@example(e=0.5)
def test_hertz_restitution_round_trip(e):
    alpha = hertz_alpha_of_restitution(e)
    assert alpha >= 0.0
    assert abs(hertz_restitution_of_alpha(alpha) - e) < 1e-9


@SETTINGS
@given(
    k1=st.floats(1.0, 1e7),
    e=st.floats(0.05, 1.0),
    peak=st.floats(1e-7, 1e-3),
    back=st.floats(0.0, 1.0),
    again=st.floats(0.0, 2.0),
)
def test_walton_braun_work_is_stored_energy_plus_plastic_dissipation(k1, e, peak, back, again):
    """Along a path load to δ_a, unload to a fraction of it, reload beyond it (steps small
    enough to resolve the branches, with the branch points as step ends): the work of the
    force (trapezoids: the law is piecewise linear) equals the change of the stored energy
    plus the plastic dissipation, and a full load-unload cycle dissipates ½ k1 (1 - e²) δ_max²
    (Walton & Braun 1986)."""
    p = np.array([k1, e * e])
    d0_of = lambda m: m * (1.0 - e * e)  # noqa: E731 (δ0 of a largest overlap m)
    lows = (d0_of(peak) + back * (peak - d0_of(peak)), peak, peak * (1.0 + again))
    points = [np.linspace(0.0, peak, 50)]
    points.append(np.linspace(peak, lows[0], 50)[1:])
    points.append(np.linspace(lows[0], peak, 50)[1:])  # reload along the unloading line
    points.append(np.linspace(peak, lows[2], 50)[1:])  # and beyond: loading again
    path = np.concatenate(points)
    m = 0.0
    work = plastic = 0.0
    f_prev, u0 = 0.0, 0.0
    for k, d in enumerate(path):
        f, _, _, _, u, m, dp = normal.walton_braun_force(p, d, 0.0, 1e-3, 1e-3, m)
        if k:
            work += 0.5 * (f + f_prev) * (d - path[k - 1])
        plastic += dp
        f_prev = f
    assert work == pytest.approx(u - u0 + plastic, rel=1e-9, abs=1e-18 * k1)
    assert m == max(peak, lows[2])
    cycle = normal.walton_braun_force(p, m, 0.0, 1e-3, 1e-3, m)[4]  # stored at the top
    assert plastic == pytest.approx(0.5 * k1 * (1.0 - e * e) * m * m, rel=1e-12)
    assert cycle == pytest.approx(0.5 * k1 * e * e * m * m, rel=1e-12)
