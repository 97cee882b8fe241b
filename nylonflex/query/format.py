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

from ..variables import AXES, CATEGORIES, COOLING, DESIGN, MODEL, SPREAD, VARIABLES, to_display
from ..conditions import EXACT, OPTIONAL, default_columns


def _var(name):
    return {"model": MODEL, "cooling": COOLING}.get(name) or VARIABLES[name]


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
INTEGERS = ("limit", "validity", "validity_model_any")


def _integer(x):
    """A flag's value as an int, None when unknown (NaN)."""
    x = float(x)
    return int(x) if math.isfinite(x) else None


def cell_text(name, x) -> str:
    """The table text of value ``x`` [SI] of column ``name``: the model's name, the validity
    flags by name, the limit by word, an axis in its display unit to 6 digits, any other
    variable in its display unit to 3 significant digits."""
    if name in CATEGORIES:
        return str(x)
    if name in ("validity", "validity_model_any"):
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
    return name not in CATEGORIES and len(x) > 0 and not np.isfinite(np.asarray(x, float)).any()


def shown_columns(res, fmt="table") -> tuple:
    """The columns a format prints: those ``--columns`` named; else, for a table, the
    axes, the asked-for variables and the headline ones (:func:`default_columns`), and for
    JSON and CSV every column. A table leaves out a column no row has a value in
    (``heating_time`` without a supply) unless ``--columns`` named it."""
    if res.chosen is not None:
        return tuple(c for c in CATEGORIES if c in res.columns) + res.chosen
    if fmt != "table":
        return res.columns
    names = res.columns if getattr(res, "every", False) else \
        default_columns(res.columns, res.asked)
    return tuple(n for n in names if not _all_nan(res, n))


def _band_notes(res, names) -> dict:
    """``{name: "   (models 1.20 .. 1.82 N)"}``: a one-design answer's range over the cube's
    model spread (docs/model.md s. 23) of each value that has one; ``validity`` the flags of
    any variant."""
    out = {}
    for name in names:
        lo, hi = f"{name}_model_lo", f"{name}_model_hi"
        if lo in names and hi in names:
            unit = "" if _unit(name) == "1" else f" {_unit(name)}"
            out[name] = (f"   (models {cell_text(lo, res.data[lo][0])} .. "
                         f"{cell_text(hi, res.data[hi][0])}{unit})")
    if "validity" in names and "validity_model_any" in names:
        out["validity"] = f"   (any model: {cell_text('validity_model_any', res.data['validity_model_any'][0])})"
    return out


def format_table(res) -> str:
    """Aligned text in display units: a key/value list for one design, else a table."""
    out = io.StringIO()
    n = len(res)
    if res.single and n == 1:
        print(f"design at {_describe_at(res)}", file=out)
        names = [*DESIGN, *(c for c in res.columns if c in OPTIONAL)] \
            if res.chosen is None else [c for c in res.chosen if c not in AXES]
        # a model spread: each range beside its value, not on lines of its own
        band = {} if res.chosen is not None else _band_notes(res, names)
        for name in names:
            if res.chosen is None and (_all_nan(res, name) or name in SPREAD):
                continue  # heating_time without a supply; a range shown beside its value
            x = res.data[name][0]
            unit = _unit(name)
            text = cell_text(name, x)
            if name == "limit":
                text = {"stroke": "stroke-limited (full range of motion)",
                        "strength": "strength-limited (the nylon's strength cuts in)",
                        "supply": "supply-limited (the supply cannot heat it to T_max)",
                        "load": "load-limited (the muscle stalls against the wrap's load)",
                        "boundary": "between grid points that disagree: refine the grid"
                        }[text]
            elif unit != "1":
                text += f" {unit}"
            print(f"  {name:<16} {text}{band.get(name, '')}", file=out)
        return out.getvalue()
    if res.at:
        print(f"at {_describe_at(res)}", file=out)
    heads = list(shown_columns(res, "table"))
    cells = [[cell_text(h, res.data[h][i]) for h in heads] for i in range(n)]
    for line in _columns_text(heads, cells):
        print(line, file=out)
    print(rows_note(res), file=out)
    return out.getvalue()


