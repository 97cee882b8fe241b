"""The explorer's data: the slices of a cube each view of ``nylonflex explore`` shows.

Every function reads only the slice it needs from a lazily opened cube
(``ds[name].isel(...).values``), so a cube of tens of millions of designs opens in seconds
and memory stays bounded by the views, not by the cube. Values are never interpolated: a
design is always a grid point of the cube (:func:`snap` says which and whether a requested
value fell between grid points). Numbers come back in display units (mm, deg, kPa, N) with
their labels from the variable registry; a variable the registry does not know keeps the
units the cube gives it.

The page itself (Panel, HoloViews) is built by :func:`nylonflex.explore_page.build_page`.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from .units import InputError
from .variables import AXES, VARIABLES, to_display

__all__ = ["Snapped", "axis_text", "design_curves", "design_table", "design_variables",
           "colour_range", "design_config", "display_unit", "fig12_lines", "flag_meanings", "label",
           "map_slice", "snap", "stand_in_note", "validity_names",
           "to_display_any"]

#: Curves of a design and the coordinate each is drawn against.
CURVE_AXES = {"nylon_force": "stroke", "bend_angle": "pressure", "tip_force": "pressure"}


# ---------------------------------------------------------------------------- units, labels
def display_unit(ds, name: str) -> str:
    """The unit ``name`` is shown in: the registry's display unit, else the cube's units."""
    if name in VARIABLES:
        return VARIABLES[name].display
    return str(ds[name].attrs.get("units", "1")) if name in ds.variables else "1"


def to_display_any(ds, name: str, si):
    """SI values of ``name`` in :func:`display_unit` (registry names converted)."""
    if name in VARIABLES:
        return to_display(name, si)
    return np.asarray(si, dtype=float)


def label(ds, name: str) -> str:
    """``"maximum tip force [N]"``: long name and display unit of ``name``."""
    if name in VARIABLES:
        long_name = VARIABLES[name].long_name
    else:
        long_name = str(ds[name].attrs.get("long_name", name))
    unit = display_unit(ds, name)
    return long_name if unit == "1" else f"{long_name} [{unit}]"


def axis_text(ds, name: str, si) -> str:
    """``"7.5 mm"``, ``"8 deg"``, ``"1.7"``: one value of an axis or variable for a label."""
    value = float(to_display_any(ds, name, si))
    unit = display_unit(ds, name)
    return f"{value:.4g}" if unit == "1" else f"{value:.4g} {unit}"


# ---------------------------------------------------------------------------- the cube's parts
def design_variables(ds) -> list[str]:
    """The cube's design variables: those over every design axis, registry order first.

    ``validity`` (a flag set) is left out; ``limit`` is included (0 stroke-, 1 strength-
    limited).
    """
    names = [n for n in ds.data_vars
             if set(AXES) <= set(ds[n].dims) and set(ds[n].dims) <= {*AXES, "model"}
             and n != "validity"]
    order = list(VARIABLES)
    return sorted(names, key=lambda n: (order.index(n) if n in order else len(order), n))


def flag_meanings(ds, name: str = "validity") -> list[tuple[int, str]]:
    """The (mask, meaning) pairs of a CF flag variable (``flag_masks``/``flag_meanings``)."""
    if name not in ds.variables:
        return []
    attrs = ds[name].attrs
    masks = np.atleast_1d(attrs.get("flag_masks", attrs.get("flag_values", [])))
    meanings = str(attrs.get("flag_meanings", "")).split()
    return [(int(m), s) for m, s in zip(masks, meanings) if int(m) != 0]


def validity_names(ds, bits) -> str:
    """A design's ``validity`` as its flag names: ``"valid"`` for 0, ``"self contact,
    stretch beyond fit"`` for the bits set, ``"unknown"`` for NaN (docs/model.md s. 17)."""
    if bits is None or not np.isfinite(bits):
        return "unknown"
    names = [m.replace("_", " ") for mask, m in flag_meanings(ds) if int(bits) & mask]
    return ", ".join(names) if names else "valid"


