"""Running a case end to end: checks, the time loop, outputs, progress, failures, restart.

Output directory layout::

    OUT/case.resolved.yaml                the case with every default filled in
    OUT/run.log                           everything the run printed (appended on restart)
    OUT/status.json                       running | finished | failed | interrupted, step, time
    OUT/timeseries.csv                    one row per output.timeseries_interval
    OUT/particles.pvd, OUT/walls.pvd      time indices ParaView opens
    OUT/vtk/particles_NNNNNNNNN.vtu       one frame per output.interval (and the last step)
    OUT/vtk/walls_NNNNNNNNN.vtu
    OUT/checkpoints/checkpoint_NNNNNNNNN.h5   at step 0, every output.checkpoint_interval, at
                                          the end and on an interrupt (newest
                                          output.checkpoint_keep kept, the final one always)
    OUT/failed.h5                         the state when a SimulationError was raised

Three entry points: :func:`run_case` (a fresh run), :func:`restart_run` (continue the run in
an output directory from its newest checkpoint, appending to its outputs) and
:func:`run_from_checkpoint` (a new output directory starting from any checkpoint, with the
stored or a changed case). All three go through one loop, :func:`_drive`.

Failures: a :class:`SimulationError` from the engine writes ``failed.h5`` (the state at the
failure, for inspection) and is raised again with the last good checkpoint named in the
message. SIGINT (Ctrl-C) and SIGTERM finish the current step, write a checkpoint and raise
:class:`~thermodem.errors.RunInterrupted`; a second signal aborts at once without writing.
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
import json
import math
import os
import signal
import socket
import sys
import threading
import time as wallclock
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from thermodem.config.dump import resolved_case_yaml
from thermodem.config.schema import Case
from thermodem.engine.checks import check_simulation_time_step
from thermodem.engine.simulation import Simulation
from thermodem.engine.validation import (
    check_completeness,
    check_resources,
    estimate_resources,
    format_duration,
    total_steps,
)
from thermodem.errors import ConfigError, RunInterrupted, SimulationError
from thermodem.io.checkpoint import (
    checkpoint_name,
    list_checkpoints,
    read_checkpoint,
    write_checkpoint,
)
from thermodem.io.vtk import PVDWriter, write_particles_vtu, write_walls_vtu

__all__ = [
    "FrameWriter",
    "RunLog",
    "TimeseriesWriter",
    "prepare_output_dir",
    "resolved_case_yaml",
    "restart_run",
    "run_case",
    "run_from_checkpoint",
]

CHECKPOINT_DIR = "checkpoints"
STATUS_FILE = "status.json"
TIMESERIES_FILE = "timeseries.csv"
LOG_FILE = "run.log"
FAILED_FILE = "failed.h5"


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


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


# ------------------------------------------------------------------------------------ log
class RunLog:
    """Messages to the console and to ``run.log`` (``file_only`` lines go to the file only)."""

    def __init__(
        self, path: Path | None, console: TextIO | None = None, append: bool = False
    ) -> None:
        self.console = console
        self.file = open(path, "a" if append else "w", encoding="utf-8") if path else None  # noqa: SIM115

    def _stamp(self) -> str:
        return _dt.datetime.now().strftime("%Y-%m-%d %H:%M:%S")

    def info(self, message: str) -> None:
        if self.console is not None:
            print(message, file=self.console, flush=True)
        self.file_only(message)

    def warn(self, message: str) -> None:
        self.info(f"warning: {message}")

    def file_only(self, message: str) -> None:
        if self.file is not None:
            self.file.write(f"[{self._stamp()}] {message}\n")
            self.file.flush()

    def close(self) -> None:
        if self.file is not None:
            self.file.close()
            self.file = None


# --------------------------------------------------------------------------------- frames
class FrameWriter:
    """Writes particle and wall frames and keeps the PVD indices valid after every frame."""

    def __init__(self, out: Path, wall_extent: float, resume_time: float | None = None) -> None:
        self.out = out
        (out / "vtk").mkdir(parents=True, exist_ok=True)
        if resume_time is None:
            self.particles_pvd = PVDWriter(out / "particles.pvd")
            self.walls_pvd = PVDWriter(out / "walls.pvd")
        else:
            self.particles_pvd = PVDWriter.resume(out / "particles.pvd", resume_time)
            self.walls_pvd = PVDWriter.resume(out / "walls.pvd", resume_time)
        self.wall_extent = wall_extent
        self.frames = len(self.particles_pvd.entries)
        self.last_step = -1

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
            "coordination_number": sim.coordination_number().astype(np.int32),
        }
        if sim.thermal is not None:
            from thermodem.state.particles import HEAT_MECHANISMS

            for k, mech in enumerate(HEAT_MECHANISMS):
                col = p.heat_rate_by_mechanism[:, k]
                if np.any(col):
                    fields[f"heat_rate_{mech}"] = np.ascontiguousarray(col)
        write_particles_vtu(self.out / "vtk" / name, p.position, fields)
        self.particles_pvd.add(sim.time, f"vtk/{name}")
        if sim.wall_rows.shape[0]:
            wname = f"walls_{sim.step_count:09d}.vtu"
            write_walls_vtu(
                self.out / "vtk" / wname, sim.wall_kind, sim.wall_rows, None, self.wall_extent
            )
            self.walls_pvd.add(sim.time, f"vtk/{wname}")
        self.frames = len(self.particles_pvd.entries)
        self.last_step = sim.step_count


# ----------------------------------------------------------------------------- time series
def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool | np.bool_):
        return str(int(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


class TimeseriesWriter:
    """``timeseries.csv``: ``time``, ``step`` and every key of ``sim.report()`` as columns.

    Values are written exactly (``repr`` of the float). Columns come from what the engine
    reports: when a later row has a key the header does not have yet (a heat mechanism that
    became active), the file is rewritten with the new column, earlier rows left empty there.
    With ``resume_step`` the rows after that step are dropped first (a restart).
    """

    def __init__(self, path: Path, resume_step: int | None = None) -> None:
        self.path = path
        self.columns: list[str] = []
        self.rows = 0
        self.last_step = -1
        if resume_step is not None and path.exists():
            with path.open(newline="") as f:
                reader = csv.reader(f)
                header = next(reader, None)
                kept = [r for r in reader if r and int(r[1]) <= resume_step] if header else []
            self.columns = list(header or [])
            self._rewrite(kept)
            self.rows = len(kept)
            if kept:
                self.last_step = int(kept[-1][1])
        elif path.exists():
            path.unlink()

    def _rewrite(self, rows: list[list[str]]) -> None:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        if self.columns:
            writer.writerow(self.columns)
        for r in rows:
            writer.writerow(r + [""] * (len(self.columns) - len(r)))
        _atomic_write_text(self.path, buf.getvalue())

    def write(self, sim: Simulation) -> None:
        row: dict[str, Any] = {"time": sim.time, "step": sim.step_count}
        row.update(sim.report())
        new = [k for k in row if k not in self.columns]
        if new:
            old_rows: list[list[str]] = []
            if self.path.exists() and self.columns:
                with self.path.open(newline="") as f:
                    old_rows = list(csv.reader(f))[1:]
            self.columns += new
            self._rewrite(old_rows)
        with self.path.open("a", newline="") as f:
            csv.writer(f, lineterminator="\n").writerow([_cell(row.get(c)) for c in self.columns])
        self.rows += 1
        self.last_step = sim.step_count


def read_timeseries(path: Path) -> dict[str, np.ndarray]:
    """Columns of a ``timeseries.csv`` as float arrays (empty cells are NaN)."""
    with Path(path).open(newline="") as f:
        reader = csv.reader(f)
        header = next(reader, [])
        rows = [r for r in reader if r]
    out = {}
    for k, name in enumerate(header):
        out[name] = np.array([float(r[k]) if k < len(r) and r[k] != "" else math.nan for r in rows])
    return out


# --------------------------------------------------------------------------------- status
@dataclass
class Status:
    """``status.json``: what ``thermodem info`` reports about a running or finished run."""

    path: Path
    data: dict[str, Any] = field(default_factory=dict)

    def update(self, **values: Any) -> None:
        self.data.update(values)
        self.data["updated"] = _dt.datetime.now().isoformat(timespec="seconds")
        _atomic_write_text(self.path, json.dumps(self.data, indent=2) + "\n")

    @staticmethod
    def read(directory: Path) -> dict[str, Any]:
        path = Path(directory) / STATUS_FILE
        if not path.exists():
            return {}
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError):
            return {}


# ------------------------------------------------------------------------------- progress
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
            counts=f"{sim.particles.count} particles {sim.contact_count} contacts",
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
            f"particle-steps/s, ETA {format_duration(n['eta'])}, {sim.particles.count} "
            f"particles, {sim.contact_count} contacts"
        )

    def update(self, sim: Simulation) -> None:
        self.particle_steps += sim.particles.count
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
class _StopRequest:
    """SIGINT/SIGTERM handler: the first signal asks the loop to stop after the current step,
    a second one aborts at once (KeyboardInterrupt)."""

    def __init__(self, log: RunLog) -> None:
        self.log = log
        self.signum = 0
        self._old: dict[int, Any] = {}

    def _handler(self, signum: int, frame: object) -> None:
        if self.signum:
            raise KeyboardInterrupt
        self.signum = signum
        self.log.info(
            f"{signal.Signals(signum).name} received: finishing the step and writing a "
            "checkpoint (send it again to abort without one)"
        )

    def __enter__(self) -> _StopRequest:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)


# ---------------------------------------------------------------------------------- driver
@dataclass
class _Run:
    """Everything the loop needs besides the simulation."""

    output: Path
    log: RunLog
    status: Status
    frames: FrameWriter | None
    timeseries: TimeseriesWriter
    total: int
    frame_every: int
    series_every: int
    checkpoint_every: int
    checkpoint_keep: int | None
    progress_bar: bool | None
    log_interval: float
    callback: Callable[[Simulation], None] | None
    every: int
    case_yaml: str = ""
    last_checkpoint: Path | None = None


def _schedule(case: Case, sim: Simulation, interval: float | None, default_fraction: float) -> int:
    dt = case.simulation.end_time / max(total_steps(sim), 1)
    value = interval if interval is not None else case.simulation.end_time * default_fraction
    return max(1, int(round(value / dt)))


def _make_run(
    sim: Simulation,
    output: Path,
    log: RunLog,
    status: Status,
    resume: bool,
    progress: bool | None,
    log_interval: float,
    callback: Callable[[Simulation], None] | None,
    every: int,
) -> _Run:
    case = sim.case
    out = case.output
    extent = out.wall_extent or 0.5 * float(
        np.max(np.subtract(case.domain.upper, case.domain.lower))
    )
    frames = None
    if out.vtu:
        frames = FrameWriter(output, extent, resume_time=sim.time if resume else None)
    series = TimeseriesWriter(
        output / TIMESERIES_FILE, resume_step=sim.step_count if resume else None
    )
    return _Run(
        output=output,
        log=log,
        status=status,
        frames=frames,
        timeseries=series,
        total=total_steps(sim),
        frame_every=_schedule(case, sim, out.interval, 1.0 / 20.0),
        series_every=_schedule(case, sim, out.timeseries_interval, 1.0 / 1000.0),
        checkpoint_every=_schedule(case, sim, out.checkpoint_interval, 1.0 / 10.0),
        checkpoint_keep=out.checkpoint_keep,
        progress_bar=progress,
        log_interval=log_interval,
        callback=callback,
        every=max(1, int(every)),
        case_yaml=resolved_case_yaml(case),
    )


def _checkpoint(sim: Simulation, run: _Run, kind: str) -> Path:
    directory = run.output / CHECKPOINT_DIR
    path = write_checkpoint(
        sim, directory / checkpoint_name(sim.step_count), kind=kind, case_yaml=run.case_yaml
    )
    run.last_checkpoint = path
    if run.checkpoint_keep is not None:
        existing = list_checkpoints(directory)
        for old in existing[: max(0, len(existing) - run.checkpoint_keep)]:
            if old != path:
                old.unlink(missing_ok=True)
    return path


def _status_numbers(sim: Simulation, run: _Run) -> dict[str, Any]:
    return {
        "step": sim.step_count,
        "time": sim.time,
        "total_steps": run.total,
        "end_time": sim.case.simulation.end_time,
        "particles": sim.particles.count,
        "contacts": sim.contact_count,
        "frames": run.frames.frames if run.frames else 0,
        "last_checkpoint": str(run.last_checkpoint) if run.last_checkpoint else None,
    }


def _drive(sim: Simulation, run: _Run, fresh: bool) -> Simulation:
    """The time loop with outputs on their triggers; failures and interrupts handled here."""
    log = run.log
    if fresh:
        run.timeseries.write(sim)
        if run.frames:
            run.frames.write(sim)
        _checkpoint(sim, run, "checkpoint")
    run.status.update(status="running", pid=os.getpid(), message="", **_status_numbers(sim, run))
    in_step = False
    stop = None
    progress = Progress(log, sim, run.total, run.log_interval, run.progress_bar)
    started = wallclock.perf_counter()
    start_step = sim.step_count
    try:
        with _StopRequest(log) as stop, progress, warnings.catch_warnings():
            warnings.simplefilter("always", RuntimeWarning)
            warnings.showwarning = lambda msg, *a, **k: log.warn(str(msg))
            while sim.step_count < run.total:
                if stop.signum:
                    raise KeyboardInterrupt
                in_step = True
                sim.step()
                in_step = False
                k = sim.step_count
                if k % run.series_every == 0:
                    run.timeseries.write(sim)
                if run.frames and k % run.frame_every == 0:
                    run.frames.write(sim)
                if k % run.checkpoint_every == 0 and k < run.total:
                    _checkpoint(sim, run, "checkpoint")
                    run.status.update(**_status_numbers(sim, run))
                progress.update(sim)
                if run.callback is not None and k % run.every == 0:
                    run.callback(sim)
    except SimulationError as exc:
        raise _failed(sim, run, exc) from None
    except KeyboardInterrupt:
        raise _interrupted(sim, run, in_step, stop.signum if stop else 0) from None
    # the last step: a row, a frame and a checkpoint even off their schedules
    if run.timeseries.last_step != sim.step_count:
        run.timeseries.write(sim)
    if run.frames and run.frames.last_step != sim.step_count:
        run.frames.write(sim)
    final = _checkpoint(sim, run, "final")
    elapsed = wallclock.perf_counter() - started
    steps = sim.step_count - start_step
    log.info(progress.line(sim))
    run.status.update(
        status="finished",
        message=f"finished in {format_duration(elapsed)}",
        wallclock_seconds=elapsed,
        **_status_numbers(sim, run),
    )
    log.info(
        f"done: {steps} steps in {format_duration(elapsed)}, {sim.particles.count} particles at "
        f"t = {sim.time:.6g} s; final checkpoint {final}; open {run.output / 'particles.pvd'} "
        "in ParaView"
    )
    return sim


def _failed(sim: Simulation, run: _Run, exc: SimulationError) -> SimulationError:
    failed = run.output / FAILED_FILE
    try:
        write_checkpoint(sim, failed, kind="failed", message=str(exc), case_yaml=run.case_yaml)
        failed_text = f"state at the failure (for inspection): {failed}"
    except Exception as write_error:  # noqa: BLE001 (report the original error regardless)
        failed_text = f"the state at the failure could not be written: {write_error}"
    last = run.last_checkpoint
    if last is None:
        existing = list_checkpoints(run.output / CHECKPOINT_DIR)
        last = existing[-1] if existing else None
    if last is not None:
        good = read_checkpoint(last)
        last_text = (
            f"last good state: {last} (step {good.step}, t = {good.time:.6g} s); to continue "
            f"from it with a changed case: thermodem run CASE --restart {last} --output NEWDIR"
        )
    else:
        last_text = "no checkpoint of a good state was written"
    message = f"{exc}\n{last_text}\n{failed_text}"
    run.log.file_only(f"error: {message}")
    run.status.update(status="failed", message=str(exc), **_status_numbers(sim, run))
    return SimulationError(
        message, exc.step, exc.time, exc.particle, checkpoint=str(last) if last else None
    )


def _interrupted(sim: Simulation, run: _Run, in_step: bool, signum: int) -> RunInterrupted:
    if in_step:
        # aborted inside a step: the state is not consistent, keep the last checkpoint
        last = run.last_checkpoint
        message = (
            f"aborted during step {sim.step_count + 1}: no checkpoint written; last good "
            f"state: {last}; continue with: thermodem restart {run.output}"
        )
    else:
        last = _checkpoint(sim, run, "interrupted")
        message = (
            f"interrupted at step {sim.step_count} (t = {sim.time:.6g} s): state saved to "
            f"{last}; continue with: thermodem restart {run.output}"
        )
    run.log.info(message)
    run.status.update(status="interrupted", message=message, **_status_numbers(sim, run))
    code = 128 + (signum or signal.SIGINT)
    return RunInterrupted(message, checkpoint=str(last) if last else None, exit_code=code)


# ---------------------------------------------------------------------------- entry points
def _open(
    output: Path, console: TextIO | None | str, append: bool, case_name: str | None
) -> tuple[RunLog, Status]:
    if console == "stdout":  # resolved at call time (tests and the CLI replace sys.stdout)
        console = sys.stdout
    log = RunLog(output / LOG_FILE, console, append=append)
    status = Status(output / STATUS_FILE, Status.read(output) if append else {})
    if not append:
        status.data.update(
            case=case_name,
            started=_dt.datetime.now().isoformat(timespec="seconds"),
            host=socket.gethostname(),
        )
    return log, status


def _header(log: RunLog, sim: Simulation, threads: int | None, output: Path) -> None:
    from thermodem import __version__

    estimate = estimate_resources(sim, threads)
    for warning in check_resources(estimate):
        log.warn(warning)
    log.info(
        f"thermodem {__version__}: output {output}, {estimate.threads} thread(s), "
        f"time step {sim.dt:g} s, end time {sim.case.simulation.end_time:g} s"
    )
    for line in estimate.lines():
        log.info("  " + line)


def run_case(
    case: Case,
    output: str | os.PathLike[str],
    threads: int | None = None,
    overwrite: bool = False,
    log: TextIO | None | str = "stdout",
    *,
    case_name: str | None = None,
    progress: bool | None = None,
    log_interval: float = 10.0,
    callback: Callable[[Simulation], None] | None = None,
    every: int = 1,
) -> Simulation:
    """Validate, build, run to ``simulation.end_time`` and write the output directory.

    ``log``: console stream (default sys.stdout; None: silent; ``run.log`` is written
    regardless). ``progress``:
    a rich bar (True), plain lines (False) or a bar only on a terminal (None). ``callback`` is
    called every ``every`` steps with the simulation (raising KeyboardInterrupt from it stops
    the run like Ctrl-C).
    Raises ConfigError (bad input), SimulationError (the run failed), RunInterrupted.
    """
    output = Path(output)
    check_completeness(case)
    prepare_output_dir(output, overwrite)
    for stale in (STATUS_FILE, FAILED_FILE, TIMESERIES_FILE):
        (output / stale).unlink(missing_ok=True)
    for old in list_checkpoints(output / CHECKPOINT_DIR):
        old.unlink()
    (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
    runlog, status = _open(output, log, append=False, case_name=case_name)
    try:
        sim = Simulation(case, threads=threads)
        for warning in check_simulation_time_step(sim):
            runlog.warn(warning)
        _header(runlog, sim, threads, output)
        run = _make_run(sim, output, runlog, status, False, progress, log_interval, callback, every)
        return _drive(sim, run, fresh=True)
    except ConfigError as exc:
        runlog.file_only(f"error: {exc}")
        status.update(status="failed", message=str(exc))
        raise
    finally:
        runlog.close()


def restart_run(
    output: str | os.PathLike[str],
    threads: int | None = None,
    log: TextIO | None | str = "stdout",
    *,
    end_time: float | None = None,
    progress: bool | None = None,
    log_interval: float = 10.0,
    callback: Callable[[Simulation], None] | None = None,
    every: int = 1,
) -> Simulation:
    """Continue the run in ``output`` from its newest checkpoint to end_time (``end_time``
    replaces the stored one). Frames and time-series rows after the checkpoint are dropped and
    written again, so the finished directory is the same as an uninterrupted run's."""
    output = Path(output)
    if not output.is_dir():
        raise ConfigError(f"{str(output)!r} is not an output directory")
    checkpoints = list_checkpoints(output / CHECKPOINT_DIR)
    if not checkpoints:
        raise ConfigError(f"no checkpoints in {output / CHECKPOINT_DIR}; nothing to restart from")
    previous = Status.read(output)
    pid = previous.get("pid")
    if previous.get("status") == "running" and pid and pid != os.getpid() and _alive(pid):
        if previous.get("host") in (None, socket.gethostname()):
            raise ConfigError(f"{output} is still being written by a running process (pid {pid})")
    ckpt = read_checkpoint(checkpoints[-1])
    case = ckpt.case()
    if end_time is not None:
        case.simulation.end_time = float(end_time)
    sim = Simulation.from_checkpoint(ckpt, threads=threads, case=case)
    if end_time is not None:
        (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
    runlog, status = _open(output, log, append=True, case_name=previous.get("case"))
    try:
        runlog.info(
            f"restart from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s) to end time "
            f"{case.simulation.end_time:g} s"
        )
        (output / FAILED_FILE).unlink(missing_ok=True)
        _header(runlog, sim, threads, output)
        run = _make_run(sim, output, runlog, status, True, progress, log_interval, callback, every)
        run.last_checkpoint = ckpt.path
        if sim.step_count >= run.total:
            runlog.info(f"already at the end time (step {sim.step_count}); nothing to do")
            return sim
        result = _drive(sim, run, fresh=False)
        return result
    finally:
        runlog.close()


def run_from_checkpoint(
    checkpoint: str | os.PathLike[str],
    output: str | os.PathLike[str],
    case: Case | None = None,
    threads: int | None = None,
    overwrite: bool = False,
    log: TextIO | None | str = "stdout",
    *,
    case_name: str | None = None,
    progress: bool | None = None,
    log_interval: float = 10.0,
    callback: Callable[[Simulation], None] | None = None,
    every: int = 1,
) -> Simulation:
    """A new run in ``output`` starting from the state in ``checkpoint`` (``case``: a changed
    case, e.g. a smaller time step after a failure; default the stored one)."""
    output = Path(output)
    ckpt = read_checkpoint(checkpoint)
    case = case or ckpt.case()
    sim = Simulation.from_checkpoint(ckpt, threads=threads, case=case)
    prepare_output_dir(output, overwrite)
    for stale in (STATUS_FILE, FAILED_FILE, TIMESERIES_FILE):
        (output / stale).unlink(missing_ok=True)
    (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
    runlog, status = _open(output, log, append=False, case_name=case_name)
    try:
        runlog.info(f"starting from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s)")
        for warning in check_simulation_time_step(sim):
            runlog.warn(warning)
        _header(runlog, sim, threads, output)
        run = _make_run(sim, output, runlog, status, False, progress, log_interval, callback, every)
        return _drive(sim, run, fresh=True)
    finally:
        runlog.close()


def _alive(pid: int) -> bool:
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError, ValueError):
        return True
    return True


def output_summary(directory: str | os.PathLike[str]) -> list[str]:
    """Lines describing a finished or running output directory (``thermodem info``)."""
    directory = Path(directory)
    if not directory.is_dir():
        raise ConfigError(f"{str(directory)!r} is not a directory")
    status = Status.read(directory)
    resolved = directory / "case.resolved.yaml"
    if not status and not resolved.exists():
        raise ConfigError(f"{str(directory)!r} is not a thermodem output directory")
    lines = [f"output: {directory}"]
    state = status.get("status", "unknown")
    pid = status.get("pid")
    if state == "running" and pid and status.get("host") in (None, socket.gethostname()):
        if not _alive(pid):
            state = f"stopped without a final status (process {pid} is gone: killed?)"
        else:
            state = f"running (pid {pid})"
    lines.append(f"status: {state}")
    if status.get("message"):
        lines.append(f"message: {status['message'].splitlines()[0]}")
    if status.get("case"):
        lines.append(f"case: {status['case']}")
    if "time" in status:
        end = status.get("end_time") or math.nan
        frac = 100.0 * status["time"] / end if end else math.nan
        lines.append(
            f"time: {status['time']:.6g} s of {end:g} s ({frac:.1f} %), step "
            f"{status.get('step')} of {status.get('total_steps')}"
        )
        lines.append(f"particles: {status.get('particles')}, contacts: {status.get('contacts')}")
    if status.get("started"):
        lines.append(f"started: {status['started']}, last update: {status.get('updated')}")
    pvd = directory / "particles.pvd"
    if pvd.exists():
        entries = PVDWriter.read(pvd)
        last = f", last at t = {entries[-1][0]:.6g} s" if entries else ""
        lines.append(f"frames: {len(entries)}{last} ({pvd})")
    ckpts = list_checkpoints(directory / CHECKPOINT_DIR)
    if ckpts:
        lines.append(f"checkpoints: {', '.join(p.name for p in ckpts)}")
    if (directory / FAILED_FILE).exists():
        lines.append(f"state at the failure: {directory / FAILED_FILE}")
    ts = directory / TIMESERIES_FILE
    if ts.exists():
        with ts.open(newline="") as f:
            rows = [r for r in csv.reader(f) if r]
        if len(rows) > 1:
            lines.append(f"timeseries: {len(rows) - 1} rows; last row:")
            lines += [f"  {k} = {v}" for k, v in zip(rows[0], rows[-1], strict=False) if v != ""]
    return lines
