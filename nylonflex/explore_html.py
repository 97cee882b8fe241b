"""The explorer as one self-contained HTML file: bokeh with the cube's numbers inside.

Panel's ``save(embed=True)`` renders the page once per widget state in Python (about a
second a state here), which is too slow for more than a few dozen states. This page instead
carries a bounded part of the cube (at most :data:`MAX_DESIGNS` designs, chosen axis by
axis; all of a small cube) as typed arrays and redraws in the browser with bokeh
``CustomJS``: every slider, the variable, the model and clicks on the map work offline,
with bokeh's JavaScript inlined (no CDN, no server). The page says what it holds.

Hooks for tests: ``#nf-readout`` carries ``data-variable``, ``data-value`` (display units)
and ``data-unit``.
"""

from __future__ import annotations

import html
import math
import re

import numpy as np

from .explore import (design_config, design_variables, display_unit, flag_meanings, label,
                      snap, stand_in_note, to_display_any)
from .variables import AXES

#: The most designs an exported page carries (the rest of a larger cube is left out).
MAX_DESIGNS = 120_000
_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
            "#000000")
_DEFAULT = {"radius": 15e-3, "wall_thickness": 2e-3, "length": 90e-3, "coil_index": 1.7,
            "wrap_angle": math.radians(8.0)}


