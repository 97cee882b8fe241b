"""``sealed_chamber``'s coefficients from records of the sealed, stroke-driven FE twin
(docs/model.md s. 22), with the leave-one-design-out error of each.

A record is one design driven to one stroke: ``design`` (``radius``, ``wall_thickness``,
``length`` [m], optionally ``base_thickness`` [m], b = t without), ``stroke`` [-],
``pressure`` [Pa] (gauge), ``bend_angle`` [rad] (free), ``tip_force`` [N] (blocked, at
the same stroke), optionally ``volume_ratio`` V/V0 [-] (else p0/(p0 + p), Boyle),
``free_volume`` [-] (the chamber's volume with the air vented, which separates the
compliance from the rounding) and ``blocked_pressure`` [Pa] (the chamber's pressure held
straight, which the blocked pressure's ratio is fitted to). :func:`fe_records` reads the
sealed twin's record files into this form.

Each group is fitted by linear least squares on what a record says of it:

- stiffness: ln(K_i / (mu0 (1 - (a/(a+t))^2))) = k0 + k1 ln(t/a), K_i = p / (V/V0 -
  v_free), only from records with ``free_volume`` (without: k0 = k1 = 0, Lame's);
- rounding: gamma_i = ln(v_free / (1 - s)^2) / s = g0 + g1 ln(t/a), v_free = V/V0 - p/K;
- squeeze: c_i = (theta - theta_lateral(p)) h / (s L) = c0 + c1 ln(t/a);
- blocked pressure: ln(p_b / p) = r0 + r1 x + r2 x^2 + r3 ln s + r4 a/L (x = ln(t/a)),
  with p the free pressure the fitted stiffness and rounding predict, from the records
  with ``blocked_pressure``;
- blocked moment: F L = c_a M_lateral(rho p) + c_b M_S(kappa_sq), relative least
  squares, rho the blocked pressure's ratio just fitted (what the model itself adds).

Left out one design at a time, the others' coefficients predict its pressure, bend and
blocked force through the whole model (:func:`~nylonflex.physics.sealed_model.sealed_state`
at the record's stroke), which is the error reported.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..materials import silicone_parameters
from ..physics import P_ATM
from ..physics.sealed import BLOCKED_NEUTRAL, COEFFICIENT_NAMES, GAMMA_MAX, calibration
from ..physics.sealed_model import blocked_ratio, lateral_state, sealed_state

__all__ = ["TOLERANCE", "calibration_document", "fe_records", "fit_sealed_chamber",
           "record_groups"]

#: The relative miss counted as a hit in the leave-one-out summary [-].
TOLERANCE = 0.15


def fe_records(folder) -> tuple[list, list]:
    """The sealed twin's records in ``folder`` (``design_NNN.json``, written by
    ``nf.fe_stroke`` runs; the folder's README.txt gives the format) as the records
    :func:`fit_sealed_chamber` takes, in index order (``tip_force`` NaN where the blocked
    solve stalled: the record still informs the free fit); and the names of the files left
    out (a free solve that stalled, or a file that is not a complete record)."""
    records, skipped = [], []
    for path in sorted(Path(folder).glob("design_*.json")):
        try:
            doc = json.loads(path.read_text())
            reached = doc.get("reached", {})
            if not reached.get("free"):
                skipped.append(path.name)
                continue
            free = doc["free"]
            blocked = doc["blocked"] if reached.get("blocked") else \
                {"tip_force": math.nan, "pressure": math.nan}
            rec = {"design": dict(doc["design"]), "stroke": float(doc["stroke"]),
                   "pressure": float(free["pressure"]),
                   "volume_ratio": float(free["volume_ratio"]),
                   "bend_angle": float(free["bend_angle"]),
                   "tip_force": float(blocked["tip_force"]),
                   "blocked_pressure": float(blocked["pressure"]),
                   "index": int(doc.get("index", len(records))),
                   "silicone": doc.get("silicone", "tc5005"),
                   "paper": dict(doc.get("paper") or {}),
                   "discretisation_error": max(float(free.get("discretisation_error") or 0),
                                               float(blocked.get("discretisation_error")
                                                     or 0))}
        except (ValueError, KeyError, TypeError, OSError):
            skipped.append(path.name)
            continue
        if all(math.isfinite(rec[k]) and rec[k] > 0 for k in
               ("stroke", "pressure", "bend_angle")):
            records.append(rec)
        else:
            skipped.append(path.name)
    records.sort(key=lambda r: r["index"])
    return records, skipped


def _design(rec):
    d = rec["design"]
    a, t, L = (float(d[k]) for k in ("radius", "wall_thickness", "length"))
    b = float(d.get("base_thickness") or t)
    return a, t, b, L


def record_groups(records, silicone="tc5005", p_atm=P_ATM) -> dict:
    """Per record, the regressor ln(t/a) and what it says of each group (arrays):
    ``lame`` [Pa] mu0 (1 - (a/(a+t))^2), ``stiffness`` K_i [Pa] (NaN without
    ``free_volume``), ``volume`` V/V0 [-], the lateral balance's bend ``theta_p`` [rad] at
    the record's pressure, and ``h`` = b + a + t/2 [m]."""
    mu0 = silicone_parameters(silicone).initial_shear_modulus
    out = {k: [] for k in ("x", "lame", "stiffness", "volume", "theta_p", "h")}
    for rec in records:
        a, t, b, L = _design(rec)
        p = float(rec["pressure"])
        v = float(rec.get("volume_ratio") or p_atm / (p_atm + p))
        vf = rec.get("free_volume")
        out["x"].append(math.log(t / a))
        out["lame"].append(mu0 * (1.0 - (a / (a + t)) ** 2))
        out["stiffness"].append(p / (v - float(vf)) if vf is not None and v > float(vf)
                                else math.nan)
        out["volume"].append(v)
        out["theta_p"].append(lateral_state(p, a, t, b, silicone)[0] * L)
        out["h"].append(b + a + 0.5 * t)
    return {k: np.asarray(v, dtype=float) for k, v in out.items()}


