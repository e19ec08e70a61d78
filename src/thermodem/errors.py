"""Typed exceptions: bad input (ConfigError) and a run that went wrong (SimulationError)."""

from __future__ import annotations


class ConfigError(ValueError):
    """A case that cannot run; the message names the key path, the value and what is allowed."""


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
