"""``nylonflex fit fe``: FE runs over the design space, and ``fe_calibrated``'s correction
fitted to them.

The correction scales ``lateral_pressure``'s bend angle (``physics.calibrated``):

    theta_cal = theta_lateral exp(c0 + c1 ln(t/a) + c2 ln(L/a) + c3 q/(1+q)),
    q = p a / (mu0 t)

The runs: designs filling the space designers sweep (:data:`TRAINING_RANGES`, a scrambled
Latin hypercube, b = t as in the fig12 cube), each solved at the pressures where
``lateral_pressure`` bends :data:`TARGET_ANGLES`, on the coarse mesh and the one below
it, their Richardson extrapolation taken as the FE angle (within 0.6 % of the fine mesh on
example 1, 1.4-3.5 % below it on the slender example 2 at 17-40 deg: docs/fidelity.md). The fit is linear least squares of the
log ratio ln(theta_FE / theta_lateral) on the four terms; its leave-one-design-out error
(each design's angles predicted by the fit to all the others) is reported with the
coefficients, the training designs and their FE angles in one JSON file with provenance,
the file ``physics/fe_calibrated.json`` ships.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import silicone_parameters
from ..physics.calibrated import TERMS
from ..physics.limits import model_bend_angle
from ..units import InputError
from . import extrapolated, fe_bend
from .runs import journaled_runs, plan_material, plan_silicone

__all__ = ["MIN_DESIGNS", "TARGET_ANGLES", "TRAINING_RANGES", "correction_terms", "fit_correction",
           "run_training", "training_plan"]

#: The design space the training designs fill [m] (the fig12 and big20m sweeps').
TRAINING_RANGES = {"radius": (5e-3, 25e-3), "wall_thickness": (1e-3, 6e-3),
                   "length": (50e-3, 150e-3)}
#: ``lateral_pressure``'s bend angles at which each training design is solved [rad].
TARGET_ANGLES = (math.radians(20.0), math.radians(50.0))
#: Number of coefficients of the correction (:func:`correction_terms`).
N_TERMS = 4
#: Fewest training designs a fit takes: the coefficients and two more, so that every
#: leave-one-design-out fit is still overdetermined.
MIN_DESIGNS = N_TERMS + 2


def correction_terms(pressure, radius, wall_thickness, length, mu0):
    """The correction's regressors (1, ln(t/a), ln(L/a), q/(1+q)), q = p a/(mu0 t),
    stacked on the last axis (``physics.calibrated.TERMS``; pressure and mu0 [Pa], lengths
    [m])."""
    p, a, t, L = (np.asarray(v, float) for v in (pressure, radius, wall_thickness, length))
    p, a, t, L = np.broadcast_arrays(p, a, t, L)
    q = p * a / (mu0 * t)
    return np.stack([np.ones_like(q), np.log(t / a), np.log(L / a), q / (1.0 + q)], axis=-1)


def _pressure_at(angle, design, silicone):
    """The pressure [Pa] at which ``lateral_pressure`` bends ``design`` by ``angle`` [rad]."""
    from scipy.optimize import brentq

    def gap(p):
        return model_bend_angle(p, design["radius"], design["wall_thickness"],
                                design["length"], silicone=silicone,
                                model="lateral_pressure") - angle

    hi = 1e3
    while gap(hi) < 0:
        hi *= 2.0
        if hi > 1e6:
            raise InputError("fit fe: no pressure up to 1 MPa bends a training design "
                             f"by {math.degrees(angle):g} deg")
    return float(brentq(gap, 0.0, hi, xtol=1e-6, rtol=1e-12))


def training_plan(designs=48, seed=0, mesh="coarse", silicone="tc5005") -> dict:
    """The training runs: ``designs`` sampled designs, each with the pressures of
    :data:`TARGET_ANGLES` (JSON-able; it identifies a run folder)."""
    from scipy.stats import qmc

    sil = silicone_parameters(silicone)
    names = tuple(TRAINING_RANGES)
    u = qmc.LatinHypercube(d=len(names), seed=seed).random(designs)
    rows = []
    for row in u:
        d = {n: TRAINING_RANGES[n][0] + row[k] * (TRAINING_RANGES[n][1] - TRAINING_RANGES[n][0])
             for k, n in enumerate(names)}
        d["base_thickness"] = d["wall_thickness"]
        d["pressures"] = [_pressure_at(th, d, sil) for th in TARGET_ANGLES]
        rows.append(d)
    return {"designs": rows, "mesh": mesh, "seed": int(seed),
            "target_angles_deg": [math.degrees(th) for th in TARGET_ANGLES],
            **plan_material(sil)}


def _solve(task):
    """One training run: the FE angles on the mesh and the one below it [rad]."""
    d, sil, mesh = task
    res = fe_bend(d["radius"], d["wall_thickness"], d["length"], d["pressures"],
                  base_thickness=d["base_thickness"],
                  silicone=plan_silicone(sil),
                  mesh=mesh)
    return {"bend_angle": res["bend_angle"].tolist(),
            "coarser_bend_angle": res["coarser_bend_angle"].tolist()}


def run_training(parts, plan, *, workers=1, scheduler=None, progress=None, log=None) -> dict:
    """The training runs of ``plan``, journaled in the folder ``parts``: {index: result}."""
    tasks = [(d, plan["silicone"], plan["mesh"]) for d in plan["designs"]]
    return journaled_runs(parts, plan, tasks, _solve, workers=workers, scheduler=scheduler,
                          progress=progress, log=log, what="fit fe")


def fit_correction(plan, done, *, silicone=None) -> dict:
    """Fit the correction to the journaled runs; returns the coefficients, the per-point
    ratios of calibrated and lateral_pressure angles to FE, and the leave-one-design-out
    ratios (a design's points predicted by the fit to all other designs)."""

    rows = plan["designs"]
    sil = silicone or plan_silicone(plan["silicone"])
    pts = []  # (design index, pressure, FE angle)
    for k, d in enumerate(rows):
        if k not in done:
            continue
        fe = extrapolated(done[k]["bend_angle"], done[k]["coarser_bend_angle"])
        for p, th in zip(d["pressures"], fe):
            if np.isfinite(th) and th > 0:
                pts.append((k, p, float(th)))
    if len({k for k, _, _ in pts}) < MIN_DESIGNS:
        raise InputError("fit fe: too few FE angles to fit the correction "
                         f"({len(pts)} points)")
    idx = np.array([k for k, _, _ in pts])
    fe = np.array([th for _, _, th in pts])
    a = np.array([rows[k]["radius"] for k in idx])
    t = np.array([rows[k]["wall_thickness"] for k in idx])
    L = np.array([rows[k]["length"] for k in idx])
    p = np.array([pp for _, pp, _ in pts])
    lateral = np.array([model_bend_angle(pp, aa, tt, ll, silicone=sil, model="lateral_pressure")
                        for pp, aa, tt, ll in zip(p, a, t, L)])
    X = correction_terms(p, a, t, L, silicone_parameters(sil).initial_shear_modulus)
    y = np.log(fe / lateral)

    def fit(sel):
        return np.linalg.lstsq(X[sel], y[sel], rcond=None)[0]

    coef = fit(np.ones(len(pts), bool))
    loo = np.empty(len(pts))
    for k in np.unique(idx):
        out = idx == k
        loo[out] = np.exp(X[out] @ fit(~out)) * lateral[out] / fe[out]
    return {"coefficients": coef.tolist(), "terms": list(TERMS), "points": len(pts),
            "designs_used": int(len(np.unique(idx))),
            "design_index": idx.tolist(), "pressure": p.tolist(), "fe_bend_angle": fe.tolist(),
            "calibrated_over_fe": (np.exp(X @ coef) * lateral / fe).tolist(),
            "lateral_over_fe": (lateral / fe).tolist(),
            "loo_calibrated_over_fe": loo.tolist()}

