"""``nylonflex simulate CONFIG``: run the closed loop, write it, chart it, summarise it."""

from __future__ import annotations

from pathlib import Path

from ._common import progress_bar

HELP = "simulate the closed loop in time"


def add_arguments(m):
    m.add_argument("config", help="YAML simulation config (configs/control.yaml)")
    m.add_argument("--out", help="output file (default sweeps/<name>/sim.h5)")
    m.add_argument("--no-charts", action="store_true", help="skip the chart")
    m.add_argument("--quiet", action="store_true",
                   help="no progress (a bar on a terminal, else a line a minute)")


def run(args) -> int:
    from ..sim import load_sim_config, run_simulation, summary, write_simulation

    cfg = load_sim_config(args.config)
    out = Path(args.out) if args.out else Path("sweeps") / cfg.name / "sim.h5"
    from ..files.atomic import refuse_special

    refuse_special(out, "--out", inputs=[args.config])  # before the work
    with progress_bar("simulate", unit="s", quiet=args.quiet):  # the time elapsed
        ds = run_simulation(cfg)
    write_simulation(ds, out, inputs=[args.config])
    written = [str(out)]
    if not getattr(args, "no_charts", False):
        from ..charts.sim import draw_simulation_charts

        written += [str(p) for p in draw_simulation_charts(ds, out.parent, stem=out.stem)]
    for line in summary(cfg, ds):
        print(line)
    print(f"  wrote {', '.join(written)}")
    return 0
