"""Thermal models, one module per family or model group; importing the package imports every
module in it, whose ``register()`` calls fill the registry (a new model module needs no line
here)."""

import importlib
import pkgutil

for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")
