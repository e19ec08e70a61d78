"""The per-particle pass (kernels/heat_terms.py: particle_pass), by chunks of particles with
the term's (Q, G) in scratch rows and Gunn's loops that vectorise, against each model's own
kernel called particle by particle with the particle's material row, added in the order of
the terms: the same heat rates and conductance sums bit for bit, over several chunks (one
partial), two materials with different rows, one term or two (either order); 1 and 2
threads."""

from __future__ import annotations

import numpy as np
import pytest

from thermodem.engine.threads import apply_threads
from thermodem.kernels import fields as fk
from thermodem.kernels.heat_terms import (
    EVAL_CONVECTION,
    EVAL_RADIATION,
    PARTICLE_CHUNK,
    particle_pass,
)
from thermodem.models import registry
from thermodem.state.materials import Material, resolve_pair

FAMILIES = {"convection": EVAL_CONVECTION, "radiation": EVAL_RADIATION}
N = 2 * PARTICLE_CHUNK + 123
MATERIALS = [
    Material(density=2500.0, youngs_modulus=1e8, poisson_ratio=0.3, emissivity=0.7),
    Material(density=7800.0, youngs_modulus=2e8, poisson_ratio=0.3, emissivity=0.35),
]
#: (family, model, parameters of material 0, of material 1)
TERMS = {
    "gunn": ("convection", "gunn1978", {}, {"reynolds_velocity": "superficial"}),
    "ranz": ("convection", "ranz_marshall1952", {}, {}),
    "krause": ("radiation", "krause2017", {}, {"environment_temperature": 320.0}),
    "surroundings": ("radiation", "surroundings",
                     {"environment_temperature": 300.0},
                     {"environment_temperature": 350.0, "exposure": "fraction"}),
}  # fmt: skip


def _fields(rng: np.random.Generator) -> np.ndarray:
    f = np.zeros((fk.NFIELDS, N))
    f[fk.F_POROSITY] = rng.uniform(0.25, 1.0, N)
    f[fk.F_FLUID_TEMPERATURE] = rng.uniform(250.0, 1500.0, N)
    f[fk.F_RELATIVE_SPEED] = 10 ** rng.uniform(-3, 1.5, N) * (rng.uniform(size=N) > 0.05)
    f[fk.F_FLUID_CONDUCTIVITY] = rng.uniform(0.01, 0.7, N)
    f[fk.F_FLUID_DENSITY] = rng.uniform(0.1, 1000.0, N)
    f[fk.F_FLUID_SPECIFIC_HEAT] = rng.uniform(500.0, 5000.0, N)
    f[fk.F_FLUID_VISCOSITY] = 10 ** rng.uniform(-5.5, -2.5, N)
    f[fk.F_SURFACE_VISCOSITY] = f[fk.F_FLUID_VISCOSITY] / rng.uniform(1.0, 3.0, N)
    fk.prandtl_columns(f)
    area = rng.uniform(0.0, 1e-5, N) * (rng.uniform(size=N) > 0.1)
    f[fk.F_NEIGHBOUR_AREA] = area
    f[fk.F_NEIGHBOUR_EMISSION] = area * rng.uniform(300.0, 1500.0, N) ** 4
    f[fk.F_WALL_VIEW] = rng.uniform(0.0, 1.0, N) * (rng.uniform(size=N) < 0.3)
    f[fk.F_WALL_EMISSION] = f[fk.F_WALL_VIEW] * rng.uniform(300.0, 1500.0, N) ** 4
    f[fk.F_SCRATCH_HEAT :] = np.nan  # whatever an earlier step left there
    return f


def _term(name: str) -> tuple:
    family, model, *params = TERMS[name]
    spec = registry.get(family, model)
    rows = [spec.pack(spec.params(**p), resolve_pair(m, m))
            for p, m in zip(params, MATERIALS, strict=True)]  # fmt: skip
    return FAMILIES[family], spec.model_id, np.array(rows, np.float64), spec.kernel


@pytest.mark.parametrize(
    ("names", "threads"),
    [(("gunn", "krause"), 1), (("gunn", "krause"), 2), (("krause", "gunn"), 1),
     (("gunn",), 2), (("ranz", "surroundings"), 1), (("surroundings",), 2)],
)  # fmt: skip
def test_particle_pass_equals_the_kernels_particle_by_particle(names: tuple, threads: int) -> None:
    rng = np.random.default_rng(len(names) * 31 + threads)
    fields = _fields(rng)
    temperature = rng.uniform(250.0, 1500.0, N)
    radius = 10 ** rng.uniform(-4, -2, N)
    type_id = rng.integers(0, 2, N).astype(np.int32)
    heat = rng.uniform(-1.0, 1.0, (4, N))
    sums = rng.uniform(0.0, 1.0, N)
    terms = [_term(name) for name in names]
    columns = [1, 3][: len(terms)]
    ref_heat, ref_sums = heat.copy(), sums.copy()
    for i in range(N):
        for (_, _, table, kernel), col in zip(terms, columns, strict=True):
            q, g = kernel(table[type_id[i]], temperature[i], radius[i], fields, i)
            ref_heat[col, i] += q
            ref_sums[i] += g
    (ev, mid, table, _), (ev2, mid2, table2, _) = terms[0], terms[-1]
    apply_threads(threads)
    try:
        particle_pass(temperature, radius, type_id, fields, ev, mid, table, columns[0], ev2,
                      mid2, table2, columns[-1] if len(terms) == 2 else -1, heat, sums)  # fmt: skip
    finally:
        apply_threads(1)
    assert np.all(np.isfinite(ref_heat)) and np.all(np.isfinite(ref_sums))
    assert np.array_equal(heat, ref_heat)
    assert np.array_equal(sums, ref_sums)
