"""Model variants side by side: one variable against radius for every model."""

from __future__ import annotations

from ..variables import VARIABLES, display_label, to_display
from ._common import _figure, _footer, _nearest, _suptitle, _text


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

