"""Particle insertion: configuration, radius sampling, packings, pouring and particle files.

Reference values come from outside the code under test: cKDTree neighbour searches for
overlaps, scipy.stats for distributions, and hand computations for lattices and fractions.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError
from scipy import stats
from scipy.spatial import cKDTree

from thermodem.config.insertion import (
    BoxRegion,
    DiscreteRadius,
    FileInsertion,
    LatticeInsertion,
    ListInsertion,
    LognormalRadius,
    MonoRadius,
    PourInsertion,
    RandomBoxInsertion,
    RandomCylinderInsertion,
    TruncatedNormalRadius,
    UniformRadius,
    parse_insertion_section,
)
from thermodem.errors import ConfigError
from thermodem.geometry.insertion import (
    InsertedParticles,
    Pourer,
    insert,
    load_particle_file,
    sample_radii,
    save_particle_file,
)

N_STATS = 20000


# --------------------------------------------------------------------------------------------
# helpers (independent of the code under test)
# --------------------------------------------------------------------------------------------


def count_overlaps(pos: np.ndarray, rad: np.ndarray) -> int:
    """Number of overlapping pairs within one set of spheres."""
    if len(rad) < 2:
        return 0
    pairs = cKDTree(pos).query_pairs(2.0 * rad.max(), output_type="ndarray")
    if pairs.size == 0:
        return 0
    d = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    return int(np.sum(d < rad[pairs[:, 0]] + rad[pairs[:, 1]] - 1e-12))


def count_cross_overlaps(pos_a, rad_a, pos_b, rad_b) -> int:
    """Number of overlapping pairs between two sets of spheres."""
    if len(rad_a) == 0 or len(rad_b) == 0:
        return 0
    hits = cKDTree(pos_b).query_ball_point(pos_a, rad_a + rad_b.max())
    n = 0
    for i, js in enumerate(hits):
        for j in js:
            if np.linalg.norm(pos_a[i] - pos_b[j]) < rad_a[i] + rad_b[j] - 1e-12:
                n += 1
    return n


def inside_box(pos, rad, lower, upper) -> bool:
    lower, upper = np.asarray(lower), np.asarray(upper)
    r = rad[:, None]
    return bool(np.all(pos - r >= lower - 1e-12) and np.all(pos + r <= upper + 1e-12))


def inside_cylinder(pos, rad, base, axis, radius, length) -> bool:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    rel = pos - np.asarray(base)
    h = rel @ axis
    rho = np.linalg.norm(rel - h[:, None] * axis, axis=1)
    return bool(
        np.all(h >= rad - 1e-12)
        and np.all(h <= length - rad + 1e-12)
        and np.all(rho <= radius - rad + 1e-12)
    )


def random_box(**kw) -> RandomBoxInsertion:
    base = dict(
        material="glass",
        distribution={"kind": "uniform", "min_radius": 0.02, "max_radius": 0.04},
        lower=(0.0, 0.0, 0.0),
        upper=(1.0, 1.0, 1.0),
        count=300,
    )
    base.update(kw)
    return RandomBoxInsertion(**base)


# --------------------------------------------------------------------------------------------
# configuration
# --------------------------------------------------------------------------------------------


def test_section_parses_every_kind(tmp_path):
    entries = parse_insertion_section(
        [
            {
                "kind": "lattice",
                "material": "a",
                "distribution": {"kind": "mono", "radius": 0.01},
                "lower": [0, 0, 0],
                "upper": [1, 1, 1],
                "spacing": 0.05,
            },
            {
                "kind": "random_box",
                "material": "a",
                "distribution": {"kind": "uniform", "min_radius": 0.01, "max_radius": 0.02},
                "lower": [0, 0, 0],
                "upper": [1, 1, 1],
                "volume_fraction": 0.1,
            },
            {
                "kind": "random_cylinder",
                "material": "a",
                "distribution": {
                    "kind": "truncated_normal",
                    "mean": 0.01,
                    "std": 0.002,
                    "min_radius": 0.005,
                    "max_radius": 0.015,
                },
                "base_centre": [0, 0, 0],
                "axis": [0, 0, 2],
                "radius": 0.5,
                "length": 1,
                "count": 10,
                "velocity": [0, 0, -1],
                "temperature": 300,
            },
            {
                "kind": "pour",
                "material": "a",
                "distribution": {
                    "kind": "lognormal",
                    "median": 0.01,
                    "sigma": 0.2,
                    "max_radius": 0.02,  # a pour needs a largest radius
                },
                "region": {
                    "kind": "cylinder",
                    "base_centre": [0, 0, 1],
                    "axis": [0, 0, 1],
                    "radius": 0.2,
                    "length": 0.1,
                },
                "rate": 100,
                "end_time": 1,
                "interval": 0.05,
            },
            {"kind": "file", "material": "a", "path": str(tmp_path / "p.csv")},
        ]
    )
    kinds = [type(e) for e in entries]
    assert kinds == [
        LatticeInsertion,
        RandomBoxInsertion,
        RandomCylinderInsertion,
        PourInsertion,
        FileInsertion,
    ]
    assert entries[2].axis == (0.0, 0.0, 1.0)  # normalised
    assert entries[2].temperature == 300.0
    assert entries[3].region.kind == "cylinder"


def test_lower_must_be_below_upper_names_axis_and_values():
    with pytest.raises(ValidationError) as err:
        random_box(lower=(0, 0, 0.5), upper=(1, 1, 0.5))
    msg = str(err.value)
    assert "lower corner must be < upper corner" in msg
    assert "z axis" in msg and "0.5" in msg


def test_discrete_fractions_must_sum_to_one():
    with pytest.raises(ValidationError, match=r"sum to 0\.9.*must sum to 1"):
        DiscreteRadius(radii=[1e-3, 2e-3], fractions=[0.5, 0.4])
    # within 1e-9 is fine
    DiscreteRadius(radii=[1e-3, 2e-3], fractions=[0.5, 0.5 + 5e-10])
    with pytest.raises(ValidationError, match="one fraction per radius"):
        DiscreteRadius(radii=[1e-3, 2e-3, 3e-3], fractions=[0.5, 0.5])


@pytest.mark.parametrize(
    ("model", "kwargs", "pattern"),
    [
        (UniformRadius, {"min_radius": 2e-3, "max_radius": 1e-3}, "min_radius=0.002"),
        (
            TruncatedNormalRadius,
            {"mean": 1e-3, "std": 1e-5, "min_radius": 1e-2, "max_radius": 2e-2},
            "zero probability",
        ),
        (LognormalRadius, {"median": 1e-3, "mean": 1e-3, "sigma": 0.1}, "exactly one"),
        (LognormalRadius, {"sigma": 0.1}, "exactly one"),
        (MonoRadius, {"radius": -1.0}, "greater than 0"),
        (MonoRadius, {"radius": 1e-3, "colour": "red"}, "Extra inputs"),
    ],
)
def test_distribution_validation_errors(model, kwargs, pattern):
    with pytest.raises(ValidationError, match=pattern):
        model(**kwargs)


def test_entry_validation_errors():
    with pytest.raises(ValidationError, match="exactly one of 'count' or 'volume_fraction'"):
        random_box(volume_fraction=0.2)
    with pytest.raises(ValidationError, match="non-zero vector"):
        RandomCylinderInsertion(
            material="a",
            distribution={"kind": "mono", "radius": 0.01},
            base_centre=(0, 0, 0),
            axis=(0, 0, 0),
            radius=1,
            length=1,
            count=1,
        )
    with pytest.raises(ValidationError, match="end_time=0.5 must be > start_time=1.0"):
        PourInsertion(
            material="a",
            distribution={"kind": "mono", "radius": 0.01},
            region={"kind": "box", "lower": (0, 0, 0), "upper": (1, 1, 1)},
            rate=10,
            start_time=1.0,
            end_time=0.5,
            interval=0.1,
        )
    lattice = dict(
        material="a",
        distribution={"kind": "mono", "radius": 0.01},
        lower=(0, 0, 0),
        upper=(1, 1, 1),
    )
    with pytest.raises(ValidationError, match=r"spacing along x is 0\.015 m.*0\.02"):
        LatticeInsertion(**lattice, spacing=0.015)
    with pytest.raises(ValidationError, match="exactly one of 'spacing' or 'count'"):
        LatticeInsertion(**lattice, spacing=0.1, count=(2, 2, 2))
    with pytest.raises(ValidationError, match="spacing along y"):
        LatticeInsertion(**lattice, count=(2, 100, 2))
    with pytest.raises(ValidationError, match="bounded radius distribution"):
        LatticeInsertion(
            **{**lattice, "distribution": {"kind": "lognormal", "median": 0.01, "sigma": 0.1}},
            spacing=0.1,
        )
    with pytest.raises(ValidationError, match="union_tag_invalid|does not match any"):
        parse_insertion_section([{"kind": "sprinkle", "material": "a"}])
    with pytest.raises(ValidationError, match="Extra inputs"):
        random_box(distributon={"kind": "mono", "radius": 0.01})


# --------------------------------------------------------------------------------------------
# radius distributions
# --------------------------------------------------------------------------------------------


def test_mono_and_uniform_statistics():
    rng = np.random.default_rng(0)
    assert np.all(sample_radii(MonoRadius(radius=1e-3), 50, rng) == 1e-3)
    a, b = 1e-3, 3e-3
    r = sample_radii(UniformRadius(min_radius=a, max_radius=b), N_STATS, rng)
    assert r.shape == (N_STATS,) and r.min() >= a and r.max() <= b
    std = (b - a) / math.sqrt(12.0)
    assert abs(r.mean() - (a + b) / 2) < 5 * std / math.sqrt(N_STATS)
    assert r.std() == pytest.approx(std, rel=0.03)
    assert stats.kstest(r, stats.uniform(loc=a, scale=b - a).cdf).pvalue > 1e-3


@pytest.mark.parametrize(
    ("mean", "std", "lo", "hi"),
    [
        (1e-3, 2e-4, 7e-4, 1.5e-3),  # both tails cut
        (1e-3, 5e-4, 1.6e-3, 3e-3),  # interval entirely in the upper tail
        (1e-3, 1e-4, 5e-4, 1.5e-3),  # nearly untruncated
    ],
)
def test_truncated_normal_matches_scipy(mean, std, lo, hi):
    rng = np.random.default_rng(1)
    dist = TruncatedNormalRadius(mean=mean, std=std, min_radius=lo, max_radius=hi)
    r = sample_radii(dist, N_STATS, rng)
    ref = stats.truncnorm((lo - mean) / std, (hi - mean) / std, loc=mean, scale=std)
    assert r.min() >= lo and r.max() <= hi
    assert abs(r.mean() - ref.mean()) < 5 * ref.std() / math.sqrt(N_STATS)
    assert r.std() == pytest.approx(ref.std(), rel=0.03)
    assert stats.kstest(r, ref.cdf).pvalue > 1e-3


def test_lognormal_median_and_mean_parametrisations():
    rng = np.random.default_rng(2)
    sigma = 0.3
    r = sample_radii(LognormalRadius(median=1e-3, sigma=sigma), N_STATS, rng)
    ref = stats.lognorm(s=sigma, scale=1e-3)
    assert stats.kstest(r, ref.cdf).pvalue > 1e-3
    assert np.median(r) == pytest.approx(1e-3, rel=0.02)
    assert np.log(r).std() == pytest.approx(sigma, rel=0.03)

    target_mean = 2e-3
    r = sample_radii(LognormalRadius(mean=target_mean, sigma=sigma), N_STATS, rng)
    sd = target_mean * math.sqrt(math.exp(sigma**2) - 1.0)  # lognormal std from its mean
    assert abs(r.mean() - target_mean) < 5 * sd / math.sqrt(N_STATS)


def test_truncated_lognormal():
    rng = np.random.default_rng(3)
    median, sigma, lo, hi = 1e-3, 0.5, 6e-4, 2e-3
    r = sample_radii(
        LognormalRadius(median=median, sigma=sigma, min_radius=lo, max_radius=hi), N_STATS, rng
    )
    assert r.min() >= lo and r.max() <= hi
    mu = math.log(median)
    ref = stats.truncnorm(
        (math.log(lo) - mu) / sigma, (math.log(hi) - mu) / sigma, loc=mu, scale=sigma
    )
    assert stats.kstest(np.log(r), ref.cdf).pvalue > 1e-3


def test_mass_fractions_convert_to_number_fractions_by_hand():
    # Two sizes, equal mass: a 2x larger sphere weighs 8x more, so there are 8x fewer of them.
    d = DiscreteRadius(radii=[1e-3, 2e-3], fractions=[0.5, 0.5], fraction_basis="mass")
    np.testing.assert_allclose(d.number_fractions(), [8 / 9, 1 / 9], rtol=1e-12)

    d = DiscreteRadius(radii=[1.0, 2.0, 3.0], fractions=[0.2, 0.3, 0.5], fraction_basis="mass")
    w = [0.2 / 1.0, 0.3 / 8.0, 0.5 / 27.0]
    np.testing.assert_allclose(d.number_fractions(), np.array(w) / sum(w), rtol=1e-12)

    d = DiscreteRadius(radii=[1.0, 2.0], fractions=[0.25, 0.75])
    np.testing.assert_allclose(d.number_fractions(), [0.25, 0.75])


def test_discrete_sampling_frequencies():
    rng = np.random.default_rng(4)
    d = DiscreteRadius(radii=[1e-3, 2e-3], fractions=[0.5, 0.5], fraction_basis="mass")
    r = sample_radii(d, N_STATS, rng)
    assert set(np.unique(r)) == {1e-3, 2e-3}
    observed = np.array([np.sum(r == 1e-3), np.sum(r == 2e-3)])
    assert stats.chisquare(observed, N_STATS * np.array([8 / 9, 1 / 9])).pvalue > 1e-3
    # the sampled mass split is close to the requested one
    mass = observed * np.array([1.0, 8.0])
    assert mass[0] / mass.sum() == pytest.approx(0.5, abs=0.02)


def test_sampling_is_deterministic_for_a_seed():
    d = LognormalRadius(median=1e-3, sigma=0.2, max_radius=2e-3)
    a = sample_radii(d, 100, np.random.default_rng(5))
    b = sample_radii(d, 100, np.random.default_rng(5))
    c = sample_radii(d, 100, np.random.default_rng(6))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


# --------------------------------------------------------------------------------------------
# random packings
# --------------------------------------------------------------------------------------------


def test_random_box_no_overlap_inside_and_count():
    entry = random_box(count=400, velocity=(1.0, 2.0, 3.0), temperature=350.0)
    p = insert(entry, np.random.default_rng(10), np.zeros((0, 3)), np.zeros(0))
    assert isinstance(p, InsertedParticles)
    assert len(p) == 400 and p.position.shape == (400, 3) and p.material == "glass"
    assert count_overlaps(p.position, p.radius) == 0
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)
    np.testing.assert_array_equal(p.velocity, np.tile([1.0, 2.0, 3.0], (400, 1)))
    np.testing.assert_array_equal(p.temperature, np.full(400, 350.0))


def test_random_box_volume_fraction():
    entry = random_box(
        distribution={"kind": "mono", "radius": 0.03}, count=None, volume_fraction=0.2
    )
    p = insert(entry, np.random.default_rng(11), None, None)
    v_particle = 4.0 / 3.0 * math.pi * 0.03**3
    assert len(p) == math.ceil(0.2 / v_particle)  # box volume is 1 m^3
    assert count_overlaps(p.position, p.radius) == 0
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)
    assert p.temperature is None


def test_random_box_avoids_existing_particles():
    rng = np.random.default_rng(12)
    existing_pos = np.vstack([[0.5, 0.5, 0.5], rng.uniform(0.0, 1.0, (200, 3))])
    existing_rad = np.concatenate([[0.3], np.full(200, 0.03)])
    entry = random_box(count=200)
    p = insert(entry, rng, existing_pos, existing_rad)
    assert len(p) == 200
    assert count_overlaps(p.position, p.radius) == 0
    assert count_cross_overlaps(p.position, p.radius, existing_pos, existing_rad) == 0
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)


def test_random_cylinder_tilted_axis():
    entry = RandomCylinderInsertion(
        material="steel",
        distribution={"kind": "discrete", "radii": [0.01, 0.02], "fractions": [0.7, 0.3]},
        base_centre=(0.1, -0.2, 0.3),
        axis=(1.0, 1.0, 0.5),
        radius=0.15,
        length=0.6,
        count=300,
    )
    p = insert(entry, np.random.default_rng(13), None, None)
    assert len(p) == 300
    assert count_overlaps(p.position, p.radius) == 0
    assert inside_cylinder(p.position, p.radius, entry.base_centre, (1, 1, 0.5), 0.15, 0.6)
    # the cylinder is filled throughout, not only near its axis
    rel = p.position - np.array(entry.base_centre)
    a = np.array([1, 1, 0.5]) / 1.5
    rho = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
    assert rho.max() > 0.1


def test_random_insertion_too_many_particles_raises():
    # 110 spheres of r = 0.1 fill 0.46 of the unit box: allowed, but random sequential
    # addition jams below that (0.38 for equal spheres, less against walls)
    entry = random_box(distribution={"kind": "mono", "radius": 0.1}, count=110, max_attempts=50)
    with pytest.raises(ValueError, match=r"placed only \d+ of 110 particles.*larger region"):
        insert(entry, np.random.default_rng(14), None, None)
    too_big = random_box(distribution={"kind": "mono", "radius": 0.6}, count=1)
    with pytest.raises(ValueError, match="does not fit"):
        insert(too_big, np.random.default_rng(14), None, None)


def test_random_insertion_is_deterministic_for_a_seed():
    entry = random_box(count=100)
    a = insert(entry, np.random.default_rng(15), None, None)
    b = insert(entry, np.random.default_rng(15), None, None)
    c = insert(entry, np.random.default_rng(16), None, None)
    np.testing.assert_array_equal(a.position, b.position)
    np.testing.assert_array_equal(a.radius, b.radius)
    assert not np.array_equal(a.position, c.position)


def test_walls_ok_rejects_candidates():
    entry = random_box(count=100)
    p = insert(
        entry, np.random.default_rng(17), None, None, walls_ok=lambda x, r: x[:, 0] - r >= 0.5
    )
    assert len(p) == 100
    assert np.all(p.position[:, 0] - p.radius >= 0.5)
    assert count_overlaps(p.position, p.radius) == 0


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    count=st.integers(1, 60),
    r_min=st.floats(0.005, 0.02),
    ratio=st.floats(1.0, 2.0),
)
def test_random_box_property(seed, count, r_min, ratio):
    entry = random_box(
        distribution={"kind": "uniform", "min_radius": r_min, "max_radius": r_min * ratio},
        count=count,
        lower=(-0.2, 0.0, 0.3),
        upper=(0.4, 0.5, 1.0),
    )
    p = insert(entry, np.random.default_rng(seed), None, None)
    assert len(p) == count
    assert count_overlaps(p.position, p.radius) == 0
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)


# --------------------------------------------------------------------------------------------
# lattice
# --------------------------------------------------------------------------------------------


def test_lattice_spacing_count_and_centring():
    entry = LatticeInsertion(
        material="a",
        distribution={"kind": "mono", "radius": 0.001},
        lower=(0.0, 0.0, 0.0),
        upper=(0.1, 0.05, 0.02),
        spacing=0.01,
    )
    p = insert(entry, np.random.default_rng(20), None, None)
    # usable span per axis = extent - 2 r = 0.098, 0.048, 0.018 -> 10, 5, 2 sites
    assert len(p) == 10 * 5 * 2
    for a, n in enumerate((10, 5, 2)):
        u = np.unique(np.round(p.position[:, a], 12))
        assert u.size == n
        np.testing.assert_allclose(np.diff(u), 0.01, rtol=1e-9)
    # centred: equal margins on both sides of each axis
    np.testing.assert_allclose(p.position.min(axis=0) + p.position.max(axis=0), [0.1, 0.05, 0.02])
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)
    assert count_overlaps(p.position, p.radius) == 0


def test_lattice_count_per_axis():
    entry = LatticeInsertion(
        material="a",
        distribution={"kind": "uniform", "min_radius": 0.05, "max_radius": 0.1},
        lower=(0.0, 0.0, 0.0),
        upper=(1.0, 1.0, 1.0),
        count=(4, 3, 1),
    )
    p = insert(entry, np.random.default_rng(21), None, None)
    assert len(p) == 12
    xs = np.unique(np.round(p.position[:, 0], 12))
    np.testing.assert_allclose(xs, [0.1, 0.1 + 0.8 / 3, 0.1 + 1.6 / 3, 0.9])
    np.testing.assert_allclose(np.unique(np.round(p.position[:, 1], 12)), [0.1, 0.5, 0.9])
    np.testing.assert_allclose(p.position[:, 2], 0.5)
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)


def test_lattice_jitter_stays_inside_without_overlap():
    entry = LatticeInsertion(
        material="a",
        distribution={"kind": "mono", "radius": 0.02},
        lower=(0.0, 0.0, 0.0),
        upper=(0.5, 0.5, 0.5),
        spacing=0.05,
        jitter=0.005,
    )
    rng = np.random.default_rng(22)
    p = insert(entry, rng, None, None)
    ref = insert(entry.model_copy(update={"jitter": 0.0}), rng, None, None)
    assert count_overlaps(p.position, p.radius) == 0
    assert inside_box(p.position, p.radius, entry.lower, entry.upper)
    assert not np.allclose(np.sort(p.position[:, 0]), np.sort(ref.position[:, 0]))


def test_lattice_skips_sites_overlapping_existing():
    entry = LatticeInsertion(
        material="a",
        distribution={"kind": "mono", "radius": 0.02},
        lower=(0.0, 0.0, 0.0),
        upper=(1.0, 1.0, 1.0),
        spacing=0.1,
    )
    full = insert(entry, np.random.default_rng(23), None, None)
    ex_pos, ex_rad = np.array([[0.5, 0.5, 0.5]]), np.array([0.25])
    p = insert(entry, np.random.default_rng(23), ex_pos, ex_rad)
    assert count_cross_overlaps(p.position, p.radius, ex_pos, ex_rad) == 0
    blocked = np.linalg.norm(full.position - 0.5, axis=1) < 0.27
    assert len(p) == len(full) - blocked.sum() and blocked.sum() > 0


# --------------------------------------------------------------------------------------------
# particle files
# --------------------------------------------------------------------------------------------


def test_file_round_trip_with_optional_columns(tmp_path):
    rng = np.random.default_rng(30)
    n = 25
    original = InsertedParticles(
        position=rng.normal(size=(n, 3)),
        radius=rng.uniform(1e-3, 2e-3, n),
        velocity=rng.normal(size=(n, 3)),
        temperature=rng.uniform(280.0, 400.0, n),
        material="glass",
    )
    path = tmp_path / "particles.txt"
    save_particle_file(path, original)
    back = load_particle_file(path, material="glass")
    np.testing.assert_array_equal(back.position, original.position)
    np.testing.assert_array_equal(back.radius, original.radius)
    np.testing.assert_array_equal(back.velocity, original.velocity)
    np.testing.assert_array_equal(back.temperature, original.temperature)
    assert back.material == "glass"


@pytest.mark.parametrize(
    "text",
    [
        "x y z radius vx vy vz temperature\n0.1 0.2 0.3 1e-3 1 2 3 300\n\n"
        "# comment\n-0.5 0.25 1e3 2.5e-3 -1 -2 -3 310.5\n",
        "# radius, z, y, x\n0.001, 3.0, 2.0, 1.0\n\n# a comment\n0.002,6,5,4\n",
        "x,y,z,radius\n1,2,3,0.5\n",
    ],
)
def test_file_fast_parser_equals_the_checked_parser(tmp_path, text):
    """The NumPy fast path is taken for regular files and gives the checked parser's values
    and line numbers (the checked parser remains the reference and the error reporter)."""
    from thermodem.io.particle_file import _parse_checked, _parse_fast

    path = tmp_path / "p.txt"
    path.write_text(text)
    fast = _parse_fast(path, "glass")
    checked = _parse_checked(path, "glass")
    assert fast is not None
    for name in ("position", "radius", "velocity"):
        np.testing.assert_array_equal(
            getattr(fast.particles, name), getattr(checked.particles, name)
        )
    if checked.particles.temperature is None:
        assert fast.particles.temperature is None
    else:
        np.testing.assert_array_equal(fast.particles.temperature, checked.particles.temperature)
    np.testing.assert_array_equal(fast.line_numbers, checked.line_numbers)
    assert (fast.has_velocity, fast.has_temperature) == (
        checked.has_velocity,
        checked.has_temperature,
    )


def test_file_csv_any_column_order_comments_and_defaults(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("# radius, z, y, x\n0.001, 3.0, 2.0, 1.0\n\n# a comment\n0.002,6,5,4\n")
    p = load_particle_file(path)
    np.testing.assert_array_equal(p.position, [[1, 2, 3], [4, 5, 6]])
    np.testing.assert_array_equal(p.radius, [0.001, 0.002])
    np.testing.assert_array_equal(p.velocity, np.zeros((2, 3)))
    assert p.temperature is None

    entry = FileInsertion(material="sand", path=path, velocity=(0, 0, -2), temperature=310)
    q = insert(entry, np.random.default_rng(0), None, None)
    assert q.material == "sand"
    np.testing.assert_array_equal(q.velocity, [[0, 0, -2], [0, 0, -2]])
    np.testing.assert_array_equal(q.temperature, [310.0, 310.0])

    # file columns override the entry defaults
    path2 = tmp_path / "p2.txt"
    path2.write_text("x y z radius vx vy vz temperature\n0 0 0 1e-3 1 2 3 500\n")
    q = insert(FileInsertion(material="sand", path=path2, temperature=310), None, None, None)
    np.testing.assert_array_equal(q.velocity, [[1, 2, 3]])
    np.testing.assert_array_equal(q.temperature, [500.0])


def test_file_with_a_byte_order_mark_is_read(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte order mark: the header was refused as the
    unknown column '\\ufeffx'. Read by the fast parser and by the checked one (which names
    the line of a duplicate row)."""
    path = tmp_path / "excel.csv"
    path.write_bytes(b"\xef\xbb\xbfx,y,z,radius\r\n0,0,0,1e-3\r\n0.01,0,0,1e-3\r\n")
    p = load_particle_file(path)
    np.testing.assert_array_equal(p.position, [[0, 0, 0], [0.01, 0, 0]])
    path.write_bytes(b"\xef\xbb\xbfx y z radius\n0 0 0 abc\n")
    with pytest.raises(ValueError, match=r"line 2, column 'radius': 'abc' is not a number"):
        load_particle_file(path)


