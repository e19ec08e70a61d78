"""Plain text / CSV particle files: read a bed made elsewhere, write one for reuse."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from thermodem.geometry.insertion import InsertedParticles

FILE_REQUIRED_COLUMNS = ("x", "y", "z", "radius")
FILE_OPTIONAL_COLUMNS = ("vx", "vy", "vz", "temperature")

#: Header names accepted for each column (case-insensitive). ``diameter``/``d`` replace
#: ``radius`` (the radius is half of it).
COLUMN_ALIASES: dict[str, tuple[str, ...]] = {
    "x": ("x",),
    "y": ("y",),
    "z": ("z",),
    "radius": ("radius", "r", "rad"),
    "diameter": ("diameter", "d", "diam"),
    "vx": ("vx",),
    "vy": ("vy",),
    "vz": ("vz",),
    "temperature": ("temperature", "t", "temp"),
}
_CANONICAL = {alias: name for name, aliases in COLUMN_ALIASES.items() for alias in aliases}
_ALLOWED_TEXT = (
    "x, y, z, radius (or r, rad; or diameter, d), and optionally vx, vy, vz and temperature "
    "(or t, temp); in a 2D case z and vz may be left out (x y r)"
)


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


def _header_names(line: str) -> list[str]:
    """Column names of a header line: a leading ``#`` allowed, text after ``;`` or a second
    ``#`` is a comment (``# x y z r ; box 0.09 0.09 0.055``), units in brackets dropped
    (``x[m]``, ``radius (m)``), commas or blanks between names; lower case."""
    text = line.strip().lstrip("#")
    text = re.split(r"[;#]", text, maxsplit=1)[0]
    text = re.sub(r"\[[^\]]*\]|\([^)]*\)", " ", text)
    return text.replace(",", " ").lower().split()


def _is_header(line: str) -> bool:
    names = _header_names(line)
    return bool(names) and all(n in _CANONICAL for n in names)


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _content_lines(lines: Iterable[str]) -> Iterator[tuple[int, str, bool]]:
    """(line number, text, is the header) of the header and of every data line.

    The header is the first of the leading ``#`` lines that names only known columns
    (comment lines may come before it), else the first line that does not start with ``#``.
    After the header, blank lines, ``#`` lines and text after a ``#`` on a data line are
    skipped. When no line qualifies, the first non-blank line is reported as the header (so
    that the checked parser names it in its message).
    """
    header_seen = False
    first_comment: tuple[int, str] | None = None
    for lineno, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line:
            continue
        if header_seen:
            if line.startswith("#"):
                continue
            line = line.split("#", 1)[0].strip()
            if line:
                yield lineno, line, False
            continue
        if line.startswith("#"):
            if _is_header(line):
                header_seen = True
                yield lineno, line, True
            elif first_comment is None:
                first_comment = (lineno, line)
            continue
        header_seen = True
        text = line.split("#", 1)[0].strip()
        tokens = text.replace(",", " ").split()
        if first_comment is not None and tokens and _is_number(tokens[0]):
            # comment lines, then data: the header is missing (or misspelt in a comment)
            yield first_comment[0], first_comment[1], True
            yield lineno, text, False
        else:
            yield lineno, line, True
    if not header_seen and first_comment is not None:
        yield first_comment[0], first_comment[1], True


def _data_line_numbers(path: Path) -> np.ndarray:
    """Line numbers of the data lines."""
    with path.open(encoding="utf-8-sig") as f:
        numbers = [n for n, _, is_header in _content_lines(f) if not is_header]
    return np.asarray(numbers, dtype=np.int64)


def _columns(header: list[str], planar: bool = False) -> dict[str, int] | None:
    """Canonical column name -> index, None unless the header is complete and unambiguous
    (``planar``: z and vz may be missing)."""
    names = [_CANONICAL.get(n) for n in header]
    if any(n is None for n in names) or len(set(names)) != len(names):
        return None
    col = {str(n): j for j, n in enumerate(names)}
    needed = "xy" if planar else "xyz"
    if ("radius" in col) == ("diameter" in col) or any(a not in col for a in needed):
        return None
    vel = [a in col for a in (("vx", "vy") if planar else ("vx", "vy", "vz"))]
    if any(vel) and not all(vel):
        return None
    if "vz" in col and "vx" not in col:
        return None
    return col


def _parse_particle_file(path: str | Path, material: str = "", planar: bool = False) -> _ParsedFile:
    """Fast path: NumPy's C parser, no Python object per value (a 50,000-particle file needed
    ~780 B/particle of transient memory with the token-by-token parser, and left ~250 B/particle
    of fragmented heap behind). Any irregularity falls back to :func:`_parse_checked`, which
    gives the error message with file, line and column."""
    path = Path(path)
    fast = _parse_fast(path, material, planar)
    return fast if fast is not None else _parse_checked(path, material, planar)


def _parse_fast(path: Path, material: str, planar: bool = False) -> _ParsedFile | None:
    try:
        header: list[str] | None = None
        header_line = 0
        comma = False
        with path.open(encoding="utf-8-sig") as f:
            for lineno, line, is_header in _content_lines(f):
                if is_header:
                    header = _header_names(line)
                    header_line = lineno
                else:  # the first data line tells the delimiter
                    comma = "," in line
                    break
        col = _columns(header, planar) if header else None
        if col is None:
            return None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "input contained no data": the checked parser says
            data = np.loadtxt(
                path,
                dtype=np.float64,
                comments="#",
                delimiter="," if comma else None,
                skiprows=header_line,
                ndmin=2,
                encoding="utf-8-sig",  # (a BOM, as Excel writes it, is not a column name)
            )
    except (ValueError, OSError, UnicodeDecodeError):
        return None
    if data.shape[1] != len(col) or data.shape[0] == 0 or not np.isfinite(data).all():
        return None
    for name in ("radius", "diameter", "temperature"):
        if name in col and not (data[:, col[name]] > 0.0).all():
            return None
    return _assemble(data, col, "vx" in col, material, None, path)


def _assemble(
    data: np.ndarray,
    col: dict[str, int],
    has_velocity: bool,
    material: str,
    lines: np.ndarray | None,
    path: Path,
) -> _ParsedFile:
    n = data.shape[0]

    def triple(names: tuple[str, str, str]) -> np.ndarray:  # a missing z column (2D) is 0
        out = np.zeros((n, 3))
        for a, name in enumerate(names):
            if name in col:
                out[:, a] = data[:, col[name]]
        return out

    velocity = triple(("vx", "vy", "vz")) if has_velocity else np.zeros((n, 3))
    from thermodem.geometry.insertion import InsertedParticles

    if "radius" in col:
        radius = np.ascontiguousarray(data[:, col["radius"]])
    else:
        radius = 0.5 * data[:, col["diameter"]]
    particles = InsertedParticles(
        position=triple(("x", "y", "z")),
        radius=radius,
        velocity=np.ascontiguousarray(velocity),
        temperature=np.ascontiguousarray(data[:, col["temperature"]])
        if "temperature" in col
        else None,
        material=material,
    )
    return _ParsedFile(particles, lines, has_velocity, "temperature" in col, path)


def _read_text(path: Path) -> str:
    where = f"particle file {str(path)!r}"
    if not path.exists():
        hint = ""
        if "$" in str(path):
            hint = " (environment variables such as $HOME are not expanded: write the path)"
        raise ValueError(f"{where} does not exist{hint}")
    if path.is_dir():
        raise ValueError(f"{where} is a directory, expected a text file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read {where}: {exc.strerror}") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ValueError(
            f"{where}, line {line}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset "
            f"{exc.start}); particle files are plain text (save it as UTF-8 or ASCII)"
        ) from None


def _parse_checked(path: Path, material: str = "", planar: bool = False) -> _ParsedFile:
    """Token-by-token parse that names the file, line and column of the first problem."""
    text = _read_text(path)
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
            f"({_ALLOWED_TEXT})"
        )
    for name in header:
        if name not in _CANONICAL:
            if _is_number(name):
                raise ValueError(
                    f"{where}, line {header_line}: no header; the first line must name the "
                    f"columns ({_ALLOWED_TEXT}), e.g. 'x y z radius', but it starts with the "
                    f"number {name!r}"
                )
            raise ValueError(
                f"{where}, line {header_line}: unknown column {name!r} in the header; allowed "
                f"columns are {_ALLOWED_TEXT} (the first line must be the header; text after "
                "';' or '#' is a comment)"
            )
    canonical = [_CANONICAL[n] for n in header]
    duplicated = sorted({n for n in canonical if canonical.count(n) > 1})
    if duplicated:
        raise ValueError(
            f"{where}, line {header_line}: column(s) {duplicated} appear twice (names and "
            "their aliases count as the same column)"
        )
    if "radius" in canonical and "diameter" in canonical:
        raise ValueError(f"{where}, line {header_line}: give the radius or the diameter, not both")
    missing = [a for a in ("xy" if planar else "xyz") if a not in canonical]
    if "radius" not in canonical and "diameter" not in canonical:
        missing.append("radius")
    if missing:
        needed = "x, y (z optional in 2D)" if planar else "x, y, z"
        raise ValueError(
            f"{where}, line {header_line}: the header lacks required column(s) "
            f"{', '.join(missing)}; it must name {needed} and radius (or r, or diameter)"
        )
    vel_cols = [name for name in ("vx", "vy", "vz") if name in canonical]
    vel_needed = ("vx", "vy") if planar and "vz" not in canonical else ("vx", "vy", "vz")
    if vel_cols and any(v not in vel_cols for v in vel_needed):
        what = "vx, vy (and vz or not)" if planar else "vx, vy, vz"
        raise ValueError(
            f"{where}, line {header_line}: give all of {what} or none, got only "
            f"{', '.join(vel_cols)}"
        )
    if not rows:
        raise ValueError(
            f"{where} has a header (line {header_line}) but no particle rows: give one line "
            f"of {' '.join(header)} per particle"
        )
    ncol = len(header)
    lines = np.asarray(line_numbers, dtype=np.int64)
    widths = np.fromiter((len(r) for r in rows), dtype=np.int64, count=len(rows))
    bad = np.flatnonzero(widths != ncol)
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"{where}, line {lines[i]}: expected {ncol} values ({' '.join(header)}, as the "
            f"header on line {header_line} names), found {widths[i]}"
        )
    try:
        data = np.array(rows, dtype=np.float64).reshape(len(rows), ncol)
    except ValueError:
        for i, row in enumerate(rows):
            for j, token in enumerate(row):
                if not _is_number(token):
                    raise ValueError(
                        f"{where}, line {lines[i]}, column {header[j]!r}: {token!r} is not a number"
                    ) from None
        raise
    col = {name: j for j, name in enumerate(canonical)}
    nonfinite = np.argwhere(~np.isfinite(data))
    if nonfinite.size:
        i, j = (int(v) for v in nonfinite[0])
        raise ValueError(
            f"{where}, line {lines[i]}, column {header[j]!r}: value {float(data[i, j])!r} is not "
            "finite"
        )
    for name in ("radius", "diameter", "temperature"):
        if name in col:
            bad = np.flatnonzero(data[:, col[name]] <= 0.0)
            if bad.size:
                i = int(bad[0])
                unit = "K" if name == "temperature" else "m"
                raise ValueError(
                    f"{where}, line {lines[i]}, column {header[col[name]]!r}: value "
                    f"{float(data[i, col[name]])!r} must be > 0 [{unit}]"
                )
    return _assemble(data, col, bool(vel_cols), material, lines, path)


def load_particle_file(
    path: str | Path, material: str = "", planar: bool = False
) -> InsertedParticles:
    """Read particles from a whitespace- or comma-separated text file.

    The header names the columns (a leading ``#`` is allowed; comment lines may come before
    it; text after ``;`` or a second ``#`` on it is a comment, so a LIGGGHTS/Yade-style
    ``# x y z r ; box ...`` works): ``x y z radius`` are required (``r``/``rad`` for radius,
    or ``diameter``/``d`` instead), ``vx vy vz`` (all three) and ``temperature`` (``t``,
    ``temp``) are optional (:data:`COLUMN_ALIASES`); names are case-insensitive and columns
    may come in any order. Blank lines, later lines starting with ``#`` and text after ``#``
    on a data line are ignored. Missing velocity columns give zero velocities; a missing
    temperature column gives ``temperature=None``. Errors name the file, the line number and
    the column (a missing file, a header without rows, text that is not UTF-8 included).
    ``planar`` (a 2D case): ``x y r`` suffice (z = 0; ``vx vy`` without ``vz``).
    """
    return _parse_particle_file(path, material, planar).particles


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
