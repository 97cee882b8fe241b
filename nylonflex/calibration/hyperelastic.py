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
from scipy.optimize import nnls

from ..materials import WALL_STRETCH_RANGE
from ..units import InputError
from ._lsq import derived, solve, solve_ar1
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
#: An Ogden term whose stress stays below this fraction of the largest stress has collapsed.
COLLAPSE = 1e-3
#: A fit that reaches this many times the designs' top stretch is warned about.
FAR_BEYOND = 1.5


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


def _window(max_stretch):
    """(top stretch or None for the whole curve, how it was chosen) of ``max_stretch``."""
    if max_stretch is None or (isinstance(max_stretch, str) and max_stretch == "all"):
        return None, "all"
    if isinstance(max_stretch, str) and max_stretch == "design":
        return float(WALL_STRETCH_RANGE[1]), "design"
    if isinstance(max_stretch, str):
        try:
            max_stretch = float(max_stretch)
        except ValueError:
            raise InputError(f"--max-stretch: a stretch > 1, 'design' or 'all'; got "
                             f"{max_stretch!r}") from None
    return float(max_stretch), "given"


def _collapsed(x, n_terms, lam, y, test):
    """Indices of Ogden terms that carry (almost) nothing of the stress over the data.

    A term collapses when its largest |mu_i (l^a_i - l^(k a_i))/l| over the fitted
    stretches is below :data:`COLLAPSE` of the largest |stress|: the fit drove it to zero
    (mu_i on its bound) and its exponent, then its interval, is undetermined.
    """
    mu, alpha = x[:n_terms], x[n_terms:]
    _, dmu, _ = _ogden(lam, mu, alpha, test)
    share = np.max(np.abs(dmu * mu[None, :]), axis=0) / max(float(np.max(np.abs(y))), 1e-300)
    return [i for i in range(n_terms) if share[i] < COLLAPSE]


def _bic(ssr, n, p):
    """Bayesian information criterion of a least-squares fit, n ln(SSR/n) + p ln n."""
    return n * np.log(max(ssr, 1e-300) / n) + p * np.log(n)


def fit_silicone(data, model="ogden2", test="uniaxial", max_stretch="design", name="",
                 starts=6, seed=0) -> FitResult:
    """Fit an incompressible hyperelastic law to a tensile test.

    Parameters
    ----------
    data : str, Path or Table
        A data file (see :func:`nylonflex.calibration.read_table`) or a read table.
    model : str
        ``ogden1``, ``ogden2``, ``ogden3``, ``neo_hookean`` or ``yeoh2``. An Ogden term that
        collapses (carries less than :data:`COLLAPSE` of the stress) is dropped, and the
        form with one term fewer is reported when it fits as well by the BIC; the result's
        ``model`` and ``notes`` say so.
    test : str
        ``uniaxial`` (tensile) or ``planar`` (pure shear).
    max_stretch : float, "design" or "all"
        Fit only the points with stretch <= this [-], > 1. ``"design"`` (the default): the
        stretch the actuators' walls reach, :data:`nylonflex.materials.WALL_STRETCH_RANGE`;
        ``"all"`` (or None): the whole curve.
    name : str
        Name of the fitted set.
    starts : int
        Starts per sign pattern of the Ogden exponents (>= 2).
    seed : int
        Seed of the random starts.

    Returns
    -------
    FitResult
        ``parameters`` ``{"mu": [Pa], "alpha": [-]}`` (Ogden forms; neo-Hookean alpha = 2)
        or ``{"c1": Pa, "c2": Pa}`` (Yeoh); ``derived["initial_shear_modulus"]`` [Pa]. The
        estimate and intervals allow for residuals correlated along the pull (an AR(1)
        residual model, :func:`nylonflex.calibration._lsq.solve_ar1`).

    Raises
    ------
    InputError
        Bad data, too few points for the model, or a fit that does not converge.
    """
    _check_model(model, test)
    table = data if isinstance(data, Table) else read_table(data)
    top, how = _window(max_stretch)
    lam_all, _ = silicone_data(table, None)
    lam, stress = silicone_data(table, top)
    notes = _window_notes(lam_all, lam, top, how)
    res = _fit_form(table, lam, stress, model, test, top, starts, seed)
    res.notes[:0] = notes
    return _named(res, name)


