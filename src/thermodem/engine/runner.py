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
    OUT/run.lock                          pid, host and start of the process writing OUT (while
                                          it runs; a second run, --overwrite or restart of OUT
                                          is refused while that process is alive)

Three entry points: :func:`run_case` (a fresh run, here), and in engine/restarted_runs.py
``restart_run`` (continue the run in an output directory from its newest checkpoint,
appending to its outputs) and ``run_from_checkpoint`` (a new output directory starting from
any checkpoint, with the stored or a changed case). All three go through one loop,
:func:`_drive`.

Before anything in an output directory is written or deleted, everything that can be checked
is: the output path (its parent must be a directory), the lock of a live process writing it,
the checkpoint to continue from (complete, consistent arrays, written for this directory:
the ``run_id`` of ``status.json`` and the stored case, end time aside), the end time, the
resources. A truncated last row of ``timeseries.csv`` (a run killed while writing it) is
dropped at a restart with a message.

Failures: a :class:`SimulationError` from the engine writes ``failed.h5`` (the state at the
failure, for inspection) and is raised again with the last good checkpoint named in the
message. SIGINT (Ctrl-C) and SIGTERM finish the current step, write a checkpoint and raise
:class:`~thermodem.errors.RunInterrupted`; a second signal during a step aborts at once
without writing, one while the interrupt checkpoint (or the failure's record, or the final
outputs) is being written is noted and the writing finished (engine/run_signals.py).
"""

from __future__ import annotations

import datetime as _dt
import os
import signal
import socket
import sys
import time as wallclock
import uuid
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from thermodem.config.dump import resolved_case_yaml
from thermodem.config.schema import Case
from thermodem.engine.progress import Progress, _short  # noqa: F401
from thermodem.engine.run_checks import (  # noqa: F401 (LOCK_FILE, process_start re-exported)
    LOCK_FILE,
    RunLock,
    check_checkpoint_belongs,
    check_output_path,
    check_restart_start,
    process_start,
    read_newest_checkpoint,
    refuse_if_busy,
    restart_changes,
    restored_simulation,
    timeseries_repair,
)
from thermodem.engine.run_info import output_summary  # noqa: F401 (re-exported)
from thermodem.engine.run_signals import Starting, StopRequest, not_started
from thermodem.engine.simulation import Simulation
from thermodem.engine.validation import (
    built_simulation,
    check_completeness,
    check_resources,
    estimate_resources,
    format_duration,
    pre_run_checks,
    total_steps,
    with_warnings,
)
from thermodem.errors import ConfigError, RunInterrupted, RunNotice, SimulationError
from thermodem.io.checkpoint import (
    checkpoint_name,
    list_checkpoints,
    read_checkpoint,
    write_checkpoint,
)
from thermodem.io.run_files import (  # noqa: F401 (re-exported)
    CHECKPOINT_DIR,
    FAILED_FILE,
    LOG_FILE,
    STATUS_FILE,
    TIMESERIES_FILE,
    FrameWriter,
    RunLog,
    Status,
    TimeseriesWriter,
    _atomic_write_text,
    _cell,
    no_checkpoint_to_restart,
    only_run_record,
    prepare_output_dir,
    read_timeseries,
)

__all__ = [
    "FrameWriter",
    "RunLog",
    "TimeseriesWriter",
    "prepare_output_dir",
    "resolved_case_yaml",
    "run_case",
]


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
    run_id: str = ""


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
        frames = FrameWriter(
            output, extent, resume_time=sim.time if resume else None, contacts=out.contacts
        )
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


def _checkpoint(sim: Simulation, run: _Run, kind: str, state: dict | None = None) -> Path:
    """The next checkpoint of the run, the oldest beyond ``output.checkpoint_keep`` removed
    (``state``: the state to write, e.g. the MPI ranks' gathered one; default ``sim``'s)."""
    directory = run.output / CHECKPOINT_DIR
    path = write_checkpoint(
        sim,
        directory / checkpoint_name(sim.step_count),
        kind=kind,
        case_yaml=run.case_yaml,
        run_id=run.run_id,
        state=state,
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


def _first_outputs(sim: Simulation, run: _Run) -> None:
    """The outputs of the starting state: a row, a frame and the first checkpoint."""
    try:
        run.timeseries.write(sim)
        if run.frames:
            run.frames.write(sim)
        _checkpoint(sim, run, "checkpoint")
    except OSError as exc:
        raise _unwritable(sim, run, exc) from None


def _drive(sim: Simulation, run: _Run, fresh: bool) -> Simulation:
    """The time loop with outputs on their triggers; failures and interrupts handled here."""
    try:
        return _loop(sim, run, fresh)
    except OSError as exc:
        raise _unwritable(sim, run, exc) from None


def _unwritable(sim: Simulation, run: _Run, exc: OSError, ranks: int = 1) -> SimulationError:
    """An output the system refused in the middle of the run (the directory removed, the disk
    full, a read-only file system): the run stops with the file, the cause, the step and what
    is left on disk (before, an OSError traceback and status.json saying 'running'). ``ranks``:
    the MPI ranks of the run (the commands it suggests start with ``mpiexec -n``)."""
    cause = exc.strerror or str(exc)
    name = f" ({exc.filename})" if exc.filename else ""
    where = f"at step {sim.step_count} (t = {sim.time:.6g} s)"
    last = run.last_checkpoint if run.last_checkpoint and run.last_checkpoint.is_file() else None
    launch = f"mpiexec -n {ranks} thermodem" if ranks > 1 else "thermodem"
    if last is not None:
        left = (
            f"last checkpoint on disk: {last}; once the directory can be written again, "
            f"continue with: {launch} restart {run.output} (or {launch} run CASE --restart "
            f"{last} --output NEWDIR)"
        )
    else:
        left = f"no checkpoint of this run is left in {run.output}: start it again"
    message = (
        f"the run directory {run.output} cannot be written {where}: {cause}{name}; the run "
        f"stopped\n{left}"
    )
    try:
        run.log.file_only(f"error: {message}")
        run.status.update(status="failed", message=message, **_status_numbers(sim, run))
    except OSError:
        pass  # (the directory that refused the output may refuse these too)
    return SimulationError(
        message, sim.step_count, sim.time, -1, checkpoint=str(last) if last else None
    )


@contextmanager
def logged_warnings(log: RunLog) -> Iterator[None]:
    """Warnings raised inside (while the simulation is built: a fluid section no model reads;
    while it steps: a pour that placed fewer particles) go to the console and ``run.log``
    through ``log`` as ``warning: ...`` lines (a :class:`RunNotice` as a plain line), not to
    the CLI's stderr only: a user reading run.log later sees them."""
    with warnings.catch_warnings():
        warnings.simplefilter("always", RuntimeWarning)
        warnings.showwarning = lambda msg, cat, *a, **k: (
            log.info if issubclass(cat, RunNotice) else log.warn
        )(str(msg))
        yield