#: The widest line a query table prints [characters].
WIDTH = 120


def _name_lines(name, width) -> list[str]:
    """``name`` over as few lines as fit in ``width``, broken after its underscores
    (``"wall_"``, ``"thickness"``); a word longer than ``width`` keeps its line."""
    pieces = [w + "_" for w in name.split("_")[:-1]] + [name.split("_")[-1]]
    lines = [pieces[0]]
    for piece in pieces[1:]:
        if len(lines[-1]) + len(piece) <= width:
            lines[-1] += piece
        else:
            lines.append(piece)
    return lines


def _columns_text(heads, cells, width=WIDTH) -> list[str]:
    """The lines of a table of ``cells`` under ``heads`` (a unit line below the names), at
    most ``width`` wide where it can be: first in one line per name; else with long names
    broken after their underscores over a few header lines; else in blocks of columns, each
    led by a row number ``#``."""
    units = [("[" + _unit(h) + "]") if _unit(h) != "1" else "" for h in heads]
    body = [max([len(u), *(len(r[j]) for r in cells)]) for j, u in enumerate(units)]

    def render(cols, names):
        widths = [max(body[j], *(len(x) for x in names[j])) for j in cols]
        # names to the left (the model and cooling columns), numbers to the right
        just = [str.ljust if heads[j] in CATEGORIES else str.rjust for j in cols]
        depth = max(len(names[j]) for j in cols)
        head = [[""] * (depth - len(names[j])) + names[j] for j in cols]
        lines = ["  ".join(jf(h[k], w) for h, w, jf in zip(head, widths, just)).rstrip()
                 for k in range(depth)]
        lines.append("  ".join(jf(units[j], w) for j, w, jf in zip(cols, widths, just)))
        lines += ["  ".join(jf(r[j], w) for j, w, jf in zip(cols, widths, just))
                  for r in cells]
        return lines

    every = list(range(len(heads)))
    lines = render(every, [[h] for h in heads])
    if max(map(len, lines)) <= width:
        return lines
    names = [_name_lines(h, max(body[j], 1)) for j, h in enumerate(heads)]
    lines = render(every, names)
    if max(map(len, lines)) <= width:
        return lines
    # blocks of columns: each starts with the row number, then as many columns as fit
    number = [str(i + 1) for i in range(len(cells))]
    lead = max([1, *map(len, number)])
    blocks, current, used = [], [], lead
    for j in every:
        w = max(body[j], *(len(x) for x in names[j]))
        if current and used + 2 + w > width:
            blocks.append(current)
            current, used = [], lead
        current.append(j)
        used += 2 + w
    blocks.append(current)
    out = []
    for b, cols in enumerate(blocks):
        part = render(cols, names)
        depth = len(part) - len(cells)
        tags = [""] * (depth - 2) + ["#", ""] + number
        if b:
            out.append("")
        out += [(t.rjust(lead) + "  " + line).rstrip() for t, line in zip(tags, part)]
    return out


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
    if name in CATEGORIES:
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
    for name in ("validity", "validity_model_any"):
        if name in columns:
            flags[name] = {str(k): v for k, v in _flag_meanings("validity").items()}
    if flags:
        doc["flags"] = flags
    return json.dumps(doc, indent=1) + "\n"


def format_csv(res) -> str:
    """CSV in SI, one row per design; the header names the units (``radius [m]``)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    columns = shown_columns(res, "csv")
    head = ([] if not res.point else ["point"]) + \
        [n if n in CATEGORIES else f"{n} [{VARIABLES[n].units}]" for n in columns]
    w.writerow(head)
    for i in range(len(res)):
        row = [] if not res.point else [res.point]
        for name in columns:
            x = _json_value(name, res.data[name][i])
            row.append("" if x is None else x if isinstance(x, (str, int)) else repr(x))
        w.writerow(row)
    return out.getvalue()
