"""Direct conduction models against hand computations written out here (spec 2.2-2.4)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from thermodem.models import registry
from thermodem.models.thermal import batchelor_obrien_contact as bob
from thermodem.models.thermal import direct_conduction as dc
from thermodem.models.thermal.contact_radius import geometric_contact_radius
from thermodem.models.thermal.direct_conduction_family import swap_row
from thermodem.state.gas import GasProperties
from thermodem.state.materials import Material, resolve_pair

INF = np.inf
PI = math.pi


def material(**kw) -> Material:
    base = dict(density=2500.0, youngs_modulus=1.0e8, poisson_ratio=0.25, specific_heat=800.0,
                thermal_conductivity=2.0, microhardness=5e9, surface_roughness=1e-6,
                surface_slope=0.05, thermal_accommodation=0.8)  # fmt: skip
    base.update(kw)
    return Material(**base)


MAT_A = material(thermal_conductivity=2.0)
MAT_B = material(thermal_conductivity=6.0, density=7800.0, specific_heat=460.0)


def row(model: str, mi=MAT_A, mj=MAT_B, is_wall=False, k_f=None, **params) -> np.ndarray:
    """The packed row; ``k_f``: the conductivity of the case's gas (None: default air)."""
    spec = registry.get("direct_conduction", model)
    gas = None if k_f is None else GasProperties(thermal_conductivity=k_f)
    return spec.pack(spec.params(**params), resolve_pair(mi, mj, is_wall=is_wall, gas=gas))


def rate(model, p, t_i, t_j, r_i, r_j, overlap, r_c, f_n=0.0, t_contact=0.0, v=0.0, m=0.0):
    kernel = registry.get("direct_conduction", model).kernel
    dist = r_i + r_j - overlap
    return kernel(p, t_i, t_j, r_i, r_j, dist, overlap, r_c, f_n, t_contact, v, m)


# ------------------------------------------------------------------- Batchelor & O'Brien
def test_bob_simple_uses_the_series_conductivity():
    p = row("batchelor_obrien_simple")
    k_bar = 2.0 * 6.0 / (2.0 + 6.0)  # appendix A: k_i k_j/(k_i + k_j) = 1.5
    q = rate("batchelor_obrien_simple", p, 300.0, 310.0, 1e-3, 2e-3, 1e-6, 3e-5)
    assert q == pytest.approx(4.0 * k_bar * 3e-5 * 10.0, rel=1e-14)
    p = row("batchelor_obrien_simple", MAT_A, MAT_A)  # equal materials: 2 k R_c ΔT
    q = rate("batchelor_obrien_simple", p, 300.0, 310.0, 1e-3, 1e-3, 1e-6, 3e-5)
    assert q == pytest.approx(2.0 * 2.0 * 3e-5 * 10.0, rel=1e-14)


K_HIGH = material(thermal_conductivity=1000.0)
R_EFF = 0.5e-3  # two spheres of 1 mm
KPF = 1.0e4  # k_p = 1000, k_f = 0.1; η = k_pf R_c / (2 R*) = 1e7 R_c


def bob_row(**kw):
    return row("batchelor_obrien_complete", K_HIGH, K_HIGH, k_f=0.1, **kw)


@pytest.mark.parametrize(
    ("eta", "h"),
    [
        (0.5, 0.22 * 0.25 - 0.05 * 0.25),
        (200.0, 2 * 200 / PI - 2 * math.log(200.0)),
        (50.0, (1 - 49 / 99) * 0.17 * 50**2 + 49 / 99 * (2 * 50 / PI - 2 * math.log(50.0))),
    ],
)
def test_bob_complete_contact_regimes(eta, h):
    r_c = eta / 1.0e7
    q = rate("batchelor_obrien_complete", bob_row(), 300.0, 301.0, 1e-3, 1e-3, 1e-6, r_c)
    assert q == pytest.approx(2 * PI * R_EFF * 0.1 * (h + math.log(KPF**2)), rel=1e-12)


