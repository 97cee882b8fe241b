"""Unit strings at the edges (configs, command line, charts); SI everywhere inside.

Every quantity has a *kind* (length, angle, pressure, ...). A unit string is parsed once,
here, into a factor (and for temperatures an offset) to SI.
"""

from __future__ import annotations

import math
import re
import reprlib

__all__ = ["UNITS", "InputError", "bare_angle_error", "bare_number", "json_text",
           "parse_quantity", "plainly_degrees", "short", "slip_hint", "to_si", "from_si",
           "unit_kind"]


class InputError(ValueError):
    """Bad user input: the message is one line naming the field and what it accepts."""


#: unit -> (kind, factor to SI, offset to SI); SI value = value * factor + offset.
UNITS: dict[str, tuple[str, float, float]] = {
    "m": ("length", 1.0, 0.0),
    "cm": ("length", 1e-2, 0.0),
    "mm": ("length", 1e-3, 0.0),
    "um": ("length", 1e-6, 0.0),
    "rad": ("angle", 1.0, 0.0),
    "deg": ("angle", math.pi / 180.0, 0.0),
    "Pa": ("pressure", 1.0, 0.0),
    "kPa": ("pressure", 1e3, 0.0),
    "MPa": ("pressure", 1e6, 0.0),
    "bar": ("pressure", 1e5, 0.0),
    "N": ("force", 1.0, 0.0),
    "mN": ("force", 1e-3, 0.0),
    "N m": ("torque", 1.0, 0.0),
    "N mm": ("torque", 1e-3, 0.0),
    "mN m": ("torque", 1e-3, 0.0),
    "K": ("temperature", 1.0, 0.0),
    "degC": ("temperature", 1.0, 273.15),
    "s": ("time", 1.0, 0.0),
    "ms": ("time", 1e-3, 0.0),
    "min": ("time", 60.0, 0.0),
    "h": ("time", 3600.0, 0.0),
    "Hz": ("frequency", 1.0, 0.0),
    "mHz": ("frequency", 1e-3, 0.0),
    "J": ("energy", 1.0, 0.0),
    "mJ": ("energy", 1e-3, 0.0),
    "m/s": ("speed", 1.0, 0.0),
    "V": ("voltage", 1.0, 0.0),
    "W": ("power", 1.0, 0.0),
    "A": ("current", 1.0, 0.0),
    "ohm": ("resistance", 1.0, 0.0),
    "kohm": ("resistance", 1e3, 0.0),
    "mA": ("current", 1e-3, 0.0),
    "ml": ("volume", 1e-6, 0.0),
    "uL": ("volume", 1e-9, 0.0),
    "1": ("dimensionless", 1.0, 0.0),
    "%": ("dimensionless", 1e-2, 0.0),
}

_ALIASES = {"N*m": "N m", "N.m": "N m",
            "celsius": "degC", "degrees": "deg", "degree": "deg", "": "1", "-": "1",
            "mL": "ml", "ul": "uL", "\u03a9": "ohm"}

#: Spellings refused because the unit libraries a user's other tools use (pint, UDUNITS)
#: read them otherwise or not at all: unit -> (the spelling to write, why). ``C`` is the
#: coulomb there, ``Nm`` no unit (``nm`` is the nanometre), ``Ohm`` is case-sensitive.
_PINT_SPELLING = {"C": ("degC", "C is the coulomb in pint and UDUNITS"),
                  "Nm": ("N m", "pint reads no unit Nm"),
                  "Nmm": ("N mm", "pint reads no unit Nmm"),
                  "mNm": ("mN m", "pint reads no unit mNm"),
                  "Ohm": ("ohm", "unit names are case-sensitive")}

_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


def _canonical(unit: str) -> str:
    unit = unit.strip()
    if unit in _PINT_SPELLING:
        spelling, why = _PINT_SPELLING[unit]
        raise InputError(f"unit {unit!r}: write {spelling!r} ({why})")
    return _ALIASES.get(unit, unit)


