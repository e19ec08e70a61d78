"""Progress display of a run: a rich bar on a terminal, plain log lines otherwise."""

from __future__ import annotations

import math
import time as wallclock
from typing import Any

from thermodem.engine.simulation import Simulation
from thermodem.engine.validation import (
    format_duration,
)
from thermodem.io.run_files import RunLog


def _short(x: float) -> str:
    """3 significant digits with k / M / G: 3.21k, 205k, 1.1M."""
    for factor, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(x) >= factor:
            return f"{x / factor:.3g}{suffix}"
    return f"{x:.3g}"


class Progress:
    """A rich progress bar on a terminal; plain log lines every ``interval`` s otherwise.

    Both show simulated time and fraction done, steps/s, particle-steps/s, the ETA and the
    particle and contact counts; ``run.log`` always receives the plain lines.
    """

    def __init__(
        self, log: RunLog, sim: Simulation, total: int, interval: float, bar: bool | None
    ) -> None:
        self.log = log
        self.total = total
        self.end_time = sim.case.simulation.end_time
        self.start_step = sim.step_count
        self.interval = interval
        self.start = wallclock.perf_counter()
        self.last_line = self.start
        self.last_bar = 0.0
        self.particle_steps = 0.0
        self._bar = None
        self._task = None
        if bar is None:
            bar = log.console is not None and log.console.isatty()
        if bar and log.console is not None:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                TaskProgressColumn,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )
            from rich.progress import Progress as RichProgress

            self._bar = RichProgress(
                TextColumn("t {task.fields[t]}/{task.fields[end]} s"),
                BarColumn(bar_width=16),
                TaskProgressColumn(),
                TextColumn("{task.fields[rates]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                TextColumn("{task.fields[counts]}"),
                console=Console(file=log.console),
                transient=False,
            )
        self._sim: Simulation | None = None

    def __enter__(self) -> Progress:
        if self._bar is not None:
            self._bar.start()
            self._task = self._bar.add_task(
                "run",
                total=self.total,
                completed=self.start_step,
                t="0",
                end=f"{self.end_time:g}",
                rates="",
                counts="",
            )
        return self

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            if self._sim is not None:
                self._refresh(self._sim, wallclock.perf_counter())
            self._bar.stop()

    def _refresh(self, sim: Simulation, now: float) -> None:
        self.last_bar = now
        n = self._numbers(sim, now)
        self._bar.update(
            self._task,
            completed=sim.step_count,
            t=f"{sim.time:.4g}",
            rates=f"{_short(n['sps'])} steps/s {_short(n['psps'])} particle-steps/s",
            counts=f"{sim.global_count} particles {sim.global_contacts} contacts",
        )

    def _numbers(self, sim: Simulation, now: float) -> dict[str, Any]:
        elapsed = max(now - self.start, 1e-9)
        steps = sim.step_count - self.start_step
        sps = steps / elapsed
        remaining = (self.total - sim.step_count) / sps if sps > 0 else math.inf
        return {
            "sps": sps,
            "psps": self.particle_steps / elapsed,
            "eta": remaining,
            "fraction": sim.step_count / max(self.total, 1),
        }

    def line(self, sim: Simulation, now: float | None = None) -> str:
        n = self._numbers(sim, wallclock.perf_counter() if now is None else now)
        return (
            f"t = {sim.time:.6g} / {self.end_time:g} s ({100 * n['fraction']:.1f} %), step "
            f"{sim.step_count}/{self.total}, {n['sps']:.3g} steps/s, {n['psps']:.3g} "
            f"particle-steps/s, ETA {format_duration(n['eta'])}, {sim.global_count} "
            f"particles, {sim.global_contacts} contacts"
        )

    def update(self, sim: Simulation) -> None:
        self.particle_steps += sim.global_count
        now = wallclock.perf_counter()
        self._sim = sim
        if self._bar is not None and now - self.last_bar > 0.2:
            self._refresh(sim, now)
        if now - self.last_line >= self.interval:
            self.last_line = now
            if self._bar is None:
                self.log.info(self.line(sim, now))
            else:
                self.log.file_only(self.line(sim, now))


# -------------------------------------------------------------------------------- signals