def test_bob_spec_blend_is_not_monotonic_and_hermite_is():
    eta = np.linspace(0.5, 120.0, 4001)
    spec = np.array([bob.bob_contact_h(e, bob.BLEND_SPEC_LINEAR) for e in eta])
    herm = np.array([bob.bob_contact_h(e, bob.BLEND_HERMITE) for e in eta])
    assert spec.max() > 5 * bob.bob_contact_h(100.0, 0)  # peak ≈ 277.8 near η ≈ 68.8
    assert np.all(np.diff(herm) > 0)
    for e0 in (1.0, 100.0):  # hermite: value and slope continuous at both ends
        lo = bob.bob_contact_h(e0 - 1e-7, 1)
        hi = bob.bob_contact_h(e0 + 1e-7, 1)
        assert hi - lo == pytest.approx(0.0, abs=1e-6)
        s_lo = (lo - bob.bob_contact_h(e0 - 1e-4, 1)) / (1e-4 - 1e-7)
        s_hi = (bob.bob_contact_h(e0 + 1e-4, 1) - hi) / (1e-4 - 1e-7)
        assert s_lo == pytest.approx(s_hi, rel=1e-3)


def test_bob_separated_regimes_and_cutoff():
    p = bob_row(cylinder_radius=2.0, cutoff_gap_ratio=1.0)
    r_bar = 2.0 * R_EFF
    # λ = k_pf² d_s / (2R*) = 1e11 d_s: λ = 1e-4 -> ln k_pf²; λ = 1e7 -> ln(1 + r̄²/(2R* d_s))
    for gap, h in [(1e-15, math.log(KPF**2)), (1e-4, math.log(1 + r_bar**2 / (2 * R_EFF * 1e-4)))]:
        q = rate("batchelor_obrien_complete", p, 300.0, 301.0, 1e-3, 1e-3, -gap, 0.0)
        assert q == pytest.approx(2 * PI * R_EFF * 0.1 * h, rel=1e-12)
    assert rate("batchelor_obrien_complete", p, 300.0, 301.0, 1e-3, 1e-3, -6e-4, 0.0) == 0.0
    spec = registry.get("direct_conduction", "batchelor_obrien_complete")
    assert spec.interaction_range(spec.params(), 1e-3, 1e-3) == pytest.approx(R_EFF)
    assert spec.interaction_range(spec.params(), 1e-3, INF) == pytest.approx(1e-3)


def test_bob_modified_series_network_by_hand():
    k_f, r_i, r_j, r_c = 0.05, 1e-3, 2e-3, 1e-4
    r_eff = r_i * r_j / (r_i + r_j)
    k_p = 2 * 2.0 * 6.0 / 8.0  # harmonic mean = 3
    eta = k_p / k_f * r_c / (2 * r_eff)
    assert 1.0 < eta < 100.0
    w = (eta - 1) / 99
    h_t = (1 - w) * 0.17 * eta**2 + w * (2 * eta / PI - 2 * math.log(eta))
    h_bob = 2 * PI * r_eff * k_f * (h_t + math.log((k_p / k_f) ** 2))
    for option, r_bar in [
        (2.0, 2.0 * r_eff),
        ("dai2019_correlation", 1.3121 * (k_p / k_f) ** -0.19 * r_i),
    ]:
        p = row("batchelor_obrien_modified", k_f=k_f, cylinder_radius=option)
        h_i, h_j = 2.0 * PI * r_bar**2 / r_i, 6.0 * PI * r_bar**2 / r_j
        expected = 10.0 / (1 / h_i + 1 / h_j + 1 / h_bob)
        q = rate("batchelor_obrien_modified", p, 300.0, 310.0, r_i, r_j, 1e-6, r_c)
        assert q == pytest.approx(expected, rel=1e-12)
        # wall: isothermal, its inner resistance is dropped; R* = R_i
        eta_w = k_p / k_f * r_c / (2 * r_i)
        w = (eta_w - 1) / 99
        h_t = (1 - w) * 0.17 * eta_w**2 + w * (2 * eta_w / PI - 2 * math.log(eta_w))
        h_bob_w = 2 * PI * r_i * k_f * (h_t + math.log((k_p / k_f) ** 2))
        r_bar_w = 2.0 * r_i if option == 2.0 else r_bar
        h_i = 2.0 * PI * r_bar_w**2 / r_i
        q = rate("batchelor_obrien_modified", p, 300.0, 310.0, r_i, INF, 1e-6, r_c)
        assert q == pytest.approx(10.0 / (1 / h_i + 1 / h_bob_w), rel=1e-12)


