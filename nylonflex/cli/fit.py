"""``nylonflex fit silicone|stroke|thermal|muscle DATA``: fit a set, write its material file;
``nylonflex fit fe``: fit ``fe_calibrated``'s correction to FE runs of the twin;
``nylonflex fit chamber DATA``: the sealed chamber of one built actuator (docs/bench.md)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from .. import __version__
from ..units import InputError, json_text, parse_quantity
from . import warn
from ._common import progress_bar

HELP = ("fit a silicone or nylon muscle set or a sealed chamber to bench data, or "
        "fe_calibrated to the FE twin")
DESCRIPTION = """Fit a material set to measurements and write the material file a config uses
as `silicone: {file: ...}` or `nylon: {file: ...}`. Formats: docs/calibration.md.

  nylonflex fit silicone tests/data/ecoflex_0050.csv      # stretch <= 2, the designs' window
  nylonflex fit silicone tests/data/ecoflex_0050.csv --model ogden2 --max-stretch 4 \\
      --out fits/ecoflex50.yaml --chart fits/
  nylonflex fit stroke heating.csv --coil-index 1.5 --out fits/nylon.yaml
  nylonflex fit thermal step.csv --voltage 5V --muscle-length 300mm
  nylonflex fit muscle force.csv
  nylonflex fit chamber bench.csv --radius 20mm --wall-thickness 6mm --length 90mm \\
      --out fits/chamber.yaml                                 # docs/bench.md
  nylonflex fit fe --designs 48 --workers 2 --out fe_calibration.json   # needs [fe]
  nylonflex fit sealed fe_runs/ --out sealed_chamber.json    # sealed_chamber from FE records"""

KINDS = ("silicone", "stroke", "thermal", "muscle", "fe", "chamber", "sealed")


def add_arguments(p):
    p.add_argument("kind", choices=KINDS, help="what to fit")
    p.add_argument("data", nargs="?", help="data file (CSV with units in the header, or a "
                   "Soft Robotics Materials Database file); none for 'fe'; for 'sealed' the "
                   "folder of the sealed FE twin's records")
    p.add_argument("--model", default="ogden2",
                   help="silicone: ogden1|ogden2|ogden3|neo_hookean|yeoh2 (default ogden2)")
    p.add_argument("--test", default="uniaxial", choices=["uniaxial", "planar"],
                   help="silicone: the test (default uniaxial)")
    p.add_argument("--max-stretch", default="design", metavar="X|design|all",
                   help="silicone: fit stretch <= X only; 'design' (default): the stretch "
                   "the designs' walls reach (2); 'all': the whole curve")
    p.add_argument("--coil-index", type=float, help="stroke: coil index C of the muscle")
    p.add_argument("--voltage", help="thermal: step voltage, e.g. 5V")
    p.add_argument("--muscle-length", help="thermal: muscle length, e.g. 300mm (for lambda', c')")
    p.add_argument("--resistance", help="thermal: muscle resistance, e.g. 45ohm (default r' l_m)")
    p.add_argument("--nylon", default="silver_nylon66",
                   help="stroke/thermal/muscle: base nylon set (T_amb, T_max, coil table)")
    p.add_argument("--t-amb", help="ambient temperature, e.g. 25degC (default: the set's)")
    p.add_argument("--t-max", help="highest temperature, e.g. 150degC (default: the set's)")
    p.add_argument("--radius", help="chamber: the actuator's radius, e.g. 20mm")
    p.add_argument("--wall-thickness", help="chamber: its wall thickness, e.g. 6mm")
    p.add_argument("--length", help="chamber: its length, e.g. 90mm")
    p.add_argument("--base-thickness", help="chamber: its base thickness (default the wall's)")
    p.add_argument("--chamber-volume", help="chamber: its measured volume V0, e.g. 56ml "
                   "(default pi a^2 L / 2)")
    p.add_argument("--silicone", default="tc5005",
                   help="chamber: the silicone set it is made of (default tc5005)")
    p.add_argument("--name", default="", help="name of the fitted set")
    p.add_argument("--out", metavar="FILE.yaml", help="write the material file here")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --out file")
    p.add_argument("--chart", metavar="DIR", help="draw data, fit and residuals into DIR")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument("--quiet", action="store_true",
                   help="no progress (a bar on a terminal, else a line a minute)")
    p.add_argument("--designs", type=int, default=48,
                   help="fe: training designs (default 48, 6 to 500)")
    p.add_argument("--workers", type=int, default=1, help="fe: local processes (default 1)")
    p.add_argument("--mesh", default="coarse", metavar="coarse|default|fine",
                   help="fe: the FE mesh (default coarse, Richardson-extrapolated)")
    p.add_argument("--seed", type=int, default=0, help="fe: the sample's seed (default 0)")


