"""The scan of ``nylonflex query``: a cube read slab by slab, in chunk order.

``--where`` is tested one variable at a time (a slab none of whose designs passes is left
after the first variable that rules it out) and the other columns are read only over the
box of a slab's matching rows, so a selective query reads little more than the variables
it tests (:mod:`.where`).
"""

from __future__ import annotations

import numpy as np

from ..physics import design_limits
from ..units import InputError
from ..variables import CATEGORIES, AXES, DESIGN, SPREAD
from ..conditions import (CATEGORY_WHERE, COLUMNS, EXACT, GRID, INTERPOLATED, OPTIONAL, Condition,
                    parse_sort, missing_hint, parse_at, parse_columns, parse_condition)
from .grid import at_value, locate
from .result import QueryResult
from .spread import PER_LENGTH, TIMES_LENGTH, exact_spread, spread_variants
from .where import where_rows

# Slab size when scanning a cube: about this many float64 values per variable.
_SLAB_VALUES = 2**20


def slab_rows(ds, at_loc, r0, r1):
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
        forces = [n for n in TIMES_LENGTH if n in sub]  # with a model spread's range
        angles = [n for n in PER_LENGTH if n in sub]
        if name == "length":
            # F* = M*/L and theta* = kappa(p*) L (docs/model.md s. 8): interpolate the
            # length-free M* and kappa*, exact along this axis, then scale back (for
            # fe_calibrated kappa* carries (L/a)^c2, docs/model.md s. 21: smooth, not exact)
            la, lb = (float(ds["length"].values[k]) for k in at_loc["length"][:2])
            length = la * (1.0 - w) + lb * w
            for n in forces:
                a[n], b[n] = a[n] * la, b[n] * lb
            for n in angles:
                a[n], b[n] = a[n] / la, b[n] / lb
        sub = a * (1.0 - w) + b * w
        if name == "length":
            for n in forces:
                sub[n] = sub[n] / length
            for n in angles:
                sub[n] = sub[n] * length
        # a flag is never interpolated: between two grid points it is known only where
        # both agree (query_cube then takes it from the exact model where it can)
        sub["limit"] = a["limit"].where(~mixed)
        for flag in ("validity", "validity_model_any"):
            if flag in sub:
                sub[flag] = a[flag].where(a[flag] == b[flag])
    # a cube of several models (cooling sets): the model, then the cooling set, are the
    # last (fastest) axes of the rows
    cats = [d for d in CATEGORIES if d in sub.dims]
    dims = [d for d in AXES if d in sub.dims] + cats
    shape = [sub.sizes[d] for d in dims]
    for cat in cats:  # variables free of it: the same value for each model (cooling set)
        sub = sub.map(lambda v, c=cat: v if c in v.dims else v.expand_dims({c: sub[c]}))
    rows = {}
    for name in AXES:
        if name in sub.dims:
            axis_shape = [-1 if d == name else 1 for d in dims]
            coord = sub[name].values.astype(float).reshape(axis_shape)
            rows[name] = np.broadcast_to(coord, shape).reshape(-1)
        else:
            rows[name] = np.full(int(np.prod(shape)), at_value(at_loc, name, ds))
    for cat in cats:
        names = sub[cat].values.astype(str).astype(object)
        axis_shape = [-1 if d == cat else 1 for d in dims]
        rows[cat] = np.broadcast_to(names.reshape(axis_shape), shape).reshape(-1)
    for name in DESIGN:
        rows[name] = sub[name].transpose(*dims).values.reshape(-1) if name in sub else \
            np.full(int(np.prod(shape)), np.nan)  # heating_time: only with a supply
    for name in (n for n in OPTIONAL if n in sub):
        rows[name] = sub[name].transpose(*dims).values.reshape(-1)
    return rows


#: Designs up to which the exact model of an off-grid ``--at`` runs the physics layer's
#: Python loop (:func:`nylonflex.physics.design_limits`, about 4 ms a design) instead of the
#: compiled kernel: a query of a few designs then loads no Numba and, on a new install or
#: after an upgrade, compiles nothing (the kernel's compile is 15-20 CPU-s). The two run the
#: same formulas and agree to 1e-9 relative (tests/test_engine.py; typically 1e-15).
PYTHON_LOOP_UP_TO = 64


def _exact_count(ds, at_loc) -> int:
    """How many designs the exact model evaluates for an ``--at`` (every slab) [1]."""
    return int(np.prod([ds.sizes[name] for name in AXES if name not in at_loc]))


def _evaluator(n_total: int):
    """The exact model for a query of ``n_total`` designs: the Python loop or the kernel."""
    if n_total <= PYTHON_LOOP_UP_TO:
        return design_limits
    from ..engine.pointwise import evaluate

    return evaluate


