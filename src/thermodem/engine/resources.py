"""Resources a run needs, estimated before it starts: memory (refused above the machine's
physical memory) and run time (engine/validation.py's layer 3; the constants are measured on
the 2-core VM, see below).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

#: The run time estimate: a fixed cost per step (Python orchestration and kernel launches,
#: independent of the particle count) plus a cost per particle-step, each for mechanics and
#: for heat, on 1 thread; 2 or more threads divide the per-particle part by THREAD_SPEED_UP
#: and add THREAD_STEP_SECONDS per step (waking the threads). Measured on the 2-core VM
#: (2026-12-02; tools/measure_threads.py, jammed beds of 8 to 16,000 spheres, Hertz-Mindlin,
#: and whole runs of the examples): 1 thread, 0.04-0.05 ms per step below 125 spheres,
#: 0.19-0.22 µs per particle-step; heat (batchelor_obrien_simple every step) +0.015 ms per
#: step, +0.03 µs per particle-step; the 50,000-sphere bench bed: 6 M particle-steps/s on 1
#: thread, 11 M on 2 (docs/STATUS.md). Estimated / measured: default example 9 s / 11 s,
#: heated_bed 13 s / 10 s, two spheres with heat (100,000 steps) 6 s / 6 s. A machine shared
#: with other processes is slower: the progress lines' ETA then tells the truth.
STEP_SECONDS = 4.5e-5
PARTICLE_STEP_SECONDS = 2.0e-7
HEAT_STEP_SECONDS = 1.5e-5
HEAT_PARTICLE_STEP_SECONDS = 3.0e-8
#: Per-particle-step heat cost of the direct conduction models that cost more than the
#: default's (bench/bench_packed_bed.py --heat: resistance_network +130 % over mechanics).
HEAT_PARTICLE_STEP_SECONDS_BY_MODEL = {"resistance_network": 2.2e-7}
THREAD_SPEED_UP = 1.8
THREAD_STEP_SECONDS = 2.0e-5
#: Writing outputs: a time-series row; a frame or checkpoint file, and per particle in it [s]
#: (VTU of 200,000 particles: 0.11-0.15 s, io/vtk.py).
ROW_SECONDS = 2.0e-4
FILE_SECONDS = 3.0e-3
FILE_SECONDS_PER_PARTICLE = 1.0e-6
#: Memory model: bytes per particle (state arrays, neighbour index, copies while sorting) and
#: per listed pair (indices, history, normal force, state, and a rebuild's new
#: indices; ×1.25 growth margin), and pairs per particle in a dense bed (3.6 measured in the
#: benchmark bed, plus near pairs). Measured: ~560 B per particle in that bed.
BYTES_PER_PARTICLE = 400.0
PAIRS_PER_PARTICLE = 4.5
BASELINE_BYTES = 250e6


def physical_memory() -> tuple[float, float]:
    """(total, available) physical memory [bytes]; NaN where unknown."""
    total = avail = math.nan
    try:
        text = Path("/proc/meminfo").read_text()
        values = {line.split(":")[0]: float(line.split()[1]) * 1024.0 for line in text.splitlines()}
        total = values.get("MemTotal", math.nan)
        avail = values.get("MemAvailable", math.nan)
    except (OSError, ValueError, IndexError):
        try:
            total = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
        except (ValueError, OSError, AttributeError):
            pass
    return total, avail


def poured_particles(entry: Any, start: float, end: float) -> tuple[float, float]:
    """(particles a pour entry adds between ``start`` and ``end``, their particle-seconds
    until ``end``)."""
    t0 = max(float(entry.start_time), start)
    t1 = min(float(entry.end_time) if entry.end_time is not None else end, end)
    if t1 <= t0:
        return 0.0, 0.0
    count = entry.rate * (t1 - t0)
    return count, entry.rate * (0.5 * (t1 - t0) ** 2 + (t1 - t0) * (end - t1))


@dataclass
class ResourceEstimate:
    particles_now: int
    particles_final: int
    steps: int
    particle_steps: float
    memory_bytes: float
    run_seconds: float
    threads: int
    memory_total: float
    memory_available: float
    step_seconds: float = 0.0  # the fixed part of run_seconds

    def lines(self) -> list[str]:
        def gb(x: float) -> str:
            return "unknown" if not math.isfinite(x) else f"{x / 1e9:.3g} GB"

        return [
            f"particles: {self.particles_now} now, about {self.particles_final} at the end",
            f"steps: {self.steps} ({self.particle_steps:.3g} particle-steps)",
            f"estimated memory: {gb(self.memory_bytes)} (physical memory {gb(self.memory_total)}, "
            f"available {gb(self.memory_available)})",
            f"estimated run time: {format_duration(self.run_seconds)} on {self.threads} "
            f"thread(s) ({format_duration(self.step_seconds)} of it a fixed cost per step, "
            f"the rest per particle; measured on a 2-core VM, a busy machine is slower)",
        ]


def format_duration(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "unknown"
    seconds = int(round(seconds))
    h, rem = divmod(seconds, 3600)
    m, s = divmod(rem, 60)
    if h:
        return f"{h} h {m:02d} min"
    if m:
        return f"{m} min {s:02d} s"
    return f"{s} s"


def total_steps(sim: Simulation, end_time: float | None = None) -> int:
    """Steps from t = 0 to end_time (thermal steps with frozen mechanics)."""
    end = sim.case.simulation.end_time if end_time is None else end_time
    dt = sim.dt
    th = sim.thermal
    if th is not None and th.settings.frozen_mechanics:
        dt = th.settings.time_step
    return int(round(end / dt))


def estimate_resources(sim: Simulation, threads: int | None = None) -> ResourceEstimate:
    """Rough memory and run time of running ``sim`` from its current step to end_time."""
    import numba

    threads = int(threads or getattr(sim, "threads", 0) or numba.get_num_threads())
    end = sim.case.simulation.end_time
    steps = max(0, total_steps(sim) - sim.step_count)
    dt_run = end / max(total_steps(sim), 1)
    n_now = sim.particles.count
    final = float(n_now)
    particle_seconds = n_now * max(0.0, end - sim.time)
    for pourer in sim.pourers:
        count, seconds = poured_particles(pourer.entry, sim.time, end)
        final += count
        particle_seconds += seconds
    particle_steps = particle_seconds / dt_run
    per_particle = bytes_per_particle(sim.pairs.history_width, sim.thermal is not None)
    memory = BASELINE_BYTES + final * per_particle
    fixed, variable = run_time(sim, steps, particle_steps, threads)
    total, avail = physical_memory()
    return ResourceEstimate(
        particles_now=n_now,
        particles_final=int(round(final)),
        steps=steps,
        particle_steps=particle_steps,
        memory_bytes=memory,
        run_seconds=fixed + variable,
        threads=threads,
        memory_total=total,
        memory_available=avail,
        step_seconds=fixed,
    )


def run_time(
    sim: Simulation, steps: int, particle_steps: float, threads: int
) -> tuple[float, float]:
    """(fixed seconds, per-particle seconds) of ``steps`` steps and ``particle_steps``
    particle-steps of ``sim`` on ``threads`` threads (the constants above), outputs included."""
    th = sim.thermal
    per_step, per_particle = STEP_SECONDS, PARTICLE_STEP_SECONDS
    if th is not None:
        model = th.settings.direct_conduction.model
        heat = HEAT_PARTICLE_STEP_SECONDS_BY_MODEL.get(model, HEAT_PARTICLE_STEP_SECONDS)
        if th.settings.frozen_mechanics:  # thermal steps only
            per_step, per_particle = HEAT_STEP_SECONDS, heat
        else:
            every = max(1, int(th.substeps))
            per_step += HEAT_STEP_SECONDS / every
            per_particle += heat / every
    if threads > 1:
        per_step += THREAD_STEP_SECONDS
        per_particle /= THREAD_SPEED_UP
    out = sim.case.output
    end = sim.case.simulation.end_time

    def count(interval: float | None, default: int) -> int:  # default: end_time / default
        return min(default if interval is None else int(end / interval), steps) + 1

    rows = count(out.timeseries_interval, 1000)
    files = count(out.checkpoint_interval, 10) + (count(out.interval, 20) if out.vtu else 0)
    n = sim.particles.count + sum(poured_particles(p.entry, sim.time, end)[0] for p in sim.pourers)
    writing = rows * ROW_SECONDS + files * (FILE_SECONDS + n * FILE_SECONDS_PER_PARTICLE)
    return steps * per_step + writing, particle_steps * per_particle


def bytes_per_particle(history_width: int = 6, thermal: bool = False) -> float:
    """Estimated memory per particle [B]: its arrays plus its share of the pair lists."""
    pair_bytes = 1.25 * (8 + 8 * history_width + 8 + 1 + 9)
    if thermal:
        pair_bytes += 16  # conductance and heat rate (heat-only passes)
    return BYTES_PER_PARTICLE + PAIRS_PER_PARTICLE * pair_bytes


def insertion_counts(case: Case) -> list[tuple[str, float, str]]:
    """(key path, about how many particles, how the number comes about) of every insertion
    entry, computed from the case alone (nothing is allocated; particle files: their data
    lines are not counted, 0)."""
    from thermodem.geometry.distributions import mean_sphere_volume
    from thermodem.geometry.insertion import lattice_axis_counts

    out: list[tuple[str, float, str]] = []
    end = case.simulation.end_time
    planar = case.simulation.planar
    for k, entry in enumerate(case.insertion):
        key = f"insertion.{k}"
        if entry.kind == "lattice":
            nx, ny, nz = lattice_axis_counts(entry, planar)
            out.append((key, float(nx) * ny * nz, f"a lattice of {nx} × {ny} × {nz} sites"))
        elif entry.kind in ("random_box", "random_cylinder"):
            if entry.count is not None:
                out.append((key, float(entry.count), f"count {entry.count}"))
            else:
                extent = np.subtract(entry.upper, entry.lower)
                volume = entry.volume_fraction * float(np.prod(extent[:2] if planar else extent))
                n = volume / mean_sphere_volume(entry.distribution, planar=planar)
                out.append((key, n, f"volume_fraction {entry.volume_fraction}"))
        elif entry.kind == "pour":
            n, _ = poured_particles(entry, 0.0, end)
            out.append((key, n, f"rate {entry.rate:g}/s until t = {end:g} s"))
        elif entry.kind == "list":
            out.append((key, float(len(entry.positions)), "positions"))
        else:
            out.append((key, 0.0, "a particle file"))
    return out


def check_insertion_memory(case: Case) -> None:
    """Refuse, before anything is allocated, a case whose insertion entries would need more
    memory than the machine has (a lattice of 1e9 sites, a count of 1e9): ConfigError naming
    the largest entry."""
    counts = insertion_counts(case)
    if not counts:
        return
    total_count = sum(n for _, n, _ in counts)
    from thermodem.engine.simulation import history_layout_of

    width = history_layout_of(case).width
    memory = BASELINE_BYTES + total_count * bytes_per_particle(width, case.thermal is not None)
    total, _ = physical_memory()
    if math.isfinite(total) and memory > total:
        key, n, how = max(counts, key=lambda c: c[1])
        raise ConfigError(
            f"{key}: {how} gives about {n:.3g} particles; the estimated memory "
            f"{memory / 1e9:.3g} GB for about {total_count:.3g} particles exceeds the physical "
            f"memory {total / 1e9:.3g} GB of this machine (refused before allocating); use "
            "fewer particles (a larger spacing, a smaller count or region)"
        )


def check_resources(estimate: ResourceEstimate) -> list[str]:
    """Warnings; ConfigError when the estimated memory exceeds the physical memory."""
    mem, total, avail = estimate.memory_bytes, estimate.memory_total, estimate.memory_available
    if math.isfinite(total) and mem > total:
        raise ConfigError(
            f"estimated memory {mem / 1e9:.3g} GB for about {estimate.particles_final} "
            f"particles exceeds the physical memory {total / 1e9:.3g} GB of this machine"
        )
    warnings = []
    if math.isfinite(avail) and mem > 0.8 * avail:
        warnings.append(
            f"estimated memory {mem / 1e9:.3g} GB is more than 80 % of the available "
            f"{avail / 1e9:.3g} GB"
        )
    return warnings


# ------------------------------------------------------------------ the built simulation
