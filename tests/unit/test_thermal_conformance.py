"""Every registered thermal pair model (contact_radius, direct_conduction, indirect_conduction):
dispatcher == own kernel, row shape, swap/symmetry, required properties named in errors, a docs
page. The family list is registry.FAMILIES: a family with models but no dispatcher here (or in
test_registry_conformance.py for the mechanical ones) fails."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermodem.models import registry
from thermodem.models.thermal.contact_radius import contact_radius_dispatch
from thermodem.models.thermal.direct_conduction import direct_conduction_dispatch
from thermodem.models.thermal.direct_conduction_family import swap_row
from thermodem.models.thermal.indirect_conduction import indirect_conduction_dispatch
from thermodem.models.thermal.voronoi import voronoi_dispatch
from thermodem.state.materials import Material, resolve_pair

DISPATCH = {
    "contact_radius": contact_radius_dispatch,
    "direct_conduction": direct_conduction_dispatch,
    "indirect_conduction": indirect_conduction_dispatch,
}
PARTICLE_FAMILIES = ("convection", "radiation")  # tests/unit/test_particle_terms_conformance.py
MECHANICAL = ("normal", "tangential", "rolling")  # tests/unit/test_registry_conformance.py
GENERATION_FAMILIES = ("heat_generation",)  # tests/unit/test_heat_generation_models.py
FAMILIES = tuple(f for f in registry.FAMILIES if f in DISPATCH)
DOCS = Path(__file__).resolve().parents[2] / "docs" / "models"


def material(**kw) -> Material:
    base = dict(
        density=2500.0,
        youngs_modulus=5.0e7,
        poisson_ratio=0.25,
        specific_heat=800.0,
        thermal_conductivity=2.0,
        microhardness=5e9,
        surface_roughness=1e-6,
        surface_slope=0.05,
        thermal_accommodation=0.8,
        youngs_modulus_real=6e10,
        emissivity=0.8,
    )
    base.update(kw)
    return Material(**base)


MAT_I = material()
MAT_J = material(
    thermal_conductivity=7.0,
    density=7800.0,
    specific_heat=460.0,
    youngs_modulus=2e8,
    youngs_modulus_real=2e11,
    poisson_ratio=0.3,
    microhardness=2e9,
    surface_roughness=3e-6,
    thermal_accommodation=0.6,
)

SPECS = [registry.get(f, n) for f in FAMILIES for n in registry.names(f)]
IDS = [f"{s.family}.{s.name}" for s in SPECS]


def params_of(spec):
    return spec.params(**spec.example_params)


def random_inputs(rng, wall: bool):
    r_i = rng.uniform(2e-4, 5e-3)
    r_j = np.inf if wall else rng.uniform(2e-4, 5e-3)
    overlap = rng.uniform(-1e-4, 2e-5)
    d = r_i + r_j - overlap
    r_c = rng.uniform(0.0, 1e-4) if overlap > 0 else 0.0
    return dict(
        t_i=rng.uniform(250, 1200),
        t_j=rng.uniform(250, 1200),
        r_i=r_i,
        r_j=r_j,
        dist=d,
        overlap=overlap,
        r_c=r_c,
        f_n=rng.uniform(0, 5),
        t_contact=rng.uniform(0, 1e-4),
        v=rng.uniform(0, 2),
        m=rng.uniform(1e-7, 1e-4),
        # the input row of an external pair set (no extra draw: the other inputs stay as they
        # were)
        face_area=(1.0 + 2000.0 * r_i) * r_i * r_i,
    )


def call(spec, fn, p, x, swap=False):
    i, j = ("j", "i") if swap else ("i", "j")
    geo = (x[f"r_{i}"], x[f"r_{j}"], x["dist"], x["overlap"])
    tail = (x["f_n"], x["t_contact"], x["v"], x["m"])
    if spec.family == "contact_radius":
        return fn(p, *geo, *tail)
    if spec.family == "indirect_conduction" and spec.target == "external":
        inputs = np.array([x["face_area"]])
        return fn(p, x[f"r_{i}"], x[f"r_{j}"], x["dist"], x["r_c"], inputs)
    if spec.family == "indirect_conduction":
        return fn(p, x[f"r_{i}"], x[f"r_{j}"], x["dist"], x["r_c"], x["f_n"])
    if spec.family in PARTICLE_FAMILIES:
        return fn(p, x[f"t_{i}"], x[f"r_{i}"], np.zeros((1, 0)), 0)
    return fn(p, x[f"t_{i}"], x[f"t_{j}"], *geo, x["r_c"], *tail)


def same(a, b) -> bool:  # noqa: ANN001
    if isinstance(a, tuple):
        return all(same(x, y) for x, y in zip(a, b, strict=True))
    return a == b or (math.isnan(a) and math.isnan(b))


def test_every_family_with_models_is_checked_by_a_conformance_test():
    for family in registry.FAMILIES:
        if registry.names(family):
            assert (
                family in DISPATCH
                or family in MECHANICAL
                or family in PARTICLE_FAMILIES
                or family in GENERATION_FAMILIES
            ), family


def test_every_family_has_none_with_id_zero_and_unknown_ids_give_nan():
    for family in FAMILIES:
        assert registry.get(family, "none").model_id == 0
        ids = [registry.get(family, n).model_id for n in registry.names(family)]
        assert sorted(ids) == list(range(len(ids)))
    p = np.zeros(max(s.width for s in registry.all_models()))
    unknown = len(registry.names("contact_radius"))
    assert math.isnan(contact_radius_dispatch(unknown, p, 1e-3, 1e-3, 2e-3, 1e-6, 1.0, 0, 0, 1e-5))
    unknown = len(registry.names("direct_conduction"))
    q = direct_conduction_dispatch(unknown, p, 300, 310, 1e-3, 1e-3, 2e-3, 1e-6, 1e-5, 1, 0, 0, 1)
    assert math.isnan(q)
    unknown = len(registry.names("indirect_conduction"))
    assert math.isnan(indirect_conduction_dispatch(unknown, p, 1e-3, 1e-3, 2e-3, 1e-5, 1.0))


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
@pytest.mark.parametrize("wall", [False, True])
def test_dispatcher_agrees_with_kernel_and_swap(spec, wall):
    p = spec.pack(params_of(spec), resolve_pair(MAT_I, MAT_J, is_wall=wall))
    assert p.dtype == np.float64 and p.shape == (spec.width,)
    rng = np.random.default_rng(spec.model_id + 100 * wall)
    # models of the external pair set (the Voronoi faces) have their own dispatcher
    dispatch = voronoi_dispatch if spec.target == "external" else DISPATCH[spec.family]
    for _ in range(60):
        x = random_inputs(rng, wall)
        own = call(spec, spec.kernel, p, x)
        via = call(spec, lambda *a: dispatch(spec.model_id, *a), p, x)
        assert same(own, via), (own, via)
        assert np.all(np.isfinite(own))
        if spec.family in PARTICLE_FAMILIES:  # (Q, G): G = -dQ/dT_i >= 0, by differences
            q, g = own
            x_up = dict(x, t_i=x["t_i"] * (1 + 1e-6))
            q_up = call(spec, spec.kernel, p, x_up)[0]
            assert g >= 0.0 and -(q_up - q) / (x["t_i"] * 1e-6) == pytest.approx(g, rel=1e-4)
            continue
        if wall:
            continue
        if spec.antisymmetric:
            swapped = call(spec, spec.kernel, swap_row(p, spec.swap_pairs), x, swap=True)
            assert swapped == -own
        elif spec.family == "indirect_conduction":  # a conductance: symmetric to the bit
            assert spec.symmetric
            swapped = call(spec, spec.kernel, swap_row(p, spec.swap_pairs), x, swap=True)
            assert swapped == own and own >= 0.0
        else:
            assert spec.symmetric
            assert call(spec, spec.kernel, p, x, swap=True) == pytest.approx(own, rel=1e-12)


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_metadata_and_missing_properties(spec):
    assert spec.summary and spec.reference and spec.params.__doc__
    fields = Material.model_fields
    for prop in spec.requires:
        assert prop in fields, prop
        if fields[prop].is_required():
            continue  # always present
        brokens = [resolve_pair(material(**{prop: None}), MAT_J)]
        if spec.family not in PARTICLE_FAMILIES:  # (a particle term sees one material)
            brokens.append(resolve_pair(MAT_I, material(**{prop: None})))
        for broken in brokens:
            with pytest.raises(ValueError, match=prop):
                spec.pack(params_of(spec), broken)


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_docs_page_exists(spec):
    page = DOCS / f"{spec.family}-{spec.name}.md"
    assert page.is_file(), page
    assert spec.name in page.read_text(encoding="utf-8")


@pytest.mark.parametrize(
    "spec", [s for s in SPECS if s.family != "contact_radius"], ids=lambda s: f"{s.family}.{s.name}"
)
def test_no_model_conducts_beyond_the_pairs_its_pair_set_holds(spec):
    """A model whose range the neighbour machinery does not cover cannot exist: a model that
    is not evaluated on the range set (contacts target, no interaction range of its own)
    gives exactly 0 for every separated pair, and a model with a range gives 0 beyond it
    (its pairs within the range are all in the range set, tests/verification/
    test_range_set.py). External-set models get their pairs from outside (Voronoi faces)."""
    if spec.target == "external":
        pytest.skip("pairs from the external set")
    fn = spec.kernel
    rng = np.random.default_rng(41)
    on_range_set = spec.target == "range" or (
        spec.family == "direct_conduction" and spec.interaction_range is not None
    )
    params = params_of(spec)
    for wall in (False, True):
        p = spec.pack(params, resolve_pair(MAT_I, MAT_J, is_wall=wall))
        for _ in range(300):
            x = random_inputs(rng, wall)
            reach = spec.interaction_range(params, x["r_i"], x["r_j"]) if on_range_set else 0.0
            gap = reach * (1.0 + rng.uniform(0.0, 2.0)) + rng.uniform(1e-12, 1e-4)
            x["overlap"], x["r_c"] = -gap, 0.0
            x["dist"] = x["r_i"] + gap if wall else x["r_i"] + x["r_j"] + gap
            assert call(spec, fn, p, x) == 0.0, (spec.name, wall, x)
    if not on_range_set and spec.interaction_range is not None:
        assert spec.interaction_range(params, 1e-3, 1e-3) == 0.0
