"""Running a case on several MPI ranks: the output directory, the loop, failures.

The same output directory as a serial run (engine/runner.py), written by rank 0 only: the
checks before anything is touched, the lock, ``case.resolved.yaml``, ``run.log``,
``status.json``, ``timeseries.csv`` (one row per interval, from reductions over the ranks),
one VTU frame and one checkpoint per output time (the particles gathered to rank 0,
:mod:`thermodem.mpi.gather`; the gather and write times are in run.log at the end), progress
lines. Every rank runs the loop; everything that needs the ranks together (the step, a
report, a gather) is called by all of them in the same order.

Failures: a :class:`SimulationError` is agreed inside the step (every rank raises the same
message, :meth:`DistributedSimulation.agree`), the state at the failure is gathered to
``failed.h5`` and the message names the last good checkpoint, on every rank. A signal
(SIGINT, SIGTERM) on any rank stops every rank after the same step with a checkpoint (the
stop request travels with the step's reduction); one while the run (or a restart) is being
set up is agreed at fixed points of the set-up and every rank stops there
(engine/run_signals.py: StartingTogether, not_started, restart_not_started). An output the
system refuses on rank 0 (a full disk, the run directory removed) is agreed after each write:
every rank stops with rank 0's message (engine/runner.py's ``_unwritable``). Any other
exception on one rank cannot be agreed (the others wait in a collective): the rank prints it
and aborts the MPI job (``MPI_Abort``), so no rank hangs (``thermodem.cli``).
"""

from __future__ import annotations

import os
import signal
import sys
import time as wallclock
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, TextIO

from thermodem.config.schema import Case
from thermodem.engine import runner as R
from thermodem.engine.checks import check_simulation_time_step
from thermodem.engine.progress import Progress
from thermodem.engine.run_signals import (
    StartingTogether,
    StopRequest,
    not_started,
    restart_not_started,
)
from thermodem.engine.validation import (
    check_completeness,
    format_duration,
    on_every_rank,
    pre_run_checks,
)
from thermodem.errors import ConfigError, RunInterrupted, RunNotice, SimulationError
from thermodem.io.checkpoint import (
    Checkpoint,
    list_checkpoints,
    read_checkpoint,
    write_checkpoint,
)
from thermodem.io.run_files import CHECKPOINT_DIR, FAILED_FILE, STATUS_FILE, TIMESERIES_FILE
from thermodem.mpi.gather import gathered_view
from thermodem.mpi.simulation import REBALANCE_THRESHOLD, DistributedSimulation


def _comm() -> Any:
    from mpi4py import MPI

    return MPI.COMM_WORLD


def _agreed(comm: Any, error: Exception | None) -> None:
    """Raise on every rank the ConfigError that rank 0 met (or nothing)."""
    message = comm.bcast(str(error) if error is not None else None, root=0)
    if message is not None:
        raise ConfigError(message)


class _OutputRefused(Exception):
    """Rank 0 could not write an output (agreed: every rank raises it with rank 0's text)."""