def _q(text, field, kind, unit):
    return None if text is None else parse_quantity(text, field, kind, unit)


def fit(args):
    """The FitResult the arguments ask for."""
    from ..calibration import fit_muscle, fit_silicone, fit_stroke, fit_thermal

    t_amb = _q(args.t_amb, "--t-amb", "temperature", "degC")
    t_max = _q(args.t_max, "--t-max", "temperature", "degC")
    if args.kind == "silicone":
        return fit_silicone(args.data, args.model, args.test, args.max_stretch, args.name)
    if args.kind == "chamber":
        return _fit_chamber(args)
    nylon = {"file": args.nylon} if args.nylon.endswith((".yaml", ".yml")) else args.nylon
    if args.kind == "stroke":
        if args.coil_index is None:
            raise InputError("--coil-index: required for 'fit stroke'")
        return fit_stroke(args.data, args.coil_index, nylon, t_amb, t_max, args.name)
    if args.kind == "thermal":
        if args.voltage is None:
            raise InputError("--voltage: required for 'fit thermal', e.g. --voltage 5V")
        return fit_thermal(args.data, _q(args.voltage, "--voltage", "voltage", "V"),
                           _q(args.muscle_length, "--muscle-length", "length", "mm"),
                           _q(args.resistance, "--resistance", "resistance", "ohm"),
                           nylon, t_amb, args.name)
    return fit_muscle(args.data, nylon, t_amb, t_max, args.name)


def _fit_chamber(args):
    from ..calibration.chamber_bench import fit_chamber

    size = {}
    for flag in ("radius", "wall_thickness", "length"):
        text = getattr(args, flag)
        if text is None:
            raise InputError(f"--{flag.replace('_', '-')}: required for 'fit chamber', "
                             "e.g. 20mm")
        size[flag] = _q(text, f"--{flag.replace('_', '-')}", "length", "mm")
        if not size[flag] > 0:
            raise InputError(f"--{flag.replace('_', '-')}: must be > 0 mm, got {text}")
    base = _q(args.base_thickness, "--base-thickness", "length", "mm")
    volume = _q(args.chamber_volume, "--chamber-volume", "volume", "ml")
    for flag, v in (("--base-thickness", base), ("--chamber-volume", volume)):
        if v is not None and not v > 0:
            raise InputError(f"{flag}: must be > 0, got {v:g} (SI)")
    return fit_chamber(args.data, **size, base_thickness=base, chamber_volume=volume,
                       silicone=args.silicone, name=args.name)


def _shown(unit, value, spread=False):
    """A value in the unit a user reads: temperatures [K] in degC (a spread, such as a
    standard error, keeps its size), the rest as fitted."""
    if unit == "K":
        return ("degC", value) if spread else ("degC", value - 273.15)
    return unit, value


def format_table(res) -> str:
    """The fit as aligned text lines (temperatures in degC; JSON stays SI)."""
    def one(v):
        return f"{v:.6g}"

    def line(name, unit, v, s, c):
        shown, v = _shown(unit, v)
        s, lo, hi = _shown(unit, s, True)[1], _shown(unit, c[0])[1], _shown(unit, c[1])[1]
        return (f"  {name + ' [' + shown + ']':<36}{one(v):>14}{one(s):>14}   "
                f"[{one(lo)}, {one(hi)}]")

    lines = [f"{res.kind} fit: {res.model}" + (f" ({res.test})" if res.test else "")
             + f", {res.n_points} points of {res.data['path']}",
             f"  data sha256 {res.data['sha256']}",
             f"  {'parameter':<36}{'value':>14}{'std error':>14}   95 % interval"]
    for key, val in res.parameters.items():
        unit = res.units.get(key, "")
        vals = val if isinstance(val, list) else [val]
        ses = res.stderr[key] if isinstance(val, list) else [res.stderr[key]]
        cis = res.ci95[key] if isinstance(val, list) else [res.ci95[key]]
        for i, (v, s, c) in enumerate(zip(vals, ses, cis)):
            name = f"{key}_{i + 1}" if isinstance(val, list) else key
            lines.append(line(name, unit, v, s, c))
    for key, d in res.derived.items():
        if key in res.parameters:  # tau: fitted, and listed among the derived values too
            continue
        lines.append(line(key, res.units.get(key, ""), d["value"], d["stderr"], d["ci95"]))
    rng = ", ".join(f"{k} {one(v[0])}-{one(v[1])}" for k, v in res.fitted_range.items())
    rmse_unit, rmse = _shown(res.units.get("rmse", ""), res.rmse, spread=True)
    lines.append(f"  RMSE {one(rmse)} {rmse_unit}, R^2 {res.r2:.6f}; "
                 f"fitted range (SI): {rng}; intervals: {res.uncertainty}")
    lines += [f"  note: {n}" for n in res.notes]
    return "\n".join(lines) + "\n"


