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

__all__ = ["MIN_STEP_FRACTION", "check_fixed", "check_steps", "merge_equal", "on_resolution",
           "snap"]

#: |x/step - k| below this is the multiple k itself (float noise of typed values).
_ON_TOL = 1e-6
#: Objectives this close (relative) are equal.
_EQUAL_RTOL = 1e-9


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
