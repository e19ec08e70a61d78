"""A natural logarithm written in Numba, so that LLVM can inline and vectorise it.

Why: Numba lowers ``math.log`` to a call of the C library's ``log``. A loop holding that
call does not vectorise: LLVM only replaces it by a vector function when it has a vector
math library (Intel's SVML), which the PyPI build of llvmlite does not ship (``numba -s``:
SVML not available). In the range pass of a surrounding-layer model (issue 10 §3) the one
logarithm per pair was about half the cost of a pair and kept the whole loop scalar.

:func:`fast_log` is fdlibm's ``__ieee754_log`` (Sun Microsystems, 1993; the ``e_log.c`` of
FreeBSD's msun and of Java's StrictMath) without its branches: x = 2^k m with
√½ <= m < √2 (the exponent and mantissa split through the bits, :func:`float_bits`), then
log m = 2 atanh(s), s = (m - 1)/(m + 1), as f - (f²/2 - s (f²/2 + R(s²))) with f = m - 1 and
R fdlibm's degree-14 minimax polynomial of 2 atanh(s)/s - 2 (error below 2^-58.45), and
k ln 2 in two parts (ln2_hi has trailing zero bits, so k ln2_hi is exact). fdlibm states
an error below 1 ulp; measured (``tests/unit/test_fastmath_log.py``, against numpy's log in
long double): at most 0.78 ulp, relative error <= 1.5e-16 over random doubles from 1e-308 to
1e308, ratios near 1 and subnormals, and at most 1 ulp (2.2e-16 relative) from the C
library's correctly rounded-or-nearly value. Special values as ``math.log``: log(0) = -inf,
log(x < 0) = NaN, log(inf) = inf, log(NaN) = NaN (no exception: selects, not branches).

Every operation is a plain IEEE operation (no fast-math flags), so the result does not
depend on whether LLVM vectorises the call site.
"""

from __future__ import annotations

import math

from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

LN2_HI = 6.93147180369123816490e-01  # 0x3FE62E42FEE00000: k * LN2_HI is exact
LN2_LO = 1.90821492927058770002e-10  # 0x3DEA39EF35793C76
LG1 = 6.666666666666735130e-01
LG2 = 3.999999999940941908e-01
LG3 = 2.857142874366239149e-01
LG4 = 2.222219843214978396e-01
LG5 = 1.818357216161805012e-01
LG6 = 1.531383769920937332e-01
LG7 = 1.479819860511658591e-01
SMALLEST_NORMAL = 2.2250738585072014e-308
TWO54 = 18014398509481984.0  # 2^54: scales a subnormal into the normal range
EXPONENT_ONE = 0x3FF0000000000000  # the bits of 1.0
MANTISSA = 0x000FFFFFFFFFFFFF
SQRT2_BITS = 0x3FF6A09E667F3BCD  # the bits of √2 (a mantissa at least this is halved)
EXPONENT_STEP = 0x0010000000000000  # one in the exponent field


@intrinsic
def float_bits(typingctx, x):  # noqa: ANN001, ANN201, ARG001
    """The IEEE bits of a float64 as an int64 (an LLVM bitcast: no memory, vectorisable)."""
    if not (isinstance(x, types.Float) and x.bitwidth == 64):
        return None

    def codegen(context, builder, sig, args):  # noqa: ANN001, ANN202, ARG001
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(types.float64), codegen


@intrinsic
def bits_float(typingctx, bits):  # noqa: ANN001, ANN201, ARG001
    """The float64 whose IEEE bits are the int64 ``bits`` (an LLVM bitcast)."""
    if not (isinstance(bits, types.Integer) and bits.bitwidth == 64):
        return None

    def codegen(context, builder, sig, args):  # noqa: ANN001, ANN202, ARG001
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.int64), codegen


@njit(cache=True, inline="always", error_model="numpy")
def fast_log(x):
    """Natural logarithm of a float64, within 1 ulp (see the module docstring)."""
    subnormal = x < SMALLEST_NORMAL
    scaled = x * TWO54 if subnormal else x
    bits = float_bits(scaled)
    k = ((bits >> 52) & 0x7FF) - (1023 + 54 if subnormal else 1023)
    mantissa = (bits & MANTISSA) | EXPONENT_ONE  # m in [1, 2)
    big = mantissa >= SQRT2_BITS  # m >= √2: m/2 in [√½, 1), k + 1
    mantissa = mantissa - EXPONENT_STEP if big else mantissa
    k = k + 1 if big else k
    f = bits_float(mantissa) - 1.0
    hfsq = 0.5 * f * f
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (LG2 + w * (LG4 + w * LG6))
    t2 = z * (LG1 + w * (LG3 + w * (LG5 + w * LG7)))
    r = t2 + t1
    dk = float(k)
    y = dk * LN2_HI - ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f)
    y = y if x < math.inf else x  # inf -> inf; NaN -> NaN (NaN < inf is false)
    y = -math.inf if x == 0.0 else y
    return math.nan if x < 0.0 else y
