"""Design charts drawn from a saved cube: the paper's figures 4, 6, 7 and 12, and a design map.

Charts read the :class:`xarray.Dataset` only; they never compute physics. Every axis label
comes from the variable registry (:mod:`nylonflex.variables`) in the unit a designer reads
(mm, deg, kPa, N), and every title names the slice of the cube it shows. Figures are
:class:`matplotlib.figure.Figure` objects made without pyplot (:func:`new_figure`): drawing
never switches the caller's backend nor leaves figures in pyplot's state.

Each chart is a function ``f(ds, **slice) -> matplotlib.figure.Figure``; the keyword
arguments choose the slice in SI (default: the grid values nearest the paper's choices), and
:func:`draw_charts` passes a slice (``at``, ``coil_index``) to every chart that draws along
it (``nylonflex chart CUBE --at length=70mm,wrap_angle=8deg --coil-index 1.1,1.7``).
Subtitles are written from the values drawn; the paper's worked examples are marked only
where the slice holds them exactly, with the cube's values there.
"""

from __future__ import annotations

import inspect
import warnings
from pathlib import Path

import numpy as np

from ..config.charts import CHART_REGISTRY
from ..files.atomic import OwnedFiles, save_figure
from ..units import InputError
from ..variables import VARIABLES, to_display
from ._common import FORMATS, RC, _grid_value, new_figure, rc_context
from ._parallel import draw_all
from .compare import comparable, compare
from .curves import fig4, fig6, fig7
from .dynamics import cycle_rate_lines, cycle_rate_map, force_rate, tracking_map
from .fig12 import fig12a, fig12b, fig12c
from .maps import design_map, feasibility_map

__all__ = ["CHARTS", "FORMATS", "RC", "SLICE_AXES", "chart_slice", "compare", "cycle_rate_lines",
           "cycle_rate_map", "design_map", "force_rate",
           "draw_charts", "feasibility_map", "fig4", "fig6", "fig7", "fig12a", "fig12b",
           "fig12c", "new_figure", "rc_context", "tracking_map"]


#: Chart name -> function, the names a config's ``charts`` list accepts (the registry's,
#: :data:`nylonflex.config.charts.CHART_REGISTRY`, in its order).
CHARTS = {name: chart.load() for name, chart in CHART_REGISTRY.items()}
#: Axes each chart draws along: a cube with a single value there cannot show it.
NEEDS = {name: chart.needs for name, chart in CHART_REGISTRY.items()}
#: Drawing time of each chart relative to fig4's: the longest are drawn first.
COST = {name: chart.cost for name, chart in CHART_REGISTRY.items()}
#: Charts that draw every model of a cube in one figure; the others are drawn once a model.
ALL_MODELS = tuple(name for name, chart in CHART_REGISTRY.items() if not chart.per_model)


def _unmet(ds, name):
    chart = CHART_REGISTRY[name]
    if chart.variable is not None and chart.variable not in ds:
        return f"{name} skipped: the cube has no {chart.variable} ({chart.absent})"
    short = [axis for axis in chart.needs if ds.sizes[axis] < 2]
    return (f"{name} skipped: it needs at least 2 values of {' and '.join(short)}; the cube "
            "has 1") if short else None


#: Axes a chart slice (``--at``) may fix.
SLICE_AXES = ("radius", "wall_thickness", "length", "wrap_angle")


def _on_grid(ds, name, values, field):
    out = []
    for value in np.atleast_1d(values):
        grid = _grid_value(ds, name, float(value))
        if grid is None:
            v = VARIABLES[name]
            unit = "" if v.display == "1" else f" {v.display}"
            shown = ", ".join(f"{x:g}" for x in to_display(name, ds[name].values[:12]))
            more = ", ..." if ds.sizes[name] > 12 else ""
            raise InputError(f"{field}: {name}={float(to_display(name, value)):g}{unit} is "
                             f"not a grid value of the cube; it has {shown}{more}{unit}")
        out.append(grid)
    return out


def chart_slice(ds, at=None, coil_index=None) -> dict:
    """Check a chart slice against the cube: ``{axis: grid value}`` [SI] and coil indices.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube.
    at : dict, optional
        ``{axis: value}`` [SI] for axes of :data:`SLICE_AXES`.
    coil_index : float or sequence of float, optional
        Coil indices to draw [-].

    Returns
    -------
    dict
        The slice with grid values, ``coil_index`` a list.

    Raises
    ------
    InputError
        An axis that charts cannot fix, or a value that is not a grid value.
    """
    out = {}
    for name, value in (at or {}).items():
        if name not in SLICE_AXES:
            raise InputError(f"--at: charts take {', '.join(SLICE_AXES)} (coil indices with "
                             f"--coil-index), got {name!r}")
        out[name] = _on_grid(ds, name, value, "--at")[0]
    if coil_index is not None:
        out["coil_index"] = _on_grid(ds, "coil_index", coil_index, "--coil-index")
    return out


