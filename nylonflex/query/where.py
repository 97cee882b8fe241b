"""``--where`` tested variable by variable over a slab of the cube (``nylonflex query``).

The conditions are tested one variable at a time (axes first: they cost no read), each
variable read only over the box (an index range per axis) that still holds matching
designs after the ones before; a slab is left as soon as nothing matches. The other
columns are then read over the final box of the rows kept only (none once ``--limit`` rows
are kept: the scan then reads the tested variables alone).

This scan reads a cube through a few members alone: ``sizes``, ``dims``, ``attrs``,
``name in ds``, ``ds[axis].values`` and :func:`read_values`. So besides an xarray Dataset
(:func:`nylonflex.open_cube`) it takes a cube read through h5py alone
(:class:`nylonflex.storage.light.LightCube`); :func:`by_variable` says when a query is
answered by it.
"""

from __future__ import annotations

import numpy as np

from ..conditions import CATEGORY_WHERE, COLUMNS, OPTIONAL, parse_at
from ..units import InputError
from ..variables import AXES, CATEGORIES, DESIGN
from .grid import at_value, locate

__all__ = ["by_variable", "read_values", "where_rows"]


def read_values(ds, name: str, index: dict, dims=None) -> np.ndarray:
    """Variable ``name`` of a cube over ``index`` (``{dimension: int or slice}``; an int
    drops the dimension), float64 [SI], its axes in the order ``dims`` (default: the
    variable's own).

    ``ds`` is an xarray Dataset, or a cube that reads itself (no ``isel``: a
    :class:`~nylonflex.storage.light.LightCube`, whose ``read`` decodes the same numbers).
    """
    if not hasattr(ds, "isel"):
        return ds.read(name, index, dims)
    da = ds[name].isel(index)
    return np.asarray((da if dims is None else da.transpose(*dims)).values, dtype=float)


def by_variable(ds, at, where, interpolate: bool) -> bool:
    """Whether :func:`~nylonflex.query.query_cube` answers ``at``, ``where`` and
    ``interpolate`` on the cube ``ds`` by :func:`where_rows` alone (so that a cube without
    xarray serves it): a condition on a variable or axis, no ``--interpolate``, one model
    and one cooling set, and every ``--at`` value on the grid.

    ``at`` is the ``--at`` text(s) (or a dict of SI values); one that is malformed or off
    the grid answers False (xarray's path then evaluates it, or says what is wrong).
    """
    if interpolate or any(c in ds.dims for c in CATEGORIES):
        return False
    if not [w for w in where if not CATEGORY_WHERE.match(str(w))]:
        return False
    try:
        at = parse_at(at) if at and isinstance(at, (str, list, tuple)) else dict(at or {})
        return all(locate(ds, name, value)[3] for name, value in at.items())
    except InputError:
        return False


class _Slab:
    """A slab of radii [r0, r1) with the ``--at`` axes fixed: its free axes (``dims``), and
    reads over a box of it (``{axis: (start, stop)}``, indices within the slab)."""

    def __init__(self, ds, at_loc, r0, r1):
        self.ds = ds
        self.fixed = {name: loc[0] for name, loc in at_loc.items() if name != "radius"}
        self.at = {name: at_value(at_loc, name, ds) for name in self.fixed}
        self.dims = [d for d in AXES if d not in self.fixed]
        self.start = {d: (r0 if d == "radius" else 0) for d in self.dims}
        self.whole = {d: (0, (r1 - r0) if d == "radius" else ds.sizes[d]) for d in self.dims}
        self.coords = {d: ds[d].values.astype(float)[self.start[d]:self.start[d] +
                                                      self.whole[d][1]] for d in self.dims}

    def shape(self, box) -> list[int]:
        return [box[d][1] - box[d][0] for d in self.dims]

    def axis(self, name, box) -> np.ndarray:
        """The values [SI] of axis ``name`` at each design of ``box``."""
        if name in self.fixed:
            return np.full(self.shape(box), self.at[name])
        shape = [-1 if d == name else 1 for d in self.dims]
        values = self.coords[name][box[name][0]:box[name][1]].reshape(shape)
        return np.broadcast_to(values, self.shape(box))

    def read(self, name, box) -> np.ndarray:
        """Variable ``name`` [SI] over ``box`` (NaN where the cube has none: heating_time
        without a supply)."""
        if name not in self.ds:
            return np.full(self.shape(box), np.nan)
        index = dict(self.fixed)
        index.update({d: slice(self.start[d] + box[d][0], self.start[d] + box[d][1])
                      for d in self.dims})
        return read_values(self.ds, name, index, self.dims)

    def shrink(self, mask, box):
        """The matches' bounding box, and the mask cut to it."""
        cut = {}
        for j, d in enumerate(self.dims):
            others = tuple(k for k in range(len(self.dims)) if k != j)
            hit = np.flatnonzero(mask.any(axis=others))
            cut[d] = (int(hit[0]), int(hit[-1]) + 1)
        return (mask[tuple(slice(*cut[d]) for d in self.dims)],
                {d: (box[d][0] + cut[d][0], box[d][0] + cut[d][1]) for d in self.dims})

    def rows(self, mask, box, read_at) -> dict:
        """The columns of the designs ``mask`` picks in ``box``, in grid order; a variable
        in ``read_at`` (``{name: (values, the box they were read over)}``) is not read
        again."""
        rows = {name: self.axis(name, box)[mask] for name in AXES}
        for name in (*DESIGN, *(n for n in OPTIONAL if n in self.ds)):
            if name in read_at:
                x, b = read_at[name]
                x = x[tuple(slice(box[d][0] - b[d][0], box[d][1] - b[d][0])
                            for d in self.dims)]
            else:
                x = self.read(name, box)
            rows[name] = x[mask]
        return rows


def where_rows(ds, at_loc, r0, r1, conditions, room=None):
    """The rows of radius indices [r0, r1) that meet every condition (``--at`` on the
    grid), at most ``room`` of them (the first in grid order; None: all), and how many
    matched.

    The rows are the columns of :data:`~nylonflex.query.COLUMNS` and the cube's
    :data:`~nylonflex.query.OPTIONAL` ones (SI arrays), picked in grid order as
    :func:`~nylonflex.query.slab_rows` gives them.
    """
    slab = _Slab(ds, at_loc, r0, r1)
    box = dict(slab.whole)
    empty = {name: np.empty(0) for name in COLUMNS + tuple(n for n in OPTIONAL if n in ds)}
    read_at = {}  # name: (values, the box they were read over)
    mask = None
    for c in sorted(conditions, key=lambda c: c.name not in AXES):
        if c.name in AXES:
            x = slab.axis(c.name, box)
        else:
            x = slab.read(c.name, box)
            read_at[c.name] = (x, dict(box))
        m = c.mask(x)
        mask = m if mask is None else mask & m
        if not mask.any():
            return empty, 0
        mask, box = slab.shrink(mask, box)  # before the next read
    matched = int(mask.sum())
    if room is not None:
        if room <= 0:
            return empty, matched
        first = np.flatnonzero(mask.ravel())[:room]
        mask = np.zeros(mask.shape, dtype=bool)
        mask.ravel()[first] = True
        mask, box = slab.shrink(mask, box)
    return slab.rows(mask, box, read_at), matched
