"""The explorer page's views, each a group of Bokeh models built from the page's payload.

:func:`~.page.build_document` puts them on the page and hands them to ``update.js``, which
draws every one of them in the browser from one state: the widgets that hold that state
(:func:`state_widgets`), the map (:func:`map_view`), the figure-12 lines
(:func:`lines_view`), the picked design's curves (:func:`curve_views`), the table of the
designs that meet ``--where`` (:func:`where_view`) and the map's key to the flagged
designs (:func:`flag_key`). The ones ``update.js`` reads are returned under the names it
reads them by. Bokeh is imported only when a view is built.
"""

from __future__ import annotations

import html
from importlib.resources import files

from ..variables import AXES, label, name_label
from .data import flag_meanings

#: Flagged designs (``validity`` != 0): grey, as on the charts.
FLAG_GREY = "#9e9e9e"
#: The colours of the lines (one a coil index) and of the curves (one a curve).
COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
           "#000000")
#: The curves a page draws for the picked design: name -> (its x axis, the design axes it
#: varies over).
CURVES = {"nylon_force": ("stroke", ("radius", "wall_thickness", "coil_index", "wrap_angle")),
          "bend_angle": ("pressure", ("radius", "wall_thickness", "length")),
          "tip_force": ("pressure", ("radius", "wall_thickness", "length"))}


def script(name: str) -> str:
    """The text of one of the page's scripts (``update.js``, ``pick.js``)."""
    return files(__package__).joinpath(name).read_text(encoding="utf-8")


def state_widgets(ds, p, default_var):
    """The widgets that hold the page's whole state: ``variable`` (opened on the variable
    of index ``default_var``), ``model`` (None for a cube of one model), ``map_x``,
    ``map_y`` and a slider an axis (``sliders``, opened on the payload's first design)."""
    from bokeh.models import CustomJSTickFormatter, RadioButtonGroup, Select, Slider

    variables, models, sizes = p["variables"], p["models"], p["sizes"]
    variable = Select(title="variable (map, lines and read-out)", width=280,
                      options=[(str(i), label(ds[n])) for i, n in enumerate(variables)],
                      value=str(default_var), name="nf-variable")
    model = RadioButtonGroup(labels=models, active=0, name="nf-model") if models else None
    axis_options = [(a, label(ds[a])) for a in AXES]
    map_x = Select(title="map across", options=axis_options, value="radius", width=135,
                   name="nf-map-x")
    map_y = Select(title="map up", options=axis_options, value="wall_thickness", width=135,
                   name="nf-map-y")
    sliders = {}
    for j, a in enumerate(AXES):
        start = p["first"][a]
        fmt = CustomJSTickFormatter(args={"labels": p["labels"][a]},
                                    code="return labels[Math.round(tick)] || '';")
        sliders[a] = Slider(start=0, end=max(1, sizes[j] - 1), step=1, value=start,
                            title=label(ds[a]).split(" [")[0], format=fmt, width=280,
                            disabled=sizes[j] < 2, name=f"nf-slider-{a}",
                            css_classes=[f"nf-slider-{a}"])
    return {"variable": variable, "model": model, "map_x": map_x, "map_y": map_y,
            "sliders": sliders}


