"""``nylonflex fit chamber``: the sealed chamber's compliance, rounding, squeeze and air
heating from one built actuator on the bench (docs/bench.md, docs/model.md s. 22).

One CSV, a ``phase`` column saying which test a row belongs to:

1. syringe, free: ``volume`` pushed into the (water-filled) chamber, ``pressure``;
2. syringe, held straight: the same with the actuator clamped straight;
3. sealed, heated: muscle ``stroke``, chamber ``pressure``, ``air_temperature``,
   ``muscle_temperature``, ``bend_angle``; the first row is the state it was sealed at;
4. vented, heated: ``stroke`` and ``bend_angle`` with the chamber open (p = 0).

Fitted: the volumetric stiffness K [Pa] and the rounding gamma [-] together, by least
squares on the pressures of phases 1 (p = K dV/V0) and 3 ((p0 + p)(v_free(s) + p/K) =
p0 T_air/T0, v_free = (1 - s)^2 exp(gamma s)); the air-heating share h [-] from phase 3,
T_air - T0 = h (T_muscle - T0); the squeeze c_sq [-] from phase 4, theta = c_sq s L/h_s
(h_s = b + a + t/2). Phase 2 gives the held stiffness, reported beside K.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from ..materials import silicone_parameters
from ..physics import P_ATM
from ..physics.sealed_model import boyle_pressure, chamber_stiffness
from ..units import InputError
from ._lsq import solve
from .data import column, read_table
from .result import FitResult, statistics

__all__ = ["PHASES", "fit_chamber"]

#: The ``phase`` codes of the CSV (docs/bench.md).
PHASES = {1: "syringe, free", 2: "syringe, held straight", 3: "sealed, heated",
          4: "vented, heated"}


def _through_origin(x, y):
    """(slope, its standard error, its 95 % interval) of y = c x by least squares."""
    sxx = float(x @ x)
    c = float(x @ y) / sxx
    dof = max(x.size - 1, 1)
    se = math.sqrt(float(((y - c * x) @ (y - c * x))) / dof / sxx)
    t = float(stats.t.ppf(0.975, dof))
    return c, se, [c - t * se, c + t * se]


def _pressure_model(x, s, tau, dv, phase3, p_atm):
    """Model pressures [Pa] of the phase-1 rows (K dV/V0) and the phase-3 rows (Boyle)."""
    k, gamma = x
    v = (1.0 - s) ** 2 * np.exp(gamma * s)
    out = np.where(phase3, 0.0, k * dv)
    if np.any(phase3):
        out[phase3] = boyle_pressure(v[phase3], k, tau[phase3], p_atm)
    return out


def _columns(table, phase):
    """The CSV's columns in SI (a column a phase does not use may hold anything)."""
    need = {"volume": ("volume", "volume", (1, 2)), "pressure": ("pressure", "pressure", (1, 2, 3)),
            "stroke": ("stroke", "dimensionless", (3, 4)),
            "air_temperature": ("air_temperature", "temperature", (3,)),
            "muscle_temperature": ("muscle_temperature", "temperature", (3,)),
            "bend_angle": ("bend_angle", "angle", (4,))}
    cols = {}
    for key, (name, kind, phases) in need.items():
        if np.any(np.isin(phase, phases)):
            cols[key] = column(table, (name,), key.replace("_", " "), kind)[1]
    return cols


def fit_chamber(data, radius, wall_thickness, length, base_thickness=None,
                chamber_volume=None, silicone="tc5005", name="", p_atm=P_ATM) -> FitResult:
    """Fit the chamber of one built actuator to its bench CSV (module docstring).

    Parameters
    ----------
    data : str or Path
        The CSV (units in its header; docs/bench.md).
    radius, wall_thickness, length : float
        The actuator's a, t, L [m].
    base_thickness : float, optional
        b [m]; b = t when None.
    chamber_volume : float, optional
        V0 [m^3]; pi a^2 L / 2 when None.
    silicone : str, dict or Silicone
        The silicone it is made of (for K over the model's closed form; its initial shear
        modulus is written with the design, the mu0 a sweep anchors K on).
    name : str
        Name of the fitted set.
    p_atm : float
        The absolute pressure it was sealed at [Pa].

    Returns
    -------
    FitResult
        ``stiffness`` K [Pa], ``rounding`` gamma [-], ``air_heating`` h [-] and ``squeeze``
        c_sq [-] with standard errors and 95 % intervals; derived ``stiffness_held`` [Pa],
        ``stiffness_factor`` K over the shipped model's [-] and ``heating_share`` of the
        pressure at phase 3's largest stroke [-]. x, y: phases 1 and 3's pressures.
    """
    table = read_table(data)
    phase = _phases(table, data)
    cols = _columns(table, phase)
    b = wall_thickness if base_thickness is None else base_thickness
    v0 = chamber_volume or 0.5 * math.pi * radius ** 2 * length
    k_model = float(chamber_stiffness(radius, wall_thickness, silicone))
    pv = _pressure_fit(phase, cols, v0, k_model, p_atm, data)
    sol, s, y, p3, fit = pv["solution"], pv["stroke"], pv["pressure"], pv["sealed"], pv["fit"]
    k, gamma = (float(v) for v in sol.x)
    se, ci = sol.stderr, sol.ci95()
    rows3 = phase == 3
    t_m = cols["muscle_temperature"][rows3]
    heat = _through_origin(t_m - t_m[0], cols["air_temperature"][rows3] - pv["t0"])
    rows4 = phase == 4
    squeeze = _through_origin(cols["stroke"][rows4] * length / (b + radius + 0.5 * wall_thickness),
                              cols["bend_angle"][rows4])
    derived = {"stiffness_factor": {"value": k / k_model, "stderr": float(se[0]) / k_model,
                                    "ci95": [float(c) / k_model for c in ci[0]]},
               "heating_share": {"value": pv["heating_share"], "stderr": math.nan,
                                 "ci95": [math.nan, math.nan]}}
    if np.sum(phase == 2) >= 2:
        held = _through_origin(cols["volume"][phase == 2] / v0, cols["pressure"][phase == 2])
        derived["stiffness_held"] = {"value": held[0], "stderr": held[1], "ci95": held[2]}
    rmse, r2 = statistics(y, fit)
    params = {"stiffness": k, "rounding": gamma, "air_heating": heat[0], "squeeze": squeeze[0]}
    cov = np.diag([se[0] ** 2, se[1] ** 2, heat[1] ** 2, squeeze[1] ** 2])
    cov[:2, :2] = sol.covariance
    return FitResult(
        kind="chamber", model="sealed_chamber", parameters=params,
        stderr={"stiffness": float(se[0]), "rounding": float(se[1]), "air_heating": heat[1],
                "squeeze": squeeze[1]},
        ci95={"stiffness": [float(c) for c in ci[0]], "rounding": [float(c) for c in ci[1]],
              "air_heating": heat[2], "squeeze": squeeze[2]},
        parameter_order=list(params), covariance=cov, derived=derived, rmse=rmse, r2=r2,
        fitted_range={"stroke": [float(s[p3].min()), float(s[p3].max())],
                      "pressure": [float(y.min()), float(y.max())]},
        data={"path": str(data), "sha256": table.sha256}, x_name="stroke", y_name="pressure",
        x=s, y=y, y_fit=fit, uncertainty=sol.method, name=name,
        units={"stiffness": "Pa", "rounding": "1", "air_heating": "1", "squeeze": "1",
               "stiffness_factor": "1", "stiffness_held": "Pa", "heating_share": "1",
               "rmse": "Pa"},
        extra={"design": {"radius": radius, "wall_thickness": wall_thickness, "length": length,
                          "base_thickness": b, "chamber_volume": v0,
                          "initial_shear_modulus": silicone_parameters(silicone)
                          .initial_shear_modulus}},
        notes=_notes(phase, gamma, r2))


