"""The paper's figure 12: (a) nylon force against stroke with the strength limits, (b)
maximum torque and (c) maximum bend angle against radius, with each wrap angle's threshold
and, for a sampled cube, quantile bands."""

from __future__ import annotations

import numpy as np

from ..variables import VARIABLES, label, quantile_name, to_display
from ._common import (_COLOURS, _DASHES, _EXAMPLES, _FLAG_GREY, _LENGTH_DEFAULT,
                      _WRAP_DEFAULT, _coil_colour, _flag_text, _models, _one_model,
                      _coils, _eq, _example_point, _figure, _footer,
                      _labelled_psis, _nearest, _pick_few, _psi_colour, _stroke_max,
                      _suptitle, _text)
from .model_spread import example_range, legend_text, model_bands


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
        ax.set_xlabel(label(ds["stroke"], " [-]"))
    left.set_ylabel(label(ds["nylon_force"]))
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
            # the last design the strength does not bind (full, supply's or load's stroke)
            hits = np.flatnonzero((lim[:-1] != 1) & (lim[1:] == 1))
            if hits.size:
                points.append((x[hits[0]], value[hits[0]]))
        out[w] = points
    return out


def _limit_lines(ax, ds, var, sel, coils, psis, psi_ref=None, fixed=False):
    """Fig. 12(b,c) panel: ``var`` against radius per coil index (solid while
    stroke-limited) and each wrap angle's threshold (dashed black) through the last
    designs with a full range of motion.

    The solid line is stroke-limited at some wrap angle of the cube, or, with ``fixed``
    (the caller fixed the wrap angles to ``psis``), at one of ``psis``: it then ends where
    their strength limit cuts in, on their thresholds.

    Supply- and load-limited designs (``supply``, ``coupled_muscle``) depend on the wrap
    angle: drawn thinner, dashed, at ``psi_ref`` [rad]. Designs flagged by ``validity`` at
    ``psi_ref`` get a grey underlay. Returns ``(limits, flag_bits)``: the limit codes of
    the dashed lines drawn (a set of 2, 3) and the OR of the flags under the curves.
    """
    x = to_display("radius", ds["radius"].values)
    flagged = "validity" in ds
    # read the panel's slice once (a large cube's chunks span every coil and wrap angle)
    ds = ds[[var, "limit", *(["validity"] if flagged else [])]].sel(**sel)
    if fixed:  # only the wrap angles asked for: no solid past their thresholds
        ds = ds.sel(wrap_angle=list(psis))
    ds = ds.load()
    sel = {}
    j_ref = None if psi_ref is None else \
        int(np.argmin(np.abs(ds["wrap_angle"].values - psi_ref)))
    load_drawn, bits = set(), 0
    for c in coils:
        colour = _coil_colour(ds, c)
        cut = ds.sel(coil_index=c)
        value = to_display(var, cut[var].transpose("wrap_angle", "radius").values)
        lim = cut["limit"].transpose("wrap_angle", "radius").values
        v = np.nan_to_num(cut["validity"].transpose("wrap_angle", "radius").values) \
            .astype(int) if flagged else np.zeros(lim.shape, int)
        # the whole stroke: the same for every wrap angle (s* = s_max(C))
        stroke_limited = lim == 0
        best = np.argmax(np.where(stroke_limited, value, -np.inf), axis=0)
        solid = np.where(stroke_limited.any(axis=0),
                         np.take_along_axis(value, best[None], 0)[0], np.nan)
        v_solid = np.take_along_axis(v, best[None], 0)[0]
        # a flagged design (docs/model.md s. 17) keeps no colour: grey, drawn apart
        bad = (v_solid != 0) & np.isfinite(solid)
        ax.plot(x, np.where(bad, np.nan, solid), color=colour, lw=2.0, zorder=3)
        if bad.any():
            bits |= int(np.bitwise_or.reduce(v_solid[bad]))
            _grey_line(ax, x, solid, bad, c)
        if j_ref is None:
            continue
        # the supply's stroke (the wrap's muscle length sets T_ss) or where the muscle
        # settles against its load: the value depends on the wrap angle
        short = (lim[j_ref] == 2) | (lim[j_ref] == 3)
        load = np.where(short, value[j_ref], np.nan)
        if short.any():
            load_drawn |= {int(code) for code in lim[j_ref][short]}
            bad = (v[j_ref] != 0) & short
            ax.plot(x, np.where(bad, np.nan, load), color=colour, lw=1.5,
                    ls=(0, (4, 1.5)), zorder=3)
            if bad.any():
                bits |= int(np.bitwise_or.reduce(v[j_ref][bad]))
                _grey_line(ax, x, load, bad, c)
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
    ax.set_xlabel(label(ds["radius"]))
    return load_drawn, bits


