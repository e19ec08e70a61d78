"""thermodem: thermal discrete element method (soft spheres that carry temperatures).

Numba's on-disk cache is keyed on the file that defines a kernel only, so a change in a model
module would not invalidate the cached loop that inlines it. thermodem therefore keeps its
compiled kernels in a cache directory named after a hash of all of its own source files
(``~/.cache/thermodem/numba-<hash>``, or under ``$THERMODEM_CACHE_DIR``): any source change
gives a fresh cache, and an unchanged installation loads everything from disk. Setting
``NUMBA_CACHE_DIR`` yourself overrides this.

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

import hashlib
import os
from pathlib import Path

__version__ = "0.1.0"


def _configure_numba_cache() -> None:
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    root = Path(__file__).parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    base = Path(os.environ.get("THERMODEM_CACHE_DIR", Path.home() / ".cache" / "thermodem"))
    cache = base / f"numba-{digest.hexdigest()[:16]}"
    try:
        cache.mkdir(parents=True, exist_ok=True)
    except OSError:
        return
    import numba

    numba.config.CACHE_DIR = str(cache)


_configure_numba_cache()


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
    "restart_run": "thermodem.engine.runner",
    "run_from_checkpoint": "thermodem.engine.runner",
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
