"""Design charts drawn from a saved cube: the paper's figures 4, 6, 7 and 12, and a design map.

Charts read the :class:`xarray.Dataset` only; they never compute physics. Every axis label
comes from the variable registry (:mod:`nylonflex.variables`) in the unit a designer reads
(mm, deg, kPa, N), and every title names the slice of the cube it shows. matplotlib is
imported lazily with the headless Agg backend (after ``xarray/plot/utils.py``).

Each chart is a function ``f(ds, **slice) -> matplotlib.figure.Figure``; the keyword
arguments choose the slice in SI (default: the grid values nearest the paper's choices), and
:func:`draw_charts` passes a slice (``at``, ``coil_index``) to every chart that draws along
it (``nylonflex chart CUBE --at length=70mm,wrap_angle=8deg --coil-index 1.1,1.7``).
Subtitles are written from the values drawn; the paper's worked examples are marked only
where the slice holds them exactly, with the cube's values there.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .config import CHARTS as _CHART_NAMES
from .units import InputError
from .variables import VARIABLES, display_label, quantile_name, to_display

__all__ = ["CHARTS", "FORMATS", "SLICE_AXES", "chart_slice", "design_map", "draw_charts",
           "feasibility_map", "fig4", "fig6",
           "fig7", "fig12a", "fig12b", "fig12c"]

#: Image formats a chart can be written in.
FORMATS = ("png", "pdf", "svg")

# Colours of the Okabe-Ito palette (readable for colour-blind readers and in greyscale).
_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
            "#000000")
# Dash patterns of the strength limits, one per wrap angle; all black as in the paper.
_DASHES = ((0, (6, 2)), (0, (3, 1.5)), (0, (1, 1.2)), (0, (6, 1.5, 1, 1.5)),
           (0, (10, 3)), (0, (2, 3)))

_RC = {"font.size": 10, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 8.5,
       "legend.title_fontsize": 8.5, "xtick.labelsize": 9, "ytick.labelsize": 9,
       "figure.titlesize": 11, "axes.grid": True, "grid.alpha": 0.3, "lines.linewidth": 1.6,
       "savefig.dpi": 200, "svg.fonttype": "none", "pdf.fonttype": 42}

# The paper's worked examples (section 4), SI: (radius, wall, length, coil index).
_EXAMPLES = ((20e-3, 6e-3, 90e-3, 1.1), (7.5e-3, 2e-3, 70e-3, 1.7))
_WRAP_DEFAULT = math.radians(8.0)  # docs/model.md s. 8 checks the examples at psi = 8 deg
_LENGTH_DEFAULT = 90e-3


# ---------------------------------------------------------------------------- helpers
def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _figure(nrows=1, ncols=1, size=(6.0, 4.2), **kw):
    plt = _plt()
    with plt.rc_context(_RC):
        fig, axes = plt.subplots(nrows, ncols, figsize=size, layout="constrained",
                                 squeeze=False, **kw)
    return fig, axes




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


def _label(name, unit_note=""):
    return display_label(name) + unit_note


def _footer(fig, ds):
    name = ds.attrs.get("name", "?")
    version = ds.attrs.get("nylonflex_version", "?")
    note = f"cube '{name}' (nylonflex {version}, {ds.attrs.get('silicone', '?')} / " \
           f"{ds.attrs.get('nylon', '?')})"
    if ds.attrs.get("complete") != "true":
        note += " - INCOMPLETE cube: missing radii are blank"
    # above the canvas (savefig's tight bounding box takes it in): clear of titles,
    # axes and legends whatever the layout
    fig.text(0.0, 1.0, note, ha="left", va="bottom", fontsize=7, color="0.4")


def _suptitle(fig, title, subtitle):
    fig.suptitle(f"{title}\n{subtitle}", fontsize=_RC["figure.titlesize"])


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


# ---------------------------------------------------------------------------- figure 12
def fig12a(ds, *, radii=None, walls=None, wrap_angle=None, wrap_angles=None,
           radius=None, wall_thickness=None, coil_index=None):
    """Figure 12(a): nylon force against stroke, with each coil index's strength limit.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    radii, walls : sequence of float, optional
        Radii and wall thicknesses of the left panel [m]; default five radii over the
        grid and the walls nearest 2 and 6 mm.
    wrap_angle : float, optional
        Wrap angle of the left panel [rad]; default nearest 8 deg.
    wrap_angles : sequence of float, optional
        Wrap angles of the right panel [rad]; default up to four over the grid.
    radius, wall_thickness : float, optional
        Design of the right panel [m]; default nearest 15 mm and 4 mm.
    coil_index : float or sequence of float, optional
        Coil indices whose strength limits are drawn [-]; default every one of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    radii = [_nearest(ds, "radius", r) for r in radii] if radii else \
        _pick_few(ds, "radius", 5)
    walls = _example_walls(ds, walls)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    psis = [_nearest(ds, "wrap_angle", w) for w in wrap_angles] if wrap_angles else \
        _pick_few(ds, "wrap_angle", 4)
    a_r = _nearest(ds, "radius", 15e-3 if radius is None else radius)
    t_r = _nearest(ds, "wall_thickness", 4e-3 if wall_thickness is None else wall_thickness)

    # F_n does not depend on the coil index (docs/model.md s. 4): read it at the first one
    force = ds["nylon_force"].isel(coil_index=0)
    stroke = to_display("stroke", ds["stroke"].values)
    f_lim = to_display("nylon_force_limit", ds["nylon_force_limit"].values)
    s_max = _stroke_max(ds)
    chosen = _coils(ds, coil_index)
    keep = [k for k, c in enumerate(ds["coil_index"].values) if float(c) in chosen]
    coils, f_lim, s_max = ds["coil_index"].values[keep], f_lim[keep], s_max[keep]

    from matplotlib.lines import Line2D

    fig, axes = _figure(1, 2, size=(9.0, 5.4), sharey=True)
    left, right = axes[0]
    styles = ("-", "-.", ":", (0, (5, 1, 1, 1, 1, 1)))
    for i, a in enumerate(radii):
        for j, t in enumerate(walls):
            y = force.sel(radius=a, wall_thickness=t, wrap_angle=psi).values
            left.plot(stroke, to_display("nylon_force", y), color=_COLOURS[i % len(_COLOURS)],
                      ls=styles[j % len(styles)])
    left.set_title(f"radius and wall at {_eq('wrap_angle', psi)}")
    for i, w in enumerate(psis):
        y = force.sel(radius=a_r, wall_thickness=t_r, wrap_angle=w).values
        right.plot(stroke, to_display("nylon_force", y), color=_COLOURS[i % len(_COLOURS)],
                   label=_eq("wrap_angle", w))
    right.set_title(f"wrap angle at {_eq('radius', a_r)}, {_eq('wall_thickness', t_r)}")

    # Each coil index's working box: F_n <= F_lim(C) up to s <= s_max(C), dashed black.
    top = max(float(np.nanmax(f_lim)) * 1.3, 1e-9)
    for ax in (left, right):
        for k, c in enumerate(coils):
            end = s_max[k] if np.isfinite(s_max[k]) else stroke[-1]
            ax.plot([stroke[0], end], [f_lim[k]] * 2, color="k", ls="--", lw=1.1)
            if np.isfinite(s_max[k]):
                ax.plot([end, end], [0, f_lim[k]], color="k", ls=":", lw=0.9)
            ax.annotate(f"C = {c:g}", (end, f_lim[k]), xytext=(-2, 2),
                        textcoords="offset points", fontsize=8, ha="right", va="bottom",
                        bbox={"boxstyle": "square,pad=0.05", "fc": "white", "ec": "none",
                              "alpha": 0.8})
        ax.set_xlim(stroke[0], stroke[-1])
        ax.set_ylim(0, top)
        ax.set_xlabel(_label("stroke", " [-]"))
    left.set_ylabel(_label("nylon_force"))
    handles = [Line2D([], [], color=_COLOURS[i % len(_COLOURS)], label=_eq("radius", a))
               for i, a in enumerate(radii)]
    handles += [Line2D([], [], color="0.3", ls=styles[j % len(styles)],
                       label=_eq("wall_thickness", t)) for j, t in enumerate(walls)]
    # two columns each: a legend wider than its panel would run into its neighbour's
    left.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2,
                fontsize=8)
    right.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=8)
    _suptitle(fig, "Figure 12(a): nylon force against muscle stroke",
              "dashed: each coil index's strength limit F_lim(C) up to its largest stroke "
              "s_max(C) (dotted)\nthe force is the same for every coil index and length")
    _footer(fig, ds)
    return fig


