"""The loop of a run on several MPI ranks and its outputs (mpi/runner.py sets the run up).

Every rank runs the loop; everything that needs the ranks together (the step, a report, a
gather) is called by all of them in the same order. Rank 0 writes the outputs: the time
series from reductions over the ranks, one VTU frame and one checkpoint per output time (the
particles gathered to rank 0, :mod:`thermodem.mpi.gather`), progress lines. An output the
system refuses on rank 0 is agreed after each write (every rank stops with rank 0's message);
a failure is agreed inside the step and its state gathered to ``failed.h5``; a signal on any
rank stops every rank after the same step with a checkpoint.
"""

from __future__ import annotations

import os
import signal
import time as wallclock
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from thermodem.engine import runner as R
from thermodem.engine.progress import Progress
from thermodem.engine.run_signals import (
    StopRequest,
)
from thermodem.engine.validation import (
    format_duration,
)
from thermodem.errors import RunInterrupted, RunNotice, SimulationError
from thermodem.io.checkpoint import (
    read_checkpoint,
    write_checkpoint,
)
from thermodem.io.run_files import FAILED_FILE
from thermodem.mpi.gather import gathered_view
from thermodem.mpi.simulation import DistributedSimulation


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
