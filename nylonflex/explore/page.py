"""The explorer page: one Bokeh document, served by ``nylonflex explore`` or saved offline.

One code path builds both forms (issue 28): :func:`build_document` makes the document, with
the cube's numbers inside (at most :data:`MAX_DESIGNS` designs, chosen axis by axis; all of
a small cube) as typed arrays, and every view is redrawn in the browser by one script,
``update.js``, from one state (the variable, the model, the map's axes and a grid index per
axis). :func:`build_html` writes that document as one self-contained file (bokeh's
JavaScript inlined, no CDN, no server); :func:`serve` serves the same document from a local
Bokeh server. Nothing is computed on the server after the page is built, so no view can
show another design than the read-out and no key press waits on Python.

Why not Panel's embedding (``panel.io.save(embed=True)``)? It records the page once per
combination of widget states, rendering each in Python: on the fig12 cube the 14 states of
the variable selector alone took 96 s (6.9 s a state on a busy machine, 1.1 MB), the page's
sliders and selectors span 14 x 41 x 4 x 3 x 4 x 6 = 330,624 states, and a click on the map
is no widget state at all (the README's section on the explorer).

Hooks for tests and scripts: ``#nf-readout`` carries ``data-variable``, ``data-value``
(display units), ``data-unit`` and ``data-design`` (the grid index of each axis, comma
separated, then the model's index where the cube has several); the map's marker (the
bokeh model named ``nf-star``) and each curve's source (``nf-curve-NAME``) carry the same
``design`` in their data; ``#nf-validity`` carries the flag bits.
"""

from __future__ import annotations

import html
import logging
import math
import re

import numpy as np

from ..query import parse_where
from ..units import InputError
from ..variables import AXES, incomplete_text, label
from .data import (PAPER_EXAMPLES, design_config, design_variables, display_unit,
                   first_design, flag_meanings, snap, stand_in_note, to_display_any,
                   validity_names)
from .fidelity import fidelity_widgets
from .model_spread import spread_args
from .views import (CURVES, curve_views, flag_key, lines_view, map_view, script,
                    state_widgets, where_view)

#: The most designs a page carries (the rest of a larger cube is left out, and it says so).
MAX_DESIGNS = 120_000
#: The most rows the table of designs matching ``--where`` lists.
MAX_ROWS = 2000
#: The design a page prefers to open on [SI]: the paper's second worked example (7.5 mm,
#: 2 mm, 70 mm, C 1.7, 8 deg); a page opens on it where the cube holds it, valid, else on
#: the valid design nearest it (:func:`nylonflex.explore.data.first_design`).
DEFAULT_DESIGN = dict(PAPER_EXAMPLES[0][1])
_SYMBOL = {"radius": "a", "wall_thickness": "t", "length": "L", "coil_index": "C",
           "wrap_angle": "\u03c8"}


def _conditions(where):
    """``--where`` texts parsed by the query's parser (Condition objects pass through)."""
    return [c for w in (where or ()) for c in (parse_where([w]) if isinstance(w, str)
                                               else [w])]


