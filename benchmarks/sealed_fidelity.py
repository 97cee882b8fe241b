"""The numbers of docs/fidelity.md's "sealed_chamber against the sealed twin": each model's
full-stroke bend and blocked tip force over the sealed FE twin's, on the twin's records.

    python benchmarks/sealed_fidelity.py RECORDS_DIR [SEALED_JSON]

``paper`` and ``fe_calibrated`` at the record's stroke s* (their own, which the record's
stroke is: ``nf.evaluate``'s usable stroke of the paper's model); ``sealed_chamber`` left
one design out of its own fit (``SEALED_JSON``'s ``fit.loo``, written by ``nylonflex fit
sealed``; without it, fitted here).
"""

from __future__ import annotations

import json
import sys

import numpy as np

import nylonflex as nf
from nylonflex.calibration.chamber import TOLERANCE, fe_records, fit_sealed_chamber


def ratios(records, loo) -> dict:
    """model -> {"bend_angle": ratios, "tip_force": ratios} (model over FE)."""
    fe_bend = np.array([r["bend_angle"] for r in records])
    fe_tip = np.array([r["tip_force"] for r in records])
    d = {k: np.array([r["design"][k] for r in records])
         for k in ("radius", "wall_thickness", "length", "coil_index", "wrap_angle",
                   "base_thickness")}
    out = {"paper": {"bend_angle": np.array([r["paper"]["bend_angle"] for r in records])
                     / fe_bend,
                     "tip_force": np.array([r["paper"]["tip_force"] for r in records]) / fe_tip}}
    cal = nf.evaluate(d["radius"], d["wall_thickness"], d["length"], d["coil_index"],
                      d["wrap_angle"], base_thickness=d["base_thickness"],
                      model="fe_calibrated")
    out["fe_calibrated"] = {"bend_angle": cal["bend_angle_max"] / fe_bend,
                            "tip_force": cal["tip_force_max"] / fe_tip}
    out["sealed_chamber (leave-one-out)"] = {"bend_angle": np.asarray(loo["bend_angle"]),
                                             "tip_force": np.asarray(loo["tip_force"])}
    out["sealed_chamber pressure"] = {"pressure": np.asarray(loo["pressure"])}
    return out


def table(records, loo) -> str:
    lines = ["| model | quantity | median | range | within 15 % |", "|---|---|---|---|---|"]
    for model, q in ratios(records, loo).items():
        for name, r in q.items():
            r = np.asarray(r, dtype=float)
            r = r[np.isfinite(r)]
            if r.size == 0:
                continue
            ok = int(np.sum(np.abs(r - 1.0) <= TOLERANCE))
            lines.append(f"| {model} | {name} | {np.median(r):.3f} | {r.min():.3f}-"
                         f"{r.max():.3f} | {ok} of {r.size} |")
    return "\n".join(lines)


def main(argv) -> int:
    records, skipped = fe_records(argv[0])
    if len(argv) > 1:
        loo = json.loads(open(argv[1]).read())["fit"]["loo"]
    else:
        loo = fit_sealed_chamber(records, records[0]["silicone"])["loo"]
    print(f"{len(records)} records ({len(skipped)} left out: {', '.join(skipped) or 'none'})")
    print(table(records, loo))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