@pytest.mark.parametrize(
    ("content", "pattern"),
    [
        (
            "x y z radius\n0 0 0 1e-3\n0 0 0 abc\n",
            r"line 3, column 'radius': 'abc' is not a number",
        ),
        ("x y z radius\n0 0 0 1e-3\n\n1 1 1\n", r"line 4: expected 4 values .* found 3"),
        ("x,y,z,radius\n0,0,0,1e-3\n0,0,0,-1e-3\n", r"line 3, column 'radius'.*must be > 0"),
        ("x y z radius\n0 nan 0 1e-3\n", r"line 2, column 'y'.*not finite"),
        ("x y radius\n0 0 1e-3\n", r"line 1: the header lacks required column\(s\) z"),
        ("x y z radius colour\n0 0 0 1 2\n", r"line 1: unknown column 'colour'.*allowed"),
        ("0 0 0 1e-3\n", r"line 1: no header.*starts with the number '0'"),
        ("x y z radius vx vy\n0 0 0 1e-3 0 0\n", r"line 1: give all of vx, vy, vz"),
        ("x y z radius temperature\n0 0 0 1e-3 300\n0 0 0 1e-3 0\n", r"line 3.*temperature"),
        ("\n\n", r"is empty"),
    ],
)
def test_bad_files_name_file_line_and_column(tmp_path, content, pattern):
    path = tmp_path / "bad.txt"
    path.write_text(content)
    with pytest.raises(ValueError, match=pattern) as err:
        load_particle_file(path)
    assert "bad.txt" in str(err.value)


