"""Slow, obviously right references for the fast solvers (as numbagg's and stumpy's
tests/naive.py).

Adaptive scipy quadrature of docs/model.md section 6's double integral exactly as written (no
change of variables), bracketing root finders, and nothing shared with nylonflex's solvers
but the material constants and the closed-form stress of docs/model.md section 5. The
benchmarks time :func:`stroke_limit` and :func:`curvature` (benchmarks/suite.py);
:func:`random_designs` draws designs over the registry's accepted ranges.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import dblquad, quad
from scipy.optimize import brentq

P_ATM = 101325.0
EPSREL = 1e-12


def stress(lam, mu, alpha):
    """Plane-strain nominal Ogden stress S = sum mu (l^(a-1) - l^(-a-1)) [Pa]."""
    return sum(m * (lam ** (a - 1.0) - lam ** (-a - 1.0)) for m, a in zip(mu, alpha))


def material_moment(kappa, a, t, b, mu, alpha):
    """M_S(kappa) by scipy quad (base) and dblquad (wall) at epsrel 1e-12 [N m]."""
    base, _ = quad(lambda y: stress(1 + kappa * y, mu, alpha) * y, 0.0, b,
                   epsabs=0.0, epsrel=EPSREL, limit=200)

    def wall(r, phi):
        y = b + r * math.sin(phi)
        return stress(1 + kappa * y, mu, alpha) * y * r

    ann, _ = dblquad(wall, 0.0, math.pi, a, a + t, epsabs=0.0, epsrel=EPSREL)
    return 2 * (a + t) * base + ann


def pressure_moment(p, a, b):
    """M_P = p (4a^3 + 3 pi a^2 b)/6 [N m]."""
    return p * (4 * a**3 + 3 * math.pi * a**2 * b) / 6


def curvature(p, a, t, b, mu, alpha, near=None):
    """kappa solving M_S = M_P by brentq on the adaptive moment [1/m].

    ``near`` narrows the bracket to +-1e-6 relative around a candidate; the sign change that
    brentq demands is still checked on the adaptive moment, so a wrong candidate fails.
    """
    target = pressure_moment(p, a, b)
    if target == 0.0:
        return 0.0
    f = lambda k: material_moment(k, a, t, b, mu, alpha) - target  # noqa: E731
    if near is not None:
        lo, hi = near * (1 - 1e-6), near * (1 + 1e-6)
    else:
        lo, hi = 0.0, 1.0
        while f(hi) < 0:
            lo, hi = hi, 2 * hi
    return brentq(f, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)


def gauge_pressure(s):
    """Boyle's gauge pressure of the chamber shrunk by (1 - s) both ways (eqs. 7-8) [Pa]."""
    return P_ATM * ((1 - s) ** -2 - 1)


def nylon_force(s, a, t, b, psi, c, mu, alpha, fibre_diameter):
    """F_n(s) of docs/model.md section 4, written out [N]."""
    p = gauge_pressure(s)
    s_theta = stress(1 - s, mu, alpha)
    p_out = math.pi * (a + t) + 2 * (a + t) + 2 * b
    pitch = max(p_out * math.tan(psi), fibre_diameter * (c + 1) / math.cos(psi))
    return (p * a + abs(s_theta) * t) * pitch / math.cos(psi)


def stroke_limit(force_limit, s_max, a, t, b, psi, c, mu, alpha, fibre_diameter):
    """s* = min(s_max, s_lim) by brentq [-]."""
    f = lambda s: nylon_force(s, a, t, b, psi, c, mu, alpha, fibre_diameter) - force_limit  # noqa
    if f(s_max) <= 0:
        return s_max
    return brentq(f, 0.0, s_max, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)


def table_value(c, xs, ys):
    """The coil-index table's column ``ys`` at C by linear interpolation between rows."""
    rows = list(zip(xs, ys))
    for (x0, y0), (x1, y1) in zip(rows, rows[1:]):
        if x0 <= c <= x1:
            return y0 + (y1 - y0) * (c - x0) / (x1 - x0)
    raise ValueError(f"coil index {c} outside the table {xs}")


def force_limit(c, xs, strengths, fibre_diameter):
    """Breaking force sigma_u(C) pi d_f^2 / 4 [N]."""
    return table_value(c, xs, strengths) * math.pi * fibre_diameter**2 / 4


def random_designs(n: int, seed: int = 2026) -> dict:
    """``n`` designs drawn over the whole accepted range of each axis (log-uniform lengths).

    Radius, wall and length log-uniform over the registry's ranges, coil index uniform over
    the default table, wrap angle uniform over its range; SI.
    """
    from nylonflex.variables import COORDS

    rng = np.random.default_rng(seed)
    log_uniform = lambda v: np.exp(rng.uniform(np.log(v.lo), np.log(v.hi), n))  # noqa: E731
    return {"radius": log_uniform(COORDS["radius"]),
            "wall_thickness": log_uniform(COORDS["wall_thickness"]),
            "length": log_uniform(COORDS["length"]),
            "coil_index": rng.uniform(1.1, 1.7, n),
            "wrap_angle": rng.uniform(COORDS["wrap_angle"].lo, COORDS["wrap_angle"].hi, n)}
