"""Bending of the actuator: moments, curvature, angle and tip force.

docs/model.md sections 6-7, after Polygerinos et al. (IEEE T-RO 31(3):778, 2015). Constant
curvature kappa = theta / L; a fibre at height y above the inextensible bottom face is
stretched to l(y) = 1 + kappa y. The angle solves M_P(p) = M_S(kappa).

The material moment [choice: nominal stress on the undeformed section]::

    M_S(kappa) = 2 (a + t) int_0^b S(1 + kappa y) y dy
               + int_0^pi int_a^(a+t) S(1 + kappa y) y r dr dphi,   y = b + r sin(phi)

is evaluated with Gauss-Legendre quadrature. The half-annulus term is the difference of
two half discs, and a half disc of radius R is, with h = R sin(phi),
``int_0^(pi/2) g(b + R sin phi) 2 R^2 cos^2 phi dphi`` with g(y) = S(1 + kappa y) y: a smooth
one-dimensional integrand, so a few dozen nodes reach 1e-13 (checked against adaptive
quadrature of the original double integral in the tests).
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import silicone_parameters
from ._formula import check, check_section, formula, scalar_or_array
from .silicone import _stress_and_slope

__all__ = [
    "QUADRATURE_ORDERS",
    "bend_angle",
    "curvature",
    "material_moment",
    "pressure_moment",
    "quadrature_nodes",
    "tip_force",
]

#: Gauss-Legendre orders of the material moment: ``phi`` for each half disc, ``base`` for
#: the bottom layer. The cheapest orders that keep kappa(p) within 1e-9 / 10 of adaptive
#: quadrature over the design range (radius 5-25 mm, wall 1-6 mm, pressure 0-60 kPa, every
#: set) AND within 1e-12 of the previous orders (24, 12): measured 2.4e-13 against the
#: adaptive reference, 1.6e-14 against (24, 12) (docs/model.md s. 12).
QUADRATURE_ORDERS = {"phi": 24, "base": 7}

#: Relative Newton step below which the curvature counts as converged [-]. The error
#: after that step is of the order of its square.
NEWTON_RTOL = 1e-9


def quadrature_nodes(orders=None):
    """The material moment's quadrature: ``(x_base, w_base, phi_trig, w_phi)``.

    ``x_base``, ``w_base``: Gauss-Legendre nodes and weights on [-1, 1] of the base layer;
    ``w_phi``: the weights of each half disc, whose nodes phi_i = pi/4 (x_i + 1) on
    [0, pi/2] enter only through cos and sin: ``phi_trig`` holds them, shape (2, n), so that
    no evaluation computes a trigonometric function (computed here once with ``math``, the
    same functions and so the same bits as the kernels would get).
    """
    orders = QUADRATURE_ORDERS if orders is None else orders
    key = (int(orders["base"]), int(orders["phi"]))
    if key not in _NODES:
        xb, wb = np.polynomial.legendre.leggauss(key[0])
        xp, wp = np.polynomial.legendre.leggauss(key[1])
        half = 0.25 * math.pi
        trig = np.array([[math.cos(half * (x + 1.0)) for x in xp],
                         [math.sin(half * (x + 1.0)) for x in xp]])
        for arr in (xb, wb, trig, wp):
            arr.flags.writeable = False
        _NODES[key] = (xb, wb, trig, wp)
    return _NODES[key]


_NODES: dict = {}


@formula
def _pressure_moment(pressure, radius, base_thickness):
    """M_P = p (4 a^3 + 3 pi a^2 b) / 6 [N m] (eq. 16, closed form of eq. 14)."""
    a = radius
    return pressure * (4.0 * a * a * a + 3.0 * math.pi * a * a * base_thickness) / 6.0


@formula
def _section_stress(stretch, mu, alpha, cauchy):
    """Stress of the moment integral and its slope [Pa]: nominal S(l), or Cauchy l S(l)."""
    s, ds = _stress_and_slope(stretch, mu, alpha)
    if cauchy:
        return stretch * s, s + stretch * ds
    return s, ds


@formula
def _section_nodes(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi,
                   y, wy, wyy):
    """Fill the section's node table: heights ``y`` [m] and weights ``wy`` [m^3], ``wyy``.

    One table for the whole section (base layer, outer half disc, inner half disc with
    negative weights), so that M_S(kappa) = sum wy S(1 + kappa y) and dM_S/dkappa =
    sum wyy S'(1 + kappa y): the nodes depend on (a, t, b) only, not on kappa, and are
    computed once per section instead of at every Newton step (docs/model.md s. 12).
    ``y``, ``wy``, ``wyy`` have ``x_base.size + 2 w_phi.size`` entries.
    """
    half = 0.5 * base_thickness
    width = 2.0 * (radius + wall_thickness)
    nb = x_base.shape[0]
    nphi = w_phi.shape[0]
    for i in range(nb):
        yi = half * (x_base[i] + 1.0)
        y[i] = yi
        wy[i] = w_base[i] * half * width * yi
        wyy[i] = wy[i] * yi
    quarter = 0.25 * math.pi  # phi in [0, pi/2]
    for j in range(2):
        outer = radius + wall_thickness if j == 0 else radius
        sign = 1.0 if j == 0 else -1.0
        r2 = 2.0 * outer * outer
        for i in range(nphi):
            c = phi_trig[0, i]
            yi = base_thickness + outer * phi_trig[1, i]
            k = nb + j * nphi + i
            y[k] = yi
            wy[k] = sign * (w_phi[i] * quarter * r2 * c * c * yi)
            wyy[k] = wy[k] * yi


@formula
def _section_moment(kappa, y, wy, wyy, mu, alpha, cauchy):
    """M_S(kappa) [N m] and dM_S/dkappa [N m^2] from a :func:`_section_nodes` table.

    One flat loop over every node of the section (one log and one exp a term a node), no
    trigonometry and no per-node weight arithmetic: those live in the table.
    """
    n = y.shape[0]
    m = 0.0
    dm = 0.0
    for i in range(n):
        s, ds = _section_stress(1.0 + kappa * y[i], mu, alpha, cauchy)
        m += wy[i] * s
        dm += wyy[i] * ds
    return m, dm


@formula
def _node_table(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi):
    """A new :func:`_section_nodes` table ``(y, wy, wyy)`` of a section."""
    n = x_base.shape[0] + 2 * w_phi.shape[0]
    y = np.empty(n)
    wy = np.empty(n)
    wyy = np.empty(n)
    _section_nodes(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi,
                   y, wy, wyy)
    return y, wy, wyy


@formula
def _material_moment(kappa, radius, wall_thickness, base_thickness, mu, alpha,
                     x_base, w_base, phi_trig, w_phi):
    """M_S(kappa) [N m] and dM_S/dkappa [N m^2] (docs/model.md section 6)."""
    return _material_moment_of(kappa, radius, wall_thickness, base_thickness, mu, alpha,
                               x_base, w_base, phi_trig, w_phi, False)


@formula
def _material_moment_of(kappa, radius, wall_thickness, base_thickness, mu, alpha,
                        x_base, w_base, phi_trig, w_phi, cauchy):
    """:func:`_material_moment` with nominal or (``cauchy``) Cauchy stress (docs/model.md s. 16)."""
    y, wy, wyy = _node_table(radius, wall_thickness, base_thickness, x_base, w_base,
                             phi_trig, w_phi)
    return _section_moment(kappa, y, wy, wyy, mu, alpha, cauchy)


@formula
def _curvature(moment, radius, wall_thickness, base_thickness, mu, alpha,
               x_base, w_base, phi_trig, w_phi, guess, rtol):
    """Solve M_S(kappa) = moment for kappa >= 0 [1/m] (nominal stress; :func:`_curvature_of`)."""
    return _curvature_of(moment, radius, wall_thickness, base_thickness, mu, alpha,
                         x_base, w_base, phi_trig, w_phi, guess, rtol, False)


@formula
def _curvature_of(moment, radius, wall_thickness, base_thickness, mu, alpha,
                  x_base, w_base, phi_trig, w_phi, guess, rtol, cauchy):
    """Solve M_S(kappa) = moment for kappa >= 0 [1/m] by safeguarded Newton.

    ``cauchy`` integrates the Cauchy stress l S(l) instead of the nominal S(l)
    (``cauchy_moment``, docs/model.md s. 16).

    ``guess`` <= 0 starts from the linear (small-angle) solution. M_S is smooth and strictly
    increasing, so the root is unique; a step that leaves the bracket is replaced by
    bisection (or doubling while no upper bound is known).
    """
    y, wy, wyy = _node_table(radius, wall_thickness, base_thickness, x_base, w_base,
                             phi_trig, w_phi)
    return _curvature_nodes(moment, y, wy, wyy, mu, alpha, guess, rtol, cauchy)


@formula
def _curvature_nodes(moment, y, wy, wyy, mu, alpha, guess, rtol, cauchy):
    """:func:`_curvature_of` on a section's node table (:func:`_section_nodes`) [1/m]."""
    if moment <= 0.0:
        return 0.0
    if guess > 0.0:
        k = guess
    else:
        m0, dm0 = _section_moment(0.0, y, wy, wyy, mu, alpha, cauchy)
        k = moment / dm0
    lo = 0.0
    hi = math.inf
    for _ in range(200):
        m, dm = _section_moment(k, y, wy, wyy, mu, alpha, cauchy)
        f = m - moment
        if f == 0.0:
            return k
        if f > 0.0:
            hi = k
        else:
            lo = k
        step = f / dm
        k_new = k - step
        if abs(step) <= rtol * k and lo < k_new < hi:
            return k_new
        if not (lo < k_new < hi):
            k_new = 0.5 * (lo + hi) if hi < math.inf else 2.0 * k
        k = k_new
    return k