def test_missing_file_and_walls_ok_rejection(tmp_path):
    with pytest.raises(ValueError, match="nothere.txt"):
        load_particle_file(tmp_path / "nothere.txt")
    path = tmp_path / "p.txt"
    path.write_text("x y z radius\n0 0 0 0.1\n0 0 -1 0.1\n")
    entry = FileInsertion(material="a", path=path)
    with pytest.raises(ValueError, match="1 particle.*line 3"):
        insert(entry, None, None, None, walls_ok=lambda x, r: x[:, 2] - r >= -0.5)


BED_HEADER = "# x y z r ; box 0.09 0.09 0.054959948092\n"


@pytest.mark.parametrize(
    ("text", "radius", "temperature"),
    [
        # LIGGGHTS/Yade-style: a comment after the names on the header line
        (BED_HEADER + "1e-3 2e-3 3e-3 0.001\n4e-3 5e-3 6e-3 0.002\n", [0.001, 0.002], None),
        ("# written by another code\n# X Y Z R\n1e-3 2e-3 3e-3 0.001\n4e-3 5e-3 6e-3 0.002\n",
         [0.001, 0.002], None),
        ("x[m] y[m] z[m] rad (m)\n1e-3 2e-3 3e-3 0.001 # first\n4e-3 5e-3 6e-3 0.002\n",
         [0.001, 0.002], None),
        ("x,y,z,diameter,T\n1e-3,2e-3,3e-3,0.002,300\n4e-3,5e-3,6e-3,0.004,310\n",
         [0.001, 0.002], [300.0, 310.0]),
        ("x y z d temp\n1e-3 2e-3 3e-3 0.002 300\n4e-3 5e-3 6e-3 0.004 310\n",
         [0.001, 0.002], [300.0, 310.0]),
    ],
    ids=["bed-header-comment", "comment-before-header", "units-and-inline-comment",
         "diameter-csv", "d-temp"],
)  # fmt: skip
def test_file_aliases_and_header_comments(tmp_path, text, radius, temperature):
    """Headers other codes write: r/rad, diameter/d (radius = d/2), T/temp, units in brackets,
    text after ';' or '#', comment lines before the header; fast and checked parsers agree."""
    from thermodem.io.particle_file import _parse_checked, _parse_fast

    path = tmp_path / "bed.txt"
    path.write_text(text)
    fast, checked = _parse_fast(path, "g"), _parse_checked(path, "g")
    assert fast is not None
    for parsed in (fast, checked):
        np.testing.assert_array_equal(
            parsed.particles.position, [[1e-3, 2e-3, 3e-3], [4e-3, 5e-3, 6e-3]]
        )
        np.testing.assert_array_equal(parsed.particles.radius, radius)
        if temperature is None:
            assert parsed.particles.temperature is None
        else:
            np.testing.assert_array_equal(parsed.particles.temperature, temperature)
    np.testing.assert_array_equal(fast.line_numbers, checked.line_numbers)