def _subset(ds) -> dict:
    """Indices kept per axis so that the product stays within :data:`MAX_DESIGNS`.

    The axes the page draws along (radius, then wall thickness) keep the most values; each
    axis keeps its ends and the default design's value.
    """
    sizes = {a: ds.sizes[a] for a in AXES}
    keep = dict(sizes)
    order = ["wrap_angle", "length", "coil_index", "wall_thickness", "radius"]
    while math.prod(keep.values()) > MAX_DESIGNS:
        # halve the axis with most values relative to its priority
        a = max(order, key=lambda a: keep[a] / (4 if a == "radius" else
                                                 2 if a == "wall_thickness" else 1))
        keep[a] = max(2, keep[a] // 2) if keep[a] > 2 else 1
    out = {}
    for a in AXES:
        idx = sorted(set(np.round(np.linspace(0, sizes[a] - 1, keep[a])).astype(int)
                         .tolist()))
        d = snap(ds, a, _DEFAULT[a]).index
        if len(idx) >= 3 and d not in idx:  # swap the nearest inner value for the default
            j = 1 + int(np.argmin([abs(i - d) for i in idx[1:-1]]))
            idx = sorted(idx[:j] + idx[j + 1:] + [d])
        out[a] = idx
    return out


def _edges(x):
    x = np.asarray(x, float)
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = (x[1:] + x[:-1]) / 2
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


def _f32(a):
    return np.ascontiguousarray(np.asarray(a, dtype=np.float32))


_JS = """
const iv = Number(variable.value), im = model ? model.active : 0;
const ix = {}; for (const k of AXES) ix[k] = sliders[k].value;
const N = sizes;  // per axis, C order radius, wall, length, coil, wrap
function flagtext(bits) {
  if (!isFinite(bits)) return "unknown";
  const on = flags.filter(f => (bits & f[0]) != 0).map(f => f[1]);
  return on.length ? on.join(", ") : "valid";
}
function flat(r, t, l, c, w) {
  return (((r * N[1] + t) * N[2] + l) * N[3] + c) * N[4] + w;
}
const nd = N[0] * N[1] * N[2] * N[3] * N[4];
const off = im * nd;
const arr = data[iv];
const z = map_src.data.z, h = map_src.data.h, lc = map_src.data.lc, fa = map_src.data.fa;
// the colour scale: clean designs only (flagged ones, drawn faded, do not set it)
let lo = Infinity, hi = -Infinity, alo = Infinity, ahi = -Infinity;
for (let t = 0; t < N[1]; t++) for (let r = 0; r < N[0]; r++) {
  const i = flat(r, t, ix.length, ix.coil_index, ix.wrap_angle) + off;
  const k = t * N[0] + r;
  const bad = validity && validity[i] != 0;
  z[k] = arr[i];
  if (isFinite(arr[i])) {
    alo = Math.min(alo, arr[i]); ahi = Math.max(ahi, arr[i]);
    if (!bad) { lo = Math.min(lo, arr[i]); hi = Math.max(hi, arr[i]); }
  }
  h[k] = (limit && limit[i] == 1) ? "x" : " ";
  lc[k] = bad ? "#D55E00" : null;
  fa[k] = bad ? 0.35 : 1.0;
}
if (!isFinite(lo)) { lo = alo; hi = ahi; }
if (!(hi > lo)) { hi = lo + 1; }
mapper.low = lo; mapper.high = hi;
colorbar.title = vlabels[iv];
hover.tooltips = [[vlabels[iv], "@z{0.000}"], ["validity", "@vf"]];
const vf = map_src.data.vf;
for (let t = 0; t < N[1]; t++) for (let r = 0; r < N[0]; r++) {
  const i = flat(r, t, ix.length, ix.coil_index, ix.wrap_angle) + off;
  vf[t * N[0] + r] = flagtext(validity ? validity[i] : 0);
}
map_src.change.emit();
const sel = flat(ix.radius, ix.wall_thickness, ix.length, ix.coil_index, ix.wrap_angle) + off;
star.data = {x: [gx.radius[ix.radius]], y: [gx.wall_thickness[ix.wall_thickness]]};
const held = (ks) => ks.map(k => names[k] + " = " + labels[k][ix[k]]).join(", ");
const mname = model ? ", model " + model.labels[im] : "";
map_fig.title.text = vshort[iv] + " at " + held(["length", "coil_index", "wrap_angle"]) + mname;
// figure 12 style lines: var against radius, one per coil index
for (let c = 0; c < N[3]; c++) {
  const all = [], solid = [];
  for (let r = 0; r < N[0]; r++) {
    const i = flat(r, ix.wall_thickness, ix.length, c, ix.wrap_angle) + off;
    all.push(arr[i]); solid.push(limit && limit[i] == 1 ? NaN : arr[i]);
  }
  line_srcs[c].data = {x: gx.radius, y: all}; solid_srcs[c].data = {x: gx.radius, y: solid};
}
lines_fig.title.text = "Figure 12 style at " +
  held(["wall_thickness", "length", "wrap_angle"]) + mname;
lines_yaxis.axis_label = vlabels[iv];
// curves of the selected design
const nf = [], ba = [], tf = [];
const S = curves.nstroke, P = curves.npressure;
const inf = im * N[0] * N[1] * N[3] * N[4] * S + (((ix.radius * N[1] + ix.wall_thickness) * N[3] + ix.coil_index) * N[4] + ix.wrap_angle) * S;
for (let s = 0; s < S; s++) nf.push(curves.nylon_force[inf + s]);
const ibp = im * N[0] * N[1] * N[2] * P + ((ix.radius * N[1] + ix.wall_thickness) * N[2] + ix.length) * P;
for (let p = 0; p < P; p++) { ba.push(curves.bend_angle[ibp + p]); tf.push(curves.tip_force[ibp + p]); }
nf_src.data = {x: curves.stroke, y: nf}; ba_src.data = {x: curves.pressure, y: ba};
tf_src.data = {x: curves.pressure, y: tf};
if (flim) { flim_span.location = curves.flim[ix.coil_index]; }
// read-out and table
const fmt = (v) => isFinite(v) ? Number(v.toPrecision(4)).toString() : "nan";
const v = arr[sel];
let text = '<div id="nf-readout" class="nf-readout" data-variable="' + vnames[iv] +
  '" data-value="' + v + '" data-unit="' + vunits[iv] + '" style="font-size:15px">' +
  vshort[iv] + ' of the selected design: <b>' + fmt(v) +
  (vunits[iv] == "1" ? "" : " " + vunits[iv]) + '</b><br><span style="color:#555">design: ' +
  AXES.map(k => k + " " + labels[k][ix[k]]).join(", ") + mname + '</span>' +
  '<br><span id="nf-validity" data-value="' + (validity ? validity[sel] : 0) + '">validity: <b>' +
  flagtext(validity ? validity[sel] : 0) + '</b></span>';
if (note.tags.length) text += '<br><span class="nf-snap" style="color:#a0522d">' + note.tags[0] + '</span>';
if (config) {
  let yaml = config;
  for (const k of AXES) yaml = yaml.replace("'@" + k + "@'", cfgvals[k][ix[k]]);
  text += '<details style="font-size:12px"><summary>copy as config (a sweep of this design)' +
    '</summary><pre id="nf-config">' + yaml + '</pre></details>';
}
readout.text = text + '</div>';
let rows = '';
for (let j = 0; j < vnames.length; j++) {
  const x = data[j][sel];
  rows += '<tr data-name="' + vnames[j] + '" data-value="' + x + '"><td>' + vlabels[j] +
    '</td><td style="text-align:right"><b>' + fmt(x) + '</b></td></tr>';
}
table.text = '<table id="nf-design" style="border-collapse:collapse;font-size:13px">' +
  '<tr><th style="text-align:left">every design variable of the selected design</th>' +
  '<th>value</th></tr>' + rows + '</table>';
"""

_TAP = """
const i = cb_obj.indices;
if (!i.length) return;
const k = i[0];
const r = k % sizes[0], t = Math.floor(k / sizes[0]);
note.tags = ["picked on the map: the cell of grid point radius " + labels.radius[r] +
  ", wall_thickness " + labels.wall_thickness[t] + " (the cube holds no values between grid points)"];
sliders.radius.value = r; sliders.wall_thickness.value = t;
"""


def build_html(ds, *, source: str = "") -> str:
    """The self-contained explorer page of a cube, as HTML text (bokeh JS inlined).

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube (read lazily; only the kept part is loaded).
    source : str
        The cube's path, named on the page.

    Returns
    -------
    str
    """
    from bokeh.embed import file_html
    from bokeh.layouts import column, row
    from bokeh.models import (ColorBar, ColumnDataSource, CustomJS, CustomJSTickFormatter,
                              Div, HoverTool, LinearColorMapper, RadioButtonGroup, Select, Slider,
                              Span, TapTool, Title)
    from bokeh.plotting import figure
    from bokeh.resources import Resources

    keep = _subset(ds)
    part = ds.isel(keep)
    variables = design_variables(ds)
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else None
    order = (("model",) if models else ()) + AXES

    def design_array(name):
        da = part[name]
        if models and "model" not in da.dims:
            da = da.expand_dims(model=len(models))
        return _f32(to_display_any(ds, name, da.transpose(*order).values.astype(float))).ravel()

    data = [design_array(n) for n in variables]
    limit = (np.asarray(part["limit"].transpose(*[d for d in order if d in part["limit"].dims])
                        .values, dtype=np.float32).ravel() if "limit" in ds else None)
    if limit is not None and models and "model" not in part["limit"].dims:
        limit = np.tile(limit, len(models))
    validity = None
    if "validity" in ds:
        vd = part["validity"]
        if models and "model" not in vd.dims:
            vd = vd.expand_dims(model=len(models))
        validity = _f32(np.nan_to_num(vd.transpose(*order).values.astype(float))).ravel()
    sizes = [len(keep[a]) for a in AXES]
    grid = {a: part[a].values.astype(float) for a in AXES}
    gx = {a: _f32(to_display_any(ds, a, grid[a])).tolist() for a in AXES}
    labels = {a: [f"{float(to_display_any(ds, a, v)):.4g}"
                  + ("" if display_unit(ds, a) == "1" else f" {display_unit(ds, a)}")
                  for v in grid[a]] for a in AXES}
    curves = {"nstroke": ds.sizes["stroke"], "npressure": ds.sizes["pressure"],
              "stroke": to_display_any(ds, "stroke", ds["stroke"].values).tolist(),
              "pressure": to_display_any(ds, "pressure", ds["pressure"].values).tolist()}
    for name, dims in (("nylon_force", ("radius", "wall_thickness", "coil_index",
                                        "wrap_angle", "stroke")),
                       ("bend_angle", ("radius", "wall_thickness", "length", "pressure")),
                       ("tip_force", ("radius", "wall_thickness", "length", "pressure"))):
        da = part[name]
        if models:
            if "model" not in da.dims:
                da = da.expand_dims(model=len(models))
            dims = ("model",) + dims
        curves[name] = _f32(to_display_any(ds, name, da.transpose(*dims).values.astype(float))
                            ).ravel()
    flim = "nylon_force_limit" in ds
    if flim:
        curves["flim"] = to_display_any(ds, "nylon_force_limit",
                                        part["nylon_force_limit"].values).tolist()

    # ---- widgets
    default_var = variables.index("tip_force_max") if "tip_force_max" in variables else 0
    variable = Select(title="variable (map, lines and read-out)", width=300,
                      options=[(str(i), label(ds, n)) for i, n in enumerate(variables)],
                      value=str(default_var))
    model = RadioButtonGroup(labels=models, active=0) if models else None
    sliders = {}
    for j, a in enumerate(AXES):
        start = int(np.argmin(np.abs(grid[a] - _DEFAULT[a])))
        fmt = CustomJSTickFormatter(args={"labels": labels[a]},
                                    code="return labels[Math.round(tick)] || '';")
        sliders[a] = Slider(start=0, end=max(1, sizes[j] - 1), step=1, value=start,
                            title=label(ds, a).split(" [")[0], format=fmt, width=300,
                            disabled=sizes[j] < 2, name=f"nf-slider-{a}",
                            css_classes=[f"nf-slider-{a}"])
    # ---- map
    ex, ey = _edges(gx["radius"]), _edges(gx["wall_thickness"])
    nr, nt = sizes[0], sizes[1]
    rr, tt = np.meshgrid(np.arange(nr), np.arange(nt))
    map_src = ColumnDataSource({
        "left": ex[rr.ravel()], "right": ex[rr.ravel() + 1], "bottom": ey[tt.ravel()],
        "top": ey[tt.ravel() + 1], "z": np.zeros(nr * nt), "h": [" "] * (nr * nt),
        "lc": [None] * (nr * nt), "fa": [1.0] * (nr * nt), "vf": ["valid"] * (nr * nt)})
    mapper = LinearColorMapper(palette="Viridis256", low=0, high=1)
    map_fig = figure(width=520, height=380, tools="tap,reset,save",
                     x_axis_label=label(ds, "radius"), y_axis_label=label(ds, "wall_thickness"),
                     x_range=(ex[0], ex[-1]), y_range=(ey[0], ey[-1]))
    cells = map_fig.quad(source=map_src, left="left", right="right", bottom="bottom",
                         top="top", fill_color={"field": "z", "transform": mapper},
                         fill_alpha="fa", line_color="lc", line_width=2, hatch_pattern="h",
                         hatch_color="white", hatch_alpha=0.8, hatch_scale=8,
                         nonselection_fill_alpha="fa", selection_fill_alpha="fa")
    # the cells only (the star has no value), named with the variable and its unit
    hover = HoverTool(renderers=[cells], tooltips=[(label(ds, variables[default_var]), "@z{0.000}")])
    map_fig.add_tools(hover)
    colorbar = ColorBar(color_mapper=mapper, width=12, title=label(ds, variables[default_var]))
    map_fig.add_layout(colorbar, "right")
    star = ColumnDataSource({"x": [0.0], "y": [0.0]})
    map_fig.scatter("x", "y", source=star, marker="star", size=20, fill_color="gold",
                    line_color="black")
    map_fig.select_one(TapTool).mode = "replace"
    # ---- figure 12 style lines
    lines_fig = figure(width=520, height=380, x_axis_label=label(ds, "radius"),
                       tools="pan,box_zoom,reset,save")
    line_srcs, solid_srcs = [], []
    for k, c in enumerate(gx["coil_index"]):
        colour = _COLOURS[k % len(_COLOURS)]
        line_srcs.append(ColumnDataSource({"x": [], "y": []}))
        solid_srcs.append(ColumnDataSource({"x": [], "y": []}))
        lines_fig.line("x", "y", source=line_srcs[-1], color=colour, line_dash="dashed",
                       legend_label=f"C = {c:.3g}")
        lines_fig.line("x", "y", source=solid_srcs[-1], color=colour, line_width=3)
    lines_fig.legend.location = "top_left"
    lines_fig.add_layout(Title(text="solid: full range of motion; dashed: strength-limited",
                               text_font_style="italic", text_font_size="11px"), "above")
    # ---- curves of the selected design
    def curve_fig(title, x, y, colour):
        f = figure(width=400, height=280, title=title, x_axis_label=label(ds, x),
                   y_axis_label=label(ds, y), tools="pan,box_zoom,reset,save")
        src = ColumnDataSource({"x": [], "y": []})
        f.line("x", "y", source=src, color=colour, line_width=2)
        return f, src
    nf_fig, nf_src = curve_fig("nylon force vs stroke (dashed: its limit)",
                               "stroke", "nylon_force", _COLOURS[0])
    flim_span = Span(location=0, dimension="width", line_dash="dashed", line_color="black")
    nf_fig.add_layout(flim_span)
    ba_fig, ba_src = curve_fig("bend angle against chamber pressure", "pressure",
                               "bend_angle", _COLOURS[1])
    tf_fig, tf_src = curve_fig("tip force against chamber pressure", "pressure", "tip_force",
                               _COLOURS[2])
    readout = Div(width=640, name="nf-readout")
    table = Div(width=420)
    note = Div(text="", visible=False)

    n_all = math.prod(ds.sizes[a] for a in AXES)
    n_kept = math.prod(sizes)
    held = ("every design of the cube" if n_kept == n_all else
            f"{n_kept:,} of the cube's {n_all:,} designs (" + ", ".join(
                f"{a}: {s} of {ds.sizes[a]} values" for a, s in zip(AXES, sizes)
                if s < ds.sizes[a]) + ")")
    flags = flag_meanings(ds)
    flag_text = (" Cells outlined in orange are flagged: " + ", ".join(
        m.replace("_", " ") for _, m in flags) + "." if flags else "")
    header = Div(width=1250, text=(
        f"<h2 style='margin:0'>nylonflex explorer: cube '{html.escape(str(ds.attrs.get('name', '?')))}'"
        f"</h2><p>Exported page: it works offline and holds {held}"
        + (f", from <code>{html.escape(source)}</code>" if source else "") +
        ". Sliders snap to grid values and nothing is interpolated; click the map to pick a "
        "design (the nearest grid point). The map shows radius against wall thickness; "
        "<b>hatched (x) cells are strength-limited</b>: the nylon breaks before the muscle "
        f"uses its full stroke, so the range of motion is cut short.{flag_text} Run "
        f"<code>nylonflex explore {html.escape(source or 'CUBE')}</code> for other map "
        "axes. The colour scale is set by the unflagged designs; flagged ones are faded."
        "</p>" + (f"<p id='nf-stand-in' style='color:#a0522d'>{html.escape(stand_in_note(ds))}"
                  "</p>" if stand_in_note(ds) else "")))

    args = dict(variable=variable, model=model, sliders=sliders, data=data, limit=limit,
                flags=[[m, n.replace("_", " ")] for m, n in flag_meanings(ds)],
                config=(html.escape(design_config(ds, _DEFAULT, placeholders=True), quote=False)
                        if "config_yaml" in ds.attrs else ""),
                cfgvals={a: [f"{float(to_display_any(ds, a, v)):.12g}" for v in grid[a]]
                         for a in AXES},
                colorbar=colorbar, hover=hover,
                validity=validity, sizes=sizes, AXES=list(AXES), map_src=map_src,
                mapper=mapper, star=star, gx=gx, names={"radius": "a", "wall_thickness": "t", "length": "L", "coil_index": "C",
                       "wrap_angle": "\u03c8"}, labels=labels,
                map_fig=map_fig, lines_fig=lines_fig, lines_yaxis=lines_fig.yaxis[0], line_srcs=line_srcs,
                solid_srcs=solid_srcs, curves=curves, nf_src=nf_src, ba_src=ba_src,
                tf_src=tf_src, flim=flim, flim_span=flim_span, readout=readout, table=table,
                note=note, vnames=variables,
                vlabels=[label(ds, n) for n in variables],
                vshort=[label(ds, n).split(" [")[0] for n in variables],
                vunits=[display_unit(ds, n) for n in variables])
    update = CustomJS(args=args, code=_JS)
    clear_note = CustomJS(args={"note": note}, code="note.tags = [];")
    variable.js_on_change("value", update)
    if model is not None:
        model.js_on_change("active", update)
    for s in sliders.values():
        s.js_on_change("value", clear_note, update)
    map_src.selected.js_on_change("indices", CustomJS(
        args={"sizes": sizes, "sliders": sliders, "labels": labels, "note": note}, code=_TAP))
    map_src.selected.js_on_change("indices", update)

    controls = [variable] + ([Div(text="model variant"), model] if model else []) + \
        list(sliders.values())
    layout = column(header, row(column(*controls, width=320),
                                column(readout, row(map_fig, lines_fig))),
                    row(table, nf_fig, ba_fig, tf_fig), note)
    from bokeh.document import Document

    doc = Document()
    doc.add_root(layout)
    doc.js_on_event("document_ready", update)
    text = file_html(doc, Resources(mode="inline"),
                     title=f"nylonflex explorer: {ds.attrs.get('name', '')}")
    # Where Panel is imported in the same process, bokeh bundles its extensions' script
    # tags (relative URLs this page never uses and that could not load offline): drop them.
    return re.sub(r'<script[^>]*\bsrc="[^"]*"[^>]*>\s*</script>\s*', "", text)

