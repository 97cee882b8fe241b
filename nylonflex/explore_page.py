"""The explorer's page: Panel widgets and HoloViews (bokeh) plots over a lazily read cube.

Built with HoloViz Panel and HoloViews, which serve xarray-backed data as interactive pages
and export them as static HTML with the widgets' states embedded. Every view reads only its
slice through :mod:`nylonflex.explore`; every number is a grid value of the cube, never an
interpolation.

Two forms of the same page:

* served (``nylonflex explore CUBE``): every axis has a slider, the map's two axes are
  chosen, and a click on the map picks the design (snapped to the nearest grid point);
* static (``--html``): the variable and the sliders of the axes the map does not show are
  embedded, each with a bounded set of grid values (:data:`STATIC_MAX_STATES` in all); the
  map shows radius against wall thickness and the picked design is fixed. The page says so.

Stable hooks for tests and scripts: the element ``#nf-readout`` carries ``data-variable``,
``data-value`` (display units) and ``data-unit``; each row of ``#nf-design`` carries
``data-name`` and ``data-value``.
"""

from __future__ import annotations

import html
import math

import numpy as np

from .explore import (_index, axis_text, colour_range, design_config, design_curves,
                      design_table,
                      design_variables, display_unit, fig12_lines, flag_meanings, label,
                      map_slice, snap, stand_in_note, validity_names)
from .variables import AXES

#: The most widget states an exported page embeds (variable x embedded sliders).
STATIC_MAX_STATES = 400
#: The default design: the paper's second worked example, at the nearest grid point [SI].
DEFAULT_DESIGN = {"radius": 15e-3, "wall_thickness": 2e-3, "length": 90e-3,
                  "coil_index": 1.7, "wrap_angle": math.radians(8.0)}
_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
            "#000000")
_FLAG_MARKERS = ("circle", "square", "triangle", "diamond", "inverted_triangle", "hex")
_PLOT = {"width": 460, "height": 330}


_SYMBOL = {"radius": "a", "wall_thickness": "t", "length": "L", "coil_index": "C",
           "wrap_angle": "\u03c8"}


def _held(ds, at, axes) -> str:
    """``"t 2 mm, L 90 mm, psi 8 deg"``: the held axes of a view, for its title."""
    text = ", ".join(f"{_SYMBOL[k]} = {axis_text(ds, k, at[k])}" for k in axes)
    return text + (f", model {at['model']}" if "model" in at else "")


def _fmt(value: float) -> str:
    return "nan" if not np.isfinite(value) else f"{value:.4g}"


def _slider_options(ds, axis, limit=None) -> dict:
    """``{"7.5 mm": 0.0075, ...}``: the grid values of an axis (at most ``limit`` of them,
    evenly spread, ends and the default design's value kept)."""
    values = [float(v) for v in ds[axis].values]
    if limit is not None and len(values) > limit:
        keep = set(np.round(np.linspace(0, len(values) - 1, limit)).astype(int).tolist())
        keep.add(snap(ds, axis, DEFAULT_DESIGN[axis]).index)
        values = [values[i] for i in sorted(keep)]
    return {axis_text(ds, axis, v): v for v in values}


def _static_limits(ds) -> dict:
    """Values per embedded slider so that variables x sliders stays within the budget."""
    n_var = len(design_variables(ds)) * (ds.sizes["model"] if "model" in ds.dims else 1)
    axes = ("length", "coil_index", "wrap_angle")
    per = max(1, int((STATIC_MAX_STATES / n_var) ** (1 / len(axes))))
    out = {a: min(ds.sizes[a], per) for a in axes}
    # spend what is left on the axes cut shortest
    for a in sorted(axes, key=lambda a: ds.sizes[a] - out[a], reverse=True):
        while out[a] < ds.sizes[a] and n_var * math.prod(
                out[b] + (b == a) for b in axes) <= STATIC_MAX_STATES:
            out[a] += 1
    return out


