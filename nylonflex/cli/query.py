"""``nylonflex query CUBE``: print the designs asked for (INTERFACE.md)."""

from __future__ import annotations

import sys

HELP = "ask a cube about designs"


def add_arguments(q):
    q.add_argument("cube")
    q.add_argument("--at", metavar="NAME=VALUE,...", help="one design, e.g. radius=7.5mm")
    q.add_argument("--where", action="append", default=[], metavar="EXPR",
                   help='filter, e.g. "tip_force_max >= 0.5 N" (repeatable)')
    q.add_argument("--sort", metavar="NAME", help="order by a variable or axis (- for desc)")
    q.add_argument("--limit", type=int, help="at most N rows")
    q.add_argument("--format", choices=["table", "json", "csv"], default="table")


def run(args) -> int:
    import numpy as np

    from ..query import format_csv, format_json, format_table, parse_at, parse_where, query_cube
    from ..units import InputError
    from ._common import open_cube_for

    ds = open_cube_for("query", args.cube)  # an incomplete cube: queried where it is done
    try:
        res = query_cube(ds, at=parse_at(args.at) if args.at else None,
                         where=parse_where(args.where), sort=args.sort, limit=args.limit)
        if res.single and len(res) == 1 and np.isnan(res.data["tip_force_max"][0]):
            raise InputError("--at: this design is not in the cube yet (an incomplete "
                             "cube); finish the sweep with 'nylonflex sweep CONFIG --resume'")
    finally:
        ds.close()
    fmt = {"table": format_table, "json": format_json, "csv": format_csv}[args.format]
    sys.stdout.write(fmt(res))
    return 0
