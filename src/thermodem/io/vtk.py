"""ParaView output: particles and walls as VTU files, indexed in time by PVD collections.

Recommended layout of an output directory (for whoever writes the run output)::

    out/particles.pvd             # time index of the particle frames (part 0)
    out/walls.pvd                 # time index of the wall frames (part 0)
    out/vtk/particles_000042.vtu  # one VTU per output frame
    out/vtk/walls_000042.vtu

Particles and walls go to *separate* PVD files. A single PVD with two parts would make
ParaView read every frame as a multiblock dataset, so that filters (Glyph on the particles,
colouring by a particle field) act on both blocks at once. With two collections the user gets
two independent pipeline sources. :class:`PVDWriter` nevertheless supports the ``part``
attribute, so both kinds of frame can share one PVD (particles part 0, walls part 1) if wanted.

A frame of an empty bed (before a pour starts, or after every particle left) is a valid VTU
with no points: VTK reads it (checked with VTK 9.7.2 in ``tests/run/test_faults.py``), meshio
5.3 does not (its reader fails on any file without cells, meshio issue #1412): read frames
back with :func:`thermodem.io.vtk_read.read_vtu` (re-exported here), which handles both.

The VTU files are written with meshio as uncompressed base64 "binary" XML (``header_type``
UInt64, so a single array may exceed 4 GiB); they read back with meshio and with VTK's
``vtkXMLUnstructuredGridReader`` (checked with VTK 9.7: vertex cells, all arrays and dtypes
intact). Measured on the development machine (2 cores): 200 000 particles with 10 fields
(6 float64 scalars, 2 float64 vectors, an int64 and an int32 field) take 0.11-0.15 s to write
(41.6 MB). A hand-written raw-appended VTU took about 0.06 s (29.8 MB) for the same data; not
worth a second XML writer for now. zlib compression cuts the size by a quarter but takes about
1 s, which is why it is off by default.

Names (materials, walls) travel as an integer array plus a *name table* in the file's field
data: one single-valued Int32 array per name whose array name says it, e.g.
``material_id 0 = glass`` (value 0), ``wall_id 3 = floor`` (value 3). ParaView lists them in
the Information panel (Data Arrays, field data) and the spreadsheet view; every VTU reader opens
them. VTK's own string arrays (``type="String"``) would show the same in ParaView but are
refused by meshio and other strict readers, which is why they are not used.
:func:`thermodem.io.vtk_read.read_name_table` gives the table back as a list.

A run's frames (:func:`write_particle_frame`, :func:`write_wall_frame`): particles carry
``global_id``, ``material_id``, ``radius``, ``mass``, velocities, force, torque,
``temperature``, ``heat_rate`` (and ``heat_rate_MECHANISM`` for the active mechanisms of a
thermal run), ``coordination_number``; wall triangles carry ``wall_id``, ``material_id``
and ``temperature`` (the wall's temperature for a wall at a fixed temperature, NaN for an
adiabatic wall).

A 2D case (``simulation.dimension: 2``) writes its particles as discs: the same points (in
the plane z = 0) with ``radius``, the disc axis ``normal`` = (0, 0, 1) and the disc
``thickness`` (0 for spheres kept in the plane). In ParaView: *Glyph* with glyph type
*2D Glyph*, *Circle* with *Filled* on, scale array ``radius``, scale factor 2: filled discs
in the x-y plane (docs/two-dimensional.md). Walls are drawn as strips of the disc thickness
around z = 0 (lines and circles seen along z).
"""

from __future__ import annotations

import math
import os
import shutil
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from thermodem.geometry.wall_layout import (
    COL_HALF_U,
    COL_HALF_V,
    COL_MATERIAL,
    COL_TEMPERATURE,
    COL_THERMAL_KIND,
    WALL_WIDTH,
)
from thermodem.io.vtk_read import read_vtu  # noqa: F401 (re-exported: docs/run-layer.md)
from thermodem.io.wall_mesh import wall_surface_mesh

if TYPE_CHECKING:
    from thermodem.engine.simulation import Simulation

__all__ = [
    "PART_PARTICLES",
    "PART_WALLS",
    "PVDWriter",
    "particle_frame_fields",
    "write_particle_frame",
    "write_particles_vtu",
    "write_wall_frame",
    "write_walls_vtu",
    "read_vtu",
]

#: ``part`` index of particle frames when particles and walls share one PVD.
PART_PARTICLES = 0
#: ``part`` index of wall frames when particles and walls share one PVD.
PART_WALLS = 1

_VTU_OPTIONS = {"binary": True, "header_type": "UInt64"}


# --------------------------------------------------------------------------------------------
# Arrays
# --------------------------------------------------------------------------------------------


