"""Thermal models (imported to register them)."""

from thermodem.models.thermal import (  # noqa: F401
    contact_radius,
    convection,
    direct_conduction,
    indirect_conduction,
    radiation,
    resistance_network,
)