@formula
def _curvature_guess(pressure, pressures, kappas, n):
    """Newton start for kappa(p) from solves already made at ``pressures[:n]`` [1/m].

    Quadratic interpolation (or extrapolation past the last point) in p of kappa(p) / p
    through the three nearest solved points with p > 0, which are sorted and increasing;
    kappa / p is smooth and nearly constant, so the start is close to the root and Newton
    needs one or two steps. With one or two such points, kappa / p constant or linear
    through them; 0 (the linear start) with none.
    """
    j0 = 0
    while j0 < n and pressures[j0] <= 0.0:
        j0 += 1
    if n - j0 < 1 or pressure <= 0.0:
        return 0.0
    if n - j0 < 3:
        q0 = kappas[j0] / pressures[j0]
        q = q0
        if n - j0 == 2:
            q1 = kappas[j0 + 1] / pressures[j0 + 1]
            q = q0 + (q1 - q0) * (pressure - pressures[j0]) / (pressures[j0 + 1]
                                                               - pressures[j0])
        return q * pressure if q > 0.0 else 0.0
    j = j0
    while j < n - 1 and pressures[j] < pressure:
        j += 1
    i = j - 1
    if i > n - 3:
        i = n - 3
    if i < j0:
        i = j0
    p0, p1, p2 = pressures[i], pressures[i + 1], pressures[i + 2]
    q0, q1, q2 = kappas[i] / p0, kappas[i + 1] / p1, kappas[i + 2] / p2
    if q0 <= 0.0 or q1 <= 0.0 or q2 <= 0.0:
        return 0.0
    x = pressure
    q = (q0 * (x - p1) * (x - p2) / ((p0 - p1) * (p0 - p2))
         + q1 * (x - p0) * (x - p2) / ((p1 - p0) * (p1 - p2))
         + q2 * (x - p0) * (x - p1) / ((p2 - p0) * (p2 - p1)))
    return q * x if q > 0.0 else 0.0