def test_the_shared_bed_file_loads():
    """The first lines of ../shared/beds/bed50k.txt (a LIGGGHTS bed), as users load it."""
    from pathlib import Path

    bed = Path("/work/shared/beds/bed50k.txt")
    if not bed.exists():
        pytest.skip("the shared bed is not on this machine")
    p = load_particle_file(bed)
    assert len(p) == 50000 and np.all(p.radius == 0.001)
    assert np.all(p.position >= 0.0) and np.all(p.position[:, :2] <= 0.09)


@pytest.mark.parametrize(
    ("content", "pattern"),
    [
        ("x y z r radius\n0 0 0 1 1\n", r"line 1: column\(s\) \['radius'\] appear twice"),
        ("x y z r d\n0 0 0 1 1\n", r"line 1: give the radius or the diameter, not both"),
        ("# x y z r\n", r"has a header \(line 1\) but no particle rows"),
        ("# generated\n1 2 3 4\n", r"line 1: unknown column 'generated'"),
        ("x y z r\n0 0 0 \xe9\n", r"line 2, column 'r': '\xe9' is not a number"),
    ],
)
def test_more_bad_files(tmp_path, content, pattern):
    path = tmp_path / "bad.txt"
    path.write_text(content, encoding="utf-8")
    with pytest.raises(ValueError, match=pattern):
        load_particle_file(path)


