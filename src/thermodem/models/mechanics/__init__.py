"""Mechanical contact models: normal, tangential, rolling (imported to register them)."""

from thermodem.models.mechanics import normal, rolling, tangential  # noqa: F401