def _as_vtk_array(name: str, value: np.ndarray, n: int, what: str) -> np.ndarray:
    """Return ``value`` as a contiguous array of ``n`` tuples that VTU can store.

    Booleans become uint8; arrays of more than two dimensions (e.g. (n, 3, 3) tensors) are
    flattened to (n, k) components; a trailing dimension of 1 is dropped.
    """
    a = np.asarray(value)
    if a.ndim == 0 or a.shape[0] != n:
        raise ValueError(f"{what} field {name!r} has shape {a.shape}, expected ({n}, ...)")
    if a.dtype == np.bool_:
        a = a.astype(np.uint8)
    elif a.dtype.kind not in "iuf":
        raise TypeError(f"{what} field {name!r} has unsupported dtype {a.dtype}")
    if a.ndim > 2:
        a = a.reshape(n, -1)
    if a.ndim == 2 and a.shape[1] == 1:
        a = a[:, 0]
    # Native byte order and C order: meshio writes ``tobytes()`` of the array.
    a = a.astype(a.dtype.newbyteorder("="), copy=False)
    return np.ascontiguousarray(a)


def _prepare_path(path: str | os.PathLike[str]) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    return p


NameTables = Mapping[str, Sequence[str]]


def _name_table_xml(tables: NameTables | None) -> bytes:
    """``<FieldData>`` with one Int32 array ``'KEY k = NAME'`` (value k) per name."""
    if not tables:
        return b""
    arrays = []
    for key, names in tables.items():
        for k, name in enumerate(names):
            label = quoteattr(f"{key} {k} = {name}")
            arrays.append(
                f'<DataArray type="Int32" Name={label} NumberOfTuples="1" format="ascii">'
                f"{k}</DataArray>"
            )
    return ("<FieldData>" + "".join(arrays) + "</FieldData>").encode("utf-8")


def _write_mesh(
    path: str | os.PathLike[str],
    mesh: meshio.Mesh,
    compression: str | None,
    tables: NameTables | None,
) -> None:
    """meshio's VTU with the name tables inserted as field data (meshio writes none)."""
    target = _prepare_path(path)
    if not tables:
        meshio.write(target, mesh, file_format="vtu", compression=compression, **_VTU_OPTIONS)
        return
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        meshio.write(tmp, mesh, file_format="vtu", compression=compression, **_VTU_OPTIONS)
        tag = b"<UnstructuredGrid>"
        with open(tmp, "rb") as src, open(target, "wb") as dst:
            head = src.read(4096)  # the tag follows the XML declaration and <VTKFile ...>
            at = head.index(tag) + len(tag)
            dst.write(head[:at] + _name_table_xml(tables) + head[at:])
            shutil.copyfileobj(src, dst, 1 << 20)
    finally:
        tmp.unlink(missing_ok=True)


# --------------------------------------------------------------------------------------------
# Particles
# --------------------------------------------------------------------------------------------


def write_particles_vtu(
    path: str | os.PathLike[str],
    positions: np.ndarray,
    fields: Mapping[str, np.ndarray] | None = None,
    *,
    compression: str | None = None,
    names: NameTables | None = None,
) -> None:
    """Write particles as a VTU unstructured grid with one vertex cell per particle.

    Parameters
    ----------
    path:
        Output ``.vtu`` file (its directory is created if needed).
    positions:
        (N, 3) particle centres.
    fields:
        Point data, each of shape (N,) (scalars) or (N, k) (vectors: k = 3); float or integer
        dtypes are written as they are (float32 stays float32, int32 stays Int32, ...),
        booleans as uint8, (N, 3, 3) tensors as 9 components.
    compression:
        ``None`` (default, fastest) or ``"zlib"`` / ``"lzma"``.
    names:
        Name tables for integer fields, e.g. ``{"material_id": ["glass", "steel"]}``: written
        as field data (see the module docstring; :func:`~thermodem.io.vtk_read.read_name_table`
        reads them).

    In ParaView, apply a *Glyph* filter (glyph type Sphere, scale array ``radius``, scale
    factor 2) or the *Point Gaussian* representation to draw the spheres.
    """
    pos = np.ascontiguousarray(positions, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"positions must have shape (N, 3), got {pos.shape}")
    n = pos.shape[0]
    point_data = {
        name: _as_vtk_array(name, value, n, "particle") for name, value in (fields or {}).items()
    }
    cells = [("vertex", np.arange(n, dtype=np.int64).reshape(n, 1))]
    mesh = meshio.Mesh(pos, cells, point_data=point_data)
    _write_mesh(path, mesh, compression, names)


# --------------------------------------------------------------------------------------------
# Walls
# --------------------------------------------------------------------------------------------