def test_not_utf8_and_directory(tmp_path):
    path = tmp_path / "latin1.txt"
    path.write_bytes("x y z r\n0 0 0 1\n# caf\u00e9\n".encode("latin-1"))
    with pytest.raises(ValueError, match=r"latin1.txt', line 3: not UTF-8 text \(byte 0xe9"):
        load_particle_file(path)
    with pytest.raises(ValueError, match="is a directory"):
        load_particle_file(tmp_path)


DOMAIN = (np.zeros(3), np.full(3, 0.01))


def list_entry(**kw) -> ListInsertion:
    base = dict(material="glass", positions=[(0.005, 0.005, 0.002)], radius=0.001)
    base.update(kw)
    return ListInsertion(**base)


def test_list_of_one_two_and_ten_particles():
    one = insert(list_entry(velocity=(0, 0, -1), temperature=350), None, None, None)
    np.testing.assert_array_equal(one.position, [[0.005, 0.005, 0.002]])
    np.testing.assert_array_equal(one.velocity, [[0, 0, -1]])
    np.testing.assert_array_equal(one.temperature, [350.0])
    two = insert(
        list_entry(
            positions=[(0.004, 0.005, 0.005), (0.006, 0.005, 0.005)],
            radius=None,
            radii=[0.001, 0.0009],
            velocities=[(1, 0, 0), (-1, 0, 0)],
            temperatures=[300, 400],
        ),
        None, None, None, domain=DOMAIN,
    )  # fmt: skip
    np.testing.assert_array_equal(two.radius, [0.001, 0.0009])
    np.testing.assert_array_equal(two.velocity, [[1, 0, 0], [-1, 0, 0]])
    np.testing.assert_array_equal(two.temperature, [300.0, 400.0])
    line = [(0.0005 + 0.001 * k, 0.005, 0.005) for k in range(10)]  # touching neighbours
    ten = insert(list_entry(positions=line, radius=0.0005), None, None, None, domain=DOMAIN)
    assert len(ten) == 10 and ten.temperature is None
    np.testing.assert_array_equal(ten.velocity, np.zeros((10, 3)))


