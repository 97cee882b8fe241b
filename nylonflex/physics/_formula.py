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
from ..variables import INPUTS, VARIABLES, range_text


def formula(func):
    """Mark ``func`` as a Numba-compilable formula (it is returned unchanged)."""
    func.__nylonflex_formula__ = True
    return func


def primitive(func):
    """Mark ``func`` as a primitive: a formula may call it, and :mod:`nylonflex.kernels`
    compiles it to machine instructions of its own (a bit cast) with the same result, bit
    for bit, because the Python form here does not compile (it is returned unchanged)."""
    func.__nylonflex_primitive__ = True
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
        raise ValueError(f"{name}: must be a number{_unit(unit)}, got {_short(value)}") from None
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


#: Factors of the unit slips a design input is checked for: a value typed in mm (or deg)
#: where the API takes metres (or radians).
_SLIPS = {"length": (1e-3, "mm", "metres"), "angle": (math.pi / 180.0, "deg", "radians")}


def check_input(name, value, lo=None, hi=None):
    """``value`` as a float array after checking it against the registry's accepted range.

    The range of a design input is written once, in :mod:`nylonflex.variables`; ``lo`` and
    ``hi`` [SI] replace it where another source sets it (the coil index's table). A value
    that would be in range in another unit (mm typed for metres, deg for radians) is named as
    the likely slip.

    Raises
    ------
    ValueError
        One line: the parameter, its accepted range in SI, the bad value, the likely slip.
    """
    v = INPUTS[name] if name in INPUTS else VARIABLES[name]
    lo = v.lo if lo is None else lo
    hi = v.hi if hi is None else hi
    if float_in_range(value, lo, hi, v.lo_open, v.hi_open):
        return np.asarray(value)  # one design in range: the array test below costs 10 us
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be a number [{v.units}], got "
                         f"{_short(value)}") from None
    bad = ~np.isfinite(arr)
    bad |= (arr <= lo) if v.lo_open else (arr < lo)
    bad |= (arr >= hi) if v.hi_open else (arr > hi)
    if np.any(bad):
        got = float(arr[bad].flat[0])
        msg = f"{name}: must be {range_text(name, lo, hi, v.units)}, got {got:g} {v.units}"
        slip = _SLIPS.get(v.kind)
        if slip and np.isfinite(got) and lo <= got * slip[0] <= hi:
            msg += (f"; {got:g} looks like {slip[1]}: the Python API takes {slip[2]} "
                    f"({got * slip[0]:g} {v.units})")
        raise ValueError(msg.replace(" 1,", ",").removesuffix(" 1"))
    return arr


def input_range(name) -> tuple:
    """``(lo, hi, lo_open, hi_open)`` of a design input in the registry [SI]: what
    :func:`check_input` tests ``name`` against."""
    v = INPUTS[name] if name in INPUTS else VARIABLES[name]
    return v.lo, v.hi, v.lo_open, v.hi_open


def float_in_range(value, lo, hi, lo_open=False, hi_open=False) -> bool:
    """Whether ``value`` is a float (a NumPy float64 too) that :func:`check_input` accepts
    without its array test: finite, in [lo, hi], an open bound left out. False says
    nothing about other values (an int, an array), which the array test checks."""
    return isinstance(value, float) and lo <= value <= hi and (value > lo or not lo_open) \
        and (value < hi or not hi_open) and math.isfinite(value)


def _short(value, n=40):
    text = repr(value)
    return text if len(text) <= n else text[:n] + "..."


def check_section(radius, wall_thickness, base_thickness=None):
    """Checked a, t, b [m] of the cross-section; b = t when None (docs/model.md s. 1 [choice])."""
    a = check_input("radius", radius)
    t = check_input("wall_thickness", wall_thickness)
    b = t if base_thickness is None else check_input("base_thickness", base_thickness)
    return a, t, b


def check_wrap_angle(wrap_angle):
    """Checked helix angle psi [rad], in the registry's range."""
    return check_input("wrap_angle", wrap_angle)


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
