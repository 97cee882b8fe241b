"""The ``formula`` marker and input checks shared by the physics modules.

A *formula* is a small pure function of floats (and float64 arrays of material constants)
written in the subset of Python that Numba compiles: arithmetic, ``math`` and loops. The
physics layer calls it from NumPy code; :mod:`nylonflex.kernels` compiles the very same
function, and every formula it calls, with Numba. That keeps one formula in one place
without the physics layer importing Numba.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import ZERO_CELSIUS  # noqa: F401  (one definition)


def formula(func):
    """Mark ``func`` as a Numba-compilable formula (it is returned unchanged)."""
    func.__nylonflex_formula__ = True
    return func


def check(name, value, lo=None, hi=None, *, lo_open=False, hi_open=False, unit=""):
    """Return ``value`` as a float array after checking it lies in the accepted range.

    Raises
    ------
    ValueError
        One line naming ``name``, the accepted range with its unit and the bad value.
    """
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be a number{_unit(unit)}, got {value!r}") from None
    bad = ~np.isfinite(arr)
    if lo is not None:
        bad |= (arr <= lo) if lo_open else (arr < lo)
    if hi is not None:
        bad |= (arr >= hi) if hi_open else (arr > hi)
    if np.any(bad):
        got = arr[bad].flat[0] if arr.ndim else float(arr)
        raise ValueError(f"{name}: must be {_range(lo, hi, lo_open, hi_open)}{_unit(unit)}, "
                         f"got {got:g}")
    return arr


def check_section(radius, wall_thickness, base_thickness=None):
    """Checked a, t, b [m] of the cross-section; b = t when None (MODEL.md s. 1 [choice])."""
    a = check("radius", radius, 0.0, lo_open=True, unit="m")
    t = check("wall_thickness", wall_thickness, 0.0, lo_open=True, unit="m")
    b = t if base_thickness is None else check("base_thickness", base_thickness, 0.0,
                                               lo_open=True, unit="m")
    return a, t, b


def check_wrap_angle(wrap_angle):
    """Checked helix angle psi [rad], in (0, pi/2)."""
    return check("wrap_angle", wrap_angle, 0.0, math.pi / 2, lo_open=True, hi_open=True,
                 unit="rad")


def _unit(unit):
    return f" [{unit}]" if unit else ""


def _range(lo, hi, lo_open, hi_open):
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo:g}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi:g}"
    return "finite"


def scalar_or_array(x):
    """A 0-d result as a Python float, anything else unchanged."""
    x = np.asarray(x)
    return float(x) if x.ndim == 0 else x
