"""``nylonflex query CUBE``: print the designs asked for (docs/interface.md)."""

from __future__ import annotations

import argparse
import sys

from ..units import InputError
from ._common import open_cube_for, progress_bar

HELP = "ask a cube about designs"

#: Rows printed when ``--limit`` is not given.
DEFAULT_LIMIT = 20


def _limit(text):
    if str(text).strip().lower() in ("all", "none"):
        return None
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number or 'all', got {text!r}")
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more, got {value}")
    return value


def add_arguments(q):
    from ..query import COLUMNS
    from ..variables import AXES

    q.add_argument("cube")
    q.add_argument("--at", action="append", default=[], metavar="NAME=VALUE,...",
                   help="one design or a slice, e.g. radius=7.5mm,wall_thickness=2mm; names: "
                        f"{', '.join(AXES)}; bare numbers in mm, deg (none for coil_index); "
                        "between grid points the exact model is evaluated; repeated --at "
                        "options are merged (each axis once)")
    q.add_argument("--interpolate", action="store_true",
                   help="between grid points, interpolate the cube linearly instead of "
                        "evaluating the exact model")
    q.add_argument("--where", action="append", default=[], metavar="EXPR",
                   help='filter, e.g. "tip_force_max >= 0.5 N", "radius <= 10mm", '
                        '"bend_angle_max >= 180deg" (repeatable, ANDed); OP one of <, <=, '
                        "==, !=, >=, >; a bare number is in the display unit (mm, deg, kPa, "
                        "N mm, ...: nylonflex list variables)")
    q.add_argument("--sort", metavar="NAME",
                   help=f"order by one of: {', '.join(COLUMNS)} (-NAME or NAME:desc for "
                        "descending)")
    q.add_argument("--columns", action="append", metavar="NAME,...",
                   help="the columns to print, e.g. radius,tip_force_max,validity ('all' for "
                        "every one); default: a table shows the axes, the --where and --sort "
                        "names, then limit, tip_force_max, bend_angle_max and validity; json "
                        "and csv every column")
    q.add_argument("--limit", type=_limit, default=DEFAULT_LIMIT, metavar="N|all",
                   help=f"at most N rows (default {DEFAULT_LIMIT}; 'all' for every one)")
    q.add_argument("--format", choices=["table", "json", "csv"], default="table",
                   help="table (display units), json or csv (SI)")
    q.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    import numpy as np

    from ..query import (by_variable, format_csv, format_json, format_table, held_back,
                         parse_at, parse_where, query_cube)
    from ..query.notes import unit_notes

    # a --where scan on the grid reads the cube through h5py alone (no xarray nor pandas)
    light = (lambda c: by_variable(c, args.at, args.where, args.interpolate)) \
        if args.where and not args.interpolate else None
    # an incomplete cube: queried where it is done
    ds = open_cube_for("query", args.cube, light=light)
    try:
        where = parse_where(args.where)
        with progress_bar("query", unit="slab", quiet=args.quiet) as bar:
            res = query_cube(ds, at=parse_at(args.at) if args.at else None,
                             where=where, sort=args.sort,
                             limit=args.limit, interpolate=args.interpolate,
                             columns=args.columns,
                             progress=bar, log=lambda m: bar.write(f"nylonflex query: {m}"))
        if res.single and len(res) == 1 and np.isnan(res.data["tip_force_max"][0]):
            raise InputError("--at: this design is not in the cube yet (an incomplete "
                             "cube); finish the sweep with 'nylonflex sweep CONFIG --resume'")
        notes = unit_notes(ds, where, res.matched) if not res.point else []
    finally:
        ds.close()
    fmt = {"table": format_table, "json": format_json, "csv": format_csv}[args.format]
    sys.stdout.write(fmt(res))
    for note in notes:  # a bare number read in mm or deg where the answer hints at m or rad
        print(f"nylonflex query: note: {note}", file=sys.stderr)
    hidden = held_back(res)
    if hidden and args.format == "csv":  # a table and JSON say so themselves
        print(f"nylonflex query: {len(res)} rows of {res.matched} matching; {hidden} held "
              "back (--limit N for more, --limit all for every one)", file=sys.stderr)
    return 0