def _grey_line(ax, x, y, bad, coil=None):
    """The flagged stretch of a curve (of coil index ``coil``, named in its hidden label):
    grey, thick, faded, no colour of the coils."""
    ax.plot(x, np.where(bad, y, np.nan), color=_FLAG_GREY, lw=5, alpha=0.6, marker="o",
            ms=5, mew=0, solid_capstyle="round", zorder=2.5, gid="nf-flagged",
            label="_flagged" if coil is None else f"_flagged C = {coil:g}")


def _legend_12bc(fig, coils, psis, load_psi=None, flags="", limits=()):
    """The fig. 12(b,c) legend; ``load_psi`` [rad]: supply- or load-limited lines (limit
    codes ``limits``) were drawn at that wrap angle; ``flags``: the names of the validity
    flags under the curves ("" none)."""
    from matplotlib.lines import Line2D

    shown = _labelled_psis(psis)
    handles = [Line2D([], [], color=colour, lw=2.0, label=f"C = {c:g}")
               for c, colour in coils]
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
    if load_psi is not None:
        what = " or ".join(w for code, w in ((2, "supply-limited"), (3, "load-limited"))
                           if code in limits)
        handles.append(Line2D([], [], color="0.3", lw=1.5, ls=(0, (4, 1.5)),
                              label=f"{what} (muscle stops short), at "
                                    f"{_eq('wrap_angle', load_psi)}"))
    if flags:
        handles.append(Line2D([], [], color=_FLAG_GREY, lw=5, alpha=0.6,
                              label=f"flagged design: {flags} (grey, not coloured)"))
    fig.legend(handles=handles, loc="outside lower center",
               ncol=min(6, max(len(coils), len(shown) + (len(shown) < len(psis)))),
               title="coil index C: solid while the design has its full range of motion "
                     f"(stroke-limited)\nwrap angle \u03c8{note}: dashed threshold through "
                     "the last full-range design of each C; beyond it the nylon's strength "
                     "limits")


def _examples(ax, ds, var, t, length=None, corner="upper left", coils=None, brief=False):
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
        if brief:  # a narrow panel of a model comparison: the value beside the star
            ax.annotate(f"{y:.3g} {unit}{example_range(ds, var, at)}", (x, y), xytext=(6, 4), textcoords="offset points",
                        fontsize=7.5, zorder=7, bbox={"boxstyle": "round,pad=0.15",
                                                      "fc": "white", "ec": "0.6"})
            continue
        text = f"paper example: {_eq('radius', at['radius'])}, " \
               f"{_eq('coil_index', at['coil_index'])}, {_eq('wrap_angle', at['wrap_angle'])}" \
               f"\n{VARIABLES[var].long_name} {y:.3g} {unit}{example_range(ds, var, at)}"
        full = "full range of motion" if int(point["limit"]) == 0 else \
            "range of motion cut short"
        if length is None:
            text += f"\nat {_eq('length', at['length'])} tip force " \
                    f"{float(point['tip_force_max']):.3g} N" \
                    f"{example_range(ds, 'tip_force_max', at)}, {full}"
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


def _row_limits(rows):
    """From zero to the largest value drawn in each row of panels (one shared scale; set
    after every model is drawn, since matplotlib freezes a shared scale at its first
    ``set_ylim``)."""
    for row in rows:
        tops = [ax.dataLim.y1 for ax in row if ax.has_data() and np.isfinite(ax.dataLim.y1)]
        row[0].set_ylim(0, 1.05 * max(tops) if tops and max(tops) > 0 else 1.0)


