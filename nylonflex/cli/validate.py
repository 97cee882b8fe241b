"""``nylonflex validate CONFIG DATA``: one design's model against its measurements."""

from __future__ import annotations

import sys
from pathlib import Path

from ..units import json_text

HELP = "compare a design's model with actuator measurements"
DESCRIPTION = """Compare the model of the design in CONFIG (a `design:` section, as in
configs/control.yaml, and its silicone and nylon sets) with measurements: columns
stroke,pressure [kPa] (figure 4), pressure [kPa],bend_angle [deg] (figure 6) or
pressure [kPa],tip_force [N] (figure 7). Prints the error as the paper reports it (largest
model-data difference over the largest measured value, %) and the RMSE."""


def add_arguments(p):
    p.add_argument("config", help="config with a design: section")
    p.add_argument("data", help="measurements (CSV, units in the header)")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument("--chart", metavar="DIR", help="draw model against data into DIR")


def run(args) -> int:
    from ..calibration.data import read_table
    from ..calibration.validate import validate_design

    table = read_table(args.data)
    comps = validate_design(args.config, table)
    if args.chart:
        from ..charts.fit import validate_chart

        validate_chart(comps, Path(args.chart) / f"validate_{Path(args.data).stem}.png",
                       title=f"{Path(args.config).name} against {Path(args.data).name}")
    if args.format == "json":
        out = {"config": str(args.config), "data": {"path": table.path, "sha256": table.sha256},
               "checks": [c.to_json() for c in comps]}
        sys.stdout.write(json_text(out, indent=2))
        return 0
    from ..variables import VARIABLES, to_display

    print(f"{args.config} against {table.path} ({len(table)} rows)")
    for c in comps:
        # the RMSE in the unit the data is read in (deg, kPa), as the table quotes it
        known = c.quantity in VARIABLES and VARIABLES[c.quantity].units == c.unit
        rmse = float(to_display(c.quantity, c.rmse)) if known else c.rmse
        unit = VARIABLES[c.quantity].display if known else c.unit
        print(f"  {c.quantity:<11} against {c.x_name:<9} {c.error_name.replace('_', ' ')} "
              f"{c.error_percent:.2f} %, RMSE {rmse:.4g} {unit} ({c.x.size} points)")
    return 0