def _cut_ins(ds, var, sel, coils, psis):
    """Where each wrap angle's strength limit cuts in, per coil index.

    Returns ``{psi: [(radius, value) of the last grid design with a full range of motion,
    one per coil index that reaches its limit inside the grid]}`` in display units.
    """
    x = to_display("radius", ds["radius"].values)
    out = {}
    for w in psis:
        points = []
        for c in coils:
            cut = ds[[var, "limit"]].sel(coil_index=c, wrap_angle=w, **sel)
            lim = cut["limit"].values
            value = to_display(var, cut[var].values)
            hits = np.flatnonzero((lim[:-1] == 0) & (lim[1:] == 1))
            if hits.size:
                points.append((x[hits[0]], value[hits[0]]))
        out[w] = points
    return out


def _limit_lines(ax, ds, var, sel, coils, psis):
    """Fig. 12(b,c) panel: ``var`` against radius per coil index (solid while
    stroke-limited) and each wrap angle's threshold (dashed black) through the last
    designs with a full range of motion."""
    x = to_display("radius", ds["radius"].values)
    # read the panel's slice once (a large cube's chunks span every coil and wrap angle)
    ds = ds[[var, "limit"]].sel(**sel).load()
    sel = {}
    for k, c in enumerate(coils):
        cut = ds[[var, "limit"]].sel(coil_index=c, **sel)
        value = to_display(var, cut[var].transpose("wrap_angle", "radius").values)
        stroke_limited = cut["limit"].transpose("wrap_angle", "radius").values == 0
        # stroke-limited values are the same for every wrap angle (s* = s_max(C))
        solid = np.where(stroke_limited.any(axis=0), np.nanmax(
            np.where(stroke_limited, value, -np.inf), axis=0), np.nan)
        ax.plot(x, solid, color=_COLOURS[k % len(_COLOURS)], lw=2.0, zorder=3)
    shown = _labelled_psis(psis)
    annotate = len(shown) <= 4  # more labels than that overprint: the legend names them
    for w, points in _cut_ins(ds, var, sel, coils, psis).items():
        if not points:
            continue
        px, py = np.array(points).T
        if w not in shown:  # the rest: faint context, unlabelled
            ax.plot(px, py, color="0.75", lw=0.7, zorder=2)
            continue
        j = shown.index(w)
        ax.plot(px, py, color=_psi_colour(j, len(shown)), ls=_DASHES[j % len(_DASHES)],
                lw=1.4, marker="o", ms=4, mfc="white",
                mec=_psi_colour(j, len(shown)), zorder=4)
        if annotate:
            end = int(np.argmax(px))
            ax.annotate(f"\u03c8 = {_text('wrap_angle', w)}", (px[end], py[end]),
                        xytext=(4, -2), textcoords="offset points", fontsize=8,
                        ha="left", va="top", zorder=6,
                        bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none",
                              "alpha": 0.8})
    ax.set_xlabel(_label("radius"))


