"""A design result as text: a table in display units, JSON or CSV in SI."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np

from ..query import COLUMNS, cell_text, default_columns
from ..query.format import INTEGERS
from ..variables import VARIABLES, to_display

__all__ = ["format_csv", "format_json", "format_table"]


def _columns(res):
    extra = [k for d in res.designs[:1] for k in d
             if k not in COLUMNS and k not in ("source", "alternatives")]
    return [*COLUMNS, *extra]


def _table_columns(res):
    """A table's columns: the axes, the objectives and constrained variables, then the
    headline ones (as ``query`` shows them), leaving out columns no design has a value in."""
    asked = [o.name for o in res.spec.objectives] + [c.name for c in res.spec.constraints]
    cols = [c for c in default_columns(_columns(res), asked)
            if any(math.isfinite(float(d[c])) for d in res.designs)]
    if any(d.get("alternatives") for d in res.designs):
        cols.append("alternatives")
    return cols


def _alternatives_text(alt, steps=None) -> str:
    """``"wrap_angle 5-15, 20 deg"``: the values of the axes over which the design is the
    same; a run of consecutive multiples of the axis's resolution step (``steps``,
    {axis: SI step}) as ``lo-hi``."""
    parts = []
    for name, values in alt.items():
        unit = VARIABLES[name].display
        shown = [f"{float(to_display(name, v)):.6g}" for v in values]
        step = (steps or {}).get(name)
        runs, start = [], 0
        for i in range(1, len(values) + 1):
            if i < len(values) and step and \
                    abs((values[i] - values[i - 1]) / step - 1.0) < 1e-6:
                continue
            runs.append(shown[start] if i - 1 == start else
                        f"{shown[start]}, {shown[i - 1]}" if i - 1 == start + 1 else
                        f"{shown[start]}-{shown[i - 1]}")
            start = i
        parts.append(f"{name} " + ", ".join(runs) + ("" if unit == "1" else f" {unit}"))
    return "; ".join(parts)


def _shown(name, x) -> str:
    unit = VARIABLES[name].display if name in VARIABLES else "1"
    return f"{float(to_display(name, x)) if name in VARIABLES else x:.4g}" + \
        ("" if unit == "1" else f" {unit}")


def summary(res) -> list:
    """Lines that say what was asked, what the grid gave and what refinement added."""
    spec, scan = res.spec, res.scan
    under = "" if getattr(res, "model", "paper") == "paper" else f" (model {res.model})"
    lines = [f"design '{spec.name}'{under}: " + ", ".join(str(o) for o in spec.objectives)
             + (" subject to " + "; ".join(c.text for c in spec.constraints)
                if spec.constraints else "")]
    if not res.designs:
        if scan.feasible:
            lines.append(f"infeasible once evaluated exactly: {scan.feasible} of the "
                         f"{scan.total} designs scanned meet every constraint in the cube")
        else:
            lines.append(f"infeasible: none of the {scan.total} designs scanned meets every "
                         "constraint")
        lines += [f"  {r}" for r in res.reasons]
        return lines
    lines.append(f"grid: {scan.feasible} of {scan.total} designs feasible")
    for name, (g, b, rel) in res.improvement.items():
        if name == "hypervolume":
            lines.append(f"refined front: {len(res.reported_rows()['radius'])} designs "
                         f"({sum(d['source'] == 'refined' for d in res.designs)} refined); "
                         f"it dominates or equals the grid front of "
                         f"{len(res.grid_front['radius'])}; dominated area +{100 * rel:.2f} %")
        else:
            how = (f"refined {_shown(name, b)}, {100 * rel:+.2f} %" if b != g else
                   "refinement found nothing better (the optimum sits on the grid, at "
                   "the bounds the constraints allow)")
            lines.append(f"best grid point: {name} {_shown(name, g)}; {how}")
    if not res.improvement and len(spec.objectives) == 1:
        name = spec.objectives[0].name
        lines.append(f"best grid point: {name} {_shown(name, res.designs[0][name])} "
                     "(refine is off)")
    elif not res.improvement:
        lines.append(f"grid front: {len(res.designs)} designs (refine is off)")
    lines += _density(res)
    if res.dropped:
        lines.append(f"{res.dropped} design(s) dropped: exact re-evaluation broke "
                     "a constraint")
    snapped = getattr(res, "snapped", {}) or {}
    if snapped.get("steps"):
        steps = ", ".join(f"{n} {_shown(n, v)}" for n, v in snapped["steps"].items())
        lines.append(f"resolution {steps}: every design snapped to it and re-checked "
                     f"exactly ({snapped['candidates']} on-resolution candidates met every "
                     "constraint" + (f"; {snapped['lost']} design(s) had no on-resolution "
                                     "neighbour that does" if snapped["lost"] else "") + ")")
        if snapped.get("lattice_moves"):
            lines.append(f"lattice search: {snapped['lattice_moves']} reported design(s) moved "
                         "to a better buildable design a step or more away (the front "
                         "re-optimised on the resolution)")
    if snapped.get("merged"):
        lines.append(f"{snapped['merged']} design(s) equal in every objective merged into "
                     "the row listing them under 'alternatives'")
    lines.append(f"{res.evaluations} exact evaluations")
    return lines


def _density(res) -> list:
    """Two objectives: how densely the front covers the second, and its largest gap."""
    if len(res.spec.objectives) != 2 or len(res.designs) < 2:
        return []
    name = res.spec.objectives[1].name
    v = np.unique([d[name] for d in res.designs])
    if len(v) < 2:
        return []
    gaps = np.diff(v)
    k = int(np.argmax(gaps))
    return [f"front density: {len(res.designs)} designs over {name} {_shown(name, v[0])} .. "
            f"{_shown(name, v[-1])}, median gap {_shown(name, float(np.median(gaps)))}, "
            f"largest gap {_shown(name, gaps[k])} (between {_shown(name, v[k])} and "
            f"{_shown(name, v[k + 1])}); between neighbours the front is not searched and "
            "a design there may beat the nearer front design"]


def format_table(res) -> str:
    """The summary, then the designs in display units."""
    out = io.StringIO()
    for line in summary(res):
        print(line, file=out)
    if not res.designs:
        return out.getvalue()
    heads = ["source", *_table_columns(res)]
    units = [""] + [f"[{VARIABLES[h].display}]" if h in VARIABLES and
                    VARIABLES[h].display != "1" else "" for h in heads[1:]]

    def cell(h, d):
        if h == "alternatives":
            return _alternatives_text(d.get("alternatives") or {}, res.spec.resolution)
        return cell_text(h, d[h]) if h in VARIABLES else f"{d[h]:g}"

    cells = [[d["source"]] + [cell(h, d) for h in heads[1:]] for d in res.designs]
    widths = [max(len(h), len(u), *(len(r[j]) for r in cells))
              for j, (h, u) in enumerate(zip(heads, units))]
    just = [str.ljust if h == "alternatives" else str.rjust for h in heads]
    print("  ".join(j(h, w) for h, w, j in zip(heads, widths, just)).rstrip(), file=out)
    print("  ".join(j(u, w) for u, w, j in zip(units, widths, just)).rstrip(), file=out)
    for r in cells:
        print("  ".join(j(c, w) for c, w, j in zip(r, widths, just)).rstrip(), file=out)
    return out.getvalue()


def _value(name, x):
    if name in INTEGERS:
        return int(x) if math.isfinite(x) else None
    return float(x) if math.isfinite(x) else None


def format_json(res) -> str:
    """``{"designs": [{...SI..., "source": ...}], "units": {...}}`` (docs/interface.md);
    a design into which others equal in every objective were merged lists their differing
    axes under ``alternatives`` (``{axis: [SI values]}``)."""
    cols = _columns(res)
    designs = [{**{k: _value(k, d[k]) for k in cols}, "source": d["source"],
                **({"alternatives": d["alternatives"]} if "alternatives" in d else {})}
               for d in res.designs]
    units = {k: VARIABLES[k].units if k in VARIABLES else "1" for k in cols}
    return json.dumps({"designs": designs, "units": units}, indent=1) + "\n"


def format_csv(res) -> str:
    """CSV in SI, one row per design; the header names the units (``radius [m]``)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    cols = _columns(res)
    w.writerow(["source"] + [f"{k} [{VARIABLES[k].units if k in VARIABLES else '1'}]"
                             for k in cols])
    for d in res.designs:
        w.writerow([d["source"]] + ["" if _value(k, d[k]) is None else
                                    (_value(k, d[k]) if k in INTEGERS else
                                     repr(float(d[k])))
                                    for k in cols])
    return out.getvalue()