def test_bob_conductivity_mean_arithmetic_by_hand():
    """Two materials (k 2 and 6): conductivity_mean arithmetic takes k_p = (2 + 6)/2 = 4 in
    every k_p of complete and modified (η, ln k_pf², the Dai correlation, the separated λ),
    harmonic (the default) 2·2·6/8 = 3; the inner resistances keep each particle's own k."""
    k_f, r_i, r_j, r_c = 0.05, 1e-3, 2e-3, 1e-4
    r_eff = r_i * r_j / (r_i + r_j)

    def h_contact(k_p, r_eff=r_eff):
        eta = k_p / k_f * r_c / (2 * r_eff)
        assert 1.0 < eta < 100.0
        w = (eta - 1) / 99
        h_t = (1 - w) * 0.17 * eta**2 + w * (2 * eta / PI - 2 * math.log(eta))
        return 2 * PI * r_eff * k_f * (h_t + math.log((k_p / k_f) ** 2))

    for mean, k_p in [("harmonic", 3.0), ("arithmetic", 4.0)]:
        p = row("batchelor_obrien_complete", k_f=k_f, conductivity_mean=mean)
        q = rate("batchelor_obrien_complete", p, 300.0, 310.0, r_i, r_j, 1e-6, r_c)
        assert q == pytest.approx(10.0 * h_contact(k_p), rel=1e-12)
        # separated (gap 1e-5 m < R*): near form ln k_pf² (λ = k_pf² d_s/(2R*) > 0.01, and
        # the minimum of both forms between)
        gap = 1e-5
        lam = (k_p / k_f) ** 2 * gap / (2 * r_eff)
        near = math.log((k_p / k_f) ** 2)
        far = math.log(1 + (2.0 * r_eff) ** 2 / (2 * r_eff * gap))
        x = near if lam < 0.01 else far if lam > 100 else min(near, far)
        q = rate("batchelor_obrien_complete", p, 300.0, 310.0, r_i, r_j, -gap, 0.0)
        assert q == pytest.approx(10.0 * 2 * PI * r_eff * k_f * x, rel=1e-12)
        for option, r_bar in [
            (2.0, 2.0 * r_eff),
            ("dai2019_correlation", 1.3121 * (k_p / k_f) ** -0.19 * r_i),
        ]:
            p = row(
                "batchelor_obrien_modified", k_f=k_f, cylinder_radius=option, conductivity_mean=mean
            )
            h_i, h_j = 2.0 * PI * r_bar**2 / r_i, 6.0 * PI * r_bar**2 / r_j
            expected = 10.0 / (1 / h_i + 1 / h_j + 1 / h_contact(k_p))
            q = rate("batchelor_obrien_modified", p, 300.0, 310.0, r_i, r_j, 1e-6, r_c)
            assert q == pytest.approx(expected, rel=1e-12)
        # a wall of material B: k_p of the particle's and the wall's k, R* = R_i
        p = row("batchelor_obrien_complete", is_wall=True, k_f=k_f, conductivity_mean=mean)
        q = rate("batchelor_obrien_complete", p, 300.0, 310.0, r_i, INF, 1e-6, r_c)
        assert q == pytest.approx(10.0 * h_contact(k_p, r_i), rel=1e-12)
    # one material: the two means are the same number
    same = [
        row("batchelor_obrien_complete", MAT_B, MAT_B, k_f=k_f, conductivity_mean=m)
        for m in ("harmonic", "arithmetic")
    ]
    q = [rate("batchelor_obrien_complete", p, 300.0, 310.0, r_i, r_j, 1e-6, r_c) for p in same]
    assert q[0] == q[1]
    # k_pf > 1 is checked with the chosen mean: k 2 and 6 in a gas of 3.5 (harmonic 3 < 3.5)
    with pytest.raises(ValueError, match="k_p/k_f > 1"):
        row("batchelor_obrien_complete", k_f=3.5)
    row("batchelor_obrien_complete", k_f=3.5, conductivity_mean="arithmetic")
    with pytest.raises(ValueError):
        row("batchelor_obrien_complete", conductivity_mean="geometric")


SEP_KF = 0.1  # k_p = 1000 (K_HIGH), k_pf = 1e4, k_pf² = 1e8; R* = 0.5 mm: λ = 1e11 d_s


