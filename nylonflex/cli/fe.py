"""``nylonflex fe``: the FE twin's bend angle of one design, beside every variant's."""

from __future__ import annotations

import re
import sys

from ..units import InputError, json_text, parse_quantity
from ._common import progress_bar
from ._fe_stroke import run_blocked, run_stroke

HELP = "bend angle of one design by the finite-element twin (needs the [fe] extra)"
DESCRIPTION = """\
Solve one design with the finite-element twin (FElupe; docs/fidelity.md) at a list of
chamber pressures and print its bend angle beside every model variant's analytic angle;
or drive it as built, the muscle's stroke shortening the wrap of a sealed chamber.

  nylonflex fe --at radius=20mm,wall_thickness=6mm,length=90mm --pressure 0:12:4kPa
  nylonflex fe --at radius=20mm,wall_thickness=6mm,length=90mm --stroke 0:0.054:4
  nylonflex fe --at radius=20mm,wall_thickness=6mm,length=90mm --stroke 0.054 --blocked

--pressure takes START:STOP:STEP (STOP included) or a comma list, with a unit
(kPa when bare). --stroke takes START:STOP:NUM (NUM strokes from START to STOP, both
included) or a comma list, fractions of the muscle's length (or with %), each in
[0, 0.5). --blocked holds the tip straight and prints the moment it takes and the
force of eq. (16), F = M/L. --air-heating (with --stroke) warms the sealed air by a
temperature rise in K. --at takes radius, wall_thickness, length and optionally
base_thickness (mm when bare) and silicone=NAME."""

#: --at's names and the unit a bare number means.
AT_NAMES = ("radius", "wall_thickness", "length", "base_thickness")


def add_arguments(p):
    p.add_argument("--at", required=True, metavar="NAME=VALUE,...",
                   help="the design: radius, wall_thickness, length [, base_thickness] "
                        "(mm when bare) [, silicone=NAME]")
    p.add_argument("--pressure", metavar="START:STOP:STEP|P,P,...",
                   help="chamber pressures (kPa when bare), e.g. 0:12:4kPa or 2,5,10")
    p.add_argument("--stroke", metavar="START:STOP:NUM|S,S,...",
                   help="muscle strokes [-] driving the sealed twin, e.g. 0:0.054:4 "
                        "(4 strokes) or 0.03,0.054 or 5%%")
    p.add_argument("--blocked", action="store_true",
                   help="hold the tip straight: print the moment and the force F = M/L")
    p.add_argument("--air-heating", metavar="DT",
                   help="with --stroke: the sealed air's temperature rise, in K (e.g. 20K)")
    p.add_argument("--mesh", default="default", metavar="coarse|default|fine",
                   help="mesh level (default: default)")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def parse_design(text):
    """``radius=20mm,...`` -> (design dict in SI, silicone name or None)."""
    design, silicone = {}, None
    for part in [s for s in str(text).split(",") if s.strip()]:
        if "=" not in part:
            raise InputError(f"--at: expected NAME=VALUE, got {part.strip()!r}; names: "
                             f"{', '.join(AT_NAMES)}, silicone")
        name, value = (s.strip() for s in part.split("=", 1))
        if name == "silicone":
            silicone = value
            continue
        if name not in AT_NAMES:
            raise InputError(f"--at: unknown name {name!r}; accepted: "
                             f"{', '.join(AT_NAMES)}, silicone")
        if name in design:
            raise InputError(f"--at: {name} given twice")
        design[name] = float(parse_quantity(value, f"--at {name}", "length", "mm"))
    missing = [n for n in AT_NAMES[:3] if n not in design]
    if missing:
        raise InputError(f"--at: missing {', '.join(missing)} (radius, wall_thickness and "
                         "length are needed)")
    return design, silicone


