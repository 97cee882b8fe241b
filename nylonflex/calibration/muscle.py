"""Fits of the coiled nylon muscle: stroke (eq. 2), heating (eq. 3) and force (eq. 1).

- :func:`fit_stroke`: free contraction against temperature of a heating run, one coil index,
  to the eq. (2) shape ``s(T) = gamma (T - T_amb) + beta (erf((T - T_g)/(sigma_g sqrt 2))
  - erf((T_amb - T_g)/(sigma_g sqrt 2)))`` (the contraction eps(T_amb) - eps(T) of the
  paper's eq. 2); s_max = s(T_max).
- :func:`fit_thermal`: a step response at a known voltage to eq. (3),
  ``T(t) = T_inf + (T_0 - T_inf) exp(-(t - t_0)/tau)``; lambda' = V^2 / (R l_m (T_inf - T_amb))
  and c' = tau lambda' (R = r' l_m, Lambda = lambda' l_m, C = c' l_m).
- :func:`fit_muscle`: force against displacement and temperature (and velocity) to eq. (1),
  ``F = k x + c (T - T_amb) [+ b dx/dt]``; the blocked force c (T_max - T_amb).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import erf

from ..materials import ZERO_CELSIUS, nylon_parameters
from ..units import InputError
from ._lsq import derived, solve
from .data import Table, column, read_table
from .result import FitResult, statistics

__all__ = ["fit_muscle", "fit_stroke", "fit_thermal", "stroke_shape"]

_SQRT2 = math.sqrt(2.0)


def _table(data):
    return data if isinstance(data, Table) else read_table(data)


def _flat(sol, names, scales=None):
    scales = np.ones(len(names)) if scales is None else np.asarray(scales, float)
    v, se, ci = sol.x * scales, sol.stderr * scales, sol.ci95() * scales[:, None]
    return ({n: float(a) for n, a in zip(names, v)}, {n: float(a) for n, a in zip(names, se)},
            {n: [float(c[0]), float(c[1])] for n, c in zip(names, ci)},
            sol.covariance * np.outer(scales, scales))


def _numeric_gradient(f, x):
    g = np.zeros_like(x)
    for i in range(x.size):
        h = 1e-6 * max(abs(x[i]), 1e-3)
        e = np.zeros_like(x)
        e[i] = h
        g[i] = (f(x + e) - f(x - e)) / (2 * h)
    return g


def _derived(sol, f):
    v, se, ci = derived(sol, f, lambda x: _numeric_gradient(f, x))
    return {"value": v, "stderr": se, "ci95": [float(ci[0]), float(ci[1])]}


def _too_few(path, n, p, what):
    if n < p + 2:
        raise InputError(f"{path}: {n} usable points; the {what} fit needs at least {p + 2}")


def stroke_shape(temperature, t_amb, gamma, beta, t_g, sigma_g):
    """Contraction of the eq. (2) shape, zero at T_amb [-].

    Parameters
    ----------
    temperature : float or array
        Muscle temperature T [K].
    t_amb : float
        Ambient temperature [K].
    gamma : float
        Linear coefficient [1/K].
    beta : float
        Height of the erf step [-].
    t_g, sigma_g : float
        Centre [K] and width [K] of the step.
    """
    c = 1.0 / (sigma_g * _SQRT2)
    t = np.asarray(temperature, float)
    return gamma * (t - t_amb) + beta * (erf((t - t_g) * c) - erf((t_amb - t_g) * c))


def fit_stroke(data, coil_index, nylon="silver_nylon66", t_amb=None, t_max=None, name="",
               tensile_strength=None) -> FitResult:
    """Fit the eq. (2) stroke shape to a heating run of one coil index.

    Parameters
    ----------
    data : str, Path or Table
        Columns ``temperature`` (with a unit) and ``stroke`` (contraction, [-] or [%];
        ``contraction`` or ``strain`` also read).
    coil_index : float
        Coil index C of the muscle tested [-], > 1.
    nylon : str, dict or Nylon
        The set whose coil-index table gets the fitted row, and whose T_amb, T_max are used.
    t_amb, t_max : float, optional
        Ambient and highest temperature [K] (default: the set's).
    name : str
        Name of the fitted set.
    tensile_strength : float, optional
        sigma_u of a new table row [Pa] (default: the set's table, interpolated).

    Returns
    -------
    FitResult
        ``parameters`` gamma [1/K], beta [-], t_g [K], sigma_g [K];
        ``derived["stroke_max"]`` s(T_max) [-]; ``extra["fields"]`` the nylon file's fields.
    """
    table = _table(data)
    path = table.path
    ny = nylon_parameters(nylon)
    t_amb = ny.t_amb if t_amb is None else float(t_amb)
    t_max = ny.t_max if t_max is None else float(t_max)
    if not (np.isfinite(coil_index) and coil_index > 1.0):
        raise InputError(f"--coil-index: must be > 1, got {coil_index:g}")
    if not t_max > t_amb:
        raise InputError("--t-max: must be above the ambient temperature")
    _, temp = column(table, ["temperature"], "temperature", "temperature")
    _, s = column(table, ["stroke", "contraction", "strain"], "stroke", "dimensionless")
    if np.any(temp <= 0):
        raise InputError(f"{path}: temperature must be above 0 K")
    _too_few(path, temp.size, 4, "stroke")
    order = np.argsort(temp)
    temp, s = temp[order], s[order]
    span = float(max(temp.max() - temp.min(), 1.0))

    def model(x, t):
        return stroke_shape(t, t_amb, x[0], x[1], x[2], x[3])

    def res(x):
        return model(x, temp) - s

    def jac(x):
        return _stroke_jac(x, temp, t_amb)
    starts = []
    for tg in np.linspace(temp.min(), temp.max(), 5):
        for sg in (0.1 * span, 0.3 * span):
            basis = np.stack([temp - t_amb, erf((temp - tg) / (sg * _SQRT2))
                              - erf((t_amb - tg) / (sg * _SQRT2))], axis=1)
            gb = np.linalg.lstsq(basis, s, rcond=None)[0]
            starts.append(np.array([gb[0], gb[1], tg, sg]))
    lo = [-np.inf, -np.inf, temp.min() - span, 0.5]
    hi = [np.inf, np.inf, temp.max() + span, 5.0 * span]
    sol = solve(res, jac, starts, lo, hi)
    if sol is None or not sol.converged:
        raise InputError(f"{path}: the eq. (2) stroke fit did not converge")
    names = ["gamma", "beta", "t_g", "sigma_g"]
    params, se, ci, cov = _flat(sol, names)
    smax = _derived(sol, lambda x: float(model(x, t_max)))
    if not 0 < smax["value"] < 1:
        raise InputError(f"{path}: the fitted stroke at T_max is {smax['value']:g}; must be "
                         "in (0, 1) (is the column a contraction, positive on heating?)")
    fit = model(sol.x, temp)
    rmse, r2 = statistics(s, fit)
    # the nylon file: this shape for every coil index, the row of C added or replaced
    c_tab = list(ny.coil_index_table)
    s_tab = list(ny.stroke_max_table)
    u_tab = list(ny.tensile_strength_table)
    su = float(np.interp(coil_index, c_tab, u_tab)) if tensile_strength is None else \
        float(tensile_strength)
    hit = [i for i, c in enumerate(c_tab) if abs(c - coil_index) < 1e-9]
    if hit:
        s_tab[hit[0]] = smax["value"]
        if tensile_strength is not None:
            u_tab[hit[0]] = su
    else:
        i = int(np.searchsorted(c_tab, coil_index))
        c_tab.insert(i, float(coil_index))
        s_tab.insert(i, smax["value"])
        u_tab.insert(i, su)
    g, b, tg, sg = sol.x
    alpha = g * (t_amb - ZERO_CELSIUS) + b * math.erf((t_amb - tg) / (sg * _SQRT2))
    fields = {"base": ny.name.split("+")[0] if not ny.name.startswith("file:") else
              "silver_nylon66", "gamma": g, "beta": b, "t_g": tg, "sigma_g": sg,
              "alpha": alpha, "stroke_reference": smax["value"], "t_amb": t_amb,
              "t_max": t_max, "coil_index_table": c_tab, "stroke_max_table": s_tab,
              "tensile_strength_table": u_tab}
    return FitResult(
        kind="stroke", model="eq2", name=name, parameters=params, stderr=se, ci95=ci,
        parameter_order=names, covariance=cov, derived={"stroke_max": smax}, rmse=rmse, r2=r2,
        fitted_range={"temperature": [float(temp[0]), float(temp[-1])]},
        data={"path": path, "sha256": table.sha256}, x_name="temperature", y_name="stroke",
        x=temp, y=s, y_fit=fit, uncertainty=sol.method,
        units={"gamma": "1/K", "beta": "1", "t_g": "K", "sigma_g": "K", "stroke_max": "1",
               "rmse": "1"},
        extra={"fields": fields, "coil_index": float(coil_index), "t_max": t_max})


def _stroke_jac(x, t, t_amb):
    g, b, tg, sg = x
    c = 1.0 / (sg * _SQRT2)
    za, zt = (t_amb - tg) * c, (t - tg) * c
    k = 2.0 / math.sqrt(math.pi)
    d_erf_t, d_erf_a = k * np.exp(-zt**2), k * math.exp(-za**2)
    return np.stack([t - t_amb, erf(zt) - math.erf(za),
                     b * (-d_erf_t * c + d_erf_a * c),
                     b * (-d_erf_t * zt / sg + d_erf_a * za / sg)], axis=1)


def fit_thermal(data, voltage, muscle_length=None, resistance=None, nylon="silver_nylon66",
                t_amb=None, name="") -> FitResult:
    """Fit a heating step response to eq. (3): tau, lambda' and c'.

    Parameters
    ----------
    data : str, Path or Table
        Columns ``time`` and ``temperature`` (or ``resistance``; then only tau).
    voltage : float
        Voltage of the step [V], > 0.
    muscle_length : float, optional
        Length of the muscle l_m [m]; needed for lambda' and c'.
    resistance : float, optional
        Its resistance R [ohm] (default r' l_m of the set).
    nylon : str, dict or Nylon
        Set for T_amb and r'.
    t_amb : float, optional
        Ambient temperature [K] (default: the set's).
    name : str
        Name of the fitted set.

    Returns
    -------
    FitResult
        ``parameters`` t_0 and t_inf [K] (or [ohm]) and tau [s]; ``derived`` tau [s],
        and with a temperature column and l_m, heat_loss_per_length lambda' [W/(K m)] and
        heat_capacity_per_length c' [J/(K m)].
    """
    table = _table(data)
    path = table.path
    ny = nylon_parameters(nylon)
    t_amb = ny.t_amb if t_amb is None else float(t_amb)
    if not (np.isfinite(voltage) and voltage > 0):
        raise InputError(f"--voltage: must be > 0 V, got {voltage:g}")
    _, time = column(table, ["time", "t"], "time", "time")
    if table.has("temperature"):
        _, y = column(table, ["temperature"], "temperature", "temperature")
        yname, yunit = "temperature", "K"
    else:
        _, y = column(table, ["resistance"], "temperature or resistance", "resistance")
        yname, yunit = "resistance", "ohm"
    if np.any(np.diff(time) <= 0):
        raise InputError(f"{path}: time must increase row by row")
    _too_few(path, time.size, 3, "eq. (3) step")
    t0 = time[0]
    dt = time - t0
    span = float(dt[-1]) or 1.0

    def res(x):
        return x[1] + (x[0] - x[1]) * np.exp(-dt / x[2]) - y

    def jac(x):
        e = np.exp(-dt / x[2])
        return np.stack([e, 1.0 - e, (x[0] - x[1]) * e * dt / x[2] ** 2], axis=1)
    starts = [np.array([y[0], y[-1], f * span]) for f in (0.05, 0.2, 0.5, 1.0)]
    sol = solve(res, jac, starts, [-np.inf, -np.inf, 1e-6 * span], [np.inf, np.inf,
                                                                     100.0 * span])
    if sol is None or not sol.converged:
        raise InputError(f"{path}: the eq. (3) step-response fit did not converge")
    names = [f"{yname}_0", f"{yname}_inf", "tau"]
    params, se, ci, cov = _flat(sol, names)
    out = {"tau": _derived(sol, lambda x: float(x[2]))}
    units = {names[0]: yunit, names[1]: yunit, "tau": "s", "rmse": yunit}
    fields = {"base": "silver_nylon66"}
    if yname == "temperature" and muscle_length is not None:
        if not muscle_length > 0:
            raise InputError(f"--muscle-length: must be > 0, got {muscle_length:g}")
        r = ny.resistance_per_length * muscle_length if resistance is None else float(resistance)
        if sol.x[1] <= t_amb:
            raise InputError(f"{path}: the fitted final temperature is not above ambient")

        def lam(x):
            return voltage**2 / (r * muscle_length * (x[1] - t_amb))
        out["heat_loss_per_length"] = _derived(sol, lam)
        out["heat_capacity_per_length"] = _derived(sol, lambda x: lam(x) * x[2])
        units.update(heat_loss_per_length="W/(K m)", heat_capacity_per_length="J/(K m)")
        fields.update(heat_loss_per_length=out["heat_loss_per_length"]["value"],
                      heat_capacity_per_length=out["heat_capacity_per_length"]["value"])
        if resistance is not None:
            # measured on this muscle: the same r' at every coil index (docs/model.md s. 9)
            fields["resistance_per_length"] = r / muscle_length
            fields["resistance_coil_index"] = 0.0
    fit = res(sol.x) + y
    rmse, r2 = statistics(y, fit)
    return FitResult(
        kind="thermal", model="eq3", name=name, parameters=params, stderr=se, ci95=ci,
        parameter_order=names, covariance=cov, derived=out, rmse=rmse, r2=r2,
        fitted_range={"time": [float(time[0]), float(time[-1])]},
        data={"path": path, "sha256": table.sha256}, x_name="time", y_name=yname, x=time,
        y=y, y_fit=fit, uncertainty=sol.method, units=units,
        extra={"fields": fields, "voltage": float(voltage)})


def fit_muscle(data, nylon="silver_nylon66", t_amb=None, t_max=None, name="") -> FitResult:
    """Fit eq. (1), F = k x + c (T - T_amb) [+ b dx/dt], to force measurements.

    Parameters
    ----------
    data : str, Path or Table
        Columns ``displacement`` (length), ``temperature``, ``force`` and optionally
        ``velocity`` (e.g. ``velocity [mm/s]``).
    nylon : str, dict or Nylon
        Set for T_amb and T_max.
    t_amb, t_max : float, optional
        Ambient and highest temperature [K] (default: the set's).
    name : str
        Name of the fitted set.

    Returns
    -------
    FitResult
        ``parameters`` stiffness k [N/m], thermal_force_coefficient c [N/K] (and damping b
        [N s/m]); ``derived["blocked_force"]`` c (T_max - T_amb) [N].
    """
    table = _table(data)
    path = table.path
    ny = nylon_parameters(nylon)
    t_amb = ny.t_amb if t_amb is None else float(t_amb)
    t_max = ny.t_max if t_max is None else float(t_max)
    _, x = column(table, ["displacement", "x"], "displacement", "length")
    _, temp = column(table, ["temperature"], "temperature", "temperature")
    _, force = column(table, ["force"], "force", "force")
    cols = [x, temp - t_amb]
    names = ["stiffness", "thermal_force_coefficient"]
    if table.has("velocity"):
        _, v = column(table, ["velocity"], "velocity", "compound")
        cols.append(v)
        names.append("damping")
    basis = np.stack(cols, axis=1)
    _too_few(path, force.size, len(names), "eq. (1)")
    if np.linalg.matrix_rank(basis) < len(names):
        raise InputError(f"{path}: displacement, temperature (and velocity) do not vary "
                         "independently; eq. (1) cannot be fitted")
    scales = 1.0 / np.max(np.abs(basis), axis=0)
    b = basis * scales

    def res(p):
        return b @ p - force

    def jac(p):
        return b
    p0 = np.linalg.lstsq(b, force, rcond=None)[0]
    sol = solve(res, jac, [p0], [-np.inf] * len(names), [np.inf] * len(names))
    if sol is None:
        raise InputError(f"{path}: the eq. (1) fit did not converge")
    params, se, ci, cov = _flat(sol, names, scales)
    blocked = _derived(sol, lambda p: float(p[1] * scales[1] * (t_max - t_amb)))
    fit = b @ sol.x
    rmse, r2 = statistics(force, fit)
    units = {"stiffness": "N/m", "thermal_force_coefficient": "N/K", "damping": "N s/m",
             "blocked_force": "N", "rmse": "N"}
    fields = {"base": "silver_nylon66", **params}
    return FitResult(
        kind="muscle", model="eq1", name=name, parameters=params, stderr=se, ci95=ci,
        parameter_order=names, covariance=cov, derived={"blocked_force": blocked}, rmse=rmse,
        r2=r2, fitted_range={"displacement": [float(x.min()), float(x.max())],
                             "temperature": [float(temp.min()), float(temp.max())]},
        data={"path": path, "sha256": table.sha256}, x_name="force", y_name="force",
        x=fit, y=force, y_fit=fit, uncertainty=sol.method,
        units={k: v for k, v in units.items() if k in names or k in ("blocked_force", "rmse")},
        extra={"fields": fields})