@contextmanager
def recorded_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """Warnings raised inside kept, not shown: a restart builds its simulation before it
    touches the output directory (no run.log yet); :func:`say_warnings` says them once the
    log is open, or a refusal carries them (:func:`refusal_with`)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        yield caught


def say_warnings(log: RunLog, caught: list[warnings.WarningMessage]) -> None:
    """The recorded warnings through ``log`` as :func:`logged_warnings` says them; others
    (not thermodem's) as Python would have shown them."""
    for w in caught:
        if issubclass(w.category, RunNotice):
            log.info(str(w.message))
        elif issubclass(w.category, RuntimeWarning):
            log.warn(str(w.message))
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)


def refusal_with(exc: ConfigError, caught: list[warnings.WarningMessage]) -> ConfigError:
    """``exc`` carrying the RuntimeWarnings recorded before it (the CLI says them before the
    error: they may explain it)."""
    if exc.warnings is None:
        exc.warnings = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    return exc


def _loop(sim: Simulation, run: _Run, fresh: bool) -> Simulation:
    # the signal handlers stay until the run's end is on disk: once it is stopping or ending
    # (the interrupt checkpoint, the record of a failure, the final outputs) a signal is
    # noted, not obeyed (run_signals.StopRequest.finish)
    with StopRequest(run.log) as stop:
        return _stepped(sim, run, fresh, stop)


