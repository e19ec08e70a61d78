"""Whether this installation's Numba cache is cold, so the first run compiles the kernels.

thermodem keeps its compiled kernels in one cache directory whose entries are stamped with a
hash of each kernel's file and the package modules it imports (``thermodem/_numba_cache.py``).
A fresh installation, or a change of those sources, finds no fresh entry and the first
simulation compiles every kernel it uses: on the 2-core
development VM that took :data:`COMPILE_SECONDS_MECHANICS` for a mechanics-only case and
:data:`COMPILE_SECONDS_HEAT` more with heat (measured with an empty cache, see
docs/run-layer.md), with nothing printed in the meantime. :func:`compile_note` tells the user
beforehand.

The check looks for Numba's index files (``*.nbi``) of the time-integration kernels
(``integrate.kick_drift``) and, for a case with heat, of the thermal kernels
(``thermal.*``), and whether their stamp is the current one. A new model combination in a
warm cache still compiles its pair pass (a few seconds to half a minute); that is not
announced.
"""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import Any

#: Seconds to compile the kernels of a mechanics-only case with an empty cache (2-core VM).
COMPILE_SECONDS_MECHANICS = 20.0
#: Extra seconds for the thermal kernels of a case with heat.
COMPILE_SECONDS_HEAT = 10.0


def cache_directory() -> Path | None:
    """Numba's cache directory for this installation (None: caching is off)."""
    import numba

    if getattr(numba.config, "DISABLE_CACHE", False):
        return None
    directory = getattr(numba.config, "CACHE_DIR", "")
    return Path(directory) if directory else None


def _has_index(directory: Path, prefix: str, source: str) -> bool:
    """Whether an index file of a kernel of ``source`` (relative to the package) starting
    with ``prefix`` holds this installation's stamp (Numba's index: a pickled version, then
    the pickled (stamp, overloads))."""
    from thermodem import _numba_cache

    stamp = _numba_cache.dependency_stamp(str(_numba_cache.PACKAGE_ROOT / source))
    for path in directory.rglob(f"{prefix}*.nbi"):
        try:
            with open(path, "rb") as f:
                pickle.load(f)
                saved, _ = pickle.loads(f.read())
        except Exception:  # noqa: BLE001 (unreadable: not a fresh entry)
            continue
        if saved == stamp:
            return True
    return False


def cold_parts(heat: bool) -> list[str]:
    """Which kernel groups have no compiled code on disk: ``[]``, ``['mechanics']``,
    ``['heat']`` or both."""
    directory = cache_directory()
    if directory is None or not directory.is_dir():
        return ["mechanics", "heat"] if heat else ["mechanics"]
    cold = []
    if not _has_index(directory, "integrate.kick_drift", "kernels/integrate.py"):
        cold.append("mechanics")
    if heat and not _has_index(directory, "thermal.", "kernels/thermal.py"):
        cold.append("heat")
    return cold


def compile_note(case: Any) -> str | None:
    """``'compiling kernels (first run only, ~N s)'`` when the cache is cold for ``case``,
    else None."""
    heat = getattr(case, "thermal", None) is not None
    cold = cold_parts(heat)
    if not cold:
        return None
    seconds = 0.0
    if "mechanics" in cold:
        seconds += COMPILE_SECONDS_MECHANICS
    if "heat" in cold:
        seconds += COMPILE_SECONDS_HEAT
    where = cache_directory()
    if where is None:
        return f"compiling kernels (~{seconds:.0f} s; Numba's cache is off, so every run does)"
    return f"compiling kernels (first run only, ~{seconds:.0f} s; kept in {where})"
