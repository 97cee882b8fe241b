"""What every chart shares: the palette and rc, the paper's worked examples, labels and
titles from the variable registry, the grid-slice helpers, the footer, and
:func:`new_figure`: a :class:`matplotlib.figure.Figure` made without pyplot, so drawing never
changes a user's backend or pyplot state."""

from __future__ import annotations

import math

import numpy as np

from ..variables import VARIABLES, incomplete_text, to_display

#: Image formats a chart can be written in.
FORMATS = ("png", "pdf", "svg")

# Colours of the Okabe-Ito palette (readable for colour-blind readers and in greyscale).
_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
            "#000000")
# Flagged designs (``validity`` != 0): greyed or hatched in this grey.
_FLAG_GREY = "0.55"
_FLAG_FILL = (0.55, 0.55, 0.55, 0.7)
# Dash patterns of the strength limits, one per wrap angle; all black as in the paper.
_DASHES = ((0, (6, 2)), (0, (3, 1.5)), (0, (1, 1.2)), (0, (6, 1.5, 1, 1.5)),
           (0, (10, 3)), (0, (2, 3)))

#: The charts' matplotlib style (sizes in points; ``savefig.dpi`` in dots per inch).
RC = {"font.size": 10, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 8.5,
       "legend.title_fontsize": 8.5, "xtick.labelsize": 9, "ytick.labelsize": 9,
       "figure.titlesize": 11, "axes.grid": True, "grid.alpha": 0.3, "lines.linewidth": 1.6,
       "savefig.dpi": 200, "svg.fonttype": "none", "pdf.fonttype": 42}

# The paper's worked examples (section 4), SI: (radius, wall, length, coil index).
_EXAMPLES = ((20e-3, 6e-3, 90e-3, 1.1), (7.5e-3, 2e-3, 70e-3, 1.7))
_WRAP_DEFAULT = math.radians(8.0)  # docs/model.md s. 8 checks the examples at psi = 8 deg
_LENGTH_DEFAULT = 90e-3


# ---------------------------------------------------------------------------- helpers
def new_figure(nrows=1, ncols=1, size=(6.0, 4.2), rc=None, **kw):
    """A new :class:`matplotlib.figure.Figure` and its ``(nrows, ncols)`` array of axes.

    Built without pyplot: no figure manager, no global current figure, the caller's backend
    untouched (a notebook keeps its own); the file format picks the canvas when the figure
    is saved. ``size`` is in inches; ``rc`` (default :data:`RC`) styles what is created;
    ``layout="constrained"`` unless ``kw`` says otherwise (``layout=None``).
    """
    from matplotlib import rc_context
    from matplotlib.figure import Figure

    layout = kw.pop("layout", "constrained")
    with rc_context(RC if rc is None else rc):
        fig = Figure(figsize=size, layout=layout)
        axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def rc_context(rc=None):
    """:func:`matplotlib.rc_context` of the charts' style (default :data:`RC`)."""
    import matplotlib

    return matplotlib.rc_context(RC if rc is None else rc)


_figure = new_figure  # the name the chart modules of this package use


def _text(name, si) -> str:
    """``"90 mm"``, ``"8 deg"``, ``"1.7"``: a value of a registered name for a title."""
    v = VARIABLES[name]
    value = float(to_display(name, si))
    unit = "" if v.display == "1" else (" deg" if v.display == "deg" else f" {v.display}")
    return f"{value:.4g}{unit}"


_SYMBOL = {"radius": "a", "wall_thickness": "t", "length": "L", "coil_index": "C",
           "wrap_angle": "\u03c8", "pressure": "p"}


def _eq(name, si) -> str:
    """``"L = 90 mm"``: a slice value for a legend or title."""
    return f"{_SYMBOL.get(name, name)} = {_text(name, si)}"


def _nearest(ds, name, target):
    """The grid value of ``name`` nearest ``target`` [SI]."""
    values = ds[name].values
    return float(values[int(np.argmin(np.abs(values - target)))])


def _spread(ds, name, lo, hi, n):
    """Up to ``n`` grid values of ``name`` in [lo, hi] [SI], evenly spread, ends included.

    Where fewer than three (or fewer than the axis has) lie inside, the values spread over
    the whole axis instead: a chart of a cube on another grid still shows a family.
    """
    values = ds[name].values
    span = max(abs(hi - lo), 1e-300)
    inside = values[(values >= lo - 1e-9 * span) & (values <= hi + 1e-9 * span)]
    if inside.size < min(3, values.size, n):
        inside = values
    if inside.size <= n:
        return [float(x) for x in inside]
    idx = np.unique(np.round(np.linspace(0, inside.size - 1, n)).astype(int))
    return [float(inside[i]) for i in idx]