def _stepped(sim: Simulation, run: _Run, fresh: bool, stop: StopRequest) -> Simulation:
    log = run.log
    if fresh:
        _first_outputs(sim, run)
    run.status.update(status="running", pid=os.getpid(), message="", **_status_numbers(sim, run))
    in_step = False
    progress = Progress(log, sim, run.total, run.log_interval, run.progress_bar)
    started = wallclock.perf_counter()
    start_step = sim.step_count
    try:
        with progress, logged_warnings(log):
            while sim.step_count < run.total:
                if stop.signum:
                    raise KeyboardInterrupt
                in_step = True
                sim.step(complete=False)  # the writers below complete the heat rates
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
                    sim.complete_rates()
                    run.callback(sim)
    except SimulationError as exc:
        stop.finish("writing the state at the failure and the record of it")
        raise _failed(sim, run, exc) from None
    except KeyboardInterrupt:
        stop.finish(
            "recording the stop in status.json" if in_step else "writing the interrupt checkpoint"
        )
        raise _interrupted(sim, run, in_step, stop.signum) from None
    # the last step: a row, a frame and a checkpoint even off their schedules
    stop.finish("writing the final outputs")
    if run.timeseries.last_step != sim.step_count:
        run.timeseries.write(sim)
    if run.frames and run.frames.last_step != sim.step_count:
        run.frames.write(sim)
    final = _checkpoint(sim, run, "final")
    elapsed = wallclock.perf_counter() - started
    steps = sim.step_count - start_step
    log.info(progress.line(sim))
    governor = sim.governor
    if governor.single_steps:
        log.info(
            f"threads: {governor.single_steps} of the run's steps ran on 1 thread, which was "
            f"faster than {governor.chosen} when timed (another process on the cores, or too "
            "little work per step for the threads)"
        )
    run.status.update(
        status="finished",
        message=f"finished in {format_duration(elapsed)}",
        wallclock_seconds=elapsed,
        **_status_numbers(sim, run),
    )
    log.info(
        f"done: {steps} steps in {format_duration(elapsed)}, {sim.particles.count} particles at "
        f"t = {sim.time:.6g} s; final checkpoint {final}; {outputs_text(run.output, run.frames)}"
    )
    return sim


def outputs_text(output: Path, frames: FrameWriter | None) -> str:
    """The last line's pointer to the outputs: only files that were written (with
    ``output.vtu: false`` there is no ``particles.pvd`` to open)."""
    series = f"time series {output / TIMESERIES_FILE}"
    if frames is None:
        return (
            f"{series}; no VTU frames were written (output.vtu: false): thermodem export "
            f"{output} gives the particles of a checkpoint as CSV"
        )
    return f"{series}; open {output / 'particles.pvd'} in ParaView"


