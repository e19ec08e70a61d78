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


def test_a_kernels_cache_stamp_covers_the_modules_it_imports_and_nothing_else(
    tmp_path: Path,
) -> None:
    """An edit to a model module invalidates the kernels that can inline it (the pair
    passes), not the neighbour search or the integrator; an edit to the orchestration
    invalidates no kernel (thermodem/_numba_cache.py)."""
    import shutil

    from thermodem import _numba_cache as cache

    root = tmp_path / "thermodem"
    shutil.copytree(cache.PACKAGE_ROOT, root, ignore=shutil.ignore_patterns("__pycache__"))
    kernels = ["kernels/neighbors.py", "kernels/integrate.py", "kernels/pair_pass.py",
               "kernels/heat_terms.py", "kernels/conditions.py"]  # fmt: skip

    def stamps() -> dict[str, str]:
        return {k: cache.compute_stamp(root / k, root) for k in kernels}

    before = stamps()
    assert stamps() == before  # deterministic
    with open(root / "models/thermal/direct_conduction.py", "a") as f:
        f.write("\n# an edit\n")
    after_model = stamps()
    changed = {k for k in kernels if after_model[k] != before[k]}
    assert changed == {"kernels/pair_pass.py", "kernels/heat_terms.py"}
    with open(root / "engine/runner.py", "a") as f:
        f.write("\n# an edit\n")
    with open(root / "cli.py", "a") as f:
        f.write("\n# an edit\n")
    assert stamps() == after_model
    with open(root / "geometry/wall_layout.py", "a") as f:
        f.write("\n# an edit\n")
    assert stamps()["kernels/neighbors.py"] != after_model["kernels/neighbors.py"]