def _legend_12bc(fig, coils, psis):
    from matplotlib.lines import Line2D

    shown = _labelled_psis(psis)
    handles = [Line2D([], [], color=_COLOURS[k % len(_COLOURS)], lw=2.0,
                      label=f"C = {c:g}") for k, c in enumerate(coils)]
    handles += [Line2D([], [], color=_psi_colour(j, len(shown)),
                       ls=_DASHES[j % len(_DASHES)], lw=1.4, marker="o", ms=4, mfc="white",
                       mec=_psi_colour(j, len(shown)),
                       label=f"\u03c8 = {_text('wrap_angle', w)}")
                for j, w in enumerate(shown)]
    note = ""
    if len(shown) < len(psis):
        handles.append(Line2D([], [], color="0.75", lw=0.7,
                              label=f"the other {len(psis) - len(shown)} wrap angles"))
        note = f" ({len(shown)} of {len(psis)} labelled)"
    fig.legend(handles=handles, loc="outside lower center",
               ncol=min(6, max(len(coils), len(shown) + (len(shown) < len(psis)))),
               title="coil index C: solid while the design has its full range of motion "
                     f"(stroke-limited)\nwrap angle \u03c8{note}: dashed threshold through "
                     "the last full-range design of each C; beyond it the nylon's strength "
                     "limits")