def unit_kind(unit: str) -> str:
    """The kind of quantity a unit measures ("length", "angle", ...)."""
    unit = _canonical(unit)
    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}; accepted: {', '.join(UNITS)}")
    return UNITS[unit][0]


def _fraction(x: float):
    """The decimal a float was typed as (its shortest repr), exactly."""
    from fractions import Fraction

    return Fraction(repr(float(x)))


def decimal_to_si(value, unit: str) -> float:
    """The SI float of a decimal ``value`` (a :class:`fractions.Fraction` or a float read
    as the decimal it prints as) in ``unit``: the float nearest the exact SI value where
    the unit's factor is a decimal (mm, kPa, degC, ...: ``10.5 mm`` is exactly the float
    ``0.0105``, as typed), else ``value * factor`` (deg: ``math.radians``'s product).
    """
    from fractions import Fraction

    _, factor, offset = UNITS[_canonical(unit)]
    exact = value if isinstance(value, Fraction) else _fraction(value)
    if factor in _IRRATIONAL:
        return float(exact) * factor + offset
    return float(exact * _fraction(factor) + _fraction(offset))


#: Factors that are not decimals (a float times them is the best one can do).
_IRRATIONAL = frozenset((math.pi / 180.0,))


def to_si(value, unit: str, field: str = "value", kind: str | None = None):
    """Convert ``value`` (number or array) given in ``unit`` to SI.

    A finite scalar converts exactly (:func:`decimal_to_si`: ``10.3 mm`` is the float
    nearest 0.0103 m, where ``10.3 * 1e-3`` is an ulp off); arrays by ``value * factor +
    offset``.

    Raises
    ------
    InputError
        Unknown unit, or a unit of another kind than ``kind``; the message names ``field``.
    """
    try:
        u = _canonical(unit)
    except InputError as err:  # a spelling other tools read otherwise: name the field
        raise InputError(f"{field}: {err}") from None
    if u not in UNITS:
        raise InputError(f"{field}: unknown unit {unit!r}; accepted: "
                         f"{', '.join(_units_of(kind) if kind else UNITS)}")
    k, factor, offset = UNITS[u]
    if kind is not None and k != kind:
        raise InputError(f"{field}: unit {unit!r} is not a {kind}; accepted: "
                         f"{', '.join(_units_of(kind))}")
    if isinstance(value, (int, float)) and not isinstance(value, bool) and \
            math.isfinite(value) and (factor != 1.0 or offset != 0.0):
        try:
            si = decimal_to_si(value, u)
        except OverflowError:
            si = math.inf
        if not math.isfinite(si):  # 1e308 kPa: finite as typed, not in SI
            raise InputError(f"{field}: {value:g} {unit} is beyond any float in SI; "
                             "give a plausible value")
        return si
    return value * factor + offset


def from_si(value, unit: str):
    """Convert an SI value (number or array) to ``unit``."""
    _, factor, offset = UNITS[_canonical(unit)]
    return (value - offset) / factor


def _units_of(kind):
    return [u for u, (k, _, _) in UNITS.items() if k == kind]