@pytest.mark.parametrize(
    ("kw", "pattern"),
    [
        (dict(radius=None), r"radius: give exactly one of 'radius'"),
        (dict(radii=[0.001]), r"radius: give exactly one"),
        (dict(radius=None, radii=[0.001, 0.001]), r"radii: 2 value\(s\) for 1 position"),
        (dict(velocities=[(0, 0, 0)] * 2), r"velocities: 2 value\(s\) for 1 position"),
        (dict(velocities=[(0, 0, 0)], velocity=(1, 0, 0)), r"velocities: give 'velocity'"),
        (dict(temperatures=[300], temperature=300), r"temperatures: give 'temperature'"),
        (dict(temperatures=[0]), r"greater than 0"),
        (dict(positions=[(0, 0, float("inf"))]), r"finite"),
        (dict(positions=[]), r"at least 1"),
    ],
)
def test_list_validation(kw, pattern):
    with pytest.raises(ValidationError, match=pattern):
        list_entry(**kw)


def test_given_particles_inside_the_domain_and_not_coincident(tmp_path):
    outside = list_entry(positions=[(0.005, 0.005, 0.002), (0.005, 0.005, 0.0101)])
    with pytest.raises(
        ConfigError,
        match=r"^insertion.3.positions.1: particle centre .* "
        r"outside the domain",
    ):
        insert(outside, None, None, None, key="insertion.3", domain=DOMAIN)
    dup = list_entry(positions=[(0.002, 0.002, 0.002), (0.006, 0.006, 0.006)] * 2)
    with pytest.raises(
        ConfigError, match=r"positions.2: .* same position as insertion.positions.0"
    ):
        insert(dup, None, None, None)
    # an overlap of 0.3 r is refused at the default limit 0.2 and accepted at 0.35
    deep = list_entry(positions=[(0.004, 0.005, 0.005), (0.0057, 0.005, 0.005)])
    with pytest.raises(ConfigError, match=r"positions.1: .* overlaps .*by 0.3 of the smaller"):
        insert(deep, None, None, None)
    assert len(insert(deep, None, None, None, max_overlap_ratio=0.35)) == 2
    # overlap_check: false takes deep overlaps, even a small sphere inside a large one ...
    inside = list_entry(
        positions=[(0.004, 0.005, 0.005), (0.0042, 0.005, 0.005)],
        radius=None,
        radii=[0.002, 0.0005],
        overlap_check=False,
    )
    assert len(insert(inside, None, None, None)) == 2
    # ... but never coincident centres
    same = list_entry(positions=[(0.004, 0.005, 0.005)] * 2, overlap_check=False)
    with pytest.raises(ConfigError, match=r"same position .*even with overlap_check: false"):
        insert(same, None, None, None)
    with pytest.raises(ConfigError, match=r"same position"):
        insert(list_entry(positions=[(0.004, 0.005, 0.005)], overlap_check=False), None,
               np.array([[0.004, 0.005, 0.005]]), np.array([0.003]))  # fmt: skip
    # against the particles of an earlier entry
    with pytest.raises(ConfigError, match=r"earlier insertion entry at \[0.004, 0.005, 0.005\]"):
        insert(list_entry(positions=[(0.0041, 0.005, 0.005)]), None,
               np.array([[0.004, 0.005, 0.005]]), np.array([0.001]))  # fmt: skip
    # a duplicate row of a file names both lines
    path = tmp_path / "bed.txt"
    path.write_text("# x y z r\n0.002 0.002 0.002 0.001\n0.005 0.005 0.002 0.001\n"
                    "0.002 0.002 0.002 0.001\n")  # fmt: skip
    with pytest.raises(
        ConfigError,
        match=r"insertion.0.path: .*bed.txt', line 4: .* same "
        r"position as the particle of .*bed.txt', line 2",
    ):
        insert(FileInsertion(material="g", path=path), None, None, None, key="insertion.0")


