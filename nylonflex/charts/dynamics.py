"""How fast a design moves (issue 29; docs/model.md s. 19-20): a cycle-rate map over two
axes, cycle rate against radius per coil index (figure-12 style), the trade-off of tip force
against cycle rate, and the closed loop's bandwidth (or tracking error) map.

Each chart is ``f(ds, *, ax=None, **slice) -> matplotlib.figure.Figure``: drawn into ``ax``
when given (its figure is returned), else into a new :class:`matplotlib.figure.Figure`
(no pyplot state). The cube must have a supply (``cycle_rate`` is stored only then).
Axis labels come from the registry, in display units.
"""

from __future__ import annotations

import numpy as np

from ..units import InputError
from ..variables import AXES, label, to_display
from ._common import (_FLAG_GREY, _LENGTH_DEFAULT, _WRAP_DEFAULT, _coil_colour,
                      _coils, _eq, _flag_patch, _flag_text, _footer, _grey_flagged, _nearest,
                      _valid_range, new_figure)

__all__ = ["cycle_rate_lines", "cycle_rate_map", "force_rate", "tracking_map"]


def _need_rate(ds):
    if "cycle_rate" not in ds:
        raise InputError("cycle_rate: the cube has none (it needs a supply: add "
                         "'supply: {voltage: 12, units: V}' to the sweep config)")


def _axes(ax, size):
    """``(fig, ax)``: the given axes and their figure, or a new figure (no pyplot)."""
    if ax is not None:
        return ax.figure, ax
    fig, axes = new_figure(size=size)
    return fig, axes[0, 0]


def _fixed(ds, free, **given):
    """The grid values of every axis but ``free``: ``given`` [SI] or the defaults (length
    nearest 90 mm, wrap angle nearest 8 deg, coil index nearest 1.7, radius 15 mm, wall
    2 mm)."""
    default = {"radius": 15e-3, "wall_thickness": 2e-3, "length": _LENGTH_DEFAULT,
               "coil_index": 1.7, "wrap_angle": _WRAP_DEFAULT}
    out = {}
    for name in AXES:
        if name in free:
            continue
        value = given.get(name)
        if isinstance(value, (list, tuple, np.ndarray)):
            value = value[0]
        out[name] = _nearest(ds, name, default[name] if value is None else value)
    return out


def _title(ax, title, fixed):
    ax.set_title(f"{title}\n" + ", ".join(_eq(k, v) for k, v in fixed.items()), fontsize=9)