def map_view(ds, p, shown):
    """The map of the shown variable ``shown`` (its name) over two axes, its cells laid out
    by ``update.js`` for the chosen axes: ``map_src`` (the cells), ``mapper``, ``map_fig``
    with its axes ``map_xaxis`` and ``map_yaxis``, ``hover``, ``colorbar``, ``match_src``
    (the designs meeting ``--where``) and ``star`` (the picked design)."""
    from bokeh.models import (ColorBar, ColumnDataSource, HoverTool, LinearColorMapper,
                              TapTool)
    from bokeh.plotting import figure

    map_src = ColumnDataSource({k: [] for k in ("left", "right", "bottom", "top", "z", "zc",
                                                "h", "hc", "vf", "xv", "yv")},
                               name="nf-map")
    # flagged cells: zc is NaN there, so they take the mapper's grey, never a scale colour
    mapper = LinearColorMapper(palette="Viridis256", low=0, high=1, nan_color=FLAG_GREY)
    map_fig = figure(height=400, min_width=380, sizing_mode="stretch_width",
                     tools="tap,reset,save", name="nf-map-figure",
                     x_axis_label=label(ds["radius"]), y_axis_label=label(ds["wall_thickness"]),
                     x_range=(p["edges"]["radius"][0], p["edges"]["radius"][-1]),
                     y_range=(p["edges"]["wall_thickness"][0],
                              p["edges"]["wall_thickness"][-1]))
    cells = map_fig.quad(source=map_src, left="left", right="right", bottom="bottom",
                         top="top", fill_color={"field": "zc", "transform": mapper},
                         line_color=None, hatch_pattern="h", hatch_color="hc",
                         hatch_alpha=0.8, hatch_scale=8, nonselection_fill_alpha=1.0,
                         selection_fill_alpha=1.0)
    hover = HoverTool(renderers=[cells], tooltips=[(label(ds[shown]), "@z{0.000}")])
    map_fig.add_tools(hover)
    colorbar = ColorBar(color_mapper=mapper, width=12, title=label(ds[shown]))
    map_fig.add_layout(colorbar, "right")
    match_src = ColumnDataSource({"x": [], "y": []}, name="nf-match")
    if p["match"] is not None:
        map_fig.scatter("x", "y", source=match_src, marker="circle", size=6,
                        fill_color="white", line_color="black",
                        legend_label="meets --where: " + "; ".join(p["where"]))
        map_fig.add_layout(map_fig.legend[0], "below")  # not over the cells
    star = ColumnDataSource({"x": [], "y": [], "design": []}, name="nf-star")
    map_fig.scatter("x", "y", source=star, marker="star", size=20, fill_color="gold",
                    line_color="black")
    map_fig.select_one(TapTool).mode = "replace"
    return {"map_src": map_src, "mapper": mapper, "map_fig": map_fig,
            "map_xaxis": map_fig.xaxis[0], "map_yaxis": map_fig.yaxis[0], "hover": hover,
            "colorbar": colorbar, "match_src": match_src, "star": star}


def lines_view(ds, p):
    """The figure-12 lines against the radius, one a coil index: ``lines_fig`` and its
    ``lines_yaxis``, a dashed (``line_srcs``) and a solid (``solid_srcs``, full range of
    motion) line a coil index, and the flagged designs' grey points (``flag_pts``)."""
    from bokeh.models import ColumnDataSource, Range1d, Title
    from bokeh.plotting import figure

    # explicit ranges, set by update.js from the valid designs (an auto range would take
    # in the flagged ones, and starts empty: "could not set initial ranges")
    lines_fig = figure(height=400, min_width=380, sizing_mode="stretch_width",
                       x_axis_label=label(ds["radius"]), tools="pan,box_zoom,reset,save",
                       x_range=Range1d(p["gx"]["radius"][0], p["gx"]["radius"][-1]),
                       y_range=Range1d(0, 1), name="nf-lines-figure")
    line_srcs, solid_srcs = [], []
    for k, c in enumerate(p["gx"]["coil_index"]):
        colour = COLOURS[k % len(COLOURS)]
        line_srcs.append(ColumnDataSource({"x": [], "y": []}))
        solid_srcs.append(ColumnDataSource({"x": [], "y": []}))
        lines_fig.line("x", "y", source=line_srcs[-1], color=colour, line_dash="dashed",
                       legend_label=f"C = {c:.3g}")
        lines_fig.line("x", "y", source=solid_srcs[-1], color=colour, line_width=3)
    flag_pts = ColumnDataSource({"x": [], "y": []}, name="nf-lines-flagged")
    if p["validity"] is not None:
        lines_fig.scatter("x", "y", source=flag_pts, size=7, color=FLAG_GREY, alpha=0.8,
                          legend_label="flagged design (grey)")
    lines_fig.legend.location = "top_left"
    lines_fig.add_layout(Title(text="solid: full range of motion; dashed: strength-limited",
                               text_font_style="italic", text_font_size="11px"), "above")
    return {"lines_fig": lines_fig, "lines_yaxis": lines_fig.yaxis[0],
            "line_srcs": line_srcs, "solid_srcs": solid_srcs, "flag_pts": flag_pts}