@dataclass
class _Outputs:
    """What the loop writes besides the simulation; ``run`` is None on the other ranks."""

    run: R._Run | None
    total: int
    frame_every: int
    series_every: int
    checkpoint_every: int
    gather_seconds: float = 0.0
    write_seconds: float = 0.0
    frames_written: int = 0
    checkpoints_written: int = 0
    last_checkpoint: Path | None = None
    callback: Callable[[DistributedSimulation], None] | None = None
    every: int = 1

    # every rank calls these at the same steps (they are collective)
    def series(self, sim: DistributedSimulation) -> None:
        refused = None
        if self.run is not None:
            try:
                self.run.timeseries.write(sim)  # (sim.report(), the collective part, first)
            except OSError as exc:
                refused = exc
        else:
            sim.report()
        self._agree_written(sim, refused)

    def frame(self, sim: DistributedSimulation) -> None:
        t0 = wallclock.perf_counter()
        view = gathered_view(sim)
        t1 = wallclock.perf_counter()
        self.gather_seconds += t1 - t0
        refused = None
        if self.run is not None and self.run.frames is not None:
            try:
                self.run.frames.write(view)
            except OSError as exc:
                refused = exc
            self.write_seconds += wallclock.perf_counter() - t1
        self._agree_written(sim, refused)
        self.frames_written += 1

    def _agree_written(self, sim: DistributedSimulation, refused: OSError | None) -> None:
        """After rank 0's write: every rank stops with rank 0's message if the system refused
        it (a full disk, the run directory removed), instead of rank 0 dying alone while the
        others wait in the next collective."""
        text = None
        if refused is not None and self.run is not None:
            text = R._unwritable(sim, self.run, refused, ranks=sim.size).args[0]
        text = sim.comm.bcast(text, root=0)
        if text is not None:
            raise _OutputRefused(text)

    def checkpoint(self, sim: DistributedSimulation, kind: str) -> Path:
        t0 = wallclock.perf_counter()
        state = sim.state_dict()
        t1 = wallclock.perf_counter()
        self.gather_seconds += t1 - t0
        path = Path(".")
        refused = None
        if self.run is not None:
            try:
                path = R._checkpoint(sim, self.run, kind, state)
            except OSError as exc:
                refused = exc
            self.write_seconds += wallclock.perf_counter() - t1
        self._agree_written(sim, refused)
        self.checkpoints_written += 1
        path = Path(sim.comm.bcast(str(path) if self.run is not None else None, root=0))
        self.last_checkpoint = path
        return path


def _outputs(
    sim: DistributedSimulation,
    run: R._Run | None,
    callback: Callable[[DistributedSimulation], None] | None = None,
    every: int = 1,
) -> _Outputs:
    from thermodem.engine.validation import total_steps

    case = sim.case
    out = case.output
    return _Outputs(
        run=run,
        total=total_steps(sim),
        frame_every=R._schedule(case, sim, out.interval, 1.0 / 20.0) if out.vtu else 0,
        series_every=R._schedule(case, sim, out.timeseries_interval, 1.0 / 1000.0),
        checkpoint_every=R._schedule(case, sim, out.checkpoint_interval, 1.0 / 10.0),
        callback=callback,
        every=max(1, int(every)),
    )


def _first_outputs(sim: DistributedSimulation, out: _Outputs) -> None:
    """The outputs of the starting state (collective): a row, a frame and the first
    checkpoint."""
    out.series(sim)
    if out.frame_every:
        out.frame(sim)
    out.checkpoint(sim, "checkpoint")


def _drive(sim: DistributedSimulation, out: _Outputs, pending: int = 0) -> DistributedSimulation:
    """The time loop of every rank (engine/runner.py: _loop, with collective outputs); the
    signal handlers stay until the run's end is on disk. ``pending``: a signal noted after
    the set-up's last agreed point (run_signals.StartingTogether): the run stops after the
    first step."""
    with StopRequest(out.run.log if out.run is not None else _Silent()) as stop:
        stop.signum = pending
        return _stepped(sim, out, stop)