def _examples(ax, ds, var, t, length=None, corner="upper left", coils=None):
    """Mark the paper's worked examples (section 4) on a fig. 12(b,c) panel of wall ``t``.

    An example is marked only where the cube holds its design exactly (every value a grid
    value; the panel's wall, and ``length`` [m] for a length-dependent ``var``, equal to
    the example's; its coil index among ``coils``), with the cube's values there. None for
    ``length`` (a length-free ``var``) adds the example's own tip force to the label.
    """
    texts = []
    for example in _EXAMPLES:
        at = _example_point(ds, example, wall_thickness=t, length=length)
        if at is None or (coils is not None and at["coil_index"] not in coils):
            continue
        point = ds[[var, "tip_force_max", "limit"]].sel(**at)
        x, y = float(to_display("radius", at["radius"])), float(to_display(var, point[var]))
        if not np.isfinite(y):  # an incomplete cube without this design
            continue
        ax.plot(x, y, "*", ms=13, mfc="gold", mec="k", zorder=7)
        unit = VARIABLES[var].display
        text = f"paper example: {_eq('radius', at['radius'])}, " \
               f"{_eq('coil_index', at['coil_index'])}, {_eq('wrap_angle', at['wrap_angle'])}" \
               f"\n{VARIABLES[var].long_name} {y:.3g} {unit}"
        full = "full range of motion" if int(point["limit"]) == 0 else \
            "range of motion cut short"
        if length is None:
            text += f"\nat {_eq('length', at['length'])} tip force " \
                    f"{float(point['tip_force_max']):.3g} N, {full}"
        else:
            text += f", {full}"
        texts.append(text)
        # an empty corner of the panel (fig. 12(b): curves rise to the right)
        upper, left = corner.split()[0] == "upper", corner.split()[1] == "left"
        step = 0.14 * (len(texts) - 1)
        ax.annotate(text, (x, y),
                    xytext=(0.03 if left else 0.97, 0.97 - step if upper else 0.03 + step),
                    textcoords="axes fraction", ha="left" if left else "right",
                    va="top" if upper else "bottom", fontsize=8, zorder=7,
                    arrowprops={"arrowstyle": "->", "color": "0.3", "lw": 0.8,
                                "shrinkB": 6},
                    bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": "0.6"})


def _psis(ds, wrap_angle=None):
    if wrap_angle is None:
        return [float(w) for w in ds["wrap_angle"].values]
    return [_nearest(ds, "wrap_angle", w) for w in np.atleast_1d(wrap_angle)]


def _example_walls(ds, walls):
    if walls:
        return [_nearest(ds, "wall_thickness", t) for t in walls]
    # the walls of the paper's two examples: 2 mm and 6 mm
    return sorted({_nearest(ds, "wall_thickness", t) for t in (2e-3, 6e-3)})


def fig12b(ds, *, walls=None, length=None, wrap_angle=None, coil_index=None):
    """Figure 12(b): maximum torque against radius, per coil index, with strength limits.

    The solid line of each coil index is its torque M* while the design is stroke-limited
    (the muscle's whole stroke is usable); each wrap angle's dashed black threshold joins
    the last such design of every coil index: beyond it the nylon's strength limits.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    walls : sequence of float, optional
        Wall thicknesses, one panel each [m]; default nearest 2 and 6 mm.
    length : float, optional
        Length at which M* is read [m] (M* does not depend on it); default nearest 90 mm.
    wrap_angle : float or sequence of float, optional
        Wrap angles whose thresholds are drawn [rad]; default every one of the cube (up to
        six labelled, the rest faint).
    coil_index : float or sequence of float, optional
        Coil indices drawn [-]; default every one of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    walls = _example_walls(ds, walls)
    length = _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length)
    coils = _coils(ds, coil_index)
    psis = _psis(ds, wrap_angle)
    fig, axes = _figure(1, len(walls), size=(4.4 * len(walls) + 0.4, 5.4))
    for ax, t in zip(axes[0], walls):
        _limit_lines(ax, ds, "torque_max", {"wall_thickness": t, "length": length},
                     coils, psis)
        _quantile_bands(ax, ds, "torque_max", {"wall_thickness": t, "length": length},
                        coils)
        _examples(ax, ds, "torque_max", t, coils=coils)
        ax.set_title(f"wall thickness {_eq('wall_thickness', t)}")
        ax.set_ylabel(_label("torque_max"))
        ax.set_ylim(bottom=0)
    _legend_12bc(fig, coils, psis)
    _suptitle(fig, "Figure 12(b): maximum torque against actuator radius",
              "any length (M* does not depend on L; tip force = M*/L)")
    _footer(fig, ds)
    return fig


def fig12c(ds, *, walls=None, length=None, wrap_angle=None, coil_index=None):
    """Figure 12(c): maximum bend angle and range of motion against radius.

    Top row: the maximum free bend angle theta* per coil index, solid while the design has
    its full range of motion, with each wrap angle's threshold dashed (as figure 12(b)).
    Bottom row: the range of motion theta*/theta(s_max) [%] at one wrap angle; it falls
    below 100 % where the nylon's strength cuts the bend short.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    walls : sequence of float, optional
        Wall thicknesses, one column each [m]; default nearest 2 and 6 mm.
    length : float, optional
        Actuator length [m] (theta* grows in proportion); default nearest 90 mm.
    wrap_angle : float, optional
        Wrap angle of the bottom row [rad] (and the only threshold drawn on the top row when
        given); default nearest 8 deg, every wrap angle's threshold on top.
    coil_index : float or sequence of float, optional
        Coil indices drawn [-]; default every one of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    walls = _example_walls(ds, walls)
    length = _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    coils = _coils(ds, coil_index)
    psis = _psis(ds, wrap_angle)
    fig, axes = _figure(2, len(walls), size=(4.4 * len(walls) + 0.4, 7.6), sharex=True,
                        height_ratios=(3, 2))
    x = to_display("radius", ds["radius"].values)
    for col, t in enumerate(walls):
        sel = {"wall_thickness": t, "length": length}
        top, bottom = axes[0][col], axes[1][col]
        _limit_lines(top, ds, "bend_angle_max", sel, coils, psis)
        _quantile_bands(top, ds, "bend_angle_max", sel, coils, psi, note_at=(0.02, 0.98))
        _examples(top, ds, "bend_angle_max", t, length, corner="lower right", coils=coils)
        top.set_title(f"wall thickness {_eq('wall_thickness', t)}")
        top.set_xlabel("")
        top.set_ylabel(_label("bend_angle_max"))
        top.set_ylim(bottom=0)
        fraction = ds["range_fraction"].sel(wrap_angle=psi, **sel).load()
        for k, c in enumerate(coils):
            rf = fraction.sel(coil_index=c).values
            bottom.plot(x, 100 * rf, color=_COLOURS[k % len(_COLOURS)], lw=1.8)
        bottom.set_title(f"range of motion at {_eq('wrap_angle', psi)} "
                         "(100 % = full range)")
        bottom.set_xlabel(_label("radius"))
        bottom.set_ylabel("range of motion [%]")
        bottom.set_ylim(0, 105)
    _legend_12bc(fig, coils, psis)
    _suptitle(fig, "Figure 12(c): maximum bend angle (range of motion) against radius",
              f"{_eq('length', length)} (the angle grows in proportion to L; "
              "the range fraction does not)")
    _footer(fig, ds)
    return fig


# ---------------------------------------------------------------------------- figures 4-7
def fig4(ds, *, coil_index=None):
    """Figure 4: chamber pressure against muscle stroke, with each coil index's s_max.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    coil_index : float or sequence of float, optional
        Coil indices whose largest stroke is marked [-]; default every one of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = _figure(1, 1, size=(5.6, 4.3))
    ax = axes[0][0]
    stroke = to_display("stroke", ds["stroke"].values)
    p = to_display("chamber_pressure", ds["chamber_pressure"].values)
    ax.plot(stroke, p, color=_COLOURS[0], lw=2.0, label="p(s), Boyle's law")
    s_max = _stroke_max(ds)
    chosen = _coils(ds, coil_index)
    for k, c in enumerate(ds["coil_index"].values):
        if not np.isfinite(s_max[k]) or float(c) not in chosen:
            continue
        p_k = float(np.interp(s_max[k], ds["stroke"].values, p))  # reading the curve
        ax.plot([s_max[k]] * 2, [0, p_k], color="k", ls=":", lw=0.9)
        ax.plot(s_max[k], p_k, "o", color=_COLOURS[(k + 1) % len(_COLOURS)], ms=6,
                mec="k", label=f"largest stroke of C = {c:g}: s_max = {s_max[k]:.3f}, "
                               f"p = {p_k:.3g} {VARIABLES['pressure'].display}")
    ax.set_xlim(stroke[0], stroke[-1])
    ax.set_ylim(bottom=0)
    ax.set_xlabel(_label("stroke", " [-]"))
    ax.set_ylabel(_label("chamber_pressure"))
    ax.legend(loc="upper left")
    _suptitle(fig, "Figure 4: chamber pressure against muscle stroke",
              "sealed air chamber, same for every design")
    _footer(fig, ds)
    return fig


def _curve_panel(ax, ds, var, name, values, fixed):
    pressure = to_display("pressure", ds["pressure"].values)
    for i, v in enumerate(values):
        y = ds[var].sel({name: v, **fixed}).values
        ax.plot(pressure, to_display(var, y), color=_COLOURS[i % len(_COLOURS)],
                label=_eq(name, v))
    ax.set_xlim(pressure[0], pressure[-1])
    ax.set_ylim(bottom=0)
    ax.set_xlabel(_label("pressure"))
    ax.set_ylabel(_label(var))
    ax.set_title(", ".join(_eq(k, v) for k, v in fixed.items()))
    ax.legend(loc="upper left", title=VARIABLES[name].long_name)


def _held_design(ds, radius, wall_thickness, length):
    """The grid design nearest (a, t, L) [m], by default 10 mm, 2 mm, 90 mm."""
    return (_nearest(ds, "radius", 10e-3 if radius is None else radius),
            _nearest(ds, "wall_thickness", 2e-3 if wall_thickness is None else wall_thickness),
            _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length))


def fig6(ds, *, radius=None, wall_thickness=None, length=None):
    """Figure 6(b, c): bend angle against pressure, varying radius and wall thickness.

    The paper shows radius 6-14 mm and wall 1-4 mm; the cube's grid values in those spans
    are drawn (the nearest ones where none lies inside), and the subtitle says which.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    radius : float, optional
        Radius of the wall panel [m]; default nearest 10 mm.
    wall_thickness : float, optional
        Wall of the radius panel [m]; default nearest 2 mm.
    length : float, optional
        Actuator length [m]; default nearest 90 mm.

    Returns
    -------
    matplotlib.figure.Figure
    """
    a, t, length = _held_design(ds, radius, wall_thickness, length)
    fig, axes = _figure(1, 2, size=(9.0, 4.2))
    radii = _spread(ds, "radius", 6e-3, 14e-3, 5)
    walls = _spread(ds, "wall_thickness", 1e-3, 4e-3, 5)
    _curve_panel(axes[0][0], ds, "bend_angle", "radius", radii,
                 {"wall_thickness": t, "length": length})
    _curve_panel(axes[0][1], ds, "bend_angle", "wall_thickness", walls,
                 {"radius": a, "length": length})
    _suptitle(fig, "Figure 6: bend angle against chamber pressure",
              f"(b) radius {_range_text('radius', radii)}, (c) wall thickness "
              f"{_range_text('wall_thickness', walls)}; free bending")
    _footer(fig, ds)
    return fig


def fig7(ds, *, radius=None, wall_thickness=None, length=None):
    """Figure 7: blocked tip force against pressure, varying radius, wall and length.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    radius, wall_thickness, length : float, optional
        The design the other panels hold fixed [m]; default nearest 10, 2 and 90 mm.

    Returns
    -------
    matplotlib.figure.Figure
    """
    a, t, length = _held_design(ds, radius, wall_thickness, length)
    fig, axes = _figure(1, 3, size=(11.0, 4.0), sharey=True)
    _curve_panel(axes[0][0], ds, "tip_force", "radius", _spread(ds, "radius", 6e-3, 14e-3, 5),
                 {"wall_thickness": t, "length": length})
    _curve_panel(axes[0][1], ds, "tip_force", "wall_thickness",
                 _pick_few(ds, "wall_thickness", 6), {"radius": a, "length": length})
    _curve_panel(axes[0][2], ds, "tip_force", "length", _pick_few(ds, "length", 5),
                 {"radius": a, "wall_thickness": t})
    for ax in axes[0][1:]:
        ax.set_ylabel("")
    _suptitle(fig, "Figure 7: blocked tip force against chamber pressure",
              "actuator held straight; each panel varies one dimension")
    _footer(fig, ds)
    return fig


# ---------------------------------------------------------------------------- design map
def design_map(ds, *, length=None, wrap_angle=None, coil_index=None):
    """Maximum tip force over radius and wall thickness, strength-limited region hatched.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    length : float, optional
        Actuator length [m]; default nearest 90 mm.
    wrap_angle : float, optional
        Wrap angle [rad]; default nearest 8 deg.
    coil_index : float or sequence of float, optional
        Coil index of each panel [-]; default every coil index of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.patches import Patch

    plt = _plt()
    length = _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    coils = _coils(ds, coil_index)
    ncols = min(3, len(coils)) if len(coils) != 4 else 2
    nrows = math.ceil(len(coils) / ncols)
    fig, axes = _figure(nrows, ncols, size=(4.4 * ncols + 1.0, 3.6 * nrows + 1.0),
                        sharex=True, sharey=True)
    cut = ds[["tip_force_max", "limit"]].sel(length=length, wrap_angle=psi).load()
    force = to_display("tip_force_max", cut["tip_force_max"].sel(coil_index=coils).values)
    top = float(np.nanmax(force)) if np.isfinite(force).any() else 1.0
    levels = _nice_levels(top)
    x = to_display("radius", ds["radius"].values)
    y = to_display("wall_thickness", ds["wall_thickness"].values)
    mappable = None
    for i, ax in enumerate(axes.flat):
        if i >= len(coils):
            ax.set_visible(False)
            continue
        c = coils[i]
        f = to_display("tip_force_max", cut["tip_force_max"].sel(coil_index=c)
                  .transpose("wall_thickness", "radius").values)
        lim = cut["limit"].sel(coil_index=c).transpose("wall_thickness", "radius").values
        mappable = ax.contourf(x, y, f, levels=levels, cmap="viridis", extend="max")
        lines = ax.contour(x, y, f, levels=levels[2::2], colors="white", linewidths=0.6)
        ax.clabel(lines, fmt="%g N", fontsize=7.5)
        strength = np.where(np.isnan(lim), np.nan, (lim == 1).astype(float))
        if np.nanmax(np.nan_to_num(strength)) > 0:
            with plt.rc_context({"hatch.color": "white", "hatch.linewidth": 0.8}):
                ax.contourf(x, y, strength, levels=[0.5, 1.5], colors="none",
                            hatches=["///"])
            ax.contour(x, y, strength, levels=[0.5], colors="k", linewidths=1.6)
        for example in _map_examples(ds, length, psi, c):
            ax.plot(to_display("radius", example[0]),
                    to_display("wall_thickness", example[1]), "*", ms=13, mfc="gold",
                    mec="k", zorder=6, clip_on=False)  # inside the map: stretches nothing
        ax.set_title(_eq("coil_index", c))
        ax.grid(False)
        if i % ncols == 0:
            ax.set_ylabel(_label("wall_thickness"))
        if i >= len(coils) - ncols:
            ax.set_xlabel(_label("radius"))
    fig.colorbar(mappable, ax=axes, label=_label("tip_force_max"), shrink=0.9)
    handles = [Patch(fc="#2a788e", ec="white", hatch="///",
                     label="strength-limited: nylon breaks first, range of motion cut short"),
               Patch(fc="#2a788e", ec="none", label="stroke-limited: full range of motion")]
    if any(_map_examples(ds, length, psi, c) for c in coils):
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], ls="", marker="*", ms=10, mfc="gold", mec="k",
                              label="paper's worked example"))
    fig.legend(handles=handles, loc="outside lower center", ncol=2, fontsize=8)
    _suptitle(fig, "Design map: maximum tip force over radius and wall thickness",
              f"slice {_eq('length', length)}, {_eq('wrap_angle', psi)}; "
              "one panel per coil index")
    _footer(fig, ds)
    return fig


