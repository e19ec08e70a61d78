"""Running a case on several MPI ranks: the output directory, set-up and entry points (the
loop and its outputs are mpi/run_loop.py).

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
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any, TextIO

from thermodem.config.schema import Case
from thermodem.engine import runner as R
from thermodem.engine.checks import check_simulation_time_step
from thermodem.engine.run_signals import (
    StartingTogether,
    not_started,
    restart_not_started,
)
from thermodem.engine.validation import (
    built_simulation,
    check_completeness,
    on_every_rank,
    pre_run_checks,
)
from thermodem.errors import ConfigError, RunInterrupted, SimulationError
from thermodem.io.checkpoint import (
    Checkpoint,
    list_checkpoints,
    read_checkpoint,
)
from thermodem.io.run_files import CHECKPOINT_DIR, FAILED_FILE, STATUS_FILE, TIMESERIES_FILE
from thermodem.mpi.run_loop import _drive, _first_outputs, _header, _max_op, _outputs
from thermodem.mpi.simulation import REBALANCE_THRESHOLD, DistributedSimulation


def _comm() -> Any:
    from mpi4py import MPI

    return MPI.COMM_WORLD


def _agreed(comm: Any, error: Exception | None) -> None:
    """Raise on every rank the ConfigError that rank 0 met (or nothing)."""
    message = comm.bcast(str(error) if error is not None else None, root=0)
    if message is not None:
        raise ConfigError(message)


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
    if ckpt is None:  # (a failure while it is built is the input's, as serially)
        return built_simulation(
            case,
            build=lambda: DistributedSimulation(
                case, threads, rebalance_threshold=rebalance_threshold
            ),
        )
    if ckpt.kind == "failed":
        raise ConfigError(
            f"{ckpt.path} holds the state at a failure (for inspection) and cannot be "
            "continued; restart from the last good checkpoint instead"
        )
    sim = DistributedSimulation(
        case, threads, insert_particles=False, rebalance_threshold=rebalance_threshold
    )
    try:
        sim.load_state(ckpt.state)  # (collective: the rebuild distributes the particles)
    except SimulationError as exc:
        # the distributing rebuild refused the (changed) case's lists: a periodic axis too
        # short for the restored particles, agreed by every rank (the global R_max); an input
        # error, as serially (engine/run_checks.py: check_restored_lists)
        raise ConfigError(
            f"{exc} (met while the restart from {ckpt.path} was set up, before any step)"
        ) from None
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise ConfigError(
            f"checkpoint {ckpt.path} cannot be restored ({type(exc).__name__}: {exc}); the file "
            "is damaged or was written by another version"
        ) from None
    return sim