def stand_in_note(ds) -> str:
    """One sentence naming the cube's material sets whose values include proposals or
    stand-ins (source tag P, or a description saying "stand-in"), "" when none do."""
    import yaml

    parts = []
    for kind in ("silicone", "nylon"):
        try:
            doc = yaml.safe_load(str(ds.attrs.get(f"{kind}_parameters", ""))) or {}
        except yaml.YAMLError:
            continue
        if not isinstance(doc, dict):
            continue
        sources = doc.get("sources") or {}
        proposed = sorted(k for k, v in sources.items() if "P" in str(v).split(":")[0])
        stand_in = "stand-in" in str(doc.get("description", ""))
        if proposed or stand_in:
            name = doc.get("name", ds.attrs.get(kind, kind))
            what = f"{len(proposed)} of its {len(sources)} values are proposals (tag P)" \
                if proposed else "a stand-in"
            parts.append(f"{kind} {name}: {'a stand-in; ' if stand_in and proposed else ''}"
                         f"{what}")
    if not parts:
        return ""
    return ("Stand-in materials: " + "; ".join(parts) + " (docs/model.md s. 9; fit your "
            "own with nylonflex fit). The numbers are the model's with these sets, not "
            "measurements.")


def colour_range(z, validity=None) -> tuple[float, float]:
    """``(lo, hi)`` of a map's colour scale: the finite values of the clean designs
    (``validity`` 0), so that flagged ones (a 1 mm wall bending 1,300 deg) do not set it;
    every finite value where no design is clean."""
    z = np.asarray(z, float)
    ok = np.isfinite(z)
    if validity is not None:
        clean = ok & (np.nan_to_num(np.asarray(validity, float), nan=1.0) == 0)
        ok = clean if clean.any() else ok
    if not ok.any():
        return 0.0, 1.0
    lo, hi = float(z[ok].min()), float(z[ok].max())
    return (lo, hi) if hi > lo else (lo, lo + 1.0)


def _curve_axis(name, si) -> dict:
    """A curve axis of a config in display units: start/stop/num when evenly spaced."""
    v = np.asarray(to_display(name, np.asarray(si, float)), float)
    unit = VARIABLES[name].display
    units = {} if unit == "1" else {"units": unit}
    if v.size > 2 and np.allclose(v, np.linspace(v[0], v[-1], v.size), rtol=0,
                                  atol=1e-9 * max(1.0, abs(v[-1]))):
        return {"start": float(f"{v[0]:.12g}"), "stop": float(f"{v[-1]:.12g}"),
                "num": int(v.size), **units}
    return {"values": [float(f"{x:.12g}") for x in v], **units}


def design_config(ds, at: dict, placeholders: bool = False) -> str:
    """The selected design as a runnable sweep config (YAML, display units): one grid value
    per axis, the cube's curves, and its materials as ``{set: NAME, field: value, ...}``
    with every field of the cube's resolved sets, so that ``nylonflex sweep`` of it gives
    this design's values of the cube ("copy as config"). With ``placeholders`` each grid
    value is ``'@AXIS@'``, for a page to fill in."""
    import yaml

    from .materials import NYLON_PARAMETERS, SILICONE_PARAMETERS

    cfg = yaml.safe_load(str(ds.attrs.get("config_yaml", ""))) or {}
    out = {"name": f"{cfg.get('name', 'design')}_design"}
    for kind, table, default in (("silicone", SILICONE_PARAMETERS, "tc5005"),
                                 ("nylon", NYLON_PARAMETERS, "silver_nylon66")):
        m = cfg.get(kind)
        if isinstance(m, dict):
            base = str(m.get("name", default)).split("+")[0]
            out[kind] = {"set": base if base in table else default,
                         **{k: v for k, v in m.items() if k != "name"}}
        elif m is not None:
            out[kind] = m
    if "base_thickness" in cfg:
        b = cfg["base_thickness"]
        out["base_thickness"] = b if b == "wall" or b is None else \
            {"value": float(f"{float(to_display('wall_thickness', float(b))):.12g}"),
             "units": "mm"}
    if isinstance(cfg.get("model"), str):
        out["model"] = cfg["model"]
    grid = {}
    for axis in AXES:
        value = float(ds[axis].values[snap(ds, axis, float(at[axis])).index])
        unit = VARIABLES[axis].display
        shown = f"@{axis}@" if placeholders else float(f"{float(to_display(axis, value)):.12g}")
        grid[axis] = {"values": [shown],
                      **({} if unit == "1" else {"units": unit})}
    out["grid"] = grid
    out["curves"] = {c: _curve_axis(c, ds[c].values) for c in ("stroke", "pressure")}
    head = (f"# the design picked in the explorer of cube '{cfg.get('name', '?')}': "
            "nylonflex sweep THIS.yaml\n")
    return head + yaml.safe_dump(out, sort_keys=False, default_flow_style=None, width=100)


