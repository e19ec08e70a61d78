"""Files of a run directory: run.log, frames (VTU/PVD), timeseries.csv, status.json."""

from __future__ import annotations

import csv
import datetime as _dt
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError
from thermodem.io.vtk import PVDWriter, write_particle_frame, write_wall_frame

CHECKPOINT_DIR = "checkpoints"
STATUS_FILE = "status.json"
TIMESERIES_FILE = "timeseries.csv"
LOG_FILE = "run.log"
FAILED_FILE = "failed.h5"


#: The files a run leaves when its input was refused before the first step (the record of
#: the refusal: ``status.json`` says ``failed`` with ``refused_input: true``).
REFUSED_RUN_FILES = frozenset({"case.resolved.yaml", LOG_FILE, STATUS_FILE})


def only_run_record(path: Path, ignore: str = "") -> bool:
    """``path`` holds nothing but the record files a run writes before its first step (and
    ``ignore``: the lock of the run that asks)."""
    return {child.name for child in path.iterdir()} - {ignore} <= REFUSED_RUN_FILES


def refused_run_record(path: Path) -> bool:
    """``path`` holds only the record of a run whose input was refused before its first step,
    or that a signal stopped while it was being set up (nothing a user made or a run
    computed): the next run may reuse it without --overwrite, so that after fixing the case
    the same command works (and an unfixed case is told its error again, not that the
    directory is not empty)."""
    if not (path / STATUS_FILE).is_file() or not only_run_record(path):
        return False
    status = Status.read(path)
    return status.get("refused_input") is True or status.get("not_started") is True


def never_ran(path: Path, ranks: int = 1) -> str:
    """'' or, for the record of a run refused (or stopped) before its first step, what to say
    instead of 'no checkpoints' / 'no time series': the run's own message and how to run it
    again (export, plot, info and restart of such a directory; ``ranks``: the MPI ranks of
    the command that asks, for the command it suggests)."""
    if not refused_run_record(path):
        return ""
    status = Status.read(path)
    case = f" ({status['case']})" if status.get("case") else ""
    why = (
        f"its input was refused: {status.get('message')}"
        if status.get("refused_input") is True
        else "it was stopped while it was being set up"
    )
    launch = f"mpiexec -n {ranks} thermodem" if ranks > 1 else "thermodem"
    return (
        f"; the run in {str(path)!r} never started ({STATUS_FILE}: {why}); after fixing the "
        f"case{case} run it again: {launch} run CASE --output {path}"
    )


def no_checkpoint_to_restart(path: Path, ranks: int = 1) -> str:
    """The message of ``thermodem restart DIR`` for a directory without checkpoints: the run
    that never started (:func:`never_ran`: its refusal from status.json and the command to run
    it again), or nothing to restart from."""
    why = never_ran(path, ranks)
    if why:
        return f"cannot restart {str(path)!r}: no checkpoints in {path / CHECKPOINT_DIR}{why}"
    return f"no checkpoints in {path / CHECKPOINT_DIR}; nothing to restart from"


def prepare_output_dir(path: Path, overwrite: bool) -> None:
    """Refuse an existing non-empty directory unless ``overwrite`` (never silently); the
    record of a refused input (:func:`refused_run_record`) counts as empty."""
    if path.exists() and not path.is_dir():
        raise ConfigError(f"--output {str(path)!r} exists and is not a directory")
    if path.exists() and any(path.iterdir()) and not overwrite and not refused_run_record(path):
        raise ConfigError(
            f"--output {str(path)!r} exists and is not empty; choose another "
            "directory or pass --overwrite"
        )
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # (a file system that refuses it: read-only, /proc, full)
        raise ConfigError(
            f"--output {str(path)!r}: the directory cannot be created: {exc.strerror or exc}; "
            "choose another --output"
        ) from None


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


# ------------------------------------------------------------------------------------ log
class RunLog:
    """Messages to the console and to ``run.log`` (``file_only`` lines go to the file only)."""

    def __init__(
        self, path: Path | None, console: TextIO | None = None, append: bool = False
    ) -> None:
        self.console = console
        self.file = open(path, "a" if append else "w", encoding="utf-8") if path else None  # noqa: SIM115

    def _stamp(self) -> str:
        return _dt.datetime.now().strftime("%Y-%m-%d %H:%M:%S")

    def info(self, message: str) -> None:
        if self.console is not None:
            print(message, file=self.console, flush=True)
        self.file_only(message)

    def warn(self, message: str) -> None:
        self.info(f"warning: {message}")

    def file_only(self, message: str) -> None:
        if self.file is not None:
            self.file.write(f"[{self._stamp()}] {message}\n")
            self.file.flush()

    def close(self) -> None:
        if self.file is not None:
            self.file.close()
            self.file = None