def _stepped(sim: DistributedSimulation, out: _Outputs, stop: StopRequest) -> DistributedSimulation:
    run = out.run
    root = run is not None
    log = run.log if root else None
    if root:
        out.last_checkpoint = run.last_checkpoint
        run.status.update(status="running", pid=os.getpid(), message="", **_status(sim, run))
    progress = Progress(log, sim, out.total, run.log_interval, run.progress_bar) if root else None
    started = wallclock.perf_counter()
    start_step = sim.step_count
    in_step = False
    try:
        with progress or _NoContext(), warnings.catch_warnings():
            warnings.simplefilter("always", RuntimeWarning)
            if root:
                warnings.showwarning = lambda msg, cat, *a, **k: (
                    log.info if issubclass(cat, RunNotice) else log.warn
                )(str(msg))
            while sim.step_count < out.total:
                sim.stop_requested = stop.signum
                in_step = True
                sim.step()
                in_step = False
                if sim.stop_agreed:
                    # every rank stops after this step: a signal from here on is noted (one
                    # obeyed on one rank would leave the others in a collective)
                    stop.finish("writing the interrupt checkpoint")
                k = sim.step_count
                if k % out.series_every == 0:
                    out.series(sim)
                if out.frame_every and k % out.frame_every == 0:
                    out.frame(sim)
                if k % out.checkpoint_every == 0 and k < out.total:
                    out.checkpoint(sim, "checkpoint")
                    if root:
                        run.status.update(**_status(sim, run))
                if progress is not None:
                    progress.update(sim)
                if sim.stop_agreed:
                    raise KeyboardInterrupt
                if out.callback is not None and k % out.every == 0:
                    out.callback(sim)
    except _OutputRefused as exc:
        raise SimulationError(str(exc), sim.step_count, sim.time, -1) from None
    except SimulationError as exc:
        stop.finish("writing the state at the failure and the record of it")
        raise _failed(sim, out, exc) from None
    except KeyboardInterrupt:
        if in_step or not sim.stop_agreed:
            # a second signal, or one that reached this rank only: the others cannot be
            # brought to the same step; end the job (the last checkpoint stays good)
            if root:
                log.info(f"aborted during step {sim.step_count + 1}: no checkpoint written; "
                         f"last good state: {out.last_checkpoint}")  # fmt: skip
            sim.comm.Abort(128 + (stop.signum or signal.SIGINT))
        stop.finish("writing the interrupt checkpoint")
        raise _interrupted(sim, out, stop.signum) from None
    stop.finish("writing the final outputs")
    # the last step: a row, a frame and a checkpoint even off their schedules (rank 0 knows
    # what its writers wrote last)
    last = (run.timeseries.last_step, run.frames.last_step if run.frames else -1) if root else None
    last_row, last_frame = sim.comm.bcast(last, root=0)
    if last_row != sim.step_count:
        out.series(sim)
    if out.frame_every and last_frame != sim.step_count:
        out.frame(sim)
    final = out.checkpoint(sim, "final")
    elapsed = wallclock.perf_counter() - started
    summary = sim.halo_summary()
    if root:
        steps = sim.step_count - start_step
        log.info(progress.line(sim))
        run.status.update(status="finished", message=f"finished in {format_duration(elapsed)}",
                          wallclock_seconds=elapsed, **_status(sim, run))  # fmt: skip
        log.info(_mpi_line(summary, out, elapsed))
        log.info(
            f"done: {steps} steps in {format_duration(elapsed)} on {sim.size} MPI ranks, "
            f"{sim.global_count} particles at t = {sim.time:.6g} s; final checkpoint {final}; "
            f"{R.outputs_text(run.output, run.frames)}"
        )
    return sim


def _status(sim: DistributedSimulation, run: R._Run) -> dict[str, Any]:
    """The numbers of status.json (engine/runner.py: _status_numbers) of the whole run."""
    numbers = R._status_numbers(sim, run)
    numbers.update(particles=sim.global_count, contacts=sim.global_contacts, ranks=sim.size)
    return numbers


class _Silent:
    def info(self, message: str) -> None:
        pass


class _NoContext:
    def __enter__(self) -> _NoContext:
        return self

    def __exit__(self, *exc: object) -> None:
        pass


def _mpi_line(summary: dict[str, float], out: _Outputs, elapsed: float) -> str:
    return (
        f"MPI: {summary['ranks']} ranks, {summary['particles']} particles (most on one rank "
        f"{summary['max_owned']}, imbalance {100 * summary['imbalance']:.1f} %), "
        f"{summary['ghosts']} ghosts; halo exchange {summary['halo_seconds_mean']:.3g} s and "
        f"rebuilds {summary['rebuild_seconds_mean']:.3g} s per rank of {elapsed:.3g} s, "
        f"{summary['rebalances']} rebalances; outputs: {out.frames_written} frames and "
        f"{out.checkpoints_written} checkpoints gathered in {out.gather_seconds:.3g} s, written "
        f"in {out.write_seconds:.3g} s (rank 0)"
    )


