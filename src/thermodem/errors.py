"""Typed exceptions: bad input (ConfigError), a run that went wrong (SimulationError), a run
stopped by a signal after writing a checkpoint (RunInterrupted)."""

from __future__ import annotations


class ConfigError(ValueError):
    """A case that cannot run; the message names the key path, the value and what is allowed.

    ``warnings``: the warnings of the case computed before the refusal (a density in g/cm³
    that explains a time step refused for the tiny mass it gives), said before the error:
    the CLI prints them as ``warning: ...`` lines; a run that logs them itself (run.log)
    empties the list. None when none were gathered."""

    warnings: list[str] | None = None


class SimulationError(RuntimeError):
    """A run that went wrong; the message says what, where (particle) and when (step, time)."""

    def __init__(
        self,
        message: str,
        step: int = -1,
        time: float = float("nan"),
        particle: int = -1,
        checkpoint: str | None = None,
    ) -> None:
        super().__init__(message)
        self.step = step
        self.time = time
        self.particle = particle
        self.checkpoint = checkpoint


class RunNotice(RuntimeWarning):
    """Information for the run log (a cost, a rebuild), issued as a warning: the runner logs
    it as a plain line, not as a warning."""


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT) or SIGTERM after writing a checkpoint.

    ``checkpoint`` is the file to continue from (``thermodem restart OUT``); ``exit_code`` is
    128 + the signal number (130 for SIGINT, 143 for SIGTERM), what the CLI exits with.
    """

    def __init__(self, message: str, checkpoint: str | None = None, exit_code: int = 130) -> None:
        super().__init__(message)
        self.message = message
        self.checkpoint = checkpoint
        self.exit_code = exit_code

    def __str__(self) -> str:
        return self.message
