"""Every registered per-particle model (convection, radiation): the family dispatcher agrees
with the model's own kernel on random fields, 'none' has id 0 and unknown ids give NaN, G is
non-negative, each model has a docs page, and `thermodem models` lists them."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from thermodem.kernels import fields as fk
from thermodem.kernels.heat_terms import EVAL_CONVECTION, EVAL_RADIATION, particle_term
from thermodem.models import registry
from thermodem.state.materials import Material, resolve_pair

FAMILIES = {"convection": EVAL_CONVECTION, "radiation": EVAL_RADIATION}
DOCS = Path(__file__).resolve().parents[2] / "docs" / "models"
SPECS = [registry.get(f, n) for f in FAMILIES for n in registry.names(f)]
IDS = [f"{s.family}.{s.name}" for s in SPECS]
MATERIAL = Material(density=2500.0, youngs_modulus=1e8, poisson_ratio=0.3, emissivity=0.7)


def _params(spec: registry.ModelSpec):  # noqa: ANN202
    example = dict(spec.example_params)
    if spec.name == "surroundings":
        example.setdefault("environment_temperature", 300.0)
    return spec.params(**example)


def _random_fields(rng: np.random.Generator, n: int = 6) -> np.ndarray:
    f = np.zeros((fk.NFIELDS, n))
    f[fk.F_POROSITY] = rng.uniform(0.3, 1.0, n)
    f[fk.F_FLUID_TEMPERATURE] = rng.uniform(250, 1500, n)
    f[fk.F_RELATIVE_SPEED] = 10 ** rng.uniform(-3, 1.5, n)
    f[fk.F_FLUID_CONDUCTIVITY] = rng.uniform(0.01, 0.7, n)
    f[fk.F_FLUID_DENSITY] = rng.uniform(0.1, 1000, n)
    f[fk.F_FLUID_SPECIFIC_HEAT] = rng.uniform(500, 5000, n)
    f[fk.F_FLUID_VISCOSITY] = 10 ** rng.uniform(-5.5, -2.5, n)
    f[fk.F_SURFACE_VISCOSITY] = f[fk.F_FLUID_VISCOSITY] / rng.uniform(1, 3, n)
    fk.prandtl_columns(f)
    f[fk.F_NEIGHBOURS] = rng.integers(0, 20, n)
    f[fk.F_NEIGHBOUR_TEMPERATURE] = f[fk.F_NEIGHBOURS] * rng.uniform(300, 1500, n)
    area = rng.uniform(0, 1e-5, n) * (f[fk.F_NEIGHBOURS] > 0)
    f[fk.F_NEIGHBOUR_AREA] = area
    f[fk.F_NEIGHBOUR_EMISSION] = area * rng.uniform(300, 1500, n) ** 4
    f[fk.F_WALL_VIEW] = rng.uniform(0, 1, n) * (rng.uniform(size=n) < 0.5)
    f[fk.F_WALL_EMISSION] = f[fk.F_WALL_VIEW] * rng.uniform(300, 1500, n) ** 4
    return f


@pytest.mark.parametrize("family", list(FAMILIES))
def test_none_is_id_zero_and_unknown_ids_give_nan(family: str) -> None:
    assert registry.get(family, "none").model_id == 0
    f = np.zeros((fk.NFIELDS, 1))
    q, g = particle_term(FAMILIES[family], 99, np.zeros(4), 300.0, 1e-3, f, 0)
    assert math.isnan(q) and math.isnan(g)


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_dispatcher_agrees_with_kernel(spec: registry.ModelSpec) -> None:
    rng = np.random.default_rng(abs(hash(spec.name)) % 2**32)
    row = spec.pack(_params(spec), resolve_pair(MATERIAL, MATERIAL))
    assert row.shape == (spec.width,)
    assert spec.target == "particles"
    f = _random_fields(rng)
    for i in range(f.shape[1]):
        t = float(rng.uniform(250, 1500))
        r = float(10 ** rng.uniform(-4, -2))
        got = particle_term(FAMILIES[spec.family], spec.model_id, row, t, r, f, i)
        assert got == spec.kernel(row, t, r, f, i)
        assert got[1] >= 0.0 and np.isfinite(got).all()


@pytest.mark.parametrize("spec", SPECS, ids=IDS)
def test_docs_page_exists(spec: registry.ModelSpec) -> None:
    page = DOCS / f"{spec.family}-{spec.name}.md"
    assert page.exists(), page
    assert f"`{spec.name}`" in page.read_text().splitlines()[0]


def test_cli_lists_the_models() -> None:
    out = subprocess.run([sys.executable, "-m", "thermodem.cli", "models", "convection"],
                         capture_output=True, text=True, check=True).stdout  # fmt: skip
    for name in registry.names("convection"):
        assert f"convection.{name}:" in out
    assert "reads thermal.gas: thermal_conductivity, specific_heat, dynamic_viscosity" in out
    out = subprocess.run([sys.executable, "-m", "thermodem.cli", "models", "radiation"],
                         capture_output=True, text=True, check=True).stdout  # fmt: skip
    for name in ("surroundings", "zhou2009", "krause2017"):
        assert f"radiation.{name}:" in out
    assert "radius_ratio" in out and "wall_view_factor" in out
