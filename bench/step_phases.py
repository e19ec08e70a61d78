"""Per-phase timing of ``Simulation.step`` (a profiling aid for the benchmarks).

:func:`instrument` wraps the kernels and methods one step calls (drift, force reset, pair and
wall passes, final kick, ledger sums, neighbour rebuild, and the thermal engine's prepare,
conditions, heat passes, other terms and Euler update) with timers, in place, for the life
of the process. Each phase accumulates wall seconds and this process's CPU seconds (on a
machine shared with other work the CPU seconds of a 1-thread run are the steadier figure).
Nested phases are counted in their own line and in the enclosing one (e.g. ``thermal.
conditions`` inside ``thermal.prepare``).

    from step_phases import instrument, report
    instrument()
    sim.run(steps=500)
    print(report(steps=500, particles=sim.particles.count))
"""

from __future__ import annotations

import functools
import time
from collections import defaultdict
from typing import Any

WALL: dict[str, float] = defaultdict(float)
CPU: dict[str, float] = defaultdict(float)
CALLS: dict[str, int] = defaultdict(int)


def _timed(name: str, fn: Any) -> Any:
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        w0, c0 = time.perf_counter(), time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            WALL[name] += time.perf_counter() - w0
            CPU[name] += time.process_time() - c0
            CALLS[name] += 1

    wrapper.__wrapped_phase__ = True  # type: ignore[attr-defined]
    return wrapper


def _wrap(owner: Any, attr: str, name: str) -> None:
    fn = getattr(owner, attr)
    if getattr(fn, "__wrapped_phase__", False):
        return
    setattr(owner, attr, _timed(name, fn))


def instrument() -> None:
    """Wrap the phases of a step (idempotent)."""
    from thermodem.engine import simulation as S
    from thermodem.engine import simulation_ledger as SL
    from thermodem.engine import thermal as T
    from thermodem.engine import thermal_conditions as TC
    from thermodem.kernels import pair_pass as PP

    for attr, name in (
        ("kick_drift", "drift"),
        ("reduce_checks", "checks"),
        ("reset_forces", "force reset"),
        ("final_kick", "final kick"),
    ):
        _wrap(S, attr, name)
    _wrap(SL, "ledger_totals", "ledger sums")
    _wrap(S.Simulation, "rebuild", "neighbour rebuild")
    _wrap(S.Simulation, "step", "step (total)")

    original = PP.passes_for
    if not getattr(original, "__wrapped_phase__", False):

        @functools.wraps(original)
        def passes_for(heat: bool, *ids: Any) -> tuple[Any, Any]:
            pair, wall = original(heat, *ids)
            tag = "heat" if heat else "mech"
            return _timed(f"pair pass ({tag})", pair), _timed(f"wall pass ({tag})", wall)

        passes_for.__wrapped_phase__ = True  # type: ignore[attr-defined]
        S.PP.passes_for = passes_for
    for attr in ("prepare", "after_contact_pass", "step", "conduction_passes",
                 "evaluate_terms", "finish", "_fixed_and_sources"):  # fmt: skip
        _wrap(T.ThermalEngine, attr, f"thermal.{attr.lstrip('_')}")
    _wrap(T.kernels, "euler_step", "thermal.euler kernel")
    _wrap(TC.ThermalConditions, "apply", "thermal.conditions kernel")


def reset() -> None:
    WALL.clear()
    CPU.clear()
    CALLS.clear()


def report(steps: int, particles: int) -> str:
    """One line per phase: ms per step and ns per particle-step, wall and CPU."""
    total = WALL.get("step (total)", 0.0) or 1e-30
    lines = [f"{'phase':28s} {'calls':>6s} {'wall ms/step':>12s} {'ns/p-step':>10s} "
             f"{'cpu ms/step':>11s} {'share':>6s}"]  # fmt: skip
    for name in sorted(WALL, key=lambda k: -WALL[k]):
        w, c = WALL[name], CPU[name]
        lines.append(
            f"{name:28s} {CALLS[name]:6d} {1e3 * w / steps:12.3f} "
            f"{1e9 * w / (steps * particles):10.1f} {1e3 * c / steps:11.3f} {w / total:6.1%}"
        )
    return "\n".join(lines)
