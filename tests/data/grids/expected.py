"""The fields of the grid fixtures (trilinear: reproduced exactly by trilinear interpolation)."""

import numpy as np

AXES = (
    0.001 + 0.003 * np.arange(4),
    -0.002 + 0.004 * np.arange(3),
    0.0 + 0.0025 * np.arange(5),
)


def temperature(x, y, z):
    return 300.0 + 1000.0 * x + 2000.0 * y + 3000.0 * z + 1.0e5 * x * y * z


def velocity(x, y, z):
    return (1.0 + 10.0 * x + 0.0 * y, 2.0 + 20.0 * y + 0.0 * z, 3.0 + 3000.0 * z * x + 0.0 * y)
