"""Least squares with several starts, and the uncertainty of its result.

The covariance of the parameters is s^2 (J^T J)^-1 at the optimum (s^2 = SSR/(n - p)), the
Gauss-Newton approximation that is right for independent, equal-variance errors and a
solution inside the bounds. Where it is not (a parameter on a bound, a singular J^T J), the
caller gets a residual bootstrap instead. Intervals are Student-t with n - p degrees of
freedom; a derived quantity g(theta) gets the delta method, g'^T C g'. A tensile pull, whose
residuals are correlated along the pull, gets :func:`solve_ar1` instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

__all__ = ["AR1Solution", "Solution", "derived", "solve", "solve_ar1"]


@dataclass
class Solution:
    """Best least-squares solution and its uncertainty (internal)."""

    x: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    dof: int
    method: str  # "jacobian" or "bootstrap"
    converged: bool
    samples: np.ndarray | None = None  # bootstrap parameter draws

    @property
    def stderr(self) -> np.ndarray:
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    @property
    def t95(self) -> float:
        return float(stats.t.ppf(0.975, max(self.dof, 1)))

    def ci95(self) -> np.ndarray:
        """(p, 2) array of 95 % intervals."""
        if self.samples is not None:
            return np.percentile(self.samples, [2.5, 97.5], axis=0).T
        se = self.stderr
        return np.stack([self.x - self.t95 * se, self.x + self.t95 * se], axis=1)


def _cov(jac, residuals, dof):
    s2 = float(residuals @ residuals) / max(dof, 1)
    jtj = jac.T @ jac
    if not np.all(np.isfinite(jtj)) or np.linalg.cond(jtj) > 1e14:
        return None
    return s2 * np.linalg.inv(jtj)


def solve(residual, jacobian, starts, lower, upper, *, bootstrap=100, seed=0,
          max_nfev=2000):
    """Minimise ``sum residual(x)^2`` from several starts, with bounds.

    Parameters
    ----------
    residual : callable
        ``x -> r`` (model minus data), in units of the data.
    jacobian : callable
        ``x -> dr/dx`` (n, p).
    starts : iterable of array
        Starting points, inside the bounds.
    lower, upper : array
        Bounds of each parameter.
    bootstrap : int
        Residual-bootstrap draws when the Jacobian covariance does not hold.
    max_nfev : int
        Evaluations allowed a start.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    Solution or None
        None when no start converged to a finite solution.
    """
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    best = None
    for x0 in starts:
        x0 = np.clip(np.asarray(x0, float), lower, upper)
        try:
            r = optimize.least_squares(residual, x0, jac=jacobian, bounds=(lower, upper),
                                       method="trf", x_scale="jac", max_nfev=max_nfev)
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            continue
        if not (np.all(np.isfinite(r.x)) and np.isfinite(r.cost)):
            continue
        if best is None or r.cost < best.cost:
            best = r
    if best is None:
        return None
    res = best.fun
    n, p = res.size, best.x.size
    dof = n - p
    jac = np.asarray(jacobian(best.x), float)
    span = upper - lower
    on_bound = np.any(np.isfinite(span) & ((np.abs(best.x - lower) < 1e-9 * (1 + np.abs(lower)))
                                           | (np.abs(upper - best.x) < 1e-9 *
                                              (1 + np.abs(upper)))))
    cov = None if on_bound else _cov(jac, res, dof)
    if cov is not None:
        return Solution(best.x, cov, res, dof, "jacobian", best.status > 0)
    # residual bootstrap around the optimum
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(bootstrap):
        # new data = model(x_best) + resampled error, so residual'(x) = residual(x) + shift
        shift = rng.choice(res, size=n, replace=True) - res

        def r2(x, shift=shift):
            return residual(x) + shift
        try:
            rb = optimize.least_squares(r2, best.x, jac=jacobian, bounds=(lower, upper),
                                        method="trf", x_scale="jac", max_nfev=100)
        except (ValueError, FloatingPointError):
            continue
        if np.all(np.isfinite(rb.x)):
            draws.append(rb.x)
    draws = np.asarray(draws) if draws else np.full((1, p), np.nan)
    cov = np.atleast_2d(np.cov(draws, rowvar=False)) if len(draws) > 1 else np.full((p, p),
                                                                                    np.nan)
    return Solution(best.x, cov, res, dof, "bootstrap", best.status > 0, samples=draws)


def derived(sol: Solution, value, gradient):
    """A derived quantity g(x): (value, standard error, 95 % interval).

    ``value(x)`` and ``gradient(x)``; the delta method for a Jacobian covariance, the
    bootstrap draws' percentiles otherwise.
    """
    g = float(value(sol.x))
    if getattr(sol, "profile", None):  # AR(1): the largest over the profile set of rho
        d = np.asarray(gradient(sol.x), float)
        se = float(np.sqrt(max(max(d @ c @ d for _, c in sol.profile), 0.0)))
        return g, se, (g - sol.t95 * se, g + sol.t95 * se)
    if sol.samples is not None:
        vals = np.array([value(s) for s in sol.samples])
        lo, hi = np.percentile(vals, [2.5, 97.5])
        return g, float(np.std(vals, ddof=1)) if len(vals) > 1 else float("nan"), \
            (float(lo), float(hi))
    d = np.asarray(gradient(sol.x), float)
    se = float(np.sqrt(max(d @ sol.covariance @ d, 0.0)))
    return g, se, (g - sol.t95 * se, g + sol.t95 * se)


#: Lag-1 correlations the AR(1) residual model is profiled over: 0 (independent errors) to
#: 0.999, denser towards 1 where a dense pull's residuals sit.
RHO_GRID = np.concatenate([np.linspace(0.0, 0.9, 10), 1.0 - np.geomspace(0.1, 1e-3, 12)[1:]])
#: Drop of the restricted log-likelihood that bounds the set of rho the intervals are the
#: widest over: 1/2, the one-sigma set (chi^2_1 = 1). The 95 % set (1.92) gave 199 of 200
#: intervals covering mu_0 on simulated pulls (rho = 0.99, 43 points), wider than asked; the
#: one-sigma set gave 148 of 160 (92.5 %), docs/calibration.md.
PROFILE_DROP = 0.5


def _whiten(v, rho):
    """Prais-Winsten transform of residuals (n,) or a Jacobian (n, p) for AR(1) errors."""
    out = np.array(v, dtype=float, copy=True)
    out[1:] = v[1:] - rho * v[:-1]
    out[0] = np.sqrt(1.0 - rho * rho) * v[0]
    return out


@dataclass
class AR1Solution(Solution):
    """A least-squares solution with intervals under AR(1) errors (internal).

    ``x`` is the ordinary least-squares estimate; ``profile`` holds ``(rho, covariance)``
    for every rho of its profile set, the covariance of ``x`` under AR(1) errors with that
    rho; the standard errors are the largest over that set.
    """

    rho: float = 0.0
    rho_set: tuple = (0.0, 0.0)
    profile: list | None = None
    bounds: tuple | None = None  # (lower, upper): the intervals are cut to them

    @property
    def stderr(self) -> np.ndarray:
        var = np.max([np.clip(np.diag(c), 0.0, None) for _, c in self.profile], axis=0)
        return np.sqrt(var)

    def ci95(self) -> np.ndarray:
        se = self.stderr
        lo, hi = self.x - self.t95 * se, self.x + self.t95 * se
        if self.bounds is not None:  # the estimate is inside its bounds, so still inside
            lo, hi = np.maximum(lo, self.bounds[0]), np.minimum(hi, self.bounds[1])
        return np.stack([lo, hi], axis=1)


def solve_ar1(residual, jacobian, x0, lower, upper, *, max_nfev=2000):
    """Intervals of a least-squares optimum whose residuals are correlated in order.

    A dense tensile pull's residuals are strongly correlated (lag-1 correlation near 1), so
    s^2 (J^T J)^-1 understates the uncertainty many times over. The errors are modelled as
    AR(1), e_i = rho e_(i-1) + w_i with w white. For each rho of :data:`RHO_GRID` the model is
    fitted by generalised least squares (Prais-Winsten whitening, warm-started from the
    previous rho), which gives the restricted (REML) likelihood of rho and the innovation
    variance s_w^2; the covariance of the ordinary estimate ``x0`` is then the sandwich
    A J^T Sigma J A, A = (J^T J)^-1, Sigma_ij = s_w^2 rho^|i-j| / (1 - rho^2). The standard
    errors are the largest over the set of rho within :data:`PROFILE_DROP` of the best
    restricted likelihood, which allows for the uncertainty of rho itself (REML is biased
    towards 0 on short series). Intervals are estimate +- t_(n-p) se, so they always contain
    their estimate; a parameter's interval is cut to its bounds (mu_i alpha_i >= 0,
    0.05 <= |alpha_i| <= 40), which the estimate also keeps.

    Parameters
    ----------
    residual, jacobian : callable
        ``x -> model - data`` (n,) and its derivative (n, p), the data in time order.
    x0 : array
        The ordinary least-squares optimum, inside the bounds.
    lower, upper : array
        Bounds.
    max_nfev : int
        Evaluations allowed each rho's solve.

    Returns
    -------
    AR1Solution or None
        None when no rho gives a finite solution.
    """
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    x_ols = np.clip(np.asarray(x0, float), lower, upper)
    res = np.asarray(residual(x_ols), float)
    jac = np.asarray(jacobian(x_ols), float)
    n, p = jac.shape
    a = np.linalg.pinv(jac.T @ jac)
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    x, fits = x_ols, []
    for rho in RHO_GRID:
        try:
            r = optimize.least_squares(lambda v, rho=rho: _whiten(residual(v), rho), x,
                                       jac=lambda v, rho=rho: _whiten(jacobian(v), rho),
                                       bounds=(lower, upper), method="trf", x_scale="jac",
                                       max_nfev=max_nfev)
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            continue
        if not (np.all(np.isfinite(r.x)) and np.isfinite(r.cost)):
            continue
        x = r.x
        ssr = float(r.fun @ r.fun)
        jw = np.asarray(r.jac, float)
        sign, logdet = np.linalg.slogdet(jw.T @ jw)
        if not ssr > 0 or sign <= 0:
            continue
        reml = (-0.5 * (n - p) * np.log(ssr / (n - p)) + 0.5 * np.log(1.0 - rho * rho)
                - 0.5 * logdet)
        sigma = ssr / (n - p) / (1.0 - rho * rho) * rho ** lag
        fits.append((reml, float(rho), a @ jac.T @ sigma @ jac @ a))
    if not fits:
        return None
    best = max(fits, key=lambda f: f[0])
    keep = [f for f in fits if f[0] >= best[0] - PROFILE_DROP]
    return AR1Solution(x_ols, keep[-1][2], res, n - p, "ar1", True, rho=best[1],
                       rho_set=(keep[0][1], keep[-1][1]), profile=[(f[1], f[2]) for f in keep],
                       bounds=(lower, upper))