def _window_notes(lam_all, lam, top, how):
    design = float(WALL_STRETCH_RANGE[1])
    notes = []
    if how == "design" and lam_all[-1] > top:
        notes.append(f"fitted stretch <= {top:g}, the window the designs use "
                     f"(docs/model.md s. 5); {lam_all.size - lam.size} of {lam_all.size} "
                     f"points beyond it left out (the data reaches {lam_all[-1]:.3g}); "
                     "--max-stretch all fits the whole curve")
    if lam[-1] > FAR_BEYOND * design:
        notes.append(f"the fit reaches stretch {lam[-1]:.3g}, far beyond the designs' "
                     f"{design:g}: its small-strain stiffness is set by stretches no wall "
                     "reaches; --max-stretch design fits the designs' window")
    return notes


def _named(res, name):
    res.name = name
    return res


def _fit_form(table, lam, stress, model, test, top, starts, seed):
    """One form fitted (the ordinary least-squares optimum from many starts, then AR(1))."""
    path = table.path
    n_terms = MODELS[model]
    n_par = 2 if model == "yeoh2" else (1 if model == "neo_hookean" else 2 * n_terms)
    if lam.size < n_par + 2:
        raise InputError(f"{path}: {lam.size} points (stretch <= {top or 'any'}); "
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
        lo, hi = np.array([0.0, -np.inf]), np.array([np.inf, np.inf])
        sol = solve(res, jac, [np.array([0.1, 0.0]), np.array([1.0, 0.01])], lo, hi,
                    bootstrap=0)
    elif model == "neo_hookean":
        def res(x):
            return _ogden(lam, x, np.array([2.0]), test)[0] - y

        def jac(x):
            return _ogden(lam, x, np.array([2.0]), test)[1]
        lo, hi = np.array([0.0]), np.array([np.inf])
        sol = solve(res, jac, [np.array([0.1]), np.array([1.0])], lo, hi, bootstrap=0)
    else:
        res, jac = _res, _jac
        screened = []  # a short run from every start, then the best few run to the end
        for x0, signs in _ogden_starts(n_terms, lam, y, test, rng, max(starts, 2)):
            lo_s = np.concatenate([np.where(signs > 0, 0.0, -np.inf),
                                   np.where(signs > 0, _ALPHA_MIN, -_ALPHA_MAX)])
            hi_s = np.concatenate([np.where(signs > 0, np.inf, 0.0),
                                   np.where(signs > 0, _ALPHA_MAX, -_ALPHA_MIN)])
            cand = solve(_res, _jac, [x0], lo_s, hi_s, bootstrap=0, max_nfev=400)
            if cand is not None:
                screened.append((float(cand.residuals @ cand.residuals), cand.x, lo_s, hi_s))
        screened.sort(key=lambda c: c[0])
        sol, lo, hi = None, None, None
        for _, x0, lo_s, hi_s in screened[:4]:
            cand = solve(_res, _jac, [x0], lo_s, hi_s, bootstrap=0)
            if cand is not None and (sol is None or cand.residuals @ cand.residuals <
                                     sol.residuals @ sol.residuals):
                sol, lo, hi = cand, lo_s, hi_s
    if sol is None or not sol.converged or not np.all(np.isfinite(sol.x)):
        raise InputError(f"{path}: the {model} fit did not converge; try another --model "
                         "or --max-stretch")
    if n_terms and n_terms > 1 and model.startswith("ogden"):
        fewer = _fewer_terms(table, lam, stress, model, test, top, starts, seed, sol, y)
        if fewer is not None:
            return fewer
    ar1 = solve_ar1(res, jac, sol.x, lo, hi)
    if ar1 is None or not np.all(np.isfinite(ar1.x)):
        raise InputError(f"{path}: the {model} fit did not converge; try another --model "
                         "or --max-stretch")
    return _silicone_result(ar1, model, test, lam, stress, scale, table, "", n_terms)


def _fewer_terms(table, lam, stress, model, test, top, starts, seed, sol, y):
    """The fit with fewer Ogden terms when terms collapsed or it fits as well (BIC)."""
    n_terms = MODELS[model]
    gone = _collapsed(sol.x, n_terms, lam, y, test)
    k = max(len(gone), 1)
    if k >= n_terms:
        return None
    fewer_model = f"ogden{n_terms - k}"
    try:
        fewer = _fit_form(table, lam, stress, fewer_model, test, top, starts, seed)
    except InputError:
        return None
    n = lam.size
    bic_n = _bic(float(sol.residuals @ sol.residuals) * (np.max(np.abs(stress))) ** 2, n,
                 2 * n_terms)
    bic_f = _bic(float(fewer.residuals @ fewer.residuals), n, 2 * (n_terms - k))
    mu = sol.x[:n_terms] * float(np.max(np.abs(stress)))
    if gone:
        terms = ", ".join(f"term {i + 1} (mu = {mu[i]:.3g} Pa, alpha = "
                          f"{sol.x[n_terms + i]:.3g})" for i in gone)
        why = (f"{model}: {terms} collapsed (carries < {100 * COLLAPSE:g} % of the stress, "
               f"its interval undetermined): dropped, reported as {fewer.model}")
    elif bic_f <= bic_n:
        why = (f"{model} fits no better than {fewer_model} by the BIC ({bic_n:.1f} against "
               f"{bic_f:.1f}): reported as {fewer.model}")
    else:
        return None
    fewer.notes.insert(0, why)
    return fewer


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
    g_ci = (max(g_ci[0], 0.0), g_ci[1])  # mu_0 > 0: a stable silicone
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
    if sol.method == "ar1":
        # issue 46: [0, 48 kPa] beside R^2 0.997 read as a failed fit; say what each means
        # the effective number of independent points of n AR(1) errors (of their mean)
        k = np.arange(1, len(lam))
        n_eff = len(lam) / (1.0 + 2.0 * np.sum((1.0 - k / len(lam)) * sol.rho ** k))
        notes.append(f"intervals allow for residuals correlated along the pull: AR(1) "
                     f"lag-1 correlation {sol.rho:.3g} (likely {sol.rho_set[0]:.3g}-"
                     f"{sol.rho_set[1]:.3g}; the widest interval over that range); R^2 "
                     f"{r2:.4g} says the curve is fitted well, the intervals say how far a "
                     f"second specimen's parameters may lie: the residuals are one smooth "
                     f"misfit, so the {len(lam)} points weigh like about {n_eff:.2g} "
                     f"independent ones; an interval ending at 0 is cut at the bound "
                     f"(mu_i alpha_i >= 0); more specimens narrow them "
                     f"(docs/calibration.md)")
    return FitResult(
        kind="silicone", model=model, test=test, name=name, parameters=params,
        stderr=stderr, ci95=ci95, parameter_order=order, covariance=cov,
        derived={"initial_shear_modulus": {"value": g, "stderr": g_se, "ci95": list(g_ci)}},
        rmse=rmse, r2=r2, fitted_range={"stretch": [float(lam[0]), float(lam[-1])]},
        data={"path": table.path, "sha256": table.sha256}, x_name="stretch",
        y_name="nominal_stress", x=lam, y=stress, y_fit=y_fit, uncertainty=sol.method,
        units={**units, "initial_shear_modulus": "Pa", "rmse": "Pa"}, notes=notes)
