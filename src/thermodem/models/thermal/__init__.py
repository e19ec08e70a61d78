"""Thermal models (imported to register them)."""

from thermodem.models.thermal import (  # noqa: F401
    contact_radius,
    direct_conduction,
    indirect_conduction,
    radiation,
    resistance_network,
    surrounding_layer,
    vargas_mccarthy,
)