def _failed(sim: Simulation, run: _Run, exc: SimulationError) -> SimulationError:
    failed = run.output / FAILED_FILE
    try:
        write_checkpoint(
            sim,
            failed,
            kind="failed",
            message=str(exc),
            case_yaml=run.case_yaml,
            run_id=run.run_id,
        )
        failed_text = f"state at the failure (for inspection): {failed}"
    except Exception as write_error:  # noqa: BLE001 (report the original error regardless)
        failed_text = f"the state at the failure could not be written: {write_error}"
    last = run.last_checkpoint
    if last is None:
        existing = list_checkpoints(run.output / CHECKPOINT_DIR)
        last = existing[-1] if existing else None
    last_text = "no checkpoint of a good state was written"
    if last is not None:
        try:
            good = read_checkpoint(last)
        except Exception as read_error:  # noqa: BLE001 (the run's failure comes first)
            last_text = f"the last checkpoint {last} cannot be read: {read_error}"
            last = None
        else:
            last_text = (
                f"last good state: {last} (step {good.step}, t = {good.time:.6g} s); to "
                f"continue from it with a changed case: thermodem run CASE --restart {last} "
                "--output NEWDIR"
            )
    message = f"{exc}\n{last_text}\n{failed_text}"
    try:
        run.log.file_only(f"error: {message}")
        run.status.update(status="failed", message=str(exc), **_status_numbers(sim, run))
    except OSError:
        pass  # (a directory that refuses them: the message on the console says it all)
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
            run_id=uuid.uuid4().hex,
        )
    return log, status


def _header(log: RunLog, sim: Simulation, threads: int | None, output: Path) -> None:
    from thermodem import __version__

    _threads_line(log, sim, threads)
    estimate = estimate_resources(sim, sim.threads)
    for warning in check_resources(estimate):
        log.warn(warning)
    log.info(
        f"thermodem {__version__}: output {output}, {estimate.threads} thread(s), "
        f"time step {sim.dt:g} s, end time {sim.case.simulation.end_time:g} s"
    )
    for line in estimate.lines():
        log.info("  " + line)


def _compile_note(log: RunLog, case: Case) -> None:
    """Say so before a simulation compiles its kernels (a cold cache; engine/kernel_cache.py)."""
    from thermodem.engine.kernel_cache import compile_note

    note = compile_note(case)
    if note:
        log.info(note)


def _threads_line(log: RunLog, sim: Simulation, threads: int | None) -> None:
    """Choose the thread count for the run (the request, or from the work) and log it with
    the threading layer (engine/threads.py)."""
    from thermodem.engine.threads import threading_layer

    sim.set_threads(threads)
    log.info(f"threads: {sim.threads} ({sim.threads_reason}); threading layer {threading_layer()}")


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
    check_output_path(output)
    if output.is_dir():
        refuse_if_busy(output, "--overwrite" if overwrite else "a new run")
    prepare_output_dir(output, overwrite)
    lock = RunLock(output)
    lock.acquire()
    try:
        for stale in (STATUS_FILE, FAILED_FILE, TIMESERIES_FILE):
            (output / stale).unlink(missing_ok=True)
        for old in list_checkpoints(output / CHECKPOINT_DIR):
            old.unlink()
        (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
        runlog, status = _open(output, log, append=False, case_name=case_name)
        _compile_note(runlog, case)
        run_id = status.data["run_id"]
        starting = Starting()
        try:
            try:
                with starting, logged_warnings(runlog):
                    sim = built_simulation(case, threads)
                    for warning in pre_run_checks(sim):  # (the MPI runner calls the same)
                        runlog.warn(warning)
                    _header(runlog, sim, threads, output)
                    run = _make_run(
                        sim, output, runlog, status, False, progress, log_interval, callback, every
                    )
                    run.run_id = run_id
                    _first_outputs(sim, run)
            except KeyboardInterrupt:
                raise not_started(output, runlog, status, starting.signum) from None
            except ConfigError as exc:
                # the warnings that may explain the refusal, before it (a density in g/cm³
                # before the time step its tiny mass refuses), on the console and in run.log
                for warning in with_warnings(exc, case).warnings or ():
                    runlog.warn(warning)
                exc.warnings = []  # (told: the CLI does not print them again)
                runlog.file_only(f"error: {exc}")
                status.update(status="failed", message=str(exc), refused_input=True)
                raise
            # a signal from here on is the loop's (run_signals.StopRequest), not a stop before
            # the first step (a second SIGINT while the interrupt checkpoint was written was
            # reported as one)
            return _drive(sim, run, fresh=False)
        finally:
            runlog.close()
    finally:
        lock.release()
