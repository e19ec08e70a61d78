"""A second process loads every compiled kernel from Numba's on-disk cache.

The pair passes are compiled per model combination (closures with the model ids as constants,
``kernels/pair_pass.py``); this checks that such kernels, like all others, are written to the
cache once and loaded, not recompiled, by the next run of the same case (and that the run
does not announce a compilation then; engine/kernel_cache.py).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).parents[2] / "examples" / "heated_bed.yaml"


def _run(out: Path) -> str:
    exe = Path(sys.executable).with_name("thermodem")
    env = dict(os.environ, NUMBA_DEBUG_CACHE="1")
    proc = subprocess.run(
        [
            str(exe),
            "run",
            str(EXAMPLE),
            "--output",
            str(out),
            "--no-progress",
            "--end-time",
            "0.05",
        ],  # fmt: skip
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout + proc.stderr


def test_second_run_compiles_nothing(tmp_path: Path) -> None:
    _run(tmp_path / "first")  # compiles whatever earlier tests did not
    log = _run(tmp_path / "second")
    assert "data loaded" in log  # the debug output is there, kernels came from the cache
    saved = [line for line in log.splitlines() if "data saved" in line]
    assert saved == [], "recompiled in the second run:\n" + "\n".join(saved[:10])
    assert "compiling kernels" not in log  # a warm cache is not announced as cold
