"""An exponential and a power written in Numba, so that LLVM can inline and vectorise them.

Why: as for the logarithm (:mod:`thermodem.kernels.fastmath_log`), Numba lowers ``math.exp``
to a call of the C library, and a loop holding that call does not vectorise (no SVML in the
PyPI llvmlite). Gunn's (1978) Nusselt number takes Re^0.2 of every particle at every thermal
step; in the per-particle pass (``kernels/heat_terms.py: particle_pass``) that power, as
exp(0.2 ln Re) through the C library, and the scalar loop around it were most of the pass's
cost on the 50k bed (issue 13).

:func:`fast_exp` is fdlibm's ``__ieee754_exp`` (Sun Microsystems, 1993; ``e_exp.c`` of
FreeBSD's msun) without its branches: x = k ln 2 + r with |r| <= ln 2 / 2 (k the nearest
integer to x / ln 2, found by adding and subtracting 1.5 × 2^52, which rounds to nearest
even; k ln2_hi is exact), exp r = 1 + r + r c / (2 - c) with c = r - r² P(r²) and P fdlibm's
degree-5 minimax polynomial (error below 2^-59), then 2^k applied as two exact factors
2^(k//2) 2^(k - k//2) built from their bits, so that the results that overflow or are
subnormal come out of the last multiplication (inf, the subnormal, 0) without a branch.
fdlibm states an error below 1 ulp; measured (``tests/unit/test_fastmath_exp.py``, against
numpy's exp in long double): at most ~0.85 ulp for normal results. Special values as
``math.exp``: exp(inf) = inf, exp(-inf) = 0, exp(NaN) = NaN (selects, not branches).

:func:`fast_power` is x^a = exp(a ln x) with :func:`fast_log`, 0 for x <= 0 (and NaN), as
``convection.power``; relative error within a few 1e-16 of x^a for the exponents of the
correlations (e.g. 0.2: at most ~9e-16 against long double over 1e-10..1e6, as the C
library's pair).

Every operation is a plain IEEE operation (no fast-math flags), so the result does not
depend on whether LLVM vectorises the call site: a scalar call and a vectorised loop give the
same bits.
"""

from __future__ import annotations

from numba import njit

from thermodem.kernels.fastmath_log import LN2_HI, LN2_LO, bits_float, fast_log, float_bits

INVLN2 = 1.44269504088896338700e00
P1 = 1.66666666666666019037e-01
P2 = -2.77777777770155933842e-03
P3 = 6.61375632143793436117e-05
P4 = -1.65339022054652515390e-06
P5 = 4.13813679705723846039e-08
SHIFTER = 6755399441055744.0  # 1.5 × 2^52: x + SHIFTER - SHIFTER rounds x to an integer
#: Arguments are clamped to [EXP_LOWEST, EXP_HIGHEST] (beyond them exp is 0 or inf anyway):
#: k stays within the two factors' normal range.
EXP_LOWEST = -746.0
EXP_HIGHEST = 710.0
EXPONENT_BIAS = 1023


@njit(cache=True, inline="always", error_model="numpy")
def fast_exp(x):
    """e^x of a float64, within 1 ulp (see the module docstring)."""
    y = EXP_LOWEST if x < EXP_LOWEST else x
    y = EXP_HIGHEST if y > EXP_HIGHEST else y  # (NaN: kept, restored below)
    t = y * INVLN2 + SHIFTER
    kf = t - SHIFTER
    k = float_bits(t) - float_bits(SHIFTER)  # the integer kf (|k| < 2^51)
    hi = y - kf * LN2_HI
    lo = kf * LN2_LO
    r = hi - lo
    s = r * r
    c = r - s * (P1 + s * (P2 + s * (P3 + s * (P4 + s * P5))))
    e = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)  # e^r, in [0.7, 1.5)
    k1 = k >> 1
    k2 = k - k1
    e = e * bits_float((k1 + EXPONENT_BIAS) << 52) * bits_float((k2 + EXPONENT_BIAS) << 52)
    return e if x == x else x


@njit(cache=True, inline="always", error_model="numpy")
def fast_power(x, a):
    """x^a as exp(a ln x) (compiled, vectorisable); 0 for x <= 0 or NaN."""
    return fast_exp(a * fast_log(x)) if x > 0.0 else 0.0


__all__ = ["fast_exp", "fast_power"]
