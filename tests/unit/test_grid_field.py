"""Grid field files (io/grid_field.py): VTK files written by the VTK library itself
(tests/data/grids, made by make_vtk_fixtures.py: image data, rectilinear and structured grids;
ascii, inline binary and appended raw/base64 data; zlib, LZMA or no compression; UInt32 and
UInt64 headers; both byte orders; legacy ASCII and binary), NPZ and CSV files, and the errors
for files that cannot be used."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from thermodem.io.grid_field import read_grid_field

DATA = Path(__file__).resolve().parents[1] / "data" / "grids"
sys.path.insert(0, str(DATA))
from expected import AXES, temperature, velocity  # noqa: E402

VTK_FILES = sorted(
    p.name
    for p in DATA.iterdir()
    if p.suffix in (".vti", ".vtr", ".vts", ".vtk") and p.stem != "curvilinear"
)


@pytest.mark.parametrize("name", VTK_FILES)
def test_vtk_files_written_by_vtk(name: str) -> None:
    assert len(VTK_FILES) == 9
    x, y, z = np.meshgrid(*AXES, indexing="ij")
    axes, t = read_grid_field(DATA / name, "T", 1)
    for a, b in zip(axes, AXES, strict=True):
        assert np.allclose(a, b, rtol=0, atol=1e-15)
    assert t.shape == (4, 3, 5, 1)
    assert np.allclose(t[..., 0], temperature(x, y, z), rtol=1e-14, atol=0)
    _, u = read_grid_field(DATA / name, "U", 3)
    assert np.allclose(u, np.stack(velocity(x, y, z), axis=-1), rtol=1e-14, atol=0)
    # cell data at the cell centres
    axes, tc = read_grid_field(DATA / name, "Tc", 1)
    centres = [0.5 * (a[1:] + a[:-1]) for a in AXES]
    for a, b in zip(axes, centres, strict=True):
        assert np.allclose(a, b, rtol=0, atol=1e-15)
    assert np.allclose(
        tc[..., 0], temperature(*np.meshgrid(*centres, indexing="ij")), rtol=1e-14, atol=0
    )
    with pytest.raises(ValueError, match=r"no cell data array 'T'.*cell data: \['Tc'\]"):
        read_grid_field(DATA / name, "T", 1, "cell")


def test_curvilinear_structured_grid_is_refused() -> None:
    with pytest.raises(ValueError, match="curvilinear"):
        read_grid_field(DATA / "curvilinear.vts", "T", 1)


def _lattice() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x, y, z = np.meshgrid(*AXES, indexing="ij")
    return x, y, z


def test_npz_and_its_errors(tmp_path: Path) -> None:
    x, y, z = _lattice()
    u = np.stack(velocity(x, y, z), axis=-1)
    path = tmp_path / "flow.npz"
    np.savez(
        path,
        x=AXES[0],
        y=AXES[1],
        z=AXES[2],
        T=temperature(x, y, z),
        U=u,
        ux=u[..., 0],
        uy=u[..., 1],
        uz=u[..., 2],
    )
    _, t = read_grid_field(path, "T", 1)
    assert np.array_equal(t[..., 0], temperature(x, y, z))
    _, v = read_grid_field(path, "U", 3)
    assert np.array_equal(v, u)
    _, v3 = read_grid_field(path, ("ux", "uy", "uz"), 3)
    assert np.array_equal(v3, u)
    with pytest.raises(ValueError, match=r"has no array 'P'; arrays: x, y, z, T, U"):
        read_grid_field(path, "P", 1)
    with pytest.raises(ValueError, match=r"scalar field; a vector needs"):
        read_grid_field(path, "T", 3)
    bad = temperature(x, y, z)
    bad[1, 2, 3] = np.nan
    np.savez(path, x=AXES[0], y=AXES[1], z=AXES[2], T=bad)
    with pytest.raises(ValueError, match=r"value nan at grid index \(1, 2, 3\)"):
        read_grid_field(path, "T", 1)
    np.savez(path, x=AXES[0][::-1], y=AXES[1], z=AXES[2], T=bad)
    with pytest.raises(ValueError, match="the x axis must increase strictly"):
        read_grid_field(path, "T", 1)


def test_csv_in_any_row_order_with_paraview_names(tmp_path: Path) -> None:
    x, y, z = _lattice()
    u = np.stack(velocity(x, y, z), axis=-1).reshape(-1, 3)
    t = temperature(x, y, z).ravel()
    pts = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    order = np.random.default_rng(1).permutation(len(t))
    header = "T,U:0,U:1,U:2,Points:0,Points:1,Points:2"
    rows = np.column_stack([t, u, pts])[order]
    path = tmp_path / "flow.csv"
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.17g")
    axes, got = read_grid_field(path, "T", 1)
    assert all(np.allclose(a, b, rtol=0, atol=1e-17) for a, b in zip(axes, AXES, strict=True))
    assert np.array_equal(got[..., 0], temperature(x, y, z))
    _, v = read_grid_field(path, "U", 3)
    assert np.array_equal(v, np.stack(velocity(x, y, z), axis=-1))
    # a missing point
    np.savetxt(path, rows[1:], delimiter=",", header=header, comments="", fmt="%.17g")
    with pytest.raises(ValueError, match="do not form a full rectilinear grid"):
        read_grid_field(path, "T", 1)
    np.savetxt(path, rows, delimiter=",", header="a,b,c,d,e,f,g", comments="", fmt="%.17g")
    with pytest.raises(ValueError, match="no columns x, y, z"):
        read_grid_field(path, "T", 1)


def test_missing_files_and_formats(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="does not exist"):
        read_grid_field(tmp_path / "none.vti", "T", 1)
    bad = tmp_path / "bad.vti"
    bad.write_text("<VTKFile type='ImageData'><ImageData")
    with pytest.raises(ValueError, match=r"bad.vti: cannot be read as a grid field"):
        read_grid_field(bad, "T", 1)
    lz4 = tmp_path / "lz4.vti"
    text = (DATA / "image_ascii.vti").read_text()
    lz4.write_text(
        text.replace(
            'header_type="UInt64"', 'header_type="UInt64" compressor="vtkLZ4DataCompressor"'
        )
    )
    with pytest.raises(ValueError, match="vtkLZ4DataCompressor' is not supported"):
        read_grid_field(lz4, "T", 1)
