"""The paper's figures 4, 6 and 7: chamber pressure against stroke, bend angle and blocked
tip force against pressure."""

from __future__ import annotations

import numpy as np

from ..variables import VARIABLES, label, to_display
from ._common import (_COLOURS, _FLAG_FILL, _FLAG_GREY, _LENGTH_DEFAULT, _coils, _eq, _figure, _footer,
                      _nearest, _pick_few, _range_text, _spread, _stroke_max, _suptitle)


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
    ax.set_xlabel(label(ds["stroke"], " [-]"))
    ax.set_ylabel(label(ds["chamber_pressure"]))
    ax.legend(loc="upper left")
    _suptitle(fig, "Figure 4: chamber pressure against muscle stroke",
              "sealed air chamber, same for every design")
    _footer(fig, ds)
    return fig


#: The bend at which the tip runs into the base (docs/model.md s. 17, ``self_contact``).
_CONTACT_DEG = 360.0
#: Figure 6's bend axis ends this far above it: the rest of a curve is clipped.
_CONTACT_TOP = 1.25 * _CONTACT_DEG


def _curve_panel(ax, ds, var, name, values, fixed):
    """Curves of ``var`` against pressure, one per value of ``name``. A bend angle past
    360 deg (the tip runs into the base, the design's ``self_contact`` flag) is drawn
    grey and dotted and the axis ends at 450 deg (clipped); returns whether any was."""
    pressure = to_display("pressure", ds["pressure"].values)
    contact = False
    for i, v in enumerate(values):
        y = to_display(var, ds[var].sel({name: v, **fixed}).values)
        over = y > _CONTACT_DEG if var == "bend_angle" else np.zeros(y.shape, bool)
        # the coloured line stops at the last point short of contact; grey dotted on
        cut = np.where(over, np.nan, y)
        if over.any():
            contact = True
            joined = over | np.append(over[1:], False)  # from the point before
            ax.plot(pressure, np.where(joined, y, np.nan), color=_FLAG_GREY, ls=":",
                    lw=1.4, gid="nf-flagged")
        ax.plot(pressure, cut, color=_COLOURS[i % len(_COLOURS)], label=_eq(name, v))
    ax.set_xlim(pressure[0], pressure[-1])
    ax.set_ylim(bottom=0)
    if contact:
        ax.axhspan(_CONTACT_DEG, _CONTACT_TOP, color=_FLAG_FILL, lw=0, zorder=0)
        ax.set_ylim(0, _CONTACT_TOP)
        ax.text(0.98, (_CONTACT_DEG + 0.5 * (_CONTACT_TOP - _CONTACT_DEG)) / _CONTACT_TOP,
                "self-contact: past 360 deg the tip runs into the base\n(flagged; grey "
                "dotted, clipped at 450 deg)", transform=ax.transAxes, ha="right",
                va="center", fontsize=7.5, color="0.15")
    ax.set_xlabel(label(ds["pressure"]))
    ax.set_ylabel(label(ds[var]))
    ax.set_title(", ".join(_eq(k, v) for k, v in fixed.items()))
    # below the grey band where it is drawn
    ax.legend(loc="upper left", title=VARIABLES[name].long_name,
              bbox_to_anchor=(0, _CONTACT_DEG / _CONTACT_TOP) if contact else None)
    return contact


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

