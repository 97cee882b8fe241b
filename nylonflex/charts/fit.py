"""Charts of calibration: a fit with its residuals, and a design's model against its data.

Each a :class:`matplotlib.figure.Figure` made without pyplot (the caller's backend
untouched); labels from the variable names with display units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files.atomic import save_figure

__all__ = ["fit_chart", "fit_figure", "validate_chart", "validate_figure"]

#: quantity -> (label, display unit, factor from SI, offset from SI)
_DISPLAY = {
    "stretch": ("stretch", "-", 1.0, 0.0),
    "nominal_stress": ("nominal stress", "kPa", 1e-3, 0.0),
    "temperature": ("temperature", "degC", 1.0, -273.15),
    "stroke": ("stroke", "%", 100.0, 0.0),
    "time": ("time", "s", 1.0, 0.0),
    "resistance": ("resistance", "ohm", 1.0, 0.0),
    "force": ("force", "N", 1.0, 0.0),
    "pressure": ("pressure", "kPa", 1e-3, 0.0),
    "bend_angle": ("bend angle", "deg", 180.0 / np.pi, 0.0),
    "tip_force": ("tip force", "N", 1.0, 0.0),
}


def _d(name, v, residual=False):
    label, unit, f, o = _DISPLAY.get(name, (name, "SI", 1.0, 0.0))
    return np.asarray(v) * f + (0.0 if residual else o), f"{label} [{unit}]"


def fit_chart(result, path) -> Path:
    """Write :func:`fit_figure` of ``result`` into ``path`` (PNG at 120 dpi); returns it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fit_figure(result), path, dpi=120)


def fit_figure(result):
    """Data, fit and residuals of a :class:`~nylonflex.calibration.FitResult`
    (a :class:`matplotlib.figure.Figure`)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 5.6))
    ax, axr = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    if result.kind == "muscle":
        x, xl = _d("force", result.x)
        xl = "model force [N]"
    else:
        x, xl = _d(result.x_name, result.x)
    y, yl = _d(result.y_name, result.y)
    yf, _ = _d(result.y_name, result.y_fit)
    r, rl = _d(result.y_name, result.residuals, residual=True)
    ax.plot(x, y, "o", ms=3, color="0.45", label=f"data ({Path(result.data['path']).name})")
    order = np.argsort(x)
    ax.plot(x[order], yf[order], "-", color="C3", lw=1.8,
            label=f"{result.model} fit, R$^2$ = {result.r2:.4f}")
    ax.set_ylabel(("measured " if result.kind == "muscle" else "") + yl)
    ax.legend(frameon=False)
    ax.set_title(f"nylonflex fit {result.kind}: {result.model}"
                 + (f" ({result.test})" if result.test else ""))
    axr.axhline(0.0, color="0.6", lw=0.8)
    axr.plot(x, r, ".", ms=3, color="C0")
    axr.set_ylabel("residual\n" + rl.split("[")[-1].join(["[", ""]))
    axr.set_xlabel(xl)
    fig.tight_layout()
    return fig


def validate_chart(comparisons, path, title="") -> Path:
    """Write :func:`validate_figure` into ``path`` (PNG at 120 dpi); returns it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(validate_figure(comparisons, title), path, dpi=120)


def validate_figure(comparisons, title=""):
    """Model against data, one panel per measured quantity (a
    :class:`matplotlib.figure.Figure`)."""
    from matplotlib.figure import Figure

    n = len(comparisons)
    fig = Figure(figsize=(5.2 * n, 4.2))
    axes = fig.subplots(1, n, squeeze=False)
    for ax, c in zip(axes[0], comparisons):
        x, xl = _d(c.x_name, c.x)
        y, yl = _d(c.quantity, c.data)
        m, _ = _d(c.quantity, c.model)
        order = np.argsort(x)
        ax.plot(x, y, "o", ms=4, color="0.45", label="data")
        ax.plot(x[order], m[order], "-", color="C3", lw=1.8, label="model")
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(f"{c.error_name.replace('_', ' ')} {c.error_percent:.1f} %", fontsize=10)
        ax.legend(frameon=False)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
