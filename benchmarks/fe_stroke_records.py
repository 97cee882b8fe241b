"""The sealed, stroke-driven FE twin (``nf.fe_stroke``) over many designs at full stroke.

    python benchmarks/fe_stroke_records.py OUT_DIR [--designs 48] [--mesh default] [--seed 0]
                                                   [--reverse]

Designs: a Latin hypercube over radius 5-25 mm, wall 1-6 mm (base = wall), length 50-150
mm, coil index 1.1-1.7 and wrap angle 5-20 deg (rounded to 0.5 mm, 0.05 and 1 deg). Each
design's full stroke s* is ``nf.evaluate``'s ``usable_stroke`` (silicone tc5005, nylon
silver_nylon66, the paper's model); the twin is solved there free and blocked. One JSON
record per design, ``OUT_DIR/design_NNN.json`` (written whole, then renamed: a record
that exists is complete, and a rerun skips it); its fields are in OUT_DIR/README.txt
(written by this script). Outputs are SI.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

README = """\
One JSON record per design, design_NNN.json, written by nylonflex's
benchmarks/fe_stroke_records.py (nf.fe_stroke: the FE twin driven as built, the wrap's rest
length 1 - s, the chamber sealed, Boyle isothermal; docs/fidelity.md "Driven as built").
All values SI. A record exists only once complete.

{"index": int,
 "design": {"radius": m, "wall_thickness": m, "base_thickness": m, "length": m,
            "coil_index": -, "wrap_angle": rad},
 "silicone": "tc5005", "nylon": "silver_nylon66", "mesh": "default",
 "stroke": s* [-] (nf.evaluate's usable_stroke, the paper's model),
 "paper": {"pressure": eq. 8 at s* [Pa], "bend_angle": [rad], "tip_force": eq. 16 [N]}
          (nf.evaluate's pressure_max, bend_angle_max, tip_force_max),
 "free":    {"pressure": [Pa], "volume_ratio": V/V0 [-], "bend_angle": [rad],
             "discretisation_error": [1], "coarser": {same names, the coarser mesh}},
 "blocked": {"pressure": [Pa], "volume_ratio": [-], "tip_moment": [N m], "tip_force": [N],
             "discretisation_error": [1], "coarser": {...}},
 "reached": {"free": bool, "blocked": bool}   (false: the solve stalled; values null),
 "wall_s": {"free": s, "blocked": s}}
discretisation_error: the larger Richardson estimate (pressure and bend angle, or pressure
and tip moment) against the next coarser mesh, as nf.fe_stroke returns it.
"""


def designs(n, seed):
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=5, seed=seed).random(n)
    lo = np.array([5.0, 1.0, 50.0, 1.1, 5.0])
    hi = np.array([25.0, 6.0, 150.0, 1.7, 20.0])
    x = lo + u * (hi - lo)
    x[:, :3] = np.round(x[:, :3] * 2) / 2
    x[:, 3] = np.round(x[:, 3] * 20) / 20
    x[:, 4] = np.round(x[:, 4])
    return x


def _pick(res, names):
    return {k: (None if not np.isfinite(res[k][0]) else float(res[k][0])) for k in names}


def record(index, row, mesh):
    import nylonflex as nf

    a, t, L = row[0] * 1e-3, row[1] * 1e-3, row[2] * 1e-3
    coil, psi = float(row[3]), float(np.radians(row[4]))
    ev = nf.evaluate(a, t, L, coil, psi)
    s = float(ev["usable_stroke"])
    out = {"index": index,
           "design": {"radius": a, "wall_thickness": t, "base_thickness": t, "length": L,
                      "coil_index": coil, "wrap_angle": psi},
           "silicone": "tc5005", "nylon": "silver_nylon66", "mesh": mesh, "stroke": s,
           "paper": {"pressure": float(ev["pressure_max"]),
                     "bend_angle": float(ev["bend_angle_max"]),
                     "tip_force": float(ev["tip_force_max"])},
           "reached": {}, "wall_s": {}}
    for kind, names in (("free", ["pressure", "volume_ratio", "bend_angle"]),
                        ("blocked", ["pressure", "volume_ratio", "tip_moment", "tip_force"])):
        t0 = time.perf_counter()
        res = nf.fe_stroke(a, t, L, [s], mesh=mesh, blocked=kind == "blocked")
        out["wall_s"][kind] = round(time.perf_counter() - t0, 1)
        part = _pick(res, names + ["discretisation_error"])
        part["coarser"] = _pick(res, [f"coarser_{n}" for n in names if n != "tip_force"])
        out[kind] = part
        out["reached"][kind] = part[names[0]] is not None and part[names[-1]] is not None
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("--designs", type=int, default=48)
    p.add_argument("--mesh", default="default")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--reverse", action="store_true",
                   help="last design first (a second process on the same folder)")
    args = p.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    readme = os.path.join(args.out, "README.txt")
    if not os.path.exists(readme):
        with open(readme, "w") as f:
            f.write(README)
    rows = list(enumerate(designs(args.designs, args.seed)))
    for i, row in rows[::-1] if args.reverse else rows:
        path = os.path.join(args.out, f"design_{i:03d}.json")
        if os.path.exists(path):
            continue
        try:
            rec = record(i, row, args.mesh)
        except ValueError as exc:  # a design outside the twin's range: say so, go on
            rec = {"index": i, "design_mm_c_deg": row.tolist(), "error": str(exc)}
        tmp = path + ".part"
        with open(tmp, "w") as f:
            json.dump(rec, f, indent=1)
        os.replace(tmp, path)
        print(f"{path}: {json.dumps(rec.get('reached', rec.get('error')))}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
