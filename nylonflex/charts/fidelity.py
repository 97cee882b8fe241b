"""The fidelity map: each variant's bend angle over the FE twin's, across two design axes.

Drawn from the fidelity dataset ``nylonflex verify`` writes beside a cube
(:mod:`nylonflex.fe.verify`), never from physics. One panel a model: the sampled designs
coloured by model/FE (1 is exact; below 1 the model bends too little), the 10 % and 25 %
bands outlined where three or more designs allow a triangulation.
"""

from __future__ import annotations

import numpy as np

from ..variables import label, to_display
from ._common import _figure

__all__ = ["fidelity_map", "stroke_fidelity_map"]

#: The bands drawn: |model/FE - 1| = 0.10 and 0.25.
BANDS = (0.10, 0.25)


def ratio_stats(ratio) -> dict | None:
    """The summary of model/FE bend-angle ratios [1] (their finite values): ``median``,
    ``min``, ``max``, ``within`` (how many within :data:`BANDS`\\[0] = 10 % of 1) and ``n``;
    None when none is finite. The one computation behind the map's titles, ``nylonflex
    verify``'s and ``info``'s summary lines and the explorer's (issue 46: they said 33 %
    and 29 %, one over both pressures, the other at p* alone)."""
    r = np.asarray(ratio, dtype=float).ravel()
    r = r[np.isfinite(r)]
    if not r.size:
        return None
    return {"median": float(np.median(r)), "min": float(r.min()), "max": float(r.max()),
            "within": int(np.sum(np.abs(r - 1.0) <= BANDS[0])), "n": int(r.size)}


