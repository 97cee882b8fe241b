"""Notes on how ``--where`` read a bare number, when the answer suggests a unit slip.

``--where "radius <= 0.01"`` reads 0.01 in mm (the display unit), and ``"bend_angle_max >=
3.14"`` reads 3.14 in deg; a designer who meant metres or radians gets no designs, or every
design, with no hint. :func:`unit_notes` returns one line for each condition whose bare
value was read in a display unit other than SI when the answer is empty or the value lies
outside the cube's range of that variable: the unit it was read in, the cube's range in
that unit, and how to write the SI reading.
"""

from __future__ import annotations

import numpy as np

from ..units import bare_number, from_si
from ..variables import AXES, VARIABLES
from ..conditions import CONDITION_PATTERN, Condition
from .where import read_values

__all__ = ["unit_notes", "variable_range"]


def variable_range(ds, name, slab_values: int = 2**20):
    """``(min, max)`` [SI] of cube variable ``name`` over its computed values, read in
    slabs of radii (bounded memory); ``(nan, nan)`` when none is computed."""
    if name in AXES:
        grid = ds[name].values.astype(float)
        return float(grid.min()), float(grid.max())
    per_radius = max(1, int(np.prod([ds.sizes[d] for d in ds[name].dims if d != "radius"])))
    step = max(1, slab_values // per_radius)
    lo, hi = np.inf, -np.inf
    for r0 in range(0, ds.sizes["radius"], step):
        x = read_values(ds, name, {"radius": slice(r0, r0 + step)})
        x = x[np.isfinite(x)]
        if x.size:
            lo, hi = min(lo, float(x.min())), max(hi, float(x.max()))
    return (lo, hi) if lo <= hi else (float("nan"), float("nan"))


def unit_notes(ds, conditions, matched) -> list[str]:
    """One line per condition whose bare value the answer suggests was a unit slip.

    Parameters
    ----------
    ds : xarray.Dataset
        The cube queried (or a cube read through h5py alone:
        :func:`~nylonflex.query.where.read_values`).
    conditions : sequence of Condition or str
        The ``--where`` conditions (strings that are not a Condition are skipped).
    matched : int
        How many designs matched.

    Returns
    -------
    list of str
        ``--where "radius <= 0.01": the bare 0.01 is read in mm (0.01 mm); the cube's
        radius spans 5 .. 25 mm; write '0.01m' for metres`` for each condition whose value
        was typed without a unit in a display unit other than SI, when nothing matched or
        the value lies outside the cube's range (checked for a design variable, whose range
        costs a read of it, when none or every design matched).
    """
    notes = []
    for c in conditions:
        if not isinstance(c, Condition) or c.name not in VARIABLES:
            continue
        m = CONDITION_PATTERN.match(c.text)
        typed = bare_number(m.group(3)) if m else None
        v = VARIABLES[c.name]
        if typed is None or v.display == v.units or c.name not in ds:
            continue
        every = int(np.prod([ds.sizes[d] for d in ds[c.name].dims]))
        if c.name not in AXES and 0 < matched < every:
            continue  # a design variable's range costs a read: only for none or all matched
        lo, hi = variable_range(ds, c.name)
        outside = np.isfinite(lo) and not lo <= c.value <= hi
        if not (matched == 0 or outside):
            continue
        span = (f"{from_si(lo, v.display):.4g} .. {from_si(hi, v.display):.4g} {v.display}"
                if np.isfinite(lo) else "no computed values")
        notes.append(f"--where \"{c.text}\": the bare {typed:g} is read in {v.display} "
                     f"({typed:g} {v.display}); the cube's {c.name} spans {span}; write "
                     f"'{typed:g}{v.units.replace(' ', '')}' for {v.units}")
    return notes
