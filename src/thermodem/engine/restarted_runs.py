"""Continuing a run: :func:`restart_run` (the run in an output directory from its newest
checkpoint, appending to its outputs) and :func:`run_from_checkpoint` (a new output directory
starting from any checkpoint, with the stored or a changed case). Both set up with the checks
of engine/run_checks.py before the directory is touched, then run through the loop of
engine/runner.py (:func:`~thermodem.engine.runner._drive`), as :func:`run_case` does.

A signal while a restart is set up stops it before its first step (run_signals.py); the
warnings said while its simulation is rebuilt (before run.log is open) are recorded and said
once the log is open (runner.recorded_warnings).
"""

from __future__ import annotations

import math
import os
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from thermodem.config.dump import resolved_case_yaml
from thermodem.config.schema import Case
from thermodem.engine.checks import check_simulation_time_step
from thermodem.engine.run_checks import (
    RunLock,
    check_checkpoint_belongs,
    check_output_path,
    check_restart_start,
    read_newest_checkpoint,
    refuse_if_busy,
    restart_changes,
    restored_simulation,
    timeseries_repair,
)
from thermodem.engine.run_signals import Starting, not_started, restart_not_started
from thermodem.engine.runner import (
    _drive,
    _first_outputs,
    _header,
    _make_run,
    _open,
    recorded_warnings,
    refusal_with,
    say_warnings,
)
from thermodem.engine.simulation import Simulation
from thermodem.engine.validation import check_resources, estimate_resources
from thermodem.errors import ConfigError, RunInterrupted
from thermodem.io.checkpoint import Checkpoint, list_checkpoints, read_checkpoint
from thermodem.io.run_files import (
    CHECKPOINT_DIR,
    FAILED_FILE,
    STATUS_FILE,
    TIMESERIES_FILE,
    RunLog,
    Status,
    no_checkpoint_to_restart,
    prepare_output_dir,
)
from thermodem.io.vtk import PVDWriter