# --------------------------------------------------------------------------------- frames
class FrameWriter:
    """Writes particle and wall frames and keeps the PVD indices valid after every frame."""

    def __init__(
        self,
        out: Path,
        wall_extent: float,
        resume_time: float | None = None,
        contacts: bool = False,
    ) -> None:
        self.out = out
        (out / "vtk").mkdir(parents=True, exist_ok=True)
        self.contacts_pvd = None
        if resume_time is None:
            self.particles_pvd = PVDWriter(out / "particles.pvd")
            self.walls_pvd = PVDWriter(out / "walls.pvd")
            if contacts:
                self.contacts_pvd = PVDWriter(out / "contacts.pvd")
        else:
            self.particles_pvd = PVDWriter.resume(out / "particles.pvd", resume_time)
            self.walls_pvd = PVDWriter.resume(out / "walls.pvd", resume_time)
            if contacts:
                path = out / "contacts.pvd"
                self.contacts_pvd = (
                    PVDWriter.resume(path, resume_time) if path.exists() else PVDWriter(path)
                )
        self.wall_extent = wall_extent
        self.frames = len(self.particles_pvd.entries)
        self.last_step = -1

    def write(self, sim: Simulation) -> None:
        name = f"particles_{sim.step_count:09d}.vtu"
        write_particle_frame(self.out / "vtk" / name, sim)
        self.particles_pvd.add(sim.time, f"vtk/{name}")
        if sim.wall_rows.shape[0]:
            wname = f"walls_{sim.step_count:09d}.vtu"
            write_wall_frame(self.out / "vtk" / wname, sim, self.wall_extent)
            self.walls_pvd.add(sim.time, f"vtk/{wname}")
        if self.contacts_pvd is not None:
            self._write_contacts(sim)
        self.frames = len(self.particles_pvd.entries)
        self.last_step = sim.step_count

    def _write_contacts(self, sim: Simulation) -> None:
        """``vtk/contacts_<step>.vtu``: the touching contacts as lines with their data."""
        from thermodem.io.contacts_vtu import write_contacts_vtu

        data = sim.contacts()
        p = sim.particles
        where = np.full(int(p.global_id.max()) + 1 if p.count else 0, -1, np.int64)
        where[p.global_id] = np.arange(p.count)
        centre_i = p.position[where[data["id_i"]]]
        wall = data["wall"] >= 0
        centre_j = np.where(wall[:, None], data["point"], p.position[where[data["id_j"]]])
        name = f"contacts_{sim.step_count:09d}.vtu"
        write_contacts_vtu(self.out / "vtk" / name, data, centre_i, centre_j)
        self.contacts_pvd.add(sim.time, f"vtk/{name}")


# ----------------------------------------------------------------------------- time series
def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool | np.bool_):
        return str(int(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


class TimeseriesWriter:
    """``timeseries.csv``: ``time``, ``step`` and every key of ``sim.report()`` as columns.

    Values are written exactly (``repr`` of the float). Columns come from what the engine
    reports: when a later row has a key the header does not have yet (a heat mechanism that
    became active), the file is rewritten with the new column, earlier rows left empty there.
    With ``resume_step`` the rows after that step are dropped first (a restart).
    """

    def __init__(self, path: Path, resume_step: int | None = None) -> None:
        self.path = path
        self.columns: list[str] = []
        self.rows = 0
        self.last_step = -1
        if resume_step is not None and path.exists():
            with path.open(newline="") as f:
                reader = csv.reader(f)
                header = next(reader, None)
                kept = [r for r in reader if r and int(r[1]) <= resume_step] if header else []
            self.columns = list(header or [])
            self._rewrite(kept)
            self.rows = len(kept)
            if kept:
                self.last_step = int(kept[-1][1])
        elif path.exists():
            path.unlink()

    def _rewrite(self, rows: list[list[str]]) -> None:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        if self.columns:
            writer.writerow(self.columns)
        for r in rows:
            writer.writerow(r + [""] * (len(self.columns) - len(r)))
        _atomic_write_text(self.path, buf.getvalue())

    def write(self, sim: Simulation) -> None:
        row: dict[str, Any] = {"time": sim.time, "step": sim.step_count}
        row.update(sim.report())
        new = [k for k in row if k not in self.columns]
        if new:
            old_rows: list[list[str]] = []
            if self.path.exists() and self.columns:
                with self.path.open(newline="") as f:
                    old_rows = list(csv.reader(f))[1:]
            self.columns += new
            self._rewrite(old_rows)
        with self.path.open("a", newline="") as f:
            csv.writer(f, lineterminator="\n").writerow([_cell(row.get(c)) for c in self.columns])
        self.rows += 1
        self.last_step = sim.step_count


def read_timeseries(path: Path) -> dict[str, np.ndarray]:
    """Columns of a ``timeseries.csv`` as float arrays (empty cells are NaN). A cell that is
    not a number (another file written over it: a CSV of particles, a text) is a ConfigError
    naming the file, the line and the column, not a ValueError traceback."""
    with Path(path).open(newline="") as f:
        reader = csv.reader(f)
        header = next(reader, [])
        rows = [(reader.line_num, r) for r in reader if r]
    out = {}
    for k, name in enumerate(header):
        values = []
        for line, r in rows:
            cell = r[k] if k < len(r) else ""
            try:
                values.append(float(cell) if cell != "" else math.nan)
            except ValueError:
                raise ConfigError(
                    f"{path}, line {line}, column {name!r}: {cell[:40]!r} is not a number; "
                    "it is not a time series thermodem wrote (every cell is a number): was "
                    "another file written over it?"
                ) from None
        out[name] = np.array(values)
    return out


# --------------------------------------------------------------------------------- status
@dataclass
class Status:
    """``status.json``: what ``thermodem info`` reports about a running or finished run."""

    path: Path
    data: dict[str, Any] = field(default_factory=dict)

    def update(self, **values: Any) -> None:
        self.data.update(values)
        self.data["updated"] = _dt.datetime.now().isoformat(timespec="seconds")
        _atomic_write_text(self.path, json.dumps(self.data, indent=2) + "\n")

    @staticmethod
    def read(directory: Path) -> dict[str, Any]:
        path = Path(directory) / STATUS_FILE
        if not path.exists():
            return {}
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError):
            return {}


# ------------------------------------------------------------------------------- progress
