"""Details for failure messages: who overlaps most, and the likely cause with its numbers.

Called only when a run fails, so clarity matters more than speed here.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from thermodem.kernels import contact as C
from thermodem.kernels.neighbors import wall_distance
from thermodem.kernels.pair_pass import WALL_CHUNK

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation


def _time_step_numbers(sim: Simulation) -> tuple[bool, str]:
    """(time step beyond a refusal limit?, 'X × the Rayleigh time ...; a collision ...')."""
    dt = sim.dt
    try:
        t = sim.stable_time_steps()
    except Exception:  # noqa: BLE001 (a message helper must not fail the error path)
        return False, "not compared with the Rayleigh and collision times (see 'validate')"
    parts = []
    too_large = False
    if math.isfinite(t.get("rayleigh", math.inf)):
        frac = dt / t["rayleigh"]
        too_large |= frac > 1.0
        parts.append(f"{frac:.3g} × the Rayleigh time {t['rayleigh']:.4g} s")
    if math.isfinite(t.get("collision", math.inf)):
        steps = t["collision"] / dt
        too_large |= steps < 10.0
        parts.append(
            f"a collision at {t['impact_speed']:.3g} m/s lasts {t['collision']:.4g} s = "
            f"{steps:.3g} steps (at least 10 needed, 30 recommended)"
        )
    return too_large, "; ".join(parts) if parts else "no particles to compare with"


def time_step_cause(sim: Simulation) -> str:
    """Likely cause of non-finite values: the time step (with both numbers) or something else."""
    too_large, numbers = _time_step_numbers(sim)
    if too_large:
        return f"time step {sim.dt:.4g} s too large for the contact stiffness: it is {numbers}"
    return (
        f"not the time step alone ({sim.dt:.4g} s is {numbers}): look for particles inserted "
        "overlapping, unphysical velocities, or a contact stiffness too low for the loads"
    )


def overlap_cause(sim: Simulation) -> str:
    """Likely cause of an excessive overlap, with the time step numbers."""
    too_large, numbers = _time_step_numbers(sim)
    if too_large:
        return f"time step {sim.dt:.4g} s too large for the contact stiffness: it is {numbers}"
    if sim.step_count == 1:  # the first step from t = 0: the overlap was (nearly) there
        ratio = sim.max_overlap_ratio
        remedy = (
            f"move them apart, or raise simulation.max_overlap_ratio (at most 1) above "
            f"{ratio:.3g} to let the run push them apart"
            if ratio < 1.0
            else "move them apart (simulation.max_overlap_ratio allows at most 1)"
        )
        return (
            "particles inserted overlapping: at the first step the overlap is the one they "
            "started with (a particle file or list entry with overlap_check: false accepts "
            f"it); {remedy}; the time step {sim.dt:.4g} s is within the limits ({numbers})"
        )
    return (
        "contact stiffness (youngs_modulus) too low for the loads or impact speeds; the time "
        f"step {sim.dt:.4g} s is within the limits ({numbers})"
    )


def left_domain_cause(sim: Simulation, index: int) -> str:
    """Likely cause of a particle outside the domain, with its speed and step length."""
    p = sim.particles
    v = p.velocity[index]
    speed = float(np.sqrt(np.sum(v * v))) if np.all(np.isfinite(v)) else math.inf
    r = float(p.radius[index])
    step = speed * sim.dt
    if step > 0.5 * r:
        return (
            f"it moves |v| Δt = {step:.3g} m per step at {speed:.3g} m/s, more than half its "
            f"radius {r:.3g} m, so it can pass through a wall in one step: a time step "
            f"{sim.dt:.4g} s too large for this speed, or an unphysical velocity (an "
            f"explosion from a large overlap, an insertion velocity)"
        )
    return (
        f"it moved {step:.3g} m in the last step at {speed:.3g} m/s (radius {r:.3g} m): "
        "there is no wall where it left, or the domain is smaller than the container"
    )


def worst_overlap(sim: Simulation) -> tuple[float, int, int, str]:
    """(ratio, global id i, global id j or -1, 'particle' | 'wall LABEL') of the deepest overlap.

    Recomputed from the current positions in the slab group (particle pairs) and the particle
    chunk (wall pairs) that reported the maximum.
    """
    p = sim.particles
    best = (0.0, -1, -1, "")
    pb, wb = sim.pairs, sim.walls
    npc = pb.ngroups if pb.count else 0
    if npc:
        c = int(np.argmax(pb.chunk_ledger[:npc, C.L_MAX_OVERLAP_RATIO]))
        lo, hi = int(pb.group_start[c]), int(pb.group_start[c + 1])
        i, j = pb.i[lo:hi], pb.j[lo:hi]
        d = p.position[j] - p.position[i]
        length = sim.upper - sim.lower
        for a in range(3):
            if sim.periodic[a]:
                d[:, a] -= length[a] * np.round(d[:, a] / length[a])
        dist = np.sqrt((d * d).sum(axis=1))
        ri, rj = p.radius[i], p.radius[j]
        ratio = (ri + rj - dist) / np.minimum(ri, rj)
        if ratio.size:
            k = int(np.nanargmax(ratio))
            best = (
                float(ratio[k]),
                int(p.global_id[i[k]]),
                int(p.global_id[j[k]]),
                "particle",
            )
    n = p.count
    nwc = (n + WALL_CHUNK - 1) // WALL_CHUNK if wb.count else 0
    if nwc:
        c = int(np.argmax(wb.chunk_ledger[:nwc, C.L_MAX_OVERLAP_RATIO]))
        rs = sim.wall_row_start
        for k in range(int(rs[c * WALL_CHUNK]), int(rs[min(n, (c + 1) * WALL_CHUNK)])):
            i, w = int(wb.i[k]), int(wb.j[k])
            dist = wall_distance(sim.wall_kind[w], sim.wall_rows[w], p.position[i])[0]
            ratio = (p.radius[i] - dist) / p.radius[i]
            if ratio > best[0]:
                best = (float(ratio), int(p.global_id[i]), -1, f"wall {sim.wall_labels[w]}")
    return best