__all__ = ["restart_run", "run_from_checkpoint"]


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
    written again, so the finished directory is the same as an uninterrupted run's.

    Everything is checked before the directory is touched: no live process writing it, the
    end time (finite, > 0, not before the checkpoint), the checkpoint (complete, written for
    this directory), the resources. A signal (SIGINT, SIGTERM) while the restart is set up
    stops it before its first step (RunInterrupted, 130/143) with the directory's checkpoints
    and status.json as they were (run_signals.restart_not_started)."""
    output = Path(output)
    if not output.is_dir():
        raise ConfigError(f"{str(output)!r} is not an output directory")
    if end_time is not None and not (math.isfinite(end_time) and end_time > 0.0):
        raise ConfigError(
            f"--end-time: {end_time!r} is not allowed; give a finite end time > 0 [s]"
        )
    checkpoints = list_checkpoints(output / CHECKPOINT_DIR)
    if not checkpoints:
        raise ConfigError(no_checkpoint_to_restart(output))
    refuse_if_busy(output, "restart")
    previous = Status.read(output)
    # a signal while the restart is set up (the checkpoint read, the simulation rebuilt and
    # compiled, the directory opened) stops it before its first step with the checkpoint it
    # would have continued from; the earlier run's record stays as it was
    # (run_signals.restart_not_started)
    starting = Starting()
    ckpt = None
    try:
        with starting, recorded_warnings() as built:
            ckpt = read_newest_checkpoint(checkpoints)
            check_checkpoint_belongs(ckpt, output, previous)
            case = ckpt.case()
            if end_time is not None:
                if end_time < ckpt.time:
                    raise ConfigError(
                        f"--end-time: {end_time:g} s is before the time of the newest "
                        f"checkpoint, {ckpt.time:.6g} s ({ckpt.path}); give a later end time"
                    )
                case.simulation.end_time = float(end_time)
            sim = restored_simulation(ckpt, threads, case)
            check_resources(estimate_resources(sim, threads))  # refuses before any write
            series_repair = timeseries_repair(output / TIMESERIES_FILE)
            for pvd in ("particles.pvd", "walls.pvd"):
                if (output / pvd).exists():
                    try:
                        PVDWriter.read(output / pvd)
                    except (ValueError, OSError, SyntaxError) as exc:  # ParseError: SyntaxError
                        raise ConfigError(
                            f"{output / pvd} cannot be read ({exc}); restart refused, nothing "
                            "was changed: repair or delete it"
                        ) from None
    except KeyboardInterrupt:
        raise _restart_stopped(None, starting.signum, ckpt, checkpoints) from None
    except ConfigError as exc:
        refusal_with(exc, built)
        raise
    # nothing above wrote to the directory
    lock = RunLock(output)
    lock.acquire()
    try:
        runlog, status = _open(output, log, append=True, case_name=previous.get("case"))
        run_id = status.data.setdefault("run_id", ckpt.run_id or uuid.uuid4().hex)
        try:
            try:
                with starting:
                    runlog.info(
                        f"restart from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s) "
                        f"to end time {case.simulation.end_time:g} s"
                    )
                    if series_repair is not None:
                        runlog.warn(series_repair())
                    say_warnings(runlog, built)
                    _header(runlog, sim, threads, output)
                    run = _make_run(
                        sim, output, runlog, status, True, progress, log_interval, callback, every
                    )
                    run.run_id = run_id
                    run.last_checkpoint = ckpt.path
            except KeyboardInterrupt:
                raise _restart_stopped(runlog, starting.signum, ckpt, checkpoints) from None
            # the set-up is done: the new end time and the end of the failure's record (kept
            # until here, so that a restart stopped while it was set up changes neither)
            if end_time is not None:
                (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
            (output / FAILED_FILE).unlink(missing_ok=True)
            if sim.step_count >= run.total:
                runlog.info(f"already at the end time (step {sim.step_count}); nothing to do")
                return sim
            return _drive(sim, run, fresh=False)
        finally:
            runlog.close()
    finally:
        lock.release()


def _restart_stopped(
    log: RunLog | None, signum: int, ckpt: Checkpoint | None, checkpoints: list[Path]
) -> RunInterrupted:
    """run_signals.restart_not_started with the checkpoint the restart continues from (the
    newest, read or not yet)."""
    if ckpt is None:
        return restart_not_started(log, signum, checkpoints[-1])
    return restart_not_started(log, signum, ckpt.path, ckpt.step, ckpt.time)


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
    # a signal while the checkpoint is read and the simulation rebuilt (compiled) stops the
    # run before ``output`` is touched (run_signals.not_started without a record)
    starting = Starting()
    try:
        with starting, recorded_warnings() as built:
            ckpt = read_checkpoint(checkpoint)
            case = case or ckpt.case()
            check_restart_start(ckpt, case)
            changes = restart_changes(ckpt, case)
            sim = restored_simulation(ckpt, threads, case)
    except KeyboardInterrupt:
        raise not_started(output, None, None, starting.signum, checkpoint) from None
    except ConfigError as exc:
        refusal_with(exc, built)
        raise
    check_output_path(output)
    if output.is_dir():
        refuse_if_busy(output, "--overwrite" if overwrite else "a new run")
    prepare_output_dir(output, overwrite)
    lock = RunLock(output)
    lock.acquire()
    try:
        for stale in (STATUS_FILE, FAILED_FILE, TIMESERIES_FILE):
            (output / stale).unlink(missing_ok=True)
        (output / "case.resolved.yaml").write_text(resolved_case_yaml(case))
        runlog, status = _open(output, log, append=False, case_name=case_name)
        try:
            runlog.info(f"starting from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s)")
            for line in changes:
                runlog.info(line)
            if getattr(sim, "heat_start", None):  # (engine/heat_start.py)
                runlog.info(sim.heat_start)
            say_warnings(runlog, built)
            try:
                with starting:
                    for warning in check_simulation_time_step(sim):
                        runlog.warn(warning)
                    _header(runlog, sim, threads, output)
                    run = _make_run(
                        sim, output, runlog, status, False, progress, log_interval, callback, every
                    )
                    run.run_id = status.data["run_id"]
                    _first_outputs(sim, run)
            except RunInterrupted:
                raise
            except KeyboardInterrupt:
                raise not_started(output, runlog, status, starting.signum, ckpt.path) from None
            return _drive(sim, run, fresh=False)
        finally:
            runlog.close()
    finally:
        lock.release()
