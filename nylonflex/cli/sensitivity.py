"""``nylonflex sensitivity CONFIG``: Sobol' indices of design variables (docs/interface.md)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

from ..units import InputError, json_text
from ._common import progress_bar

HELP = "Sobol' sensitivity of design variables to the uncertain parameters"
DESCRIPTION = """Sobol' first-order and total indices (SALib, Saltelli sampling, 95 %
bootstrap intervals) of the chosen outputs with respect to every parameter of the config's
uncertainty: section. --at with all five axes analyses one design; fewer (or none) fixes
those axes and averages the per-design indices over grid designs (at most --designs of
them, drawn with the seed). With a tracking: block the closed-loop variables
(tracking_rms_error, tracking_max_temperature, tracking_energy, tracking_bandwidth) are
outputs too: every sample runs the sweep's closed loop, about 8 ms of CPU each for
fig12_tracking.yaml's 125 s loop (512 x (4 factors + 2) = 3,072 runs of one design: about
25 s of CPU), at most 16,384 runs an analysis. A config without an
uncertainty: section takes one from --set, e.g. --set 'uncertainty={parameters:
{silicone.mu: {rel_sd: 0.1}, nylon.heat_loss_per_length: {rel_sd: 0.1}}}'. See
docs/uncertainty.md."""


def add_arguments(p):
    p.add_argument("config", help="sweep config with an uncertainty: section")
    p.add_argument("--at", metavar="NAME=VALUE,...",
                   help="design axes, e.g. radius=7.5mm,wall_thickness=2mm,...")
    p.add_argument("--output", nargs="+", default=["tip_force_max"], metavar="NAME",
                   help="design variables to analyse (default tip_force_max); with a "
                   "tracking: block also tracking_rms_error, tracking_max_temperature, "
                   "tracking_energy (and tracking_bandwidth with tracking.bandwidth)")
    p.add_argument("--samples", type=int, default=512, metavar="N",
                   help="Saltelli base sample N, a power of 2 (default 512)")
    p.add_argument("--designs", type=int, default=16, metavar="N",
                   help="most grid designs averaged over without a full --at (default 16)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config key")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument("--chart", metavar="DIR", help="write the bar chart sensitivity.png there")
    p.add_argument("--quiet", action="store_true",
                   help="no progress (a bar on a terminal, else a line a minute)")


def run(args) -> int:
    from ..config import load_config
    from ..query import parse_at
    from ..uncertainty import sobol_indices
    from ..variables import AXES

    cfg = load_config(args.config, args.set)
    at = parse_at(args.at) if args.at else {}
    if args.designs < 1:
        raise InputError(f"--designs: must be 1 or more, got {args.designs}")
    with progress_bar("sensitivity", unit="step", quiet=args.quiet) as bar:
        res = sobol_indices(cfg, tuple(args.output), at=at, base_samples=args.samples,
                            max_designs=args.designs, progress=bar)
    if args.chart:
        path = Path(args.chart) / "sensitivity.png"
        from ..charts.sensitivity import sensitivity_chart

        sensitivity_chart(res, path)
        print(f"wrote {path}", file=sys.stderr)
    if args.format == "json":
        sys.stdout.write(json_text(res.to_json(), indent=1))
        return 0
    where = ("one design" if len(at) == len(AXES) else
             f"mean over {res.designs} grid designs")
    print(f"Sobol' indices ({where}, {res.samples} runs a design, +- 95 % interval)")
    width = max(len(p) for p in res.parameters)
    for o, d in res.indices.items():
        print(f"{o}:")
        if all(math.isnan(v) for v in d["first"].values()):  # the output never varied
            print("  does not vary over the samples here: no indices")
            continue
        print(f"  {'parameter':<{width}}  {'first':>15}  {'total':>15}")
        for p in res.parameters:
            first, total = (f"{d[k][p]:.3f} +- {d[k + '_conf'][p]:.3f}"
                            for k in ("first", "total"))
            print(f"  {p:<{width}}  {first:>15}  {total:>15}")
    return 0
