"""A cube's model spread on the figure-12 panels (``fidelity: spread``, docs/model.md s. 22).

Each coil index's curve gets range bars, from the lowest to the highest value of its
variable over the cube's model variants (``<var>_model_lo``/``_hi``), at a few radii and
one wrap angle; the bars of the coil indices sit side by side (a shaded band per coil index
overlapped the next one's into one grey area on the fig12 grid). A cube without a spread
draws nothing. The paper's worked examples name their range.
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..variables import VARIABLES, spread_name, to_display
from ._common import _COLOURS, _eq

__all__ = ["example_range", "legend_text", "model_bands", "spread_variants"]

#: Radii a panel draws range bars at (evenly over the grid).
BARS = 7


def spread_variants(ds) -> list[str]:
    """The variants of a cube's model spread (its ``model_spread`` attribute); [] without.
    At most 64 names of at most 64 characters are read (an edited attribute stays a line)."""
    value = ds.attrs.get("model_spread", "")
    words = str(value.decode() if isinstance(value, bytes) else value)[:64 * 65].split()
    return [w[:64] for w in words[:64]]


def _has(ds, var) -> bool:
    return spread_name(var, "lo") in ds and spread_name(var, "hi") in ds


def _bar_indices(n: int, count: int = BARS) -> np.ndarray:
    """``count`` radius indices of ``n``, evenly spread, the ends left out where there is
    room (a bar at the panel's edge is half hidden)."""
    if n <= count:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, count + 2)[1:-1]).astype(int))


def model_bands(ax, ds, var, sel, coils, wrap_angle, *, scale=1.0, everywhere=False,
                note_at=(0.99, 0.01)):
    """Draw each coil index's range of ``var`` over the cube's model variants at
    ``wrap_angle`` [rad] as vertical bars at a few radii; ``sel`` fixes the wall (and
    length).

    A bar is drawn where the cube's own design there is not strength-limited (on the solid
    curve, as the quantile bands), or, with ``everywhere``, at every radius chosen (the
    range-of-motion row). ``scale`` multiplies the display values (100: a fraction in %);
    ``note_at`` (axes fraction, None: no note) places the note naming the bars. Nothing
    without a spread; returns whether bars were drawn.
    """
    if not _has(ds, var):
        return False
    x = to_display("radius", ds["radius"].values)
    pick = _bar_indices(x.size)
    # the coil indices' bars side by side over half the gap between two bar radii
    gap = float(np.min(np.diff(x[pick]))) if pick.size > 1 else \
        (float(np.ptp(x)) or 1.0) / BARS
    names = [spread_name(var, "lo"), spread_name(var, "hi"), "limit"]
    cut = ds[names].sel(wrap_angle=wrap_angle, **sel).isel(radius=pick).load()
    n = len(coils)
    for k, c in enumerate(coils):
        one = cut.sel(coil_index=c)
        lo = scale * to_display(var, one[names[0]].values)
        hi = scale * to_display(var, one[names[1]].values)
        lim = one["limit"].values.astype(float)
        keep = np.isfinite(lo) & np.isfinite(hi)
        if not everywhere:
            keep &= np.isfinite(lim) & (lim != 1)
        if not keep.any():
            continue
        at = x[pick][keep] + (k - (n - 1) / 2) * (0.5 * gap / max(n, 1))
        colour = _COLOURS[k % len(_COLOURS)]
        ax.vlines(at, lo[keep], hi[keep], color=colour, lw=1.6, alpha=0.85, zorder=3.5)
        for edge in (lo[keep], hi[keep]):
            ax.plot(at, edge, ls="none", marker="_", ms=7, mew=1.6, color=colour,
                    alpha=0.85, zorder=3.5)
    if note_at is None:
        return True
    ax.text(*note_at, f"bars: range over {len(spread_variants(ds))} models at "
            f"{_eq('wrap_angle', wrap_angle)}", transform=ax.transAxes,
            ha="right" if note_at[0] > 0.5 else "left",
            va="bottom" if note_at[1] < 0.5 else "top", fontsize=7.5, color="0.3", zorder=8,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
    return True


def example_range(ds, var, at) -> str:
    """``" (models 0.0514-2.1 N)"``: the range of ``var`` over the cube's model spread at
    the design ``at`` (a ``.sel`` of grid values), "" without a spread."""
    if not _has(ds, var):
        return ""
    lo, hi = (float(to_display(var, ds[spread_name(var, side)].sel(**at)))
              for side in ("lo", "hi"))
    if not (np.isfinite(lo) and np.isfinite(hi)):
        return ""
    unit = VARIABLES[var].display
    return f" (models {lo:.3g}-{hi:.3g}{'' if unit == '1' else ' ' + unit})"


def legend_text(ds, wrap_angle) -> str:
    """The suptitle's lines on a cube's model spread, its bars drawn at ``wrap_angle``
    [rad] (wrapped), "" without one."""
    variants = spread_variants(ds)
    if not variants:
        return ""
    return "\n" + "\n".join(textwrap.wrap(
        f"bars at {_eq('wrap_angle', wrap_angle)}: the lowest to the highest value over "
        f"{len(variants)} model variants, {', '.join(variants)} (fidelity: spread)", 110))
