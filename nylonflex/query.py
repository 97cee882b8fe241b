"""``nylonflex query``: ask a saved cube about designs, with units, in bounded memory.

A query picks designs three ways, which combine:

* ``--at radius=7.5mm,coil_index=1.7``: fixes the named axes. A value on the grid (within a
  tiny tolerance) is read as is ("grid point"); between grid points the model is evaluated
  exactly at that design with the cube's own materials and settings from its provenance
  ("exact model", :func:`nylonflex.evaluate`, milliseconds), or, with ``interpolate=True``
  (``--interpolate``), the design variables are interpolated linearly in each axis
  ("interpolated"; up to tens of per cent off where the response bends). Axes not named
  keep all their grid values, so a partial ``--at`` lists a slice of the cube (one row per
  design); naming all five axes gives one design. Outside the grid is refused.
* ``--where "tip_force_max >= 0.5 N"``: conditions on axes or design variables, with units;
  several are ANDed.
* ``--sort NAME`` (``--sort=-NAME`` or ``--sort NAME:desc`` descending; ties keep grid
  order) and ``--limit N``.

The cube is read in slabs of radii, so memory stays bounded on a cube of any size; only the
matching rows (at most ``--limit``) are kept, and every match is counted, so that the
output can say how many rows it held back.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re

import numpy as np

from .units import InputError, from_si, parse_quantity
from .variables import AXES, DESIGN, MODEL, VARIABLES, to_display

__all__ = ["EXACT", "GRID", "INTERPOLATED", "Condition", "QueryResult", "format_csv", "format_json", "format_table",
           "held_back", "parse_at", "parse_where", "query_cube", "rows_note"]

#: Columns of every row: the five axes, then the design variables (registry order).
COLUMNS = (*AXES, *DESIGN)
#: Columns a cube has only when its sweep asked for them (``requirements``).
OPTIONAL = ("feasibility",)
_FIELDS = ", ".join(COLUMNS + OPTIONAL)
# Values this close (relative to the axis span) to a grid value are that grid value.
_GRID_RTOL = 1e-6
# Slab size when scanning a cube: about this many float64 values per variable.
_SLAB_VALUES = 2**20
#: How an ``--at`` design was found: on the grid, by the exact model, interpolated.
GRID, EXACT, INTERPOLATED = "grid point", "exact model", "interpolated"
_LIMIT_WORDS = {"stroke": 0, "stroke_limited": 0, "strength": 1, "strength_limited": 1,
                "supply": 2, "supply_limited": 2, "load": 3, "load_limited": 3}


# ---------------------------------------------------------------------------- parsing
def _quantity(name, text, field):
    v = VARIABLES[name]
    if name == "limit" and str(text).strip().lower() in _LIMIT_WORDS:
        return float(_LIMIT_WORDS[str(text).strip().lower()])
    return parse_quantity(text, field, v.kind, v.display)


def parse_at(text) -> dict:
    """Parse ``"radius=7.5mm,wall_thickness=2mm"`` into ``{axis: SI value}``.

    Bare numbers are in the axis's display unit (mm, deg; none for ``coil_index``). A list
    of such texts (``--at`` given several times) is merged into one design.

    Raises
    ------
    InputError
        Not ``NAME=VALUE``, an unknown axis, an axis given twice (in one text or across
        several) or a bad value.
    """
    texts = [text] if isinstance(text, str) else list(text or ())
    repeated = len(texts) > 1
    out = {}
    for part in [p for t in texts for p in str(t).split(",") if p.strip()]:
        if "=" not in part:
            raise InputError(f"--at: expected NAME=VALUE, got {part.strip()!r}; names: "
                             f"{', '.join(AXES)}")
        name, value = (s.strip() for s in part.split("=", 1))
        if name not in AXES:
            raise InputError(f"--at: unknown axis {name!r}; accepted: {', '.join(AXES)}")
        if name in out:
            where = " (across repeated --at options, which are merged into one design)" \
                if repeated else ""
            raise InputError(f"--at: {name} given twice{where}; --at picks one design: "
                             f"give each axis once, or use --where for a range, e.g. "
                             f"--where \"{name} >= ...\"")
        out[name] = float(_quantity(name, value, f"--at {name}"))
    if not out:
        raise InputError(f"--at: expected NAME=VALUE,...; names: {', '.join(AXES)}")
    return out


class Condition:
    """One ``--where`` condition: ``name op value`` with ``value`` in SI."""

    _OPS = {"<=": np.less_equal, ">=": np.greater_equal, "<": np.less, ">": np.greater,
            "==": None, "=": None, "!=": None}
    _PATTERN = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|==|!=|<|>|=)\s*(.+?)\s*$")

    def __init__(self, text: str):
        if str(text).strip() == "valid":  # issue 10: clean designs, validity == 0
            text = "validity == 0"
        m = self._PATTERN.match(str(text))
        if not m:
            raise InputError(f"--where: expected 'NAME OP VALUE [UNIT]' with OP one of "
                             f"<, <=, ==, !=, >=, >, got {text!r}")
        self.name, op, value = m.groups()
        if self.name not in COLUMNS + OPTIONAL:
            raise InputError(f"--where: unknown name {self.name!r}; accepted: {_FIELDS}")
        self.op = "==" if op == "=" else op
        self.value = float(_quantity(self.name, value, f"--where {self.name}"))
        self.text = str(text).strip()

    def mask(self, x: np.ndarray) -> np.ndarray:
        """True where ``x`` [SI] meets the condition (NaN never does)."""
        if self.op in ("==", "!="):
            # equality to a typed value up to its float noise (7.5 mm, 8 deg, 1)
            near = np.isclose(x, self.value, rtol=1e-9, atol=1e-12 * max(1.0, abs(self.value)))
            return near if self.op == "==" else ~near & ~np.isnan(x)
        return self._OPS[self.op](x, self.value)

    def __repr__(self):
        return f"Condition({self.text!r})"


def parse_where(texts) -> list[Condition]:
    """Parse ``--where`` strings (ANDed) into :class:`Condition` objects.

    ``model == NAME`` stays a string: :func:`query_cube` selects that model's slice.
    """
    return [t if _MODEL_WHERE.match(str(t)) else Condition(t) for t in texts or ()]


def _parse_sort(text):
    if not text:
        return None, False
    name = text.strip()
    descending = name.startswith("-")
    name = name.lstrip("-+").strip()
    # "NAME:desc" too: argparse reads "--sort -NAME" as an option (write --sort=-NAME)
    if ":" in name:
        name, order = (s.strip() for s in name.split(":", 1))
        if order not in ("asc", "desc"):
            raise InputError(f"--sort: order must be 'asc' or 'desc', got {order!r}")
        descending = order == "desc"
    if name not in COLUMNS + OPTIONAL:
        raise InputError(f"--sort: unknown name {name!r}; accepted: {_FIELDS} "
                         "(prefix '-' for descending)")
    return name, descending


# ---------------------------------------------------------------------------- the grid
def _locate(ds, name, value):
    """Where ``value`` [SI] sits on axis ``name``: ``(i0, i1, weight of i1, on_grid)``.

    Raises
    ------
    InputError
        The value lies outside the axis's range (the message gives it in display units).
    """
    grid = ds[name].values.astype(float)
    lo, hi = float(grid.min()), float(grid.max())
    tol = _GRID_RTOL * max(hi - lo, abs(hi), abs(lo), 1e-300)
    near = int(np.argmin(np.abs(grid - value)))
    if abs(grid[near] - value) <= tol:
        return near, near, 0.0, True
    if not lo - tol <= value <= hi + tol:
        v = VARIABLES[name]
        unit = "" if v.display == "1" else f" {v.display}"
        shown = ", ".join(f"{x:g}" for x in from_si(grid, v.display)) if grid.size <= 8 \
            else f"{from_si(lo, v.display):g} .. {from_si(hi, v.display):g}"
        raise InputError(f"--at: {name}={from_si(value, v.display):g}{unit} is outside the "
                         f"cube's grid; {name} takes {shown}{unit}")
    if np.any(np.diff(grid) <= 0):  # a grid the sweep wrote is increasing; be safe
        raise InputError(f"--at: the cube's {name} axis is not increasing; cannot interpolate")
    i1 = int(np.searchsorted(grid, value))
    i0 = i1 - 1
    return i0, i1, float((value - grid[i0]) / (grid[i1] - grid[i0])), False


# ---------------------------------------------------------------------------- the scan
class QueryResult:
    """Rows of a query: ``data`` maps each column to an SI array.

    Attributes
    ----------
    data : dict of str to numpy.ndarray
        One array per column of :data:`COLUMNS`, SI.
    point : str or None
        ``"grid point"``, ``"exact model"`` or ``"interpolated"`` for an ``--at`` query,
        else None.
    interpolated : list of str
        The ``--at`` axes that lie between grid points (evaluated exactly, or interpolated
        when ``point`` is ``"interpolated"``).
    matched : int or None
        Designs that met the conditions (every one is counted, shown or not).
    single : bool
        The query named one design (all five axes in ``--at``).
    """

    def __init__(self, data, point, interpolated, matched, single, at, columns=COLUMNS):
        self.data, self.point, self.interpolated = data, point, interpolated
        self.matched, self.single, self.at = matched, single, at
        self.columns = tuple(columns)  # COLUMNS and the cube's OPTIONAL ones

    def __len__(self):
        return len(self.data[COLUMNS[0]])


def _slab_rows(ds, at_loc, r0, r1):
    """Rows (SI arrays by column) of radius indices [r0, r1) after ``--at`` selection."""
    # read each given axis's bracketing pair (one index on a grid point), then collapse it
    index = {name: slice(i0, i1 + 1) for name, (i0, i1, _, _) in at_loc.items()
             if name != "radius"}
    index["radius"] = slice(r0, r1)
    names = [n for n in (*DESIGN, *OPTIONAL) if n in ds]
    sub = ds[names].isel(index).load()
    sub = sub.astype(float)  # limit: int8 (float when masked); NaN marks unknown below
    for name, (i0, i1, w, on_grid) in at_loc.items():
        if on_grid or i0 == i1:
            sub = sub.isel({name: 0})
            continue
        a, b = sub.isel({name: 0}), sub.isel({name: 1})
        mixed = (a["limit"] != b["limit"]) | a["limit"].isnull() | b["limit"].isnull()
        if name == "length":
            # F* = M*/L and theta* = kappa(p*) L (docs/model.md s. 8): interpolate the
            # length-free M* and kappa*, exact along this axis, then scale back
            la, lb = (float(ds["length"].values[k]) for k in at_loc["length"][:2])
            length = la * (1.0 - w) + lb * w
            a["tip_force_max"], b["tip_force_max"] = (a["tip_force_max"] * la,
                                                      b["tip_force_max"] * lb)
            a["bend_angle_max"], b["bend_angle_max"] = (a["bend_angle_max"] / la,
                                                        b["bend_angle_max"] / lb)
        sub = a * (1.0 - w) + b * w
        if name == "length":
            sub["tip_force_max"] = sub["tip_force_max"] / length
            sub["bend_angle_max"] = sub["bend_angle_max"] * length
        # a limit between two grid points is known only where both agree
        sub["limit"] = a["limit"].where(~mixed)
    # a cube of several models: the model is the last (fastest) axis of the rows
    dims = [d for d in (*AXES, "model") if d in sub.dims]
    shape = [sub.sizes[d] for d in dims]
    if "model" in sub.dims:  # model-free variables: the same value for every model
        sub = sub.map(lambda v: v if "model" in v.dims else v.expand_dims(model=sub["model"]))
    rows = {}
    for name in AXES:
        if name in sub.dims:
            axis_shape = [-1 if d == name else 1 for d in dims]
            coord = sub[name].values.astype(float).reshape(axis_shape)
            rows[name] = np.broadcast_to(coord, shape).reshape(-1)
        else:
            rows[name] = np.full(int(np.prod(shape)), at_value(at_loc, name, ds))
    if "model" in sub.dims:
        names = sub["model"].values.astype(str).astype(object)
        rows["model"] = np.broadcast_to(names.reshape([1] * (len(dims) - 1) + [-1]),
                                        shape).reshape(-1)
    for name in DESIGN:
        rows[name] = sub[name].transpose(*dims).values.reshape(-1) if name in sub else \
            np.full(int(np.prod(shape)), np.nan)  # heating_time: only with a supply
    for name in (n for n in OPTIONAL if n in sub):
        rows[name] = sub[name].transpose(*dims).values.reshape(-1)
    return rows


def at_value(at_loc, name, ds):
    """SI value of an ``--at`` axis after location (the grid value on a grid point)."""
    i0, i1, w, on_grid = at_loc[name]
    grid = ds[name].values.astype(float)
    return float(grid[i0]) if on_grid else float(grid[i0] * (1 - w) + grid[i1] * w)


def _exact_rows(ds, at, at_loc, r0, r1, settings):
    """Rows of radius indices [r0, r1) with the design variables from the exact model.

    The ``--at`` axes take their typed values (the grid value on a grid point), the others
    their grid values; :func:`nylonflex.evaluate` computes every design variable there with
    the cube's materials and settings (``settings``, from its provenance).
    """
    from .engine.pointwise import evaluate

    free = [name for name in AXES if name not in at_loc]
    grids = []
    for name in free:
        values = ds[name].values.astype(float)
        grids.append(values[r0:r1] if name == "radius" else values)
    mesh = np.meshgrid(*grids, indexing="ij") if grids else []
    n = int(np.prod([len(g) for g in grids])) if grids else 1
    rows = {}
    for name in AXES:
        if name in at_loc:
            value = at_value(at_loc, name, ds) if at_loc[name][3] else float(at[name])
            rows[name] = np.full(n, value)
        else:
            rows[name] = mesh[free.index(name)].reshape(-1)
    out = evaluate(*(rows[name] for name in AXES), **settings)
    for name in DESIGN:
        rows[name] = np.asarray(out[name], dtype=float).reshape(-1)
    return rows


def _exact_settings(ds):
    from .engine.provenance import evaluate_settings

    try:
        settings = evaluate_settings(ds.attrs)
    except ValueError as err:
        raise InputError(f"--at: {err}; use --interpolate to interpolate between grid "
                         "points instead") from None
    if isinstance(settings.get("model"), list):
        raise InputError("--at: this cube holds several models "
                         f"({', '.join(settings['model'])}); the exact model between grid "
                         "points needs one: use --interpolate, or query a one-model cube")
    return settings


def query_cube(ds, at=None, where=(), sort=None, limit=None, *, interpolate=False,
               progress=None, log=None) -> QueryResult:
    """Designs of a cube selected by ``--at``, filtered by ``--where``, sorted, limited.

    Parameters
    ----------
    ds : xarray.Dataset
        A cube from :func:`nylonflex.open_cube` (lazy; read slab by slab).
    at : dict or str or list of str, optional
        ``{axis: SI value}`` or the ``--at`` text(s).
    where : sequence of str or Condition
        Conditions, ANDed.
    sort : str, optional
        Column to sort by, ``-NAME`` for descending; ties keep grid order.
    limit : int, optional
        At most this many rows; every match is still counted (``matched``).
    interpolate : bool, default False
        Between grid points, interpolate the cube linearly instead of evaluating the
        exact model (:func:`nylonflex.evaluate`) with the cube's materials and settings.
    progress : callable, optional
        Called as ``progress(done, total)`` [slabs] after each slab of the scan.
    log : callable, optional
        Receives a one-line notice while the model's kernels compile (a first exact
        evaluation).

    Returns
    -------
    QueryResult

    Raises
    ------
    InputError
        Bad names, units or values, or an ``--at`` point outside the grid.
    """
    if isinstance(at, (str, list, tuple)):
        at = parse_at(at)
    at = dict(at or {})
    ds, where = _select_model(ds, where)
    conditions = [c if isinstance(c, Condition) else Condition(c) for c in where]
    sort_name, descending = _parse_sort(sort)
    columns = COLUMNS + tuple(n for n in OPTIONAL if n in ds)
    if "model" in ds.dims:  # every model at once: the model names each row
        columns = ("model", *columns)
    for name in [c.name for c in conditions] + [sort_name]:
        if name in OPTIONAL and name not in ds:
            raise InputError(f"{name}: the cube has no {name}; sweep a config with "
                             "'requirements' (docs/uncertainty.md)")
    if limit is not None and limit < 0:
        raise InputError(f"--limit: must be 0 or more, got {limit}")
    at_loc = {name: _locate(ds, name, value) for name, value in at.items()}
    off_grid = [name for name, loc in at_loc.items() if not loc[3]]
    exact = bool(off_grid) and not interpolate
    settings = _exact_settings(ds) if exact else None
    if exact and log is not None:
        from .engine.warmup import warm_up_points

        warm_up_points(settings, notice=log)

    # radius slabs: the --at bracket, or the whole axis cut to bounded memory
    if "radius" in at_loc:
        i0, i1 = at_loc["radius"][:2]
        slabs = [(i0, i1 + 1)]
    else:
        other = 1
        for name in AXES[1:]:
            other *= 2 if name in at_loc else ds.sizes[name]
        other *= ds.sizes.get("model", 1)
        step = max(1, _SLAB_VALUES // max(other, 1))
        slabs = [(r, min(r + step, ds.sizes["radius"]))
                 for r in range(0, ds.sizes["radius"], step)]
    done = ds["slab_done"].values.astype(bool) if "slab_done" in ds and not exact else None

    kept = {name: np.empty(0, dtype=object if name == "model" else float)
            for name in columns}
    matched = 0
    for k, (r0, r1) in enumerate(slabs):
        if done is not None and "radius" not in at_loc and not done[r0:r1].any():
            if progress is not None:
                progress(k + 1, len(slabs))
            continue  # an incomplete cube: nothing computed here
        rows = _exact_rows(ds, at, at_loc, r0, r1, settings) if exact else \
            _slab_rows(ds, at_loc, r0, r1)
        mask = np.ones(len(rows[COLUMNS[0]]), dtype=bool)
        for c in conditions:
            mask &= c.mask(rows[c.name])
        if not conditions and done is not None and "radius" not in at_loc:
            mask &= ~np.isnan(rows["tip_force_max"])  # skip masked, uncomputed radii
        n = int(mask.sum())
        matched += n
        room = None if limit is None or sort_name is not None else \
            limit - len(kept[COLUMNS[0]])
        if room is None or room > 0:
            kept = {name: np.concatenate([kept[name], rows[name][mask][:room]])
                    for name in columns}
        if limit is not None and sort_name is not None:
            kept = _sorted(kept, sort_name, descending, limit)
        if progress is not None:
            progress(k + 1, len(slabs))
    if sort_name is not None:
        kept = _sorted(kept, sort_name, descending, limit)
    elif limit is not None:
        kept = {name: v[:limit] for name, v in kept.items()}
    point = None
    if at_loc:
        point = (EXACT if exact else INTERPOLATED) if off_grid else GRID
    return QueryResult(kept, point, off_grid, matched, single=len(at_loc) == len(AXES),
                       at=at, columns=columns)


_MODEL_WHERE = re.compile(r"^\s*model\s*(==|=)\s*([A-Za-z0-9_]+)\s*$")


def _select_model(ds, where):
    """The cube at the model a ``--where "model == NAME"`` names, and the other conditions.

    A cube of several models (docs/model.md s. 16) without such a condition is queried
    across every model at once (a ``model`` column names each row's).
    """
    where = list(where or ())
    names = [m.group(2) for m in (_MODEL_WHERE.match(str(w)) for w in where) if m]
    rest = [w for w in where if not _MODEL_WHERE.match(str(w))]
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else \
        str(ds.attrs.get("models", "paper")).split()
    for name in names:
        if name not in models:
            raise InputError(f"--where model: this cube has {', '.join(models)}, got {name!r}")
    if "model" not in ds.dims:
        return ds, rest
    if not names:
        return ds, rest
    if len(set(names)) != 1:
        raise InputError(f"--where: one model at a time ({', '.join(models)}), or none for "
                         f"every model; got {', '.join(sorted(set(names)))}")
    return ds.sel(model=names[0], drop=True), rest


def _sorted(rows, name, descending, limit):
    key = rows[name]
    # stable, NaN last either way; descending keeps ties in grid order too
    order = np.argsort(-key if descending else key, kind="stable")
    if limit is not None:
        order = order[:limit]
    return {k: v[order] for k, v in rows.items()}


# ---------------------------------------------------------------------------- output


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