def write_walls_vtu(
    path: str | os.PathLike[str],
    kinds: np.ndarray,
    rows: np.ndarray,
    fields: Mapping[str, np.ndarray] | None = None,
    infinite_extent: float = 1.0,
    *,
    resolution: int = 48,
    names: Sequence[str] | None = None,
    tables: NameTables | None = None,
) -> None:
    """Write all walls as one VTU of triangles.

    Each triangle carries the cell data ``wall_id`` (int32, the wall's row index) and, for
    every entry of ``fields`` (arrays of shape (W,) or (W, k), e.g. temperature or force
    magnitude), the value of its wall. With no walls an empty (but valid) grid is written.
    ``names`` (one per wall) become the field-data name table of ``wall_id``; ``tables`` adds
    further tables (e.g. ``{"material_id": [...]}`` for a ``material_id`` field).
    """
    kinds = np.asarray(kinds).reshape(-1)
    rows = np.asarray(rows, dtype=np.float64).reshape(-1, WALL_WIDTH)
    w = kinds.shape[0]
    if rows.shape[0] != w:
        raise ValueError(f"{w} wall kinds but {rows.shape[0]} wall rows")
    fields = dict(fields or {})
    if "wall_id" in fields:
        raise ValueError("'wall_id' is reserved for the wall index")
    per_wall = {name: _as_vtk_array(name, value, w, "wall") for name, value in fields.items()}

    all_points: list[np.ndarray] = []
    all_triangles: list[np.ndarray] = []
    counts = np.zeros(w, dtype=np.int64)
    offset = 0
    for i in range(w):
        pts, tri = wall_surface_mesh(int(kinds[i]), rows[i], resolution, infinite_extent)
        all_points.append(pts)
        all_triangles.append(tri + offset)
        counts[i] = tri.shape[0]
        offset += pts.shape[0]
    points = np.concatenate(all_points) if w else np.zeros((0, 3))
    triangles = np.concatenate(all_triangles) if w else np.zeros((0, 3), dtype=np.int64)

    cell_data = {"wall_id": [np.repeat(np.arange(w, dtype=np.int32), counts)]}
    for name, value in per_wall.items():
        cell_data[name] = [np.ascontiguousarray(np.repeat(value, counts, axis=0))]
    mesh = meshio.Mesh(points, [("triangle", triangles)], cell_data=cell_data)
    all_tables = dict(tables or {})
    if names is not None:
        if len(names) != w:
            raise ValueError(f"{w} walls but {len(names)} wall names")
        all_tables["wall_id"] = list(names)
    _write_mesh(path, mesh, None, all_tables)


# --------------------------------------------------------------------------------------------
# A simulation's frames
# --------------------------------------------------------------------------------------------


def particle_frame_fields(sim: Simulation) -> dict[str, np.ndarray]:
    """The point data of a particle frame (see the module docstring)."""
    sim.complete_rates()
    p = sim.particles
    fields = {
        "global_id": p.global_id,
        "material_id": p.type_id,
        "radius": p.radius,
        "mass": p.mass,
        "velocity": p.velocity,
        "angular_velocity": p.angular_velocity,
        "force": p.force,
        "torque": p.torque,
        "temperature": p.temperature,
        "heat_rate": p.heat_rate,
        "coordination_number": sim.coordination_number().astype(np.int32),
    }
    if getattr(sim, "planar", False):  # 2D: discs of a thickness with their axis (z)
        normal = np.zeros((p.count, 3))
        normal[:, 2] = 1.0
        fields["normal"] = normal
        fields["thickness"] = np.full(p.count, float(sim.disc_thickness))
    if sim.thermal is not None:
        from thermodem.state.particles import HEAT_MECHANISMS

        for k, mech in enumerate(HEAT_MECHANISMS):
            col = p.heat_rate_by_mechanism[:, k]
            if np.any(col):
                fields[f"heat_rate_{mech}"] = np.ascontiguousarray(col)
    return fields


def write_particle_frame(path: str | os.PathLike[str], sim: Simulation) -> None:
    """The particles of ``sim`` now, with the material name table."""
    write_particles_vtu(
        path,
        sim.particles.position,
        particle_frame_fields(sim),
        names={"material_id": list(sim.material_names)},
    )


def write_wall_frame(path: str | os.PathLike[str], sim: Simulation, extent: float) -> None:
    """The walls of ``sim`` now: ``wall_id`` with the wall names, ``material_id`` with the
    material names, ``temperature`` (NaN for an adiabatic wall)."""
    rows = sim.wall_rows
    if getattr(sim, "planar", False):  # 2D: the unbounded z extents drawn as the disc slab
        rows = rows.copy()
        half = float(sim.upper[2])
        for col in (COL_HALF_U, COL_HALF_V):  # (COL_HALF_V is the cylinders' half length)
            column = rows[:, col]
            column[np.isinf(column)] = half
    fixed = rows[:, COL_THERMAL_KIND] > 0.0
    temperature = np.where(fixed, rows[:, COL_TEMPERATURE], np.nan)
    fields = {
        "material_id": rows[:, COL_MATERIAL].astype(np.int32),
        "temperature": temperature,
    }
    write_walls_vtu(
        path,
        sim.wall_kind,
        rows,
        fields,
        extent,
        names=list(sim.wall_labels),
        tables={"material_id": list(sim.material_names)},
    )


