"""Radiation models (family ``radiation``), per-particle terms.

Kernel signature of a per-particle term (``p``: the packed row of the particle's material,
``fields``: the per-particle fields of the engine, ``i`` the particle's row in them)::

    kernel(p, t_i, r_i, fields, i) -> (Q [W] into particle i, G [W/K])

G is the linearised conductance -dQ/dT_i (>= 0), which the explicit stability limit
m c / ΣG uses, so a non-linear term (T⁴) keeps the limit right.

Spec: dem-heat-transfer-models.md, "Heat Radiation Mechanisms" (net radiation with the
surrounding environment, Q_r = ε A_s σ (T_e⁴ − T_s⁴), grey body: absorptivity = emissivity;
net radiation with other surfaces, Q = ε F A σ (T_2⁴ − T_1⁴)) and "DEM Radiation Models"
(the continuum models of Zhou et al. 2009 and Krause et al. 2017: T_e from the particles
whose centre lies in a sphere of radiative influence, radius 3 R_i by default).

Models:

- ``surroundings``: T_e given; every particle in view of it (``exposure: all``), or only the
  particles whose local porosity is at least a threshold (``threshold``), or each with the
  fraction ε_i of its surface (``fraction``);
- ``zhou2009``: T_e = ε T_f + (1 − ε) (1/n_p) Σ_j T_j (ε the local porosity, T_f the fluid);
- ``krause2017``: T_e⁴ = Σ_j ε_j A_j σ T_j⁴ / 2 / Σ_j ε_j A_j σ / 2 (half the surface of each
  particle whose centre lies in the sphere).

Particle–wall radiation (any model, ``walls: true``): a particle whose surface gap to a
fixed-temperature wall is below ``wall_range`` × R_i sees that wall with the view factor
``wall_view_factor`` (default 1/2: a sphere facing a plane); the fraction Σ_w F_iw of its
surface exchanges with the walls, ε A σ Σ_w F_iw (T_w⁴ − T⁴), and the rest, 1 − Σ_w F_iw,
with the model's environment. The neighbourhood sums and the wall view factors are fields
(``kernels/fields.py``) filled by ``engine/fields.py`` before the terms run.

The continuum models are not pairwise: what particle i receives from its environment is not
taken from the neighbours, so the bed's radiative heat does not sum to zero; it is ledgered
as a boundary mechanism (``heat_in_radiation``), and the ledger still closes.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from thermodem.config.base import StrictModel
from thermodem.kernels.fields import (
    F_FLUID_TEMPERATURE,
    F_NEIGHBOUR_AREA,
    F_NEIGHBOUR_EMISSION,
    F_NEIGHBOUR_TEMPERATURE,
    F_NEIGHBOURS,
    F_POROSITY,
    F_WALL_EMISSION,
    F_WALL_VIEW,
)
from thermodem.models.registry import packed, register
from thermodem.models.thermal.contact_radius import require
from thermodem.state.materials import PairContext

NONE = 0
SURROUNDINGS = 1
ZHOU2009 = 2
KRAUSE2017 = 3

FAMILY = "radiation"

#: Stefan–Boltzmann constant [W/(m² K⁴)] (CODATA 2018, exact in the SI since 2019).
STEFAN_BOLTZMANN = 5.670374419e-8

SURROUNDINGS_COLUMNS = ("emissivity", "environment_temperature", "exposure", "threshold")
SR_EMISSIVITY, SR_ENVIRONMENT, SR_EXPOSURE, SR_THRESHOLD = 0, 1, 2, 3
EXPOSURE = {"all": 0.0, "threshold": 1.0, "fraction": 2.0}
ZHOU_COLUMNS = ("emissivity",)
KRAUSE_COLUMNS = ("emissivity", "environment_temperature")
KR_ENVIRONMENT = 1

#: Radiation models that read the local porosity / the neighbourhood sums / the fluid.
NEIGHBOURHOOD_MODELS = ("zhou2009", "krause2017")


class WallRadiation(StrictModel):
    """Particle–wall radiation, common to every radiation model (see the module docstring)."""

    walls: bool = Field(
        default=False,
        description="radiation with the fixed-temperature walls in view (ε F A σ (T_w⁴ − T⁴))",
    )
    wall_view_factor: float = Field(
        default=0.5,
        gt=0,
        le=1,
        description="F_iw [-] of each wall in view (1/2: a sphere facing a plane)",
    )
    wall_range: float = Field(
        default=1.0,
        ge=0,
        description="a wall is in view while the surface gap is below "
        "wall_range × R_i [-] (1: the first layer of a bed)",
    )


class NoneParams(StrictModel):
    """No radiation."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def none_radiation(p, t_i, r_i, fields, i):
    return 0.0, 0.0


