"""The config machinery every config shares: strict pydantic models, one range-error
formatter, and pydantic's errors as one line naming the dotted field.

Sweep configs (:mod:`.sweep`) and simulate configs (:mod:`.simulate`) both use it.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union, get_args, get_origin

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Tag, ValidationError

from ..materials import Cooling, Nylon, cooling_parameters
from ..units import (InputError, bare_angle_error, bare_number, from_si, parse_quantity,
                     plainly_degrees, short, slip_hint)

__all__ = ["Count", "Number", "check_range", "check_run_name", "range_error", "resolve_cooling",
           "valid_name"]


def _no_bool(value):
    if isinstance(value, bool):  # YAML's true/false/yes/no are not numbers
        raise ValueError(f"must be a number, got {str(value).lower()}")
    return value


Number = Annotated[Union[float, str], BeforeValidator(_no_bool)]
Count = Annotated[int, BeforeValidator(_no_bool)]

Number = Annotated[Union[float, str], BeforeValidator(_no_bool)]
Count = Annotated[int, BeforeValidator(_no_bool)]


def valid_name(name) -> bool:
    """A run name usable as a folder under sweeps/: letters, digits, '-', '_', '.'."""
    return isinstance(name, str) and bool(name) and not name.startswith(".") and \
        all(ch.isalnum() or ch in "-_." for ch in name)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


def check_run_name(name):
    """A run name (pydantic validator body): refused unless :func:`valid_name`."""
    if not valid_name(name):
        raise ValueError("letters, digits, '-', '_' and '.' only")
    return name


def resolve_cooling(cooling, nylon: Nylon, field: str = "cooling") -> Cooling | None:
    """The cooling set of a config's ``cooling`` (docs/model.md s. 9), or None.

    Refused (one line naming ``field``) beside a nylon set whose heat loss is fitted: a
    ``fit thermal`` file's value is the measured muscle's own in its own environment, so a
    cooling set would silently replace a measurement. Sweep and simulate configs both ask
    here.
    """
    if cooling is None:
        return None
    if isinstance(cooling, dict) and isinstance(cooling.get("speed"), str):
        # a speed typed with its unit ("5 m/s"); cooling_parameters takes m/s numbers
        cooling = {**cooling, "speed": parse_quantity(cooling["speed"], f"{field}.speed",
                                                      "speed", "m/s")}
    try:
        env = cooling_parameters(cooling)
    except ValueError as err:
        msg = str(err)
        raise InputError(field + msg[len("cooling"):] if msg.startswith("cooling") else
                         f"{field}: {msg}") from None
    if "nylonflex fit" in str(nylon.sources.get("heat_loss_per_length", "")):
        raise InputError(f"{field}: the nylon set's heat_loss_per_length is fitted (a fit "
                         "thermal file); leave out cooling: or the fitted value")
    return env


def range_error(field: str, lo, hi, display_unit: str, got, lo_open: bool = False,
                hi_open: bool = False) -> InputError:
    """The one-line refusal of a value outside its range, shown in display units.

    Parameters
    ----------
    field : str
        The dotted field, e.g. ``grid.radius.stop``.
    lo, hi : float or int or None
        Accepted range, SI [unit of the quantity]; None: unbounded on that side.
    display_unit : str
        Unit to show the range and the value in (``"1"``: none shown).
    got : float or int
        The refused value, SI [unit of the quantity].
    lo_open, hi_open : bool
        Whether the bound itself is refused.

    Returns
    -------
    InputError
        ``grid.radius.stop: must be in [0.5, 200] mm, got 900 mm``.
    """
    def show(x):
        if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
            return str(int(x))  # counts and seeds: every digit
        return f"{from_si(x, display_unit):g}"

    unit = "" if display_unit in ("1", "", None) else f" {display_unit}"
    if lo is not None and hi is not None:
        rng = f"in {'(' if lo_open else '['}{show(lo)}, {show(hi)}{')' if hi_open else ']'}"
    elif lo is not None:
        rng = f"{'>' if lo_open else '>='} {show(lo)}"
    elif hi is not None:
        rng = f"{'<' if hi_open else '<='} {show(hi)}"
    else:
        return InputError(f"{field}: must be finite, got {show(got)}{unit}")
    return InputError(f"{field}: must be {rng}{unit}, got {show(got)}{unit}")


def check_range(raw, field: str, kind: str, unit: str, lo=None, hi=None,
                display_unit: str | None = None, *, lo_open: bool = False,
                hi_open: bool = False, slack: float = 0.0, unit_stated: bool = False) -> float:
    """Parse a quantity (``"7.5 mm"`` or a bare number in ``unit``) to SI and check its range.

    Parameters
    ----------
    raw : str or float
        The value as the user typed it [``unit`` when bare].
    field : str
        The dotted field, for messages.
    kind : str
        The quantity's kind (``"length"``, ``"angle"``, ...).
    unit : str
        Unit of a bare number.
    lo, hi : float or None
        Accepted range, SI [unit of the quantity]; None: unbounded on that side.
    display_unit : str or None
        Unit of the message; ``unit`` when None.
    lo_open, hi_open : bool
        Whether the bound itself is refused.
    slack : float
        Tolerance on a closed bound, SI; a value within it is clamped onto the bound.
    unit_stated : bool
        The config states ``unit`` for a bare number (an axis's ``units: deg``). Otherwise a
        bare angle is read as degrees only when it is plainly degrees
        (:func:`nylonflex.units.plainly_degrees`: 0, or beyond ``hi`` read as radians), and
        refused naming the radians slip else.

    Returns
    -------
    float
        The value in SI, within [lo, hi].

    Raises
    ------
    InputError
        Not a number, a unit of another kind, a bare angle that may be radians, or out of
        range: one line naming ``field`` (and, for a bare number that would be in range in
        another unit, that unit: 0.0075 typed for mm reads as 7.5 um; did you mean m?).
    """
    bare = bare_number(raw)
    if kind == "angle" and bare is not None and not unit_stated and \
            not plainly_degrees(bare, 2 * math.pi if hi is None else hi):
        raise bare_angle_error(field, bare)
    value = float(parse_quantity(raw, field, kind, unit))
    ok = math.isfinite(value)
    if lo is not None:
        ok = ok and (value > lo if lo_open else value >= lo - slack)
    if hi is not None:
        ok = ok and (value < hi if hi_open else value <= hi + slack)
    if not ok:
        err = range_error(field, lo, hi, display_unit or unit, value, lo_open, hi_open)
        hint = slip_hint(bare, kind, unit, lo, hi) if bare is not None and \
            math.isfinite(value) else ""
        raise InputError(f"{err}{hint}") if hint else err
    if lo is not None and not lo_open:
        value = max(value, lo)
    if hi is not None and not hi_open:
        value = min(value, hi)
    return value


def _strip(tp):
    """A type without its Annotated metadata and without None in a union."""
    while get_origin(tp) is Annotated:
        tp = get_args(tp)[0]
    if get_origin(tp) in (Union, type(int | None)):
        args = [a for a in get_args(tp) if a is not type(None)]
        if len(args) == 1:
            return _strip(args[0])
    return tp


def _union_member(tp, tag):
    """The member of a union that pydantic's location ``tag`` names, or None."""
    for member in get_args(tp):
        meta = get_args(member)[1:] if get_origin(member) is Annotated else ()
        base = _strip(member)
        tags = {m.tag for m in meta if isinstance(m, Tag)}
        if isinstance(base, type) and issubclass(base, BaseModel):
            tags.add(base.__name__)
            kind = base.model_fields.get("kind")
            if kind is not None and get_origin(kind.annotation) is Literal:
                tags.update(get_args(kind.annotation))
        if tag in tags:
            return base
    return None


def _walk(model, loc):
    """The dotted path (``actuators[0].design.radius``) of a pydantic location, and the
    type it ends at (None when unknown); union members' tags are not part of the path."""
    path, tp = "", model
    for part in loc:
        tp = _strip(tp)
        if get_origin(tp) in (Union, type(int | None)):
            tp = _union_member(tp, part)  # a union's tag: not a key the user typed
            continue
        if isinstance(part, int):
            path += f"[{part}]"
            args = get_args(tp)
            tp = args[0] if get_origin(tp) in (list, tuple) and args else None
            continue
        path += f".{part}" if path else str(part)
        if isinstance(tp, type) and issubclass(tp, BaseModel) and part in tp.model_fields:
            tp = tp.model_fields[part].annotation
        elif get_origin(tp) is dict:
            tp = get_args(tp)[1]
        else:
            tp = None
    return path, _strip(tp) if tp is not None else None


_TYPE_MESSAGES = {
    "model_type": "must be a mapping of keys",
    "model_attributes_type": "must be a mapping of keys",
    "dict_type": "must be a mapping of keys",
    "list_type": "must be a list",
    "int_type": "must be an integer",
    "int_from_float": "must be an integer",
    "string_type": "must be a string",
}


#: What a missing required key of a sweep config is, as the message says it.
_MISSING_HINTS = {
    "curves": "every sweep needs its curve axes, e.g. curves: {stroke: {start: 0, stop: 0.1, "
              "num: 51}, pressure: {start: 0, stop: 40, num: 41, units: kPa}} "
              "(configs/fig12.yaml)",
    "grid": "every sweep needs its design grid: radius, wall_thickness, length, coil_index, "
            "wrap_angle (configs/fig12.yaml)",
}


def _misspelt(errors, e) -> str | None:
    """An unknown key beside a missing one ``e`` that is most likely it, misspelt."""
    import difflib

    missing = str(e["loc"][-1])
    extra = [str(x["loc"][-1]) for x in errors if x["type"] == "extra_forbidden"
             and tuple(x["loc"][:-1]) == tuple(e["loc"][:-1])]
    close = difflib.get_close_matches(missing, extra, n=1, cutoff=0.6)
    return close[0] if close else None


def _pydantic_message(err: ValidationError, model: type[BaseModel]) -> str:
    """One line for the first error of a validation against ``model``: the dotted field and
    what it accepts (a missing key beside a misspelling of it: the misspelling)."""
    errors = err.errors()
    e = errors[0]
    if e["type"] == "missing":
        typo = _misspelt(errors, e)
        if typo is not None:
            where = ".".join(str(x) for x in (*e["loc"][:-1], typo))
            return f"{where}: unknown key; did you mean '{e['loc'][-1]}'?"
    path, tp = _walk(model, e["loc"])
    msg = e["msg"].removeprefix("Value error, ")
    got = e.get("input")
    tail = "" if isinstance(got, dict) else f", got {short(got)}"
    kind = e["type"]
    if kind == "extra_forbidden":
        parent = _walk(model, e["loc"][:-1])[1]
        keys = sorted(parent.model_fields) if isinstance(parent, type) and \
            issubclass(parent, BaseModel) else []
        msg, tail = "unknown key" + (f"; accepted: {', '.join(keys)}" if keys else ""), ""
    elif kind == "missing":
        msg, tail = "missing key", ""
        if path in _MISSING_HINTS:
            msg += f"; {_MISSING_HINTS[path]}"
    elif kind == "literal_error":
        msg = msg.replace("Input should be", "must be one of")
    elif kind in ("union_tag_invalid", "union_tag_not_found"):
        key = e["ctx"]["discriminator"].strip("'")
        path = f"{path}.{key}" if path else key
        tags = [t for m in get_args(tp) for t in get_args(_strip(m).model_fields[key].annotation)]
        msg = f"must be one of {', '.join(tags)}"
        tail = f", got {short(e['ctx']['tag'])}" if kind == "union_tag_invalid" else ""
        msg = msg if tail else f"missing key; accepted: {', '.join(tags)}"
    else:
        msg = _TYPE_MESSAGES.get(kind, msg)
    return f"{path or 'config'}: {msg}{tail}"


