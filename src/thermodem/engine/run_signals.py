"""Signals (SIGINT, SIGTERM) during a run (:mod:`thermodem.engine.runner` and the MPI runner).

While the run steps, :class:`StopRequest`: the first signal asks the loop to stop after the
current step with a checkpoint, a second one aborts at once. While it is being set up (the
simulation built, the checks, the step-0 outputs), :class:`Starting`: either signal stops at
once and :func:`not_started` records it so that the same command can be run again.
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

    def _handler(self, signum: int, frame: object) -> None:
        if self.signum:
            raise KeyboardInterrupt
        self.signum = signum
        self.log.info(
            f"{signal.Signals(signum).name} received: finishing the step and writing a "
            "checkpoint (send it again to abort without one)"
        )


class Starting(SignalHandlers):
    """SIGINT/SIGTERM while a run is being set up (the simulation built, the checks, the
    step-0 outputs): there is no state worth a checkpoint yet, so either signal stops at once
    (KeyboardInterrupt, ``signum`` kept) and :func:`not_started` records it. Without it
    Ctrl-C here exited 130 without a word and SIGTERM killed the process, leaving a
    ``run.log`` and ``case.resolved.yaml`` that made the same command refuse the directory."""

    def _handler(self, signum: int, frame: object) -> None:
        self.signum = signum
        raise KeyboardInterrupt


def not_started(output: Path, log: RunLog, status: Status, signum: int) -> RunInterrupted:
    """The record of a run stopped by a signal before its first step (:class:`Starting`)."""
    signum = signum or signal.SIGINT
    name = signal.Signals(signum).name
    record_only = only_run_record(output, ignore=LOCK_FILE)
    again = "the same command" if record_only else "the same command with --overwrite"
    message = (
        f"interrupted ({name}) while the run was being set up, before its first step: nothing "
        f"was computed and no checkpoint written; to start it: {again}"
    )
    log.info(message)
    status.update(status="interrupted", message=message, not_started=True)
    return RunInterrupted(message, checkpoint=None, exit_code=128 + signum)