def _slice_kwargs(func, chosen):
    """The keyword arguments of chart ``func`` that the slice ``chosen`` sets."""
    params = inspect.signature(func).parameters
    kw = {name: value for name, value in chosen.items() if name in params}
    if "wall_thickness" in chosen and "walls" in params:
        kw["walls"] = [chosen["wall_thickness"]]
    return kw


#: Attributes a chart reads whole (the model spread's variants: charts/model_spread.py, which
#: bounds what it reads of it).
_WHOLE_ATTRS = ("model_spread",)


def _short_attrs(ds, limit=80):
    """``ds`` with every string attribute cut to ``limit`` characters (a shallow copy): a
    title or footer never lays out a huge attribute (a 10 MB ``name`` hung the chart)."""
    attrs = {k: (v if not isinstance(v, str) or len(v) <= limit or k in _WHOLE_ATTRS
                 else v[:limit] + "...") for k, v in ds.attrs.items()}
    if all(attrs[k] is v for k, v in ds.attrs.items()):
        return ds
    ds = ds.copy(deep=False)
    ds.attrs = attrs
    return ds


def chart_owner(ds) -> str:
    """Who draws charts of ``ds`` [-]: the cube's resolved path, or its name without one."""
    source = ds.encoding.get("source")
    if source:
        return str(Path(source).resolve())
    return f"cube named {str(ds.attrs.get('name', '?'))[:200]}"


def _chart_file(name, where, fmt) -> str:
    """``fig12a.png``, or with the slice of a cube of several models and cooling sets
    ``fig12a_paper_forced_air_5mps.png`` (``where``: {dimension: name}, None: whole)."""
    parts = [name, *(str(v).replace(" m/s", "mps").replace(" ", "_")
                     for v in (where or {}).values())]
    return "_".join(parts) + f".{fmt}"


def _slices(ds, name) -> list:
    """The slices chart ``name`` is drawn once for: each (model, cooling set) of a cube of
    several, a model left whole where the chart draws every model itself; [None]: once."""
    models = [str(m) for m in ds["model"].values] if "model" in ds.dims and \
        name not in ALL_MODELS else [None]
    coolings = [str(c) for c in ds["cooling"].values] if "cooling" in ds.dims else [None]
    out = [{k: v for k, v in (("model", m), ("cooling", c)) if v is not None}
           for m in models for c in coolings]
    return [w or None for w in out]