def cycle_rate_map(ds, *, ax=None, x="radius", y="wrap_angle", radius=None,
                   wall_thickness=None, length=None, coil_index=None, wrap_angle=None):
    """Cycle rate over two design axes, the others fixed.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube with a supply.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new figure.
    x, y : str
        The two axes of the map (names of :data:`nylonflex.variables.AXES`); default
        radius and wrap angle (the wrap angle sets the muscle length, which sets the rate).
    radius, wall_thickness, length, coil_index, wrap_angle : float, optional
        The fixed axes [SI]; default nearest 15 mm, 2 mm, 90 mm, 1.7 and 8 deg.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _need_rate(ds)
    return _map(ds, "cycle_rate", "Cycle rate: heat to 95 % of the stroke at the supply, "
                "cool to 5 %", "magma", ax=ax, x=x, y=y, radius=radius,
                wall_thickness=wall_thickness, length=length, coil_index=coil_index,
                wrap_angle=wrap_angle)


#: What a tracking cube's map shows, best first: the bandwidth where the sweep searched for
#: it, else the RMS error of the reference it tracked (docs/model.md s. 19).
_TRACKING = (("tracking_bandwidth", "Tracking bandwidth: the highest sine frequency tracked "
              "within the stated error", "viridis"),
             ("tracking_rms_error", "RMS tracking error of the closed loop", "viridis_r"))


def tracking_map(ds, *, ax=None, x="radius", y="wall_thickness", radius=None,
                 wall_thickness=None, length=None, coil_index=None, wrap_angle=None):
    """Tracking bandwidth (else RMS tracking error) over two design axes, the others fixed.

    The bandwidth where the sweep searched for it (``tracking: bandwidth:``), else the RMS
    error of the reference the closed loop tracked; a design whose loop did not run is a
    blank cell.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube swept with ``tracking:``.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new figure.
    x, y : str
        The two axes of the map; default radius and wall thickness.
    radius, wall_thickness, length, coil_index, wrap_angle : float, optional
        The fixed axes [SI]; default nearest 15 mm, 2 mm, 90 mm, 1.7 and 8 deg.

    Returns
    -------
    matplotlib.figure.Figure
    """
    for name, title, cmap in _TRACKING:
        if name in ds:
            return _map(ds, name, title, cmap, ax=ax, x=x, y=y, radius=radius,
                        wall_thickness=wall_thickness, length=length,
                        coil_index=coil_index, wrap_angle=wrap_angle)
    raise InputError("tracking_rms_error: the cube has none (it needs a sweep with "
                     "'tracking:', e.g. configs/fig12_tracking.yaml)")


def _map(ds, name, title, cmap, *, ax, x, y, **given):
    """Variable ``name`` over axes ``x`` and ``y``, the others fixed (``given`` [SI])."""
    for axis in (x, y):
        if axis not in AXES or x == y:
            raise InputError(f"{name} map: x and y must be two of {', '.join(AXES)}, "
                             f"got {x!r} and {y!r}")
    fixed = _fixed(ds, (x, y), **given)
    names = [name, *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(**fixed).transpose(y, x).load()
    fig, ax = _axes(ax, (6.4, 4.6))
    xs, ys = to_display(x, ds[x].values), to_display(y, ds[y].values)
    values = to_display(name, cut[name].values)
    # flagged designs: greyed and hatched, never a colour of the scale; the scale is the
    # cube's valid designs' range, the same for every slice
    values, bits = _grey_flagged(ax, xs, ys, cut["validity"].values if "validity" in cut
                                 else None, values)
    lo, hi = _valid_range(ds, name)
    if not (np.isfinite(lo) and hi > lo):
        lo, hi = (lo, lo + 1.0) if np.isfinite(lo) else (0.0, 1.0)
    finite = np.isfinite(values)
    if len(xs) > 1 and len(ys) > 1 and finite.sum() >= 4 and np.nanmax(values) > \
            np.nanmin(values):
        levels = np.linspace(lo, hi, 13)
        filled = ax.contourf(xs, ys, values, levels=levels, cmap=cmap, extend="neither")
        lines = ax.contour(xs, ys, values, levels=levels[2::3], colors="white",
                           linewidths=0.6)
        ax.clabel(lines, fmt="%.3g", fontsize=7.5)
    else:  # a line of designs, a flat field or gaps: cells, gaps left blank
        filled = ax.pcolormesh(xs, ys, np.ma.masked_invalid(values), cmap=cmap,
                               shading="nearest", vmin=lo, vmax=hi)
    if bits:
        ax.legend(handles=[_flag_patch(ds, bits)], loc="upper center",
                  bbox_to_anchor=(0.5, -0.14), fontsize=7.5, frameon=False)
    fig.colorbar(filled, ax=ax, label=label(ds[name]))
    ax.set_xlabel(label(ds[x]))
    ax.set_ylabel(label(ds[y]))
    _title(ax, title, fixed)
    _footer(fig, ds)
    return fig


def cycle_rate_lines(ds, *, ax=None, wall_thickness=None, length=None, wrap_angle=None,
                     coil_index=None):
    """Cycle rate against radius, one line per coil index (figure-12 style).

    Strength-limited designs are marked with an open circle, supply-limited ones with a
    cross (the ``limit`` flag).

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube with a supply.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new figure.
    wall_thickness, length, wrap_angle : float, optional
        The fixed axes [SI]; default nearest 2 mm, 90 mm and 8 deg.
    coil_index : float or sequence of float, optional
        Coil indices drawn [-]; default every one of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _need_rate(ds)
    fixed = _fixed(ds, ("radius", "coil_index"), wall_thickness=wall_thickness,
                   length=length, wrap_angle=wrap_angle)
    coils = _coils(ds, coil_index)
    names = ["cycle_rate", "limit", *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(**fixed).load()
    fig, ax = _axes(ax, (6.4, 4.4))
    x = to_display("radius", ds["radius"].values)
    bits = 0
    for c in coils:
        one = cut.sel(coil_index=c)
        rate = to_display("cycle_rate", one["cycle_rate"].values)
        lim = one["limit"].values
        colour = _coil_colour(ds, c)
        v = np.nan_to_num(one["validity"].values).astype(int) if "validity" in one else \
            np.zeros(rate.shape, int)
        bad = v != 0
        # a flagged design keeps no colour: its stretch of the line is grey
        ax.plot(x, np.where(bad, np.nan, rate), color=colour, label=_eq("coil_index", c))
        if bad.any():
            bits |= int(np.bitwise_or.reduce(v[bad]))
            ax.plot(x, np.where(bad, rate, np.nan), color=_FLAG_GREY, lw=1.2, ls=":",
                    marker=".", gid="nf-flagged")
        for code, marker in ((1, "o"), (2, "x")):
            hit = (lim == code) & ~bad
            if hit.any():
                ax.plot(x[hit], rate[hit], ls="", marker=marker, ms=4, mfc="none",
                        color=colour)
    from matplotlib.lines import Line2D

    handles, _ = ax.get_legend_handles_labels()
    handles += [Line2D([], [], ls="", marker="o", mfc="none", color="0.3",
                       label="strength-limited"),
                Line2D([], [], ls="", marker="x", color="0.3", label="supply-limited")]
    if bits:
        handles.append(Line2D([], [], color=_FLAG_GREY, ls=":", marker=".",
                              label=f"flagged design (grey): {_flag_text(ds, bits)}"))
    ax.legend(handles=handles, fontsize=8)
    ax.set_xlabel(label(ds["radius"]))
    ax.set_ylabel(label(ds["cycle_rate"]))
    ax.set_ylim(bottom=0)
    _title(ax, "Cycle rate against radius per coil index", fixed)
    _footer(fig, ds)
    return fig


def force_rate(ds, *, ax=None, coil_index=None, length=None, wrap_angle=None):
    """Tip force against cycle rate of every design, with the front of the largest force.

    The front is the largest force among the designs at each rate or faster; ``length``
    and ``wrap_angle`` may fix a slice.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube with a supply.
    ax : matplotlib.axes.Axes, optional
        Draw here; default a new figure.
    coil_index : float or sequence of float, optional
        Coil indices drawn [-], one colour each; default every one of the cube.
    length, wrap_angle : float, optional
        Fix these axes [SI]; default every value of the cube.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _need_rate(ds)
    coils = _coils(ds, coil_index)
    sel = {k: _nearest(ds, k, v) for k, v in (("length", length), ("wrap_angle", wrap_angle))
           if v is not None}
    names = ["cycle_rate", "tip_force_max", *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(coil_index=coils, **sel).load()
    fig, ax = _axes(ax, (6.4, 4.6))
    all_rate, all_force, bits = [], [], 0
    for c in coils:
        one = cut.sel(coil_index=c)
        rate = to_display("cycle_rate", one["cycle_rate"].values.ravel())
        force = to_display("tip_force_max", one["tip_force_max"].values.ravel())
        v = np.nan_to_num(one["validity"].values.ravel()).astype(int) if "validity" in one \
            else np.zeros(rate.shape, int)
        ok = np.isfinite(rate) & np.isfinite(force)
        bad = ok & (v != 0)
        ok &= v == 0
        ax.scatter(rate[ok], force[ok], s=4, alpha=0.35, color=_coil_colour(ds, c),
                   label=_eq("coil_index", c), rasterized=True, linewidths=0)
        if bad.any():  # flagged designs: grey, and never on the front
            bits |= int(np.bitwise_or.reduce(v[bad]))
            ax.scatter(rate[bad], force[bad], s=4, alpha=0.35, color=_FLAG_GREY,
                       rasterized=True, linewidths=0, gid="nf-flagged")
        all_rate.append(rate[ok])
        all_force.append(force[ok])
    rate, force = np.concatenate(all_rate), np.concatenate(all_force)
    if bits:
        ax.scatter([], [], s=4, color=_FLAG_GREY,
                   label=f"flagged (grey, not on the front): {_flag_text(ds, bits)}")
    if rate.size:  # the front: the largest force among valid designs at least this fast
        order = np.argsort(-rate)
        front = np.maximum.accumulate(force[order])
        ax.step(rate[order], front, where="post", color="k", lw=1.2,
                label="largest force at this rate or faster")
    ax.set_xlabel(label(ds["cycle_rate"]))
    ax.set_ylabel(label(ds["tip_force_max"]))
    ax.legend(fontsize=8, markerscale=3)
    where = ", ".join(_eq(k, v) for k, v in sel.items()) or "every design of the cube"
    ax.set_title(f"Tip force against cycle rate\n{where}", fontsize=9)
    _footer(fig, ds)
    return fig
