"""The grid stage: feasible designs of a cube, the best ones, the Pareto front, and why not.

The cube is read in radius slabs (bounded memory, as ``query`` does). Axes fixed by an
equality constraint are read as a slice (linearly interpolated when the value lies between
grid values); the other constraints are masks. What is kept per slab is small: the best
``keep`` rows (one objective) or the running non-dominated set (several), a capped sample
of the feasible cloud for the chart, and, per constraint, the design that comes nearest to
meeting it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..query import COLUMNS, at_value, locate, slab_rows
from ..variables import TRACKING
from ..query.scan import radius_slabs
from ..units import InputError
from ..variables import AXES, VARIABLES, to_display
from .spec import fixed_axes

__all__ = ["GridScan", "nondominated", "scan_grid", "violation"]

# about this many float64 values per variable in one slab (as query)
# at most this many feasible designs kept for the chart's cloud
CLOUD_MAX = 50_000


def nondominated(F) -> np.ndarray:
    """Mask of the non-dominated rows of ``F`` (n, k), every column minimised.

    Row i is dominated when some row j is <= in every column and < in one. Equal rows do
    not dominate each other (both stay). Rows with NaN are dropped.

    Notes
    -----
    In lexicographic order a row can only be dominated by an earlier one, and domination is
    transitive, so each row is checked against the front found so far only.
    """
    F = np.asarray(F, dtype=float)
    n = F.shape[0]
    keep = np.zeros(n, dtype=bool)
    if n == 0:
        return keep
    ok = ~np.isnan(F).any(axis=1)
    order = [i for i in np.lexsort(F.T[::-1]) if ok[i]]
    front = np.empty((0, F.shape[1]))
    for i in order:
        f = F[i]
        if len(front) and np.any(np.all(front <= f, axis=1) & np.any(front < f, axis=1)):
            continue
        keep[i] = True
        front = np.vstack([front, f])
    return keep


def violation(cond, x) -> np.ndarray:
    """How far values ``x`` [SI] are from meeting ``cond`` (0 where met) [SI of the name]."""
    x = np.asarray(x, dtype=float)
    if cond.op in (">=", ">"):
        d = np.maximum(cond.value - x, 0.0)
    elif cond.op in ("<=", "<"):
        d = np.maximum(x - cond.value, 0.0)
    elif cond.op == "==":
        d = np.abs(x - cond.value)
    else:  # !=: met or not
        d = np.zeros_like(x)
    d = np.where(cond.mask(x), 0.0, np.where(d > 0, d, np.finfo(float).tiny))
    return np.where(np.isnan(x), np.inf, d)


@dataclass
class GridScan:
    """What the grid stage found.

    Attributes
    ----------
    total : int
        Designs scanned (after fixing axes).
    feasible : int
        Designs that meet every constraint.
    best : dict of str to numpy.ndarray
        One objective: the ``keep`` best feasible rows, best first. Several: the grid's
        non-dominated feasible rows, ordered by the first objective.
    cloud : dict of str to numpy.ndarray
        Feasible rows (a sample of at most ``CLOUD_MAX``) for the chart.
    fixed : dict
        ``{axis: SI value}`` of the fixed axes (the grid value when on the grid).
    ranges : dict
        ``{axis: (lo, hi)}`` of the cube's axes [SI].
    reasons : list of str
        Empty when feasible designs exist; else lines that say which constraint no design
        meets and how close the nearest comes.
    """

    total: int
    feasible: int
    best: dict
    cloud: dict
    fixed: dict
    ranges: dict
    reasons: list


#: Columns a cube may hold that the exact pointwise model does not compute: the closed loop
#: of each grid design (docs/model.md s. 19). Reported from the cube, at grid points only.
CUBE_ONLY = tuple(TRACKING)


def _shown(name, x) -> str:
    unit = VARIABLES[name].display
    return f"{float(to_display(name, x)):.4g}" + ("" if unit == "1" else f" {unit}")


def _minimised(objectives, rows) -> np.ndarray:
    return np.column_stack([o.sign * np.asarray(rows[o.name], float) for o in objectives])


def _take(rows, index):
    return {k: np.asarray(v)[index] for k, v in rows.items()}


def _concat(a, b):
    return {k: np.concatenate([a[k], b[k]]) for k in a}


def scan_grid(ds, spec, keep: int = 1) -> GridScan:
    """Scan a cube for the spec's feasible designs, best rows or front, and near misses.

    Parameters
    ----------
    ds : xarray.Dataset
        The cube (lazy is fine).
    spec : DesignSpec
        Objectives and constraints.
    keep : int
        With one objective, how many of the best feasible rows to keep.

    Returns
    -------
    GridScan
    """
    asked = [*(o.name for o in spec.objectives), *(c.name for c in spec.constraints)]
    missing = [n for n in asked if n not in ds.variables]
    if missing:
        raise InputError(f"{missing[0]}: this cube holds no {missing[0]} (heating_time needs a "
                         "sweep with supply:; feasibility one with requirements:)")
    ranges = {a: (float(ds[a].values.min()), float(ds[a].values.max())) for a in AXES}
    # the columns of every row, and the cube-only ones this cube has (tracking_*)
    empty = {k: np.empty(0) for k in (*COLUMNS, *(n for n in CUBE_ONLY if n in ds))}
    fixed = fixed_axes(spec)
    at_loc, reasons = {}, []
    for name, value in fixed.items():
        if np.isnan(value):
            reasons.append(f"{name}: fixed to two different values; no design meets both")
            continue
        try:
            at_loc[name] = locate(ds, name, value)
        except InputError:
            lo, hi = ranges[name]
            reasons.append(f"{name} == {_shown(name, value)}: the cube's {name} spans "
                           f"{_shown(name, lo)} .. {_shown(name, hi)}; no design there")
    if reasons:
        return GridScan(0, 0, empty, empty, fixed, ranges, reasons)
    fixed = {name: at_value(at_loc, name, ds) for name in at_loc}
    conds = [c for c in spec.constraints if not (c.op == "==" and c.name in AXES)]
    multi = len(spec.objectives) > 1

    slabs = radius_slabs(ds, at_loc)
    done = ds["slab_done"].values.astype(bool) if "slab_done" in ds else None

    total = feasible = 0
    best, cloud = dict(empty), dict(empty)
    met_alone = np.zeros(len(conds), dtype=bool)
    near_alone = [(np.inf, np.nan)] * len(conds)   # (violation, value) over all designs
    near_others = [(np.inf, np.nan)] * len(conds)  # over designs meeting the others
    rng = np.random.default_rng(0)
    for r0, r1 in slabs:
        if done is not None and "radius" not in at_loc and not done[r0:r1].any():
            continue
        rows = slab_rows(ds, at_loc, r0, r1)
        known = ~np.isnan(rows["tip_force_max"])
        rows = _take(rows, known)
        n = int(known.sum())
        total += n
        masks = np.ones((n, len(conds)), dtype=bool)
        for j, c in enumerate(conds):
            masks[:, j] = c.mask(rows[c.name])
        ok = masks.all(axis=1)
        fails = (~masks).sum(axis=1)
        for j, c in enumerate(conds):
            d = violation(c, rows[c.name])
            met_alone[j] |= masks[:, j].any()
            if n:
                k = int(np.argmin(d))
                if d[k] < near_alone[j][0]:
                    near_alone[j] = (float(d[k]), float(rows[c.name][k]))
            others = (fails - (~masks[:, j])) == 0
            if others.any():
                k = int(np.argmin(np.where(others, d, np.inf)))
                if d[k] < near_others[j][0]:
                    near_others[j] = (float(d[k]), float(rows[c.name][k]))
        feas = _take(rows, ok)
        m = int(ok.sum())
        feasible += m
        if not m:
            continue
        cloud = _concat(cloud, feas)
        if len(cloud["radius"]) > 2 * CLOUD_MAX:
            cloud = _take(cloud, np.sort(rng.choice(len(cloud["radius"]), CLOUD_MAX,
                                                    replace=False)))
        both = _concat(best, feas)
        F = _minimised(spec.objectives, both)
        if multi:
            best = _take(both, nondominated(F))
        else:
            order = np.argsort(F[:, 0], kind="stable")
            order = order[~np.isnan(F[order, 0])][:keep]
            best = _take(both, order)
    if len(cloud["radius"]) > CLOUD_MAX:
        cloud = _take(cloud, np.sort(rng.choice(len(cloud["radius"]), CLOUD_MAX,
                                                replace=False)))
    if multi and len(best["radius"]):
        best = _take(best, np.lexsort(_minimised(spec.objectives, best).T[::-1]))
    if feasible == 0:
        reasons = _reasons(conds, met_alone, near_alone, near_others, total, fixed)
    return GridScan(total, feasible, best, cloud, fixed, ranges, reasons)


def _reasons(conds, met_alone, near_alone, near_others, total, fixed):
    if total == 0:
        return ["the cube has no computed designs"]
    where = "in the cube" if not fixed else \
        "with " + ", ".join(f"{n} {_shown(n, v)}" for n, v in fixed.items())
    out = []
    for j, c in enumerate(conds):
        d, value = near_others[j]
        others = (f"the nearest of those that meet the other constraints has {c.name} = "
                  f"{_shown(c.name, value)}") if np.isfinite(d) and len(conds) > 1 else ""
        if not met_alone[j]:
            alone = f"{c.name} = {_shown(c.name, near_alone[j][1])}"
            out.append(f"{c.text}: no design {where} meets it; the nearest has {alone}"
                       + (f"; {others}" if others else ""))
        elif others and d > 0:
            out.append(f"{c.text}: no design that meets the other constraints meets it; "
                       + others.replace(" of those that meet the other constraints", ""))
    return out or ["no design meets every constraint together"]