def _grid_value(ds, name, value):
    """The grid value of ``name`` equal to ``value`` [SI] (to rounding), or None."""
    values = ds[name].values.astype(float)
    tol = 1e-6 * max(float(np.ptp(values)) if values.size > 1 else 0.0,
                     float(np.abs(values).max()), 1e-300)
    i = int(np.argmin(np.abs(values - value)))
    return float(values[i]) if abs(values[i] - value) <= tol else None


def _coils(ds, coil_index=None):
    """Coil indices to draw: the given ones (on the grid) or every one of the cube."""
    if coil_index is None:
        return [float(c) for c in ds["coil_index"].values]
    return [_nearest(ds, "coil_index", c) for c in np.atleast_1d(coil_index)]


def _example_point(ds, example, **fixed):
    """The grid design of a paper example, or None where the cube's slice does not hold it.

    ``example`` is (radius, wall, length, coil index) [SI] at psi = 8 deg; ``fixed`` are
    the slice's values [SI] (a panel's wall, length, coil index or wrap angle), which must
    equal the example's. Every one of the five values must be a grid value: a star never
    snaps to a neighbour, so the numbers beside it are the paper's design's own.
    """
    target = dict(zip(("radius", "wall_thickness", "length", "coil_index"), example),
                  wrap_angle=_WRAP_DEFAULT)
    at = {}
    for name, value in target.items():
        grid = _grid_value(ds, name, value)
        if grid is None:
            return None
        if name in fixed and fixed[name] is not None and abs(fixed[name] - grid) > \
                1e-9 * max(abs(grid), 1e-300):
            return None
        at[name] = grid
    return at


#: Most wrap angles a fig. 12(b, c) panel labels; more are drawn faint and unlabelled.
_MAX_LABELLED = 6


def _labelled_psis(psis):
    """The wrap angles to draw in colour and label: all, or up to six spread ones."""
    if len(psis) <= _MAX_LABELLED:
        return list(psis)
    idx = np.unique(np.round(np.linspace(0, len(psis) - 1, _MAX_LABELLED)).astype(int))
    return [psis[i] for i in idx]


def _psi_colour(j, n):
    """Colour of the j-th of n labelled wrap angles (dark to light, apart from the coils)."""
    import matplotlib

    return matplotlib.colormaps["plasma"](0.05 + 0.75 * (j / max(n - 1, 1)))


def _range_text(name, values) -> str:
    """``"6-14 mm"`` or ``"2 mm"``: the span of the values drawn, for a subtitle."""
    lo, hi = min(values), max(values)
    if abs(hi - lo) <= 1e-12 * max(abs(hi), 1e-300):
        return _text(name, lo)
    v = VARIABLES[name]
    unit = "" if v.display == "1" else (" deg" if v.display == "deg" else f" {v.display}")
    return f"{float(to_display(name, lo)):.4g}-{float(to_display(name, hi)):.4g}{unit}"


def _pick_few(ds, name, n):
    """Up to ``n`` grid values of ``name`` spread over its whole range."""
    values = ds[name].values
    return _spread(ds, name, float(values.min()), float(values.max()), n)


def _footer(fig, ds):
    name = ds.attrs.get("name", "?")
    version = ds.attrs.get("nylonflex_version", "?")
    note = f"cube '{name}' (nylonflex {version}, {ds.attrs.get('silicone', '?')} / " \
           f"{ds.attrs.get('nylon', '?')})"

    # above the canvas (savefig's tight bounding box takes it in): clear of titles,
    # axes and legends whatever the layout
    fig.text(0.0, 1.0, note, ha="left", va="bottom", fontsize=7, color="0.4")
    missing = incomplete_text(ds)
    if missing:  # a sweep stopped early: the title's first line says so, in red
        title = fig.get_suptitle()
        fig.suptitle(f"{missing} (missing radii are blank)" + (f"\n{title}" if title else ""),
                     fontsize=RC["figure.titlesize"], color="#B00020", gid="nf-incomplete")


def _suptitle(fig, title, subtitle):
    fig.suptitle(f"{title}\n{subtitle}", fontsize=RC["figure.titlesize"])


def _stroke_max(ds):
    """s_max(C) [-], stored in the cube.

    Cubes written before ``stroke_max`` was stored: the usable stroke of stroke-limited
    designs (NaN for a coil index with none).
    """
    if "stroke_max" in ds:
        return ds["stroke_max"].values
    s = ds["usable_stroke"].where(ds["limit"] == 0)
    dims = [d for d in s.dims if d != "coil_index"]
    return s.max(dims).values



def _models(ds):
    """The models of a cube, or ``[None]`` for a cube without a ``model`` dimension."""
    return [str(m) for m in ds["model"].values] if "model" in ds.dims else [None]


def _one_model(ds, model):
    """The cube of one model (``model`` None: the cube as it is)."""
    return ds if model is None else ds.sel(model=model, drop=True)


