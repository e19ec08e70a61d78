"""thermodem: thermal discrete element method (soft spheres that carry temperatures).

Numba's on-disk cache is keyed on the file that defines a kernel only, so a change in a model
module would not invalidate the cached loop that inlines it. thermodem therefore keeps its
compiled kernels in a cache directory named after a hash of all of its own source files
(``~/.cache/thermodem/numba-<hash>``, or under ``$THERMODEM_CACHE_DIR``): any source change
gives a fresh cache, and an unchanged installation loads everything from disk. Setting
``NUMBA_CACHE_DIR`` yourself overrides this.
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