def curve_views(ds, p):
    """The picked design's curves (:data:`CURVES`, those the cube holds): their figures in
    order (``figures``, not read by ``update.js``), by name (``curve_figs``), their
    sources by name (``curve_srcs``) and the nylon force's limit line (``flim_span``; None
    without it)."""
    from bokeh.models import ColumnDataSource, Range1d, Span
    from bokeh.plotting import figure

    titles = {"nylon_force": "nylon force vs stroke (dashed: its limit)",
              "bend_angle": "bend angle against chamber pressure",
              "tip_force": "tip force against chamber pressure"}
    curve_figs, curve_srcs, curve_by_name = [], {}, {}
    for k, (name, (axis, _)) in enumerate(CURVES.items()):
        if name not in p["curves"]:
            continue
        xs = p["curves"][name]["x"]
        f = figure(height=280, min_width=300, sizing_mode="stretch_width", title=titles[name],
                   x_axis_label=label(ds[axis]), y_axis_label=label(ds[name]),
                   tools="pan,box_zoom,reset,save", x_range=Range1d(min(xs), max(xs)),
                   y_range=Range1d(0, 1))
        src = ColumnDataSource({"x": [], "y": [], "design": []}, name=f"nf-curve-{name}")
        f.line("x", "y", source=src, color=COLOURS[k], line_width=2)
        curve_figs.append(f)
        curve_srcs[name] = src
        curve_by_name[name] = f
    flim_span = None
    if p["flim"] is not None and "nylon_force" in curve_srcs:
        flim_span = Span(location=0, dimension="width", line_dash="dashed", line_color="black")
        curve_figs[0].add_layout(flim_span)
    return {"figures": curve_figs, "curve_figs": curve_by_name, "curve_srcs": curve_srcs,
            "flim_span": flim_span}


def where_view(ds, p, pick_args, max_rows):
    """The designs that meet ``--where``: a note and a sortable table whose rows pick their
    design (``pick.js`` with ``pick_args``), at most ``max_rows`` of them listed; [] for a
    page without conditions."""
    from bokeh.models import (ColumnDataSource, CustomJS, DataTable, Div, NumberFormatter,
                              TableColumn)

    if p["rows"] is None:
        return []
    rows = p["rows"]
    rows_src = ColumnDataSource(rows["data"], name="nf-where-rows")
    columns = []
    for n in rows["columns"]:
        title = label(ds[n]) if n in ds.variables else name_label(n)
        fmt = {} if n in ("model", "validity") else \
            {"formatter": NumberFormatter(format="0.[000]")}
        # wide enough for its whole title (the table scrolls sideways, not the page)
        columns.append(TableColumn(field=n, title=title, width=_title_width(title), **fmt))
    where_table = DataTable(source=rows_src, columns=columns, sizing_mode="stretch_width",
                            height=260, autosize_mode="none", sortable=True,
                            reorderable=False,
                            index_position=None, name="nf-where-table")
    rows_src.selected.js_on_change("indices", CustomJS(args={**pick_args, "rows": rows_src},
                                                       code=script("pick.js")))
    listed = min(rows["matching"], max_rows)
    return [Div(sizing_mode="stretch_width", name="nf-where-note", text=(
        f"<b>{rows['matching']:,} designs of this page meet --where "
        f"{html.escape(' and '.join(p['where']))}</b>"
        + (f" (the first {listed:,} in grid order listed; sorting sorts those)"
           if listed < rows["matching"] else "")
        + ": click a column's title to sort, a row to pick that design; the map marks "
        "the matching designs of its slice with a white dot.")), where_table]


def _title_width(title) -> int:
    """A table column wide enough for its title [px] (about 7 px a character)."""
    return max(70, 7 * len(title) + 24)


def flag_key(ds, p):
    """The map's key: grey, hatched / for a flagged design (its flags named), x for a
    strength-limited one; empty where the cube has no ``validity``."""
    from bokeh.models import Div

    return Div(sizing_mode="stretch_width", name="nf-map-key", text=(
        "<span style='font-size:12px'><span style='display:inline-block;width:14px;"
        f"height:10px;background:{FLAG_GREY};border:1px solid #555'></span> grey, hatched "
        "/: flagged design (" + ", ".join(m.replace("_", " ") for _, m in
                                          flag_meanings(ds)) + "), not on the colour scale"
        "; x: strength-limited</span>") if p["validity"] is not None else "")