def bob_separated_by_hand(gap, ratio, regime="dai2019", r_eff=R_EFF, k_p=1000.0, k_f=SEP_KF):
    """2π R* k_f X(λ) of the spec's two formulas and the regime rules, written out here."""
    lam = (k_p / k_f) ** 2 * gap / (2 * r_eff)
    near = math.log((k_p / k_f) ** 2)
    far = math.log(1 + (ratio * r_eff) ** 2 / (2 * r_eff * gap))
    if regime == "moscardini2018":
        x = near if lam < 0.1 else far
    elif regime == "minimum" or 0.01 <= lam <= 100:
        x = min(near, far)
    else:
        x = near if lam < 0.01 else far
    return 2 * PI * r_eff * k_f * x


@pytest.mark.parametrize("model", ["batchelor_obrien_complete", "batchelor_obrien_modified"])
@pytest.mark.parametrize("regime", ["dai2019", "moscardini2018", "minimum"])
@pytest.mark.parametrize(
    "cylinder", [0.1, 25.0, "kanuparthi2008", "yun_evans2010", "moscardini2018", "dai2019"]
)
def test_bob_separated_part_regimes_and_named_cylinders(model, regime, cylinder):
    """The separated-pair part of complete (and, through its series network, modified): the
    spec's λ rules exactly, also for thin and wide cylinders where the minimum alone is not
    Dai et al.'s rule (r̄ = 0.1 R* keeps the near form up to λ = 0.01; r̄ = 25 R* the far
    form from λ = 100), and the spec's named cylinders 1.00 / 1.00 / 1.42 / 2.00 R*."""
    ratio = {"kanuparthi2008": 1.0, "yun_evans2010": 1.0, "moscardini2018": 1.42,
             "dai2019": 2.0}.get(cylinder, cylinder)  # fmt: skip
    p = row(model, K_HIGH, K_HIGH, k_f=SEP_KF, regime=regime, cylinder_radius=cylinder)
    assert p[bob.BOB_CYLINDER_RATIO] == ratio
    r_bar = ratio * R_EFF
    h_inner = 0.5 * (1000.0 * PI * r_bar**2 / 1e-3)  # two particles k π r̄² / R in series
    for lam in (0.009, 0.05, 0.2, 50.0, 150.0):
        gap = lam / 1e11
        h = bob_separated_by_hand(gap, ratio, regime)
        if model == "batchelor_obrien_modified":
            h = 1.0 / (1.0 / h_inner + 1.0 / h)
        q = rate(model, p, 300.0, 301.0, 1e-3, 1e-3, -gap, 0.0)
        assert q == pytest.approx(h, rel=1e-12), lam
    if regime == "dai2019" and cylinder == 0.1:  # the λ < 0.01 rule, not the minimum
        gap = 0.009 / 1e11
        assert bob_separated_by_hand(gap, 0.1, "minimum") < bob_separated_by_hand(gap, 0.1)


def test_bob_modified_separated_series_by_hand():
    """Yun & Evans' network for a separated pair: the particles' inner resistances in series
    with Batchelor & O'Brien's separated conductance (spec 2.4, 'the resistance of the
    interaction type'); unequal radii and materials, and a wall (isothermal: no H_j)."""
    k_f, r_i, r_j, gap = 0.05, 1e-3, 2e-3, 2e-6
    r_eff = r_i * r_j / (r_i + r_j)
    k_p = 3.0  # harmonic mean of 2 and 6
    for option in (1.42, "dai2019_correlation"):
        p = row("batchelor_obrien_modified", k_f=k_f, cylinder_radius=option)
        r_bar = 1.42 * r_eff if option == 1.42 else 1.3121 * (k_p / k_f) ** -0.19 * r_i
        h_bob = bob_separated_by_hand(gap, r_bar / r_eff, r_eff=r_eff, k_p=k_p, k_f=k_f)
        h_i, h_j = 2.0 * PI * r_bar**2 / r_i, 6.0 * PI * r_bar**2 / r_j
        q = rate("batchelor_obrien_modified", p, 300.0, 310.0, r_i, r_j, -gap, 0.0)
        assert q == pytest.approx(10.0 / (1 / h_i + 1 / h_j + 1 / h_bob), rel=1e-12)
        pw = row("batchelor_obrien_modified", is_wall=True, k_f=k_f, cylinder_radius=option)
        r_bar_w = 1.42 * r_i if option == 1.42 else 1.3121 * (k_p / k_f) ** -0.19 * r_i
        h_bob_w = bob_separated_by_hand(gap, r_bar_w / r_i, r_eff=r_i, k_p=k_p, k_f=k_f)
        h_i = 2.0 * PI * r_bar_w**2 / r_i
        q = rate("batchelor_obrien_modified", pw, 300.0, 310.0, r_i, INF, -gap, 0.0)
        assert q == pytest.approx(10.0 / (1 / h_i + 1 / h_bob_w), rel=1e-12)


