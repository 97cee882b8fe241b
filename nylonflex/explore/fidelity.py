"""The explorer's fidelity part: where ``nylonflex verify`` has held the cube's designs
against the FE twin, the page lists them with each model's ratio to FE.

The verified designs are a space-filling sample, not grid points, so they are a table of
their own (sortable, a row per design and pressure) under a summary line per model,
rather than values on the map, which shows grid designs only.
"""

from __future__ import annotations

import html

import numpy as np

from ..fe.verify import fidelity_stats
from ..variables import label
from .data import display_unit, to_display_any

__all__ = ["fidelity_rows", "fidelity_summary_html", "fidelity_widgets"]

_AXES = ("radius", "wall_thickness", "length", "coil_index", "wrap_angle")


def fidelity_rows(ds, fid) -> dict:
    """The table's columns (display units) of a fidelity dataset ``fid`` of cube ``ds``:
    one row a design and pressure level, with the FE angle and each model's ratio."""
    n_level = fid.sizes["level"]
    rows = {}
    for a in _AXES:
        rows[a] = np.repeat(np.asarray(to_display_any(ds, a, fid[a].values), float), n_level)
    rows["pressure"] = np.asarray(to_display_any(ds, "pressure", fid["pressure"].values),
                                  float).ravel()
    rows["fe_bend_angle"] = np.degrees(fid["fe_bend_angle"].values.ravel())
    for model in fid["model"].values:
        rows[f"ratio_{model}"] = fid["ratio"].sel(model=model).values.ravel()
    return {k: np.where(np.isfinite(v), v, np.nan).tolist() for k, v in rows.items()}


def fidelity_summary_html(fid, source: str) -> str:
    """The fidelity part's heading: per model, model/FE over every verified angle."""
    parts = [f"<code>{html.escape(st['model'])}</code> median {st['median']:.3f} "
             f"({st['min']:.3f}-{st['max']:.3f}), {st['within']} of {st['n']} within 10 %"
             for st in fidelity_stats(fid)]
    return (f"<b>FE fidelity</b> ({html.escape(source)}: {fid.sizes['design']} designs held "
            f"against the FE twin by <code>nylonflex verify</code>, mesh "
            f"{html.escape(str(fid.attrs.get('fe_mesh', '?')))}): model / FE bend angle at "
            "the same pressure, " + "; ".join(parts) + ". A row a design and pressure "
            "(half and all of its pressure_max); click a title to sort.")


def fidelity_widgets(ds, fid, source: str = "") -> list:
    """Bokeh models of the fidelity part: a heading and a sortable table."""
    from bokeh.models import ColumnDataSource, DataTable, Div, NumberFormatter, TableColumn

    rows = fidelity_rows(ds, fid)
    columns = []
    for name in rows:
        if name.startswith("ratio_"):
            title = f"{name[len('ratio_'):]} / FE"
            fmt = "0.000"
        elif name == "fe_bend_angle":
            title, fmt = "FE bend angle [deg]", "0.0"
        elif name == "pressure":
            title, fmt = f"pressure [{display_unit(ds, 'pressure')}]", "0.00"
        else:
            title, fmt = label(ds[name]), "0.[00]"
        columns.append(TableColumn(field=name, title=title,
                                   formatter=NumberFormatter(format=fmt, nan_format="-")))
    table = DataTable(source=ColumnDataSource(rows, name="nf-fidelity-rows"), columns=columns,
                      sizing_mode="stretch_width", height=240, sortable=True, reorderable=False, index_position=None,
                      name="nf-fidelity-table")
    return [Div(sizing_mode="stretch_width", name="nf-fidelity-note", text=fidelity_summary_html(fid, source)),
            table]