def parse_pressures(text):
    """``0:12:4kPa`` or ``2,5,10`` (kPa when bare) -> pressures [Pa]."""
    import numpy as np

    text = str(text).strip()
    m = re.fullmatch(r"\s*([^:]+):([^:]+):([^:]+?)\s*([A-Za-z]+)?\s*", text)
    if m:
        unit = m.group(4) or "kPa"
        start, stop, step = (parse_quantity(f"{v.strip()}{unit}", "--pressure", "pressure",
                                            "kPa") for v in m.groups()[:3])
        if not step > 0:
            raise InputError(f"--pressure: STEP must be > 0, got {text!r}")
        if stop < start:
            raise InputError(f"--pressure: STOP must be >= START, got {text!r}")
        count = (stop - start) / step * (1 + 1e-12)  # inf for a step of 1e-308
        if not count < 100:
            raise InputError(f"--pressure: at most 100 pressures, {text!r} gives more")
        return _bounded(start + step * np.arange(int(np.floor(count)) + 1))
    parts = [s for s in text.split(",") if s.strip()]
    if not parts:
        raise InputError("--pressure: need at least one pressure, e.g. 0:12:4kPa or 2,5,10")
    unit = re.search(r"[A-Za-z]+\s*$", parts[-1])
    unit = unit.group(0).strip() if unit else "kPa"
    out = []
    for v in parts:
        v = v.strip()
        out.append(parse_quantity(v if re.search(r"[A-Za-z]", v) else f"{v}{unit}",
                                  "--pressure", "pressure", "kPa"))
    return _bounded(np.array(out, dtype=float))


def _bounded(pressures):
    """Refuse FE pressures [Pa] above 0 and below 0.1 Pa (a millionth of a cube's pressure
    range): ``1e-308`` solves nothing. fe_bend checks the range itself."""
    bad = [p for p in pressures if 0.0 < p < 0.1]
    if bad:
        raise InputError(f"--pressure: a pressure is 0 or at least 0.0001 kPa (0.1 Pa), got "
                         f"{bad[0] / 1e3:.3g} kPa")
    return pressures


def parse_strokes(text):
    """``0:0.054:4`` (START:STOP:NUM) or ``0.03,0.054`` or ``5%`` -> strokes [-]."""
    import numpy as np

    from ..fe.stroke import MAX_STROKE, MAX_STROKES

    text = str(text).strip()
    parts = text.split(":")
    if len(parts) == 3:
        start, stop = (parse_quantity(v.strip(), "--stroke", "dimensionless", "1")
                       for v in parts[:2])
        num = parts[2].strip()
        if not re.fullmatch(r"\d+", num) or int(num) < 2:
            raise InputError(f"--stroke: START:STOP:NUM takes a whole NUM >= 2 (the number "
                             f"of strokes), got {text!r}")
        if int(num) > MAX_STROKES:
            raise InputError(f"--stroke: at most {MAX_STROKES} strokes, got {num}")
        if stop < start:
            raise InputError(f"--stroke: STOP must be >= START, got {text!r}")
        out = np.linspace(start, stop, int(num))
    elif len(parts) == 1:
        items = [v for v in text.split(",") if v.strip()]
        if not items:
            raise InputError("--stroke: need at least one stroke, e.g. 0:0.054:4 or 0.054")
        if len(items) > MAX_STROKES:
            raise InputError(f"--stroke: at most {MAX_STROKES} strokes, got {len(items)}")
        out = np.array([parse_quantity(v.strip(), "--stroke", "dimensionless", "1")
                        for v in items])
    else:
        raise InputError(f"--stroke: expected START:STOP:NUM or S,S,..., got {text!r}")
    bad = out[~((out >= 0) & (out < MAX_STROKE))]
    if bad.size:
        raise InputError(f"--stroke: each must be in [0, {MAX_STROKE:g}) [-], got {bad[0]:g}")
    return out


def parse_air_heating(text):
    """``20K`` -> 20.0 [K]: a temperature rise, so only in K (a bare number or degC, which
    units.py reads as a temperature with its offset, is refused)."""
    from ..fe.stroke import MAX_AIR_HEATING

    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*K\s*", str(text))
    if not m:
        raise InputError(f"--air-heating: a temperature rise needs the unit K (e.g. 20K), "
                         f"got {str(text)!r}")
    value = float(m.group(1))
    if not 0.0 <= value <= MAX_AIR_HEATING:
        raise InputError(f"--air-heating: must be in [0, {MAX_AIR_HEATING:g}] K, got {value:g} K")
    return value