def _map_examples(ds, length, psi, coil):
    """The paper's examples a design-map panel holds: its length, wrap angle (8 deg) and
    coil index on the grid and equal to the panel's, radius and wall inside the map."""
    out = []
    for example in _EXAMPLES:
        a, t, l_ex, c_ex = example
        fixed = {"length": _grid_value(ds, "length", l_ex),
                 "coil_index": _grid_value(ds, "coil_index", c_ex),
                 "wrap_angle": _grid_value(ds, "wrap_angle", _WRAP_DEFAULT)}
        if any(v is None for v in fixed.values()):
            continue
        if (abs(fixed["length"] - length) > 1e-12 or abs(fixed["coil_index"] - coil) > 1e-12
                or abs(fixed["wrap_angle"] - psi) > 1e-12):
            continue
        inside = all(float(ds[n].min()) <= v <= float(ds[n].max())
                     for n, v in (("radius", a), ("wall_thickness", t)))
        if inside:
            out.append(example)
    return out


def _nice_levels(top):
    """About ten round contour levels from 0 to ``top``."""
    raw = top / 10
    mag = 10 ** math.floor(math.log10(raw)) if raw > 0 else 1.0
    step = min((s * mag for s in (1, 2, 2.5, 5, 10) if s * mag >= raw), default=raw)
    return np.arange(0, top + step, step)


