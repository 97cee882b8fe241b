"""``nylonflex explore CUBE``: a local web page with sliders over a cube (docs/interface.md)."""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

from ..units import InputError
from . import warn
from ._common import open_cube_for, progress_bar

HELP = "explore a cube in a local web page (or write one offline HTML file)"
DESCRIPTION = """\
Serve a page on http://127.0.0.1:PORT with a variable selector, a slider per axis, a design
map (strength-limited and flagged designs marked), figure 12 style lines and, for the picked
design, every design variable and its curves. Sliders snap to grid values; nothing is
interpolated. With --html, write one self-contained file that works offline instead: the
same page, drawn by the same code. --where marks the matching designs on the map and lists
them in a table (sort by a column's title, pick a design by its row).

  nylonflex explore sweeps/fig12/cube.h5
  nylonflex explore sweeps/fig12/cube.h5 --html fig12.html
  nylonflex explore sweeps/fig12/cube.h5 --where "tip_force_max >= 0.5 N"
"""


def add_arguments(p):
    p.add_argument("cube")
    p.add_argument("--port", type=int, default=5006, help="local port (default 5006)")
    p.add_argument("--html", metavar="OUT.html", help="write one offline HTML file and exit")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --html file")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument("--quiet", action="store_true",
                   help="--html: no progress (a bar on a terminal, else a line a minute)")
    p.add_argument("--where", action="append", default=[], metavar="EXPR",
                   help="mark the designs that meet EXPR (as query --where, e.g. "
                        "\"tip_force_max >= 0.5 N\"; repeat to AND) and list them in a "
                        "sortable table")
    p.add_argument("--cooling", metavar="NAME",
                   help="the cooling set the page shows, for a cube of several (its "
                        "'cooling' coordinate; nylonflex info lists them)")


_NEEDS_EXTRA = "nylonflex explore: error: {what}: pip install 'nylonflex[explore]'"


def _has(module: str) -> bool:
    """Whether ``module`` can be imported (the optional ``explore`` extra)."""
    return importlib.util.find_spec(module) is not None


def port_free(port: int, host: str = "127.0.0.1") -> bool:
    """Whether ``host:port`` can be bound now."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((host, port))
        except OSError:
            return False
    return True


def run(args) -> int:
    if args.html:
        from ..files.atomic import refuse_special

        out = Path(args.html)
        refuse_special(out, "--html", inputs=[args.cube])
        if os.path.lexists(out) and not args.overwrite:
            raise InputError(f"--html {out}: the file exists; pass --overwrite to replace it")
        if not out.parent.is_dir():
            raise InputError(f"--html {out}: no such folder {out.parent}")
    elif not 1 <= args.port <= 65535:
        raise InputError(f"--port {args.port}: expected a port number 1..65535")
    elif not port_free(args.port):
        raise InputError(f"--port {args.port}: already in use on 127.0.0.1; choose another "
                         "with --port N")

    from ..query import parse_where

    where = parse_where(args.where)  # the query's own parser: bad input before any work
    ds = open_cube_for("explore", args.cube)
    ds, source = _one_cooling(ds, args.cooling, str(args.cube))
    if not _has("bokeh"):
        print(_NEEDS_EXTRA.format(what="the explorer needs Bokeh"), file=sys.stderr)
        return 2  # the environment's: exit 2, one line (cli.environment_problem)
    from ..explore.page import build_html, serve

    fidelity = _fidelity(args.cube)
    if args.html:
        from ..files.atomic import write_atomic

        with progress_bar("explore --html", unit="s", quiet=args.quiet, command="explore"):
            text = build_html(ds, source=source, where=where, fidelity=fidelity)
        write_atomic(out, text.encode("utf-8"), "--html", inputs=[args.cube])
        print(f"{out}  {len(text) / 1e6:.1f} MB  offline explorer of {args.cube}")
        return 0

    url = f"http://127.0.0.1:{args.port}/"

    def ready():
        print(f"nylonflex explore: serving {args.cube} at {url} (Ctrl-C to stop)", flush=True)

    try:
        serve(ds, port=args.port, source=source, where=where,
              show=not args.no_browser, ready=ready, fidelity=fidelity)
    except KeyboardInterrupt:
        pass
    return 0


def _one_cooling(ds, name, source):
    """The cube at the cooling set ``name`` (a cube of several: the page shows one), and the
    page's source line naming it."""
    have = [str(c) for c in ds["cooling"].values] if "cooling" in ds.dims else []
    if name is None and not have:
        return ds, source
    if not have:
        raise InputError(f"--cooling {name}: this cube has one cooling set; leave --cooling "
                         "out")
    if name not in have:
        given = "not given" if name is None else f"got {name!r}"
        raise InputError(f"--cooling: this cube holds {len(have)} cooling sets "
                         f"({', '.join(have)}) and the page shows one; {given}")
    return ds.sel(cooling=name, drop=True), f"{source} (cooling: {name})"


def _fidelity(cube):
    """(dataset, file name) of the cube's fidelity dataset (``nylonflex verify``), or None;
    an unreadable one is a warning, and the page goes on without it."""
    from ..fe.verify import fidelity_path, open_fidelity

    try:
        fid = open_fidelity(cube)
    except (OSError, ValueError) as exc:
        warn("explore", f"{fidelity_path(cube)}: unreadable ({type(exc).__name__}); the page "
             "shows no FE fidelity")
        return None
    return None if fid is None else (fid, fidelity_path(cube).name)