@pytest.mark.parametrize("model", ["batchelor_obrien_complete", "batchelor_obrien_modified"])
@pytest.mark.parametrize("r_j", [1e-3, 3e-3, INF])
def test_bob_gap_to_contact_limit(model, r_j):
    """Gap -> 0 equals the touching value at δ -> 0 (the spec's separated formula tends to
    2π R* k_f ln k_pf², the contact formula's value at η = 0): both sides of first contact,
    with the geometric contact radius, agree to the size of the 0.17 η² term."""
    p = row(model, MAT_A, MAT_B, is_wall=math.isinf(r_j))
    for eps in (1e-12, 1e-14):
        below = rate(model, p, 300.0, 301.0, 1e-3, r_j, -eps, 0.0)
        above = rate(model, p, 300.0, 301.0, 1e-3, r_j, eps,
                     geometric_contact_radius(1e-3, r_j, eps))  # fmt: skip
        at = rate(model, p, 300.0, 301.0, 1e-3, r_j, 0.0, 0.0)
        assert below == pytest.approx(at, rel=1e-13) and above == pytest.approx(at, rel=1e-6)
        assert below > 0.0


def test_bob_separated_part_bad_parameters():
    """r̄ <= 0, a negative cut-off, unknown names: schema errors naming the key."""
    from pydantic import ValidationError

    for model in ("batchelor_obrien_complete", "batchelor_obrien_modified"):
        params = registry.get("direct_conduction", model).params
        for bad in ({"cylinder_radius": 0.0}, {"cylinder_radius": -2.0},
                    {"cylinder_radius": math.inf}, {"cylinder_radius": "dai"},
                    {"cutoff_gap_ratio": -0.5}, {"cutoff_gap_ratio": math.nan},
                    {"regime": "linear"}):  # fmt: skip
            with pytest.raises(ValidationError, match=next(iter(bad))):
                params(**bad)
    complete = registry.get("direct_conduction", "batchelor_obrien_complete").params
    with pytest.raises(ValidationError, match="cylinder_radius"):
        complete(cylinder_radius="dai2019_correlation")  # the modified model's option only


def test_bob_pack_checks():
    with pytest.raises(ValueError, match="k_p/k_f > 1"):
        row("batchelor_obrien_complete", k_f=5.0)
    with pytest.raises(ValueError, match="thermal_conductivity"):
        row("batchelor_obrien_simple", MAT_A, material(thermal_conductivity=None))
    with pytest.raises(ValueError, match="specific_heat"):
        row("zhou2008", MAT_A, material(specific_heat=None))


# ------------------------------------------------------------------------- thermal pipes
R_I, R_J, DELTA, R_C, DT = 1e-3, 2e-3, 1e-5, 3e-5, 10.0
AREA = PI * R_C**2


@pytest.mark.parametrize(
    ("model", "pair", "wall"),
    [
        ("thermal_pipe", 3.0 * AREA / (R_I + R_J - DELTA) * DT, 2.0 * AREA / (R_I - DELTA) * DT),
        (
            "quintana_ruiz_campello2020",
            (R_I + R_J) / (R_I / 2.0 + R_J / 6.0) * AREA / (R_I + R_J - DELTA) * DT,
            2.0 * AREA / R_I * DT,
        ),
        ("rojek2014", 3.0 * (R_I + R_J) / 2.0 * DT, 2.0 * 2.0 * R_I * DT),
    ],
)
def test_pipes_by_hand(model, pair, wall):
    p = row(model)
    assert rate(model, p, 300.0, 310.0, R_I, R_J, DELTA, R_C) == pytest.approx(pair, rel=1e-13)
    p = row(model, is_wall=True)
    assert rate(model, p, 300.0, 310.0, R_I, INF, DELTA, R_C) == pytest.approx(wall, rel=1e-13)
    assert rate(model, p, 300.0, 310.0, R_I, R_J, -DELTA, R_C) == 0.0