def test_overlap_search_equals_brute_force():
    """The k-d tree search finds the first too-deep pair that an O(n²) loop finds."""
    from thermodem.geometry.given_particles import _deepest_overlap

    rng = np.random.default_rng(3)
    for _ in range(20):
        n = 60
        pos = rng.uniform(0, 0.02, (n, 3))
        rad = rng.uniform(0.0005, 0.0015, n)
        limit = 0.3
        brute = None
        for i in range(n):
            for j in range(i):
                d = np.linalg.norm(pos[i] - pos[j])
                if (rad[i] + rad[j] - d) / min(rad[i], rad[j]) > limit:
                    brute = (i, j)
                    break
            if brute:
                break
        found = _deepest_overlap(pos, rad, limit, None, None)
        assert (found[:2] if found else None) == brute


# --------------------------------------------------------------------------------------------
# pouring
# --------------------------------------------------------------------------------------------


def pour_entry(**kw) -> PourInsertion:
    base = dict(
        material="glass",
        distribution={"kind": "mono", "radius": 0.002},
        region={"kind": "box", "lower": (0, 0, 0), "upper": (0.1, 0.1, 0.1)},
        rate=1000.0,
        start_time=0.1,
        end_time=0.5,
        interval=0.01,
        velocity=(0.0, 0.0, -1.0),
    )
    base.update(kw)
    return PourInsertion(**base)


def run_pour(pourer, t_from, t_to, dt, pos, rad, log):
    for step in range(round(t_from / dt), round(t_to / dt)):
        t = step * dt
        if pourer.due(t, dt):
            new = pourer.emit(t, pos, rad)
            log.append((t, len(new)))
            if len(new):
                np.testing.assert_array_equal(new.velocity[:, 2], -1.0)
                pos = np.vstack([pos, new.position])
                rad = np.concatenate([rad, new.radius])
    return pos, rad


def test_pour_rate_gives_the_right_count_over_time():
    entry = pour_entry()
    pourer = Pourer(entry, np.random.default_rng(40))
    log: list[tuple[float, int]] = []
    pos, rad = run_pour(pourer, 0.0, 0.6, 1e-3, np.zeros((0, 3)), np.zeros(0), log)
    times = np.array([t for t, n in log if n > 0])
    counts = np.array([n for t, n in log])
    assert counts.sum() == 400 == len(rad)  # 1000/s over 0.4 s
    assert times.min() > 0.1 - 1e-9 and times.max() <= 0.5 + 1e-9
    # batches every interval of rate * interval = 10 particles
    assert np.all(counts[counts > 0] == 10)
    # cumulative count follows rate * (t - start) at every batch
    cumulative = np.cumsum([n for t, n in log if n > 0])
    np.testing.assert_allclose(cumulative, np.floor(1000 * (times - 0.1) + 1e-6), atol=1)
    assert count_overlaps(pos, rad) == 0
    assert inside_box(pos, rad, (0, 0, 0), (0.1, 0.1, 0.1))
    assert pourer.finished and not pourer.due(0.7, 1e-3)
    assert pourer.state_dict()["inserted"] == 400


