"""Model variants side by side: one variable against radius for every model."""

from __future__ import annotations

import math

import numpy as np

from ..units import InputError
from ..variables import DESIGN, VARIABLES, label, to_display
from ._common import _COLOURS, _FLAG_GREY, _eq, _figure, _flag_text, _footer, _nearest, _suptitle

# the paper's first worked example's slice (docs/model.md s. 8), SI
_SLICE = (("wall_thickness", 6e-3), ("length", 90e-3), ("coil_index", 1.1),
          ("wrap_angle", math.radians(8.0)))


def comparable(ds):
    """The variables ``compare`` can draw from a cube: design variables along radius."""
    return [n for n in DESIGN if n in ds and "radius" in ds[n].dims]


def compare(ds, *, variable="tip_force_max", wall_thickness=None, length=None,
            coil_index=None, wrap_angle=None):
    """``variable`` against radius for every model, at the paper's first example's slice.

    A line style and colour per model, the legend naming each; a cross marks a flagged
    design (``validity`` != 0, docs/model.md s. 17), the legend naming the flags.
    docs/model.md s. 16.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube (several models, or one).
    variable : str, default "tip_force_max"
        A design variable of the cube (:func:`comparable`).
    wall_thickness, length : float, optional
        The slice [m]; default nearest 6 mm and 90 mm.
    coil_index : float or sequence of float, optional
        Coil index [-] (the first one of a sequence); default nearest 1.1.
    wrap_angle : float, optional
        Wrap angle [rad]; default nearest 8 deg.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        A variable the cube does not hold along radius.
    """
    accepted = comparable(ds)
    if variable not in accepted:
        raise InputError(f"--variable: compare draws one of {', '.join(accepted)}; got "
                         f"{variable!r}")
    given = {"wall_thickness": wall_thickness, "length": length,
             "coil_index": None if coil_index is None else
             float(np.atleast_1d(coil_index)[0]), "wrap_angle": wrap_angle}
    at = {name: _nearest(ds, name, default if given[name] is None else given[name])
          for name, default in _SLICE}
    names = [variable, *(["validity"] if "validity" in ds else [])]
    cut = ds[names].sel(**at).load()
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else \
        [str(ds.attrs.get("models", "paper"))]
    fig, axes = _figure()
    ax = axes[0, 0]
    styles = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]
    r = to_display("radius", ds["radius"].values)
    bits = 0
    for k, m in enumerate(models):
        one = cut.sel(model=m) if "model" in cut.dims else cut
        y = to_display(variable, one[variable].values)
        colour = _COLOURS[k % len(_COLOURS)]
        v = np.nan_to_num(np.asarray(one["validity"].values)).astype(int) \
            if "validity" in one else np.zeros(y.shape, int)
        bad = v != 0
        # a flagged design keeps no model colour: grey, crossed
        ax.plot(r, np.where(bad, np.nan, y), linestyle=styles[k % len(styles)], color=colour,
                label=m)
        if bad.any():
            bits |= int(np.bitwise_or.reduce(v[bad]))
            ax.plot(r, np.where(bad, y, np.nan), "x", ls=styles[k % len(styles)],
                    color=_FLAG_GREY, ms=6, mew=1.5, gid="nf-flagged")
    if bits:
        ax.plot([], [], "x", color=_FLAG_GREY, ms=6, mew=1.5,
                label=f"flagged (grey): {_flag_text(ds, bits)}")
    ax.set_xlabel(label(ds["radius"]))
    ax.set_ylabel(label(ds[variable]))
    ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
    ax.legend(fontsize="small", title="model")
    sub = ", ".join(_eq(n, v) for n, v in at.items())
    _suptitle(fig, f"Figure compare: {VARIABLES[variable].long_name} against radius, "
              "every model",
              f"at {sub}\n(the paper's first example's slice)")  # one line was clipped
    _footer(fig, ds)
    return fig