# ---------------------------------------------------------------------------- collisional
def zhou_c_spec(ratio, fo):
    """Spec 2.2, Zhou et al. (2008), as printed."""
    c1 = -2.300 * ratio**2 + 8.909 * ratio - 4.235
    c2 = 8.169 * ratio**2 - 33.770 * ratio + 24.885
    c3 = -5.758 * ratio**2 + 24.464 * ratio - 20.511
    return 0.435 * (math.sqrt(c2**2 - 4 * c1 * (c3 - fo)) - c2) / c1


@pytest.mark.parametrize(
    ("fo", "value"),
    [  # ratio 1: C1 = 2.374, C2 = -0.716, C3 = -1.805
        (0.0, 0.435 * (math.sqrt(0.716**2 + 4 * 2.374 * 1.805) + 0.716) / 2.374),
        (1.0, 0.435 * (math.sqrt(0.716**2 + 4 * 2.374 * 2.805) + 0.716) / 2.374),
        (10.0, 0.435 * (math.sqrt(0.716**2 + 4 * 2.374 * 11.805) + 0.716) / 2.374),
    ],
)
def test_zhou2008_coefficient_by_hand(fo, value):
    assert dc.zhou2008_coefficient(1.0, fo) == pytest.approx(value, rel=1e-12)
    assert value == pytest.approx({0.0: 0.90107, 1.0: 1.08595, 10.0: 2.07567}[fo], rel=1e-4)


@pytest.mark.parametrize("ratio", [0.6, 0.9, 1.3, 2.5])
@pytest.mark.parametrize("fo", [0.0, 0.05, 2.0])
def test_zhou2008_coefficient_both_branches_match_the_printed_formula(ratio, fo):
    assert dc.zhou2008_coefficient(ratio, fo) == pytest.approx(zhou_c_spec(ratio, fo), rel=1e-12)


E_STAR = 1.0 / (2 * (1 - 0.25**2) / 1.0e8)
M_EFF, V = 4.0e-6, 0.5


def hertz_impact(r_eff):
    r_max = (15 / 16 * M_EFF * r_eff**2 / E_STAR * V**2) ** 0.2
    t_c = 2.87 * (M_EFF**2 / (r_eff * E_STAR**2 * V)) ** 0.2
    return r_max, t_c


def test_sun_chen_by_hand_and_switch_to_static():
    p = row("sun_chen1988", MAT_A, MAT_B, correction_factor=0.8)
    r_max, t_c = hertz_impact(R_EFF)
    eff = 1 / math.sqrt(2500 * 800 * 2.0) + 1 / math.sqrt(7800 * 460 * 6.0)
    expected = 0.8 * 0.87 * PI * r_max**2 / (math.sqrt(t_c) * eff) * DT
    args = (300.0, 310.0, 1e-3, 1e-3, 1e-6, R_C, 0.0)
    assert rate("sun_chen1988", p, *args, 0.5 * t_c, V, M_EFF) == pytest.approx(expected, 1e-12)
    static = 4 * 1.5 * R_C * DT  # batchelor_obrien_simple
    assert rate("sun_chen1988", p, *args, 1.01 * t_c, V, M_EFF) == pytest.approx(static, 1e-14)
    assert rate("sun_chen1988", p, *args, 0.0, 0.0, M_EFF) == pytest.approx(static, 1e-14)
    p = row("sun_chen1988", MAT_A, MAT_B, static_model="none")
    assert rate("sun_chen1988", p, *args, 1.01 * t_c, V, M_EFF) == 0.0


def test_zhou2008_by_hand_symmetrised_coefficient():
    p = row("zhou2008", MAT_A, MAT_B)
    r_max, t_c = hertz_impact(R_EFF)
    rc_a, rc_b = 2500 * 800.0, 7800 * 460.0
    fo_a, fo_b = 2.0 * t_c / (rc_a * r_max**2), 6.0 * t_c / (rc_b * r_max**2)
    c = 0.5 * (zhou_c_spec(rc_a / rc_b, fo_a) + zhou_c_spec(rc_b / rc_a, fo_b))
    eff = 1 / math.sqrt(rc_a * 2.0) + 1 / math.sqrt(rc_b * 6.0)
    expected = c * PI * r_max**2 / (math.sqrt(t_c) * eff) * DT
    q = rate("zhou2008", p, 300.0, 310.0, 1e-3, 1e-3, 1e-6, R_C, 0.0, 0.1 * t_c, V, M_EFF)
    assert q == pytest.approx(expected, rel=1e-12)


