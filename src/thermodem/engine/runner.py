"""Running a case end to end: checks, the time loop, VTU/PVD output, log lines.

Output directory layout::

    OUT/particles.pvd, OUT/walls.pvd      time indices ParaView opens
    OUT/vtk/particles_NNNNNN.vtu          one frame per output interval (and the last step)
    OUT/vtk/walls_NNNNNN.vtu
    OUT/case.resolved.yaml                the case with every default filled in
"""

from __future__ import annotations

import sys
import time as wallclock
from pathlib import Path
from typing import TextIO

import numpy as np
import yaml

from thermodem.config.schema import Case
from thermodem.engine.checks import check_simulation_time_step
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.geometry import wall_layout as WL
from thermodem.io.vtk import PVDWriter, write_particles_vtu, write_walls_vtu
from thermodem.state.particles import HEAT_MECHANISMS


def prepare_output_dir(path: Path, overwrite: bool) -> None:
    """Refuse an existing non-empty directory unless ``overwrite`` (never silently)."""
    if path.exists() and not path.is_dir():
        raise ConfigError(f"--output {str(path)!r} exists and is not a directory")
    if path.exists() and any(path.iterdir()) and not overwrite:
        raise ConfigError(
            f"--output {str(path)!r} exists and is not empty; choose another "
            "directory or pass --overwrite"
        )
    path.mkdir(parents=True, exist_ok=True)


def resolved_case_yaml(case: Case) -> str:
    """The case with every default filled in, as YAML."""
    data = case.model_dump(mode="json")
    for family in ("normal", "tangential", "rolling"):
        choice = getattr(case.contact, family)
        data["contact"][family] = {"model": choice.model, **choice.params.model_dump(mode="json")}
    return yaml.safe_dump(data, sort_keys=False)


class FrameWriter:
    """Writes particle and wall frames and keeps the PVD indices valid after every frame."""

    def __init__(self, out: Path, wall_extent: float) -> None:
        self.out = out
        (out / "vtk").mkdir(parents=True, exist_ok=True)
        self.particles_pvd = PVDWriter(out / "particles.pvd")
        self.walls_pvd = PVDWriter(out / "walls.pvd")
        self.wall_extent = wall_extent
        self.frames = 0

    def write(self, sim: Simulation) -> None:
        p = sim.particles
        name = f"particles_{sim.step_count:09d}.vtu"
        fields = {
            "global_id": p.global_id,
            "type_id": p.type_id,
            "radius": p.radius,
            "mass": p.mass,
            "velocity": p.velocity,
            "angular_velocity": p.angular_velocity,
            "force": p.force,
            "torque": p.torque,
            "temperature": p.temperature,
            "heat_rate": p.heat_rate,
            **{
                f"heat_rate_{name}": p.heat_rate_by_mechanism[:, k]
                for k, name in enumerate(HEAT_MECHANISMS)
            },
            "coordination_number": sim.coordination_number().astype(np.int32),
        }
        write_particles_vtu(self.out / "vtk" / name, p.position, fields)
        self.particles_pvd.add(sim.time, f"vtk/{name}")
        if sim.wall_rows.shape[0]:
            wname = f"walls_{sim.step_count:09d}.vtu"
            wall_fields = {"temperature": sim.wall_rows[:, WL.COL_TEMPERATURE].copy()}
            write_walls_vtu(
                self.out / "vtk" / wname,
                sim.wall_kind,
                sim.wall_rows,
                wall_fields,
                self.wall_extent,
            )
            self.walls_pvd.add(sim.time, f"vtk/{wname}")
        self.frames += 1


def run_case(
    case: Case,
    output: Path,
    threads: int | None = None,
    overwrite: bool = False,
    log: TextIO = sys.stdout,
) -> Simulation:
    """Validate, build, run to ``simulation.end_time`` and write the output directory."""
    output = Path(output)
    prepare_output_dir(output, overwrite)
    (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
    sim = Simulation(case, threads=threads)
    for warning in check_simulation_time_step(sim):
        print(f"warning: {warning}", file=log)
    settings = case.simulation
    interval = case.output.interval or settings.end_time / 20.0
    every = max(1, int(round(interval / sim.dt)))
    total = int(round(settings.end_time / sim.dt))
    extent = case.output.wall_extent or 0.5 * float(
        np.max(np.subtract(case.domain.upper, case.domain.lower))
    )
    writer = FrameWriter(output, extent) if case.output.vtu else None
    if writer:
        writer.write(sim)
    start = wallclock.perf_counter()
    last_log = start
    particle_steps = 0
    while sim.step_count < total:
        sim.step()
        particle_steps += sim.particles.count
        if writer and sim.step_count % every == 0:
            writer.write(sim)
        now = wallclock.perf_counter()
        if now - last_log > 5.0 or sim.step_count == total:
            rate = particle_steps / max(now - start, 1e-9)
            print(
                f"t = {sim.time:.5g} s ({100 * sim.step_count / total:.0f} %), step "
                f"{sim.step_count}, {sim.particles.count} particles, {sim.contact_count} "
                f"contacts, {rate:.3g} particle-steps/s",
                file=log,
            )
            last_log = now
    if writer and sim.step_count % every != 0:
        writer.write(sim)
    return sim