def fidelity_map(fid, *, x="radius", y="wall_thickness", level=None, models=None):
    """Model/FE bend-angle ratio of every sampled design over axes ``x`` and ``y``.

    Parameters
    ----------
    fid : xarray.Dataset
        A fidelity dataset (``nylonflex verify``).
    x, y : str
        Design axes (radius, wall_thickness, length, coil_index, wrap_angle).
    level : float, optional
        The fraction of each design's p* to show (default the largest, p* itself).
    models : sequence of str, optional
        Models to draw (default every one in the dataset).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.colors as mcolors
    from matplotlib.tri import Triangulation

    if "stroke_pressure_ratio" in fid:  # nylonflex verify --drive stroke
        return stroke_fidelity_map(fid, x=x, models=models)
    models = list(fid["model"].values) if models is None else list(models)
    lv = float(fid["level"].values.max()) if level is None else float(level)
    fig, axes = _figure(1, len(models), size=(4.2 * len(models), 3.9))
    xs = np.asarray(to_display(x, fid[x].values), dtype=float)
    ys = np.asarray(to_display(y, fid[y].values), dtype=float)
    norm = mcolors.TwoSlopeNorm(vmin=0.4, vcenter=1.0, vmax=1.6)
    mappable = None
    missing = False
    for ax, model in zip(axes[0], models):
        r = fid["ratio"].sel(model=model).sel(level=lv, method="nearest").values.astype(float)
        ok = np.isfinite(r)
        if ok.sum() >= 3 and np.ptp(xs[ok]) > 0 and np.ptp(ys[ok]) > 0:
            try:
                tri = Triangulation(xs[ok], ys[ok])
                levels = sorted({1 - b for b in BANDS} | {1 + b for b in BANDS})
                cs = ax.tricontour(tri, r[ok], levels=levels, colors="0.25",
                                   linewidths=[1.2, 0.8, 0.8, 1.2], linestyles=
                                   ["--", "-", "-", "--"])
                ax.clabel(cs, fmt=lambda v: f"{v:.2f}", fontsize=7)
            except (ValueError, RuntimeError):
                pass  # collinear designs: no triangulation, points only
        mappable = ax.scatter(xs[ok], ys[ok], c=r[ok], cmap="RdBu", norm=norm, s=42,
                              edgecolors="0.2", linewidths=0.5)
        if (~ok).any():
            ax.scatter(xs[~ok], ys[~ok], marker="x", color="0.5", s=30)
            missing = True
        st = ratio_stats(r)
        within = 100 * st["within"] / st["n"] if st else 0.0
        med = st["median"] if st else float("nan")
        ax.set_title(f"{model}\nmedian {med:.2f}, {within:.0f} % within 10 %")
        ax.margins(0.06)
        ax.set_xlabel(label(fid[x]))
        ax.set_ylabel(label(fid[y]))
        ax.grid(alpha=0.3)
    cbar = fig.colorbar(mappable, ax=axes[0].tolist(), shrink=0.9)
    cbar.set_label("model / FE bend angle [1]")
    fig.suptitle(f"Model / FE bend angle: {fid.sizes['design']} designs at {lv:g} of their p*, "
                 f"FE mesh {fid.attrs.get('fe_mesh', '?')}; lines at 0.75, 0.9, 1.1, 1.25"
                 + ("\nx: no FE angle (the FE solve stalled at a large bend)"
                    if missing else ""), fontsize=10)
    return fig


#: The stroke-driven map's band: |model/twin - 1| <= 0.15.
STROKE_BAND = 0.15
#: Its panels: (ratio variable, quantity).
STROKE_PANELS = (("stroke_pressure_ratio", "pressure_max"),
                 ("stroke_bend_ratio", "bend_angle_max"),
                 ("stroke_force_ratio", "tip_force_max"))


def _minor_label(span):
    """A log axis's minor tick label: every one over less than a decade ``span`` [1], the
    2s and 5s of each decade up to three decades, none beyond (no two labels overlap)."""
    def text(v, _):
        if span < 10.0:
            return f"{v:g}"
        mantissa = round(v / 10.0 ** np.floor(np.log10(v)), 6)
        return f"{v:g}" if span < 1000.0 and mantissa in (2.0, 5.0) else ""
    return text


def stroke_fidelity_map(fid, *, x="radius", models=None):
    """The stroke-driven fidelity (``nylonflex verify --drive stroke``): a panel a quantity
    (pressure, bend, blocked force where solved), each model's ratio to the sealed twin at
    the design's full stroke [1] over design axis ``x``, the 1.0 line and a 15 % band."""
    from matplotlib.ticker import FuncFormatter

    models = list(fid["model"].values) if models is None else list(models)
    panels = [(r, q) for r, q in STROKE_PANELS if r in fid]
    fig, axes = _figure(1, len(panels), size=(4.4 * len(panels), 3.9))
    xs = np.asarray(to_display(x, fid[x].values), dtype=float)
    markers = "osD^v<>px*"
    for ax, (ratio, quantity) in zip(axes[0], panels):
        lo, hi = 1 - STROKE_BAND, 1 + STROKE_BAND
        ax.axhspan(1 - STROKE_BAND, 1 + STROKE_BAND, color="0.9", zorder=0,
                   label=f"within {100 * STROKE_BAND:.0f} %")
        ax.axhline(1.0, color="0.3", lw=1.0)
        for k, model in enumerate(models):
            r = fid[ratio].sel(model=model).values.astype(float)
            ok = np.isfinite(r)
            st = ratio_stats(r)
            med = f" (median {st['median']:.2f})" if st else " (no twin value)"
            ax.plot(xs[ok], r[ok], markers[k % len(markers)], ms=6, mfc="none", mew=1.2,
                    label=f"{model}{med}")
            if ok.any():
                lo, hi = min(lo, float(r[ok].min())), max(hi, float(r[ok].max()))
        # a log axis: a ratio and its inverse equally far from 1, a 10-fold error and the
        # band in one panel
        ax.set_yscale("log")
        ax.set_ylim(lo / 1.15, hi * 1.15)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(_minor_label(hi / lo)))
        ax.set_title(f"{quantity} / twin at s*")
        ax.set_xlabel(label(fid[x]))
        ax.set_ylabel("model / stroke-driven twin [1] (log)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"Models against the sealed, stroke-driven FE twin at each design's full "
                 f"stroke s*: {fid.sizes['design']} designs, FE mesh "
                 f"{fid.attrs.get('fe_mesh', '?')}; band at 0.85-1.15", fontsize=10)
    return fig