def run(args) -> int:
    design, silicone = parse_design(args.at)
    if args.stroke is not None and args.pressure is not None:
        raise InputError("--stroke: give --stroke or --pressure, not both")
    if args.air_heating is not None and args.stroke is None:
        raise InputError("--air-heating: only with --stroke (the sealed chamber's air)")
    if args.stroke is None and args.pressure is None:
        if args.blocked:
            raise InputError("--blocked: needs --pressure or --stroke")
        raise InputError("--pressure: needed (or --stroke), e.g. --pressure 0:12:4kPa")
    if args.stroke is not None:
        return run_stroke(args, design, silicone, parse_strokes(args.stroke),
                          None if args.air_heating is None
                          else parse_air_heating(args.air_heating))
    return _run_pressure(args, design, silicone)


def _run_pressure(args, design, silicone) -> int:
    import numpy as np

    from ..engine import bend_angle
    from ..fe import fe_bend, require_felupe
    from ..fe.verify import ANGLE_MODELS
    from ..variables import MODELS

    pressures = parse_pressures(args.pressure)
    require_felupe()
    kw = {"base_thickness": design.get("base_thickness"), "silicone": silicone or "tc5005"}
    if args.blocked:
        return run_blocked(args, design, kw, pressures)
    with progress_bar("fe", unit="solve", quiet=args.quiet) as bar:
        res = fe_bend(design["radius"], design["wall_thickness"], design["length"],
                      pressures, mesh=args.mesh, progress=bar, **kw)
    analytic = {m: np.asarray(bend_angle(res["pressure"], design["radius"],
                                         design["wall_thickness"], design["length"],
                                         model=m, **kw), dtype=float).reshape(-1)
                for m in MODELS if m in ANGLE_MODELS}
    if args.format == "json":
        out = {"design": design, "silicone": kw["silicone"], "mesh": args.mesh,
               "pressure": res["pressure"].tolist(), "bend_angle": res["bend_angle"].tolist(),
               "discretisation_error": res["discretisation_error"].tolist(),
               "models": {m: v.tolist() for m, v in analytic.items()},
               "units": {"design": "m", "pressure": "Pa", "bend_angle": "rad",
                         "discretisation_error": "1", "models": "rad"}}
        sys.stdout.write(json_text(out))
        return 0
    names = list(analytic)
    head = f"{'pressure':>9} {'FE':>8} {'error':>6} " + " ".join(f"{n:>16}" for n in names)
    print(f"FE twin, mesh {args.mesh}: bend angle [deg] (ratio FE / model in brackets)")
    print(head)
    print(f"{'[kPa]':>9} {'[deg]':>8} {'[%]':>6}")
    for i, p in enumerate(res["pressure"]):
        fe = np.degrees(res["bend_angle"][i])
        cells = []
        for n in names:
            v = np.degrees(analytic[n][i])
            ratio = f"({fe / v:.2f})" if v > 0 and np.isfinite(fe) else "(-)"
            cells.append(f"{v:9.2f} {ratio:>6}")
        err = 100 * res["discretisation_error"][i]
        fe_text = f"{fe:8.2f}" if np.isfinite(fe) else f"{'-':>8}"
        err_text = f"{err:6.2f}" if np.isfinite(err) else f"{'-':>6}"
        print(f"{p / 1e3:9.3f} {fe_text} {err_text} " + " ".join(f"{c:>16}" for c in cells))
    if not np.all(np.isfinite(res["bend_angle"])):
        print("-: not reached: the FE solve stalled (at large bends; docs/fidelity.md, status)")
    from ..variants import VARIANTS

    print("models: " + "; ".join(f"{n}: {VARIANTS[n].short}" if n in VARIANTS else n
                                 for n in names) + " (nylonflex list models)")
    sys.stdout.flush()
    return 0
