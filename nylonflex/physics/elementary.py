"""Branch-free natural logarithm and exponential for loops the compiler can vectorise.

Numba calls the C library's scalar ``log`` and ``exp``, and a loop that calls them is not
vectorised (this llvmlite has no SVML). These formulas do the same work in arithmetic and
bit operations only, so that LLVM vectorises a loop over the section's nodes (AVX-512 or
AVX2) without ``fastmath``: the material moment (:func:`.bending._section_moment`,
docs/model.md s. 12). They are fdlibm's ``e_log.c`` and ``e_exp.c`` (Sun Microsystems,
freely distributable; the same constants and polynomials as musl's ``log`` and ``exp``)
with the branches for special arguments replaced by selects: within one unit in the last
place of the C library's result, measured on 2 million arguments each (1.9 % of the logs
and 9.7 % of the exps differ from it by that unit; ``tests/test_kernels.py`` checks
400,000). The IEEE bits are read and written by two
primitives (:func:`._formula.primitive`): :mod:`struct` in Python, one bit cast each in the
kernels, so the functions run as plain Python too, with the same bits.
"""

from __future__ import annotations

import struct

from ._formula import formula, primitive

__all__: list[str] = []

_LN2_HI = 6.93147180369123816490e-01  # 0x3fe62e42 fee00000: k * LN2_HI is exact
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.44269504088896338700e+00
# log(1 + f) = f - f^2/2 + s (f^2/2 + R(s^2)), s = f / (2 + f), on [sqrt(2)/2 - 1, sqrt(2) - 1]
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01
# exp(r) = 1 + r + r c / (2 - c), c = r - r^2 P(r^2), on |r| <= ln(2) / 2
_P1 = 1.66666666666666019037e-01
_P2 = -2.77777777770155933842e-03
_P3 = 6.61375632143793436117e-05
_P4 = -1.65339022054652515390e-06
_P5 = 4.13813679705723846039e-08
#: 1.5 * 2^52: (x + _ROUND) - _ROUND is x rounded to the nearest integer, for |x| < 2^51
_ROUND = 6755399441055744.0
#: 0x3ff00000 - 0x3fe6a09e in the high word: moves the mantissa to [sqrt(2)/2, sqrt(2))
_LOG_OFFSET = 0x0009_5F62_0000_0000
_LOG_MANTISSA = 0x000F_FFFF_FFFF_FFFF
_LOG_BASE = 0x3FE6_A09E_0000_0000


_DOUBLE = struct.Struct("<d")
_INT64 = struct.Struct("<q")


@primitive
def _float_bits(x):
    """The IEEE 754 bits of the float ``x``, as a signed 64-bit integer."""
    return _INT64.unpack(_DOUBLE.pack(x))[0]


@primitive
def _bits_float(bits):
    """The float whose IEEE 754 bits are ``bits`` (a signed 64-bit integer)."""
    return _DOUBLE.unpack(_INT64.pack(bits))[0]


@formula
def _log(x):
    """Natural logarithm of a positive normal float ``x`` (NaN gives NaN) [-].

    x = 2^k m with m in [sqrt(2)/2, sqrt(2)), read from the bits; then fdlibm's
    log(1 + f), f = m - 1, and k ln 2 in two parts (Cody and Waite).
    """
    u = _float_bits(x) + _LOG_OFFSET
    k = (u >> 52) - 1023
    f = _bits_float((u & _LOG_MANTISSA) + _LOG_BASE) - 1.0
    hfsq = 0.5 * f * f
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (_LG2 + w * (_LG4 + w * _LG6))
    t2 = z * (_LG1 + w * (_LG3 + w * (_LG5 + w * _LG7)))
    r = t2 + t1
    dk = float(k)
    # + (x - x): NaN (and inf) propagate, +0 otherwise
    return (s * (hfsq + r) + dk * _LN2_LO - hfsq + f + dk * _LN2_HI) + (x - x)


@formula
def _exp(x):
    """e^x [-]: 0 below -745.2, inf above 709.8, NaN for NaN.

    x = k ln 2 + r with |r| <= ln(2)/2 (Cody and Waite), fdlibm's rational approximation of
    e^r, then 2^k as two exact power-of-two factors built from the bits.
    """
    x = 710.0 if x > 710.0 else x
    x = -746.0 if x < -746.0 else x
    kd = (x * _INV_LN2 + _ROUND) - _ROUND
    hi = x - kd * _LN2_HI
    lo = kd * _LN2_LO
    r = hi - lo
    rr = r * r
    c = r - rr * (_P1 + rr * (_P2 + rr * (_P3 + rr * (_P4 + rr * _P5))))
    y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
    k = int(kd if kd == kd else 0.0)  # kd is an integer in [-1076, 1024]; NaN stays in y
    k1 = k >> 1
    return y * _bits_float((k1 + 1023) << 52) * _bits_float((k - k1 + 1023) << 52)
