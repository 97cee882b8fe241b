"""docs/fidelity.md's Convergence table: the FE twin's bend on every mesh level, both
worked examples, at 2, 5 and 10 kPa (imposed pressure), and the default mesh against the
fine one.

    python benchmarks/fe_convergence.py [--examples 1 2] [--levels rough coarse default fine]

About 25 CPU-minutes for both examples on every level (example 2's fine mesh alone about
10): too long for CI, which keeps the three-level study of example 1
(``tests/test_fe.py::test_mesh_convergence_on_the_first_example``, slow suite). Exits 1 if
the default mesh misses the fine one by 3 % or more anywhere (the issue's target).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

EXAMPLES = {"1": (20e-3, 6e-3, 90e-3), "2": (7.5e-3, 2e-3, 70e-3)}
PRESSURES = [2e3, 5e3, 10e3]


def main(argv=None) -> int:
    from nylonflex.fe.mesh import REFINEMENT, body_mesh
    from nylonflex.fe.solve import solve_bend
    from nylonflex.materials import silicone_parameters

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--examples", nargs="+", default=list(EXAMPLES), choices=list(EXAMPLES))
    p.add_argument("--levels", nargs="+", default=["rough", "coarse", "default", "fine"])
    args = p.parse_args(argv)
    mu, alpha = silicone_parameters("tc5005").arrays()
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


if __name__ == "__main__":
    sys.exit(main())