def _ref_psi(ds, wrap_angle=None):
    """The wrap angle at which load-limited lines and flags are drawn [rad]: the first
    one asked for, or the grid value nearest 8 deg."""
    first = _WRAP_DEFAULT if wrap_angle is None else float(np.atleast_1d(wrap_angle)[0])
    return _nearest(ds, "wrap_angle", first)


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
        Length at which M* is read [m] (M* does not depend on it, but for
        ``sealed_chamber``'s, whose blocked pressure does); default nearest 90 mm.
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
    psi_ref = _ref_psi(ds, wrap_angle)
    models = _models(ds)
    many = len(models) > 1
    if many:  # a column per model, a row per wall; one scale along a row
        fig, axes = _figure(len(walls), len(models), sharex=True, sharey="row",
                            size=(3.3 * len(models) + 0.6, 3.9 * len(walls) + 1.9))
    else:
        fig, axes = _figure(1, len(walls), size=(4.4 * len(walls) + 0.4, 5.4))
    load, bits = set(), 0
    for m, model in enumerate(models):
        one = _one_model(ds, model)
        for w, t in enumerate(walls):
            ax = axes[w][m] if many else axes[0][w]
            sel = {"wall_thickness": t, "length": length}
            drew, flags = _limit_lines(ax, one, "torque_max", sel, coils, psis, psi_ref,
                                       fixed=wrap_angle is not None)
            load, bits = load | drew, bits | flags
            _quantile_bands(ax, one, "torque_max", sel, coils, psi_ref)
            model_bands(ax, one, "torque_max", sel, coils, psi_ref, note_at=None)
            _examples(ax, one, "torque_max", t, coils=coils, brief=many)
            ax.set_title(f"wall thickness {_eq('wall_thickness', t)}" if not many else
                         f"{model}\n{_eq('wall_thickness', t)}",
                         weight="bold" if many else None)
            ax.set_ylabel(label(one["torque_max"]) if m == 0 else "")
            if many and w < len(walls) - 1:
                ax.set_xlabel("")
            if not many:
                ax.set_ylim(bottom=0)
    if many:
        _row_limits(axes)
    _legend_12bc(fig, [(c, _coil_colour(ds, c)) for c in coils], psis,
                 psi_ref if load else None, _flag_text(ds, bits),
                 load)
    # sealed_chamber's blocked pressure, and so its M*, depends on a/L (docs/model.md s. 22)
    where = f"at {_eq('length', length)} (sealed_chamber's M* depends on L; tip force = " \
        "M*/L)" if "sealed_chamber" in models else \
        "any length (M* does not depend on L; tip force = M*/L)"
    _suptitle(fig, "Figure 12(b): maximum torque against actuator radius", where +
              (f"\none column per model ({len(models)}), one scale along each row"
               if many else "") + legend_text(ds, psi_ref))
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
    models = _models(ds)
    many = len(models) > 1
    if many:  # a column per model; per wall a row of angles and a row of range fractions
        fig, axes = _figure(2 * len(walls), len(models), sharex=True, sharey="row",
                            size=(3.3 * len(models) + 0.6, 6.4 * len(walls) + 1.9),
                            height_ratios=(3, 2) * len(walls))
    else:
        fig, axes = _figure(2, len(walls), size=(4.4 * len(walls) + 0.4, 7.6), sharex=True,
                            height_ratios=(3, 2))
    x = to_display("radius", ds["radius"].values)
    load, bits = set(), 0
    for m, model in enumerate(models):
        one = _one_model(ds, model)
        for w, t in enumerate(walls):
            sel = {"wall_thickness": t, "length": length}
            top, bottom = (axes[2 * w][m], axes[2 * w + 1][m]) if many else \
                (axes[0][w], axes[1][w])
            drew, flags = _limit_lines(top, one, "bend_angle_max", sel, coils, psis, psi,
                                       fixed=wrap_angle is not None)
            load, bits = load | drew, bits | flags
            _quantile_bands(top, one, "bend_angle_max", sel, coils, psi,
                            note_at=(0.02, 0.98))
            model_bands(top, one, "bend_angle_max", sel, coils, psi, note_at=None)
            _examples(top, one, "bend_angle_max", t, length, corner="lower right",
                      coils=coils, brief=many)
            top.set_title(f"wall thickness {_eq('wall_thickness', t)}" if not many else
                          f"{model}\n{_eq('wall_thickness', t)}",
                          weight="bold" if many else None)
            top.set_xlabel("")
            top.set_ylabel(label(one["bend_angle_max"]) if m == 0 else "")
            if not many:
                top.set_ylim(bottom=0)
            names = ["range_fraction", *(["validity"] if "validity" in one else [])]
            cut = one[names].sel(wrap_angle=psi, **sel).load()
            model_bands(bottom, one, "range_fraction", sel, coils, psi, scale=100.0,
                        everywhere=True, note_at=None)
            for c in coils:
                rf = 100 * cut["range_fraction"].sel(coil_index=c).values
                v = np.nan_to_num(cut["validity"].sel(coil_index=c).values).astype(int) \
                    if "validity" in cut else np.zeros(rf.shape, int)
                bad = v != 0
                bottom.plot(x, np.where(bad, np.nan, rf), color=_coil_colour(one, c), lw=1.8)
                if bad.any():
                    bits |= int(np.bitwise_or.reduce(v[bad]))
                    _grey_line(bottom, x, rf, bad, c)
            bottom.set_title(f"range of motion at {_eq('wrap_angle', psi)}" +
                             ("" if many else " (100 % = full range)"))
            bottom.set_xlabel(label(ds["radius"]) if w == len(walls) - 1 or not many else "")
            bottom.set_ylabel("range of motion [%]" if m == 0 else "")
            bottom.set_ylim(0, 105)
    if many:
        _row_limits(axes[0::2])
    _legend_12bc(fig, [(c, _coil_colour(ds, c)) for c in coils], psis,
                 psi if load else None, _flag_text(ds, bits), load)
    _suptitle(fig, "Figure 12(c): maximum bend angle (range of motion) against radius",
              f"{_eq('length', length)} (the angle grows in proportion to L; "
              "the range fraction does not)" +
              (f"\none column per model ({len(models)}), one scale along each row"
               if many else "") + legend_text(ds, psi))
    _footer(fig, ds)
    return fig



# ---------------------------------------------------------------------------- uncertainty
def _band_levels(ds):
    """Indices of the outermost quantiles (5 and 95 % by default) of a sampled cube."""
    q = ds["quantile"].values
    return int(np.argmin(q)), int(np.argmax(q)), q


def _quantile_bands(ax, ds, var, sel, coils, wrap_angle=None, note_at=(0.99, 0.01)):
    """Shade each coil index's band between the cube's lowest and highest quantile of
    ``var`` (a cube with ``uncertainty``; nothing otherwise), at ``wrap_angle`` (default
    nearest 8 deg), only where the nominal design there is not strength-limited: a band
    follows its curve and ends at its wrap angle's threshold."""
    qname = quantile_name(var)
    if qname not in ds or "quantile" not in ds.coords:
        return
    lo, hi, q = _band_levels(ds)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    x = to_display("radius", ds["radius"].values)
    for c in coils:
        cut = ds[qname].sel(coil_index=c, wrap_angle=psi, **sel).transpose("quantile",
                                                                           "radius").values
        lim = ds["limit"].sel(coil_index=c, wrap_angle=psi, **sel).values.astype(float)
        drawn = np.isfinite(lim) & (lim != 1)  # where the curve is (not strength-limited)
        if "validity" in ds:  # no coloured band over a flagged (grey) design
            drawn &= np.nan_to_num(ds["validity"].sel(coil_index=c, wrap_angle=psi, **sel)
                                   .values) == 0
        ax.fill_between(x, to_display(var, cut[lo]), to_display(var, cut[hi]), where=drawn,
                        color=_coil_colour(ds, c), alpha=0.18, lw=0, zorder=2)
    ax.text(*note_at, f"bands: {100 * q[lo]:g}-{100 * q[hi]:g} % at "
            f"{_eq('wrap_angle', psi)}", transform=ax.transAxes,
            ha="right" if note_at[0] > 0.5 else "left",
            va="bottom" if note_at[1] < 0.5 else "top", fontsize=7.5, color="0.3", zorder=8,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})