# ----------------------------------------------------------------------------- properties
MODELS = [
    ("batchelor_obrien_simple", {}),
    ("batchelor_obrien_complete", {}),
    ("batchelor_obrien_complete", {"blend": "hermite"}),
    ("batchelor_obrien_modified", {}),
    ("batchelor_obrien_modified", {"cylinder_radius": "dai2019_correlation"}),
    ("thermal_pipe", {}),
    ("quintana_ruiz_campello2020", {}),
    ("rojek2014", {}),
    ("sun_chen1988", {}),
    ("sun_chen1988", {"static_model": "quintana_ruiz_campello2020"}),
    ("zhou2008", {}),
    ("zhou2008", {"static_model": "rojek2014"}),
    ("resistance_network", {}),
]
temps = st.floats(250.0, 1500.0)
radii = st.floats(2e-4, 5e-3)


@pytest.mark.parametrize(("model", "params"), MODELS)
@settings(max_examples=40, deadline=None)
@given(t_i=temps, t_j=temps, r_i=radii, r_j=st.one_of(radii, st.just(INF)),
       overlap=st.floats(-3e-4, 2e-5), f_n=st.floats(0.0, 5.0), t_contact=st.floats(0.0, 1e-4),
       v=st.floats(0.0, 2.0), m=st.floats(1e-7, 1e-4))  # fmt: skip
def test_antisymmetric_and_zero_at_equal_temperature(
    model, params, t_i, t_j, r_i, r_j, overlap, f_n, t_contact, v, m
):
    p = row(model, **params)
    r_c = geometric_contact_radius(r_i, r_j, overlap)
    args = (overlap, r_c, f_n, t_contact, v, m)
    q_ij = rate(model, p, t_i, t_j, r_i, r_j, *args)
    assert np.isfinite(q_ij)
    assert rate(model, p, t_i, t_i, r_i, r_j, *args) == 0.0
    if not math.isinf(r_j):
        q_ji = rate(model, swap_row(p), t_j, t_i, r_j, r_i, *args)
        assert q_ji == -q_ij
    if t_j > t_i:
        assert q_ij >= 0.0


# models whose R_j -> inf limit is finite (the pipes and Yun & Evans use an isothermal wall,
# tested by hand above)
WALL_LIMIT_MODELS = ["batchelor_obrien_simple", "batchelor_obrien_complete", "sun_chen1988",
                     "zhou2008", "resistance_network"]  # fmt: skip


@pytest.mark.parametrize("model", WALL_LIMIT_MODELS)
@settings(max_examples=25, deadline=None)
@given(r_i=radii, overlap=st.floats(-1e-4, 2e-5), f_n=st.floats(0.0, 5.0),
       t_contact=st.floats(0.0, 1e-4), v=st.floats(0.0, 2.0))  # fmt: skip
def test_wall_is_the_large_radius_limit(model, r_i, overlap, f_n, t_contact, v):
    p = row(model, is_wall=True)
    r_c = geometric_contact_radius(r_i, INF, overlap)
    args = (overlap, r_c, f_n, t_contact, v, 1e-5)
    wall = rate(model, p, 300.0, 400.0, r_i, INF, *args)
    far = rate(model, p, 300.0, 400.0, r_i, 1e12 * r_i, *args)
    assert wall == pytest.approx(far, rel=1e-8, abs=1e-300)


@pytest.mark.parametrize(
    ("model", "params"),
    [
        ("batchelor_obrien_simple", {}),
        ("batchelor_obrien_complete", {"blend": "hermite"}),
        ("batchelor_obrien_modified", {"blend": "hermite"}),
        ("thermal_pipe", {}),
        ("quintana_ruiz_campello2020", {}),
    ],
)
@settings(max_examples=40, deadline=None)
@given(r_i=radii, r_j=st.one_of(radii, st.just(INF)), d1=st.floats(-3e-4, 2e-5),
       d2=st.floats(-3e-4, 2e-5))  # fmt: skip
def test_monotonic_in_overlap(model, params, r_i, r_j, d1, d2):
    p = row(model, K_HIGH, K_HIGH, **params)
    lo, hi = sorted((d1, d2))
    q = [
        rate(model, p, 300.0, 310.0, r_i, r_j, d, geometric_contact_radius(r_i, r_j, d))
        for d in (lo, hi)
    ]
    assert q[0] <= q[1] * (1 + 1e-12)
