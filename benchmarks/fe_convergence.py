"""docs/fidelity.md's convergence tables: the FE twin on every mesh level, both worked
examples, and the default mesh against the fine one.

    python benchmarks/fe_convergence.py [--examples 1 2] [--levels rough coarse default fine]
                                        [--stroke]

Without ``--stroke``: the bend at imposed pressures of 2, 5 and 10 kPa ("Convergence").
With it: the sealed, stroke-driven twin at each example's full stroke s* (0.054, 0.097),
free, its pressure and bend ("Driven as built"). About 25 CPU-minutes for both examples on
every level (example 2's fine mesh alone about 10), 7 with ``--stroke``: too long for CI,
which keeps the three-level study of example 1
(``tests/test_fe.py::test_mesh_convergence_on_the_first_example``, slow suite). Exits 1 if
the default mesh misses the fine one by 3 % or more anywhere (the issue's target).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

EXAMPLES = {"1": (20e-3, 6e-3, 90e-3), "2": (7.5e-3, 2e-3, 70e-3)}
#: Each example's full stroke s* (the paper model's usable stroke, C 1.1 and 1.7, 8 deg).
FULL_STROKE = {"1": 0.054, "2": 0.097}
PRESSURES = [2e3, 5e3, 10e3]


def main(argv=None) -> int:
    from nylonflex.fe.mesh import REFINEMENT, body_mesh
    from nylonflex.fe.solve import solve_bend
    from nylonflex.materials import silicone_parameters

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--examples", nargs="+", default=list(EXAMPLES), choices=list(EXAMPLES))
    p.add_argument("--levels", nargs="+", default=["rough", "coarse", "default", "fine"])
    p.add_argument("--stroke", action="store_true",
                   help="the sealed twin at full stroke instead of imposed pressures")
    args = p.parse_args(argv)
    mu, alpha = silicone_parameters("tc5005").arrays()
    if args.stroke:
        return _stroke(args, mu, alpha)
    worst = 0.0
    for ex in args.examples:
        a, t, L = EXAMPLES[ex]
        theta, cpu = {}, {}
        for level in args.levels:
            c0 = time.process_time()
            theta[level] = solve_bend(body_mesh(a, t, L, base_thickness=t, mesh=level),
                                      mu, alpha, PRESSURES)
            cpu[level] = time.process_time() - c0
        print(f"example {ex}: a/t/L = {a*1e3:g}/{t*1e3:g}/{L*1e3:g} mm")
        for i, pressure in enumerate(PRESSURES):
            row = "  ".join(f"{lv} {math.degrees(theta[lv][i]):8.3f} deg" for lv in args.levels)
            line = f"  {pressure/1e3:4.0f} kPa: {row}"
            if "default" in theta and "fine" in theta:
                gap = theta["default"][i] / theta["fine"][i] - 1
                worst = max(worst, abs(gap))
                line += f"  default/fine - 1 = {100*gap:+.2f} %"
            print(line)
        print("  CPU s: " + ", ".join(f"{lv} {cpu[lv]:.0f}" for lv in args.levels)
              + f"  (refinement {REFINEMENT})")
    return 1 if worst >= 0.03 else 0


def _stroke(args, mu, alpha) -> int:
    """The sealed twin at each example's s* on each level: pressure and bend, the default
    mesh against the fine one, and the coarser level's pressure estimate beside it."""
    from nylonflex.fe import pressure_error
    from nylonflex.fe.mesh import body_mesh
    from nylonflex.fe.sealed import solve_stroke
    from nylonflex.physics.chamber import P_ATM

    worst = 0.0
    for ex in args.examples:
        a, t, L = EXAMPLES[ex]
        out = {}
        for level in args.levels:
            c0 = time.process_time()
            out[level] = solve_stroke(body_mesh(a, t, L, base_thickness=t, mesh=level), mu,
                                      alpha, [FULL_STROKE[ex]], p_atm=P_ATM)
            cpu = time.process_time() - c0
            print(f"example {ex} s* {FULL_STROKE[ex]}: {level:8s} p {out[level]['pressure'][0]:9.2f}"
                  f" Pa  bend {math.degrees(out[level]['bend_angle'][0]):7.3f} deg  "
                  f"({cpu:.0f} CPU-s)")
        levels = list(out)
        for fine, coarse in zip(levels[1:], levels):
            est = float(pressure_error(out[fine]["pressure"], out[coarse]["pressure"])[0])
            print(f"  {fine} against {coarse}: pressure estimate {100 * est:.1f} %")
        if "default" in out and "fine" in out:
            for name in ("pressure", "bend_angle"):
                gap = out["default"][name][0] / out["fine"][name][0] - 1
                worst = max(worst, abs(gap))
                print(f"  default/fine - 1: {name} {100 * gap:+.2f} %")
    return 1 if worst >= 0.03 else 0


if __name__ == "__main__":
    sys.exit(main())