def pressure_moment(pressure, radius, base_thickness):
    """Moment of the chamber pressure about the neutral axis M_P [N m].

    Parameters
    ----------
    pressure : float or array
        Gauge pressure p [Pa], >= 0.
    radius : float or array
        Chamber radius a [m], > 0.
    base_thickness : float or array
        Bottom layer thickness b [m], > 0.

    Returns
    -------
    float or array
        M_P = p (4 a^3 + 3 pi a^2 b) / 6 [N m].

    References
    ----------
    Paper eqs. (14), (16); docs/model.md section 6.
    """
    p = check("pressure", pressure, 0.0, unit="Pa")
    a = check("radius", radius, 0.0, lo_open=True, unit="m")
    b = check("base_thickness", base_thickness, 0.0, lo_open=True, unit="m")
    return scalar_or_array(_pressure_moment(p, a, b))


def material_moment(curvature_value, radius, wall_thickness, base_thickness=None,
                    silicone="tc5005", orders=None):
    """Bending moment of the silicone stresses M_S(kappa) [N m].

    Parameters
    ----------
    curvature_value : float or array
        Curvature kappa [1/m], >= 0.
    radius, wall_thickness : float or array
        a, t [m], > 0.
    base_thickness : float or array, optional
        b [m], > 0; b = t when None.
    silicone : str, dict or Silicone
        Material set.
    orders : dict, optional
        Gauss-Legendre orders ``{"phi": n, "base": n}``; :data:`QUADRATURE_ORDERS` default.

    Notes
    -----
    docs/model.md section 6 [choice]: nominal stress integrated over the undeformed section.
    """
    k = check("curvature", curvature_value, 0.0, unit="1/m")
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    mu, alpha = silicone_parameters(silicone).arrays()
    nodes = quadrature_nodes(orders)
    f = np.vectorize(lambda *x: _material_moment(*x, mu, alpha, *nodes)[0], otypes=[float])
    return scalar_or_array(f(k, a, t, b))