def _map_plot(ds, var, x, y, at, hv):
    m = map_slice(ds, var, x, y, at)
    ttl = _held(ds, at, [k for k in AXES if k not in (x, y)])
    xs, ys = np.meshgrid(m["x"], m["y"])
    # hover and colour bar named with the variable and its unit; the colour scale set by
    # the clean designs (a flagged 1 mm wall bending 1,300 deg would wash out the rest)
    value = hv.Dimension(var, label=label(ds, var).split(" [")[0],
                         unit=None if display_unit(ds, var) == "1" else display_unit(ds, var))
    qm = hv.QuadMesh((m["x"], m["y"], m["z"]), kdims=[label(ds, x), label(ds, y)],
                     vdims=[value]).opts(
        cmap="viridis", colorbar=True, tools=["hover"], title=f"{label(ds, var)}\n"
        f"at {ttl}", framewise=True, clim=colour_range(m["z"], m["validity"]),
        clabel=label(ds, var), **_PLOT, toolbar="above")
    layers = [qm]
    if m["limit"] is not None:
        strong = m["limit"] == 1
        layers.append(hv.Points((xs[strong], ys[strong]), kdims=[label(ds, x), label(ds, y)],
                                label="strength-limited (x): the nylon breaks first").opts(
            marker="x", color="white", line_width=1 if len(m["x"]) > 60 else 1.5,
            size=int(np.clip(300 / max(len(m["x"]), len(m["y"]), 1), 2, 7))))
    if m["validity"] is not None:
        bits = np.nan_to_num(m["validity"].astype(float)).astype(np.int64)
        for k, (mask, meaning) in enumerate(flag_meanings(ds)):
            hit = (bits & mask) != 0
            layers.append(hv.Points((xs[hit], ys[hit]), kdims=[label(ds, x), label(ds, y)],
                                    label=f"flagged: {meaning.replace('_', ' ')}").opts(
                marker=_FLAG_MARKERS[k % len(_FLAG_MARKERS)], fill_alpha=0, color="#D55E00",
                size=9, line_width=1.5))
    px, py = float(_display(ds, x, at[x])), float(_display(ds, y, at[y]))
    layers.append(hv.Points(([px], [py]), kdims=[label(ds, x), label(ds, y)],
                            label="selected design").opts(
        marker="star", size=18, color="gold", line_color="black"))
    return hv.Overlay(layers).opts(legend_position="bottom", legend_cols=1,
                                   height=_PLOT["height"] + 90)


def _lines_plot(ds, var, at, hv):
    data = fig12_lines(ds, var, at)
    x = data["radius"]
    curves = []
    for k, (c, (values, strong)) in enumerate(data["lines"].items()):
        colour = _COLOURS[k % len(_COLOURS)]
        solid = np.where(strong, np.nan, values)
        curves.append(hv.Curve((x, values), label(ds, "radius"), label(ds, var),
                               label=f"C = {c:g}").opts(color=colour, line_dash="dashed",
                                                        line_width=1))
        curves.append(hv.Curve((x, solid), label(ds, "radius"), label(ds, var)).opts(
            color=colour, line_width=3))
    held = _held(ds, at, [k for k in AXES if k not in ("radius", "coil_index")])
    return hv.Overlay(curves).opts(
        title=f"Figure 12 style at {held}\nsolid: full range of motion; dashed: "
              "strength-limited", legend_position="top_left", framewise=True, **_PLOT)


def _curves_plot(ds, at, hv):
    c = design_curves(ds, at)
    plots = []
    if "nylon_force" in c:
        x, y = c["nylon_force"]
        p = hv.Curve((x, y), label(ds, "stroke"), label(ds, "nylon_force"),
                     label="nylon force").opts(color=_COLOURS[0], line_width=2)
        if "nylon_force_limit" in c:
            p = p * hv.HLine(c["nylon_force_limit"], label="strength limit").opts(
                color="black", line_dash="dashed")
        plots.append(p.opts(title="nylon force vs stroke (dashed: its limit)", width=400, height=280))
    for name in ("bend_angle", "tip_force"):
        if name in c:
            x, y = c[name]
            plots.append(hv.Curve((x, y), label(ds, "pressure"), label(ds, name)).opts(
                color=_COLOURS[1 if name == "bend_angle" else 2], line_width=2,
                title=f"{label(ds, name).split(' [')[0]} against chamber pressure",
                width=400, height=280))
    return hv.Layout(plots).cols(3) if plots else hv.Div("no curves in this cube")


def _readout_html(ds, var, at, notes) -> str:
    point = {r["name"]: r for r in design_table(ds, at)}
    row = point[var]
    unit = "" if row["unit"] == "1" else f" {row['unit']}"
    where = ", ".join(f"{k} {axis_text(ds, k, at[k])}" for k in AXES)
    if "model" in at:
        where += f", model {at['model']}"
    text = (f'<div id="nf-readout" class="nf-readout" data-variable="{var}" '
            f'data-value="{row["value"]!r}" data-unit="{html.escape(row["unit"])}" '
            f'style="font-size:15px">{html.escape(label(ds, var).split(" [")[0])} of the '
            f'selected design: <b>{_fmt(row["value"])}{html.escape(unit)}</b>'
            f'<br><span style="color:#555">design: {html.escape(where)}</span>')
    if "validity" in ds:
        index = {k: v for k, v in _index(ds, at).items() if k in ds["validity"].dims}
        bits = float(ds["validity"].isel(index).values)
        text += (f'<br><span id="nf-validity" data-value="{bits:g}">validity: '
                 f'<b>{html.escape(validity_names(ds, bits))}</b></span>')
    for note in notes:
        text += f'<br><span class="nf-snap" style="color:#a0522d">{html.escape(note)}</span>'
    if "config_yaml" in ds.attrs:
        text += ('<details style="font-size:12px"><summary>copy as config (a sweep of this '
                 'design)</summary><pre id="nf-config">'
                 f'{html.escape(design_config(ds, at))}</pre></details>')
    return text + "</div>"


