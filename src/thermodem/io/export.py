"""``thermodem export``: the particle state of an output directory as CSV.

One row per particle, sorted by global id, with the columns :data:`COLUMNS`: global id,
material name, position, velocity, radius, temperature and heat rate (the sum over the
mechanisms). A run without a ``thermal`` section computed no temperature or heat rate (its
particles keep the initial temperature and 0 W): those columns are left out, and the first
line says so. The state comes from an output frame (``--frame N``, the N-th entry of
``particles.pvd``, counted from 0; negative counts from the end) or from a checkpoint
(``--checkpoint PATH``; by default the newest checkpoint of the directory). Nothing is
compiled or simulated: the VTU or HDF5 file is read as it is.

The first line is a comment with the source file, the step (checkpoints) and the time, so a
CSV reader that skips ``#`` lines (``pandas.read_csv(path, comment="#")``,
``numpy.genfromtxt``) reads the table; ``--out -`` writes to standard output.
"""

from __future__ import annotations

import csv
import io
import os
import sys
from pathlib import Path

import numpy as np

from thermodem.errors import ConfigError

COLUMNS = (
    "global_id",
    "material",
    "x",
    "y",
    "z",
    "vx",
    "vy",
    "vz",
    "radius",
    "temperature",
    "heat_rate",
)
UNITS = "positions [m], velocities [m/s], radius [m], temperature [K], heat_rate [W]"
#: The columns a run without a ``thermal`` section never computes (its particles keep the
#: initial temperature and a heat rate of 0): left out of the CSV of such a run.
THERMAL_COLUMNS = ("temperature", "heat_rate")
NO_HEAT = "no thermal section: the run computed no temperature or heat rate"


class ParticleTable:
    """Particle arrays for the CSV (any order; :func:`write_csv` sorts by global id)."""

    def __init__(
        self,
        global_id: np.ndarray,
        material: list[str],
        position: np.ndarray,
        velocity: np.ndarray,
        radius: np.ndarray,
        temperature: np.ndarray,
        heat_rate: np.ndarray,
        source: str,
    ) -> None:
        self.global_id = np.asarray(global_id, np.int64)
        self.material = material
        self.position = np.asarray(position, float).reshape(-1, 3)
        self.velocity = np.asarray(velocity, float).reshape(-1, 3)
        self.radius = np.asarray(radius, float)
        self.temperature = np.asarray(temperature, float)
        self.heat_rate = np.asarray(heat_rate, float)
        self.source = source
        self.frame_index: int | None = None
        self.heat = True  # False: a run without heat (no temperature or heat rate columns)

    @property
    def columns(self) -> tuple[str, ...]:
        if self.heat:
            return COLUMNS
        return tuple(c for c in COLUMNS if c not in THERMAL_COLUMNS)


def _case_has_heat(text: str | None) -> bool:
    """Whether a resolved case (its YAML text) has a ``thermal`` section; True when it cannot
    be read (the columns are then written as the file holds them)."""
    import yaml

    if text is None:
        return True
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError:
        return True
    return not isinstance(data, dict) or data.get("thermal") is not None


def _directory_has_heat(directory: Path) -> bool:
    """Whether the run in ``directory`` had heat, from its ``case.resolved.yaml``."""
    try:
        text = (directory / "case.resolved.yaml").read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return True
    return _case_has_heat(text)


def from_frame(directory: Path, frame: int) -> ParticleTable:
    """The particles of frame ``frame`` of ``directory/particles.pvd``."""

    from thermodem.io.vtk import PVDWriter
    from thermodem.io.vtk_read import read_name_table, read_vtu

    pvd = directory / "particles.pvd"
    if not pvd.is_file():
        raise ConfigError(f"{pvd} does not exist: no frames to export (try --checkpoint)")
    entries = [e for e in PVDWriter.read(pvd) if e[1] == 0]
    if not entries:
        raise ConfigError(f"{pvd} lists no frames")
    if not -len(entries) <= frame < len(entries):
        raise ConfigError(
            f"--frame {frame}: {pvd} has {len(entries)} frames (0 to {len(entries) - 1}, or "
            "negative from the end: -1 is the last)"
        )
    time, _, file = entries[frame]
    path = directory / file
    try:
        mesh = read_vtu(path)
    except Exception as exc:  # noqa: BLE001 (any reader failure is one message)
        raise ConfigError(f"frame {frame} ({path}) cannot be read: {exc}") from None
    data = mesh.point_data
    n = mesh.points.shape[0]
    names = read_name_table(mesh.field_data, "material_id")
    ids = data.get("material_id", data.get("type_id", np.zeros(n, np.int32)))
    material = [names[k] if 0 <= k < len(names) else str(int(k)) for k in np.asarray(ids)]

    def column(name: str, shape: tuple[int, ...] = ()) -> np.ndarray:
        return data[name] if name in data else np.full((n, *shape), np.nan)

    table = ParticleTable(
        data.get("global_id", np.arange(n)),
        material,
        mesh.points,
        column("velocity", (3,)),
        column("radius"),
        column("temperature"),
        column("heat_rate"),
        f"frame {frame % len(entries)} of {pvd} ({file}), t = {time!r} s",
    )
    table.frame_index = frame % len(entries)  # -1: the last frame's own number
    table.heat = _directory_has_heat(directory)
    return table


def from_checkpoint(path: Path) -> ParticleTable:
    """The particles of a checkpoint file."""
    from thermodem.io.checkpoint import read_checkpoint

    ckpt = read_checkpoint(path)
    p = ckpt.state["particles"]
    names = list(ckpt.state["scalars"].get("material_names", []))
    material = [names[k] if 0 <= k < len(names) else str(int(k)) for k in p["type_id"]]
    table = ParticleTable(
        p["global_id"],
        material,
        p["position"],
        p["velocity"],
        p["radius"],
        p["temperature"],
        p["heat_rate"],
        f"checkpoint {ckpt.path} ({ckpt.kind}), step {ckpt.step}, t = {ckpt.time!r} s",
    )
    table.heat = _case_has_heat(ckpt.case_yaml)
    return table