def _failed(sim: DistributedSimulation, out: _Outputs, exc: SimulationError) -> SimulationError:
    run = out.run
    state = sim.state_dict()  # (collective: every rank met the same error)
    message = None
    if run is not None:
        failed = run.output / FAILED_FILE
        try:
            write_checkpoint(sim, failed, kind="failed", message=str(exc),
                             case_yaml=run.case_yaml, run_id=run.run_id, state=state)  # fmt: skip
            failed_text = f"state at the failure (for inspection): {failed}"
        except Exception as write_error:  # noqa: BLE001 (report the original error regardless)
            failed_text = f"the state at the failure could not be written: {write_error}"
        last = out.last_checkpoint or run.last_checkpoint
        if last is not None:
            good = read_checkpoint(last)
            last_text = (
                f"last good state: {last} (step {good.step}, t = {good.time:.6g} s); to "
                f"continue from it with a changed case: mpiexec -n {sim.size} thermodem run "
                f"CASE --restart {last} --output NEWDIR"
            )
        else:
            last_text = "no checkpoint of a good state was written"
        message = f"{exc}\n{last_text}\n{failed_text}"
        run.log.file_only(f"error: {message}")
        run.status.update(status="failed", message=str(exc), **_status(sim, run))
    message = sim.comm.bcast(message, root=0)
    last = str(out.last_checkpoint) if out.last_checkpoint else None
    return SimulationError(message, exc.step, exc.time, exc.particle, checkpoint=last)


def _interrupted(sim: DistributedSimulation, out: _Outputs, signum: int) -> RunInterrupted:
    last = out.checkpoint(sim, "interrupted")
    message = (
        f"interrupted at step {sim.step_count} (t = {sim.time:.6g} s): state saved to {last}; "
        f"continue with: mpiexec -n {sim.size} thermodem restart "
        f"{out.run.output if out.run else 'OUT'}"
    )
    message = sim.comm.bcast(message, root=0)
    if out.run is not None:
        out.run.log.info(message)
        out.run.status.update(status="interrupted", message=message,
                              **_status(sim, out.run))  # fmt: skip
    signum = int(sim.comm.allreduce(signum or 0, op=_max_op()))
    return RunInterrupted(message, checkpoint=str(last), exit_code=128 + (signum or signal.SIGINT))


def _max_op() -> Any:
    from mpi4py import MPI

    return MPI.MAX


def _header(log: R.RunLog, sim: DistributedSimulation, output: Path) -> None:
    from thermodem import __version__

    summary = sim.halo_summary()
    log.info(
        f"threads: {sim.threads} per rank ({sim.threads_reason}); MPI: {sim.size} ranks, "
        f"recursive bisection by particle count (rebalanced above "
        f"{100 * sim.rebalance_threshold:g} % imbalance): at most {summary['max_owned']} of "
        f"{summary['particles']} particles on one rank, {summary['ghosts']} ghosts (halo "
        f"{sim.halo_width:.4g} m)"
    )
    log.info(
        f"thermodem {__version__}: output {output}, {sim.size} MPI ranks, time step "
        f"{sim.dt:g} s, end time {sim.case.simulation.end_time:g} s"
    )


