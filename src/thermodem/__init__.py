"""thermodem: thermal discrete element method (soft spheres that carry temperatures).

Numba's on-disk cache is keyed on the file that defines a kernel only, so a change in a model
module would not invalidate the cached loop that inlines it. thermodem therefore gives Numba
a cache locator whose source stamp covers a kernel's file and every package module it
imports (``thermodem._numba_cache``): an edit recompiles only the kernels that depend on the
edited module, and an unchanged installation loads everything from disk
(``~/.cache/thermodem/numba``, or under ``$THERMODEM_CACHE_DIR``). Setting
``NUMBA_CACHE_DIR`` yourself overrides the directory.

Importing thermodem also selects Numba's threading layer (OpenMP, else workqueue; never TBB
by accident) before any parallel kernel runs: see :mod:`thermodem.engine.threads`.

The Python API (imported on first use, so ``import thermodem`` stays light)::

    import thermodem
    case = thermodem.load_case("examples/default.yaml")      # or thermodem.case_from_dict({...})
    sim = thermodem.Simulation(case, threads=2)
    sim.run(steps=1000, callback=lambda s: print(s.time), every=100)
    sim.particles.position, sim.energies(), sim.report()
    thermodem.run_case(case, "out/")                          # the same outputs as the CLI
"""

from __future__ import annotations

from thermodem import _numba_cache

__version__ = "0.1.0"

_numba_cache.configure()


def _configure_threads() -> None:
    from thermodem.engine.threads import configure_threading_layer

    configure_threading_layer()


_configure_threads()

_API = {
    "Case": "thermodem.config.schema",
    "load_case": "thermodem.config.load",
    "case_from_dict": "thermodem.config.load",
    "resolved_case_yaml": "thermodem.config.dump",
    "Simulation": "thermodem.engine.simulation",
    "run_case": "thermodem.engine.runner",
    "restart_run": "thermodem.engine.restarted_runs",
    "run_from_checkpoint": "thermodem.engine.restarted_runs",
    "read_checkpoint": "thermodem.io.checkpoint",
    "write_checkpoint": "thermodem.io.checkpoint",
    "ConfigError": "thermodem.errors",
    "SimulationError": "thermodem.errors",
    "RunInterrupted": "thermodem.errors",
}

__all__ = ["__version__", *_API]


def __getattr__(name: str):  # noqa: ANN202 (PEP 562 lazy attributes)
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'thermodem' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
