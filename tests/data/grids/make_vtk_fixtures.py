"""Write the VTK grid fixtures of tests/unit/test_grid_field.py with the VTK library itself.

Not run by the test suite (VTK is not a dependency of thermodem): the files it writes are
committed. Run with a Python that has ``vtk`` (``pip install vtk``):

    python tests/data/grids/make_vtk_fixtures.py

The grid: 4 × 3 × 5 points, origin (0.001, -0.002, 0.0) m, spacing (0.003, 0.004, 0.0025) m;
point data ``T`` = f(x, y, z) and ``U`` = u(x, y, z), cell data ``Tc`` = f at the cell
centres, with the trilinear functions of ``expected.py`` (which trilinear interpolation
reproduces exactly).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from expected import AXES, temperature, velocity  # noqa: E402


def arrays():
    x, y, z = np.meshgrid(*AXES, indexing="ij")
    # VTK order: x fastest
    t = temperature(x, y, z).transpose(2, 1, 0).ravel()
    u = np.stack(velocity(x, y, z), axis=-1).transpose(2, 1, 0, 3).reshape(-1, 3)
    cx, cy, cz = (0.5 * (a[1:] + a[:-1]) for a in AXES)
    xc, yc, zc = np.meshgrid(cx, cy, cz, indexing="ij")
    tc = temperature(xc, yc, zc).transpose(2, 1, 0).ravel()
    return t, u, tc


def add_data(grid):
    t, u, tc = arrays()
    for name, values, where in (("T", t, "point"), ("U", u, "point"), ("Tc", tc, "cell")):
        arr = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        arr.SetName(name)
        (grid.GetPointData() if where == "point" else grid.GetCellData()).AddArray(arr)


def image():
    g = vtk.vtkImageData()
    g.SetDimensions(*(len(a) for a in AXES))
    g.SetOrigin(*(a[0] for a in AXES))
    g.SetSpacing(*(a[1] - a[0] for a in AXES))
    add_data(g)
    return g


def rectilinear():
    g = vtk.vtkRectilinearGrid()
    g.SetDimensions(*(len(a) for a in AXES))
    g.SetXCoordinates(numpy_to_vtk(AXES[0].copy(), deep=True))
    g.SetYCoordinates(numpy_to_vtk(AXES[1].copy(), deep=True))
    g.SetZCoordinates(numpy_to_vtk(AXES[2].copy(), deep=True))
    add_data(g)
    return g


def structured(curvilinear: bool = False):
    g = vtk.vtkStructuredGrid()
    g.SetDimensions(*(len(a) for a in AXES))
    x, y, z = np.meshgrid(*AXES, indexing="ij")
    if curvilinear:
        x = x + 0.2 * (z - z.min())
    pts = np.stack([x, y, z], axis=-1).transpose(2, 1, 0, 3).reshape(-1, 3)
    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(pts), deep=True))
    g.SetPoints(points)
    add_data(g)
    return g


def xml(writer_class, grid, name, mode, encode=True, compressor="zlib", header=64, big=False):
    w = writer_class()
    w.SetFileName(str(HERE / name))
    w.SetInputData(grid)
    {
        "ascii": w.SetDataModeToAscii,
        "binary": w.SetDataModeToBinary,
        "appended": w.SetDataModeToAppended,
    }[mode]()
    w.SetEncodeAppendedData(encode)
    {
        "zlib": w.SetCompressorTypeToZLib,
        "lzma": w.SetCompressorTypeToLZMA,
        "none": w.SetCompressorTypeToNone,
    }[compressor]()
    w.SetHeaderTypeToUInt64() if header == 64 else w.SetHeaderTypeToUInt32()
    w.SetByteOrderToBigEndian() if big else w.SetByteOrderToLittleEndian()
    assert w.Write() == 1, name


def legacy(writer_class, grid, name, binary):
    w = writer_class()
    w.SetFileName(str(HERE / name))
    w.SetInputData(grid)
    w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
    assert w.Write() == 1, name


xml(vtk.vtkXMLImageDataWriter, image(), "image_appended_base64_zlib.vti", "appended")
xml(vtk.vtkXMLImageDataWriter, image(), "image_appended_raw_zlib.vti", "appended", encode=False)
xml(vtk.vtkXMLImageDataWriter, image(), "image_ascii.vti", "ascii", compressor="none")
xml(
    vtk.vtkXMLRectilinearGridWriter,
    rectilinear(),
    "rectilinear_binary_u32.vtr",
    "binary",
    compressor="none",
    header=32,
)
xml(
    vtk.vtkXMLRectilinearGridWriter,
    rectilinear(),
    "rectilinear_binary_zlib_big.vtr",
    "binary",
    big=True,
)
xml(
    vtk.vtkXMLStructuredGridWriter,
    structured(),
    "structured_appended_raw_lzma.vts",
    "appended",
    encode=False,
    compressor="lzma",
    header=32,
)
xml(
    vtk.vtkXMLStructuredGridWriter,
    structured(),
    "structured_appended_base64_none.vts",
    "appended",
    compressor="none",
)
xml(
    vtk.vtkXMLStructuredGridWriter,
    structured(True),
    "curvilinear.vts",
    "appended",
    compressor="none",
)
legacy(vtk.vtkStructuredPointsWriter, image(), "legacy_points_ascii.vtk", binary=False)
legacy(vtk.vtkRectilinearGridWriter, rectilinear(), "legacy_rectilinear_binary.vtk", binary=True)
print(
    "written:",
    sorted(p.name for p in HERE.iterdir() if p.suffix in (".vti", ".vtr", ".vts", ".vtk")),
)
