"""Designs that can be built: snapped to a spec's ``resolution`` and merged where equal.

Refinement (:mod:`.refine`) moves the axes continuously and answers coil index 1.3989 or a
4.00006 mm wall; a workshop cuts walls in half millimetres and winds coil indices in steps
of 0.05. This step runs after refinement, on its answers and on the grid's, and knows
nothing of how they were found:

1. :func:`snap`: each design is replaced by its on-resolution neighbours (for every axis
   with a step, the multiples of the step just below and just above; one value when it is
   on a multiple already), kept inside the grid's range; every neighbour is evaluated
   exactly and kept only if it meets every constraint. The caller builds the best design
   or the front from what is left.
2. :func:`merge_equal`: reported designs equal in every objective are one row, listing
   the values of the axes that differ (``alternatives``): two rows that differ only in
   wrap angle are one answer, with a choice.

Steps are multiples from zero (``coil_index: 0.05`` gives 1.10, 1.15, ...). An axis fixed by
an equality constraint keeps its value, which must itself be on the resolution.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..units import InputError, from_si, to_si
from ..variables import AXES, VARIABLES
from .refine import evaluate_rows, meets

__all__ = ["MIN_STEP_FRACTION", "check_fixed", "check_steps", "lattice_search", "merge_equal",
           "on_resolution", "same_intervals",
           "snap"]

#: |x/step - k| below this is the multiple k itself (float noise of typed values).
_ON_TOL = 1e-6
#: Objectives this close (relative) are equal.
_EQUAL_RTOL = 1e-9
#: The lattice search: moves at most, and per free continuous axis a scan of this many
#: points, then zooms around the best (each window 2/8 of the last).
_MOVES = 8
_SCAN = 9
_ZOOMS = 5


def _multiple(name, k, step) -> float:
    """``k * step`` [SI], computed in the axis's display unit as a user would type it
    (29 x 0.05 = 1.45, 22 x 0.5 mm = 11 mm, 5 x 1 deg = 5 deg), without float noise."""
    unit = VARIABLES[name].display
    typed = float(f"{k * from_si(step, unit):.12g}")
    return float(to_si(typed, unit, name, VARIABLES[name].kind))


def on_resolution(x, step) -> np.ndarray:
    """True where ``x`` [SI] is a multiple of ``step`` [SI] (to float noise)."""
    k = np.asarray(x, dtype=float) / step
    return np.abs(k - np.round(k)) <= _ON_TOL


def _neighbours(name, x, step, lo, hi, keep_bits=False) -> list:
    """The multiples of ``step`` just below and above ``x``, inside ``[lo, hi]`` [SI]; one
    when ``x`` is on it (``x`` itself, bit for bit, with ``keep_bits``: a grid point stays
    that grid point)."""
    k = x / step
    if abs(k - round(k)) <= _ON_TOL:
        return [x if keep_bits else _multiple(name, round(k), step)]
    span = max(hi - lo, abs(hi), 1e-300)
    return [v for v in (_multiple(name, j, step) for j in (np.floor(k), np.ceil(k)))
            if lo - 1e-9 * span <= v <= hi + 1e-9 * span]


def check_fixed(resolution, fixed):
    """Refuse an axis fixed (``==``) to a value off its resolution: no design meets both.

    Raises
    ------
    InputError
        Names the axis, the fixed value and the step, in display units.
    """
    for name, value in fixed.items():
        step = resolution.get(name)
        if step is not None and np.isfinite(value) and not on_resolution(value, step):
            unit = VARIABLES[name].display
            u = "" if unit == "1" else f" {unit}"
            raise InputError(f"resolution.{name}: the constraint {name} == "
                             f"{from_si(value, unit):g}{u} is not a multiple of the step "
                             f"{from_si(step, unit):g}{u}; change one of them")


#: A step is at least this fraction of its axis's range in the cube (finer is no
#: resolution a workshop has, and multiplies the neighbours to evaluate).
MIN_STEP_FRACTION = 1e-3


def check_steps(resolution, ranges):
    """Refuse, before any work, a step outside [a thousandth of its axis's range in the
    cube, that range] (``resolution`` {axis: step} and ``ranges`` {axis: (lo, hi)} [SI]):
    a step longer than the range left no design on the resolution (an empty answer), a
    step of 1e-308 mm none that can be built. An axis of one value takes any step.

    Raises
    ------
    InputError
        One line naming ``resolution.<axis>`` and the accepted range.
    """
    for name, step in resolution.items():
        lo, hi = ranges[name]
        span = hi - lo
        if not span > 0:
            continue
        if not MIN_STEP_FRACTION * span <= step <= span:
            unit = VARIABLES[name].display
            shown = "" if unit == "1" else f" {unit}"
            raise InputError(
                f"resolution.{name}: must be in [{from_si(MIN_STEP_FRACTION * span, unit):.4g}"
                f", {from_si(span, unit):.4g}]{shown} (a thousandth of the cube's {name} "
                f"range, and that range), got {from_si(step, unit):.4g}{shown}")


def snap(model, spec, rows, ranges, keep_bits=False) -> tuple[dict, np.ndarray, int]:
    """Every on-resolution neighbour of ``rows`` that meets the constraints, exactly.

    Parameters
    ----------
    model : Model
        The exact model (:class:`nylonflex.design.refine.Model`).
    spec : DesignSpec
        Its ``resolution`` ``{axis: step}`` [SI] and constraints.
    rows : dict of str to numpy.ndarray
        Designs (every axis [SI]; other columns are recomputed).
    ranges : dict
        ``{axis: (lo, hi)}`` [SI]: the grid's range; neighbours outside it are left out.
    keep_bits : bool
        An axis value on the resolution stays as it is (grid rows); else it becomes the
        multiple as typed (an optimiser's 0.024999999999999953 m is 25 mm).

    Returns
    -------
    rows : dict of str to numpy.ndarray
        The feasible neighbours, each once, exactly evaluated, in the order of their
        designs.
    moved : numpy.ndarray of bool
        True for a row whose design was off the resolution (it had to move).
    lost : int
        Designs none of whose neighbours meets every constraint (dropped).
    """
    res = spec.resolution
    n = len(rows["radius"])
    X, moved, origin = [], [], []
    for i in range(n):
        x = [float(rows[a][i]) for a in AXES]
        options = [(_neighbours(a, v, res[a], *ranges[a], keep_bits) if a in res else [v])
                   for a, v in zip(AXES, x)]
        on = all(on_resolution(v, res[a]) for a, v in zip(AXES, x) if a in res)
        for combo in itertools.product(*options):
            X.append(combo)
            moved.append(not on)
            origin.append(i)
    if not X:
        return {k: np.empty(0) for k in rows}, np.zeros(0, bool), n
    X = np.array(X, dtype=float)
    # the same neighbour of two designs once (the first design's)
    _, first = np.unique(X, axis=0, return_index=True)
    first = np.sort(first)
    X, moved, origin = X[first], np.array(moved)[first], np.array(origin)[first]
    out = evaluate_rows(model, dict(zip(AXES, X.T)))
    ok = meets(spec, out, {})
    lost = n - len(set(origin[ok].tolist()))
    return {k: np.asarray(v)[ok] for k, v in out.items()}, moved[ok], lost


def merge_equal(designs, objectives) -> tuple[list, int]:
    """Designs equal in every objective as one: the first of each group, with
    ``alternatives`` ``{axis: [SI values of the group, sorted]}`` for the axes that differ.

    Parameters
    ----------
    designs : list of dict
        Reported designs, in their order (the first of a group is kept).
    objectives : sequence of Objective

    Returns
    -------
    designs : list of dict
        Each with ``alternatives`` (empty when nothing was merged into it).
    merged : int
        Rows merged away.
    """
    names = [o.name for o in objectives]
    out, groups = [], []
    for d in designs:
        key = np.array([d[n] for n in names], dtype=float)
        for g in groups:
            if np.allclose(key, g[0], rtol=_EQUAL_RTOL, atol=0.0, equal_nan=True):
                g[1].append(d)
                break
        else:
            groups.append((key, [d]))
    for _, members in groups:
        # a grid design first: the same design reached by refinement is that grid point
        keep = dict(next((m for m in members if m.get("source") == "grid"), members[0]))
        values = {}
        for a in AXES:  # the values that differ beyond float noise, each once
            for v in sorted(float(m[a]) for m in members):
                if not values.get(a) or not np.isclose(v, values[a][-1], rtol=1e-9, atol=0):
                    values.setdefault(a, []).append(v)
        keep["alternatives"] = {a: v for a, v in values.items() if len(v) > 1}
        out.append(keep)
    return out, len(designs) - len(out)


# ---------------------------------------------------------------------------- lattice search
def _score(model, spec, fixed, primary, eps, X):
    """``primary.sign * objective`` of designs ``X`` (n, 5) [SI], inf where one breaks a
    constraint or an epsilon bound; and their exact rows."""
    rows = model(X)
    ok = meets(spec, rows, fixed)
    for o, v in eps:
        ok &= o.sign * rows[o.name] <= o.sign * v
    return np.where(ok, primary.sign * rows[primary.name], np.inf), rows


def _fit_continuous(model, spec, fixed, primary, eps, X, axes, bounds):
    """Each design of ``X`` with its axes without a resolution (``axes``) moved to their
    best acceptable values: per axis a scan of its range, then zooms. Returns (X, f)."""
    X = np.array(X, dtype=float)
    f, _ = _score(model, spec, fixed, primary, eps, X)
    n, idx = len(X), np.arange(len(X))
    for a in axes:
        k = AXES.index(a)
        lo, hi = bounds[a]
        w_lo, w_hi = np.full(n, lo), np.full(n, hi)
        for _ in range(_ZOOMS):
            V = w_lo[:, None] + np.linspace(0.0, 1.0, _SCAN)[None, :] * (w_hi - w_lo)[:, None]
            XX = np.repeat(X, _SCAN, axis=0)
            XX[:, k] = V.ravel()
            ff = _score(model, spec, fixed, primary, eps, XX)[0].reshape(n, _SCAN)
            j = np.argmin(ff, axis=1)
            better = ff[idx, j] < f
            X[better, k] = V[idx, j][better]
            f = np.where(better, ff[idx, j], f)
            step = (w_hi - w_lo) / (_SCAN - 1)
            w_lo, w_hi = np.maximum(lo, X[:, k] - step), np.minimum(hi, X[:, k] + step)
    return X, f


def _lattice_moves(spec, x, bounds, fixed):
    """Per axis the values a move may take from design ``x`` [SI]: an axis with a
    resolution its value and the multiples one step either side (inside ``bounds``), but
    none that worsens an objective the axis is (a front's radius only goes down)."""
    res, options = spec.resolution, []
    sense = {o.name: o.sign for o in spec.objectives[1:]}
    for a, v in zip(AXES, x):
        if a not in res or a in fixed:
            options.append([v])
            continue
        lo, hi = bounds[a]
        span = max(hi - lo, abs(hi), 1e-300)
        k = int(round(v / res[a]))
        out = [v]
        for d in (-1, 1):
            if a in sense and sense[a] * d > 0:
                continue  # worse in that objective: outside the epsilon bound anyway
            w = _multiple(a, k + d, res[a])
            if lo - 1e-9 * span <= w <= hi + 1e-9 * span:
                out.append(w)
        options.append(out)
    return options


def lattice_search(model, spec, rows, bounds, fixed) -> tuple[dict, np.ndarray]:
    """Each design of ``rows`` (on its resolution) moved to the best buildable design near
    it: the first objective made best with every other objective no worse (the epsilon
    bounds of :mod:`.refine`), over the resolution lattice.

    A move goes to the best of the lattice neighbours (every axis with a step at its value
    or one step either side; the axes without a step optimised for each, a scan and zooms
    over their range), as long as one improves; each result meets every constraint,
    exactly. Refinement's continuous optimum rounded to the lattice can be a lattice
    design a step or two from the best one (issue 46: 0.0788 N at a = 5 mm where t 4.5 mm,
    L 73 mm gives 0.0817 N); this finds that one.

    Parameters
    ----------
    model : Model
    spec : DesignSpec
        Its ``resolution``, objectives and constraints.
    rows : dict of str to numpy.ndarray
        Designs on the resolution, exactly evaluated [SI].
    bounds : dict
        ``{axis: (lo, hi)}`` [SI] the designs may take.
    fixed : dict
        Axes fixed by an equality constraint [SI].

    Returns
    -------
    rows : dict of str to numpy.ndarray
        The designs reached, exactly evaluated, in the order of ``rows``.
    moved : numpy.ndarray of bool
        True where a design moved.
    """
    primary, others = spec.objectives[0], spec.objectives[1:]
    cont = [a for a in AXES if a not in spec.resolution and a not in fixed
            and bounds[a][1] > bounds[a][0]]
    n = len(rows["radius"])
    out, moved = [], np.zeros(n, bool)
    for i in range(n):
        x = np.array([float(rows[a][i]) for a in AXES])
        eps = [(o, float(rows[o.name][i])) for o in others]
        best = primary.sign * float(rows[primary.name][i])
        for _ in range(_MOVES):
            X = np.array(list(itertools.product(*_lattice_moves(spec, x, bounds, fixed))))
            X, f = _fit_continuous(model, spec, fixed, primary, eps, X, cont, bounds)
            j = int(np.argmin(f))
            if not f[j] < best - 1e-12 * abs(best):
                break
            x, best, moved[i] = X[j], float(f[j]), True
        out.append(x)
    X = np.array(out) if out else np.zeros((0, len(AXES)))
    return evaluate_rows(model, dict(zip(AXES, X.T))), moved


def same_intervals(model, spec, designs, ranges, fixed) -> list:
    """``designs`` with ``alternatives`` widened to the whole run of lattice values, along
    each axis with a resolution, over which the design stays the same: every objective
    equal (to 1e-9) and every constraint met, the other axes held (issue 46: wrap angles
    5-15 deg give one design, not just the 5 and 12 deg a search happened to visit).
    Merged alternatives outside that run are kept."""
    res = spec.resolution
    names = [o.name for o in spec.objectives]
    out = []
    for d in designs:
        alt = dict(d.get("alternatives") or {})
        x = np.array([float(d[a]) for a in AXES])
        key = np.array([d[n] for n in names], dtype=float)
        for a in AXES:
            if a not in res or a in fixed:
                continue
            lo, hi = ranges[a]
            ks = np.arange(int(np.ceil(lo / res[a] - _ON_TOL)),
                           int(np.floor(hi / res[a] + _ON_TOL)) + 1)
            values = np.array([_multiple(a, k, res[a]) for k in ks])
            if len(values) < 2:
                continue
            X = np.repeat(x[None, :], len(values), axis=0)
            X[:, AXES.index(a)] = values
            rows = model(X)
            same = meets(spec, rows, fixed)
            for n in names:
                same &= np.isclose(rows[n], key[names.index(n)], rtol=_EQUAL_RTOL, atol=0)
            here = int(np.argmin(np.abs(values - x[AXES.index(a)])))
            if not same[here]:
                continue
            j0 = j1 = here
            while j0 > 0 and same[j0 - 1]:
                j0 -= 1
            while j1 < len(values) - 1 and same[j1 + 1]:
                j1 += 1
            run = [float(v) for v in values[j0:j1 + 1]]
            run[here - j0] = float(x[AXES.index(a)])  # the design's own value, bit for bit
            merged = [v for v in alt.get(a, []) if not np.isclose(v, run, rtol=1e-9,
                                                                  atol=0).any()]
            widened = sorted(run + merged)
            if len(widened) > 1:
                alt[a] = widened
        out.append({**d, "alternatives": alt})
    return out
