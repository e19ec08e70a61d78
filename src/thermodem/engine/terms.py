"""Heat terms: every selected thermal model, built from the registry.

A :class:`HeatTerm` is one registered model with its packed parameter table, where it runs
(its ``target``: the touching pairs of the contact lists, the pairs of the range set, an
external pair set, or single particles), which kernel evaluates it, and the mechanism
columns it writes (``thermodem.state.heat``). The thermal engine loops over the terms; it
names no model family.

The conduction through the contact (the ``contact_radius`` × ``direct_conduction`` pair) is
the :class:`ContactConduction` term: it runs inside the fused contact pass of the mechanics
(``kernels/pair_pass.py``, compiled per combination of those two models), the fast path of a
dense bed. Everything else is a :class:`HeatTerm` evaluated by the heat-only passes of
``kernels/heat_terms.py`` at thermal steps.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel

from thermodem.config.schema import Case, ModelChoice
from thermodem.errors import ConfigError
from thermodem.kernels.heat_terms import (
    EVAL_CONVECTION,
    EVAL_INDIRECT,
    EVAL_RADIATION,
    EVAL_SEPARATED,
    EVAL_VORONOI,
)
from thermodem.models.registry import ModelSpec
from thermodem.models.tables import material_table, pair_table
from thermodem.state import heat


@dataclass
class ContactConduction:
    """The contact radius and direct conduction models of the fused contact pass."""

    radius: ModelChoice
    direct: ModelChoice
    radius_table: np.ndarray
    direct_table: np.ndarray

    @property
    def radius_id(self) -> int:
        return self.radius.spec.model_id

    @property
    def direct_id(self) -> int:
        return self.direct.spec.model_id

    @property
    def active(self) -> bool:
        """False when direct conduction is ``none`` (the fused pass then carries no heat)."""
        return self.direct.model != "none"


@dataclass
class Generation:
    """The heat generation model (``thermal.heat_generation``): the contact passes add each
    contact's dissipated energy per mechanism to its particles' accumulators, shared by the
    partition coefficients of ``partition``; the thermal step turns them into heat rates of
    the ``generation_<mechanism>`` columns (kernels/generation.py)."""

    choice: ModelChoice
    table: np.ndarray  # [nmat, nmat, width] packed rows (models/thermal/heat_generation.py)
    partition: np.ndarray  # [nmat, nmat, 2]: body i's share of friction heat, of other heat
    select: np.ndarray  # (len(GENERATION),) 1.0 for a mechanism the model turns into heat
    conversion_fraction: float  # χ

    @property
    def active(self) -> bool:
        return self.choice.model != "none"

    @property
    def mechanisms(self) -> list[int]:
        """Indices (in state/heat.GENERATION) of the selected mechanisms."""
        return [g for g in range(len(heat.GENERATION)) if self.select[g] != 0.0]

    @property
    def columns(self) -> list[int]:
        """The heat-by-mechanism columns it writes."""
        return [heat.M_GENERATION + g for g in self.mechanisms]


def build_generation(
    case: Case,
    names: list[str],
    meets: Callable[[str, str], bool],
    is_wall: Callable[[str, str], bool],
) -> Generation:
    """The heat generation of the case's thermal section (its rows for the materials that
    meet: particles with particles and with walls of a fixed temperature; an adiabatic wall
    takes no share, so it needs none)."""
    from thermodem.models.thermal import heat_generation as HG

    choice = case.thermal.heat_generation
    spec = choice.spec
    table = pair_table(choice, case, names, meets=meets, is_wall=is_wall,
                       key="thermal.heat_generation")  # fmt: skip
    partition = np.ascontiguousarray(
        table[:, :, [spec.column("psi_friction"), spec.column("psi_other")]]
    )
    # χ and the selection are properties of the model, the same in every packed row: the
    # row of the first particle material with itself (packed: particles meet each other)
    row = np.zeros(spec.width)
    if case.insertion:
        t = names.index(case.insertion[0].material)
        row = table[t, t]
    select = np.array([row[HG.C_SELECT + g] for g in range(len(heat.GENERATION))])
    return Generation(choice, table, partition, select, float(row[HG.C_CHI]))


@dataclass
class HeatTerm:
    """One selected thermal model evaluated by a heat-only pass (see the module docstring)."""

    key: str  # the case key that selects it, for messages ("thermal.indirect_conduction")
    choice: ModelChoice
    target: str  # "contacts" | "range" | "external" | "particles"
    evaluator: int  # EVAL_* of kernels/heat_terms.py
    table: np.ndarray  # [nmat, nmat, width]; [nmat, width] for per-particle terms
    column: int  # mechanism column of particle pairs
    wall_column: int  # mechanism column of particle-wall pairs
    k_columns: tuple[int, int]  # row columns replaced by k(T) of the two bodies, (-1, -1): none

    @property
    def spec(self) -> ModelSpec:
        return self.choice.spec

    @property
    def params(self) -> BaseModel:
        return self.choice.params

    @property
    def model_id(self) -> int:
        return self.spec.model_id

    @property
    def needs_contact_radius(self) -> bool:
        """Whether the range passes compute R_c^geo for the kernel (separated-pair parts of
        direct models and kernels that ignore r_c do not need it)."""
        return self.evaluator != EVAL_SEPARATED and self.spec.uses_contact_radius

    def max_gap(self, radius: float) -> tuple[float, float]:
        """Largest conducting surface gap [m] of particle pairs and particle-wall pairs for
        particles up to ``radius`` (ranges grow with the radii: ratio × R*, ratio × R_k)."""
        fn = self.spec.interaction_range
        if fn is None:
            return 0.0, 0.0
        return float(fn(self.params, radius, radius)), float(fn(self.params, radius, np.inf))


def _k_columns(spec: ModelSpec) -> tuple[int, int]:
    cols = spec.columns or ()
    if "k_i" in cols and "k_j" in cols:
        return cols.index("k_i"), cols.index("k_j")
    return -1, -1


def build_terms(
    case: Case,
    names: list[str],
    meets: Callable[[str, str], bool],
    is_wall: Callable[[str, str], bool],
    particle_material: Callable[[str], bool],
) -> tuple[ContactConduction, list[HeatTerm]]:
    """The contact conduction and the other heat terms of the case's thermal section."""
    settings = case.thermal
    radius, direct = settings.contact_radius, settings.direct_conduction

    def table(choice: ModelChoice, key: str) -> np.ndarray:
        return pair_table(choice, case, names, meets=meets, is_wall=is_wall, key=key)

    contact = ContactConduction(
        radius=radius,
        direct=direct,
        radius_table=table(radius, "thermal.contact_radius"),
        direct_table=table(direct, "thermal.direct_conduction"),
    )
    terms: list[HeatTerm] = []
    if direct.spec.interaction_range is not None:
        # the separated-pair part of a direct model that conducts across a gap: range set
        terms.append(
            HeatTerm(
                key="thermal.direct_conduction",
                choice=direct,
                target="range",
                evaluator=EVAL_SEPARATED,
                table=contact.direct_table,
                column=heat.M_INDIRECT,
                wall_column=heat.M_WALL_INDIRECT,
                k_columns=_k_columns(direct.spec),
            )
        )
    indirect = settings.indirect_conduction
    if indirect.model != "none":
        if direct.spec.interaction_range is not None or direct.model == "resistance_network":
            raise ConfigError(
                f"thermal.indirect_conduction = {indirect.model!r} cannot be combined with "
                f"thermal.direct_conduction = {direct.model!r}: that model already includes the "
                "conduction through the gas around the contact"
                + (" and between separated particles" if direct.spec.interaction_range else "")
                + ", which would be counted twice; choose a contact-only direct model (e.g. "
                "batchelor_obrien_simple) with it, or indirect_conduction: none"
            )
        pair_col, wall_col = heat.FAMILY_COLUMNS["indirect_conduction"]
        terms.append(
            HeatTerm(
                key="thermal.indirect_conduction",
                choice=indirect,
                target=indirect.spec.target,
                # models made for the external set read its input rows (the Voronoi faces)
                evaluator=EVAL_VORONOI if indirect.spec.target == "external" else EVAL_INDIRECT,
                table=table(indirect, "thermal.indirect_conduction"),
                column=pair_col,
                wall_column=wall_col,
                k_columns=_k_columns(indirect.spec),
            )
        )
    # per-particle terms: their fields come from engine/fields.py (the fluid, the porosity)
    for family, evaluator in (("convection", EVAL_CONVECTION), ("radiation", EVAL_RADIATION)):
        choice = getattr(settings, family)
        if choice.model == "none":
            continue
        key = f"thermal.{family}"
        terms.append(
            HeatTerm(
                key=key,
                choice=choice,
                target="particles",
                evaluator=evaluator,
                table=material_table(choice, case, names, particle_material, key),
                column=heat.FAMILY_COLUMNS[family][0],
                wall_column=-1,
                k_columns=(-1, -1),
            )
        )
    return contact, terms