def _linear(x, y):
    """(c0, c1) of y = c0 + c1 x by least squares; c1 = 0 from fewer than 3 points or one
    x."""
    ok = np.isfinite(y)
    x, y = x[ok], y[ok]
    if y.size == 0:
        return math.nan, 0.0
    if y.size < 3 or np.ptp(x) == 0.0:
        return float(np.mean(y)), 0.0
    c1, c0 = np.polyfit(x, y, 1)
    return float(c0), float(c1)


def _fit(records, groups, idx, silicone, p_atm=P_ATM):
    """Coefficients (the COEFFICIENT_NAMES order) from the records ``idx``."""
    g = {k: v[idx] for k, v in groups.items()}
    recs = [records[i] for i in idx]
    s = np.array([float(r["stroke"]) for r in recs])
    p = np.array([float(r["pressure"]) for r in recs])
    theta = np.array([float(r["bend_angle"]) for r in recs])
    force = np.array([float(r["tip_force"]) for r in recs])
    L = np.array([_design(r)[3] for r in recs])
    if np.sum(np.isfinite(g["stiffness"])) > 0:
        k0, k1 = _linear(g["x"], np.log(g["stiffness"] / g["lame"]))
    else:
        k0, k1 = 0.0, 0.0
    stiffness = g["lame"] * np.exp(k0 + k1 * g["x"])
    v_free = g["volume"] - p / stiffness
    with np.errstate(invalid="ignore", divide="ignore"):
        gamma = np.log(v_free / (1.0 - s) ** 2) / s
    g0, g1 = _linear(g["x"], np.where(np.isfinite(gamma), np.minimum(gamma, GAMMA_MAX),
                                      np.nan))
    c0, c1 = _linear(g["x"], (theta - g["theta_p"]) * g["h"] / (s * L))
    blocked = np.isfinite(force) & (force > 0)  # records whose blocked solve was reached
    # the model's own free state (c_b = c_a = 1, rho = 1): its pressure, pressure moment
    # and squeeze moment, what the blocked groups complete (fitted to what the model adds)
    free = (k0, k1, g0, g1, c0, c1, 1.0, *BLOCKED_NEUTRAL.values())
    states = [_predict(r, free, silicone, p_atm) for r, ok in zip(recs, blocked) if ok]
    held = [r for r, ok in zip(recs, blocked) if ok]
    ratio = _blocked_pressure_fit(held, [st["pressure"] for st in states])
    rho = np.array([blocked_ratio(float(r["stroke"]), *_design(r)[:2], _design(r)[3],
                                  free[:8] + ratio) for r in held])
    moment = (force * L)[blocked]
    ca, cb = _blocked_moment_fit(rho * np.array([st["pressure_moment"] for st in states]),
                                 np.array([st["squeeze_moment"] for st in states]), moment)
    return (k0, k1, g0, g1, c0, c1, cb, ca, *ratio)


def _blocked_pressure_fit(records, pressures) -> tuple:
    """(r0, .., r4): ln(p_b / p) = r0 + r1 x + r2 x^2 + r3 ln s + r4 a/L by least squares
    over the ``records`` with a blocked pressure (``pressures``: the model's free ones
    [Pa]); their mean ln(p_b / p) alone (r1 .. r4 = 0) from fewer than 8; 0 from none."""
    rows, y = [], []
    for rec, p in zip(records, pressures):
        p_b = float(rec.get("blocked_pressure", math.nan))
        if math.isfinite(p_b) and p_b > 0 and p > 0:
            a, t, _, L = _design(rec)
            x = math.log(t / a)
            rows.append((1.0, x, x * x, math.log(float(rec["stroke"])), a / L))
            y.append(math.log(p_b / p))
    if not y:
        return (0.0,) * 5
    if len(y) < 8:
        return (float(np.mean(y)),) + (0.0,) * 4
    return tuple(float(c) for c in np.linalg.lstsq(np.array(rows), np.array(y),
                                                    rcond=None)[0])


