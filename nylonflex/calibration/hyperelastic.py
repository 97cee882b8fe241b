"""Incompressible hyperelastic fits to a uniaxial or planar (pure-shear) test.

Nominal (first Piola) stress against stretch l, the free surfaces stress-free:

- Ogden (paper's eq. 5 convention), W = sum mu_i/alpha_i (l1^a_i + l2^a_i + l3^a_i - 3)::

      uniaxial (l2 = l3 = l^-1/2):  P = sum mu_i (l^(a_i - 1) - l^(-a_i/2 - 1))
      planar   (l2 = 1, l3 = 1/l):  P = sum mu_i (l^(a_i - 1) - l^(-a_i - 1))

  mu_0 = 1/2 sum mu_i alpha_i. Stability (Drucker, term by term): mu_i alpha_i > 0.
- neo-Hookean, W = C1 (I1 - 3): Ogden with one term, alpha = 2 and mu = 2 C1 = mu_0.
- Yeoh (two terms), W = C1 (I1 - 3) + C2 (I1 - 3)^2::

      uniaxial: P = 2 (l - l^-2) (C1 + 2 C2 (I1 - 3)),  I1 = l^2 + 2/l
      planar:   P = 2 (l - l^-3) (C1 + 2 C2 (I1 - 3)),  I1 = l^2 + 1 + l^-2

  mu_0 = 2 C1.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..units import InputError
from ._lsq import derived, solve
from .data import Table, column, read_table
from .result import FitResult, statistics

__all__ = ["MODELS", "TESTS", "fit_silicone", "nominal_stress", "silicone_data"]

#: model name -> number of Ogden terms (None: not an Ogden form).
MODELS = {"ogden1": 1, "ogden2": 2, "ogden3": 3, "neo_hookean": 1, "yeoh2": None}
TESTS = ("uniaxial", "planar")
_K = {"uniaxial": -0.5, "planar": -1.0}  # l3 = l^k
_ALPHA_MIN, _ALPHA_MAX = 0.05, 40.0
#: A fit that explains less than this of the variance is refused as not converged.
MIN_R2 = 0.5


def _check_model(model, test):
    if model not in MODELS:
        raise InputError(f"--model: unknown model {model!r}; accepted: {', '.join(MODELS)}")
    if test not in TESTS:
        raise InputError(f"--test: unknown test {test!r}; accepted: {', '.join(TESTS)}")


def nominal_stress(stretch, model, parameters, test="uniaxial"):
    """Nominal stress P(l) of a fitted form [Pa].

    Parameters
    ----------
    stretch : float or array
        Stretch l in the loaded direction [-], > 0.
    model : str
        One of :data:`MODELS`.
    parameters : dict
        ``{"mu": [Pa], "alpha": [-]}`` (Ogden, neo-Hookean) or ``{"c1": Pa, "c2": Pa}``.
    test : str
        ``"uniaxial"`` or ``"planar"``.
    """
    _check_model(model, test)
    lam = np.asarray(stretch, dtype=float)
    if model == "yeoh2":
        return _yeoh(lam, np.array([parameters["c1"], parameters["c2"]]), test)[0]
    return _ogden(lam, np.asarray(parameters["mu"], float), np.asarray(parameters["alpha"],
                                                                        float), test)[0]


def _ogden(lam, mu, alpha, test):
    """P and its derivatives dP/dmu (n, N), dP/dalpha (n, N)."""
    k = _K[test]
    ln = np.log(lam)[:, None]
    e1 = np.exp(alpha[None, :] * ln)
    e2 = np.exp(k * alpha[None, :] * ln)
    dmu = (e1 - e2) / lam[:, None]
    dalpha = mu[None, :] * ln * (e1 - k * e2) / lam[:, None]
    return dmu @ mu, dmu, dalpha


def _yeoh(lam, c, test):
    if test == "uniaxial":
        i1, g = lam**2 + 2.0 / lam, 2.0 * (lam - lam**-2)
    else:
        i1, g = lam**2 + 1.0 + lam**-2, 2.0 * (lam - lam**-3)
    basis = np.stack([g, 2.0 * g * 2.0 * (i1 - 3.0) / 2.0], axis=1)  # dP/dC1, dP/dC2
    return basis @ c, basis


def silicone_data(table: Table, max_stretch=None):
    """Stretch [-] and nominal stress [Pa] of a tensile test, checked.

    Stretch from a ``stretch`` column or 1 + a strain column (``engineering_strain``,
    ``strain``); stress from ``engineering_stress``, ``nominal_stress`` or ``stress``.

    Raises
    ------
    InputError
        Missing columns, a non-positive or non-monotone stretch; the message names the file.
    """
    path = table.path
    if table.has("stretch"):
        _, lam = column(table, ["stretch"], "stretch", "dimensionless")
    else:
        _, strain = column(table, ["engineering_strain", "strain", "nominal_strain"],
                           "stretch or strain", "dimensionless")
        lam = 1.0 + strain
    _, stress = column(table, ["engineering_stress", "nominal_stress", "stress"],
                       "nominal stress", "pressure")
    if np.any(lam <= 0):
        i = int(np.argmax(lam <= 0))
        raise InputError(f"{path}: stretch must be > 0 (strain > -1); row {i + 1} has "
                         f"{lam[i]:g}")
    if np.any(np.diff(lam) <= 0):
        i = int(np.argmax(np.diff(lam) <= 0)) + 1
        raise InputError(f"{path}: stretch must increase row by row (one loading branch); "
                         f"row {i + 1} has {lam[i]:g} after {lam[i - 1]:g}")
    if max_stretch is not None:
        if not max_stretch > 1.0:
            raise InputError(f"--max-stretch: must be > 1, got {max_stretch:g}")
        keep = lam <= max_stretch
        lam, stress = lam[keep], stress[keep]
    return lam, stress


def _ogden_starts(n_terms, lam, stress, test, rng, per_pattern):
    """Starts over the sign patterns of alpha; mu from a sign-constrained linear fit."""
    from scipy.optimize import nnls

    for signs in itertools.combinations_with_replacement((1.0, -1.0), n_terms):
        signs = np.array(signs)
        mags = [np.array([2.0, 5.0, 0.5][:n_terms]), np.array([1.0, 8.0, 3.0][:n_terms])]
        mags += [np.exp(rng.uniform(np.log(0.3), np.log(20.0), n_terms))
                 for _ in range(per_pattern - 2)]
        for m in mags:
            alpha = signs * m
            _, dmu, _ = _ogden(lam, np.zeros(n_terms), alpha, test)
            c, _ = nnls(dmu * signs[None, :], stress)  # mu_i = s_i c_i, c_i >= 0
            mu = signs * np.maximum(c, 1e-6 * np.max(np.abs(stress)))
            yield np.concatenate([mu, alpha]), signs


def fit_silicone(data, model="ogden2", test="uniaxial", max_stretch=None, name="",
                 starts=6, seed=0) -> FitResult:
    """Fit an incompressible hyperelastic law to a tensile test.

    Parameters
    ----------
    data : str, Path or Table
        A data file (see :func:`nylonflex.calibration.read_table`) or a read table.
    model : str
        ``ogden1``, ``ogden2``, ``ogden3``, ``neo_hookean`` or ``yeoh2``.
    test : str
        ``uniaxial`` (tensile) or ``planar`` (pure shear).
    max_stretch : float, optional
        Fit only the points with stretch <= this [-], > 1.
    name : str
        Name of the fitted set.
    starts : int
        Starts per sign pattern of the Ogden exponents (>= 2).
    seed : int
        Seed of the random starts and of a bootstrap.

    Returns
    -------
    FitResult
        ``parameters`` ``{"mu": [Pa], "alpha": [-]}`` (Ogden forms; neo-Hookean alpha = 2)
        or ``{"c1": Pa, "c2": Pa}`` (Yeoh); ``derived["initial_shear_modulus"]`` [Pa].

    Raises
    ------
    InputError
        Bad data, too few points for the model, or a fit that does not converge.
    """
    _check_model(model, test)
    table = data if isinstance(data, Table) else read_table(data)
    path = table.path
    lam, stress = silicone_data(table, max_stretch)
    n_terms = MODELS[model]
    n_par = 2 if model == "yeoh2" else (1 if model == "neo_hookean" else 2 * n_terms)
    if lam.size < n_par + 2:
        raise InputError(f"{path}: {lam.size} points (stretch <= {max_stretch or 'any'}); "
                         f"{model} needs at least {n_par + 2}")
    scale = float(np.max(np.abs(stress))) or 1.0
    y = stress / scale
    rng = np.random.default_rng(seed)

    def _res(x):
        return _ogden(lam, x[:n_terms], x[n_terms:], test)[0] - y

    def _jac(x):
        _, dmu, dal = _ogden(lam, x[:n_terms], x[n_terms:], test)
        return np.hstack([dmu, dal])

    if model == "yeoh2":
        def res(x):
            return _yeoh(lam, x, test)[0] - y

        def jac(x):
            return _yeoh(lam, x, test)[1]
        sol = solve(res, jac, [np.array([0.1, 0.0]), np.array([1.0, 0.01])],
                    [0.0, -np.inf], [np.inf, np.inf], seed=seed)
    elif model == "neo_hookean":
        def res(x):
            return _ogden(lam, x, np.array([2.0]), test)[0] - y

        def jac(x):
            return _ogden(lam, x, np.array([2.0]), test)[1]
        sol = solve(res, jac, [np.array([0.1]), np.array([1.0])], [0.0], [np.inf], seed=seed)
    else:
        screened = []  # a short run from every start, then the best few run to the end
        for x0, signs in _ogden_starts(n_terms, lam, y, test, rng, max(starts, 2)):
            lo = np.concatenate([np.where(signs > 0, 0.0, -np.inf),
                                 np.where(signs > 0, _ALPHA_MIN, -_ALPHA_MAX)])
            hi = np.concatenate([np.where(signs > 0, np.inf, 0.0),
                                 np.where(signs > 0, _ALPHA_MAX, -_ALPHA_MIN)])
            cand = solve(_res, _jac, [x0], lo, hi, bootstrap=0, max_nfev=400)
            if cand is not None:
                screened.append((float(cand.residuals @ cand.residuals), cand.x, lo, hi))
        screened.sort(key=lambda c: c[0])
        sol = None
        for _, x0, lo, hi in screened[:4]:
            cand = solve(_res, _jac, [x0], lo, hi, seed=seed)
            if cand is not None and (sol is None or cand.residuals @ cand.residuals <
                                     sol.residuals @ sol.residuals):
                sol = cand
    if sol is None or not sol.converged or not np.all(np.isfinite(sol.x)):
        raise InputError(f"{path}: the {model} fit did not converge; try another --model "
                         "or --max-stretch")
    return _silicone_result(sol, model, test, lam, stress, scale, table, name, n_terms)


def _silicone_result(sol, model, test, lam, stress, scale, table, name, n_terms):
    x = sol.x.copy()
    unit_scale = np.ones_like(x)
    if model == "yeoh2":
        unit_scale[:] = scale
        order, units = ["c1", "c2"], {"c1": "Pa", "c2": "Pa"}
        mu0 = (lambda v: 2.0 * v[0] * scale, lambda v: np.array([2.0 * scale, 0.0]))
    elif model == "neo_hookean":
        unit_scale[:] = scale
        order, units = ["mu_1"], {"mu": "Pa", "alpha": "1"}
        mu0 = (lambda v: v[0] * scale, lambda v: np.array([scale]))
    else:
        unit_scale[:n_terms] = scale
        order = [f"mu_{i + 1}" for i in range(n_terms)] + \
            [f"alpha_{i + 1}" for i in range(n_terms)]
        units = {"mu": "Pa", "alpha": "1"}
        mu0 = (lambda v: 0.5 * scale * float(v[:n_terms] @ v[n_terms:]),
               lambda v: 0.5 * scale * np.concatenate([v[n_terms:], v[:n_terms]]))
    value = x * unit_scale
    se = sol.stderr * unit_scale
    ci = sol.ci95() * unit_scale[:, None]
    cov = sol.covariance * np.outer(unit_scale, unit_scale)
    g, g_se, g_ci = derived(sol, *mu0)
    if model == "yeoh2":
        params = {"c1": value[0], "c2": value[1]}
        stderr = {"c1": se[0], "c2": se[1]}
        ci95 = {"c1": list(ci[0]), "c2": list(ci[1])}
    elif model == "neo_hookean":
        params = {"mu": [value[0]], "alpha": [2.0]}
        stderr = {"mu": [se[0]], "alpha": [0.0]}
        ci95 = {"mu": [list(ci[0])], "alpha": [[2.0, 2.0]]}
    else:
        params = {"mu": list(value[:n_terms]), "alpha": list(value[n_terms:])}
        stderr = {"mu": list(se[:n_terms]), "alpha": list(se[n_terms:])}
        ci95 = {"mu": [list(c) for c in ci[:n_terms]], "alpha": [list(c) for c in ci[n_terms:]]}
    y_fit = nominal_stress(lam, model, params, test)
    rmse, r2 = statistics(stress, y_fit)
    if not r2 >= MIN_R2:
        raise InputError(f"{table.path}: the {model} fit did not converge to a usable "
                         f"solution (R^2 = {r2:.3g} < {MIN_R2}); is this a loading curve?")
    notes = []
    if sol.method == "bootstrap":
        notes.append("a parameter sits on its bound (a vanishing or extreme Ogden term): "
                     "intervals from a residual bootstrap; consider fewer terms")
    return FitResult(
        kind="silicone", model=model, test=test, name=name, parameters=params,
        stderr=stderr, ci95=ci95, parameter_order=order, covariance=cov,
        derived={"initial_shear_modulus": {"value": g, "stderr": g_se, "ci95": list(g_ci)}},
        rmse=rmse, r2=r2, fitted_range={"stretch": [float(lam[0]), float(lam[-1])]},
        data={"path": table.path, "sha256": table.sha256}, x_name="stretch",
        y_name="nominal_stress", x=lam, y=stress, y_fit=y_fit, uncertainty=sol.method,
        units={**units, "initial_shear_modulus": "Pa", "rmse": "Pa"}, notes=notes)