# ---------------------------------------------------------------------------- uncertainty
def _band_levels(ds):
    """Indices of the outermost quantiles (5 and 95 % by default) of a sampled cube."""
    q = ds["quantile"].values
    return int(np.argmin(q)), int(np.argmax(q)), q


def _quantile_bands(ax, ds, var, sel, coils, wrap_angle=None, note_at=(0.99, 0.01)):
    """Shade each coil index's band between the cube's lowest and highest quantile of
    ``var`` (a cube with ``uncertainty``; nothing otherwise), at ``wrap_angle`` (default
    nearest 8 deg)."""
    qname = quantile_name(var)
    if qname not in ds or "quantile" not in ds.coords:
        return
    lo, hi, q = _band_levels(ds)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    x = to_display("radius", ds["radius"].values)
    for k, c in enumerate(coils):
        cut = ds[qname].sel(coil_index=c, wrap_angle=psi, **sel).transpose("quantile",
                                                                           "radius").values
        ax.fill_between(x, to_display(var, cut[lo]), to_display(var, cut[hi]),
                        color=_COLOURS[k % len(_COLOURS)], alpha=0.18, lw=0, zorder=2)
    ax.text(*note_at, f"bands: {100 * q[lo]:g}-{100 * q[hi]:g} % at "
            f"{_eq('wrap_angle', psi)}", transform=ax.transAxes,
            ha="right" if note_at[0] > 0.5 else "left",
            va="bottom" if note_at[1] < 0.5 else "top", fontsize=7.5, color="0.3", zorder=8,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})


