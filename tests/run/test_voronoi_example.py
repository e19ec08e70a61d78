"""examples/voronoi_bed.yaml runs from the command line as a user runs it: the tessellation's
cost is in run.log, the walls heat the bed through the Voronoi faces, the ledger closes."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_voronoi_example_runs(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.run(
        [str(Path(sys.executable).with_name("thermodem")), "run",
         str(ROOT / "examples" / "voronoi_bed.yaml"), "--output", str(out)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    log = (out / "run.log").read_text(encoding="utf-8")
    assert "tessellation 2 (plain)" in log and "compiled clipped cells" in log
    rows = list(csv.DictReader((out / "timeseries.csv").open(encoding="utf-8")))
    last = rows[-1]
    gas = float(last["heat_in_wall_indirect_conduction"])
    contact = float(last["heat_in_wall_direct_conduction"])
    assert gas > contact > 0.0
    assert int(float(last["tessellation_count"])) > 2
    assert abs(float(last["heat_balance_error"])) < 1e-9 * gas
