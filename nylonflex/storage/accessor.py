"""``ds.nf`` and ``da.nf``: a cube's values in the units people read them in (mm, deg, kPa).

Registered with xarray when a cube is opened or swept (:func:`nylonflex.open_cube`,
:func:`nylonflex.run_sweep`); ``import nylonflex.storage.accessor`` registers it for any
Dataset. The cube itself stays SI; these give display-unit copies for plots and tables::

    ds = nf.open_cube("sweeps/fig12/cube.h5")
    ds.nf.sel(radius="10.5 mm", wrap_angle="8 deg")     # sel with units (exact grid values)
    ds.nf.sel(radius=0.0105)                             # a bare number is SI, as in Python
    ds["tip_force_max"].nf.display()                     # N -> N, torque N m -> N mm, ...
    ds.nf.display()["radius"]                            # every registered variable
    ds.nf                                                # its name, models, materials,
                                                         # grid and completeness
"""

from __future__ import annotations

import html

import numpy as np
import xarray as xr

from ..units import InputError, from_si, parse_quantity
from ..variables import AXES, VARIABLES, is_complete, to_display

__all__ = ["CubeAccessor", "NotOnGrid", "VariableAccessor"]


class NotOnGrid(InputError, KeyError):
    """A value ``ds.nf.sel`` does not find on the grid (a KeyError, as xarray's miss)."""

    __str__ = Exception.__str__


def _miss(name, typed, si, grid, v) -> str:
    """One line: the value not on the grid, how it was read, the nearest grid values."""
    near = grid[np.argsort(np.abs(grid - si))[:2]] if len(grid) else grid
    show = ", ".join(f"{x:.6g} {v.units} ({from_si(x, v.display):.4g} {v.display})"
                     for x in sorted(near))
    read = "read in SI" if isinstance(typed, (int, float)) else "read as"
    unit = "" if v.units == "1" else f" {v.units}"
    return (f"{name}={typed!r} ({read} {si:.6g}{unit}) is not a grid value; nearest: {show}"
            + (f"; a bare number is SI ({v.units}): write '{typed}{v.display}' for "
               f"{v.display}" if isinstance(typed, (int, float)) and v.units != v.display
               else ""))


def _display(da: xr.DataArray, name: str | None = None) -> xr.DataArray:
    """``da`` (a registered variable, SI) in its display unit, ``units`` attr to match;
    a name the registry does not know is returned as it is."""
    name = name or da.name
    v = VARIABLES.get(name)
    if v is None or v.display == v.units:
        return da
    out = da.copy(data=to_display(name, da.values))
    out.attrs = {**da.attrs, "units": v.display}
    return out


@xr.register_dataarray_accessor("nf")
class VariableAccessor:
    """``da.nf``: a cube variable in its display unit."""

    def __init__(self, da: xr.DataArray):
        self._da = da

    def display(self) -> xr.DataArray:
        """The values [display unit: mm, deg, kPa, N mm, ...] and the coordinates too;
        the ``units`` attributes say which."""
        da = _display(self._da)
        coords = {c: _display(da[c], c) for c in da.coords if c in VARIABLES}
        return da.assign_coords(coords)


@xr.register_dataset_accessor("nf")
class CubeAccessor:
    """``ds.nf``: selections with units, and the cube in display units."""

    def __init__(self, ds: xr.Dataset):
        self._ds = ds

    def sel(self, **at) -> xr.Dataset:
        """``ds.sel`` with values in SI (``radius=0.0105`` [m], as everywhere in Python) or
        with a unit (``radius="10.5 mm"``, ``wrap_angle="8deg"``). Exact: the grid's
        coordinates are the floats nearest their decimal values, and so is a value typed.

        Raises
        ------
        nylonflex.units.InputError
            A name that is not an axis of the cube, or a unit of the wrong kind.
        NotOnGrid
            The value is not a grid value: one line with the nearest grid values, in SI and
            in the display unit (an :class:`~nylonflex.units.InputError` and a ``KeyError``,
            as xarray's own miss is).
        """
        si = {}
        for name, value in at.items():
            v = VARIABLES.get(name)
            if name not in self._ds.dims or v is None:
                raise InputError(f"{name}: not an axis of this cube; axes: "
                                 f"{', '.join(d for d in self._ds.dims if d in VARIABLES)}")
            si[name] = parse_quantity(value, name, v.kind, v.units)  # bare: SI
            grid = self._ds[name].values
            if not np.any(grid == si[name]):
                raise NotOnGrid(_miss(name, value, si[name], grid, v))
        return self._ds.sel(si)

    def display(self) -> xr.Dataset:
        """A copy with every registered variable and coordinate in its display unit."""
        ds = self._ds
        out = ds.assign({n: _display(ds[n], n) for n in ds.data_vars if n in VARIABLES})
        return out.assign_coords({c: _display(ds[c], c) for c in ds.coords if c in VARIABLES})

    def summary(self) -> list[str]:
        """What the cube is, one line each: its name and version, whether it is complete
        (and how far an incomplete one got), its grid in display units, its models and
        material sets, its provenance."""
        ds, a = self._ds, self._ds.attrs
        lines = [f"nylonflex cube {a.get('name', '?')!r} (cube format "
                 f"{a.get('nylonflex_cube', '?')}, nylonflex {a.get('nylonflex_version', '?')})"]
        if is_complete(a):
            lines.append("complete")
        else:
            done = ds["slab_done"].values if "slab_done" in ds else None
            part = f": {int(np.sum(done == 1))} of {done.size} slabs done" \
                if done is not None else ""
            lines.append(f"INCOMPLETE{part} (nylonflex sweep --resume finishes it)")
        axes = [n for n in AXES if n in ds.dims]
        n = int(np.prod([ds.sizes[x] for x in axes])) if axes else 0
        grid = ", ".join(_axis_text(ds, x) for x in axes)
        lines.append(f"{n:,} designs: {grid}")
        models = ds["model"].values.tolist() if "model" in ds.dims else [a.get("models", "?")]
        lines.append(f"model: {', '.join(map(str, models))}")
        for kind in ("silicone", "nylon"):
            if kind in a:
                note = a.get(f"{kind}_description", "")
                lines.append(f"{kind}: {a[kind]}" + (f" ({note})" if note else ""))
        if "created" in a:
            lines.append(f"created {a['created']}, config sha256 "
                         f"{str(a.get('config_sha256', '?'))[:12]}")
        return lines

    def __repr__(self) -> str:
        return "\n".join(self.summary())

    def _repr_html_(self) -> str:
        head, *rest = self.summary()
        items = "".join(f"<li>{html.escape(line)}</li>" for line in rest)
        return f"<div class='nylonflex'><strong>{html.escape(head)}</strong><ul>{items}</ul></div>"


def _axis_text(ds, name: str) -> str:
    """``radius 5-25 mm (41)`` in the axis's display unit."""
    v = VARIABLES[name]
    values = to_display(name, ds[name].values)
    unit = "" if v.display in ("1", "") else f" {v.display}"
    lo, hi = float(np.min(values)), float(np.max(values))
    span = f"{lo:g}" if lo == hi else f"{lo:g}-{hi:g}"
    return f"{name} {span}{unit} ({values.size})"
