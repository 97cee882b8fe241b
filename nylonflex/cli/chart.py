"""``nylonflex chart CUBE``: draw charts of a saved cube (beside it by default)."""

from __future__ import annotations

import sys
from pathlib import Path

HELP = "draw design charts from a cube"


def add_arguments(c):
    from ..config import CHARTS

    c.add_argument("cube")
    c.add_argument("--figure", nargs="+", metavar="NAME",
                   help=f"figures (default: all): {', '.join(CHARTS)}")
    c.add_argument("--out", help="folder for the images (default: beside the cube)")
    c.add_argument("--format", choices=["png", "pdf", "svg"], default="png")


def run(args) -> int:
    from ..charts import draw_charts
    from ..units import InputError
    from ._common import open_cube_for

    ds = open_cube_for("chart", args.cube)
    out = Path(args.out) if args.out else Path(args.cube).parent
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {out} is a file; give a folder for the images")
    try:
        skip = lambda msg: print(f"nylonflex chart: {msg}", file=sys.stderr)  # noqa: E731
        for path in draw_charts(ds, args.figure, out, args.format, on_skip=skip):
            print(path)
    finally:
        ds.close()
    return 0
