"""``nylonflex sweep CONFIG``: validate, sweep, write the cube and its charts."""

from __future__ import annotations

import sys
from pathlib import Path

HELP = "evaluate a design space into a cube"


def add_arguments(s):
    s.add_argument("config", help="YAML config (see configs/)")
    s.add_argument("--out", help="cube path (default sweeps/<name>/cube.h5)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config key, e.g. grid.radius.num=81 (repeatable)")
    s.add_argument("--resume", action="store_true", help="finish an interrupted run")
    s.add_argument("--overwrite", action="store_true",
                   help="replace a cube already at --out (the old one stays until the new "
                        "one is complete)")
    s.add_argument("--workers", type=int, help="local threads (default: all cores)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask distributed cluster, e.g. tcp://host:8786")
    s.add_argument("--no-charts", action="store_true", help="skip the config's charts")
    s.add_argument("--quiet", action="store_true", help="no progress bar")


def _progress(total, quiet):
    from tqdm import tqdm

    disable = quiet or not sys.stderr.isatty()
    return tqdm(total=total, unit="design", unit_scale=True, disable=disable,
                desc="sweep", smoothing=0.1, dynamic_ncols=True)


def run(args) -> int:
    from ..config import load_config
    from ..sweep import default_output, run_sweep
    from ..files import refuse_special

    cfg = load_config(args.config, args.set)
    out = Path(args.out) if args.out else default_output(cfg)
    refuse_special(out, "--out")

    def log(msg):
        if not args.quiet:
            print(msg, file=sys.stderr)

    with _progress(cfg.n_designs, args.quiet) as bar:
        ds = run_sweep(cfg, out, resume=args.resume, workers=args.workers,
                       scheduler=args.scheduler, progress=bar.update, log=log,
                       overwrite=args.overwrite)
    print(f"{out}  {cfg.n_designs:,} designs  complete")
    if cfg.charts and not args.no_charts:
        from ..charts import draw_charts

        skip = lambda msg: print(f"nylonflex sweep: {msg}", file=sys.stderr)  # noqa: E731
        for path in draw_charts(ds, cfg.charts, out.parent, "png", on_skip=skip):
            print(path)
    ds.close()
    return 0