@dataclass(frozen=True)
class Snapped:
    """A requested axis value and the grid point the cube holds for it."""

    axis: str
    index: int
    value: float          # the grid value [SI]
    requested: float      # the value asked for [SI]
    exact: bool           # the request was a grid value (to 1e-9 of the axis span)

    def note(self, ds) -> str:
        """One line for the page: the grid point, and whether the request fell between."""
        shown = axis_text(ds, self.axis, self.value)
        if self.exact:
            return f"{self.axis} {shown} (a grid point)"
        return (f"{self.axis} {axis_text(ds, self.axis, self.requested)} lies between grid "
                f"points: showing the nearest grid point {shown} (the cube holds no values "
                "between grid points)")


def snap(ds, axis: str, value: float) -> Snapped:
    """The grid point of ``axis`` nearest ``value`` [SI].

    Raises
    ------
    InputError
        ``axis`` is not a coordinate of the cube.
    """
    if axis not in ds.coords:
        raise InputError(f"{axis}: not an axis of this cube; accepted: "
                         f"{', '.join(str(c) for c in ds.coords)}")
    grid = np.asarray(ds[axis].values, dtype=float)
    i = int(np.argmin(np.abs(grid - value)))
    span = float(np.ptp(grid)) or 1.0
    return Snapped(axis, i, float(grid[i]), float(value),
                   bool(abs(grid[i] - value) <= 1e-9 * span))


def _index(ds, at: dict) -> dict:
    """Positional indexers of ``at`` (axis -> SI value or, for ``model``, a name)."""
    out = {}
    for name, value in at.items():
        if name not in ds.dims:
            continue
        if ds[name].dtype.kind in "OUS":
            names = [str(v) for v in ds[name].values]
            if str(value) not in names:
                raise InputError(f"{name}: {value!r} is not in this cube; accepted: "
                                 f"{', '.join(names)}")
            out[name] = names.index(str(value))
        else:
            out[name] = snap(ds, name, float(value)).index
    return out


def _read(ds, name: str, at: dict):
    """``ds[name]`` at the grid point(s) of ``at`` (its dims only), read from disk."""
    da = ds[name]
    return da.isel({k: v for k, v in _index(ds, at).items() if k in da.dims})


# A radius-chunked cube decompresses every chunk of a variable for a slice across radii
# (0.5 s for 20 million designs), so the map and the figure 12 lines share one block per
# variable read at the held length and wrap angle: moving the radius, wall or coil index
# sliders then reads nothing. Bounded: a few blocks, each at most _BLOCK_BYTES.
_FREE = ("radius", "wall_thickness", "coil_index")
_BLOCK_BYTES = 32 * 2**20
_BLOCKS: OrderedDict = OrderedDict()


def _block(ds, name: str, at: dict, free: tuple):
    """``ds[name]`` with every dim outside ``free`` held at ``at``, as a DataArray in
    memory (cached, least recently used first out)."""
    da = ds[name]
    held = {k: v for k, v in _index(ds, at).items() if k in da.dims and k not in free}
    key = (id(ds), name, tuple(sorted(held.items())), free)
    hit = _BLOCKS.get(key)
    if hit is not None and hit[0]() is ds:  # the same Dataset, not one reusing its id
        _BLOCKS.move_to_end(key)
        return hit[1]
    block = da.isel(held)
    if block.size * block.dtype.itemsize > _BLOCK_BYTES:
        return block
    block = block.load()
    _BLOCKS[key] = (weakref.ref(ds), block)
    while len(_BLOCKS) > 8:
        _BLOCKS.popitem(last=False)
    return block


