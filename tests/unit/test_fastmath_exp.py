"""The compiled exponential and power (kernels/fastmath_exp.py) against numpy in long double
(x86: 64-bit mantissa) where the platform has one, and against the C library: random
arguments over the whole range, near 0, the overflow and subnormal ends and the special
values; the power at the exponents of the correlations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from thermodem.kernels.fastmath_exp import fast_exp, fast_power

LONG = np.finfo(np.longdouble).nmant > np.finfo(np.float64).nmant


@njit(cache=True, error_model="numpy")
def _exps(x):
    out = np.empty_like(x)
    for t in range(x.shape[0]):
        out[t] = fast_exp(x[t])
    return out


@njit(cache=True, error_model="numpy")
def _powers(x, a):
    out = np.empty_like(x)
    for t in range(x.shape[0]):
        out[t] = fast_power(x[t], a)
    return out


def _arguments() -> np.ndarray:
    rng = np.random.default_rng(20261207)
    return np.concatenate(
        [
            rng.uniform(-708.0, 709.0, 200_000),
            rng.uniform(-1.0, 1.0, 100_000),
            rng.uniform(-1e-8, 1e-8, 10_000),
            rng.uniform(700.0, 709.78, 10_000),
            np.arange(-1000.0, 1001.0) * math.log(2.0) / 2.0,  # the reduction's edges
        ]
    )


def test_exp_special_values_and_both_ends() -> None:
    x = np.array([0.0, -0.0, math.inf, -math.inf, math.nan, 709.78, 709.79, 710.0, 1e300,
                  -1e300, -745.13, -745.14, -746.0, -720.0, -740.0])  # fmt: skip
    got = _exps(x)
    with np.errstate(over="ignore"):
        expected = np.exp(x)
    assert np.array_equal(got, expected, equal_nan=True)


def test_exp_against_the_c_library_and_long_double() -> None:
    x = _arguments()
    got = _exps(x)
    libm = np.exp(x)
    assert np.all(np.abs(got - libm) <= np.spacing(libm))  # at most 1 ulp from libm
    if LONG:
        true = np.exp(x.astype(np.longdouble))
        ulps = np.abs((got - true) / np.spacing(libm).astype(np.longdouble))
        assert float(ulps.max()) < 0.9
    sub = np.random.default_rng(3).uniform(-745.0, -708.5, 10_000)  # subnormal results
    assert np.all(np.abs(_exps(sub) - np.exp(sub)) <= np.spacing(np.exp(sub)))


@pytest.mark.parametrize("a", [0.2, 0.5, 0.7, 0.4, 2.0 / 3.0])
def test_power_against_the_c_library(a: float) -> None:
    rng = np.random.default_rng(7)
    x = np.concatenate([10.0 ** rng.uniform(-10.0, 6.0, 100_000), [1.0, 32.0, 1e5]])
    got = _powers(x, a)
    libm = np.exp(a * np.log(x))
    # exp(a ln x) carries the rounding of a ln x (its ulp) into the relative error
    bound = 2.3e-16 * (2.0 + 2.0 * np.abs(a * np.log(x)))
    assert np.all(np.abs(got - libm) / libm <= 2.0 * bound)
    if LONG:
        true = np.power(x.astype(np.longdouble), np.longdouble(a))
        assert np.all(np.abs((got - true) / true) <= bound)
    special = _powers(np.array([0.0, -1.0, math.nan, math.inf]), a)
    assert special[:3].tolist() == [0.0, 0.0, 0.0] and special[3] == math.inf
