"""``nylonflex chart CUBE``: draw charts of a saved cube (beside it by default)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..units import InputError
from ._common import open_cube_for, progress_bar

HELP = "draw design charts from a cube"


def add_arguments(c):
    from ..config import CHARTS

    c.add_argument("cube", nargs="?")  # "--figure fig4 CUBE" works too: see run()
    c.add_argument("--figure", nargs="+", metavar="NAME",
                   help=f"figures (default: all): {', '.join(CHARTS)} "
                        "('nylonflex list charts' says what each shows)")
    c.add_argument("--at", action="append", default=[], metavar="NAME=VALUE,...",
                   help="the slice, grid values of radius, wall_thickness, length, wrap_angle "
                        "(e.g. length=70mm,wrap_angle=8deg; bare numbers in mm, deg); each "
                        "chart takes the ones it holds fixed")
    c.add_argument("--coil-index", metavar="C,...",
                   help="coil indices to draw (grid values, e.g. 1.1,1.7); default all")
    c.add_argument("--variable", metavar="NAME",
                   help="the design variable --figure compare draws against radius for "
                        "every model (default tip_force_max)")
    c.add_argument("--out", help="folder for the images (default: beside the cube)")
    c.add_argument("--format", choices=["png", "pdf", "svg"], default="png",
                   help="image format: png, pdf or svg")
    c.add_argument("--overwrite", action="store_true",
                   help="replace image files nylonflex did not draw from this cube")
    c.add_argument("--quiet", action="store_true", help="no progress bar")


def _coil_indices(text):
    try:
        return [float(x) for x in str(text).split(",") if x.strip()]
    except ValueError:
        raise InputError(f"--coil-index: expected numbers separated by commas, e.g. 1.1,1.7, "
                         f"got {text!r}") from None


def run(args) -> int:
    from ..charts import draw_charts
    from ..query import parse_at

    from ..config import CHARTS

    if args.cube is None and args.figure and args.figure[-1] not in CHARTS:
        args.cube = args.figure.pop()  # "--figure fig4 CUBE": argparse gave CUBE to --figure
    if args.cube is None:
        raise InputError("cube: give the cube to draw, e.g. nylonflex chart "
                         "sweeps/fig12/cube.h5 --figure fig4")
    if args.figure == []:
        raise InputError(f"--figure: name at least one of {', '.join(CHARTS)}")
    ds = open_cube_for("chart", args.cube)
    out = Path(args.out) if args.out else Path(args.cube).parent
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {out} is a file; give a folder for the images")
    try:
        at = parse_at(args.at) if args.at else None
        coils = _coil_indices(args.coil_index) if args.coil_index else None
        skipped = []

        def skip(msg):
            skipped.append(msg)
            print(f"nylonflex chart: {msg}", file=sys.stderr)

        with progress_bar("charts", unit="chart", quiet=args.quiet, delay=0.0) as bar:
            paths = draw_charts(ds, args.figure, out, args.format, on_skip=skip, at=at,
                               coil_index=coils, progress=bar, variable=args.variable,
                               overwrite=args.overwrite)
        for path in paths:
            print(path)
    finally:
        ds.close()
    if args.figure and skipped:  # asked for by name, and not drawn: not done
        print(f"nylonflex chart: error: {len(skipped)} of the {len(args.figure)} figure(s) "
              "asked for could not be drawn from this cube (above)", file=sys.stderr)
        return 1
    return 0
