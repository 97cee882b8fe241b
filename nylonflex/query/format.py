"""The output of ``nylonflex query``: aligned text in display units, JSON and CSV in SI.

Every format prints the flags as whole numbers (JSON and CSV) or their names (a table:
``limit`` as ``stroke``/``strength``/..., ``validity`` as ``valid`` or its flag names).
"""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np

from ..variables import AXES, DESIGN, MODEL, VARIABLES, to_display
from .parse import EXACT, OPTIONAL, default_columns


def _var(name):
    return MODEL if name == "model" else VARIABLES[name]


def _unit(name):
    return _var(name).display


def _sig3(x) -> str:
    """Three significant figures, trailing zeros kept, no exponent in the usual range."""
    if x is None or not np.isfinite(x):
        return "nan"
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if -4 <= mag < 6:
        digits = max(0, 2 - mag)
        return f"{x:.{digits}f}"
    return f"{x:.2e}"


def _flag_meanings(name) -> dict:
    """``{bit: flag name}`` of a bit-field variable (``validity``), from its CF attributes."""
    attrs = VARIABLES[name].attrs()
    return dict(zip((int(v) for v in attrs["flag_masks"]), attrs["flag_meanings"].split()))


def flag_names(x) -> str:
    """``validity`` as its flag names: ``"valid"`` for 0, ``"self_contact+..."`` for the
    bits set, ``"unknown"`` for NaN (docs/model.md s. 17)."""
    if x is None or not np.isfinite(x):
        return "unknown"
    bits = int(x)
    if bits == 0:
        return "valid"
    names = [meaning for bit, meaning in _flag_meanings("validity").items() if bits & bit]
    rest = bits & ~sum(_flag_meanings("validity"))
    return "+".join(names + ([f"bits {rest}"] if rest else []))


#: Variables that hold whole numbers (flags and bit fields): printed as integers.
INTEGERS = ("limit", "validity")


def _integer(x):
    """A flag's value as an int, None when unknown (NaN)."""
    x = float(x)
    return int(x) if math.isfinite(x) else None


def _cell(name, x) -> str:
    if name == "model":
        return str(x)
    if name == "validity":
        return flag_names(x)
    if name == "limit":
        return {0.0: "stroke", 1.0: "strength", 2.0: "supply", 3.0: "load"}.get(
            float(x), "boundary") \
            if np.isfinite(x) else "boundary"
    value = float(to_display(name, x))
    if name in AXES:
        return f"{value:.6g}"
    return _sig3(value)


def _describe_at(res) -> str:
    parts = []
    for name, value in res.at.items():
        unit = _unit(name)
        parts.append(f"{name}={float(to_display(name, value)):g}"
                     + ("" if unit == "1" else f" {unit}"))
    note = res.point
    if res.point == EXACT:
        note += (" at this design (between grid points in " + ", ".join(res.interpolated)
                 + "; evaluated with the cube's materials and settings)")
    elif res.interpolated:
        note += (" linearly in " + ", ".join(res.interpolated)
                 + " between grid points (--interpolate; the exact model may differ)")
        if getattr(res, "flags", None):
            note += f"; limit and validity: {res.flags}"
    return ", ".join(parts) + f": {note}"


def _all_nan(res, name) -> bool:
    x = res.data[name]
    return name != "model" and len(x) > 0 and not np.isfinite(np.asarray(x, float)).any()


def shown_columns(res, fmt="table") -> tuple:
    """The columns a format prints: those ``--columns`` named; else, for a table, the
    axes, the asked-for variables and the headline ones (:func:`default_columns`), and for
    JSON and CSV every column. A table leaves out a column no row has a value in
    (``heating_time`` without a supply) unless ``--columns`` named it."""
    if res.chosen is not None:
        return (("model",) if "model" in res.columns else ()) + res.chosen
    if fmt != "table":
        return res.columns
    names = res.columns if getattr(res, "every", False) else \
        default_columns(res.columns, res.asked)
    return tuple(n for n in names if not _all_nan(res, n))