def run_fe(args) -> int:
    """``fit fe``: the training runs (journaled beside --out), the fit, its JSON file."""
    from datetime import datetime, timezone

    import numpy as np

    from ..fe import MESH_NAMES, require_felupe
    from ..fe.calibrate import (MIN_DESIGNS, TRAINING_RANGES, fit_correction, run_training,
                                 training_plan)
    from ..physics.calibrated import CORRECTION, TERMS
    from ..fe.verify import MAX_DESIGNS
    from ..files.atomic import refuse_special, write_atomic

    if args.data is not None:
        raise InputError(f"fit fe: takes no data file (got {args.data!r}); the FE twin "
                         "makes the data")
    if not MIN_DESIGNS <= args.designs <= MAX_DESIGNS:  # before any FE run
        raise InputError(f"--designs: must be in [{MIN_DESIGNS}, {MAX_DESIGNS}] (the "
                         f"correction's {MIN_DESIGNS - 2} terms and a leave-one-out need "
                         f"{MIN_DESIGNS}), got {args.designs}")
    if not 0 <= args.seed < 2**32:
        raise InputError(f"--seed: must be an integer in [0, 2^32), got {args.seed}")
    if not 1 <= args.workers <= 64:
        raise InputError(f"--workers: must be in [1, 64], got {args.workers}")
    if args.mesh not in MESH_NAMES:
        raise InputError(f"--mesh: must be one of {', '.join(MESH_NAMES)}, got {args.mesh!r}")
    out = Path(args.out or "fe_calibration.json")
    refuse_special(out, "--out", [])
    if os.path.lexists(out) and not args.overwrite:
        raise InputError(f"--out {out}: exists; give --overwrite to replace it")
    require_felupe()
    plan = training_plan(args.designs, args.seed, args.mesh)
    parts = out.with_name(out.name + ".parts")
    with progress_bar("fit fe", unit="design", quiet=args.quiet, delay=0.0) as bar:
        done = run_training(parts, plan, workers=args.workers, progress=bar,
                            log=lambda m: print(f"nylonflex fit fe: {m}", file=sys.stderr))
    res = fit_correction(plan, done)
    doc = {"model": "fe_calibrated",
           "correction": CORRECTION,
           "terms": list(TERMS),
           "coefficients": res["coefficients"],
           "provenance": {"command": "nylonflex fit fe " + " ".join(sys.argv[3:]),
                          "nylonflex_version": __version__,
                          "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                          "mesh": args.mesh, "seed": args.seed,
                          "training_ranges_m": {k: list(v) for k, v in TRAINING_RANGES.items()},
                          "silicone": plan["silicone"],
                          "fe_model": plan["fe_model"],
                          "target_angles_deg": plan["target_angles_deg"]},
           "fit": {k: v for k, v in res.items() if k != "coefficients"},
           "training": [{**d, "fe_bend_angle": done[k]["bend_angle"],
                         "coarser_bend_angle": done[k]["coarser_bend_angle"]}
                        for k, d in enumerate(plan["designs"])]}
    write_atomic(out, json_text(doc, indent=1).encode(), what="fit fe")
    if args.format == "json":
        sys.stdout.write(json_text(doc, indent=2))
        return 0

    def line(name, r):
        r = np.asarray(r)
        within = int(np.sum(np.abs(r - 1) <= 0.1))
        return (f"  {name:<26} median {np.median(r):.3f}, range {r.min():.3f}-{r.max():.3f}, "
                f"within 10 %: {within} of {r.size}")

    c = res["coefficients"]
    print("fe_calibrated: lateral_pressure's angle times exp(" + " ".join(
        f"{v:+.4f}" + ("" if term == "1" else f" {term}") for v, term in zip(c, TERMS))
        + "), q = p a/(mu0 t)")
    print(f"  {res['designs_used']} designs, {res['points']} FE angles (mesh {args.mesh}, "
          "Richardson-extrapolated)")
    print(line("lateral_pressure / FE", res["lateral_over_fe"]))
    print(line("corrected / FE", res["calibrated_over_fe"]))
    print(line("leave-one-out / FE", res["loo_calibrated_over_fe"]))
    idx = np.asarray(res["design_index"])
    loo = np.abs(np.asarray(res["loo_calibrated_over_fe"]) - 1.0) <= 0.1
    whole = sum(bool(loo[idx == k].all()) for k in np.unique(idx))
    print(f"  designs with every leave-one-out angle within 10 %: {whole} of "
          f"{res['designs_used']}")
    print(f"wrote {out}")
    return 0


