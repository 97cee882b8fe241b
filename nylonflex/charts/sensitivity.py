"""The bar chart of Sobol' indices (a Figure made without pyplot)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files.atomic import save_figure
from ._common import RC, new_figure, rc_context
from ..variables import name_label

__all__ = ["sensitivity_chart", "sensitivity_figure"]


def sensitivity_chart(result, path) -> Path:
    """Bars of first-order and total indices with 95 % intervals, one panel an output.

    Parameters
    ----------
    result : SensitivityResult
        From :func:`nylonflex.uncertainty.sobol_indices`.
    path : path
        Image file to write (PNG, PDF or SVG by its suffix); its folder is created.

    Returns
    -------
    pathlib.Path
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with rc_context():
        return save_figure(sensitivity_figure(result), path, bbox_inches="tight",
                           pad_inches=0.08)


def sensitivity_figure(result):
    """Bars of first-order and total indices of a :class:`SensitivityResult` with their
    95 % intervals, one panel an output (a :class:`matplotlib.figure.Figure`)."""
    outputs = list(result.indices)
    params = list(result.parameters)
    with rc_context():
        fig, axes = new_figure(1, len(outputs), size=(max(4.0, 1.1 * len(params) + 2.0)
                                                    * len(outputs), 4.2), sharey=True)
        x = np.arange(len(params))
        for ax, o in zip(axes[0], outputs):
            d = result.indices[o]
            for k, (key, colour, label) in enumerate((("first", "#0072B2", "first order"),
                                                      ("total", "#E69F00", "total"))):
                v = np.array([d[key][p] for p in params], float)
                e = np.array([d[f"{key}_conf"][p] for p in params], float)
                ax.bar(x + (k - 0.5) * 0.38, np.nan_to_num(v), 0.38, yerr=np.nan_to_num(e),
                       color=colour, label=label, capsize=3, ecolor="0.2")
            if all(not np.isfinite(d["first"][p]) for p in params):
                ax.text(0.5, 0.5, "does not vary over the samples:\nno indices",
                        transform=ax.transAxes, ha="center", va="center", color="0.3")
            ax.set_xticks(x, params, rotation=20, ha="right")
            ax.set_title(name_label(o))
            ax.axhline(0, color="0.3", lw=0.8)
            ax.set_ylim(-0.05, 1.1)
        axes[0][0].set_ylabel("Sobol' index [1]")
        axes[0][0].legend(loc="upper left", fontsize=8)
        where = "one design" if result.designs == 1 else \
            f"mean over {result.designs} grid designs"
        fig.suptitle(f"Sobol' sensitivity indices ({where}; {result.samples} model runs a "
                     "design; bars: 95 % intervals)", fontsize=RC["figure.titlesize"])
    return fig
