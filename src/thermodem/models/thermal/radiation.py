"""Radiation models (family ``radiation``), per-particle terms.

Kernel signature of a per-particle term (``p``: the packed row of the particle's material,
``fields``: the per-particle fields of the engine, ``i`` the particle's row in them)::

    kernel(p, t_i, r_i, fields, i) -> (Q [W] into particle i, G [W/K])

G is the linearised conductance -dQ/dT_i (>= 0), which the explicit stability limit
m c / ΣG uses, so a non-linear term (T⁴) keeps the limit right.

Spec: dem-heat-transfer-models.md, "Heat Radiation Mechanisms" (net radiation with the
surrounding environment, Q_r = ε A_s σ (T_e⁴ − T_s⁴), grey body: absorptivity = emissivity).
The continuum models of Zhou et al. (2009) and Krause et al. (2017), which take T_e from
the neighbourhood, come with the convection/radiation issue.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from thermodem.config.base import StrictModel
from thermodem.models.registry import packed, register
from thermodem.models.thermal.contact_radius import require
from thermodem.state.materials import PairContext

NONE = 0
SURROUNDINGS = 1

FAMILY = "radiation"

#: Stefan–Boltzmann constant [W/(m² K⁴)] (CODATA 2018, exact in the SI since 2019).
STEFAN_BOLTZMANN = 5.670374419e-8

SURROUNDINGS_COLUMNS = ("emissivity", "environment_temperature")
SR_EMISSIVITY, SR_ENVIRONMENT = 0, 1


class NoneParams(StrictModel):
    """No radiation."""


def pack_none(params: NoneParams, pair: PairContext) -> np.ndarray:
    return packed((), {})


@njit(cache=True, error_model="numpy")
def none_radiation(p, t_i, r_i, fields, i):
    return 0.0, 0.0


class SurroundingsParams(StrictModel):
    """Net radiation of every particle with a surrounding environment at T_e (spec, "Net
    radiation with surrounding environment"): Q = ε 4π R² σ (T_e⁴ − T⁴), the grey body of
    emissivity ε = the material's ``emissivity`` (absorptivity = emissivity), σ the
    Stefan–Boltzmann constant. Every particle sees the environment over its whole surface:
    a dilute suspension or a single particle in a large enclosure; in a packed bed the
    continuum models (neighbourhood temperature) apply. Row: [ε, T_e]."""

    environment_temperature: float = Field(gt=0, description="T_e [K]")


def pack_surroundings(params: SurroundingsParams, pair: PairContext) -> np.ndarray:
    emissivity = require(pair.mat_i, "emissivity", "radiation.surroundings")
    values = {"emissivity": emissivity, "environment_temperature": params.environment_temperature}
    return packed(SURROUNDINGS_COLUMNS, values)


@njit(cache=True, error_model="numpy")
def surroundings_radiation(p, t_i, r_i, fields, i):
    """(Q, G) = (ε A σ (T_e⁴ − T⁴), 4 ε A σ T³), A = 4π R²."""
    coefficient = p[SR_EMISSIVITY] * 4.0 * math.pi * r_i * r_i * STEFAN_BOLTZMANN
    t_e = p[SR_ENVIRONMENT]
    t2 = t_i * t_i
    te2 = t_e * t_e
    return coefficient * (te2 * te2 - t2 * t2), 4.0 * coefficient * t2 * t_i


@njit(cache=True, inline="always", error_model="numpy")
def radiation_dispatch(model_id, p, t_i, r_i, fields, i):
    """(Q, G) of model ``model_id`` (NaN for an unknown id, caught by the NaN flag)."""
    if model_id == SURROUNDINGS:
        return surroundings_radiation(p, t_i, r_i, fields, i)
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
)
register(
    family=FAMILY,
    name="surroundings",
    model_id=SURROUNDINGS,
    kernel=surroundings_radiation,
    params=SurroundingsParams,
    pack=pack_surroundings,
    summary="net radiation with an environment at T_e, ε 4πR² σ (T_e⁴ − T⁴)",
    reference="Stefan-Boltzmann law; Incropera et al. (2006) Fundamentals of Heat and Mass "
    "Transfer, ch. 12; spec 'Net radiation with surrounding environment'",
    requires=("emissivity",),
    columns=SURROUNDINGS_COLUMNS,
    target="particles",
    example_params={"environment_temperature": 300.0},
)