# ---------------------------------------------------------------------------- views
def map_slice(ds, var: str, x: str, y: str, at: dict) -> dict:
    """``var`` over axes ``x`` and ``y`` with every other axis held at ``at``.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    var : str
        A design variable.
    x, y : str
        Two different design axes.
    at : dict
        The other axes' values [SI] (snapped to the grid), and ``model`` where the cube has
        that dimension.

    Returns
    -------
    dict
        ``x``, ``y`` (grid values in display units), ``z`` (shape (ny, nx), display units),
        ``limit`` (1 where strength-limited, shape (ny, nx), or None) and ``validity``
        (flag bits, or None).
    """
    if x == y or x not in AXES or y not in AXES:
        raise InputError(f"map axes: two different names of {', '.join(AXES)}; "
                         f"got {x!r} and {y!r}")
    rest = {k: v for k, v in at.items() if k not in (x, y)}

    free = tuple(dict.fromkeys((*_FREE, x, y)))

    def plane(name):
        block = _block(ds, name, rest, free)
        return block.isel({k: v for k, v in _index(ds, rest).items()
                           if k in block.dims}).transpose(y, x).values

    out = {"x": to_display_any(ds, x, ds[x].values), "y": to_display_any(ds, y, ds[y].values),
           "z": to_display_any(ds, var, plane(var).astype(float)),
           "limit": plane("limit") if "limit" in ds else None,
           "validity": plane("validity") if "validity" in ds else None}
    return out


def design_table(ds, at: dict) -> list[dict]:
    """Every design variable of one design: name, label, value (display units), unit, SI."""
    rows = []
    point = ds[design_variables(ds)].isel(_index(ds, at)).load()
    for name in design_variables(ds):
        si = float(point[name].values)
        rows.append({"name": name, "label": label(ds, name),
                     "value": float(to_display_any(ds, name, si)),
                     "unit": display_unit(ds, name), "si": si})
    return rows


def design_curves(ds, at: dict) -> dict:
    """The curves of one design: ``{name: (x display, y display)}``, plus the nylon limit.

    ``nylon_force_limit`` comes back as a float [N] (the design's coil index) where the cube
    has it.
    """
    out = {}
    for name, axis in CURVE_AXES.items():
        if name in ds:
            y = _read(ds, name, at).values.astype(float)
            out[name] = (to_display_any(ds, axis, ds[axis].values),
                         to_display_any(ds, name, y))
    if "nylon_force_limit" in ds:
        out["nylon_force_limit"] = float(to_display_any(
            ds, "nylon_force_limit", _read(ds, "nylon_force_limit", at).values))
    return out


def fig12_lines(ds, var: str, at: dict) -> dict:
    """Figure 12 style: ``var`` against radius, one line per coil index.

    Every other axis is held at ``at``. Returns ``{"radius": x, "lines": {coil_index:
    (values, strength_limited)}}`` in display units; ``strength_limited`` is a bool array
    (the paper draws a design solid while it is stroke-limited).
    """
    rest = {k: v for k, v in at.items() if k not in ("radius", "coil_index")}
    idx = _index(ds, rest)

    def cut(name):
        block = _block(ds, name, rest, _FREE)
        return block.isel({k: v for k, v in idx.items() if k in block.dims})

    value_cut = cut(var)
    limit_cut = cut("limit") if "limit" in ds else None
    lines = {}
    for k, c in enumerate(ds["coil_index"].values):
        values = value_cut.isel(coil_index=k).transpose("radius").values.astype(float)
        lim = limit_cut.isel(coil_index=k).transpose("radius").values == 1 \
            if limit_cut is not None else np.zeros(values.shape, bool)
        lines[float(c)] = (to_display_any(ds, var, values), lim)
    return {"radius": to_display_any(ds, "radius", ds["radius"].values), "lines": lines}
