"""``nylonflex design SPEC.yaml``: the best design or Pareto set a spec asks for."""

from __future__ import annotations

import sys
from pathlib import Path

from . import warn
from ._common import progress_bar

HELP = "design from a spec: best design or Pareto front, refined off the grid"
DESCRIPTION = """Design from a specification (objectives, constraints with units, a cube or grid).

One objective gives the best design; several give the non-dominated (Pareto) set. With
'refine' the axes are optimised continuously with the exact model (SLSQP; epsilon-constraint
for several objectives), and every reported design is re-evaluated exactly. An infeasible
spec exits 0 and says which constraint no design meets and how close the nearest comes."""


def add_arguments(p):
    p.add_argument("spec", help="the design spec (YAML)")
    p.add_argument("--cube", metavar="PATH", help="start from this cube instead of the spec's")
    p.add_argument("--format", choices=["table", "json", "csv"], default="table")
    p.add_argument("--chart", metavar="DIR", help="draw the Pareto front into DIR")
    p.add_argument("--quiet", action="store_true",
                   help="no progress (a bar on a terminal, else a line a minute)")


def run(args) -> int:
    from ..design import run_design
    from ..design.report import format_csv, format_json, format_table, summary

    with progress_bar("refine", unit="start", quiet=args.quiet, command="design") as bar:
        res = run_design(args.spec, cube=args.cube, progress=bar)
    fmt = {"table": format_table, "json": format_json, "csv": format_csv}[args.format]
    sys.stdout.write(fmt(res))
    if not res.designs and args.format != "table":
        for line in summary(res)[1:]:  # machine formats: the explanation on stderr
            print(f"nylonflex design: {line.strip()}", file=sys.stderr)
    if args.chart:
        from ..charts.design import draw_front

        target = Path(args.chart) / f"{res.spec.name}.png"
        if target.exists():
            warn("design", f"{target} exists; replacing it")
        print(f"chart: {draw_front(res, args.chart)}", file=sys.stderr)
    return 0