# ---------------------------------------------------------------------------- entry points
def run_distributed(
    case: Case,
    output: str | os.PathLike[str],
    threads: int | None = None,
    overwrite: bool = False,
    log: TextIO | None | str = "stdout",
    *,
    checkpoint: str | os.PathLike[str] | None = None,
    case_name: str | None = None,
    progress: bool | None = None,
    log_interval: float = 10.0,
    rebalance_threshold: float = REBALANCE_THRESHOLD,
    callback: Callable[[DistributedSimulation], None] | None = None,
    every: int = 1,
) -> DistributedSimulation:
    """``run_case`` (or ``run_from_checkpoint`` with ``checkpoint``) on every rank of
    MPI.COMM_WORLD; every rank must call it. Rank 0 writes the output directory."""
    comm = _comm()
    root = comm.Get_rank() == 0
    output = Path(output)
    lock = runlog = status = None
    starting = StartingTogether()
    try:
        with starting:
            ckpt = None
            if checkpoint is not None:
                ckpt = _read_on_all(comm, checkpoint)
                case = case or ckpt.case()
            error: Exception | None = None
            if root:
                try:
                    check_completeness(case)
                    if ckpt is not None:  # (as the serial run --restart, before any write)
                        R.check_restart_start(ckpt, case)
                    R.check_output_path(output)
                    if output.is_dir():
                        R.refuse_if_busy(output, "--overwrite" if overwrite else "a new run")
                    R.prepare_output_dir(output, overwrite)
                    lock = R.RunLock(output)
                    lock.acquire()
                    for stale in (STATUS_FILE, FAILED_FILE, TIMESERIES_FILE):
                        (output / stale).unlink(missing_ok=True)
                    for old in list_checkpoints(output / CHECKPOINT_DIR):
                        old.unlink()
                    (output / "case.resolved.yaml").write_text(R.resolved_case_yaml(case))
                    runlog, status = R._open(output, log, append=False, case_name=case_name)
                    R._compile_note(runlog, case)
                except ConfigError as exc:
                    error = exc
                    if lock is not None:
                        lock.release()
                        lock = None
            _agreed(comm, error)
            _together(comm, starting)
            try:
                with _build_warnings(runlog):
                    sim = _build(case, threads, rebalance_threshold, ckpt)
                # the checks of the serial runner before the first step (engine/runner.py:
                # run_case, run_from_checkpoint), collective: a refusal on one rank is every
                # rank's
                warned = _time_step_check(sim) if ckpt is not None else pre_run_checks(sim)
            except ConfigError as exc:
                if root:
                    runlog.file_only(f"error: {exc}")
                    status.update(status="failed", message=str(exc), refused_input=True)
                raise
            run = None
            if root:
                if ckpt is not None:
                    runlog.info(
                        f"starting from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s)"
                    )
                    for line in R.restart_changes(ckpt, case):
                        runlog.info(line)
                    if getattr(sim, "heat_start", None):  # (engine/heat_start.py)
                        runlog.info(sim.heat_start)
                for warning in warned:
                    runlog.warn(warning)
                run = R._make_run(sim, output, runlog, status, False, progress, log_interval,
                                  None, 1)  # fmt: skip
                run.run_id = status.data["run_id"]
                _header(runlog, sim, output)
            else:
                sim.halo_summary()
            _together(comm, starting)
            out = _outputs(sim, run, callback, every)
            _first_outputs(sim, out)
            _together(comm, starting)
    except KeyboardInterrupt:
        record = None
        if runlog is not None and status is not None:  # (rank 0, once the directory is ready)
            record = partial(not_started, output, runlog, status, checkpoint=checkpoint)
        try:
            raise _not_started(comm, starting, record) from None
        finally:
            _close(runlog, lock)
    except BaseException:
        _close(runlog, lock)
        raise
    try:
        return _drive(sim, out, pending=starting.signum)
    finally:
        _close(runlog, lock)


def _together(comm: Any, starting: StartingTogether) -> None:
    """A point of the set-up where the ranks agree on a signal (one allreduce): if one
    reached any rank, every rank stops here (KeyboardInterrupt, ``starting.agreed``)."""
    signum = int(comm.allreduce(starting.signum, op=_max_op()))
    if signum:
        starting.signum, starting.agreed = signum, True
        raise KeyboardInterrupt


