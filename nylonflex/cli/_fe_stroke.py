"""``nylonflex fe --stroke`` and ``--blocked``: the FE twin driven as built, and held straight."""

from __future__ import annotations

import math
import sys

from ..units import json_text
from ._common import progress_bar


def _cell(value, fmt, width):
    return f"{value:{width}{fmt}}" if math.isfinite(value) else f"{'-':>{width}}"


def run_stroke(args, design, silicone, strokes, air_heating) -> int:
    """Solve the sealed twin at ``strokes`` [-] and print its table (or JSON)."""
    import numpy as np

    from ..fe import fe_stroke, require_felupe
    from ..physics.chamber import chamber_pressure

    require_felupe()
    kw = {"base_thickness": design.get("base_thickness"), "silicone": silicone or "tc5005"}
    with progress_bar("fe", unit="solve", quiet=args.quiet) as bar:
        res = fe_stroke(design["radius"], design["wall_thickness"], design["length"],
                        strokes, blocked=args.blocked, air_heating=air_heating,
                        mesh=args.mesh, progress=bar, **kw)
    eq8 = np.asarray(chamber_pressure(res["stroke"]), dtype=float).reshape(-1)
    names = ["stroke", "pressure", "volume_ratio", "bend_angle"]
    names += ["tip_moment", "tip_force"] if args.blocked else []
    if args.format == "json":
        out = {"design": design, "silicone": kw["silicone"], "mesh": args.mesh,
               "blocked": bool(args.blocked), "air_heating": res["air_heating"],
               **{n: res[n].tolist() for n in names},
               "discretisation_error": res["discretisation_error"].tolist(),
               "pressure_error": res["pressure_error"].tolist(),
               "eq8_pressure": eq8.tolist(),
               "units": {"design": "m", "air_heating": "K", "stroke": "1", "pressure": "Pa",
                         "volume_ratio": "1", "bend_angle": "rad", "tip_moment": "N m",
                         "tip_force": "N", "discretisation_error": "1",
                         "pressure_error": "1", "eq8_pressure": "Pa"}}
        sys.stdout.write(json_text(out))
        return 0
    heat = f", air +{res['air_heating']:g} K" if res["air_heating"] else ""
    held = ", tip held straight" if args.blocked else ""
    print(f"FE twin driven as built (sealed chamber{heat}{held}), mesh {args.mesh}")
    head = f"{'stroke':>7} {'p':>8} {'p err':>6} {'p eq.8':>8} {'V/V0':>7}"
    unit = f"{'[-]':>7} {'[kPa]':>8} {'[%]':>6} {'[kPa]':>8} {'[-]':>7}"
    if args.blocked:  # the bend of a body held at both ends is no result: not shown
        head += f" {'moment':>9} {'force':>7}"
        unit += f" {'[N mm]':>9} {'[N]':>7}"
    else:
        head += f" {'bend':>7}"
        unit += f" {'[deg]':>7}"
    print(head + f" {'error':>6}")
    print(unit + f" {'[%]':>6}")
    for i, s in enumerate(res["stroke"]):
        row = (f"{s:7.4f} {_cell(res['pressure'][i] / 1e3, '.3f', 8)} "
               f"{_cell(100 * res['pressure_error'][i], '.1f', 6)} {eq8[i] / 1e3:8.3f} "
               f"{_cell(res['volume_ratio'][i], '.4f', 7)}")
        if not args.blocked:
            row += f" {_cell(np.degrees(res['bend_angle'][i]), '.2f', 7)}"
        else:
            row += (f" {_cell(res['tip_moment'][i] * 1e3, '.2f', 9)}"
                    f" {_cell(res['tip_force'][i], '.4f', 7)}")
        print(row + f" {_cell(100 * res['discretisation_error'][i], '.2f', 6)}")
    main = "moment" if args.blocked else "bend"
    print(f"error: the {main}'s Richardson estimate against the next coarser mesh; p err the "
          "pressure's (first order, safety factor 3)")
    if not np.all(np.isfinite(res["pressure"])):
        print("-: not reached: the FE solve stalled (docs/fidelity.md)")
    sys.stdout.flush()
    return 0


def run_blocked(args, design, kw, pressures) -> int:
    """The tip held straight at imposed ``pressures`` [Pa]: its moment and force beside
    the paper's eq. (16)."""
    import numpy as np

    from ..fe import fe_bend

    a = design["radius"]
    b = design.get("base_thickness") or design["wall_thickness"]
    with progress_bar("fe", unit="solve", quiet=args.quiet) as bar:
        res = fe_bend(design["radius"], design["wall_thickness"], design["length"],
                      pressures, mesh=args.mesh, blocked=True, progress=bar, **kw)
    eq16 = (4 * a ** 3 + 3 * math.pi * a * a * b) / 6 * res["pressure"]
    if args.format == "json":
        out = {"design": design, "silicone": kw["silicone"], "mesh": args.mesh,
               "blocked": True, "pressure": res["pressure"].tolist(),
               "tip_moment": res["tip_moment"].tolist(), "tip_force": res["tip_force"].tolist(),
               "discretisation_error": res["discretisation_error"].tolist(),
               "eq16_moment": eq16.tolist(),
               "units": {"design": "m", "pressure": "Pa", "tip_moment": "N m",
                         "tip_force": "N", "discretisation_error": "1", "eq16_moment": "N m"}}
        sys.stdout.write(json_text(out))
        return 0
    print(f"FE twin, tip held straight, mesh {args.mesh}: moment on the holder about the "
          "skin, F = M/L (eq. 16)")
    print(f"{'pressure':>9} {'moment':>9} {'force':>8} {'eq.16 M':>9} {'FE/eq.16':>8} {'error':>6}")
    print(f"{'[kPa]':>9} {'[N mm]':>9} {'[N]':>8} {'[N mm]':>9} {'[-]':>8} {'[%]':>6}")
    for i, p in enumerate(res["pressure"]):
        m = res["tip_moment"][i]
        ratio = m / eq16[i] if eq16[i] > 0 else float("nan")
        print(f"{p / 1e3:9.3f} {_cell(m * 1e3, '.3f', 9)} {_cell(res['tip_force'][i], '.4f', 8)}"
              f" {eq16[i] * 1e3:9.3f} {_cell(ratio, '.3f', 8)}"
              f" {_cell(100 * res['discretisation_error'][i], '.2f', 6)}")
    if not np.all(np.isfinite(res["tip_moment"])):
        print("-: not reached: the FE solve stalled (docs/fidelity.md)")
    sys.stdout.flush()
    return 0