class SurroundingsParams(WallRadiation):
    """Net radiation with a surrounding environment at T_e (spec, "Net radiation with
    surrounding environment"): Q = φ_i ε 4π R² σ (T_e⁴ − T⁴), the grey body of emissivity
    ε = the material's ``emissivity`` (absorptivity = emissivity), σ the Stefan–Boltzmann
    constant, φ_i the particle's exposure: 1 for every particle (``exposure: all``: a dilute
    suspension, a single particle in a large enclosure), 1 where the local porosity is at
    least ``threshold`` and 0 elsewhere (``threshold``: the particles at the free surface of
    a bed), or the local porosity ε_i (``fraction``: the void fraction around the particle
    taken as the fraction of its surface that sees the environment). The spec does not
    define the exposure; these three are thermodem's. Row: [ε, T_e, exposure, threshold]."""

    environment_temperature: float = Field(gt=0, description="T_e [K]")
    exposure: Literal["all", "threshold", "fraction"] = Field(
        default="all",
        description="which particles see the environment (needs thermal.porosity unless 'all')",
    )
    threshold: float | None = Field(
        default=None,
        gt=0,
        le=1,
        description="porosity from which a particle is exposed [-] (exposure: threshold)",
    )

    @model_validator(mode="after")
    def _threshold(self) -> SurroundingsParams:
        if self.exposure == "threshold" and self.threshold is None:
            raise ValueError("exposure 'threshold' needs threshold (a local porosity, 0-1)")
        if self.exposure != "threshold" and self.threshold is not None:
            raise ValueError(
                f"threshold is given but exposure is {self.exposure!r}: set exposure: threshold"
            )
        return self


def pack_surroundings(params: SurroundingsParams, pair: PairContext) -> np.ndarray:
    emissivity = require(pair.mat_i, "emissivity", "radiation.surroundings")
    values = {
        "emissivity": emissivity,
        "environment_temperature": params.environment_temperature,
        "exposure": EXPOSURE[params.exposure],
        "threshold": params.threshold or 0.0,
    }
    return packed(SURROUNDINGS_COLUMNS, values)


@njit(cache=True, inline="always", error_model="numpy")
def _exchange(coefficient, t_i, te4, environment, fields, i):
    """(Q, G) of a particle whose surface fraction ``environment`` sees an environment of
    T_e⁴ = te4 and whose fraction Σ F_iw sees the walls (fields): Q = ε A σ (environment
    (T_e⁴ − T⁴) + Σ F T_w⁴ − Σ F T⁴), G = 4 ε A σ T³ (environment + Σ F)."""
    view = fields[F_WALL_VIEW, i]
    env = environment * (1.0 - view)
    t2 = t_i * t_i
    t4 = t2 * t2
    q = coefficient * (env * (te4 - t4) + (fields[F_WALL_EMISSION, i] - view * t4))
    return q, 4.0 * coefficient * t2 * t_i * (env + view)


