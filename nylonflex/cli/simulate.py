"""``nylonflex simulate CONFIG``: run the closed loop, write it, chart it, summarise it."""

from __future__ import annotations

import math
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
    from ..sim import load_sim_config, run_simulation, write_simulation

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
    for line in summary_lines(cfg, ds):
        print(line)
    print(f"  wrote {', '.join(written)}")
    return 0


def summary_lines(cfg, ds) -> list[str]:
    """Lines of the run's summary: tracking, step response, power and warnings, from the
    simulation ``ds`` of the config ``cfg`` (a :class:`~nylonflex.sim.SimConfig`), which
    holds the values (:func:`~nylonflex.sim.run_simulation`)."""
    import numpy as np

    from ..sim import reference_signal, settled_errors

    lines = [f"{cfg.name}: {len(cfg.actuators)} actuator(s) on {cfg.supply_voltage:g} V, "
             f"{cfg.duration:g} s at {cfg.step * 1e3:g} ms ({cfg.n_steps} steps), loop "
             f"{ds.attrs['loop_time'] * 1e3:.1f} ms"]
    for j, a in enumerate(cfg.actuators):
        get = (lambda k: float(ds[k].values[j])) if cfg.gripper else \
            (lambda k: float(ds.attrs[k]))
        tag = f"  {a.name}: " if cfg.gripper else "  "
        span = a.reference.span
        what = {"sine": "amplitude", "step": "step", "schedule": "range"}[a.reference.kind]
        if a.reference.kind == "sine":
            lines.append(f"{tag}RMS error {math.degrees(get('rms_error')):.2f} deg = "
                         f"{100 * get('rms_error_fraction'):.1f} % of the {math.degrees(span):.0f} "
                         f"deg {what} (from t = {a.rms_from:g} s)")
        else:  # an RMS over a step's thermal rise measures the rise, not the tracking
            pick = (lambda k: ds[k].values[j]) if cfg.gripper else (lambda k: ds[k].values)
            settled = settled_errors(ds["time"].values, pick("bend_angle"),
                                     pick("bend_angle_reference"))
            worst = float(np.max(settled))
            lines.append(f"{tag}settled error {math.degrees(worst):.2f} deg at most "
                         f"= {100 * worst / span:.1f} % of the "
                         f"{math.degrees(span):.0f} deg {what} (at the end of each of the "
                         f"{len(settled)} reference level(s))")
        if a.reference.kind == "step":
            rise = get("rise_time")
            rise_s = "never reaches 90 %" if math.isnan(rise) else f"{rise:.2f} s"
            lines.append(f"{tag}rise time (10-90 %) {rise_s}, overshoot "
                         f"{100 * get('overshoot'):.2f} %")
        lines.append(f"{tag}power mean {get('mean_power'):.2f} W, peak "
                     f"{get('peak_power'):.2f} W, energy {get('energy'):.1f} J; "
                     f"max temperature {get('temperature_max') - 273.15:.0f} degC")
        ref_max = float(np.max(reference_signal(a.reference, ds["time"].values)))
        if ref_max > get("reach") + 1e-9:
            lines.append(f"{tag}warning: the reference reaches {math.degrees(ref_max):.0f} deg, "
                         f"beyond the {math.degrees(get('reach')):.0f} deg the design settles at "
                         f"with full heating")
        if get("time_above_t_max") > 0:
            lines.append(f"{tag}warning: the muscle spent {get('time_above_t_max'):.1f} s "
                         f"above its highest safe temperature "
                         f"{a.nylon.t_max - 273.15:.0f} degC")
        if get("nylon_use_max") > 1.0:
            lines.append(f"{tag}warning: the muscle load reached "
                         f"{100 * get('nylon_use_max'):.0f} % of its breaking force")
    if cfg.gripper:
        lines.append(f"  supply current peak {1e3 * ds.attrs['supply_current_max']:.0f} mA")
    return lines
