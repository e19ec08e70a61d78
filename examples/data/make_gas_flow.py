"""Write gas_flow.vti, the gas field of examples/gas_cooled_bed.yaml, with the VTK library
(as a CFD solver or ParaView would: appended raw data, zlib). Needs ``pip install vtk``; the
file is committed, this script only documents how it was made.

The field stands for a steady CFD result of air blown upwards through the bed's box: on a
7 × 7 × 11 grid over the box (12 mm × 12 mm × 20 mm), T rises from 300 K at the floor to 340 K
at the top (the gas warms as it crosses the hot bed) and u_z is 1.2 m/s on the axis, 0.8 m/s
at the side walls; u_x, u_y are zero.
"""

from pathlib import Path

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

shape = (7, 7, 11)
lower = np.array([0.0, 0.0, -0.001])
upper = np.array([0.012, 0.012, 0.02])
spacing = (upper - lower) / (np.array(shape) - 1)
axes = [lower[a] + spacing[a] * np.arange(shape[a]) for a in range(3)]
x, y, z = np.meshgrid(*axes, indexing="ij")
temperature = 300.0 + 40.0 * (z - lower[2]) / (upper[2] - lower[2])
r2 = ((x - 0.006) ** 2 + (y - 0.006) ** 2) / 0.006**2
uz = 1.2 - 0.4 * np.minimum(r2, 1.0)
velocity = np.stack([0 * uz, 0 * uz, uz], axis=-1)

image = vtk.vtkImageData()
image.SetDimensions(*shape)
image.SetOrigin(*lower)
image.SetSpacing(*spacing)
for name, values in (
    ("T", temperature.transpose(2, 1, 0).ravel()),
    ("U", velocity.transpose(2, 1, 0, 3).reshape(-1, 3)),
):
    arr = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
    arr.SetName(name)
    image.GetPointData().AddArray(arr)
writer = vtk.vtkXMLImageDataWriter()
writer.SetFileName(str(Path(__file__).parent / "gas_flow.vti"))
writer.SetInputData(image)
writer.SetDataModeToAppended()
writer.EncodeAppendedDataOff()
writer.SetCompressorTypeToZLib()
assert writer.Write() == 1
