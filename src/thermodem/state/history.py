"""Columns of the per-contact history, allocated from the registry.

Every listed pair (particle-particle and particle-wall) has one float64 history row. Its
columns are laid out once per simulation by :func:`layout_for` from what the selected models
register (``ModelSpec.history_width``) and what the thermal settings add, and the kernels get
the first column of each block as an offset (a compile-time constant in the fused contact pass
compiled per combination, ``kernels/pair_pass.py``; an argument everywhere else). No kernel
infers a layout from the width of the array.

Blocks, in this order (a block of width 0 is absent and its offset is -1):

====================  =====  ==========================================================
block                 width  content
====================  =====  ==========================================================
contact               2      0: time in contact [s] (0 while not touching), 1: normal
                             approach speed at the first touching pass [m/s]; in every
                             layout (the contact's own columns, read by the thermal models)
tangential            w + 1  the tangential law's history (the spring displacement s,
                             3 columns) and the elastic energy ½ k_t |s|² of the last step
                             (the stiffness-work ledger); only if the law registers w > 0
rolling               w + 1  the rolling law's history (the elastic rolling torque M^k, 3
                             columns) and its energy |M^k|²/(2 k_r); only if w > 0
normal                w      the normal law's history (the largest overlap of an
                             elasto-plastic law, 1 column); only if w > 0
reuse                 3      conductance reuse (``thermal.conductance_force_tolerance``):
                             reference normal force, conductance, secant slope
collision             1      kinetic energy of the pair at the first touching pass (heat
                             generation by the collision kinetic energy, Al-Arkawazi 2017)
====================  =====  ==========================================================

The layout is saved in checkpoints and compared when a run restarts.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The contact's own columns, first in every layout.
DURATION = 0
IMPACT_VELOCITY = 1
CONTACT_WIDTH = 2

#: Positions in :attr:`HistoryLayout.offsets`.
NORMAL, SPRING, ROLL, COLLISION, REUSE = range(5)

#: Width of the conductance reuse block.
REUSE_WIDTH = 3
#: Width of the collision block.
COLLISION_WIDTH = 1


@dataclass(frozen=True)
class HistoryLayout:
    """Column offsets of one simulation's contact history (-1: the block is absent)."""

    normal: int = -1
    spring: int = -1
    spring_energy: int = -1
    roll: int = -1
    roll_energy: int = -1
    reuse: int = -1
    collision: int = -1
    width: int = CONTACT_WIDTH
    blocks: tuple[tuple[str, int, int], ...] = (("contact", 0, CONTACT_WIDTH),)

    @property
    def offsets(self) -> tuple[int, int, int, int, int]:
        """(normal, spring, roll, collision, reuse): the offsets the kernels take (the energy
        columns follow the spring and the rolling torque); see :data:`NORMAL` etc."""
        return (self.normal, self.spring, self.roll, self.collision, self.reuse)

    def describe(self) -> list[list]:
        """[[block, first column, width], ...] (checkpoints, messages)."""
        return [[name, start, width] for name, start, width in self.blocks]


def layout_for(
    normal_width: int,
    tangential_width: int,
    rolling_width: int,
    reuse: bool = False,
    collision: bool = False,
) -> HistoryLayout:
    """The layout for the registered history widths of the selected normal, tangential and
    rolling laws, with the conductance reuse and the collision block when asked for.

    The tangential and rolling laws keep a 3-vector (spring displacement, elastic torque), or
    nothing; the normal law one value (the largest overlap), or nothing.
    """
    if tangential_width not in (0, 3) or rolling_width not in (0, 3):
        raise ValueError(
            f"tangential and rolling laws keep a 3-vector or nothing; got widths "
            f"{tangential_width} and {rolling_width}"
        )
    if normal_width not in (0, 1):
        raise ValueError(f"a normal law keeps one history value or none; got {normal_width}")
    blocks: list[tuple[str, int, int]] = [("contact", 0, CONTACT_WIDTH)]
    offsets: dict[str, int] = {}
    column = CONTACT_WIDTH

    def add(name: str, width: int) -> int:
        nonlocal column
        if width == 0:
            return -1
        start = column
        blocks.append((name, start, width))
        column += width
        return start

    spring = add("tangential", tangential_width + 1 if tangential_width else 0)
    offsets["spring"] = spring
    offsets["spring_energy"] = spring + tangential_width if spring >= 0 else -1
    roll = add("rolling", rolling_width + 1 if rolling_width else 0)
    offsets["roll"] = roll
    offsets["roll_energy"] = roll + rolling_width if roll >= 0 else -1
    offsets["normal"] = add("normal", normal_width)
    offsets["reuse"] = add("reuse", REUSE_WIDTH if reuse else 0)
    offsets["collision"] = add("collision", COLLISION_WIDTH if collision else 0)
    return HistoryLayout(width=column, blocks=tuple(blocks), **offsets)
