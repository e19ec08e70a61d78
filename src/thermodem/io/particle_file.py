"""Plain text / CSV particle files: read a bed made elsewhere, write one for reuse."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from thermodem.geometry.insertion import InsertedParticles

FILE_REQUIRED_COLUMNS = ("x", "y", "z", "radius")
FILE_OPTIONAL_COLUMNS = ("vx", "vy", "vz", "temperature")


@dataclass
class _ParsedFile:
    particles: InsertedParticles
    lines: np.ndarray | None  # file line of each particle (None: computed when asked for)
    has_velocity: bool
    has_temperature: bool
    path: Path

    @property
    def line_numbers(self) -> np.ndarray:
        """The file line of each particle (for error messages)."""
        if self.lines is None:
            self.lines = _data_line_numbers(self.path)
        return self.lines


def _content_lines(lines: Iterable[str]) -> Iterator[tuple[int, str, bool]]:
    """(line number, stripped text, is the header) of the header and of every data line: the
    header is the first non-blank line (a leading # allowed); blank lines and later # lines
    are skipped."""
    header_seen = False
    for lineno, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or (header_seen and line.startswith("#")):
            continue
        yield lineno, line, not header_seen
        header_seen = True


def _header_names(line: str) -> list[str]:
    return line.lstrip("#").replace(",", " ").lower().split()


def _data_line_numbers(path: Path) -> np.ndarray:
    """Line numbers of the data lines."""
    with path.open() as f:
        numbers = [n for n, _, is_header in _content_lines(f) if not is_header]
    return np.asarray(numbers, dtype=np.int64)


def _parse_particle_file(path: str | Path, material: str = "") -> _ParsedFile:
    """Fast path: NumPy's C parser, no Python object per value (a 50,000-particle file needed
    ~780 B/particle of transient memory with the token-by-token parser, and left ~250 B/particle
    of fragmented heap behind). Any irregularity falls back to :func:`_parse_checked`, which
    gives the error message with file, line and column."""
    path = Path(path)
    fast = _parse_fast(path, material)
    return fast if fast is not None else _parse_checked(path, material)


def _parse_fast(path: Path, material: str) -> _ParsedFile | None:
    try:
        header: list[str] | None = None
        header_line = 0
        comma = False
        with path.open() as f:
            for lineno, line, is_header in _content_lines(f):
                if is_header:
                    header = _header_names(line)
                    header_line = lineno
                else:  # the first data line tells the delimiter
                    comma = "," in line
                    break
        if not header or len(set(header)) != len(header):
            return None
        allowed = FILE_REQUIRED_COLUMNS + FILE_OPTIONAL_COLUMNS
        if any(name not in allowed for name in header) or any(
            name not in header for name in FILE_REQUIRED_COLUMNS
        ):
            return None
        vel = [name in header for name in ("vx", "vy", "vz")]
        if any(vel) and not all(vel):
            return None
        data = np.loadtxt(
            path,
            dtype=np.float64,
            comments="#",
            delimiter="," if comma else None,
            skiprows=header_line,
            ndmin=2,
        )
    except (ValueError, OSError, UnicodeDecodeError):
        return None
    if data.shape[1] != len(header) or data.shape[0] == 0 or not np.isfinite(data).all():
        return None
    col = {name: j for j, name in enumerate(header)}
    for name in ("radius", "temperature"):
        if name in col and not (data[:, col[name]] > 0.0).all():
            return None
    return _assemble(data, col, all(vel), material, None, path)


def _assemble(
    data: np.ndarray,
    col: dict[str, int],
    has_velocity: bool,
    material: str,
    lines: np.ndarray | None,
    path: Path,
) -> _ParsedFile:
    n = data.shape[0]
    velocity = data[:, [col["vx"], col["vy"], col["vz"]]] if has_velocity else np.zeros((n, 3))
    from thermodem.geometry.insertion import InsertedParticles

    particles = InsertedParticles(
        position=np.ascontiguousarray(data[:, [col["x"], col["y"], col["z"]]]),
        radius=np.ascontiguousarray(data[:, col["radius"]]),
        velocity=np.ascontiguousarray(velocity),
        temperature=np.ascontiguousarray(data[:, col["temperature"]])
        if "temperature" in col
        else None,
        material=material,
    )
    return _ParsedFile(particles, lines, has_velocity, "temperature" in col, path)


def _parse_checked(path: Path, material: str = "") -> _ParsedFile:
    """Token-by-token parse that names the file, line and column of the first problem."""
    try:
        text = path.read_text()
    except OSError as exc:
        raise ValueError(f"cannot read particle file {str(path)!r}: {exc}") from exc
    allowed = FILE_REQUIRED_COLUMNS + FILE_OPTIONAL_COLUMNS
    header: list[str] | None = None
    header_line = 0
    rows: list[list[str]] = []
    line_numbers: list[int] = []
    for lineno, line, is_header in _content_lines(text.splitlines()):
        if is_header:
            header = _header_names(line)
            header_line = lineno
            continue
        rows.append(line.replace(",", " ").split())
        line_numbers.append(lineno)
    where = f"particle file {str(path)!r}"
    if not header:
        raise ValueError(
            f"{where} is empty: the first line must be a header naming the columns "
            f"({' '.join(FILE_REQUIRED_COLUMNS)} required; {' '.join(FILE_OPTIONAL_COLUMNS)} "
            "optional)"
        )
    for name in header:
        if name not in allowed:
            raise ValueError(
                f"{where}, line {header_line}: unknown column {name!r} in the header; allowed "
                f"columns are {', '.join(allowed)} (the first line must be the header)"
            )
    duplicated = sorted({name for name in header if header.count(name) > 1})
    if duplicated:
        raise ValueError(f"{where}, line {header_line}: column(s) {duplicated} appear twice")
    missing = [name for name in FILE_REQUIRED_COLUMNS if name not in header]
    if missing:
        raise ValueError(
            f"{where}, line {header_line}: the header lacks required column(s) "
            f"{', '.join(missing)}; it must name x, y, z and radius"
        )
    vel_cols = [name for name in ("vx", "vy", "vz") if name in header]
    if vel_cols and len(vel_cols) != 3:
        raise ValueError(
            f"{where}, line {header_line}: give all of vx, vy, vz or none, got only "
            f"{', '.join(vel_cols)}"
        )
    ncol = len(header)
    lines = np.asarray(line_numbers, dtype=np.int64)
    widths = np.fromiter((len(r) for r in rows), dtype=np.int64, count=len(rows))
    bad = np.flatnonzero(widths != ncol)
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"{where}, line {lines[i]}: expected {ncol} values ({' '.join(header)}), "
            f"found {widths[i]}"
        )
    try:
        data = np.array(rows, dtype=np.float64).reshape(len(rows), ncol)
    except ValueError:
        for i, row in enumerate(rows):
            for j, token in enumerate(row):
                try:
                    float(token)
                except ValueError:
                    raise ValueError(
                        f"{where}, line {lines[i]}, column {header[j]!r}: {token!r} is not a number"
                    ) from None
        raise
    col = {name: j for j, name in enumerate(header)}
    nonfinite = np.argwhere(~np.isfinite(data))
    if nonfinite.size:
        i, j = (int(v) for v in nonfinite[0])
        raise ValueError(
            f"{where}, line {lines[i]}, column {header[j]!r}: value {data[i, j]!r} is not finite"
        )
    for name in ("radius", "temperature"):
        if name in col:
            bad = np.flatnonzero(data[:, col[name]] <= 0.0)
            if bad.size:
                i = int(bad[0])
                raise ValueError(
                    f"{where}, line {lines[i]}, column {name!r}: value {data[i, col[name]]!r} "
                    "must be > 0"
                )
    return _assemble(data, col, bool(vel_cols), material, lines, path)


def load_particle_file(path: str | Path, material: str = "") -> InsertedParticles:
    """Read particles from a whitespace- or comma-separated text file.

    The first non-blank line is the header naming the columns (a leading ``#`` is allowed):
    ``x y z radius`` are required, ``vx vy vz`` (all three) and ``temperature`` are optional;
    columns may come in any order. Blank lines and later lines starting with ``#`` are ignored.
    Missing velocity columns give zero velocities; a missing temperature column gives
    ``temperature=None``. Errors name the file, the line number and the column.
    """
    return _parse_particle_file(path, material).particles


def save_particle_file(path: str | Path, particles: InsertedParticles) -> None:
    """Write particles in the format read by :func:`load_particle_file` (whitespace separated).

    Velocities are always written; temperatures when present.
    """
    columns = ["x", "y", "z", "radius", "vx", "vy", "vz"]
    blocks = [particles.position, particles.radius[:, None], particles.velocity]
    if particles.temperature is not None:
        columns.append("temperature")
        blocks.append(particles.temperature[:, None])
    np.savetxt(path, np.hstack(blocks), fmt="%.17g", header=" ".join(columns), comments="")