def _flag_text(ds, bits) -> str:
    """``"1 self_contact, 4 under_one_turn"``: the validity flags set in ``bits``, named
    from the cube's CF ``flag_masks``/``flag_meanings`` ("" for none)."""
    if not bits or "validity" not in ds:
        return ""
    attrs = ds["validity"].attrs
    masks = [int(m) for m in np.atleast_1d(attrs.get("flag_masks", []))]
    meanings = str(attrs.get("flag_meanings", "")).split()
    named = [f"{m} {n}" for m, n in zip(masks, meanings) if bits & m]
    return ", ".join(named) if named else f"validity {bits}"


# ---------------------------------------------------------------------------- flagged designs
def _valid(ds, **sel):
    """Where the designs of ``ds`` (sliced by ``sel``) carry no validity flag: a bool
    DataArray (all True for a cube without ``validity``)."""
    if "validity" not in ds:
        return None
    v = ds["validity"].sel(**sel) if sel else ds["validity"]
    return v.fillna(0) == 0


def _valid_range(ds, name, **sel):
    """``(lo, hi)`` of ``name`` in display units over the valid designs of the whole cube
    (or its slice ``sel`` along a dimension a chart draws one figure per value of, the
    model): a chart's colour scale is the same for every slice of one cube, and a flagged
    design (``validity`` != 0) never sets it. ``(nan, nan)`` where no design is finite."""
    da = ds[name].sel(**sel) if sel else ds[name]
    ok = _valid(ds, **sel)
    if ok is not None:
        da = da.where(ok.broadcast_like(da) if set(ok.dims) <= set(da.dims) else ok)
    values = np.asarray(to_display(name, da.values), float)
    if not np.isfinite(values).any():
        return math.nan, math.nan
    return float(np.nanmin(values)), float(np.nanmax(values))


def _coil_colour(ds, c):
    """The colour of coil index ``c`` [-]: by its place on the cube's axis, so a coil index
    keeps its colour whichever coil indices a chart is asked for (``--coil-index``)."""
    values = np.asarray(ds["coil_index"].values, float)
    k = int(np.argmin(np.abs(values - float(c))))
    return _COLOURS[k % len(_COLOURS)]


def _flag_patch(ds, bits):
    """The legend entry of flagged designs (grey, hatched), naming the flags set in
    ``bits``."""
    from matplotlib.patches import Patch

    return Patch(fc=_FLAG_FILL, ec="k", hatch="\\\\",
                 label=f"flagged design: {_flag_text(ds, bits)} (grey, hatched, off the "
                       "colour scale)")


def _grey_flagged(ax, x, y, valid, values):
    """Grey out the flagged cells of a map panel (``x`` across, ``y`` up, ``values`` [display
    units] over (y, x), ``valid`` their validity bits, 0 clean, or None).

    Each flagged cell (``validity`` != 0) is covered by an opaque grey hatched cell, and
    its value is replaced by its nearest clean neighbour's, so that a filled contour of the
    returned values never takes a flagged design's value: no flagged design shows in a
    colour of the scale, nor does the interpolation beside it. Returns ``(values to
    contour, OR of the flag bits)``; ``(values, 0)`` where nothing is flagged.
    """
    if valid is None:
        return values, 0
    bits_arr = np.nan_to_num(np.asarray(valid, float)).astype(int)
    bad = bits_arr != 0
    if not bad.any():
        return values, 0
    from matplotlib.collections import PolyCollection
    from scipy.ndimage import distance_transform_edt

    filled = np.array(values, float)
    if (~bad).any():
        near = distance_transform_edt(bad, return_distances=False, return_indices=True)
        filled = filled[tuple(near)]
    else:
        filled[:] = np.nan
    ex, ey = _cell_edges(x), _cell_edges(y)
    rows, cols = np.nonzero(bad)
    cells = [[(ex[c], ey[r]), (ex[c + 1], ey[r]), (ex[c + 1], ey[r + 1]), (ex[c], ey[r + 1])]
             for r, c in zip(rows, cols)]
    ax.add_collection(PolyCollection(cells, facecolors=[_FLAG_FILL[:3]], edgecolors="0.35",
                                     linewidths=0.0, hatch="\\\\", zorder=2.5,
                                     gid="nf-flagged"))
    if len(x) > 1 and len(y) > 1:  # the span of the grid, as a filled contour has it
        ax.set_xlim(min(x), max(x))
        ax.set_ylim(min(y), max(y))
    return filled, int(np.bitwise_or.reduce(bits_arr[bad]))


def _cell_edges(x):
    """Edges of the cells centred on the grid values ``x`` (halfway between neighbours)."""
    x = np.asarray(x, float)
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = (x[1:] + x[:-1]) / 2
    return np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])