def _phases(table, data) -> np.ndarray:
    """The ``phase`` column, checked: codes 1-4, at least 3 rows of phases 3 and 4."""
    phase = column(table, ("phase",), "phase (1-4, docs/bench.md)", "dimensionless")[1]
    bad = ~np.isin(phase, list(PHASES))
    if np.any(bad):
        raise InputError(f"{data}: column 'phase': must be one of 1, 2, 3, 4 (docs/bench.md), "
                         f"got {phase[bad][0]:g}")
    for code in (3, 4):
        if np.sum(phase == code) < 3:
            raise InputError(f"{data}: needs at least 3 rows of phase {code} "
                             f"({PHASES[code]}), got {int(np.sum(phase == code))}")
    return phase


def _pressure_fit(phase, cols, v0, k_model, p_atm, data) -> dict:
    """K and gamma by least squares on the pressures of phases 1 and 3 (the module
    docstring), with the rows fitted, the fit and the heating's share of the pressure at
    phase 3's largest stroke."""
    use = np.isin(phase, (1, 3))
    p3 = phase[use] == 3
    y = cols["pressure"][use]
    s = np.where(p3, cols["stroke"][use], 0.0)
    t_air = np.where(p3, cols["air_temperature"][use], 1.0)
    t0 = float(t_air[p3][0])
    tau = t_air / t0
    dv = np.where(p3, 0.0, cols["volume"][use] / v0) if "volume" in cols else np.zeros(y.size)

    def residual(x):
        return _pressure_model(x, s, tau, dv, p3, p_atm) - y

    def jacobian(x):
        h = np.array([1e-6 * x[0], 1e-6])
        return np.stack([(residual(x + np.eye(2)[i] * h[i]) - residual(x - np.eye(2)[i] * h[i]))
                         / (2 * h[i]) for i in range(2)], axis=1)

    sol = solve(residual, jacobian, [np.array([k_model, 0.0]), np.array([3 * k_model, 1.0])],
                [1.0, -20.0], [1e9, 1.5])
    if sol is None:
        raise InputError(f"{data}: the phase 1 and 3 pressures fit no chamber (K, gamma)")
    top = np.array([int(np.argmax(np.where(p3, s, -1.0)))])
    hot = float(_pressure_model(sol.x, s[top], tau[top], dv[top], p3[top], p_atm)[0])
    cold = float(_pressure_model(sol.x, s[top], np.ones(1), dv[top], p3[top], p_atm)[0])
    return {"solution": sol, "stroke": s, "pressure": y, "sealed": p3, "t0": t0,
            "fit": _pressure_model(sol.x, s, tau, dv, p3, p_atm),
            "heating_share": (hot - cold) / hot if hot > 0 else math.nan}


def _notes(phase, gamma, r2) -> list:
    """What a user should know of a fit that may not say what it seems to."""
    notes = []
    if np.sum(phase == 1) < 2:
        notes.append("no phase-1 rows: K and gamma from the sealed pressures alone, weakly "
                     "separated")
    if gamma <= -20.0 + 1e-6 or gamma >= 1.5 - 1e-6:
        notes.append(f"rounding on its bound ({gamma:g}): these pressures fit no chamber of "
                     "this form; check --chamber-volume, the strokes and the units")
    if not r2 > 0.9:
        notes.append(f"the pressures fit poorly (R^2 {r2:.3f}); docs/bench.md says what to "
                     "check")
    return notes