def _finite(obj):
    """``obj`` with every non-finite float (NaN, inf) as None, numpy scalars as Python's."""
    if isinstance(obj, dict):
        return {str(k): _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):  # numpy values
        return _finite(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def json_text(obj, indent=2) -> str:
    """``obj`` as valid JSON text (RFC 8259, a newline at the end): NaN and infinities,
    which ``json.dumps`` writes as the invalid ``NaN``/``Infinity``, become null."""
    import json

    return json.dumps(_finite(obj), indent=indent, allow_nan=False) + "\n"


def short(value, limit: int = 60) -> str:
    """The repr of ``value`` for a message, cut to about ``limit`` characters.

    Built with :mod:`reprlib`, so a huge or deeply shared value (a YAML alias bomb) is never
    expanded to be cut afterwards.
    """
    r = reprlib.Repr()
    r.maxlevel, r.maxlist, r.maxtuple, r.maxdict, r.maxset = 2, 4, 4, 4, 4
    r.maxstring = r.maxother = r.maxlong = limit
    text = r.repr(value)
    return text if len(text) <= limit + 5 else text[:limit] + "..."


def parse_decimal(text, field: str, kind: str, default_unit: str):
    """``(decimal, unit)`` of ``"7.5mm"``, ``"8 deg"`` or a bare number (in
    ``default_unit``): the number exactly as typed (:class:`fractions.Fraction`) and its
    canonical unit, for grids whose points are decimals in that unit.

    Raises
    ------
    InputError
        As :func:`parse_quantity`.
    """
    from fractions import Fraction

    parse_quantity(text, field, kind, default_unit)  # the same checks and messages
    if isinstance(text, (int, float)):
        return _fraction(text), _canonical(default_unit)
    number, unit = _NUMBER.match(text).groups()
    return Fraction(number), _canonical(unit or default_unit)


def parse_quantity(text, field: str, kind: str, default_unit: str):
    """Parse ``"7.5mm"``, ``"8 deg"`` or a bare ``"7.5"`` (in ``default_unit``) to SI.

    Raises
    ------
    InputError
        Not a number, or a unit of the wrong kind; the message names ``field``.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return to_si(float(text), default_unit, field, kind)
    m = _NUMBER.match(text) if isinstance(text, str) and len(text) < 200 else None
    if not m:
        raise InputError(f"{field}: expected a number with an optional unit "
                         f"({', '.join(_units_of(kind))}), got {short(text)}")
    number, unit = m.groups()
    return to_si(float(number), unit or default_unit, field, kind)


def bare_number(raw):
    """The float of a number typed without a unit (``0.14``, ``"0.14"``), else None."""
    if isinstance(raw, bool):
        return None
    if isinstance(raw, (int, float)):
        return float(raw)
    m = _NUMBER.match(raw) if isinstance(raw, str) and len(raw) < 200 else None
    return float(m.group(1)) if m and not m.group(2) else None


#: The rule for a bare angle in a config (docs/interface.md, "Units"): it is read as
#: degrees only when it is *plainly* degrees, i.e. larger than the largest angle the field
#: accepts, read as radians (so that it cannot be radians): wrap_angle takes up to 80 deg =
#: 1.40 rad, so ``[5, 8, 12]`` is plainly degrees while ``[0.14, 0.21]`` and ``[1]`` are
#: refused; 0 is 0 in either unit. The config states the unit instead with ``units: deg``
#: (an axis) or ``8deg`` / ``0.14rad`` (a value).
def plainly_degrees(value: float, hi_rad: float) -> bool:
    """Whether a bare angle ``value`` can only be degrees: 0, or larger in magnitude than
    ``hi_rad`` [rad], the largest angle its field accepts (so as radians it is refused)."""
    return value == 0.0 or abs(value) > hi_rad


def bare_angle_error(field: str, value: float) -> InputError:
    """The refusal of a bare angle that is not :func:`plainly_degrees`: one line naming the
    field, the unit it would read in and the likely slip (radians)."""
    deg = math.degrees(value)
    return InputError(f"{field}: {value:g} has no unit; it reads as {value:g} deg - did you "
                      f"mean {value:g} rad ({deg:.3g} deg)? write '{deg:.3g}deg' or "
                      f"'{value:g}rad' ('{value:g}deg' if degrees are meant)")


def slip_hint(value: float, kind: str, unit: str, lo, hi) -> str:
    """For a bare ``value`` read in ``unit`` and refused (outside [lo, hi], SI): the text
    naming the SI unit of its kind when the value would be in range there (the slip of
    typing SI where the display unit is read: ``0.0075`` read as mm, ``"; did you mean
    0.0075 m (7.5 mm)? write '7.5mm'"``), or ""."""
    shown = _canonical(unit)
    si_unit = next((u for u, (k, f, o) in UNITS.items() if k == kind and f == 1.0 and
                    o == 0.0), None)
    if si_unit is None or si_unit == shown or value == 0.0:
        return ""
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        return ""
    typed = from_si(value, shown)
    return f"; did you mean {value:g} {si_unit} ({typed:.4g} {shown})? write '{typed:.4g}{shown}'"