def curvature(pressure, radius, wall_thickness, base_thickness=None, silicone="tc5005",
              orders=None):
    """Curvature kappa at which the material moment balances the pressure moment [1/m].

    Parameters
    ----------
    pressure : float or array
        Gauge pressure p [Pa], >= 0.
    radius, wall_thickness : float or array
        a, t [m], > 0.
    base_thickness : float or array, optional
        b [m], > 0; b = t when None.
    silicone : str, dict or Silicone
        Material set.
    orders : dict, optional
        Gauss-Legendre orders (default :data:`QUADRATURE_ORDERS`).

    Returns
    -------
    float or array
        kappa >= 0 solving M_P(p) = M_S(kappa) [1/m] (eq. 13), by Newton on the analytic
        derivative of the quadrature.

    References
    ----------
    Paper eqs. (13)-(15); Polygerinos et al. 2015; docs/model.md section 6.
    """
    p = check("pressure", pressure, 0.0, unit="Pa")
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    mu, alpha = silicone_parameters(silicone).arrays()
    nodes = quadrature_nodes(orders)

    def one(p_, a_, t_, b_):
        return _curvature(_pressure_moment(p_, a_, b_), a_, t_, b_, mu, alpha, *nodes, 0.0,
                          NEWTON_RTOL)

    return scalar_or_array(np.vectorize(one, otypes=[float])(p, a, t, b))


def bend_angle(pressure, radius, wall_thickness, length, base_thickness=None,
               silicone="tc5005", orders=None):
    """Free bending angle theta = kappa(p) L [rad].

    Parameters
    ----------
    pressure : float or array
        Gauge pressure p [Pa], >= 0.
    radius, wall_thickness : float or array
        a, t [m], > 0.
    length : float or array
        Actuator length L [m], > 0.
    base_thickness : float or array, optional
        b [m], > 0; b = t when None.
    silicone : str, dict or Silicone
        Material set.
    orders : dict, optional
        Gauss-Legendre orders.
    """
    L = check("length", length, 0.0, lo_open=True, unit="m")
    return scalar_or_array(curvature(pressure, radius, wall_thickness, base_thickness,
                                     silicone, orders) * L)


def tip_force(pressure, radius, length, base_thickness):
    """Blocked tip force F_tip = M_P(p) / L at zero bend angle [N] (eq. 16, section 7).

    The upper bound of the tip force at pressure p.

    Parameters
    ----------
    pressure : float or array
        Gauge pressure p [Pa], >= 0.
    radius : float or array
        a [m], > 0.
    length : float or array
        Actuator length L [m], > 0.
    base_thickness : float or array
        b [m], > 0.
    """
    L = check("length", length, 0.0, lo_open=True, unit="m")
    return scalar_or_array(pressure_moment(pressure, radius, base_thickness) / L)
