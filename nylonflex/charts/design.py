"""The Pareto-front chart of a design result (a Figure made without pyplot).

Two or more objectives: the first two, the cube's feasible designs as a grey cloud, the
grid front and the refined front. One objective: the objective against the first free axis,
the cloud, the best grid point and the refined design. Axes in display units with the
registry's labels; the chart computes nothing (the result carries every value).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files.atomic import save_figure
from ._common import new_figure, rc_context
from ..variables import AXES, name_label, to_display

__all__ = ["draw_front", "front_figure"]


def _sorted_step(ax, x, y, **kw):
    order = np.argsort(x, kind="stable")
    ax.plot(np.asarray(x)[order], np.asarray(y)[order], **kw)


def draw_front(res, out_dir) -> Path:
    """Draw :func:`front_figure` of ``res`` into ``out_dir/<name>.png``; return the path.

    Parameters
    ----------
    res : DesignResult
    out_dir : path
        Created when missing; an existing chart of the same name is replaced.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{res.spec.name}.png"
    with rc_context():
        return save_figure(front_figure(res), path)


def front_figure(res):
    """The front (two or more objectives) or the best design (one) of a
    :class:`~nylonflex.design.DesignResult`, as a :class:`matplotlib.figure.Figure`."""
    objs = res.spec.objectives
    if len(objs) >= 2:
        xname, yname = objs[1].name, objs[0].name
    else:
        free = [a for a in AXES if a not in res.scan.fixed and
                res.scan.ranges[a][1] > res.scan.ranges[a][0]]
        xname, yname = (free[0] if free else "radius"), objs[0].name
    with rc_context():
        fig, axes = new_figure(size=(6.4, 4.6))
        ax = axes[0, 0]
        cloud = res.scan.cloud
        if len(cloud["radius"]):
            ax.scatter(to_display(xname, cloud[xname]), to_display(yname, cloud[yname]),
                       s=6, c="0.75", lw=0, label=f"feasible grid designs ({res.scan.feasible})",
                       rasterized=True)
        grid = res.grid_front
        # the rows the CLI reports, counted as it counts them (designs equal in every
        # objective are one row): the chart and the table say the same number
        refined = res.reported_rows()
        if len(objs) >= 2:
            if len(grid["radius"]):
                _sorted_step(ax, to_display(xname, grid[xname]), to_display(yname, grid[yname]),
                             color="C0", marker="o", ms=4, lw=1.0,
                             label=f"grid front ({len(grid['radius'])})")
            if len(refined["radius"]):
                _sorted_step(ax, to_display(xname, refined[xname]),
                             to_display(yname, refined[yname]), color="C3", marker=".",
                             ms=7, lw=1.2, ls="--",
                             label=f"reported front ({len(refined['radius'])} designs)")
        else:
            for d in res.designs:
                style = dict(color="C3", marker="*", ms=14) if d["source"] == "refined" \
                    else dict(color="C0", marker="o", ms=8, mfc="none", mew=1.8)
                ax.plot(to_display(xname, d[xname]), to_display(yname, d[yname]), ls="none",
                        label=f"{'refined design' if d['source'] == 'refined' else 'best grid point'}",
                        **style)
        ax.set_xlabel(name_label(xname) + f"  ({'min' if objs[-1].sense == 'min' else 'max'})"
                      if len(objs) >= 2 else name_label(xname))
        ax.set_ylabel(name_label(yname) + f"  ({objs[0].sense})")
        title = "Pareto front" if len(objs) >= 2 else "best design"
        ax.set_title(f"{title}: {res.spec.name}")
        if res.spec.constraints:
            text = "\n".join(c.text for c in res.spec.constraints)
            ax.text(0.99, 0.02, text, transform=ax.transAxes, ha="right", va="bottom",
                    fontsize=7.5, color="0.3")
        ax.legend(loc="upper left")
    return fig
