"""The model registry: the only list of model names in thermodem.

Every physical model is registered once, with :func:`register`, by the module that defines it.
A model is a small Numba-compiled scalar function (its *kernel*) plus:

- a pydantic parameter schema (SI names, bounds, defaults; the paper cited in its docstring),
- a ``pack`` function turning the parameters and the two materials that meet into a float64
  row for that type pair (mixing rules are written there, explicitly),
- metadata: its integer id inside the family (the fused loops switch on it), the names of its
  parameter row's columns (``columns``: the row width comes from them), history width and
  which history entries flip sign when i and j swap, the interaction range beyond contact it
  needs, where it runs (``target``: touching pairs, pairs within a range, an external pair set
  or single particles), the material properties it requires, the properties of the case's
  interstitial gas (``thermal.gas``, handed to ``pack`` as ``pair.gas``) it reads, and the
  reference.

The integer ids are written as constants in the model modules (not assigned at import time) so
that the compiled dispatchers, which are cached on disk by Numba, never disagree with the
registry; ``tests/unit/test_registry_conformance.py`` walks the registry and checks that each
family's dispatcher and each model's own kernel give the same answer.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pydantic import BaseModel

FAMILIES: tuple[str, ...] = (
    "normal",
    "tangential",
    "rolling",
    "contact_radius",
    "direct_conduction",
    "indirect_conduction",
    "convection",
    "radiation",
    "heat_generation",
    "heat_source",
)

#: Where a thermal term runs (see ``docs/architecture.md``, "Heat terms on pair sets"):
#: ``contacts`` touching pairs of the contact list, ``range`` every pair whose surface gap is
#: within the model's interaction range (touching pairs included), ``external`` a pair set
#: given from outside with per-pair inputs (Voronoi faces), ``particles`` single particles.
TARGETS: tuple[str, ...] = ("contacts", "range", "external", "particles")

#: Particle shapes of a two-dimensional case (``simulation.particle_shape``): discs of the
#: case's thickness, or spheres kept in the plane z = 0.
PLANAR_SHAPES: tuple[str, ...] = ("disc", "sphere")


def planar_support(spec: ModelSpec) -> str:
    """What ``thermodem models`` says of a model in 2D."""
    if spec.only_2d:
        return "discs only (a 2D law: refused in 3D)"
    if set(spec.planar) == set(PLANAR_SHAPES):
        return "discs and spheres in a plane"
    if spec.planar == ("disc",):
        return "discs only"
    if spec.planar == ("sphere",):
        return "spheres in a plane only (3D form)"
    return "no (3D only)"


@dataclass(frozen=True)
class ModelSpec:
    """Everything thermodem knows about one registered model."""

    family: str
    name: str
    model_id: int
    kernel: Callable[..., Any]
    params: type[BaseModel]
    pack: Callable[..., np.ndarray]
    summary: str
    reference: str
    history_width: int = 0
    history_flip: tuple[bool, ...] = ()
    requires: tuple[str, ...] = ()
    interaction_range: Callable[..., float] | None = None
    antisymmetric: bool = True
    uses_gas: tuple[str, ...] = ()
    columns: tuple[str, ...] = ()
    swap_pairs: tuple[tuple[int, int], ...] = ()
    target: str = "contacts"
    symmetric: bool = False
    conductance_from_force: bool = False
    conductance_reuse_refusal: Callable[[BaseModel], str | None] | None = None
    uses_contact_radius: bool = True
    example_params: dict[str, Any] = field(default_factory=dict)
    planar: tuple[str, ...] = ()
    only_2d: bool = False
    range_parameter: str | None = None
    requires_of: Callable[[BaseModel], tuple[str, ...]] | None = None

    def required(self, params: BaseModel) -> tuple[str, ...]:
        """Material properties required with these parameter values: ``requires`` and what
        ``requires_of(params)`` adds (a property that only some options read)."""
        extra = self.requires_of(params) if self.requires_of is not None else ()
        return tuple(dict.fromkeys((*self.requires, *extra)))

    @property
    def width(self) -> int:
        """Width of the packed parameter row: its named columns (at least 1: a model without
        parameters packs one zero)."""
        return max(len(self.columns), 1)

    def column(self, name: str) -> int:
        """Index of the named column of the packed row (KeyError naming the columns)."""
        if name not in self.columns:
            raise KeyError(f"{self.family}.{self.name} has no column {name!r}: {self.columns}")
        return self.columns.index(name)


_REGISTRY: dict[str, dict[str, ModelSpec]] = {f: {} for f in FAMILIES}


def register(
    *,
    family: str,
    name: str,
    model_id: int,
    kernel: Callable[..., Any],
    params: type[BaseModel],
    pack: Callable[..., np.ndarray],
    summary: str,
    reference: str,
    history_width: int = 0,
    history_flip: tuple[bool, ...] = (),
    requires: tuple[str, ...] = (),
    interaction_range: Callable[..., float] | None = None,
    antisymmetric: bool = True,
    uses_gas: tuple[str, ...] = (),
    columns: tuple[str, ...] = (),
    swap_pairs: tuple[tuple[int, int], ...] = (),
    target: str = "contacts",
    symmetric: bool = False,
    conductance_from_force: bool = False,
    conductance_reuse_refusal: Callable[[BaseModel], str | None] | None = None,
    uses_contact_radius: bool = True,
    example_params: dict[str, Any] | None = None,
    planar: tuple[str, ...] = (),
    only_2d: bool = False,
    range_parameter: str | None = None,
    requires_of: Callable[[BaseModel], tuple[str, ...]] | None = None,
) -> ModelSpec:
    """Register a model; the (family, name) and (family, model_id) pairs must be unique.

    ``columns`` names the columns of the row ``pack`` returns (``pack`` must return exactly
    that many values; see :func:`packed`); ``swap_pairs`` the column pairs exchanged when i
    and j swap; ``target`` where a thermal term runs (:data:`TARGETS`); ``symmetric`` that
    the kernel's value is unchanged when i and j swap (contact radii);
    ``conductance_from_force`` that the conductance depends on a contact through its normal
    force only (allows ``thermal.conductance_force_tolerance``), and
    ``conductance_reuse_refusal(params)`` a reason to refuse it for some parameter values (or
    None); ``uses_contact_radius`` False for a pair-term kernel that ignores its ``r_c``
    argument (the range pass then does not compute it); ``example_params`` parameters the
    conformance tests use for a model without defaults; ``range_parameter`` the parameter
    that sets ``interaction_range`` (in proportion), named by the range errors; ``planar`` the
    particle shapes of a two-dimensional case (``simulation.dimension: 2``) the model
    supports: ``"disc"`` (discs of ``simulation.thickness``: the model has a 2D form, or
    needs none) and/or ``"sphere"`` (spheres kept in the plane: the 3D form is right for
    them); empty: 3D only, refused in 2D before the run (:data:`PLANAR_SHAPES`); ``only_2d``
    a 2D law (refused in 3D cases).;
    ``requires_of(params)`` material properties required only with some parameter values (a
    partition formula's inputs).
    """
    if family not in _REGISTRY:
        raise ValueError(f"unknown model family {family!r}; families are {', '.join(FAMILIES)}")
    models = _REGISTRY[family]
    if name in models:
        raise ValueError(f"model {family}.{name} is registered twice")
    for other in models.values():
        if other.model_id == model_id:
            raise ValueError(
                f"model id {model_id} of {family}.{name} is already used by {family}.{other.name}"
            )
    if len(history_flip) != history_width:
        raise ValueError(f"{family}.{name}: history_flip must have history_width entries")
    for shape in planar:
        if shape not in PLANAR_SHAPES:
            raise ValueError(f"{family}.{name}: planar shape {shape!r} not in {PLANAR_SHAPES}")
    if target not in TARGETS:
        raise ValueError(f"{family}.{name}: target {target!r} is not one of {TARGETS}")
    for a, b in swap_pairs:
        if not (0 <= a < len(columns) and 0 <= b < len(columns)):
            raise ValueError(f"{family}.{name}: swap pair {(a, b)} outside columns {columns}")
    spec = ModelSpec(
        family=family,
        name=name,
        model_id=model_id,
        kernel=kernel,
        params=params,
        pack=pack,
        summary=summary,
        reference=reference,
        history_width=history_width,
        history_flip=tuple(history_flip),
        requires=tuple(requires),
        interaction_range=interaction_range,
        antisymmetric=antisymmetric,
        uses_gas=tuple(uses_gas),
        columns=tuple(columns),
        swap_pairs=tuple((int(a), int(b)) for a, b in swap_pairs),
        target=target,
        symmetric=symmetric,
        conductance_from_force=conductance_from_force,
        conductance_reuse_refusal=conductance_reuse_refusal,
        uses_contact_radius=uses_contact_radius,
        example_params=dict(example_params or {}),
        planar=tuple(planar),
        only_2d=only_2d,
        range_parameter=range_parameter,
        requires_of=requires_of,
    )
    if range_parameter is not None and range_parameter not in params.model_fields:
        raise ValueError(f"{family}.{name}: range_parameter {range_parameter!r} is no parameter")
    models[name] = spec
    return spec


def _ensure_loaded() -> None:
    # Importing the model packages runs their register() calls.
    from thermodem.models import mechanics, thermal  # noqa: F401


def get(family: str, name: str) -> ModelSpec:
    """Look up a model, raising a ``KeyError`` whose message suggests close names."""
    _ensure_loaded()
    if family not in _REGISTRY:
        raise KeyError(f"unknown model family {family!r}; families are {', '.join(FAMILIES)}")
    models = _REGISTRY[family]
    if not isinstance(name, str):  # null (None) is no name: never the default model
        raise KeyError(
            f"{family} model: {'null' if name is None else repr(name)} is not a model name; "
            f"allowed: {', '.join(sorted(models))}"
        )
    if name not in models:
        raise KeyError(unknown_name_message(family, name))
    return models[name]


def names(family: str) -> list[str]:
    """Registered model names of a family, sorted."""
    _ensure_loaded()
    return sorted(_REGISTRY[family])


def all_models() -> list[ModelSpec]:
    """Every registered model, by family then name."""
    _ensure_loaded()
    return [_REGISTRY[f][n] for f in FAMILIES for n in sorted(_REGISTRY[f])]


def unknown_name_message(family: str, name: str) -> str:
    """'unknown ... model 'x'; did you mean 'y'? allowed: ...' for error messages."""
    _ensure_loaded()
    from thermodem.config.messages import suggest  # (capitals first: 'EPSD' -> 'epsd')

    choices = sorted(_REGISTRY[family])
    close = suggest(name, choices)
    hint = f"; did you mean {close!r}?" if close else ""
    return f"unknown {family} model {name!r}{hint} allowed: {', '.join(choices)}"


def packed(columns: tuple[str, ...], values: dict[str, float]) -> np.ndarray:
    """The float64 row of a model with named ``columns`` from ``{column name: value}``.

    Every column must be given, and nothing else: a misspelt or missing name is an error here,
    not a silent zero in a kernel.
    """
    missing = [c for c in columns if c not in values]
    unknown = [k for k in values if k not in columns]
    if missing or unknown:
        raise ValueError(f"row of columns {columns}: missing {missing}, unknown {unknown}")
    row = np.array([float(values[c]) for c in columns], dtype=np.float64)
    return row if row.size else np.zeros(1)
