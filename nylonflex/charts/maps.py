"""Maps over radius and wall thickness: the maximum tip force (design map) and the
probability that every requirement holds (feasibility map)."""

from __future__ import annotations

import math

import numpy as np

from ..units import InputError
from ..variables import label, to_display
from ._common import (_EXAMPLES, _LENGTH_DEFAULT, _WRAP_DEFAULT, _coils, _eq, _figure,
                      _flag_patch, _footer, _grey_flagged, _grid_value, _nearest, _pick_few,
                      _suptitle, _valid_range)


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
    from matplotlib import rc_context
    from matplotlib.patches import Patch

    length = _nearest(ds, "length", _LENGTH_DEFAULT if length is None else length)
    psi = _nearest(ds, "wrap_angle", _WRAP_DEFAULT if wrap_angle is None else wrap_angle)
    coils = _coils(ds, coil_index)
    ncols = min(3, len(coils)) if len(coils) != 4 else 2
    nrows = math.ceil(len(coils) / ncols)
    fig, axes = _figure(nrows, ncols, size=(4.4 * ncols + 1.0, 3.6 * nrows + 1.0),
                        sharex=True, sharey=True)
    names = ["tip_force_max", "limit", *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(length=length, wrap_angle=psi).load()
    bits = 0
    # one colour scale for every slice of the cube, set by its valid designs only
    top = _valid_range(ds, "tip_force_max")[1]
    levels = _nice_levels(top if np.isfinite(top) and top > 0 else 1.0)
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
        # flagged designs (docs/model.md s. 17): no colour of the scale, greyed and hatched
        f, flags = _grey_flagged(ax, x, y, _panel_validity(cut, c), f)
        bits |= flags
        mappable = ax.contourf(x, y, f, levels=levels, cmap="viridis", extend="max")
        lines = ax.contour(x, y, f, levels=levels[2::2], colors="white", linewidths=0.6)
        ax.clabel(lines, fmt="%g N", fontsize=7.5)
        strength = np.where(np.isnan(lim) | np.isnan(f), np.nan, (lim == 1).astype(float))
        if np.nanmax(np.nan_to_num(strength)) > 0:
            with rc_context({"hatch.color": "white", "hatch.linewidth": 0.8}):
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
            ax.set_ylabel(label(ds["wall_thickness"]))
        if i >= len(coils) - ncols:
            ax.set_xlabel(label(ds["radius"]))
    fig.colorbar(mappable, ax=axes, label=label(ds["tip_force_max"]), shrink=0.9)
    handles = [Patch(fc="#2a788e", ec="white", hatch="///",
                     label="strength-limited: nylon breaks first, range of motion cut short"),
               Patch(fc="#2a788e", ec="none", label="stroke-limited: full range of motion")]
    if bits:
        handles.append(_flag_patch(ds, bits))
    if any(_map_examples(ds, length, psi, c) for c in coils):
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], ls="", marker="*", ms=10, mfc="gold", mec="k",
                              label="paper's worked example"))
    # one column under a single panel: two would run off the figure
    fig.legend(handles=handles, loc="outside lower center", ncol=1 if ncols == 1 else 2,
               fontsize=8)
    _suptitle(fig, "Design map: maximum tip force over radius and wall thickness",
              f"slice {_eq('length', length)}, {_eq('wrap_angle', psi)}; "
              "one panel per coil index")
    _footer(fig, ds)
    return fig


def _panel_validity(cut, c):
    """The validity bits of a map panel (coil index ``c``) over (wall, radius), or None."""
    if "validity" not in cut:
        return None
    return cut["validity"].sel(coil_index=c).transpose("wall_thickness", "radius").values


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
    names = ["feasibility", *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(length=length, wrap_angle=psi).load()
    bits = 0
    x = to_display("radius", ds["radius"].values)
    y = to_display("wall_thickness", ds["wall_thickness"].values)
    levels = np.linspace(0.0, 1.0, 11)
    mappable = None
    for i, ax in enumerate(axes.flat):
        if i >= len(coils):
            ax.set_visible(False)
            continue
        c = coils[i]
        p = cut["feasibility"].sel(coil_index=c).transpose("wall_thickness", "radius").values
        # a flagged design is never green: greyed and hatched, whatever its probability
        p, flags = _grey_flagged(ax, x, y, _panel_validity(cut, c), p)
        bits |= flags
        mappable = ax.contourf(x, y, p, levels=levels, cmap="RdYlGn", vmin=0, vmax=1)
        if np.isfinite(p).any() and (np.nanmax(p) > 0.5 > np.nanmin(p)
                                     or np.nanmax(p) > 0.9 > np.nanmin(p)):
            lines = ax.contour(x, y, p, levels=[0.5, 0.9], colors="k",
                               linewidths=[0.9, 1.6], linestyles=["--", "-"])
            ax.clabel(lines, fmt=lambda v: f"{100 * v:.0f} %", fontsize=7.5)
        ax.set_title(_eq("coil_index", c))
        ax.grid(False)
        if i % ncols == 0:
            ax.set_ylabel(label(ds["wall_thickness"]))
        if i >= len(coils) - ncols:
            ax.set_xlabel(label(ds["radius"]))
    fig.colorbar(mappable, ax=axes, label=label(ds["feasibility"]), shrink=0.9,
                 ticks=np.linspace(0, 1, 6))
    if bits:
        fig.legend(handles=[_flag_patch(ds, bits)], loc="outside lower center", fontsize=8)
    reqs = ds.attrs.get("requirements", "?")
    samples = ds.attrs.get("uncertainty_samples")
    how = f"{samples} samples" if samples else "nominal designs (no uncertainty)"
    _suptitle(fig, "Feasibility: probability that every requirement holds",
              f"{reqs}; {how}\nslice {_eq('length', length)}, {_eq('wrap_angle', psi)}; "
              "lines at 50 % (dashed) and 90 %")
    _footer(fig, ds)
    return fig

