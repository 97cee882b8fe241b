"""The output of ``nylonflex query``: aligned text in display units, JSON and CSV in SI."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np

from ..variables import AXES, DESIGN, MODEL, VARIABLES, to_display
from .parse import EXACT, OPTIONAL


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


def _cell(name, x) -> str:
    if name == "model":
        return str(x)
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
    return ", ".join(parts) + f": {note}"


def format_table(res) -> str:
    """Aligned text in display units: a key/value list for one design, else a table."""
    out = io.StringIO()
    n = len(res)
    if res.single and n == 1:
        print(f"design at {_describe_at(res)}", file=out)
        for name in [*DESIGN, *(c for c in res.columns if c in OPTIONAL)]:
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
    heads = list(res.columns)
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


def _json_value(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _records(res):
    units = {name: _var(name).units for name in res.columns}
    records = []
    for i in range(len(res)):
        rec = {}
        if res.point:
            rec["point"] = res.point
        for name in res.columns:
            x = res.data[name][i]
            if name == "model":
                rec[name] = str(x)
                continue
            rec[name] = (None if not np.isfinite(x) else int(x)) if name == "limit" \
                else _json_value(x)
        rec["units"] = units
        records.append(rec)
    return records


def format_json(res) -> str:
    """One JSON object for one design, else a list; SI values with a ``units`` map."""
    records = _records(res)
    doc = records[0] if res.single and len(records) == 1 else records
    return json.dumps(doc, indent=1) + "\n"


def format_csv(res) -> str:
    """CSV in SI, one row per design; the header names the units (``radius [m]``)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    head = ([] if not res.point else ["point"]) + \
        [n if n == "model" else f"{n} [{VARIABLES[n].units}]" for n in res.columns]
    w.writerow(head)
    for i in range(len(res)):
        row = [] if not res.point else [res.point]
        for name in res.columns:
            x = res.data[name][i]
            if name == "model":
                row.append(str(x))
            elif name == "limit":
                row.append("" if not np.isfinite(x) else int(x))
            else:
                row.append("" if not np.isfinite(x) else repr(float(x)))
        w.writerow(row)
    return out.getvalue()
