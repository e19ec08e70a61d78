"""Fields on a regular (rectilinear) grid read from files: the fluid of a CFD result.

:func:`read_grid_field` returns the three grid axes (strictly increasing) and the values on
the grid, shape (nx, ny, nz, components), for

- ``.npz``: arrays ``x``, ``y``, ``z`` (the axes) and the field, shape (nx, ny, nz) or
  (nx, ny, nz, 3) (or three scalar arrays for a vector);
- ``.csv``: a header row, then one row per grid point in any order, columns ``x, y, z`` (or
  ParaView's ``Points:0, Points:1, Points:2``) and the field: ``NAME``, or for a vector
  ``NAME:0, NAME:1, NAME:2`` (ParaView), ``NAME_x, NAME_y, NAME_z`` or ``NAMEx, NAMEy, NAMEz``
  (or three column names);
- VTK XML ``.vti`` (ImageData), ``.vtr`` (RectilinearGrid), ``.vts`` (StructuredGrid whose
  points form a rectilinear lattice), with ``ascii``, inline ``binary`` or ``appended``
  (raw or base64) data arrays, uncompressed or compressed with zlib or LZMA, UInt32 or UInt64
  headers, either byte order: what ParaView and the VTK writers of CFD codes produce. One
  piece per file (the parallel ``.pv*`` collections are not read);
- legacy ``.vtk`` (structured points, rectilinear or structured grid; ASCII or binary).

Point data are located at the grid points; cell data at the cell centres (``location``:
``auto`` takes point data when the file has the field there, else cell data). Every value
must be finite. Errors are ``ValueError`` with a message naming the file and what is wrong.
"""

from __future__ import annotations

import base64
import lzma
import math
import re
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import numpy as np

VTK_TYPES = {
    "Int8": "i1", "UInt8": "u1", "Int16": "i2", "UInt16": "u2", "Int32": "i4", "UInt32": "u4",
    "Int64": "i8", "UInt64": "u8", "Float32": "f4", "Float64": "f8",
}  # fmt: skip
VECTOR_SUFFIXES = ((":0", ":1", ":2"), ("_x", "_y", "_z"), ("x", "y", "z"), ("_X", "_Y", "_Z"))