def _subset(ds) -> dict:
    """Indices kept per axis so that the product stays within :data:`MAX_DESIGNS`.

    The axes the map draws by default (radius, then wall thickness) keep the most values;
    each axis keeps its ends and the default design's value.
    """
    sizes = {a: ds.sizes[a] for a in AXES}
    keep = dict(sizes)
    order = ["wrap_angle", "length", "coil_index", "wall_thickness", "radius"]
    while math.prod(keep.values()) > MAX_DESIGNS:
        a = max(order, key=lambda a: keep[a] / (4 if a == "radius" else
                                                 2 if a == "wall_thickness" else 1))
        keep[a] = max(2, keep[a] // 2) if keep[a] > 2 else 1
    out = {}
    for a in AXES:
        idx = sorted(set(np.round(np.linspace(0, sizes[a] - 1, keep[a])).astype(int)
                         .tolist()))
        d = snap(ds, a, DEFAULT_DESIGN[a]).index
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
    return np.ascontiguousarray(np.asarray(a, dtype=np.float32)).ravel()


def _full(da, order, models):
    """``da`` over ``order`` (the model first where the cube has several), C order."""
    if models and "model" not in da.dims:
        da = da.expand_dims(model=len(models))
    return da.transpose(*[d for d in order if d in da.dims])


def _where_mask(part, conditions, order, models):
    """Which designs of ``part`` meet every condition (:func:`nylonflex.query.parse_where`),
    as a bool array over ``order``; None without conditions."""
    if not conditions:
        return None
    shape = tuple(len(models) if d == "model" else part.sizes[d] for d in order)
    mask = np.ones(shape, bool)
    for c in conditions:
        if isinstance(c, str):  # "model == NAME": parse_where keeps it as its text
            name = c.split("=")[-1].strip()
            if not models or name not in models:
                raise InputError(f"--where {c}: accepted models: "
                                 f"{', '.join(models or ['(this cube has one model)'])}")
            keep = np.zeros(shape, bool)
            keep[models.index(name)] = True
            mask &= keep
            continue
        if c.name not in part.variables:
            raise InputError(f"--where {c.name}: not in this cube; accepted: "
                             f"{', '.join([*AXES, *design_variables(part), 'validity'])}")
        da = part[c.name]
        if c.name in AXES:
            da = da.broadcast_like(part["limit"] if "limit" in part else part[AXES[0]])
        values = _full(da, order, models).values.astype(float)
        mask &= np.broadcast_to(c.mask(values), shape)
    return mask


def build_payload(ds, where=()):
    """The numbers a page carries, computed once per cube (every session of a served page
    shares them): typed arrays in display units, the labels and, for parsed ``where``
    conditions, the matching designs."""
    keep = _subset(ds)
    part = ds.isel(keep)
    variables = design_variables(ds)
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims else None
    order = (("model",) if models else ()) + AXES
    p = {"keep": keep, "variables": variables, "models": models,
         "sizes": [len(keep[a]) for a in AXES]}
    p["data"] = [_f32(to_display_any(ds, n, _full(part[n], order, models).values.astype(float)))
                 for n in variables]
    p["limit"] = _f32(_full(part["limit"], order, models).values) if "limit" in ds else None
    p["validity"] = (_f32(np.nan_to_num(_full(part["validity"], order, models).values
                                        .astype(float), nan=np.nan))
                     if "validity" in ds else None)
    # the flags of any variant of a model spread (explore/model_spread.py)
    p["validity_any"] = (_f32(_full(part["validity_model_any"], order, models).values
                              .astype(float)) if "validity_model_any" in ds else None)
    grid = {a: part[a].values.astype(float) for a in AXES}
    p["grid"] = grid
    first, p["first_name"] = first_design(ds, keep)
    p["first"] = {a: keep[a].index(first[a]) for a in AXES}  # index among the kept values
    p["gx"] = {a: [float(v) for v in _f32(to_display_any(ds, a, grid[a]))] for a in AXES}
    p["edges"] = {a: _edges(p["gx"][a]).tolist() for a in AXES}
    p["labels"] = {a: [f"{float(to_display_any(ds, a, v)):.4g}"
                       + ("" if display_unit(ds, a) == "1" else f" {display_unit(ds, a)}")
                       for v in grid[a]] for a in AXES}
    curves = {}
    for name, (axis, dims) in CURVES.items():
        if name not in ds:
            continue
        da = part[name]
        dims = (("model",) if models else ()) + dims + (axis,)
        if models and "model" not in da.dims:
            da = da.expand_dims(model=len(models))
        curves[name] = {"dims": list(dims[:-1]), "n": int(ds.sizes[axis]),
                        "x": [float(v) for v in to_display_any(ds, axis, ds[axis].values)],
                        "values": _f32(to_display_any(ds, name, da.transpose(*dims).values
                                                      .astype(float)))}
    p["curves"] = curves
    p["flim"] = ([float(v) for v in to_display_any(ds, "nylon_force_limit",
                                                   part["nylon_force_limit"].values)]
                 if "nylon_force_limit" in ds else None)
    conditions = list(where or ())
    p["where_conditions"] = conditions
    mask = _where_mask(part, conditions, order, models)
    p["where"] = [getattr(c, "text", str(c)) for c in conditions]
    p["match"] = None if mask is None else mask.ravel().astype(np.uint8)
    p["rows"] = _where_rows(ds, part, mask, order, models, p) if mask is not None else None
    return p


def _where_rows(ds, part, mask, order, models, p):
    """The table of matching designs: index columns ``i_AXIS`` (for picking) and the
    axes, the conditions' names and the headline variables in display units."""
    hits = np.argwhere(mask)
    rows = {"matching": int(len(hits))}
    hits = hits[:MAX_ROWS]
    cols = {}
    for j, d in enumerate(order):
        cols[f"i_{d}"] = hits[:, j].astype(int).tolist()
    shown = [*AXES]
    headline = ("tip_force_max", "bend_angle_max", "range_fraction", "limit")
    for n in [*(getattr(c, "name", None) for c in p["where_conditions"]), *headline]:
        if n and n not in shown and n in p["variables"]:
            shown.append(n)
    flat = np.ravel_multi_index(tuple(hits.T), mask.shape) if len(hits) else \
        np.zeros(0, int)
    for n in shown:
        if n in AXES:
            cols[n] = [float(f"{p['gx'][n][i]:.6g}") for i in cols[f"i_{n}"]]
        else:
            cols[n] = [float(v) for v in p["data"][p["variables"].index(n)][flat]]
    if models:
        cols["model"] = [models[i] for i in cols["i_model"]]
        shown.insert(0, "model")
    if p["validity"] is not None:
        cols["validity"] = [validity_names(ds, v) for v in p["validity"][flat]]
        shown.append("validity")
    rows["columns"] = shown
    rows["data"] = cols
    return rows


def _header(ds, p, source, served):
    n_all = math.prod(ds.sizes[a] for a in AXES)
    n_kept = math.prod(p["sizes"])
    held = ("every design of the cube" if n_kept == n_all else
            f"{n_kept:,} of the cube's {n_all:,} designs (" + ", ".join(
                f"{a}: {s} of {ds.sizes[a]} values" for a, s in zip(AXES, p["sizes"])
                if s < ds.sizes[a]) + ")")
    flags = flag_meanings(ds)
    flag_text = (" <b>Grey cells hatched / are flagged designs</b> (" + ", ".join(
        m.replace("_", " ") for _, m in flags) + "; docs/model.md s. 17): they take no "
        "colour of the scale, and the figure-12 panel draws them as grey dots." if flags
        else "")
    form = ("Served page (127.0.0.1; everything is drawn in the browser)" if served else
            "Exported page: it works offline")
    text = (f"<h2 style='margin:0'>nylonflex explorer: cube "
            f"'{html.escape(str(ds.attrs.get('name', '?')))}'</h2><p>{form} and holds {held}"
            + (f", from <code>{html.escape(source)}</code>" if source else "") +
            f", materials {html.escape(str(ds.attrs.get('silicone', '?')))} / "
            f"{html.escape(str(ds.attrs.get('nylon', '?')))}. Sliders snap to grid values and "
            "nothing is interpolated; click the map to pick a design (the nearest grid point)."
            " <b>Hatched (x) cells are strength-limited</b>: the nylon breaks before the "
            f"muscle uses its full stroke, so the range of motion is cut short.{flag_text} "
            "The colour scale and the panels' ranges are set by the unflagged designs.</p>")
    first = ",".join(str(p["first"][a]) for a in AXES)
    text += (f"<p id='nf-opened' data-design='{first}' style='margin:0'>The page opened on "
             f"<b>{html.escape(p['first_name'])}</b>.</p>")
    missing = incomplete_text(ds)
    if missing:
        text += (f"<p id='nf-incomplete' style='color:#B00020;font-weight:bold;margin:0'>"
                 f"{html.escape(missing)}: the sweep was interrupted; the missing radii are "
                 "blank (nylonflex sweep CONFIG --resume finishes it).</p>")
    if stand_in_note(ds):
        text += (f"<p id='nf-stand-in' style='color:#a0522d'>{html.escape(stand_in_note(ds))}"
                 "</p>")
    return text


def build_document(ds, *, source: str = "", where=(), served: bool = False, payload=None,
                   doc=None, fidelity=None):
    """The explorer page of a cube as a Bokeh document.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube (read lazily; only the kept part is loaded).
    source : str
        The cube's path, named on the page.
    where : sequence of str or Condition
        Conditions (``--where``, parsed by :func:`nylonflex.query.parse_where`): the page
        marks the matching designs on the map and lists them in a sortable table.
    served : bool
        Say "served page" in the header instead of "exported page".
    payload : dict, optional
        The numbers from an earlier call for the same cube and ``where`` (a served page
        builds one document per browser session).
    doc : bokeh.document.Document, optional
        The document to fill (a server session's); a new one by default.
    fidelity : (xarray.Dataset, str), optional
        The cube's fidelity dataset (``nylonflex verify``) and its file name: the page
        lists its designs with each model's ratio to FE (:mod:`.fidelity`).

    Returns
    -------
    bokeh.document.Document
    """
    from bokeh.document import Document
    from bokeh.models import CustomJS, Div

    conditions = _conditions(where)
    if payload is None:
        payload = build_payload(ds, conditions)
    p = payload
    variables = p["variables"]
    default_var = variables.index("tip_force_max") if "tip_force_max" in variables else 0
    state = state_widgets(ds, p, default_var)
    views = {**map_view(ds, p, variables[default_var]), **lines_view(ds, p),
             **curve_views(ds, p),
             "readout": Div(sizing_mode="stretch_width", name="nf-readout"),
             "table": Div(min_width=300, sizing_mode="stretch_width"),
             "note": Div(text="", visible=False), "hold": Div(text="", visible=False)}
    update = CustomJS(args=_update_args(ds, p, state, views), code=script("update.js"))
    pick_args = _on_change(update, state, views, p)
    views["where_box"] = where_view(ds, p, pick_args, MAX_ROWS)
    views["fidelity_box"] = [] if fidelity is None else \
        fidelity_widgets(ds, fidelity[0], fidelity[1])
    layout = _layout(ds, p, state, views, _header(ds, p, source, served))
    doc = Document() if doc is None else doc
    doc.add_root(layout)
    doc.title = f"nylonflex explorer: {ds.attrs.get('name', '')}"
    doc.js_on_event("document_ready", update)
    return doc


def _update_args(ds, p, state, views) -> dict:
    """What ``update.js`` reads, by name: the state's widgets (:func:`~.views.state_widgets`),
    the views it draws (:mod:`.views`), the payload's numbers and the labels in display
    units."""
    variables = p["variables"]
    return dict(variable=state["variable"], model=state["model"], sliders=state["sliders"],
                map_x=state["map_x"], map_y=state["map_y"],
                data=p["data"], limit=p["limit"], validity=p["validity"], match=p["match"],
                flags=[[m, n.replace("_", " ")] for m, n in flag_meanings(ds)],
                config=(html.escape(design_config(ds, DEFAULT_DESIGN, placeholders=True),
                                    quote=False) if "config_yaml" in ds.attrs else ""),
                cfgvals={a: [f"{float(to_display_any(ds, a, v)):.12g}" for v in p["grid"][a]]
                         for a in AXES},
                colorbar=views["colorbar"], hover=views["hover"], sizes=p["sizes"],
                AXES=list(AXES), map_src=views["map_src"], match_src=views["match_src"],
                mapper=views["mapper"], star=views["star"], gx=p["gx"],
                edges=p["edges"], names=_SYMBOL, labels=p["labels"],
                alabels={a: label(ds[a]) for a in AXES}, map_fig=views["map_fig"],
                map_xaxis=views["map_xaxis"], map_yaxis=views["map_yaxis"],
                lines_fig=views["lines_fig"], lines_yaxis=views["lines_yaxis"],
                line_srcs=views["line_srcs"], solid_srcs=views["solid_srcs"],
                flag_pts=views["flag_pts"], curve_figs=views["curve_figs"],
                curves=p["curves"], curve_srcs=views["curve_srcs"], flim=p["flim"],
                flim_span=views["flim_span"], readout=views["readout"],
                table=views["table"], note=views["note"], hold=views["hold"],
                vnames=variables, vlabels=[label(ds[n]) for n in variables],
                vshort=[label(ds[n]).split(" [")[0] for n in variables],
                vunits=[display_unit(ds, n) for n in variables],
                vany=p["validity_any"], **spread_args(ds, variables))


def _on_change(update, state, views, p) -> dict:
    """Run ``update`` (``update.js``) on every change of the state's widgets, and
    ``pick.js`` on a click on the map. Returns the arguments ``pick.js`` reads, all but
    ``rows``: the ``--where`` table's rows pick with them too (:func:`~.views.where_view`)."""
    from bokeh.models import CustomJS

    for w in (state["variable"], state["map_x"], state["map_y"]):
        w.js_on_change("value", update)
    if state["model"] is not None:
        state["model"].js_on_change("active", update)
    for s in state["sliders"].values():
        s.js_on_change("value", update)
    pick_args = dict(sizes=p["sizes"], AXES=list(AXES), sliders=state["sliders"],
                     model=state["model"], map_x=state["map_x"], map_y=state["map_y"],
                     labels=p["labels"], note=views["note"], hold=views["hold"],
                     update=update)
    views["map_src"].selected.js_on_change("indices", CustomJS(args={**pick_args,
                                                                     "rows": None},
                                                               code=script("pick.js")))
    return pick_args


def _layout(ds, p, state, views, header):
    """The page's layout: the ``header`` text (HTML), the state's widgets (300 px wide)
    beside the read-out, the map, the lines and the map's key, then the ``--where`` part
    (``views["where_box"]``), the curves, the table of values and the fidelity part
    (``views["fidelity_box"]``)."""
    from bokeh.layouts import column, row
    from bokeh.models import Div

    model = state["model"]
    controls = [state["variable"]] + ([Div(text="model variant"), model] if model else []) + \
        [row(state["map_x"], state["map_y"])] + list(state["sliders"].values())
    key = flag_key(ds, p)
    # fits a 1,280 px window: the controls keep 300 px, the rest stretches (issue 46)
    return column(Div(sizing_mode="stretch_width", text=header),
                  row(column(*controls, width=300),
                      column(views["readout"], row(views["map_fig"], views["lines_fig"],
                                                   sizing_mode="stretch_width"),
                             key, sizing_mode="stretch_width"),
                      sizing_mode="stretch_width"),
                  *views["where_box"],
                  row(*views["figures"], sizing_mode="stretch_width"),
                  views["table"], views["note"], views["hold"], *views["fidelity_box"],
                  sizing_mode="stretch_width")


def build_html(ds, *, source: str = "", where=(), fidelity=None) -> str:
    """The self-contained explorer page of a cube, as HTML text (bokeh's JS inlined).

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    source : str
        The cube's path, named on the page.
    where : sequence of str or Condition
        ``--where`` conditions (see :func:`build_document`).
    fidelity : (xarray.Dataset, str), optional
        The cube's fidelity dataset and its name (see :func:`build_document`).

    Returns
    -------
    str
    """
    from bokeh.embed import file_html
    from bokeh.resources import Resources

    doc = build_document(ds, source=source, where=where, fidelity=fidelity)
    text = file_html(doc, Resources(mode="inline"), title=doc.title)
    # Where Panel is imported in the same process, bokeh bundles its extensions' script
    # tags (relative URLs this page never uses and that could not load offline): drop them.
    return re.sub(r'<script[^>]*\bsrc="[^"]*"[^>]*>\s*</script>\s*', "", text)


#: The page server's bounds (tornado's HTTPServer): a request's headers and body each
#: arrive within a minute [s] (a client that sends part of a request and stops no longer
#: holds its connection for an hour), headers of at most 64 KiB and a body of at most
#: 1 MiB [B] (the page sends none; its messages go over the websocket).
SERVER_LIMITS = {"idle_connection_timeout": 60, "body_timeout": 60,
                 "max_header_size": 64 * 1024, "max_body_size": 1 << 20}


class _OneLine(logging.Filter):
    """A server log record on one line: an exception a malformed request raised (tornado's
    "Uncaught exception GET /ws" with a traceback: a websocket without Bokeh's subprotocol,
    a session id that is no token) becomes the request, the exception's type and the
    first 200 characters of its message."""

    def filter(self, record):
        if record.exc_info or "\n" in str(record.msg):
            head = record.getMessage().splitlines()[0] if record.getMessage() else ""
            exc = record.exc_info[1] if record.exc_info else None
            why = f": {type(exc).__name__}: {' '.join(str(exc).split())[:200]}" if exc else ""
            record.msg, record.args = f"{head[:300]}{why}", ()
            record.exc_info = record.exc_text = record.stack_info = None
        return True


def one_line_server_logs():
    """Make every record the page server logs (tornado's, Bokeh's) one line on stderr:
    a handler of the root logger where it has none (else Python's last-resort handler
    printed tracebacks), and :class:`_OneLine` on it and on Bokeh's own handlers."""
    root = logging.getLogger()
    if not root.handlers:
        handler = logging.StreamHandler()
        handler.setLevel(logging.WARNING)
        root.addHandler(handler)
    for handler in [*root.handlers, *logging.getLogger("bokeh").handlers]:
        if not any(isinstance(f, _OneLine) for f in handler.filters):
            handler.addFilter(_OneLine())


def serve(ds, *, port: int, source: str = "", where=(), show: bool = True, ready=None,
          fidelity=None):
    """Serve the page of :func:`build_document` on ``127.0.0.1:port`` until interrupted.

    The numbers are read from the cube once; each browser session gets its own document.
    ``ready`` (no arguments) is called once the server listens.
    """
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    conditions = _conditions(where)
    payload = build_payload(ds, conditions)

    def session(doc):
        build_document(ds, source=source, where=conditions, served=True, payload=payload,
                       doc=doc, fidelity=fidelity)

    one_line_server_logs()
    server = Server({"/": Application(FunctionHandler(session))}, port=port,
                    address="127.0.0.1",
                    allow_websocket_origin=[f"127.0.0.1:{port}", f"localhost:{port}"],
                    http_server_kwargs=dict(SERVER_LIMITS))
    server.start()
    if ready is not None:
        ready()
    if show:
        server.io_loop.add_callback(server.show, "/")
    server.io_loop.start()
