"""Signals (SIGINT, SIGTERM) during a run (:mod:`thermodem.engine.runner` and the MPI runner).

While the run steps, :class:`StopRequest`: the first signal asks the loop to stop after the
current step with a checkpoint, a second one aborts at once. Once the run is stopping or
ending (the interrupt checkpoint, the record of a failure, the final outputs:
:meth:`StopRequest.finish`), a further signal is noted with a line and not obeyed, so that
the checkpoint and ``status.json`` are finished. While it is being set up (the simulation
built, the checks, the step-0 outputs), :class:`Starting`: either signal stops at once and
:func:`not_started` records it so that the same command can be run again; on several MPI
ranks :class:`StartingTogether`: the signal is noted and every rank stops at the next point
the ranks agree on (:mod:`thermodem.mpi.runner`). The same holds while a restart is set up
(the checkpoint read, the simulation rebuilt and compiled): :func:`restart_not_started` says
so and leaves the earlier run's record as it was.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

from thermodem.engine.run_checks import LOCK_FILE
from thermodem.errors import RunInterrupted
from thermodem.io.run_files import RunLog, Status, only_run_record


class SignalHandlers:
    """SIGINT and SIGTERM handled inside the ``with`` block (main thread) by the subclass's
    ``_handler(signum, frame)``."""

    _handler: Callable[[int, object], None]

    def __init__(self) -> None:
        self.signum = 0
        self._old: dict[int, Any] = {}

    def __enter__(self) -> SignalHandlers:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)


class StopRequest(SignalHandlers):
    """SIGINT/SIGTERM handler: the first signal asks the loop to stop after the current step,
    a second one aborts at once (KeyboardInterrupt)."""

    def __init__(self, log: RunLog) -> None:
        super().__init__()
        self.log = log
        self.finishing = ""

    def finish(self, what: str) -> None:
        """From here on the run is stopping or ending (``what``: "writing the interrupt
        checkpoint", ...): a signal is noted with a line, not obeyed. Obeyed, a second signal
        while the interrupt checkpoint was written exited without a word and left status.json
        saying 'running' (SIGTERM), or was reported as a stop before the first step (SIGINT)."""
        self.finishing = what

    def _handler(self, signum: int, frame: object) -> None:
        name = signal.Signals(signum).name
        if self.finishing:
            self.signum = self.signum or signum
            self._say(
                f"{name} received while {self.finishing}: finishing it first, the run stops "
                "as soon as it is on disk (stopping halfway would lose it)"
            )
            return
        if self.signum:
            raise KeyboardInterrupt
        self.signum = signum
        self._say(
            f"{name} received: finishing the step and writing a checkpoint (send it again to "
            "abort without one)"
        )

    def _say(self, message: str) -> None:
        try:
            self.log.info(message)
        except RuntimeError:  # (the signal came while the run was writing the same stream)
            pass


class Starting(SignalHandlers):
    """SIGINT/SIGTERM while a run is being set up (the simulation built, the checks, the
    step-0 outputs): there is no state worth a checkpoint yet, so either signal stops at once
    (KeyboardInterrupt, ``signum`` kept) and :func:`not_started` records it. Without it
    Ctrl-C here exited 130 without a word and SIGTERM killed the process, leaving a
    ``run.log`` and ``case.resolved.yaml`` that made the same command refuse the directory."""

    def _handler(self, signum: int, frame: object) -> None:
        self.signum = signum
        raise KeyboardInterrupt


class StartingTogether(Starting):
    """:class:`Starting` on several MPI ranks: the set-up is full of collectives (the build,
    the checks, the step-0 gathers), so a rank that stopped at once would leave the others
    waiting in one. The first signal is noted; the ranks agree on it at fixed points of the
    set-up and stop there together (:mod:`thermodem.mpi.runner`). A second one stops this
    rank at once (KeyboardInterrupt, ``agreed`` False): the job is then aborted."""

    def __init__(self) -> None:
        super().__init__()
        self.agreed = False

    def _handler(self, signum: int, frame: object) -> None:
        if self.signum:
            raise KeyboardInterrupt
        self.signum = signum


def not_started(
    output: Path,
    log: RunLog | None,
    status: Status | None,
    signum: int,
    checkpoint: Path | str | None = None,
) -> RunInterrupted:
    """The record of a run stopped by a signal before its first step (:class:`Starting`).
    ``log`` and ``status`` None: stopped before the output directory was touched (a run from
    a checkpoint, while the checkpoint was read and the simulation rebuilt); ``checkpoint``:
    the checkpoint the run starts from (``run --restart``), named as unchanged."""
    signum = signum or signal.SIGINT
    name = signal.Signals(signum).name
    if status is None:
        done = f"nothing was computed and {output} was not touched"
        again = "the same command"
    else:
        done = "nothing was computed and no checkpoint written"
        record_only = only_run_record(output, ignore=LOCK_FILE)
        again = "the same command" if record_only else "the same command with --overwrite"
    source = f" (from {checkpoint}, which is unchanged)" if checkpoint is not None else ""
    message = (
        f"interrupted ({name}) while the run was being set up, before its first step: {done}; "
        f"to start it: {again}{source}"
    )
    if log is not None:
        log.info(message)
    if status is not None:
        status.update(status="interrupted", message=message, not_started=True)
    return RunInterrupted(message, checkpoint=None, exit_code=128 + signum)


def restart_not_started(
    log: RunLog | None,
    signum: int,
    checkpoint: Path | str | None,
    step: int | None = None,
    time: float | None = None,
) -> RunInterrupted:
    """A restart of a run directory (``thermodem restart OUT``) stopped by a signal before its
    first step (:class:`Starting`, :class:`StartingTogether`): nothing was computed and the
    run's checkpoints are as they were, so the same command continues from the same one
    (``checkpoint``: the newest, at ``step`` and ``time`` once it has been read). The line
    goes to ``run.log`` (``log``, once it is open); ``status.json`` is not touched: it still
    records how the earlier run ended (its step, time and last checkpoint), which
    ``not_started`` would misreport as a run that never started."""
    signum = signum or signal.SIGINT
    name = signal.Signals(signum).name
    if checkpoint is None:
        source = "its newest checkpoint"
    else:
        source = str(checkpoint)
        if step is not None and time is not None:
            source += f" (step {step}, t = {time:.6g} s)"
    message = (
        f"interrupted ({name}) while the restart was being set up, before its first step: "
        "nothing was computed, the run's checkpoints are unchanged and nothing of the earlier "
        f"run is lost (status.json still records it); to continue: the same command, from "
        f"{source}"
    )
    if log is not None:
        log.info(message)
    return RunInterrupted(
        message, checkpoint=str(checkpoint) if checkpoint else None, exit_code=128 + signum
    )