Grid = tuple[tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def read_grid_field(
    path: str | Path, field: str | tuple[str, ...], components: int, location: str = "auto"
) -> Grid:
    """((x, y, z) axes, values (nx, ny, nz, components)) of ``field`` in the grid file."""
    path = Path(path)
    if not path.exists():
        raise ValueError(f"grid file {str(path)!r} does not exist")
    if path.is_dir():
        raise ValueError(f"grid file {str(path)!r} is a directory")
    suffix = path.suffix.lower()
    names = (field,) if isinstance(field, str) else tuple(field)
    if components == 1 and len(names) != 1:
        raise ValueError(f"{path}: a scalar field takes one array name, got {list(names)}")
    try:
        if suffix == ".npz":
            axes, values = _read_npz(path, names, components)
        elif suffix == ".csv":
            axes, values = _read_csv(path, names, components)
        elif suffix in (".vti", ".vtr", ".vts"):
            axes, values = _read_vtk_xml(path, names, components, location)
        elif suffix == ".vtk":
            axes, values = _read_vtk_legacy(path, names, components, location)
        else:
            raise ValueError(f"unknown grid file format {suffix!r}")
    except ValueError as exc:
        message = str(exc)
        raise ValueError(message if str(path) in message else f"{path}: {message}") from None
    except (OSError, KeyError, zlib.error, lzma.LZMAError, ET.ParseError) as exc:
        raise ValueError(f"{path}: cannot be read as a grid field: {exc}") from None
    return _checked(path, axes, values, components)


def _checked(path: Path, axes, values: np.ndarray, components: int) -> Grid:  # noqa: ANN001
    axes = tuple(np.ascontiguousarray(a, np.float64) for a in axes)
    for name, a in zip("xyz", axes, strict=True):
        if a.ndim != 1 or a.size < 1 or not np.isfinite(a).all():
            raise ValueError(f"{path}: the {name} axis must be finite numbers, got {a!r}")
        if a.size > 1 and not np.all(np.diff(a) > 0):
            raise ValueError(f"{path}: the {name} axis must increase strictly")
    values = np.asarray(values, np.float64)
    if values.ndim == 3:
        values = values[..., None]
    shape = tuple(a.size for a in axes)
    if values.shape != (*shape, components):
        raise ValueError(
            f"{path}: the field has shape {values.shape}, expected {(*shape, components)} "
            f"for the grid's {shape[0]} × {shape[1]} × {shape[2]} points"
        )
    bad = ~np.isfinite(values)
    if bad.any():
        k = np.argwhere(bad)[0]
        where = tuple(int(v) for v in k[:3])
        raise ValueError(f"{path}: value {float(values[tuple(k)])!r} at grid index {where}")
    return axes, np.ascontiguousarray(values)


# ------------------------------------------------------------------------------ NPZ, CSV
def _read_npz(path: Path, names: tuple[str, ...], components: int):  # noqa: ANN202
    with np.load(path, allow_pickle=False) as data:
        for key in ("x", "y", "z", *names):
            if key not in data:
                raise ValueError(f"has no array {key!r}; arrays: {', '.join(data.files)}")
        axes = (data["x"], data["y"], data["z"])
        if len(names) == 1:
            values = np.asarray(data[names[0]], np.float64)
        else:
            values = np.stack([np.asarray(data[n], np.float64) for n in names], axis=-1)
    if components == 3 and values.ndim == 3:
        raise ValueError(f"array {names[0]!r} is a scalar field; a vector needs shape (..., 3)")
    return axes, values


def _vector_columns(header: list[str], name: str) -> tuple[str, ...] | None:
    for suffixes in VECTOR_SUFFIXES:
        cols = tuple(name + s for s in suffixes)
        if all(c in header for c in cols):
            return cols
    return None


def _read_csv(path: Path, names: tuple[str, ...], components: int):  # noqa: ANN202
    with open(path, encoding="utf-8") as f:
        first = f.readline()
    header = [h.strip().strip('"') for h in first.split(",")]
    coords = ("x", "y", "z") if all(c in header for c in "xyz") else None
    if coords is None and all(f"Points:{a}" in header for a in range(3)):
        coords = ("Points:0", "Points:1", "Points:2")
    if coords is None:
        raise ValueError(f"the header has no columns x, y, z (or Points:0..2): {header}")
    cols: tuple[str, ...] | None = names
    if components == 3 and len(names) == 1:
        cols = _vector_columns(header, names[0])
        if cols is None:
            raise ValueError(
                f"no columns for the vector {names[0]!r} ({names[0]}:0..2, {names[0]}_x.., "
                f"{names[0]}x..); columns: {header}"
            )
    for c in cols:
        if c not in header:
            raise ValueError(f"no column {c!r}; columns: {header}")
    table = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if table.shape[1] != len(header):
        raise ValueError(f"rows have {table.shape[1]} values, the header {len(header)} names")
    points = table[:, [header.index(c) for c in coords]]
    data = table[:, [header.index(c) for c in cols]]
    return lattice_from_points(points, data)


def _cluster(values: np.ndarray) -> np.ndarray:
    """The distinct coordinates of one axis (values closer than 1e-9 of the extent merge)."""
    v = np.sort(values)
    tol = 1e-9 * max(float(v[-1] - v[0]), abs(float(v[-1])), 1e-300)
    keep = np.concatenate(([True], np.diff(v) > tol))
    return v[keep], tol


def lattice_from_points(points: np.ndarray, data: np.ndarray):  # noqa: ANN201
    """(axes, values) of data given at points that form a full rectilinear lattice."""
    axes = []
    index = []
    for a in range(3):
        axis, tol = _cluster(points[:, a])
        k = np.clip(np.searchsorted(axis, points[:, a] - tol), 0, axis.size - 1)
        if np.any(np.abs(axis[k] - points[:, a]) > tol):  # pragma: no cover - by construction
            raise ValueError("points do not lie on a lattice")
        axes.append(axis)
        index.append(k)
    shape = tuple(a.size for a in axes)
    if points.shape[0] != shape[0] * shape[1] * shape[2]:
        raise ValueError(
            f"the {points.shape[0]} points do not form a full rectilinear grid (their distinct "
            f"coordinates make a {shape[0]} × {shape[1]} × {shape[2]} lattice)"
        )
    values = np.full((*shape, data.shape[1]), np.nan)
    flat = (index[0] * shape[1] + index[1]) * shape[2] + index[2]
    if np.unique(flat).size != flat.size:
        raise ValueError("two rows have the same grid point")
    values.reshape(-1, data.shape[1])[flat] = data
    return tuple(axes), values


# ------------------------------------------------------------------------------ VTK XML
class _Vtk:
    """The header of a VTK XML file and its appended data (see the module docstring)."""

    def __init__(self, path: Path) -> None:
        raw = path.read_bytes()
        start = raw.find(b"<AppendedData")
        self.appended = b""
        self.appended_encoding = "raw"
        if start >= 0:
            tag_end = raw.index(b">", start)
            tag = raw[start : tag_end + 1].decode("ascii", "replace")
            m = re.search(r'encoding\s*=\s*"(\w+)"', tag)
            self.appended_encoding = m.group(1) if m else "raw"
            underscore = raw.index(b"_", tag_end)
            stop = raw.rfind(b"</AppendedData>")
            body = raw[underscore + 1 : stop if stop > underscore else len(raw)]
            self.appended = body.strip() if self.appended_encoding == "base64" else body
            raw = raw[:start] + b"</VTKFile>"
        self.root = ET.fromstring(raw)
        if self.root.tag != "VTKFile":
            raise ValueError(f"not a VTK XML file (root element {self.root.tag!r})")
        self.order = "<" if self.root.get("byte_order", "LittleEndian") == "LittleEndian" else ">"
        header = self.root.get("header_type", "UInt32")
        if header not in ("UInt32", "UInt64"):
            raise ValueError(f"header_type {header!r} is not UInt32 or UInt64")
        self.header = np.dtype(self.order + VTK_TYPES[header])
        self.compressor = self.root.get("compressor", "")
        if self.compressor not in ("", "vtkZLibDataCompressor", "vtkLZMADataCompressor"):
            raise ValueError(
                f"compressor {self.compressor!r} is not supported (zlib, LZMA or none; save "
                "the file again with one of those)"
            )

    def _inflate(self, block: bytes) -> bytes:
        if self.compressor == "vtkZLibDataCompressor":
            return zlib.decompress(block)
        return lzma.decompress(block)

    def _blocks(self, header: np.ndarray, data: bytes) -> bytes:
        nblocks = int(header[0])
        sizes = header[3 : 3 + nblocks].astype(np.int64)
        out = []
        pos = 0
        for s in sizes:
            out.append(self._inflate(data[pos : pos + int(s)]))
            pos += int(s)
        return b"".join(out)

    def _from_base64(self, text: bytes) -> bytes:
        text = b"".join(text.split())
        hs = self.header.itemsize
        if self.compressor:
            first = base64.b64decode(text[: 4 * hs])  # 3 header values
            nblocks = int(np.frombuffer(first[:hs], self.header)[0])
            chars = 4 * math.ceil((3 + nblocks) * hs / 3)
            header = np.frombuffer(base64.b64decode(text[:chars])[: (3 + nblocks) * hs],
                                   self.header)  # fmt: skip
            return self._blocks(header, base64.b64decode(text[chars:]))
        chars = 4 * math.ceil(hs / 3)
        if text[chars - 1 : chars] == b"=":  # the header was encoded on its own
            size = int(np.frombuffer(base64.b64decode(text[:chars])[:hs], self.header)[0])
            return base64.b64decode(text[chars:])[:size]
        stream = base64.b64decode(text)
        size = int(np.frombuffer(stream[:hs], self.header)[0])
        return stream[hs : hs + size]

    def _from_raw(self, offset: int) -> bytes:
        hs = self.header.itemsize
        data = self.appended
        if self.compressor:
            nblocks = int(np.frombuffer(data[offset : offset + hs], self.header)[0])
            header = np.frombuffer(data[offset : offset + (3 + nblocks) * hs], self.header)
            start = offset + (3 + nblocks) * hs
            total = int(header[3 : 3 + nblocks].astype(np.int64).sum())
            return self._blocks(header, data[start : start + total])
        size = int(np.frombuffer(data[offset : offset + hs], self.header)[0])
        return data[offset + hs : offset + hs + size]

    def array(self, node: ET.Element) -> np.ndarray:
        """The values of a DataArray element, shape (n, components)."""
        kind = node.get("type", "")
        if kind not in VTK_TYPES:
            raise ValueError(f"DataArray {node.get('Name')!r}: type {kind!r} is not numeric")
        dtype = np.dtype(self.order + VTK_TYPES[kind])
        ncomp = int(node.get("NumberOfComponents", "1"))
        fmt = node.get("format", "ascii")
        if fmt == "ascii":
            values = np.array((node.text or "").split(), dtype=np.float64)
        elif fmt == "binary":
            values = np.frombuffer(self._from_base64((node.text or "").encode()), dtype)
        elif fmt == "appended":
            offset = int(node.get("offset", "0"))
            if self.appended_encoding == "base64":
                chunk = self.appended[offset:]
                values = np.frombuffer(self._from_base64(chunk), dtype)
            else:
                values = np.frombuffer(self._from_raw(offset), dtype)
        else:
            raise ValueError(f"DataArray format {fmt!r} is not ascii, binary or appended")
        values = np.asarray(values, np.float64)
        if values.size % ncomp:
            raise ValueError(f"DataArray {node.get('Name')!r}: {values.size} values for {ncomp} "
                             "components")  # fmt: skip
        return values.reshape(-1, ncomp)


def _floats(text: str | None, count: int, what: str) -> list[float]:
    values = [float(v) for v in (text or "").split()]
    if len(values) != count:
        raise ValueError(f"{what} needs {count} numbers, got {text!r}")
    return values


def _field(vtk: _Vtk, piece: ET.Element, names: tuple[str, ...], components: int,
           location: str) -> tuple[np.ndarray, str]:  # fmt: skip
    """(values (n, components), 'point' or 'cell') of the named array(s) of a piece."""
    found: dict[str, dict[str, ET.Element]] = {}
    for where, tag in (("point", "PointData"), ("cell", "CellData")):
        group = piece.find(tag)
        found[where] = {} if group is None else {a.get("Name"): a for a in group.iter("DataArray")}
    order = {"auto": ("point", "cell"), "point": ("point",), "cell": ("cell",)}[location]
    for where in order:
        if all(n in found[where] for n in names):
            parts = [vtk.array(found[where][n]) for n in names]
            values = np.concatenate(parts, axis=1)
            if values.shape[1] != components:
                raise ValueError(
                    f"array {'/'.join(names)!r} has {values.shape[1]} components, expected "
                    f"{components}"
                )
            return values, where
    have = {w: sorted(k for k in found[w] if k) for w in found}
    raise ValueError(
        f"no {location if location != 'auto' else 'point or cell'} data array "
        f"{'/'.join(names)!r}; point data: {have['point']}, cell data: {have['cell']}"
    )


def _centres(axis: np.ndarray) -> np.ndarray:
    return axis if axis.size == 1 else 0.5 * (axis[1:] + axis[:-1])


def _grid_values(values: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """VTK order (x fastest) to (nx, ny, nz, components)."""
    nx, ny, nz = shape
    if values.shape[0] != nx * ny * nz:
        raise ValueError(f"{values.shape[0]} values for a {nx} × {ny} × {nz} grid")
    return values.reshape(nz, ny, nx, -1).transpose(2, 1, 0, 3)


def _read_vtk_xml(path: Path, names: tuple[str, ...], components: int, location: str):  # noqa: ANN202
    vtk = _Vtk(path)
    kind = vtk.root.get("type", "")
    expected = {".vti": "ImageData", ".vtr": "RectilinearGrid", ".vts": "StructuredGrid"}
    if kind != expected[path.suffix.lower()]:
        raise ValueError(f"file type {kind!r}, expected {expected[path.suffix.lower()]!r}")
    grid = vtk.root.find(kind)
    if grid is None:
        raise ValueError(f"no {kind} element")
    pieces = grid.findall("Piece")
    if len(pieces) != 1:
        raise ValueError(f"{len(pieces)} pieces; one piece per file is read (merge them first)")
    piece = pieces[0]
    extent = [int(v) for v in (piece.get("Extent") or grid.get("WholeExtent", "")).split()]
    if len(extent) != 6:
        raise ValueError("no Extent of 6 integers")
    shape = tuple(extent[2 * a + 1] - extent[2 * a] + 1 for a in range(3))
    if kind == "ImageData":
        origin = _floats(grid.get("Origin", "0 0 0"), 3, "Origin")
        spacing = _floats(grid.get("Spacing", "1 1 1"), 3, "Spacing")
        direction = grid.get("Direction")
        if direction is not None and not np.allclose(
            _floats(direction, 9, "Direction"), np.eye(3).ravel()
        ):
            raise ValueError(f"a rotated image (Direction {direction}) is not supported")
        axes = [origin[a] + spacing[a] * np.arange(extent[2 * a], extent[2 * a + 1] + 1)
                for a in range(3)]  # fmt: skip
    elif kind == "RectilinearGrid":
        coords = piece.find("Coordinates")
        if coords is None or len(coords.findall("DataArray")) != 3:
            raise ValueError("no Coordinates with three DataArrays")
        axes = [vtk.array(node)[:, 0] for node in coords.findall("DataArray")]
    else:
        points_node = piece.find("Points/DataArray")
        if points_node is None:
            raise ValueError("no Points")
        pts = _grid_values(vtk.array(points_node), shape)  # (nx, ny, nz, 3)
        axes = [pts[:, 0, 0, 0], pts[0, :, 0, 1], pts[0, 0, :, 2]]
        lattice = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        scale = max(float(np.abs(pts).max()), 1e-300)
        if not np.allclose(pts, lattice, rtol=0, atol=1e-9 * scale):
            raise ValueError(
                "the structured grid is curvilinear (its points do not form a rectilinear "
                "lattice): resample it onto an image or rectilinear grid"
            )
    values, where = _field(vtk, piece, names, components, location)
    axes = [np.asarray(a, np.float64) for a in axes]
    if where == "cell":
        axes = [_centres(a) for a in axes]
        shape = tuple(a.size for a in axes)
    return tuple(axes), _grid_values(values, shape)


LEGACY_TYPES = {
    "bit": "u1", "unsigned_char": "u1", "char": "i1", "unsigned_short": "u2", "short": "i2",
    "unsigned_int": "u4", "int": "i4", "unsigned_long": "u8", "long": "i8", "float": "f4",
    "double": "f8", "vtktypeint64": "i8", "vtktypeuint64": "u8",
}  # fmt: skip


class _Legacy:
    """A cursor over a legacy VTK file (ASCII, or BINARY: big-endian raw values)."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0
        lines = [self.line() for _ in range(3)]
        if not lines[0].lower().startswith("# vtk datafile"):
            raise ValueError("not a legacy VTK file (no '# vtk DataFile' first line)")
        kind = lines[2].strip().upper()
        if kind not in ("ASCII", "BINARY"):
            raise ValueError(f"third line must be ASCII or BINARY, got {lines[2]!r}")
        self.binary = kind == "BINARY"

    def line(self) -> str:
        end = self.data.find(b"\n", self.pos)
        end = len(self.data) if end < 0 else end
        text = self.data[self.pos : end].decode("ascii", "replace").rstrip("\r")
        self.pos = end + 1
        return text

    def words(self) -> list[str]:
        """The next non-blank line, split (None at the end of the file)."""
        while self.pos < len(self.data):
            text = self.line().strip()
            if text:
                return text.split()
        return []

    def values(self, count: int, kind: str) -> np.ndarray:
        if kind.lower() not in LEGACY_TYPES:
            raise ValueError(f"data type {kind!r} is not numeric")
        if self.binary:
            dtype = np.dtype(">" + LEGACY_TYPES[kind.lower()])
            size = count * dtype.itemsize
            out = np.frombuffer(self.data[self.pos : self.pos + size], dtype)
            if out.size != count:
                raise ValueError(f"the file ends inside a block of {count} {kind} values")
            self.pos += size
            if self.data[self.pos : self.pos + 1] == b"\n":
                self.pos += 1
            return out.astype(np.float64)
        out: list[str] = []
        while len(out) < count:
            words = self.words()
            if not words:
                raise ValueError(f"the file ends inside a block of {count} values")
            out.extend(words)
        if len(out) != count:
            raise ValueError(f"a block of {count} values has {len(out)}")
        return np.array(out, dtype=np.float64)


def _read_vtk_legacy(path: Path, names: tuple[str, ...], components: int, location: str):  # noqa: ANN202
    f = _Legacy(path.read_bytes())
    words = f.words()
    if len(words) != 2 or words[0].upper() != "DATASET":
        raise ValueError(f"expected DATASET, got {' '.join(words)!r}")
    dataset = words[1].upper()
    if dataset not in ("STRUCTURED_POINTS", "RECTILINEAR_GRID", "STRUCTURED_GRID"):
        raise ValueError(f"dataset {dataset} is not a structured grid (structured points, "
                         "rectilinear or structured grid)")  # fmt: skip
    dims: list[int] = []
    origin, spacing = [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]
    coords: list[np.ndarray] = []
    points = None
    arrays: dict[str, dict[str, np.ndarray]] = {"point": {}, "cell": {}}
    where = ""
    count = 0
    while True:
        words = f.words()
        if not words:
            break
        key = words[0].upper()
        if key == "DIMENSIONS":
            dims = [int(v) for v in words[1:4]]
        elif key == "ORIGIN":
            origin = [float(v) for v in words[1:4]]
        elif key in ("SPACING", "ASPECT_RATIO"):
            spacing = [float(v) for v in words[1:4]]
        elif key in ("X_COORDINATES", "Y_COORDINATES", "Z_COORDINATES"):
            coords.append(f.values(int(words[1]), words[2]))
        elif key == "POINTS":
            points = f.values(3 * int(words[1]), words[2]).reshape(-1, 3)
        elif key in ("POINT_DATA", "CELL_DATA"):
            where = "point" if key == "POINT_DATA" else "cell"
            count = int(words[1])
        elif key == "SCALARS":
            ncomp = int(words[3]) if len(words) > 3 else 1
            table = f.words()  # LOOKUP_TABLE name
            if not table or table[0].upper() != "LOOKUP_TABLE":
                raise ValueError(f"SCALARS {words[1]} without LOOKUP_TABLE")
            arrays[where][words[1]] = f.values(count * ncomp, words[2]).reshape(count, ncomp)
        elif key in ("VECTORS", "NORMALS"):
            arrays[where][words[1]] = f.values(3 * count, words[2]).reshape(count, 3)
        elif key == "TENSORS":
            arrays[where][words[1]] = f.values(9 * count, words[2]).reshape(count, 9)
        elif key == "FIELD":
            for _ in range(int(words[2])):
                head = f.words()
                if head and head[0].upper() == "METADATA":
                    while f.words():  # pragma: no cover - a block ends with a blank line
                        pass
                    head = f.words()
                name, ncomp, ntuples, kind = head[0], int(head[1]), int(head[2]), head[3]
                arrays[where][name] = f.values(ncomp * ntuples, kind).reshape(ntuples, ncomp)
        elif key == "METADATA":
            while True:  # skipped up to the blank line that ends it
                text = f.line().strip()
                if not text or f.pos >= len(f.data):
                    break
        elif key == "LOOKUP_TABLE":
            f.values(4 * int(words[2]), "float" if not f.binary else "unsigned_char")
        else:
            raise ValueError(f"unknown keyword {words[0]!r}")
    if len(dims) != 3:
        raise ValueError("no DIMENSIONS")
    if dataset == "STRUCTURED_POINTS":
        axes = [origin[a] + spacing[a] * np.arange(dims[a]) for a in range(3)]
    elif dataset == "RECTILINEAR_GRID":
        if len(coords) != 3:
            raise ValueError("a rectilinear grid needs X_, Y_ and Z_COORDINATES")
        axes = coords
    else:
        if points is None:
            raise ValueError("a structured grid needs POINTS")
        pts = _grid_values(points, tuple(dims))
        axes = [pts[:, 0, 0, 0], pts[0, :, 0, 1], pts[0, 0, :, 2]]
        lattice = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        scale = max(float(np.abs(pts).max()), 1e-300)
        if not np.allclose(pts, lattice, rtol=0, atol=1e-9 * scale):
            raise ValueError("the structured grid is curvilinear: resample it onto a "
                             "rectilinear grid")  # fmt: skip
    order = {"auto": ("point", "cell"), "point": ("point",), "cell": ("cell",)}[location]
    for loc in order:
        if all(n in arrays[loc] for n in names):
            values = np.concatenate([arrays[loc][n] for n in names], axis=1)
            break
    else:
        raise ValueError(
            f"no {location if location != 'auto' else 'point or cell'} data array "
            f"{'/'.join(names)!r}; point data: {sorted(arrays['point'])}, cell data: "
            f"{sorted(arrays['cell'])}"
        )
    if values.shape[1] != components:
        raise ValueError(
            f"array {'/'.join(names)!r} has {values.shape[1]} components, expected {components}"
        )
    axes = [np.asarray(a, np.float64) for a in axes]
    if loc == "cell":
        axes = [_centres(a) for a in axes]
    return tuple(axes), _grid_values(values, tuple(a.size for a in axes))