def _not_started(
    comm: Any,
    starting: StartingTogether,
    record: Callable[[int], RunInterrupted] | None,
    what: str = "run",
) -> RunInterrupted:
    """A signal while the ranks were set up (engine/run_signals.py: not_started,
    restart_not_started): ``record`` (rank 0, None on the others or before there is
    anything to record) writes it and returns the RunInterrupted. Agreed, every rank is here
    and returns rank 0's message; a second signal on this rank, the others may be waiting in
    a collective: the job is aborted (rank 0, if it is this rank, writes the record first)."""
    signum = starting.signum or signal.SIGINT
    interrupted = record(signum) if record is not None else None
    if not starting.agreed:
        if interrupted is None:
            print(
                f"interrupted ({signal.Signals(signum).name}) again on MPI rank "
                f"{comm.Get_rank()} while the {what} was being set up: aborting every rank",
                file=sys.stderr,
                flush=True,
            )
        comm.Abort(128 + signum)
    message = comm.bcast(str(interrupted) if interrupted is not None else None, root=0)
    return interrupted or RunInterrupted(message, checkpoint=None, exit_code=128 + signum)


def _close(runlog: R.RunLog | None, lock: R.RunLock | None) -> None:
    if runlog is not None:
        runlog.close()
    if lock is not None:
        lock.release()


def restart_distributed(
    output: str | os.PathLike[str],
    threads: int | None = None,
    log: TextIO | None | str = "stdout",
    *,
    end_time: float | None = None,
    progress: bool | None = None,
    log_interval: float = 10.0,
    rebalance_threshold: float = REBALANCE_THRESHOLD,
) -> DistributedSimulation:
    """``restart_run`` on every rank: continue the run in ``output`` from its newest
    checkpoint (written by any number of ranks). A signal while the ranks are set up is
    agreed at two points (after the build, before the directory is touched; after it is
    opened) and every rank stops there with rank 0's message, the checkpoints and status.json
    as they were (engine/run_signals.py: StartingTogether, restart_not_started)."""
    import math
    import uuid

    comm = _comm()
    root = comm.Get_rank() == 0
    output = Path(output)
    lock = runlog = None
    newest: Checkpoint | None = None  # (rank 0: the checkpoint the restart continues from)
    starting = StartingTogether()
    try:
        with starting:
            error: Exception | None = None
            path = None
            if root:
                try:
                    if not output.is_dir():
                        raise ConfigError(f"{str(output)!r} is not an output directory")
                    if end_time is not None and not (math.isfinite(end_time) and end_time > 0.0):
                        raise ConfigError(
                            f"--end-time: {end_time!r} is not allowed; give a finite end time "
                            "> 0 [s]"
                        )
                    checkpoints = list_checkpoints(output / CHECKPOINT_DIR)
                    if not checkpoints:
                        raise ConfigError(R.no_checkpoint_to_restart(output, comm.Get_size()))
                    R.refuse_if_busy(output, "restart")
                    path = checkpoints[-1]
                    newest = R.read_newest_checkpoint(checkpoints)
                    R.check_checkpoint_belongs(newest, output, R.Status.read(output))
                    if end_time is not None and end_time < newest.time:
                        raise ConfigError(
                            f"--end-time: {end_time:g} s is before the time of the newest "
                            f"checkpoint, {newest.time:.6g} s ({newest.path}); give a later "
                            "end time"
                        )
                except ConfigError as exc:
                    error = exc
            _agreed(comm, error)
            path = comm.bcast(str(newest.path) if root else None, root=0)
            ckpt = _read_on_all(comm, path)
            case = ckpt.case()
            if end_time is not None:
                case.simulation.end_time = float(end_time)
            with R.recorded_warnings() as built:  # (said by rank 0 once run.log is open)
                sim = _build(case, threads, rebalance_threshold, ckpt)
            _together(comm, starting)  # (nothing written yet)
            run = None
            error = None
            if root:
                try:
                    series_repair = R.timeseries_repair(output / TIMESERIES_FILE)
                    lock = R.RunLock(output)
                    lock.acquire()
                    previous = R.Status.read(output)
                    runlog, status = R._open(output, log, append=True,
                                             case_name=previous.get("case"))  # fmt: skip
                    run_id = status.data.setdefault("run_id", ckpt.run_id or uuid.uuid4().hex)
                    runlog.info(
                        f"restart from {ckpt.path} (step {ckpt.step}, t = {ckpt.time:.6g} s) "
                        f"to end time {case.simulation.end_time:g} s on {sim.size} MPI ranks"
                    )
                    R.say_warnings(runlog, built)
                    if series_repair is not None:
                        runlog.warn(series_repair())
                    run = R._make_run(sim, output, runlog, status, True, progress,
                                      log_interval, None, 1)  # fmt: skip
                    run.run_id = run_id
                    run.last_checkpoint = ckpt.path
                except ConfigError as exc:
                    error = exc
                    _close(runlog, lock)
                    runlog = lock = None
            _agreed(comm, error)
            if root:
                _header(runlog, sim, output)
            else:
                sim.halo_summary()
            out = _outputs(sim, run)
            out.last_checkpoint = ckpt.path
            _together(comm, starting)
    except KeyboardInterrupt:
        record = None
        if root and newest is not None:
            record = partial(restart_not_started, runlog, checkpoint=newest.path,
                             step=newest.step, time=newest.time)  # fmt: skip
        elif root:  # (stopped before the newest checkpoint was read)
            record = partial(restart_not_started, runlog, checkpoint=path)
        try:
            raise _not_started(comm, starting, record, "restart") from None
        finally:
            _close(runlog, lock)
    except BaseException:
        _close(runlog, lock)
        raise
    try:
        if root:
            # the set-up is done: the new end time and the end of the failure's record (kept
            # until here, so that a restart stopped while it was set up changes neither)
            if end_time is not None:
                (output / "case.resolved.yaml").write_text(R.resolved_case_yaml(case))
            (output / FAILED_FILE).unlink(missing_ok=True)
        if sim.step_count >= out.total:
            if root:
                runlog.info(f"already at the end time (step {sim.step_count}); nothing to do")
            return sim
        return _drive(sim, out, pending=starting.signum)
    finally:
        _close(runlog, lock)


