"""Charts of a closed-loop simulation: the paper's figure 9 and figure 10(a).

Drawn from the simulation Dataset only (no physics here), each a
:class:`matplotlib.figure.Figure` made without pyplot (the caller's backend untouched).
Axes are labelled in the units a designer reads: deg, s, kPa, W.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from ..files.atomic import save_figure

__all__ = ["draw_simulation_charts", "figure9", "figure10a"]


def _config_reference_kind(ds, j=0):
    try:
        return yaml.safe_load(ds.attrs["config"])["actuators"][j]["reference"]["kind"]
    except Exception:  # noqa: BLE001 - a chart without the config's label still draws
        return ""


def _design_line(ds, j=0):
    """``"control: a 7.5 mm, t 2 mm, L 70 mm, C 1.7, psi 8 deg, 12 V"`` from the config."""
    try:
        cfg = yaml.safe_load(ds.attrs["config"])
        d = cfg["actuators"][j]["design"]
        return (f"{cfg['name']}: a {d['radius'] * 1e3:g} mm, t {d['wall_thickness'] * 1e3:g} mm, "
                f"L {d['length'] * 1e3:g} mm, C {d['coil_index']:g}, "
                f"\u03c8 {math.degrees(d['wrap_angle']):.3g} deg, "
                f"{cfg['supply']['voltage']:g} V")
    except Exception:  # noqa: BLE001 - a chart without the design line still draws
        return ""


def _running_mean(t, x, window):
    """Mean of ``x`` over the last ``window`` seconds at each time (a display aid)."""
    dt = t[1] - t[0] if t.size > 1 else 1.0
    n = max(1, int(round(window / dt)))
    c = np.concatenate([[0.0], np.cumsum(x)])
    i = np.arange(1, x.size + 1)
    lo = np.maximum(i - n, 0)
    return (c[i] - c[lo]) / (i - lo)


def figure9(ds):
    """Figure 9: bend angle, its estimate and the reference against time, with the heating.

    Parameters
    ----------
    ds : xarray.Dataset
        A single-actuator simulation (dims ``time``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    t = ds["time"].values
    fig = Figure(figsize=(7.5, 5.2))
    ax, axp = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    ax.plot(t, np.degrees(ds["bend_angle"].values), color="C0", lw=2.4, label="bend angle")
    ax.plot(t, np.degrees(ds["bend_angle_estimate"].values), color="C1", lw=0.9, ls=":",
            label="estimate from pressure")
    ax.plot(t, np.degrees(ds["bend_angle_reference"].values), color="k", ls="--", lw=1.0,
            label="reference", zorder=5)
    ax.set_ylabel("bend angle [deg]")
    ax.grid(alpha=0.3)
    kind = _config_reference_kind(ds)
    a = ds.attrs
    if kind == "step":
        rise = a.get("rise_time", math.nan)
        rise_s = "not reached" if math.isnan(rise) else f"{rise:.2f} s"
        title = f"Step response: rise time (10-90 %) {rise_s}, overshoot " \
                f"{100 * a.get('overshoot', math.nan):.2f} %"
    else:
        # the fraction is of the reference's size: a sine's amplitude, a schedule's range
        size = {"sine": "amplitude", "schedule": "range"}.get(kind, "reference's size")
        rms, frac = a.get("rms_error", math.nan), a.get("rms_error_fraction", math.nan)
        of = f"{math.degrees(rms / frac):.0f} deg {size}" if frac > 0 else size
        title = f"Tracking: RMS error {math.degrees(rms):.2f} deg " \
                f"({100 * frac:.1f} % of the {of})"
    ax.set_title(f"{_design_line(ds)}\n{title}", fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    power = ds["power"].values
    # bang-bang at 10 ms is a blur at this scale: show the switching faintly and its 1 s mean
    axp.fill_between(t, power, step="post", color="C3", alpha=0.15, lw=0, label="switched")
    axp.plot(t, _running_mean(t, power, 1.0), color="C3", lw=1.2, label="1 s mean")
    axp.legend(loc="upper right", fontsize=7, ncol=2)
    axp.set_ylabel("heating [W]")
    axp.set_xlabel("time [s]")
    axp.set_ylim(0, max(float(ds["power"].max()) * 1.5, 0.1))  # room for the legend
    axp.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def figure10a(ds):
    """Figure 10(a): each actuator's chamber pressure against time, for a gripper run.

    Below the pressures, each actuator's angle against its reference and the power drawn
    from the shared supply.

    Parameters
    ----------
    ds : xarray.Dataset
        A simulation with dims (``actuator``, ``time``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    t = ds["time"].values
    fig = Figure(figsize=(7.5, 7.0))
    axp, axa, axw = fig.subplots(3, 1, sharex=True,
                                 gridspec_kw={"height_ratios": [3, 2, 1.2]})
    for j, name in enumerate(ds["actuator"].values):
        c = f"C{j}"
        axp.plot(t, ds["pressure"].values[j] / 1e3, color=c, lw=1.6, label=str(name))
        axa.plot(t, np.degrees(ds["bend_angle"].values[j]), color=c, lw=1.4)
        axa.plot(t, np.degrees(ds["bend_angle_reference"].values[j]), color=c, lw=1.0,
                 ls="--")
    axp.set_ylabel("chamber pressure [kPa]")
    axp.set_title(f"Gripper on one {ds.attrs.get('supply_voltage', math.nan):g} V supply: "
                  f"peak current {1e3 * ds.attrs.get('supply_current_max', math.nan):.0f} mA",
                  fontsize=10)
    axp.legend(loc="upper right", fontsize=8)
    axp.grid(alpha=0.3)
    axa.set_ylabel("bend angle [deg]\n(dashed: reference)")
    axa.grid(alpha=0.3)
    total = ds["power"].values.sum(axis=0)
    axw.fill_between(t, total, step="post", color="C3", alpha=0.15, lw=0)
    axw.plot(t, _running_mean(t, total, 1.0), color="C3", lw=1.2)
    axw.set_ylabel("supply power [W]\n(line: 1 s mean)")
    axw.set_xlabel("time [s]")
    axw.set_ylim(0, max(float(total.max()) * 1.15, 0.1))
    axw.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def draw_simulation_charts(ds, folder, stem="sim"):
    """Draw the charts of a run into ``folder``: ``<stem>_figure9.png`` for one actuator,
    ``<stem>_figure10a.png`` for several. Returns the paths written."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if "actuator" in ds.dims:
        return [save_figure(figure10a(ds), folder / f"{stem}_figure10a.png", dpi=130)]
    return [save_figure(figure9(ds), folder / f"{stem}_figure9.png", dpi=130)]
