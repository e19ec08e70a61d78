"""Reading back the VTU frames written by :mod:`thermodem.io.vtk`.

:func:`read_vtu` reads any frame written there, including an empty one (no particles yet, or
none left): meshio 5.3 fails on any VTU without cells (meshio issue #1412).
:func:`read_name_table` gives a name table of the field data (``material_id 0 = glass``, see
:mod:`thermodem.io.vtk`) back as a list.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import meshio
import numpy as np

__all__ = ["read_name_table", "read_vtu"]

_TABLE_ENTRY = re.compile(r"^(?P<key>\S+) (?P<k>\d+) = (?P<name>.*)$", re.DOTALL)


def read_name_table(field_data: Mapping[str, np.ndarray], key: str) -> list[str]:
    """The names of ``key`` (e.g. ``'material_id'``) from a VTU's field data (as meshio reads
    it): ``names[k]`` is the name of id ``k``."""
    found: dict[int, str] = {}
    for label in field_data:
        m = _TABLE_ENTRY.match(label)
        if m and m.group("key") == key:
            found[int(m.group("k"))] = m.group("name")
    return [found.get(k, "") for k in range(max(found) + 1)] if found else []


_VTK_DTYPES = {
    "Int8": np.int8,
    "UInt8": np.uint8,
    "Int16": np.int16,
    "UInt16": np.uint16,
    "Int32": np.int32,
    "UInt32": np.uint32,
    "Int64": np.int64,
    "UInt64": np.uint64,
    "Float32": np.float32,
    "Float64": np.float64,
}


def _field_data(root: ET.Element) -> dict[str, np.ndarray]:
    """The FieldData arrays of an uncompressed VTU (ascii or base64 binary), as meshio
    returns them; {} for a compressed file (not written by default)."""
    import base64

    if root.get("compressor"):
        return {}
    header = np.dtype(_VTK_DTYPES[root.get("header_type", "UInt32")]).newbyteorder("<")
    out: dict[str, np.ndarray] = {}
    for da in root.iterfind("UnstructuredGrid/FieldData/DataArray"):
        dtype = np.dtype(_VTK_DTYPES.get(da.get("type", "Float64"), np.float64))
        text = (da.text or "").strip()
        if da.get("format") == "ascii":
            values = np.array(text.split(), dtype=dtype)
        else:
            raw = base64.b64decode(text)
            nbytes = int(np.frombuffer(raw[: header.itemsize], header)[0])
            values = np.frombuffer(raw[header.itemsize : header.itemsize + nbytes], dtype).copy()
        k = int(da.get("NumberOfComponents", "1"))
        out[da.get("Name", "")] = values.reshape(-1, k) if k > 1 else values
    return out


def read_vtu(path: str | os.PathLike[str]) -> meshio.Mesh:
    """Read a VTU written here, including an empty frame (no particles yet, or none left).

    An empty frame is a valid VTK file (``NumberOfPoints="0"``; VTK's
    ``vtkXMLUnstructuredGridReader`` reads it with its arrays), but meshio 5.3's VTU reader
    fails on any file without cells (IndexError, meshio issue #1412). For such a file this
    returns a mesh with no points, one empty cell block (``triangle`` for a walls file, which
    has cell data, else ``vertex``), every point and cell array, empty, with its dtype and
    number of components, and the field data (name tables); other files go to
    :func:`meshio.read`.
    """
    p = Path(path)
    root = ET.parse(p).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None or int(piece.get("NumberOfCells", "1")) != 0:
        return meshio.read(p)

    def empty(section: str) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        for da in piece.iterfind(f"{section}/DataArray"):
            k = int(da.get("NumberOfComponents", "1"))
            dtype = _VTK_DTYPES.get(da.get("type", "Float64"), np.float64)
            out[da.get("Name", "")] = np.zeros((0, k) if k > 1 else (0,), dtype=dtype)
        return out

    cell_data = {name: [value] for name, value in empty("CellData").items()}
    field_data = _field_data(root)
    points = np.zeros((int(piece.get("NumberOfPoints", "0")), 3))
    if points.shape[0]:  # points but no cells: not something written here
        return meshio.read(p)
    # one empty block of the kind written here: triangles for walls (they carry cell data),
    # vertices for particles
    block = (
        ("triangle", np.zeros((0, 3), np.int64))
        if cell_data
        else ("vertex", np.zeros((0, 1), np.int64))
    )
    return meshio.Mesh(
        points,
        [block],
        point_data=empty("PointData"),
        cell_data=cell_data or None,
        field_data=field_data,
    )
