"""Physical models, grouped by family; see :mod:`thermodem.models.registry`."""