@njit(cache=True, inline="always", error_model="numpy")
def surroundings_radiation(p, t_i, r_i, fields, i):
    """(Q, G) = (φ ε A σ (T_e⁴ − T⁴), 4 φ ε A σ T³), A = 4π R² (and the walls in view)."""
    coefficient = p[SR_EMISSIVITY] * 4.0 * math.pi * r_i * r_i * STEFAN_BOLTZMANN
    t_e = p[SR_ENVIRONMENT]
    te2 = t_e * t_e
    exposure = 1.0
    mode = p[SR_EXPOSURE]
    if mode == 1.0:
        exposure = 1.0 if fields[F_POROSITY, i] >= p[SR_THRESHOLD] else 0.0
    elif mode == 2.0:
        exposure = fields[F_POROSITY, i]
    return _exchange(coefficient, t_i, te2 * te2, exposure, fields, i)


class ContinuumParams(WallRadiation):
    """Common parameter of the continuum models: the sphere of radiative influence."""

    radius_ratio: float = Field(
        default=3.0,
        gt=1,
        description="radius of the sphere of influence / R_i [-] (spec: normally 3)",
    )


class Zhou2009Params(ContinuumParams):
    """J.H. Zhou, A.B. Yu & P. Zulli (2009), Particle scale study of heat transfer in packed
    and bubbling fluidized beds, AIChE J. 55:868-884 (spec, "Continuum model"): the environment of
    particle i is the volume average of the fluid and of the n_p particles whose centre lies
    in the sphere of radius ``radius_ratio`` × R_i, T_e = ε T_f + (1 − ε) (1/n_p) Σ_j T_j with ε
    the local porosity (thermal.porosity) and T_f the fluid temperature (thermal.fluid);
    Q = ε_i A_i σ (T_e⁴ − T_i⁴). Without neighbours T_e = T_f. Row: [ε]."""


class Krause2017Params(ContinuumParams):
    """Krause et al. (2017), 3D-DEM-CFD simulation of heat and mass transfer, gas combustion
    and calcination in an intermittent operating lime shaft kiln, Int. J. Therm. Sci.
    117:121-135 (spec, "Continuum model"): T_e⁴ = Σ_j ε_j A_j σ T_j⁴ / 2 /
    Σ_j ε_j A_j σ / 2 over the particles whose centre lies in the sphere of radius
    ``radius_ratio`` × R_i (half the surface of each counts); Q = ε_i A_i σ (T_e⁴ − T_i⁴).
    A particle with no neighbour in its sphere exchanges with ``environment_temperature``
    if given, else not at all. Row: [ε, T_e of an empty sphere (0: none)]."""

    environment_temperature: float | None = Field(
        default=None,
        gt=0,
        description="T_e [K] of a particle with no neighbour in its "
        "sphere; null: no radiation then",
    )


def pack_zhou(params: Zhou2009Params, pair: PairContext) -> np.ndarray:
    emissivity = require(pair.mat_i, "emissivity", "radiation.zhou2009")
    return packed(ZHOU_COLUMNS, {"emissivity": emissivity})


def pack_krause(params: Krause2017Params, pair: PairContext) -> np.ndarray:
    emissivity = require(pair.mat_i, "emissivity", "radiation.krause2017")
    values = {
        "emissivity": emissivity,
        "environment_temperature": params.environment_temperature or 0.0,
    }
    return packed(KRAUSE_COLUMNS, values)


@njit(cache=True, inline="always", error_model="numpy")
def zhou2009_radiation(p, t_i, r_i, fields, i):
    """T_e = ε T_f + (1 − ε) mean T_j (T_f without neighbours); (Q, G) as surroundings."""
    coefficient = p[SR_EMISSIVITY] * 4.0 * math.pi * r_i * r_i * STEFAN_BOLTZMANN
    count = fields[F_NEIGHBOURS, i]
    t_f = fields[F_FLUID_TEMPERATURE, i]
    t_e = t_f
    if count > 0.0:
        eps = fields[F_POROSITY, i]
        t_e = eps * t_f + (1.0 - eps) * fields[F_NEIGHBOUR_TEMPERATURE, i] / count
    te2 = t_e * t_e
    return _exchange(coefficient, t_i, te2 * te2, 1.0, fields, i)