def _table_html(ds, at) -> str:
    rows = "".join(
        f'<tr data-name="{r["name"]}" data-value="{r["value"]!r}"><td>{html.escape(r["label"])}'
        f'</td><td style="text-align:right"><b>{_fmt(r["value"])}</b></td></tr>'
        for r in design_table(ds, at))
    return ('<table id="nf-design" style="border-collapse:collapse;font-size:13px">'
            '<tr><th style="text-align:left">every design variable of the selected design'
            f'</th><th>value</th></tr>{rows}</table>'
            '<div style="font-size:12px;color:#555">limit: 0 stroke-limited (full range of '
            'motion), 1 strength-limited (the nylon breaks first)</div>')


def build_page(ds, *, static: bool = False, source: str = ""):
    """The explorer page of a cube: a Panel layout.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube, opened lazily (:func:`nylonflex.open_cube`).
    static : bool
        Build the reduced page for a self-contained HTML file (embedded widget states).
    source : str
        The cube's path, named in the header.

    Returns
    -------
    (panel.viewable.Viewable, dict)
        The page, and for ``static`` the ``embed_states`` to pass to ``save`` (empty when
        served).
    """
    import holoviews as hv
    import panel as pn

    hv.extension("bokeh", logo=False)
    pn.extension(sizing_mode="fixed")

    variables = design_variables(ds)
    var_options = {label(ds, n): n for n in variables}
    default_var = "tip_force_max" if "tip_force_max" in variables else variables[0]
    w_var = pn.widgets.Select(label="variable (map, lines and read-out)", options=var_options,
                              value=default_var, width=300)
    widgets = [w_var]
    w_model = None
    if "model" in ds.dims:
        models = [str(m) for m in ds["model"].values]
        w_model = pn.widgets.Select(label="model variant", options=models, value=models[0],
                                    width=300)
        widgets.append(w_model)

    limits = _static_limits(ds) if static else {}
    sliders, embed_states = {}, {}
    for axis in AXES:
        if static and axis in ("radius", "wall_thickness"):
            continue
        opts = _slider_options(ds, axis, limits.get(axis))
        default = snap(ds, axis, DEFAULT_DESIGN[axis]).value
        value = min(opts.values(), key=lambda v: abs(v - default))
        sliders[axis] = pn.widgets.DiscreteSlider(label=label(ds, axis), options=opts,
                                                  value=value, width=300)
        if static:
            embed_states[sliders[axis]] = list(opts.values())
    if static:
        embed_states[w_var] = list(var_options.values())
        if w_model is not None:
            embed_states[w_model] = list(w_model.options)
    fixed = {a: snap(ds, a, DEFAULT_DESIGN[a]).value for a in ("radius", "wall_thickness")}

    if static:
        w_x = w_y = None
        x_axis, y_axis = "radius", "wall_thickness"
    else:
        w_x = pn.widgets.Select(label="map across", options={label(ds, a): a for a in AXES},
                                value="radius", width=145)
        w_y = pn.widgets.Select(label="map up", options={label(ds, a): a for a in AXES},
                                value="wall_thickness", width=145)
    notes = pn.widgets.StaticText(value="", visible=False)  # the last click's snap note

    def at_of(values, model):
        at = dict(fixed) if static else {}
        at.update(values)
        if model is not None:
            at["model"] = model
        return at

    slider_list = list(sliders.values())

    def _at(*values, model=None):
        return at_of(dict(zip(sliders, values)), model)

    model_arg = {"model": w_model} if w_model is not None else {}

    def readout(var, *values, model=None, note=""):
        return _readout_html(ds, var, _at(*values, model=model), [note] if note else [])

    def table(*values, model=None):
        return _table_html(ds, _at(*values, model=model))

    def map_view(var, x, y, *values, model=None):
        if x == y:
            return hv.Div(f"<p>choose two different axes for the map (both are {x})</p>")
        return _map_plot(ds, var, x, y, _at(*values, model=model), hv)

    def lines_view(var, *values, model=None):
        return _lines_plot(ds, var, _at(*values, model=model), hv)

    def curves_view(*values, model=None):
        return _curves_plot(ds, _at(*values, model=model), hv)

    readout_pane = pn.pane.HTML(pn.bind(readout, w_var, *slider_list, **model_arg,
                                        note=notes), width=620)
    table_pane = pn.pane.HTML(pn.bind(table, *slider_list, **model_arg), width=420)
    if static:
        map_pane = pn.panel(pn.bind(map_view, w_var, x_axis, y_axis, *slider_list,
                                    **model_arg))
    else:
        # The Tap stream sits in the DynamicMap's own streams, beside the ones pn.bind
        # makes for the widgets: a Tap whose *source* is a DynamicMap of pn.bind never
        # reaches Python when served (holoviz/holoviews#5788, #4955). transient: a redraw
        # for a widget does not replay the last click.
        tap = hv.streams.Tap(x=None, y=None, transient=True)

        def map_with_tap(*args, x=None, y=None, **kwargs):  # the click is for on_tap
            return map_view(*args, **kwargs)

        dmap = hv.DynamicMap(pn.bind(map_with_tap, w_var, w_x, w_y, *slider_list,
                                     **model_arg), streams=[tap])

        def on_tap(x=None, y=None):
            if x is None or y is None:
                return
            texts = []
            for axis, value in ((w_x.value, x), (w_y.value, y)):
                grid = np.asarray(ds[axis].values, dtype=float)
                shown = np.asarray(_display(ds, axis, grid))
                i = int(np.argmin(np.abs(shown - value)))
                span = float(np.ptp(shown)) or 1.0
                if abs(shown[i] - value) > 1e-6 * span:
                    texts.append(f"clicked {axis} {value:.4g} {display_unit(ds, axis)} lies "
                                 f"between grid points: showing the nearest grid point "
                                 f"{axis_text(ds, axis, grid[i])} (the cube holds no values "
                                 "between grid points)")
                tapping[0] = True
                try:
                    sliders[axis].value = float(grid[i])
                finally:
                    tapping[0] = False
            notes.value = "; ".join(texts)

        tapping = [False]

        def clear_note(_event):  # a slider moved by hand: the click's note is stale
            if not tapping[0]:
                notes.value = ""

        for w in slider_list:
            w.param.watch(clear_note, "value")
        tap.add_subscriber(on_tap)
        map_pane = pn.pane.HoloViews(dmap)
    lines_pane = pn.panel(pn.bind(lines_view, w_var, *slider_list, **model_arg))
    curves_pane = pn.panel(pn.bind(curves_view, *slider_list, **model_arg))

    name = ds.attrs.get("name", "?")
    n = math.prod(ds.sizes[a] for a in AXES)
    header = (f"## nylonflex explorer: cube '{name}'\n"
              f"{n:,} designs ({' x '.join(f'{ds.sizes[a]} {a}' for a in AXES)}), "
              f"materials {ds.attrs.get('silicone', '?')} / {ds.attrs.get('nylon', '?')}"
              + (f", file `{source}`" if source else "") + ".  \n"
              "Every value shown is a grid point of the cube: sliders snap to grid values and "
              "nothing is interpolated. The map's colour scale is set by the unflagged "
              "designs.")
    if stand_in_note(ds):
        header += f"  \n<span id='nf-stand-in' style='color:#a0522d'>{stand_in_note(ds)}</span>"
    if static:
        held = ", ".join(f"{a} {axis_text(ds, a, v)}" for a, v in fixed.items())
        emb = "; ".join(f"{a}: {len(embed_states[s])} of {ds.sizes[a]} grid values"
                        for a, s in sliders.items())
        header += ("\n\n**Exported page (works offline).** It embeds every variable and, "
                   f"for the sliders, {emb}. The map shows radius against wall thickness and "
                   f"the selected design is fixed at {held}. Run `nylonflex explore "
                   f"{source or 'CUBE'}` for every grid value, other map axes and picking "
                   "a design by clicking the map.")
    else:
        header += ("  \nClick the map to pick a design (it snaps to the nearest grid point); "
                   "the sliders set the axes the map does not show and the picked design.")
    controls = [w_var] + ([w_model] if w_model else [])
    if not static:
        controls.append(pn.Row(w_x, w_y))
    controls += slider_list
    if static:
        controls.append(pn.pane.Markdown(
            "selected design: " + ", ".join(f"{a} {axis_text(ds, a, v)}"
                                            for a, v in fixed.items()), width=300))
    page = pn.Column(
        pn.pane.Markdown(header, width=1250),
        pn.Row(pn.Column(*controls, width=320), pn.Column(readout_pane, pn.Row(
            map_pane, lines_pane))),
        pn.Row(table_pane, curves_pane),
    )
    return page, embed_states


def _display(ds, axis, grid):
    from .explore import to_display_any

    return to_display_any(ds, axis, grid)