def format_table(res) -> str:
    """Aligned text in display units: a key/value list for one design, else a table."""
    out = io.StringIO()
    n = len(res)
    if res.single and n == 1:
        print(f"design at {_describe_at(res)}", file=out)
        names = [*DESIGN, *(c for c in res.columns if c in OPTIONAL)] \
            if res.chosen is None else [c for c in res.chosen if c not in AXES]
        for name in names:
            if res.chosen is None and _all_nan(res, name):
                continue  # heating_time without a supply
            x = res.data[name][0]
            unit = _unit(name)
            text = _cell(name, x)
            if name == "limit":
                text = {"stroke": "stroke-limited (full range of motion)",
                        "strength": "strength-limited (the nylon's strength cuts in)",
                        "supply": "supply-limited (the supply cannot heat it to T_max)",
                        "load": "load-limited (the muscle stalls against the wrap's load)",
                        "boundary": "between grid points that disagree: refine the grid"
                        }[text]
            elif unit != "1":
                text += f" {unit}"
            print(f"  {name:<16} {text}", file=out)
        return out.getvalue()
    if res.at:
        print(f"at {_describe_at(res)}", file=out)
    heads = list(shown_columns(res, "table"))
    units = [("[" + _unit(h) + "]") if _unit(h) != "1" else "" for h in heads]
    cells = [[_cell(h, res.data[h][i]) for h in heads] for i in range(n)]
    widths = [max(len(h), len(u), *(len(r[j]) for r in cells)) for j, (h, u) in
              enumerate(zip(heads, units))] if cells else [max(len(h), len(u)) for h, u in
                                                          zip(heads, units)]
    # names to the left (the model column), numbers to the right
    just = [str.ljust if h == "model" else str.rjust for h in heads]
    print("  ".join(j(h, w) for h, w, j in zip(heads, widths, just)), file=out)
    print("  ".join(j(u, w) for u, w, j in zip(units, widths, just)), file=out)
    for r in cells:
        print("  ".join(j(c, w) for c, w, j in zip(r, widths, just)), file=out)
    print(rows_note(res), file=out)
    return out.getvalue()


def held_back(res) -> int:
    """How many matching designs a result does not show (past ``--limit``)."""
    return 0 if res.matched is None else max(0, res.matched - len(res))


def rows_note(res) -> str:
    """``"20 designs shown of 11808 matching; 11788 held back (--limit N or --limit all)"``."""
    n = len(res)
    shown = f"{n} design{'s' if n != 1 else ''}"
    hidden = held_back(res)
    if hidden:
        return (f"{shown} shown of {res.matched} matching; {hidden} held back "
                "(--limit N for more, --limit all for every one)")
    return shown


def _json_value(name, x):
    if name == "model":
        return str(x)
    if name in INTEGERS:
        return _integer(x)
    x = float(x)
    return x if math.isfinite(x) else None


def _records(res):
    """One dict per design: its ``point`` (an ``--at`` query) and SI values by column."""
    columns = shown_columns(res, "json")
    records = []
    for i in range(len(res)):
        rec = {"point": res.point} if res.point else {}
        rec.update({name: _json_value(name, res.data[name][i]) for name in columns})
        records.append(rec)
    return records


def format_json(res) -> str:
    """One JSON object (docs/interface.md): ``{"designs": [{...}, ...], "units": {...},
    "matching": N, "shown": M}``; SI values, ``limit`` and ``validity`` as integers (their
    meanings under ``flags``), null where unknown."""
    columns = shown_columns(res, "json")
    doc = {"designs": _records(res),
           "units": {name: _var(name).units for name in columns},
           "matching": res.matched if res.matched is not None else len(res),
           "shown": len(res)}
    if res.point:
        doc["point"] = res.point
    flags = {}
    if "limit" in columns:
        attrs = VARIABLES["limit"].attrs()
        flags["limit"] = dict(zip((str(int(v)) for v in attrs["flag_values"]),
                                  attrs["flag_meanings"].split()))
    if "validity" in columns:
        flags["validity"] = {str(k): v for k, v in _flag_meanings("validity").items()}
    if flags:
        doc["flags"] = flags
    return json.dumps(doc, indent=1) + "\n"


def format_csv(res) -> str:
    """CSV in SI, one row per design; the header names the units (``radius [m]``)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    columns = shown_columns(res, "csv")
    head = ([] if not res.point else ["point"]) + \
        [n if n == "model" else f"{n} [{VARIABLES[n].units}]" for n in columns]
    w.writerow(head)
    for i in range(len(res)):
        row = [] if not res.point else [res.point]
        for name in columns:
            x = _json_value(name, res.data[name][i])
            row.append("" if x is None else x if isinstance(x, (str, int)) else repr(x))
        w.writerow(row)
    return out.getvalue()