def run_sealed(args) -> int:
    """``fit sealed DIR``: ``sealed_chamber``'s coefficients from the sealed FE twin's
    records in DIR, with their leave-one-design-out errors, as the JSON file the variant
    ships (``nylonflex/physics/sealed_chamber.json``)."""
    from datetime import datetime, timezone

    import numpy as np

    from ..calibration.chamber import calibration_document, fe_records, fit_sealed_chamber
    from ..files.atomic import refuse_special, write_atomic

    if args.data is None or not Path(args.data).is_dir():
        raise InputError(f"DIR: 'fit sealed' needs the folder of FE records, got {args.data!r}")
    out = Path(args.out or "sealed_chamber.json")
    refuse_special(out, "--out", [])
    if os.path.lexists(out) and not args.overwrite:
        raise InputError(f"--out {out}: exists; give --overwrite to replace it")
    records, skipped = fe_records(args.data)
    silicones = {r["silicone"] for r in records}
    if len(silicones) > 1:
        raise InputError(f"DIR: records of several silicones ({', '.join(sorted(silicones))}); "
                         "fit one at a time")
    if len(records) < 3:
        raise InputError(f"DIR: {len(records)} complete record(s) in {args.data}; need at "
                         "least 3")
    silicone = silicones.pop()
    fit = fit_sealed_chamber(records, silicone)
    doc = calibration_document(fit, records, {
        "command": "nylonflex fit sealed " + " ".join(sys.argv[3:]),
        "nylonflex_version": __version__,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "records": str(args.data), "skipped": skipped, "silicone": silicone})
    write_atomic(out, json_text(doc, indent=1).encode(), what="fit sealed")
    if args.format == "json":
        sys.stdout.write(json_text(doc, indent=2))
        return 0
    loo = fit["loo"]
    print("sealed_chamber: " + ", ".join(f"{k} {v:+.4f}" for k, v in
                                         fit["coefficients"].items())
          + f" (stiffness: {fit['stiffness_from']})")
    print(f"  {loo['n']} designs ({len(skipped)} records left out); leave-one-out / FE:")
    for name in ("pressure", "bend_angle", "tip_force"):
        r = np.asarray(loo[name], dtype=float)
        r = r[np.isfinite(r)]
        if r.size == 0:
            print(f"  {name:<12} no FE values")
            continue
        print(f"  {name:<12} median {np.median(r):.3f}, range {r.min():.3f}-{r.max():.3f}, "
              f"within {loo['tolerance']:.0%}: {loo['within'][name]} of {r.size}")
    print(f"  bend and blocked force both within {loo['tolerance']:.0%}: "
          f"{loo['bend_and_force_within']} of {loo['n_both']}")
    print(f"wrote {out}")
    return 0


def run(args) -> int:
    if args.kind == "fe":
        return run_fe(args)
    if args.kind == "sealed":
        return run_sealed(args)
    if args.data is None:
        raise InputError(f"DATA: required for 'fit {args.kind}' (a CSV or database file)")
    from ..calibration import write_material_file
    from ..files.atomic import refuse_special

    # refused before the work: a link, a special file, the data file itself, or (without
    # --overwrite) any file
    inputs = [args.data, *([args.nylon] if args.nylon.endswith((".yaml", ".yml")) else [])]
    if args.out:
        refuse_special(Path(args.out), "--out", inputs)
        if os.path.lexists(args.out) and not args.overwrite:
            raise InputError(f"--out {args.out}: exists; give --overwrite to replace it")
    with progress_bar(f"fit {args.kind}", unit="s", quiet=args.quiet, command="fit"):
        res = fit(args)  # the time elapsed (a fit has no count to show)
    if args.out:
        write_material_file(res, args.out, name=args.name or None, overwrite=args.overwrite,
                            inputs=inputs)
    if args.chart:
        from ..charts.fit import fit_chart

        fit_chart(res, Path(args.chart) / f"fit_{args.kind}_{Path(args.data).stem}_"
                  f"{res.model}.png")
    if args.format == "json":
        sys.stdout.write(json_text(res.to_json(), indent=2))
    else:
        sys.stdout.write(format_table(res))
        if args.out:
            print(f"wrote {args.out}")
    for n in res.notes if args.format == "json" else ():
        warn("fit", n)
    return 0