def _blocked_moment_fit(pressure_moment, squeeze, moment) -> tuple:
    """(c_a, c_b) of M = c_a M_p + c_b M_S by relative least squares over the records
    (``pressure_moment`` c_a's term at the blocked pressure, ``squeeze`` M_S, ``moment``
    the twin's blocked moment F L, [N m] each); (1, 1) from none."""
    if moment.size == 0:
        return 1.0, 1.0
    a = np.c_[pressure_moment, squeeze] / moment[:, None]
    if moment.size < 2:
        return 1.0, float((1.0 - a[0, 0]) / a[0, 1])
    ca, cb = np.linalg.lstsq(a, np.ones(moment.size), rcond=None)[0]
    return float(ca), float(cb)


def _predict(rec, coef, silicone, p_atm):
    a, t, b, L = _design(rec)
    return sealed_state(float(rec["stroke"]), a, t, L, b, silicone, coef, 1.0, p_atm)


def fit_sealed_chamber(records, silicone="tc5005", p_atm=P_ATM, tolerance=TOLERANCE) -> dict:
    """Fit ``sealed_chamber``'s coefficients to FE records, with leave-one-design-out errors.

    Parameters
    ----------
    records : list of dict
        One design each (the module's docstring gives the fields, SI).
    silicone : str, dict or Silicone
        The silicone the FE twin ran with.
    p_atm : float
        The pressure the chamber was sealed at [Pa].
    tolerance : float
        The relative miss counted as within [-].

    Returns
    -------
    dict
        ``coefficients`` (name -> value, all records), ``stiffness_from`` (``"free_volume"``
        or ``"closed_form"``), ``designs`` (the records' designs), and ``loo``: per record
        the left-out prediction over the record of ``pressure``, ``bend_angle`` and
        ``tip_force`` (lists; NaN where the record has none), ``within`` (how many of them
        are within ``tolerance``) of ``counted`` (how many are known), and
        ``bend_and_force_within`` of ``n_both`` (designs with both known) and ``n``.
    """
    if len(records) < 3:
        raise ValueError(f"records: need at least 3 designs, got {len(records)}")
    groups = record_groups(records, silicone, p_atm)
    n = len(records)
    coef = _fit(records, groups, np.arange(n), silicone, p_atm)
    loo = {"pressure": [], "bend_angle": [], "tip_force": []}
    for j in range(n):
        c = _fit(records, groups, np.delete(np.arange(n), j), silicone, p_atm)
        pred = _predict(records[j], c, silicone, p_atm)
        for name in loo:
            loo[name].append(pred[name] / float(records[j][name]))
    miss = {name: np.abs(np.asarray(v) - 1.0) for name, v in loo.items()}
    within = {name: int(np.sum(m <= tolerance)) for name, m in miss.items()}
    counted = {name: int(np.sum(np.isfinite(m))) for name, m in miss.items()}
    both = int(np.sum((miss["bend_angle"] <= tolerance) & (miss["tip_force"] <= tolerance)))
    n_both = int(np.sum(np.isfinite(miss["bend_angle"]) & np.isfinite(miss["tip_force"])))
    return {"coefficients": dict(zip(COEFFICIENT_NAMES, coef)),
            "stiffness_from": "free_volume" if np.any(np.isfinite(groups["stiffness"]))
            else "closed_form",
            "designs": [dict(r["design"]) for r in records],
            "loo": {**loo, "within": within, "counted": counted,
                    "bend_and_force_within": both, "n_both": n_both, "n": n,
                    "tolerance": tolerance}}


def calibration_document(fit: dict, records: list, provenance: dict) -> dict:
    """The ``physics/sealed_chamber.json`` document of a fit (:func:`fit_sealed_chamber`)
    to ``records``: ``status: fitted``, the form, the coefficients, ``provenance`` (given:
    the command, the records' folder, ...), ``fit`` (the leave-one-out and the designs) and
    ``training`` (each record's stroke and FE values, SI)."""
    form = calibration()["form"]
    keep = ("design", "stroke", "pressure", "volume_ratio", "bend_angle", "tip_force",
            "blocked_pressure", "discretisation_error")
    return {"model": "sealed_chamber", "status": "fitted",
            "note": f"fitted to {len(records)} sealed FE twin designs; the leave-one-out "
                    "errors are in 'fit'",
            "form": form, "coefficients": dict(fit["coefficients"]),
            "provenance": {**provenance, "stiffness_from": fit["stiffness_from"]},
            "fit": {"designs": fit["designs"], "loo": fit["loo"]},
            "training": [{k: r[k] for k in keep if k in r} for r in records]}