def feasibility_map(ds, *, length=None, wrap_angle=None, coil_index=None):
    """Probability that every requirement holds, over radius and wall thickness.

    Filled contours of ``feasibility`` with lines at 50 % and 90 %, one panel per coil
    index, at one length and wrap angle (a cube swept with ``requirements``).

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube with ``feasibility``.
    length : float, optional
        Actuator length [m]; default nearest 90 mm.
    wrap_angle : float, optional
        Wrap angle [rad]; default nearest 8 deg.
    coil_index : float or sequence of float, optional
        Coil index of each panel [-]; default every coil index of the cube (up to four).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if "feasibility" not in ds:
        raise InputError("feasibility_map: the cube has no 'feasibility'; sweep a config "
                         "with 'requirements'")
    length = _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    coils = _pick_few(ds, "coil_index", 4) if coil_index is None else \
        [_nearest(ds, "coil_index", c) for c in np.atleast_1d(coil_index)]
    ncols = 1 if len(coils) == 1 else 2
    nrows = math.ceil(len(coils) / ncols)
    fig, axes = _figure(nrows, ncols, size=(4.4 * ncols + 1.0, 3.6 * nrows + 1.0),
                        sharex=True, sharey=True)
    cut = ds["feasibility"].sel(length=length, wrap_angle=psi)
    x = to_display("radius", ds["radius"].values)
    y = to_display("wall_thickness", ds["wall_thickness"].values)
    levels = np.linspace(0.0, 1.0, 11)
    mappable = None
    for i, ax in enumerate(axes.flat):
        if i >= len(coils):
            ax.set_visible(False)
            continue
        c = coils[i]
        p = cut.sel(coil_index=c).transpose("wall_thickness", "radius").values
        mappable = ax.contourf(x, y, p, levels=levels, cmap="RdYlGn", vmin=0, vmax=1)
        if np.nanmax(p) > 0.5 > np.nanmin(p) or np.nanmax(p) > 0.9 > np.nanmin(p):
            lines = ax.contour(x, y, p, levels=[0.5, 0.9], colors="k",
                               linewidths=[0.9, 1.6], linestyles=["--", "-"])
            ax.clabel(lines, fmt=lambda v: f"{100 * v:.0f} %", fontsize=7.5)
        ax.set_title(_eq("coil_index", c))
        ax.grid(False)
        if i % ncols == 0:
            ax.set_ylabel(_label("wall_thickness"))
        if i >= len(coils) - ncols:
            ax.set_xlabel(_label("radius"))
    fig.colorbar(mappable, ax=axes, label=_label("feasibility"), shrink=0.9,
                 ticks=np.linspace(0, 1, 6))
    reqs = ds.attrs.get("requirements", "?")
    samples = ds.attrs.get("uncertainty_samples")
    how = f"{samples} samples" if samples else "nominal designs (no uncertainty)"
    _suptitle(fig, "Feasibility: probability that every requirement holds",
              f"{reqs}; {how}\nslice {_eq('length', length)}, {_eq('wrap_angle', psi)}; "
              "lines at 50 % (dashed) and 90 %")
    _footer(fig, ds)
    return fig


# ---------------------------------------------------------------------------- drivers
#: Chart name -> function, the names a config's ``charts`` list accepts.
def compare(ds, *, variable="tip_force_max"):
    """``variable`` against radius for every model, at the paper's first example's slice.

    Wall 6 mm, length 90 mm, C 1.1, psi 8 deg (the nearest grid values); a cross marks a
    flagged design (``validity`` != 0, docs/model.md s. 17). docs/model.md s. 16.
    """
    import numpy as np

    at = {name: _nearest(ds, name, v) for name, v in (("wall_thickness", 6e-3),
                                                      ("length", 90e-3), ("coil_index", 1.1),
                                                      ("wrap_angle", 8 * np.pi / 180))}
    cut = ds[[variable, "validity"]].sel(**at)
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else \
        [str(ds.attrs.get("models", "paper"))]
    fig, axes = _figure()
    ax = axes[0, 0]
    styles = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]
    r = to_display("radius", ds["radius"].values)
    flagged_any = False
    for k, m in enumerate(models):
        one = cut.sel(model=m) if "model" in cut.dims else cut
        y = to_display(variable, one[variable].values)
        ax.plot(r, y, linestyle=styles[k % len(styles)], color=f"C{k}", label=m)
        bad = np.asarray(one["validity"].values) > 0
        if bad.any():
            flagged_any = True
            ax.plot(r[bad], y[bad], "x", color=f"C{k}", ms=5)
    if flagged_any:
        ax.plot([], [], "x", color="0.3", label="flagged (validity != 0)")
    ax.set_xlabel(display_label("radius"))
    ax.set_ylabel(display_label(variable))
    ax.legend(fontsize="small")
    sub = ", ".join(_text(n, float(ds[n].sel({n: v}).values)) for n, v in at.items())
    _suptitle(fig, f"Figure compare: {VARIABLES[variable].long_name}, every model", sub)
    _footer(fig, ds)
    return fig


CHARTS = {"fig12a": fig12a, "fig12b": fig12b, "fig12c": fig12c, "fig4": fig4,
          "fig6": fig6, "fig7": fig7, "design_map": design_map,
          "feasibility_map": feasibility_map, "compare": compare}
assert tuple(CHARTS) == tuple(_CHART_NAMES), "charts and config.CHARTS disagree"


#: Axes each chart draws along: a cube with a single value there cannot show it.
NEEDS = {"fig12a": ("stroke",), "fig12b": ("radius",), "fig12c": ("radius",),
         "fig4": ("stroke",), "fig6": ("pressure",), "fig7": ("pressure",),
         "design_map": ("radius", "wall_thickness"),
         "feasibility_map": ("radius", "wall_thickness"), "compare": ("radius",)}


def _unmet(ds, name):
    if name == "feasibility_map" and "feasibility" not in ds:
        return "feasibility_map skipped: the cube has no feasibility (no 'requirements')"
    short = [axis for axis in NEEDS[name] if ds.sizes[axis] < 2]
    return (f"{name} skipped: it needs at least 2 values of {' and '.join(short)}; the cube "
            "has 1") if short else None


#: Axes a chart slice (``--at``) may fix.
SLICE_AXES = ("radius", "wall_thickness", "length", "wrap_angle")


def _on_grid(ds, name, values, field):
    out = []
    for value in np.atleast_1d(values):
        grid = _grid_value(ds, name, float(value))
        if grid is None:
            v = VARIABLES[name]
            unit = "" if v.display == "1" else f" {v.display}"
            shown = ", ".join(f"{x:g}" for x in to_display(name, ds[name].values[:12]))
            more = ", ..." if ds.sizes[name] > 12 else ""
            raise InputError(f"{field}: {name}={float(to_display(name, value)):g}{unit} is "
                             f"not a grid value of the cube; it has {shown}{more}{unit}")
        out.append(grid)
    return out


def chart_slice(ds, at=None, coil_index=None) -> dict:
    """Check a chart slice against the cube: ``{axis: grid value}`` [SI] and coil indices.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    at : dict, optional
        ``{axis: value}`` [SI] for axes of :data:`SLICE_AXES`.
    coil_index : float or sequence of float, optional
        Coil indices to draw [-].

    Returns
    -------
    dict
        The slice with grid values, ``coil_index`` a list.

    Raises
    ------
    InputError
        An axis that charts cannot fix, or a value that is not a grid value.
    """
    out = {}
    for name, value in (at or {}).items():
        if name not in SLICE_AXES:
            raise InputError(f"--at: charts take {', '.join(SLICE_AXES)} (coil indices with "
                             f"--coil-index), got {name!r}")
        out[name] = _on_grid(ds, name, value, "--at")[0]
    if coil_index is not None:
        out["coil_index"] = _on_grid(ds, "coil_index", coil_index, "--coil-index")
    return out


def _slice_kwargs(func, chosen):
    """The keyword arguments of chart ``func`` that the slice ``chosen`` sets."""
    import inspect

    params = inspect.signature(func).parameters
    kw = {name: value for name, value in chosen.items() if name in params}
    if "wall_thickness" in chosen and "walls" in params:
        kw["walls"] = [chosen["wall_thickness"]]
    return kw


def _short_attrs(ds, limit=80):
    """``ds`` with every string attribute cut to ``limit`` characters (a shallow copy): a
    title or footer never lays out a huge attribute (a 10 MB ``name`` hung the chart)."""
    attrs = {k: (v if not isinstance(v, str) or len(v) <= limit else v[:limit] + "...")
             for k, v in ds.attrs.items()}
    if all(attrs[k] is v for k, v in ds.attrs.items()):
        return ds
    ds = ds.copy(deep=False)
    ds.attrs = attrs
    return ds


def chart_owner(ds) -> str:
    """Who draws charts of ``ds`` [-]: the cube's resolved path, or its name without one."""
    source = ds.encoding.get("source")
    if source:
        return str(Path(source).resolve())
    return f"cube named {str(ds.attrs.get('name', '?'))[:200]}"


