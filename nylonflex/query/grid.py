"""Where an ``--at`` value sits on a cube's grid: :func:`locate` and :func:`at_value`."""

from __future__ import annotations

import numpy as np

from ..units import InputError, from_si
from ..variables import VARIABLES

__all__ = ["at_value", "locate"]

# Values this close (relative to the axis span) to a grid value are that grid value.
_GRID_RTOL = 1e-6


def locate(ds, name, value):
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
        bare = f" (a bare number is read in {v.display})" if unit else ""
        raise InputError(f"--at: {name}={from_si(value, v.display):g}{unit} is outside the "
                         f"cube's grid; {name} takes {shown}{unit}{bare}")
    if np.any(np.diff(grid) <= 0):  # a grid the sweep wrote is increasing; be safe
        raise InputError(f"--at: the cube's {name} axis is not increasing; cannot interpolate")
    i1 = int(np.searchsorted(grid, value))
    i0 = i1 - 1
    return i0, i1, float((value - grid[i0]) / (grid[i1] - grid[i0])), False



def at_value(at_loc, name, ds):
    """SI value of an ``--at`` axis after location (the grid value on a grid point)."""
    i0, i1, w, on_grid = at_loc[name]
    grid = ds[name].values.astype(float)
    return float(grid[i0]) if on_grid else float(grid[i0] * (1 - w) + grid[i1] * w)
