"""Heat generation mechanisms that the material values switch off: a pair coefficient at the
value where the contact law dissipates nothing that way, for every pair of materials that can
meet (``engine/case_warnings.py: generation_mechanism_warnings`` tells it).

The contact laws read the pair's coefficients (``state/materials.py: resolve_pair``, the mean
of the two materials or an ``interactions`` entry): sliding friction 0 caps the tangential
force at μ F_n = 0 (no friction work, no tangential dashpot force); rolling friction 0 gives
no rolling torque (``constant_torque``) and no rolling spring or dashpot (``epsd``: k_r ∝ μ_r²);
restitution 1 is a normal dashpot of zero damping (``hertz``, ``linear``, ``hertz_2d``), hence
a zero tangential dashpot (γ_t ∝ γ_n), and no plastic work of ``walton_braun`` (k2 = k1 / e²).
"""

from __future__ import annotations

from itertools import combinations_with_replacement
from typing import TYPE_CHECKING

from thermodem.state.materials import resolve_pair

if TYPE_CHECKING:
    from thermodem.config.schema import Case

#: mechanism -> the (pair coefficient, value) that each switch it off
SWITCHES: dict[str, tuple[tuple[str, float], ...]] = {
    "sliding_friction": (("sliding_friction", 0.0),),
    "rolling_friction": (("rolling_friction", 0.0),),
    "normal_damping": (("restitution", 1.0),),
    "tangential_damping": (("sliding_friction", 0.0), ("restitution", 1.0)),
    "plastic_deformation": (("restitution", 1.0),),
}
#: what a switch does, for the message
EFFECT = {
    "sliding_friction": "sliding friction 0 (the Coulomb cap μ F_n holds no tangential force)",
    "rolling_friction": "rolling friction 0 (no rolling torque)",
    "restitution": "restitution 1 (perfectly elastic: no damping, no plastic work)",
}


def meeting_pairs(case: Case) -> list[tuple[str, str]]:
    """The pairs of materials that can meet: particles with particles, particles with walls."""
    particles = sorted({e.material for e in case.insertion})
    walls = sorted({w.material for w in case.walls})
    pairs = list(combinations_with_replacement(particles, 2))
    pairs += [(p, w) for p in particles for w in walls]
    return list(dict.fromkeys(tuple(sorted(pair)) for pair in pairs))


def _sources(case: Case, a: str, b: str, coefficient: str) -> list[str]:
    """The keys that give the pair (a, b) its ``coefficient``, with their values."""
    for k, entry in enumerate(case.interactions):
        value = getattr(entry, coefficient)
        if frozenset(entry.materials) == frozenset((a, b)) and value is not None:
            return [f"interactions.{k}.{coefficient} = {value:g}"]
    out = []
    for name in dict.fromkeys((a, b)):
        material = case.materials[name]
        default = "" if coefficient in material.model_fields_set else " (the default)"
        out.append(f"materials.{name}.{coefficient} = {getattr(material, coefficient):g}{default}")
    return out


def material_zero_reason(mechanism: str, case: Case) -> str | None:
    """Why no pair of materials that can meet dissipates by ``mechanism`` with its values
    (naming the keys and values), or None: some pair does, no pair meets, or the mechanism
    does not depend on them."""
    switches = SWITCHES.get(mechanism)
    pairs = meeting_pairs(case)
    if switches is None or not pairs:
        return None
    overrides = {frozenset(o.materials): o for o in case.interactions}
    used: list[str] = []
    keys: list[str] = []
    for a, b in pairs:
        pair = resolve_pair(case.materials[a], case.materials[b], overrides.get(frozenset((a, b))))
        off = [c for c, value in switches if getattr(pair, c) == value]
        if not off:
            return None
        used.append(off[0])
        keys += _sources(case, a, b, off[0])
    effects = " or ".join(EFFECT[c] for c in dict.fromkeys(used))
    return f"every pair of materials that can meet has {effects}: {', '.join(dict.fromkeys(keys))}"