def _exact_rows(ds, at, at_loc, r0, r1, settings, evaluate):
    """Rows of radius indices [r0, r1) with the design variables from the exact model.

    The ``--at`` axes take their typed values (the grid value on a grid point), the others
    their grid values; the exact model ``evaluate`` (:func:`_evaluator`) computes every
    design variable there with the cube's materials and settings (``settings``, from its
    provenance).
    """
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
    from ..engine.provenance import cube_settings

    try:
        settings = cube_settings(ds)
    except ValueError as err:
        raise InputError(f"--at: {err}; use --interpolate to interpolate between grid "
                         "points instead") from None
    if len(settings.models) != 1:
        raise InputError("--at: this cube holds several models "
                         f"({', '.join(settings.models)}); the exact model between grid "
                         "points needs one: use --interpolate, or query a one-model cube")
    if settings.coolings:
        raise InputError("--at: this cube holds several cooling sets "
                         f"({', '.join(c.label for c in settings.coolings)}); the exact "
                         "model between grid points needs one: use --interpolate, or query "
                         "a cube of one cooling set")
    return settings.evaluate_kwargs()


def radius_slabs(ds, at_loc) -> list[tuple[int, int]]:
    """Radius index ranges to scan: the ``--at`` bracket, or the whole axis cut so that a
    slab holds about :data:`_SLAB_VALUES` values of one variable (bounded memory)."""
    if "radius" in at_loc:
        i0, i1 = at_loc["radius"][:2]
        return [(i0, i1 + 1)]
    other = 1
    for name in AXES[1:]:
        other *= 2 if name in at_loc else ds.sizes[name]
    for cat in CATEGORIES:
        other *= ds.sizes.get(cat, 1)
    step = max(1, _SLAB_VALUES // max(other, 1))
    return [(r, min(r + step, ds.sizes["radius"])) for r in range(0, ds.sizes["radius"], step)]


def query_cube(ds, at=None, where=(), sort=None, limit=None, *, interpolate=False,
               columns=None, progress=None, log=None) -> QueryResult:
    """Designs of a cube selected by ``--at``, filtered by ``--where``, sorted, limited.

    Parameters
    ----------
    ds : xarray.Dataset
        A cube from :func:`nylonflex.open_cube` (lazy; read slab by slab), or, where
        :func:`~nylonflex.query.where.by_variable` holds, from ``storage.open_light``.
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
        The flags ``limit`` and ``validity`` are never interpolated: they come from the
        exact model at each design, or, where the cube's provenance cannot give it (a
        cube of several models), are unknown (NaN) wherever the grid points disagree.
    columns : str or sequence of str, optional
        The columns to show (``--columns``; ``"all"`` or None: the format's default,
        :func:`nylonflex.query.default_columns` for a table).
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
    chosen = parse_columns(columns)
    every = chosen == "all"
    chosen = None if every else chosen
    ds, where = _select_model(ds, where)
    conditions = [c if isinstance(c, Condition) else parse_condition(c) for c in where]
    sort_name, descending = parse_sort(sort)
    columns = COLUMNS + tuple(n for n in OPTIONAL if n in ds)
    # every model (cooling set) at once: the model (cooling set) names each row
    columns = (*(c for c in CATEGORIES if c in ds.dims), *columns)
    _check_asked(ds, [c.name for c in conditions] + [sort_name], chosen, limit)
    at_loc = {name: locate(ds, name, value) for name, value in at.items()}
    off_grid = [name for name, loc in at_loc.items() if not loc[3]]
    exact = bool(off_grid) and not interpolate
    settings = _exact_settings(ds) if exact else None
    # a model spread off the grid: every variant through the exact model (query/spread.py)
    variants = spread_variants(ds) if exact else ()
    if exact:  # the exact model gives the design variables, not the sampled or tracked ones
        columns = _exact_columns(columns, [c.name for c in conditions] + [sort_name] +
                                 list(chosen or ()), variants, off_grid)
    flags = None
    if off_grid and interpolate:  # the flags from the exact model, when it can be had
        try:
            settings = _exact_settings(ds)
            flags = EXACT
        except InputError:
            flags = "unknown where the grid points disagree"
    slabs = radius_slabs(ds, at_loc)
    evaluate = None if settings is None else _evaluator(_exact_count(ds, at_loc))
    if evaluate is not None and evaluate is not design_limits and log is not None:
        from ..engine.warmup import warm_up_points

        warm_up_points(settings, notice=log)
    done = ds["slab_done"].values.astype(bool) if "slab_done" in ds and not exact else None

    kept = {name: np.empty(0, dtype=object if name in CATEGORIES else float)
            for name in columns}
    matched = 0
    for k, (r0, r1) in enumerate(slabs):
        if done is not None and "radius" not in at_loc and not done[r0:r1].any():
            if progress is not None:
                progress(k + 1, len(slabs))
            continue  # an incomplete cube: nothing computed here
        room = None if limit is None or sort_name is not None else \
            limit - len(kept[COLUMNS[0]])
        rows, n_where = _rows_of_slab(ds, at, at_loc, (r0, r1), conditions, room,
                                      model=(settings, evaluate, variants), exact=exact,
                                      flags=flags, off_grid=off_grid)
        mask = np.ones(len(rows[COLUMNS[0]]), dtype=bool)
        for c in conditions:
            mask &= c.mask(rows[c.name])
        if not conditions and done is not None and "radius" not in at_loc:
            mask &= ~np.isnan(rows["tip_force_max"])  # skip masked, uncomputed radii
        n = int(mask.sum()) if n_where is None else n_where
        matched += n
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
    asked = [c.name for c in conditions] + ([sort_name] if sort_name else [])
    return QueryResult(kept, point, off_grid, matched, single=len(at_loc) == len(AXES),
                       at=at, columns=columns, chosen=chosen, asked=asked, flags=flags,
                       every=every)


def _check_asked(ds, names, chosen, limit):
    """Refuse a condition, sort or column the cube does not hold, and a negative limit."""
    for name in names:
        if name in OPTIONAL and name not in ds:
            raise InputError(f"{name}: the cube has no {name}; {missing_hint(name)}")
    if limit is not None and limit < 0:
        raise InputError(f"--limit: must be 0 or more, got {limit}")
    for name in chosen or ():
        if name in OPTIONAL and name not in ds:
            raise InputError(f"--columns: the cube has no {name}; {missing_hint(name)}")


def _exact_columns(columns, asked, variants, off_grid):
    """The columns an off-grid (exact) query can give: the design variables, and a model
    spread's range where the cube has one; an asked-for sampled or tracked variable is
    refused in one line."""
    for name in asked:
        if name in OPTIONAL and not (variants and name in SPREAD):
            raise InputError(f"{name}: not computed off the grid (the exact model gives "
                             "the design variables; the sweep sampled or simulated "
                             f"{name} on the grid): use --interpolate, or grid values "
                             f"for {', '.join(off_grid)}")
    return tuple(c for c in columns if c not in OPTIONAL or (variants and c in SPREAD))


def _rows_of_slab(ds, at, at_loc, bounds, conditions, room, *, model, exact, flags,
                  off_grid):
    """One slab's candidate rows and, where the conditions were applied variable by
    variable, how many matched (else None). ``model``: (settings, evaluate, variants) of
    the exact model (None, None, () where it is not used); ``exact``: the rows come from
    it (an off-grid query without --interpolate)."""
    r0, r1 = bounds
    n_where = None
    settings, evaluate, variants = model
    if exact:
        rows = _exact_rows(ds, at, at_loc, r0, r1, settings, evaluate)
        if variants:
            rows.update(exact_spread(rows, settings, evaluate, variants))
    elif conditions and not off_grid and not any(c in ds.dims for c in CATEGORIES):
        # variable by variable (a cube of several models or cooling sets is read whole,
        # per slab)
        rows, n_where = where_rows(ds, at_loc, r0, r1, conditions, room)
    else:
        rows = slab_rows(ds, at_loc, r0, r1)
    if flags == EXACT:
        rows = _exact_flags(rows, settings, evaluate)
    return rows, n_where


def _exact_flags(rows, settings, evaluate):
    """``rows`` with ``limit`` and ``validity`` from the exact model at each design (an
    interpolated row's flags: a flag between two grid points is not their mean)."""
    if not len(rows[AXES[0]]):
        return rows
    out = evaluate(*(rows[name] for name in AXES), **settings)
    rows = dict(rows)
    for name in ("limit", "validity"):
        if name in rows and name in out:
            rows[name] = np.asarray(out[name], dtype=float).reshape(-1)
    return rows


def _select_model(ds, where):
    """The cube at the model (cooling set) a ``--where "model == NAME"`` (``"cooling ==
    NAME"``) names, and the other conditions.

    A cube of several models (docs/model.md s. 16) or cooling sets (s. 9) without such a
    condition is queried across all of them at once (a ``model`` and a ``cooling`` column
    name each row's).
    """
    where = list(where or ())
    picks = [m for m in (CATEGORY_WHERE.match(str(w)) for w in where) if m]
    rest = [w for w in where if not CATEGORY_WHERE.match(str(w))]
    for cat in CATEGORIES:
        names = [m.group(3) for m in picks if m.group(1) == cat]
        if cat in ds.dims:
            have = [str(m) for m in ds[cat].values]
        elif cat == "model":
            have = str(ds.attrs.get("models", "paper")).split()
        else:
            have = []
        for name in names:
            if name not in have:
                if not have:
                    raise InputError(f"--where {cat}: this cube has no {cat} dimension "
                                     "(one cooling set)")
                raise InputError(f"--where {cat}: this cube has {', '.join(have)}, got "
                                 f"{name!r}")
        if cat not in ds.dims or not names:
            continue
        if len(set(names)) != 1:
            raise InputError(f"--where: one {cat} at a time ({', '.join(have)}), or none "
                             f"for every {cat}; got {', '.join(sorted(set(names)))}")
        ds = ds.sel({cat: names[0]}, drop=True)
    return ds, rest


def _sorted(rows, name, descending, limit):
    key = rows[name]
    # stable, NaN last either way; descending keeps ties in grid order too
    order = np.argsort(-key if descending else key, kind="stable")
    if limit is not None:
        order = order[:limit]
    return {k: v[order] for k, v in rows.items()}
