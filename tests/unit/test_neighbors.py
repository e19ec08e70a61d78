"""Neighbour search: cell-list pairs against O(N²) brute force, and skin runs against rebuilding
every step.

The brute-force references are written here with NumPy broadcasting from the case definition
(positions, radii, wall parameters), not from the engine's wall rows or kernels: a pair is
listed iff its centre distance (minimum image on periodic axes) is < R_i + R_j + extra + skin;
a particle-wall pair iff the distance from the centre to the wall is < R + extra + skin (signed
along the normal for a one-sided plane; to the closest point of a rectangle, both faces and
edges; R_cyl - ρ inside a finite cylinder, none beyond its ends).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from thermodem.config.load import case_from_dict
from thermodem.engine.simulation import Simulation
from thermodem.geometry.insertion import InsertedParticles, save_particle_file

R0 = 0.01
EXTRA = 0.1 * R0
SKIN = 0.25 * R0


pytestmark = pytest.mark.usefixtures("one_thread")


def material() -> dict:
    return {
        "density": 2500.0,
        "youngs_modulus": 1e7,
        "poisson_ratio": 0.3,
        "restitution": 0.5,
        "sliding_friction": 0.5,
        "rolling_friction": 0.1,
    }


def build(
    tmp: Path,
    position,
    radius,
    velocity=None,
    *,
    lower,
    upper,
    periodic=(False,) * 3,
    walls=(),
    neighbors=None,
    dt=1e-5,
    contact=None,
    gravity=(0.0, 0.0, 0.0),
    tag="p",
) -> Simulation:
    position = np.asarray(position, float)
    if velocity is None:
        velocity = np.zeros_like(position)
    path = tmp / f"{tag}.txt"
    save_particle_file(
        path,
        InsertedParticles(
            position, np.asarray(radius, float), np.asarray(velocity, float), None, "grain"
        ),
    )
    case = {
        "simulation": {
            "time_step": dt,
            "end_time": 1.0,
            "gravity": list(gravity),
            "max_overlap_ratio": 1.0,
        },
        "domain": {"lower": list(lower), "upper": list(upper), "periodic": list(periodic)},
        "materials": {"grain": material()},
        "contact": contact or {"normal": "hertz", "tangential": "mindlin", "rolling": "none"},
        "neighbors": neighbors or {"skin": SKIN, "extra_distance": EXTRA},
        "walls": list(walls),
        # random positions overlap freely: only coincident ones would be refused
        "insertion": [
            {"kind": "file", "material": "grain", "path": str(path), "overlap_check": False}
        ],
    }
    return Simulation(case_from_dict(case))


def listed_pairs(sim: Simulation) -> list[tuple[int, int]]:
    pb = sim.pairs
    gid = sim.particles.global_id
    a = gid[pb.i[: pb.count]]
    b = gid[pb.j[: pb.count]]
    return list(zip(a.tolist(), b.tolist(), strict=True))


def listed_wall_pairs(sim: Simulation) -> list[tuple[int, str]]:
    wb = sim.walls
    gid = sim.particles.global_id
    return [
        (int(gid[i]), sim.wall_labels[int(w)])
        for i, w in zip(wb.i[: wb.count], wb.j[: wb.count], strict=True)
    ]


def brute_pairs(pos, rad, lower, upper, periodic, cut_extra) -> set[tuple[int, int]]:
    """Pairs (a < b) of particles with centre distance < R_a + R_b + cut_extra."""
    d = pos[None, :, :] - pos[:, None, :]
    length = np.asarray(upper) - np.asarray(lower)
    for a in range(3):
        if periodic[a]:
            d[..., a] -= length[a] * np.round(d[..., a] / length[a])
    dist = np.sqrt((d**2).sum(axis=2))
    cut = rad[:, None] + rad[None, :] + cut_extra
    ia, ib = np.nonzero(np.triu(dist < cut, k=1))
    return set(zip(ia.tolist(), ib.tolist(), strict=True))


def random_packing(rng, n, lower, upper, r_min, r_max):
    lower = np.asarray(lower)
    upper = np.asarray(upper)
    pos = lower + rng.random((n, 3)) * (upper - lower)
    rad = rng.uniform(r_min, r_max, n)
    return pos, rad


def check_pairs(sim, pos, rad, lower, upper, periodic):
    listed = listed_pairs(sim)
    assert len(listed) == len(set(listed)), "a pair is listed twice"
    assert all(a < b for a, b in listed), "pairs are oriented gid_i < gid_j"
    expected = brute_pairs(pos, rad, lower, upper, periodic, EXTRA + SKIN)
    assert set(listed) == expected, (len(set(listed) - expected), len(expected - set(listed)))
    return expected


# ----------------------------------------------------------------- particle pairs vs O(N²)
@pytest.mark.parametrize(
    "periodic",
    [(False, False, False), (True, False, False), (True, True, True)],
    ids=["none", "x", "xyz"],
)
def test_pairs_equal_brute_force(tmp_path, periodic):
    rng = np.random.default_rng(42)
    lower, upper = (0.0, 0.0, 0.0), (0.12, 0.1, 0.09)
    # polydisperse, overlapping freely (no step is taken), many particles near the faces
    pos, rad = random_packing(rng, 500, lower, upper, 0.4 * R0, 1.2 * R0)
    sim = build(tmp_path, pos, rad, lower=lower, upper=upper, periodic=periodic)
    # gid k is row k of the particle file
    assert np.array_equal(np.sort(sim.particles.global_id), np.arange(len(rad)))
    expected = check_pairs(sim, pos, rad, lower, upper, periodic)
    assert len(expected) > 1024  # beyond the initial buffer capacity: growth is exercised
    if any(periodic):
        # the minimum image matters: some listed pairs are only close across the boundary
        direct = brute_pairs(pos, rad, lower, upper, (False,) * 3, EXTRA + SKIN)
        assert len(expected - direct) > 20


def test_pairs_equal_brute_force_after_moving(tmp_path):
    """Positions wrapped across periodic faces by the integrator and a rebuild in between."""
    rng = np.random.default_rng(5)
    lower, upper = (0.0, 0.0, 0.0), (0.1, 0.1, 0.1)
    periodic = (True, True, False)
    # a jittered 5 x 5 x 3 lattice (no overlaps) with random velocities, no gravity
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(3), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * 0.02 + [0.0, 0.0, 0.02]
    pos += rng.uniform(-0.1, 0.1, pos.shape) * R0
    rad = rng.uniform(0.5 * R0, 0.75 * R0, len(pos))
    vel = rng.normal(0.0, 1.0, pos.shape)
    vel[:, 2] *= 0.3
    sim = build(
        tmp_path,
        pos,
        rad,
        vel,
        lower=lower,
        upper=upper,
        periodic=periodic,
        contact={"normal": "hertz", "tangential": "none", "rolling": "none"},
        dt=2e-5,
    )
    sim.run(steps=500)  # ~1 cm: many particles cross a periodic face
    assert sim.rebuild_count > 2
    sim.rebuild()
    order = np.argsort(sim.particles.global_id)
    now = sim.particles.position[order]
    assert np.all(now[:, :2] >= 0.0) and np.all(now[:, :2] < 0.1)
    check_pairs(sim, now, rad, lower, upper, periodic)


# --------------------------------------------------------------------- wall pairs vs NumPy
def plane_distance(x, point, normal):
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    return (x - np.asarray(point)) @ n


def rectangle_distance(x, center, normal, u_axis, half_u, half_v):
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    u = np.asarray(u_axis, float) / np.linalg.norm(u_axis)
    v = np.cross(n, u)
    r = x - np.asarray(center)
    a = np.clip(r @ u, -half_u, half_u)
    b = np.clip(r @ v, -half_v, half_v)
    q = np.asarray(center) + a[:, None] * u + b[:, None] * v
    return np.linalg.norm(x - q, axis=1)


def cylinder_distance(x, center, axis, radius, length, inside):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    r = x - np.asarray(center)
    h = r @ a
    rho = np.linalg.norm(r - h[:, None] * a, axis=1)
    d = radius - rho if inside else rho - radius
    if length is not None:
        d = np.where(np.abs(h) > 0.5 * length, np.inf, d)
    return d


def box_face_distances(x, lower, upper, name):
    """Six faces of an axis-aligned box as labelled distances (closest point on each face)."""
    lower = np.asarray(lower, float)
    upper = np.asarray(upper, float)
    out = {}
    for axis in range(3):
        for side, level in (("-", lower[axis]), ("+", upper[axis])):
            q = np.clip(x, lower, upper)
            q[:, axis] = level
            out[f"{name}.{'xyz'[axis]}{side}"] = np.linalg.norm(x - q, axis=1)
    return out


WALLS = [
    {
        "kind": "plane",
        "name": "slope",
        "material": "grain",
        "point": [0.0, 0.0, 0.02],
        "normal": [0.3, -0.2, 1.0],
    },
    {
        "kind": "rectangle",
        "name": "plate",
        "material": "grain",
        "center": [0.06, 0.05, 0.05],
        "normal": [1.0, 1.0, 0.0],
        "u_axis": [-1.0, 1.0, 0.5],
        "half_extents": [0.03, 0.02],
    },
    {
        "kind": "cylinder",
        "name": "drum",
        "material": "grain",
        "center": [0.06, 0.05, 0.05],
        "axis": [0.0, 0.2, 1.0],
        "radius": 0.045,
        "length": 0.07,
    },
    {
        "kind": "cylinder",
        "name": "rod",
        "material": "grain",
        "center": [0.02, 0.05, 0.05],
        "axis": [0.0, 1.0, 0.0],
        "radius": 0.008,
        "inside": False,
    },
    {
        "kind": "box",
        "name": "box",
        "material": "grain",
        "lower": [0.005, 0.005, 0.005],
        "upper": [0.115, 0.095, 0.095],
    },
]


def test_wall_pairs_equal_brute_force(tmp_path):
    rng = np.random.default_rng(11)
    lower, upper = (0.0, 0.0, 0.0), (0.12, 0.1, 0.1)
    pos, rad = random_packing(rng, 400, lower, upper, 0.4 * R0, 1.2 * R0)
    sim = build(tmp_path, pos, rad, lower=lower, upper=upper, walls=WALLS)
    dist = {
        "slope": plane_distance(pos, **{k: WALLS[0][k] for k in ("point", "normal")}),
        "plate": rectangle_distance(
            pos,
            WALLS[1]["center"],
            WALLS[1]["normal"],
            WALLS[1]["u_axis"],
            *WALLS[1]["half_extents"],
        ),
        "drum": cylinder_distance(pos, WALLS[2]["center"], WALLS[2]["axis"], 0.045, 0.07, True),
        "rod": cylinder_distance(pos, WALLS[3]["center"], WALLS[3]["axis"], 0.008, None, False),
    }
    dist.update(box_face_distances(pos, WALLS[4]["lower"], WALLS[4]["upper"], "box"))
    assert sorted(dist) == sorted(sim.wall_labels)
    expected = set()
    for label, d in dist.items():
        hits = np.flatnonzero(d < rad + EXTRA + SKIN)
        expected |= {(int(g), label) for g in hits}
    listed = listed_wall_pairs(sim)
    assert len(listed) == len(set(listed))
    assert set(listed) == expected, (
        sorted(set(listed) - expected)[:5],
        sorted(expected - set(listed))[:5],
    )
    # every wall kind is represented, including behind the one-sided plane (negative distance)
    for label in dist:
        assert any(lab == label for _, lab in expected), label
    assert np.any(dist["slope"] < -0.01)
    assert len(expected) > 64  # beyond the initial buffer capacity
    check_pairs(sim, pos, rad, lower, upper, (False,) * 3)


# ------------------------------------------------------- Verlet skin vs rebuild every step
def settling_bed(tmp: Path, every_step: bool, tag: str) -> Simulation:
    """~100 polydisperse spheres on a jittered lattice with random velocities, falling into an
    open box: dense, frictional (Hertz-Mindlin, EPSD rolling), history carried across rebuilds."""
    rng = np.random.default_rng(2024)
    spacing = 1.99 * R0
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(4), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * spacing
    pos += rng.uniform(-0.01, 0.01, pos.shape) * R0
    rad = rng.uniform(0.95 * R0, R0, len(pos))  # small initial overlaps: a jammed start
    vel = rng.normal(0.0, 0.2, pos.shape)
    box = {
        "kind": "box",
        "material": "grain",
        "lower": [0.0, 0.0, 0.0],
        "upper": [5 * spacing, 5 * spacing, 0.2],
        "open_top": True,
    }
    neighbors = {"skin": 0.05 * R0, "rebuild_every_step": every_step}
    return build(
        tmp,
        pos,
        rad,
        vel,
        lower=(-0.01, -0.01, -0.01),
        upper=(0.12, 0.12, 0.21),
        walls=[box],
        neighbors=neighbors,
        dt=2e-5,
        gravity=(0.0, 0.0, -9.81),
        contact={"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
        tag=tag,
    )


def by_gid(sim: Simulation, name: str) -> np.ndarray:
    p = sim.particles
    return getattr(p, name)[np.argsort(p.global_id)]


def test_skin_run_equals_rebuild_every_step(tmp_path):
    steps = 400
    skin = settling_bed(tmp_path, False, "skin")
    every = settling_bed(tmp_path, True, "every")
    touching_history = []

    def watch(s: Simulation) -> None:
        pb = s.pairs
        touching = pb.state[: pb.count] == 2
        touching_history.append(np.abs(pb.history[: pb.count][touching, 0:3]).sum())

    skin.run(steps=steps, callback=watch)
    every.run(steps=steps)
    assert every.rebuild_count == steps + 1
    # the skin run rebuilt several times while contacts carried tangential history
    assert 3 <= skin.rebuild_count < steps // 4, skin.rebuild_count
    assert skin.contact_count > 50 and min(touching_history[100:]) > 0.0
    for name in ("position", "velocity", "angular_velocity"):
        a = by_gid(skin, name)
        b = by_gid(every, name)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0, err_msg=name)
    # both runs sort the particles alike (few cell changes), so each particle receives its
    # contacts in the same order and the runs even agree to the bit; in general the order
    # follows the list (kernels/slabs.py), hence the 1e-12 above
    assert np.array_equal(by_gid(skin, "position"), by_gid(every, "position"))


def test_periodic_skin_run_equals_rebuild_every_step(tmp_path, monkeypatch):
    """The same comparison on a bed that is periodic in x and y, where pairs touch across the
    boundaries of the slab axis: the list is then sorted into slab groups and the carried
    history is remapped through that sort at every rebuild."""
    from thermodem.kernels import slabs as SL

    sorts = []
    original_sort = SL.sort_pairs_by_group

    def counting_sort(*args):
        sorts.append(1)
        return original_sort(*args)

    monkeypatch.setattr(SL, "sort_pairs_by_group", counting_sort)
    rng = np.random.default_rng(7)
    spacing = 1.99 * R0
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(4), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * spacing + rng.uniform(-0.01, 0.01, (100, 3)) * R0
    rad = rng.uniform(0.95 * R0, R0, len(pos))
    vel = rng.normal(0.0, 0.2, pos.shape)
    floor = {"kind": "plane", "material": "grain", "point": [0, 0, 0], "normal": [0, 0, 1]}
    runs = []
    for every_step in (False, True):
        sim = build(
            tmp_path, pos, rad, vel, lower=(0.0, 0.0, -0.01),
            upper=(5 * spacing, 5 * spacing, 0.21), periodic=(True, True, False),
            walls=[floor], neighbors={"skin": 0.05 * R0, "rebuild_every_step": every_step},
            dt=2e-5, gravity=(0.0, 0.0, -9.81),
            contact={"normal": "hertz", "tangential": "mindlin", "rolling": "epsd"},
            tag=f"periodic{every_step}",
        )  # fmt: skip
        sim.run(steps=300)
        runs.append(sim)
    skin, every = runs
    assert 3 <= skin.rebuild_count < 100 and every.rebuild_count == 301
    assert len(sorts) > skin.rebuild_count  # pairs across the slab axis' boundary: sorted
    assert skin.contact_count > 50
    for name in ("position", "velocity", "angular_velocity"):
        np.testing.assert_allclose(
            by_gid(skin, name), by_gid(every, name), rtol=1e-12, atol=1e-15, err_msg=name
        )


def test_dropping_history_at_rebuild_changes_the_run(tmp_path):
    """The comparison above can fail: losing the history at each rebuild changes the result."""
    steps = 400
    reference = settling_bed(tmp_path, False, "reference")
    reference.run(steps=steps)
    forgetful = settling_bed(tmp_path, False, "forgetful")
    rebuild = forgetful.rebuild

    def rebuild_and_forget() -> None:
        rebuild()
        forgetful.pairs.history[:] = 0.0
        forgetful.walls.history[:] = 0.0

    forgetful.rebuild = rebuild_and_forget
    forgetful.run(steps=steps)
    assert forgetful.rebuild_count > 2
    diff = np.abs(by_gid(forgetful, "position") - by_gid(reference, "position")).max()
    assert diff > 1e-9, diff


# ------------------------------------------------------------------ slab groups and history
def test_move_rows_equals_out_of_place_copy():
    """The in-place history move against a plain copy into a second table."""
    from thermodem.kernels.neighbors import move_rows

    rng = np.random.default_rng(5)
    for trial in range(200):
        old_count = int(rng.integers(0, 40))
        new_count = int(rng.integers(0, 40))
        cap = max(old_count, new_count, 1)
        history = np.zeros((cap, 4))
        history[:old_count] = rng.normal(size=(old_count, 4))
        dest = np.full(old_count, -1, np.int32)
        carried = rng.random(old_count) < 0.7
        targets = rng.permutation(new_count)[: int(carried.sum())]
        dest[np.nonzero(carried)[0][: len(targets)]] = targets
        expected = np.zeros((new_count, 4))
        for k in range(old_count):
            if dest[k] >= 0:
                expected[dest[k]] = history[k]
        move_rows(history, dest, old_count, new_count, np.empty(old_count, np.int8),
                  np.empty(4), np.empty(4))  # fmt: skip
        assert np.array_equal(history[:new_count], expected), trial


@pytest.mark.parametrize(
    ("length", "periodic"),
    [(0.14, (False,) * 3), (0.12, (True,) * 3), (0.14, (True,) * 3)],
    ids=["open", "periodic-even", "periodic-odd"],
)
def test_slab_groups_and_contact_forces(tmp_path, length, periodic):
    """Groups of one parity write to disjoint particles, and the forces added straight into
    the particles equal an O(N²) Hertz sum written here (static contacts at t = 0: no
    damping, no tangential spring yet)."""
    rng = np.random.default_rng(11)
    lower, upper = (0.0, 0.0, 0.0), (length, 0.1, 0.09)
    pos, rad = random_packing(rng, 500, lower, upper, 0.4 * R0, 1.2 * R0)
    sim = build(tmp_path, pos, rad, lower=lower, upper=upper, periodic=periodic)
    pb = sim.pairs
    gs = pb.group_start
    assert pb.ngroups >= 4 and gs[0] == 0 and gs[-1] == pb.count
    for parity in (0, 1):
        owner: dict[int, int] = {}
        for g in range(parity, pb.ngroups, 2):
            for k in range(gs[g], gs[g + 1]):
                for q in (int(pb.i[k]), int(pb.j[k])):
                    assert owner.setdefault(q, g) == g, (q, owner[q], g)
    # forces of the engine, in file (global id) order
    p = sim.particles
    force = p.force[np.argsort(p.global_id)]
    # reference: Hertz F = 4/3 E* sqrt(R*) δ^1.5 along the minimum-image centre line
    m = material()
    e_star = m["youngs_modulus"] / (2.0 * (1.0 - m["poisson_ratio"] ** 2))
    d = pos[None, :, :] - pos[:, None, :]  # d[a, b] = x_b - x_a
    box = np.asarray(upper) - np.asarray(lower)
    for a in range(3):
        if periodic[a]:
            d[..., a] -= box[a] * np.round(d[..., a] / box[a])
    dist = np.sqrt((d**2).sum(axis=2))
    np.fill_diagonal(dist, np.inf)
    overlap = np.maximum(rad[:, None] + rad[None, :] - dist, 0.0)
    r_star = rad[:, None] * rad[None, :] / (rad[:, None] + rad[None, :])
    f_n = 4.0 / 3.0 * e_star * np.sqrt(r_star) * overlap**1.5
    expected = -(f_n[:, :, None] * d / dist[:, :, None]).sum(axis=1)
    assert (overlap > 0).sum() > 400
    scale = np.abs(expected).max()
    np.testing.assert_allclose(force, expected, rtol=0.0, atol=1e-12 * scale)
    # what i gets j loses: the forces sum to zero to round-off
    assert np.abs(force.sum(axis=0)).max() < 1e-12 * scale * len(rad)


def test_pair_buffer_growth_keeps_the_history(monkeypatch):
    """Pouring grows the pair buffers while contacts carry history (the rows are kept and then
    moved); a run that never grows them (a large first capacity) is identical to the bit."""
    from thermodem.config.load import load_case
    from thermodem.state import pairs as P

    example = Path(__file__).resolve().parents[2] / "examples" / "default.yaml"
    original_init, original_allocate = P.PairBuffers.__init__, P.PairBuffers.allocate
    kept: list[int] = []

    def allocate(self, capacity, keep=0):
        kept.append(keep)
        original_allocate(self, capacity, keep)

    def run(first_capacity: int | None) -> np.ndarray:
        def init(self, capacity, history_width):
            original_init(self, first_capacity or capacity, history_width)

        monkeypatch.setattr(P.PairBuffers, "__init__", init)
        sim = Simulation(load_case(example))
        sim.run(steps=20000)
        p = sim.particles
        return p.position[np.argsort(p.global_id)]

    monkeypatch.setattr(P.PairBuffers, "allocate", allocate)
    grown = run(None)
    assert max(kept) > 100, kept  # grown while more than 100 rows of history were in use
    kept.clear()
    fixed = run(100_000)
    assert max(kept) == 0, kept
    assert np.array_equal(grown, fixed)


def test_order_within_groups_is_a_stable_sort_by_group_then_lower_index():
    """The range set's in-group order (kernels/slabs.py), one group at a time, against a
    stable NumPy sort of the whole list by (group, lower particle index)."""
    from thermodem.kernels import slabs

    rng = np.random.default_rng(1)
    for _ in range(50):
        n = int(rng.integers(0, 2000))
        groups = int(rng.integers(1, 30))
        pair_i = rng.integers(0, 300, n + 5).astype(np.int32)  # (5 slots past the count)
        pair_j = rng.integers(0, 300, n + 5).astype(np.int32)
        cuts = np.sort(rng.integers(0, n + 1, groups - 1))
        group_start = np.concatenate([[0], cuts, [n]]).astype(np.int64)
        lower = np.minimum(pair_i[:n], pair_j[:n]).astype(np.int64)
        group = np.repeat(np.arange(groups), np.diff(group_start))
        order = np.lexsort((lower, group))  # stable: ties keep their order
        a, b = pair_i.copy(), pair_j.copy()
        slabs.order_within_groups(a, b, n, group_start)
        assert np.array_equal(a[:n], pair_i[:n][order])
        assert np.array_equal(b[:n], pair_j[:n][order])
        assert np.array_equal(a[n:], pair_i[n:]) and np.array_equal(b[n:], pair_j[n:])