def draw_charts(ds, names, out_dir, fmt="png", on_skip=None, *, at=None, coil_index=None,
                progress=None, overwrite=False, refuse_foreign=True) -> list[Path]:
    """Draw the named charts of a cube into ``<out_dir>/<name>.<fmt>``.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube (:func:`nylonflex.open_cube`).
    names : sequence of str or None
        Chart names (:data:`CHARTS`); None draws all the cube can show.
    out_dir : path
        Folder for the images (created if missing).
    fmt : {"png", "pdf", "svg"}
        Image format.
    on_skip : callable, optional
        Receives a one-line message for each chart the cube cannot show (an axis it plots
        along has a single value); a warning by default.
    at : dict, optional
        The slice, ``{axis: value}`` [SI] for axes of :data:`SLICE_AXES` (grid values):
        each chart takes the ones it holds fixed.
    coil_index : float or sequence of float, optional
        Coil indices to draw [-] (grid values); default every one of the cube.
    progress : callable, optional
        Called as ``progress(done, total)`` [charts] after each chart.
    overwrite : bool
        Replace files nylonflex did not write for this cube [-] (a manifest in the folder,
        :class:`nylonflex.files.OwnedFiles`, records the charts each cube drew).
    refuse_foreign : bool
        With such a file in the way and no ``overwrite``: raise before drawing anything
        (True) or leave that chart undrawn with a line to ``on_skip`` (False) [-].

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of ``names``.

    Raises
    ------
    InputError
        An unknown chart name or format, or (``refuse_foreign``) a file in the way that
        nylonflex did not write for this cube.
    """
    if not names:  # every chart the cube can show (feasibility only with requirements)
        names = [n for n in CHARTS if n != "feasibility_map" or "feasibility" in ds]
    names = list(names)
    unknown = [n for n in names if n not in CHARTS]
    if unknown:
        raise InputError(f"--figure: unknown chart {unknown[0]!r}; accepted: "
                         f"{', '.join(CHARTS)}")
    if fmt not in FORMATS:
        raise InputError(f"--format: unknown image format {fmt!r}; accepted: "
                         f"{', '.join(FORMATS)}")
    from .files import OwnedFiles

    chosen = chart_slice(ds, at, coil_index)
    owner = chart_owner(ds)
    ds = _short_attrs(ds)
    out_dir = Path(out_dir)
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else [None]
    jobs = [(name, m) for name in names for m in (models if name != "compare" else [None])]
    owned = OwnedFiles(out_dir, owner)
    targets = [out_dir / _chart_file(n, m, fmt) for n, m in jobs]
    blocked = {} if overwrite else {p: why for p in targets if (why := owned.foreign(p))}
    if blocked and refuse_foreign:
        first = next(iter(blocked.values()))
        more = f" (and {len(blocked) - 1} more)" if len(blocked) > 1 else ""
        raise InputError(f"--out: {first}{more}; not replaced: give another folder or "
                         "--overwrite")
    plt = _plt()
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for done, (name, model) in enumerate(jobs, 1):
        if progress is not None and done > 1:
            progress(done - 1, len(jobs))
        reason = _unmet(ds, name)
        if reason:
            if on_skip is None:
                import warnings

                warnings.warn(reason, stacklevel=2)
            else:
                on_skip(reason)
            continue
        path = out_dir / _chart_file(name, model, fmt)
        if path in blocked:
            reason = f"{blocked[path]}; not replaced (draw it with 'nylonflex chart CUBE " \
                     "--overwrite')"
            if on_skip is None:
                import warnings

                warnings.warn(reason, stacklevel=2)
            else:
                on_skip(reason)
            continue
        with plt.rc_context(_RC):
            # a cube of several models: each figure once a model, its name in title and file
            one = ds if model is None else ds.sel(model=model, drop=True)
            fig = CHARTS[name](one, **_slice_kwargs(CHARTS[name], chosen))
            if model is not None:
                fig.text(0.99, 0.995, f"model: {model}", ha="right", va="top",
                         fontsize="small", weight="bold")
            # fixed metadata so that the same cube gives byte-stable PDF/SVG files
            meta = {"png": {"Software": "nylonflex"}, "pdf": {"CreationDate": None},
                    "svg": {"Date": None}}[fmt]
            fig.savefig(path, format=fmt, metadata=meta, bbox_inches="tight",
                        pad_inches=0.08)
            plt.close(fig)
        written.append(path)
        owned.record([path])
    if progress is not None:
        progress(len(jobs), len(jobs))
    return written


def _chart_file(name, model, fmt) -> str:
    return f"{name}.{fmt}" if model is None else f"{name}_{model}.{fmt}"