# --------------------------------------------------------------------------------------------
# PVD time index
# --------------------------------------------------------------------------------------------


class PVDWriter:
    """Time index (ParaView ``.pvd`` collection) of VTU frames, always valid on disk.

    Every :meth:`add` rewrites the whole file to a temporary file in the same directory and
    moves it over the old one with :func:`os.replace`, so a run killed at any moment leaves
    either the previous or the new index, never a truncated one. Write the VTU first, then
    :meth:`add` it.

    The writer creates (or truncates) the file on construction. To continue a collection after
    a restart, use :meth:`resume`.

    Entries are kept in the order they are added. Within one ``part`` times must not decrease;
    adding a time already present for the same part replaces that entry (a restarted run that
    writes its first frame at the restart time again).

    Recommended: particles and walls in separate collections (both part 0); to put both in one
    file use ``part=PART_PARTICLES`` and ``part=PART_WALLS``.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        *,
        fsync: bool = False,
        _entries: list[tuple[float, int, str]] | None = None,
    ) -> None:
        self.path = Path(path)
        self.fsync = fsync
        self._entries: list[tuple[float, int, str]] = list(_entries or [])
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._write()

    @classmethod
    def resume(cls, path: str | os.PathLike[str], time: float, *, fsync: bool = False) -> PVDWriter:
        """Re-open ``path``, keeping the entries with ``timestep <= time`` (all parts).

        The pruned index is written back at once. A missing file gives an empty collection.
        The VTU files of dropped entries are left on disk (the restarted run overwrites them).
        """
        p = Path(path)
        entries: list[tuple[float, int, str]] = []
        if p.exists():
            for t, part, file in cls.read(p):
                if t <= time:
                    entries.append((t, part, file))
        return cls(p, fsync=fsync, _entries=entries)

    @staticmethod
    def read(path: str | os.PathLike[str]) -> list[tuple[float, int, str]]:
        """Entries ``(time, part, file)`` of an existing PVD file, in file order."""
        root = ET.parse(path).getroot()
        collection = root.find("Collection")
        if root.tag != "VTKFile" or root.get("type") != "Collection" or collection is None:
            raise ValueError(f"{path} is not a VTK collection (.pvd) file")
        return [
            (float(ds.get("timestep", "0")), int(ds.get("part", "0")), ds.get("file", ""))
            for ds in collection.iter("DataSet")
        ]

    @property
    def entries(self) -> list[tuple[float, int, str]]:
        """A copy of the entries ``(time, part, file)``."""
        return list(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def add(self, time: float, relative_vtu_path: str | os.PathLike[str], part: int = 0) -> None:
        """Append a frame and rewrite the index atomically.

        ``relative_vtu_path`` is relative to the PVD's directory (stored with ``/``); an
        absolute path is converted to a relative one.
        """
        time = float(time)
        if not math.isfinite(time):
            raise ValueError(f"time must be finite, got {time}")
        part = int(part)
        if part < 0:
            raise ValueError(f"part must be non-negative, got {part}")
        file = os.fspath(relative_vtu_path)
        if os.path.isabs(file):
            file = os.path.relpath(file, os.path.abspath(self.path.parent))
        file = Path(file).as_posix()

        entries = list(self._entries)
        same_part = [i for i, (_, q, _) in enumerate(entries) if q == part]
        if same_part and time <= entries[same_part[-1]][0]:
            last = entries[same_part[-1]][0]
            if time < last:
                raise ValueError(f"time {time!r} precedes the last time {last!r} of part {part}")
            entries[same_part[-1]] = (time, part, file)
        else:
            entries.append((time, part, file))
        # Only keep the new entry if the file was written (memory and disk stay in step).
        self._write(entries)
        self._entries = entries

    def _text(self, entries: list[tuple[float, int, str]]) -> str:
        lines = [
            '<?xml version="1.0"?>',
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
            "  <Collection>",
        ]
        lines += [
            f'    <DataSet timestep="{t!r}" group="" part="{part}" file={quoteattr(file)}/>'
            for t, part, file in entries
        ]
        lines += ["  </Collection>", "</VTKFile>", ""]
        return "\n".join(lines)

    def _write(self, entries: list[tuple[float, int, str]] | None = None) -> None:
        data = self._text(self._entries if entries is None else entries).encode("utf-8")
        # A plain open() (not mkstemp) so the file gets the usual umask permissions.
        tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")
        try:
            with open(tmp, "wb") as f:
                f.write(data)
                if self.fsync:
                    f.flush()
                    os.fsync(f.fileno())
            os.replace(tmp, self.path)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