def _build_warnings(runlog: Any) -> Any:
    """Warnings while the ranks build the simulation: rank 0's go to the console and run.log
    as in a serial run (engine/runner.py: logged_warnings), the other ranks' are dropped:
    every rank builds the same case, and what concerns the particles of every rank (the
    convection's validity ranges) is agreed and said by rank 0 (Simulation.agree_message)."""
    return R.logged_warnings(runlog) if runlog is not None else R.recorded_warnings()


def _time_step_check(sim: DistributedSimulation) -> list[str]:
    """The time-step check of every rank's particles (engine/checks.py): a refusal on any
    rank is every rank's ConfigError (the lowest such rank's message); rank 0's warnings."""
    return list(on_every_rank(sim, check_simulation_time_step))


def _read_on_all(comm: Any, path: str | os.PathLike[str]) -> Checkpoint:
    """The checkpoint read by every rank (rank 0 first: its error is everyone's)."""
    error = None
    ckpt = None
    if comm.Get_rank() == 0:
        try:
            ckpt = read_checkpoint(path)
        except ConfigError as exc:
            error = exc
    _agreed(comm, error)
    if comm.Get_rank() != 0:
        ckpt = read_checkpoint(path)
    return ckpt


def _build(
    case: Case, threads: int | None, rebalance_threshold: float, ckpt: Checkpoint | None
) -> DistributedSimulation:
    if ckpt is None:
        return DistributedSimulation(case, threads, rebalance_threshold=rebalance_threshold)
    if ckpt.kind == "failed":
        raise ConfigError(
            f"{ckpt.path} holds the state at a failure (for inspection) and cannot be "
            "continued; restart from the last good checkpoint instead"
        )
    sim = DistributedSimulation(
        case, threads, insert_particles=False, rebalance_threshold=rebalance_threshold
    )
    try:
        sim.load_state(ckpt.state)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise ConfigError(
            f"checkpoint {ckpt.path} cannot be restored ({type(exc).__name__}: {exc}); the file "
            "is damaged or was written by another version"
        ) from None
    return sim