def draw_charts(ds, names, out_dir, fmt="png", on_skip=None, *, at=None, coil_index=None,
                progress=None, variable=None, overwrite=False,
                refuse_foreign=True, processes=None) -> list[Path]:
    """Draw the named charts of a cube into ``<out_dir>/<name>.<fmt>``.

    Parameters
    ----------
    ds : xarray.Dataset
        A nylonflex cube (:func:`nylonflex.open_cube`).
    names : sequence of str or None
        Chart names (:data:`CHARTS`); None draws all the cube can show.
    out_dir : path
        Folder for the images (created if missing).
    fmt : {"png", "pdf", "svg"}
        Image format.
    on_skip : callable, optional
        Receives a one-line message for each chart the cube cannot show (an axis it plots
        along has a single value); a warning by default.
    at : dict, optional
        The slice, ``{axis: value}`` [SI] for axes of :data:`SLICE_AXES` (grid values):
        each chart takes the ones it holds fixed.
    coil_index : float or sequence of float, optional
        Coil indices to draw [-] (grid values); default every one of the cube.
    progress : callable, optional
        Called as ``progress(done, total)`` [charts] after each chart.
    variable : str, optional
        The variable ``compare`` draws (default ``tip_force_max``).
    overwrite : bool
        Replace files nylonflex did not write for this cube [-] (a manifest in the folder,
        :class:`nylonflex.files.atomic.OwnedFiles`, records the charts each cube drew).
    refuse_foreign : bool
        With such a file in the way and no ``overwrite``: raise before drawing anything
        (True) or leave that chart undrawn with a line to ``on_skip`` (False) [-].
    processes : int, optional
        Draw on this many forked processes (default: one a core; 1 draws here, one by
        one). Each chart is drawn whole by one process, so the files are the same.

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of ``names``.

    Raises
    ------
    InputError
        An unknown chart name or format, or (``refuse_foreign``) a file in the way that
        nylonflex did not write for this cube.
    """
    if not names:  # every chart the cube can show (feasibility only with requirements)
        names = [n for n, c in CHART_REGISTRY.items()
                 if c.variable is None or c.variable in ds]
    names = list(names)
    unknown = [n for n in names if n not in CHARTS]
    if unknown:
        raise InputError(f"--figure: unknown chart {unknown[0]!r}; accepted: "
                         f"{', '.join(CHARTS)}")
    if fmt not in FORMATS:
        raise InputError(f"--format: unknown image format {fmt!r}; accepted: "
                         f"{', '.join(FORMATS)}")
    chosen = chart_slice(ds, at, coil_index)
    if variable is not None:
        if "compare" not in names:
            raise InputError("--variable: only --figure compare draws a chosen variable")
        if variable not in comparable(ds):
            raise InputError(f"--variable: compare draws one of {', '.join(comparable(ds))}; "
                             f"got {variable!r}")
        chosen["variable"] = variable

    owner = chart_owner(ds)
    ds = _short_attrs(ds)
    out_dir = Path(out_dir)
    jobs = [(name, where) for name in names for where in _slices(ds, name)]
    owned = OwnedFiles(out_dir, owner)
    targets = [out_dir / _chart_file(n, m, fmt) for n, m in jobs]
    blocked = {} if overwrite else {p: why for p in targets if (why := owned.foreign(p))}
    if blocked and refuse_foreign:
        first = next(iter(blocked.values()))
        more = f" (and {len(blocked) - 1} more)" if len(blocked) > 1 else ""
        raise InputError(f"--out: {first}{more}; not replaced: give another folder or "
                         "--overwrite")
    out_dir.mkdir(parents=True, exist_ok=True)
    todo = []
    for name, model in jobs:
        reason = _unmet(ds, name)
        path = out_dir / _chart_file(name, model, fmt)
        if not reason and path in blocked:
            reason = f"{blocked[path]}; not replaced (draw it with 'nylonflex chart CUBE " \
                     "--overwrite')"
        if reason:
            if on_skip is None:
                warnings.warn(reason, stacklevel=2)
            else:
                on_skip(reason)
            continue
        todo.append((name, model, path, fmt, _slice_kwargs(CHARTS[name], chosen)))

    warm_up()  # once, before the drawing processes fork

    def done(k, total, path):  # recorded as each is written: a later failure keeps them ours
        owned.record([path])
        if progress is not None:
            progress(k, total)

    # longest first (the files and the returned order do not depend on it)
    order = sorted(range(len(todo)), key=lambda i: -COST[todo[i][0]])
    drawn = draw_all(_draw_one, ds, [todo[i] for i in order], processes, done)
    paths = [None] * len(todo)
    for i, path in zip(order, drawn):
        paths[i] = path
    return paths


def warm_up():
    """Import what drawing needs, so that forked drawing processes inherit it.

    matplotlib (Agg); and xarray's duck-array modules: xarray imports ``dask.array``
    (0.3-0.5 s) at a process's first indexing when dask is installed, which each
    drawing process would otherwise do again.
    """
    import matplotlib.backends.backend_agg  # noqa: F401  (the PNG canvas)
    import matplotlib.figure  # noqa: F401
    import xarray as xr

    xr.DataArray(np.zeros(2), dims="x").isel(x=0)


def _draw_one(ds, name, where, path, fmt, kwargs) -> Path:
    """Draw chart ``name`` (of the slice ``where``, {dimension: name}, of a cube of several
    models or cooling sets) into ``path``."""
    with rc_context():
        # a cube of several models (cooling sets): each figure once a model (cooling set),
        # its name in title and file
        one = ds if where is None else ds.sel(where, drop=True)
        fig = CHARTS[name](one, **kwargs)
        if where is not None:
            shown = ", ".join(f"{k}: {v}" for k, v in where.items())
            title = fig.get_suptitle()
            # a line of the figure's own title (the layout keeps it clear of the axes)
            fig.suptitle(f"{shown}\n{title}" if title else shown,
                         **({} if title else {"fontsize": "medium", "weight": "bold"}))
        # fixed metadata so that the same cube gives byte-stable PDF/SVG files; PNG at
        # zlib level 1: 12 % larger files, a third of the encoding time. The figure's
        # constrained layout keeps everything inside it, so the file is the figure as laid
        # out: bbox_inches="tight" drew each chart twice (a quarter of the drawing time)
        # to trim a few pixels of margin
        meta = {"png": {"Software": "nylonflex"}, "pdf": {"CreationDate": None},
                "svg": {"Date": None}}[fmt]
        extra = {"pil_kwargs": {"compress_level": 1}} if fmt == "png" else {}
        save_figure(fig, path, format=fmt, metadata=meta, **extra)
    return path
