"""Least squares with several starts, and the uncertainty of its result.

The covariance of the parameters is s^2 (J^T J)^-1 at the optimum (s^2 = SSR/(n - p)), the
Gauss-Newton approximation that is right for independent, equal-variance errors and a
solution inside the bounds. Where it is not (a parameter on a bound, a singular J^T J), the
caller gets a residual bootstrap instead. Intervals are Student-t with n - p degrees of
freedom; a derived quantity g(theta) gets the delta method, g'^T C g'.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

__all__ = ["Solution", "solve", "derived"]


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
    if sol.samples is not None:
        vals = np.array([value(s) for s in sol.samples])
        lo, hi = np.percentile(vals, [2.5, 97.5])
        return g, float(np.std(vals, ddof=1)) if len(vals) > 1 else float("nan"), \
            (float(lo), float(hi))
    d = np.asarray(gradient(sol.x), float)
    se = float(np.sqrt(max(d @ sol.covariance @ d, 0.0)))
    return g, se, (g - sol.t95 * se, g + sol.t95 * se)