def _rows(table: ParticleTable) -> list[list[str]]:
    order = np.argsort(table.global_id, kind="stable")
    rows = []
    for i in order:
        x, v = table.position[i], table.velocity[i]
        values = (x[0], x[1], x[2], v[0], v[1], v[2], table.radius[i])
        row = [str(int(table.global_id[i])), table.material[i]]
        row += [repr(float(a)) for a in values]
        if table.heat:
            row += [repr(float(table.temperature[i])), repr(float(table.heat_rate[i]))]
        rows.append(row)
    return rows


def write_csv(
    table: ParticleTable, out: Path | None, overwrite: bool = True, given: bool = True
) -> str:
    """Write the table to ``out`` (None: standard output); returns where it went. An existing
    ``out`` is replaced only with ``overwrite``; ``given``: ``out`` is the user's ``--out``
    (else the default file in the run's directory)."""
    buffer = io.StringIO()
    units = UNITS if table.heat else f"{UNITS.rsplit(', temperature', 1)[0]}; {NO_HEAT}"
    buffer.write(f"# thermodem export: {table.source}; {units}\n")
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(table.columns)
    writer.writerows(_rows(table))
    if out is None:
        sys.stdout.write(buffer.getvalue())
        return "standard output"
    try:
        _write_file(out, buffer.getvalue(), overwrite)
    except OSError as exc:  # (a file system that refuses it: read-only, /proc, full; a name
        raise ConfigError(  # too long; no permission)
            f"{'--out ' if given else ''}{str(out)!r}{'' if given else ' (no --out)'}: the file "
            f"cannot be written: {exc.strerror or exc}; choose another --out"
        ) from None
    return str(out)


def _write_file(out: Path, text: str, overwrite: bool) -> None:
    """``text`` to the file ``out`` (through a temporary file beside it, replaced atomically);
    ConfigError for a directory, an existing file without ``overwrite``, a path under a file;
    OSError where the system refuses."""
    if out.is_dir():
        raise ConfigError(f"--out {out}: is a directory; give a file name")
    if out.exists() and not overwrite:
        raise ConfigError(f"--out {out}: the file exists; give --overwrite to replace it")
    for parent in out.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ConfigError(
                    f"--out {out}: {parent} is a file, not a directory; choose another --out"
                )
            break
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"--out {out}: its directory cannot be made: {exc.strerror}") from None
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text)
        os.replace(tmp, out)
    except OSError:
        tmp.unlink(missing_ok=True)
        raise


def export_particles(
    directory: str | os.PathLike[str],
    frame: int | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    out: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
) -> str:
    """Export one state of an output directory as CSV; returns where it was written.

    ``frame`` (an index into particles.pvd) or ``checkpoint`` (a path, or None for the newest
    checkpoint of the directory); ``out``: a file, ``"-"`` for standard output, or None for
    ``DIR/particles_frame_N.csv`` / ``DIR/particles_step_NNNNNNNNN.csv`` (files of
    thermodem's own, replaced when exported again). A file given as ``out`` that exists is
    replaced only with ``overwrite``.
    """
    from thermodem.io.checkpoint import list_checkpoints

    directory = Path(directory)
    if not directory.is_dir():
        raise ConfigError(f"{str(directory)!r} is not an output directory")
    if frame is not None and checkpoint is not None:
        raise ConfigError("give --frame or --checkpoint, not both")
    if frame is not None:
        table = from_frame(directory, int(frame))
        default = directory / f"particles_frame_{table.frame_index}.csv"
    else:
        if checkpoint is None:
            found = list_checkpoints(directory / "checkpoints")
            if not found:
                from thermodem.io.run_files import never_ran

                raise ConfigError(
                    f"no checkpoints in {directory / 'checkpoints'}"
                    + (never_ran(directory) or "; give --frame N or --checkpoint PATH")
                )
            checkpoint = found[-1]
        table = from_checkpoint(Path(checkpoint))
        stem = Path(checkpoint).stem.replace("checkpoint", "step")
        default = directory / f"particles_{stem}.csv"
    if out is None:
        return write_csv(table, default, given=False)
    if str(out) == "-":
        return write_csv(table, None)
    _refuse_run_file(directory, Path(out))
    return write_csv(table, Path(out), overwrite)


#: The files of a run that ``export --out`` never replaces, even with ``--overwrite``: the
#: run's record (its restart, ``info``, ``plot`` and ParaView read them).
RUN_FILES = (
    "timeseries.csv",
    "case.resolved.yaml",
    "status.json",
    "run.log",
    "particles.pvd",
    "walls.pvd",
    "contacts.pvd",
)


def _refuse_run_file(directory: Path, out: Path) -> None:
    """``--out`` naming a file of the run being exported (its time series, its case, a
    frame or a checkpoint): ``--overwrite`` replaced it with the CSV, and the run lost it."""
    try:
        inside = out.resolve().relative_to(directory.resolve())
    except ValueError:
        return
    if not out.exists():
        return
    parts = inside.parts
    if (len(parts) == 1 and parts[0] in RUN_FILES) or (
        len(parts) > 1 and parts[0] in ("vtk", "checkpoints")
    ):
        raise ConfigError(
            f"--out {out}: is a file of the run in {directory} ({inside}), which its restart, "
            "info, plot or ParaView read; it is never replaced (not even with --overwrite); "
            "allowed: another file name, e.g. the default (leave --out out) or "
            f"{directory / 'particles.csv'}"
        )