@njit(cache=True, inline="always", error_model="numpy")
def krause2017_radiation(p, t_i, r_i, fields, i):
    """T_e⁴ = Σ ε_j A_j T_j⁴ / Σ ε_j A_j over the sphere; (Q, G) as surroundings."""
    coefficient = p[SR_EMISSIVITY] * 4.0 * math.pi * r_i * r_i * STEFAN_BOLTZMANN
    area = fields[F_NEIGHBOUR_AREA, i]
    if area > 0.0:
        return _exchange(coefficient, t_i, fields[F_NEIGHBOUR_EMISSION, i] / area, 1.0, fields, i)
    t_e = p[KR_ENVIRONMENT]
    te2 = t_e * t_e
    return _exchange(coefficient, t_i, te2 * te2, 1.0 if t_e > 0.0 else 0.0, fields, i)


@njit(cache=True, inline="always", error_model="numpy")
def radiation_dispatch(model_id, p, t_i, r_i, fields, i):
    """(Q, G) of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    if model_id == KRAUSE2017:
        return krause2017_radiation(p, t_i, r_i, fields, i)
    elif model_id == SURROUNDINGS:
        return surroundings_radiation(p, t_i, r_i, fields, i)
    elif model_id == ZHOU2009:
        return zhou2009_radiation(p, t_i, r_i, fields, i)
    elif model_id == NONE:
        return 0.0, 0.0
    return np.nan, np.nan


register(
    family=FAMILY,
    name="none",
    model_id=NONE,
    kernel=none_radiation,
    params=NoneParams,
    pack=pack_none,
    summary="no radiation",
    reference="-",
    columns=(),
    target="particles",
    planar=("disc", "sphere"),
)
register(
    family=FAMILY,
    name="surroundings",
    model_id=SURROUNDINGS,
    kernel=surroundings_radiation,
    params=SurroundingsParams,
    pack=pack_surroundings,
    summary="net radiation with an environment at T_e, ε 4πR² σ (T_e⁴ − T⁴), for every "
    "particle or the exposed ones (local porosity); optional walls in view",
    reference="Stefan-Boltzmann law; Incropera et al. (2006) Fundamentals of Heat and Mass "
    "Transfer, ch. 12; spec 'Net radiation with surrounding environment'",
    requires=("emissivity",),
    columns=SURROUNDINGS_COLUMNS,
    target="particles",
    example_params={"environment_temperature": 300.0},
    planar=("sphere",),
)
register(
    family=FAMILY,
    name="zhou2009",
    model_id=ZHOU2009,
    kernel=zhou2009_radiation,
    params=Zhou2009Params,
    pack=pack_zhou,
    summary="continuum: T_e = ε T_f + (1 − ε) mean T_j of the particles within 3 R_i "
    "(local porosity, fluid temperature); optional walls in view",
    reference="Zhou, Yu & Zulli (2009) AIChE J. 55:868-884; spec 'DEM Radiation Models'",
    requires=("emissivity",),
    columns=ZHOU_COLUMNS,
    target="particles",
)
register(
    family=FAMILY,
    name="krause2017",
    model_id=KRAUSE2017,
    kernel=krause2017_radiation,
    params=Krause2017Params,
    pack=pack_krause,
    summary="continuum: T_e⁴ = Σ ε_j A_j T_j⁴ / Σ ε_j A_j over the particles within 3 R_i "
    "(half surfaces); optional walls in view",
    reference="Krause, Liedmann, Wiese, Bucher, Wirtz, Piringer & Scherer (2017) Int. J. "
    "Therm. Sci. 117:121-135; spec 'DEM Radiation Models'",
    requires=("emissivity",),
    columns=KRAUSE_COLUMNS,
    target="particles",
)