def test_pour_fractional_rate_and_cylinder_region():
    entry = pour_entry(
        rate=333.0,
        start_time=0.0,
        end_time=0.3,
        interval=0.007,
        region={
            "kind": "cylinder",
            "base_centre": (0, 0, 0),
            "axis": (0, 1, 0),
            "radius": 0.05,
            "length": 0.08,
        },
    )
    pourer = Pourer(entry, np.random.default_rng(41))
    log: list[tuple[float, int]] = []
    pos, rad = run_pour(pourer, 0.0, 0.4, 2e-4, np.zeros((0, 3)), np.zeros(0), log)
    assert len(rad) == math.floor(333.0 * 0.3)
    assert count_overlaps(pos, rad) == 0
    assert inside_cylinder(pos, rad, (0, 0, 0), (0, 1, 0), 0.05, 0.08)


def test_pour_restart_from_state_dict():
    entry = pour_entry()
    log: list[tuple[float, int]] = []
    first = Pourer(entry, np.random.default_rng(42))
    pos, rad = run_pour(first, 0.0, 0.25, 1e-3, np.zeros((0, 3)), np.zeros(0), log)
    state = first.state_dict()
    assert state["inserted"] == len(rad)

    resumed = Pourer(entry, np.random.default_rng(43))
    resumed.load_state_dict(dict(state))
    assert resumed.state_dict() == state
    pos, rad = run_pour(resumed, 0.25, 0.6, 1e-3, pos, rad, log)
    assert len(rad) == 400
    assert count_overlaps(pos, rad) == 0
    with pytest.raises(ValueError, match="keys"):
        resumed.load_state_dict({"inserted": 1})


def test_pour_into_a_full_region_warns_and_skips():
    entry = pour_entry(
        region={"kind": "box", "lower": (0, 0, 0), "upper": (0.012, 0.012, 0.012)},
        rate=10000.0,
        max_attempts=20,
    )
    pourer = Pourer(entry, np.random.default_rng(44))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        new = pourer.emit(0.11, None, None)
    assert any("placed" in str(w.message) for w in caught)
    assert 0 < len(new) < 100
    assert count_overlaps(new.position, new.radius) == 0
    state = pourer.state_dict()
    assert state["inserted"] == len(new) and state["skipped"] == 100 - len(new)


def test_pour_does_nothing_before_start():
    pourer = Pourer(pour_entry(), np.random.default_rng(45))
    assert not pourer.due(0.05, 1e-3)
    assert len(pourer.emit(0.05, None, None)) == 0
    with pytest.raises(TypeError, match="Pourer"):
        insert(pour_entry(), np.random.default_rng(0), None, None)


def test_box_region_validation():
    with pytest.raises(ValidationError, match="on the x axis lower=2.0 and upper=1.0"):
        BoxRegion(lower=(2, 0, 0), upper=(1, 1, 1))


def test_a_pour_batch_tries_at_most_what_half_the_region_holds():
    """rate × interval = 1e6 particles for a box that holds 119 at half its volume: the batch
    tries 119 (the work is bounded), the rest are skipped and counted."""
    import time

    entry = pour_entry(
        region={"kind": "box", "lower": (0, 0, 0), "upper": (0.01, 0.01, 0.01)},
        distribution={"kind": "mono", "radius": 0.001},
        rate=1e9,
        start_time=0.0,
        end_time=None,
        interval=0.001,
    )
    pourer = Pourer(entry, np.random.default_rng(46))
    assert pourer.batch_cap == int(0.5 * 1e-6 / (4.0 / 3.0 * math.pi * 1e-9))
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        new = pourer.emit(0.001, None, None)
    assert time.perf_counter() - start < 10.0
    assert 0 < len(new) <= pourer.batch_cap
    assert pourer.inserted + pourer.skipped == 1_000_000
    assert count_overlaps(new.position, new.radius) == 0


def test_given_particles_are_checked_across_periodic_boundaries():
    """A list or file entry is checked by the nearest images on the periodic axes, as the run
    sees the pairs: two particles overlapping across the boundary were accepted and the run
    stopped at its first step. Touching across the boundary is fine, and without periodicity
    the same positions are far apart."""
    rng = np.random.default_rng(0)
    domain = (np.zeros(3), np.full(3, 0.01))

    def entry(*xs: float, **kw) -> ListInsertion:
        return ListInsertion(
            kind="list", material="m", radius=0.001, positions=[[x, 0.005, 0.005] for x in xs], **kw
        )

    def given(e: ListInsertion, periodic, existing=(None, None)) -> InsertedParticles:
        return insert(e, rng, *existing, domain=domain, periodic=periodic, key="insertion.0")

    across = (True, False, False)
    with pytest.raises(ConfigError, match=r"positions.1: .* overlaps insertion.0.positions.0 by "
                       r"1.7 .* across the periodic boundary of x"):  # fmt: skip
        given(entry(0.0002, 0.0099), across)
    assert len(given(entry(0.0002, 0.0099), (False, True, True))) == 2
    assert len(given(entry(0.0002, 0.0099), None)) == 2
    assert len(given(entry(0.001, 0.009), across)) == 2  # touching across x
    with pytest.raises(ConfigError, match="same position"):  # x = 0 and x = L are one point
        given(entry(0.0, 0.01, overlap_check=False), across)
    earlier = (np.array([[0.0095, 0.005, 0.005]]), np.array([0.001]))
    with pytest.raises(ConfigError, match="an earlier insertion entry .* periodic boundary of x"):
        given(entry(0.0003), across, earlier)
    assert len(given(entry(0.0003), None, earlier)) == 1
