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
from .elementary import _exp, _log
from .records import Nodes

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

#: Tolerance of the curvature solve [-]: it stops after a step whose predicted relative error
#: is of the order of NEWTON_RTOL^2. A Newton step leaves an error of the order of its
#: square, so it stops below NEWTON_RTOL (the NumPy yardstick,
#: benchmarks/yardstick.py); a Halley step leaves one of the order of its cube
#: (:func:`_curvature_solve`), so it stops below NEWTON_RTOL^(2/3) = 1e-6 (docs/model.md
#: s. 12).
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
def _lateral_lever(radius, wall_thickness, base_thickness):
    """dM_L/dp [m^3]: the moment per pascal of the chamber pressure on the wall and floor
    (``lateral_pressure``, docs/model.md s. 18).

    The pressure compresses the silicone through its thickness, the through-thickness
    stress falling linearly from -p on the chamber's surface to 0 on the outer one
    (after Cacucciolo et al., arXiv:1605.00949). In an incompressible solid that stress
    lowers the axial stress at a given stretch by as much, so the balance M_S = M_P gains
    ``p int (confining fraction) y dA`` over the wall and the floor under the chamber::

        wall:  (1/t) int_0^pi int_a^R (R - r) (b + r sin phi) r dr dphi
               = (pi b J1 + 2 J2) / t,  J1 = R (R^2 - a^2)/2 - (R^3 - a^3)/3,
                                        J2 = R (R^3 - a^3)/3 - (R^4 - a^4)/4,  R = a + t
        floor: int_-a^a int_0^b (y/b) y dy dx = 2 a b^2 / 3
    """
    a = radius
    t = wall_thickness
    b = base_thickness
    # J1, J2 in powers of t (no cancellation for thin walls): J1 = a t^2/2 + t^3/6,
    # J2 = a^2 t^2/2 + a t^3/3 + t^4/12
    j1 = t * t * (0.5 * a + t / 6.0)
    j2 = t * t * (0.5 * a * a + a * t / 3.0 + t * t / 12.0)
    return (math.pi * b * j1 + 2.0 * j2) / t + 2.0 * a * b * b / 3.0


#: The node table's length is a multiple of this [-]: the SIMD loops of
#: :func:`_section_moment` then end without a scalar remainder (8 doubles fill an AVX-512
#: register, two AVX2 ones). 55 nodes measured 570 ns an evaluation, padded to 56 400 ns.
NODE_PAD = 8


@formula
def _node_count(x_base, w_phi):
    """Entries of a section's node table: the quadrature's nodes, padded (:data:`NODE_PAD`)."""
    n = x_base.shape[0] + 2 * w_phi.shape[0]
    return (n + NODE_PAD - 1) // NODE_PAD * NODE_PAD


@formula
def _section_nodes(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi,
                   y, wy, wyy):
    """Fill the section's node table: heights ``y`` [m] and weights ``wy`` [m^3], ``wyy``.

    One table for the whole section (base layer, outer half disc, inner half disc with
    negative weights), so that M_S(kappa) = sum wy S(1 + kappa y) and dM_S/dkappa =
    sum wyy S'(1 + kappa y): the nodes depend on (a, t, b) only, not on kappa, and are
    computed once per section instead of at every step of the solve (docs/model.md s. 12).
    ``y``, ``wy``, ``wyy`` have :func:`_node_count` entries; those after the
    ``x_base.size + 2 w_phi.size`` nodes are y = 0 with zero weights, whose terms are exact
    zeros (S(1) = 0), so they change no sum.
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
    for k in range(nb + 2 * nphi, y.shape[0]):
        y[k] = 0.0
        wy[k] = 0.0
        wyy[k] = 0.0


#: Rows of the scratch array ``work`` of :func:`_section_moment` (one node a column).
MOMENT_WORK_ROWS = 5


@formula
def _section_moment(kappa, y, wy, wyy, work, mu, alpha, cauchy):
    """M_S(kappa) [N m], dM_S/dkappa [N m^2] and d2M_S/dkappa2 [N m^3] from a
    :func:`_section_nodes` table.

    At each node l = 1 + kappa y, and with e1 = l^(a_i-1), e2 = l^(-a_i-1) = 1/(e1 l^2) a term:
    S = sum mu_i (e1 - e2), S' = sum mu_i ((a_i-1) e1 + (a_i+1) e2) / l and
    S'' = sum mu_i ((a_i-1)(a_i-2) e1 - (a_i+1)(a_i+2) e2) / l^2 (the Cauchy stress l S:
    S + l S' and 2 S' + l S''); M_S = sum wy S, M_S' = sum wyy S', M_S'' = sum wyy y S''.
    No trigonometry and no per-node weight arithmetic: those live in the table. One log a
    node and one exp a term a node, in loops over the nodes without a branch or a call
    (:mod:`.elementary`), which compile to SIMD code; their values wait in the rows of
    ``work`` (shape (:data:`MOMENT_WORK_ROWS`, n) or larger, overwritten), and the three sums
    are taken in node order, so the result does not depend on the vector width.
    """
    n = y.shape[0]
    ln = work[0]
    inv_l2 = work[1]
    s = work[2]
    ds = work[3]
    d2s = work[4]
    for i in range(n):
        lam = 1.0 + kappa * y[i]
        ln[i] = _log(lam)
        inv_l2[i] = 1.0 / (lam * lam)
        s[i] = 0.0
        ds[i] = 0.0
        d2s[i] = 0.0
    for j in range(mu.shape[0]):
        a = alpha[j]
        c1 = mu[j] * (a - 1.0)
        c2 = mu[j] * (a + 1.0)
        c3 = c1 * (a - 2.0)
        c4 = c2 * (a + 2.0)
        for i in range(n):
            e1 = _exp((a - 1.0) * ln[i])
            e2 = inv_l2[i] / e1
            s[i] += mu[j] * (e1 - e2)
            ds[i] += c1 * e1 + c2 * e2
            d2s[i] += c3 * e1 - c4 * e2
    for i in range(n):  # each node's terms of the three sums
        lam = 1.0 + kappa * y[i]
        sv = s[i]
        dsv = ds[i] / lam
        d2sv = d2s[i] * inv_l2[i]
        if cauchy:
            sv, dsv, d2sv = lam * sv, sv + lam * dsv, 2.0 * dsv + lam * d2sv
        s[i] = wy[i] * sv
        ds[i] = wyy[i] * dsv
        d2s[i] = wyy[i] * y[i] * d2sv
    m = 0.0
    dm = 0.0
    d2m = 0.0
    for i in range(n):
        m += s[i]
        dm += ds[i]
        d2m += d2s[i]
    return m, dm, d2m


@formula
def _node_table(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi):
    """A new :func:`_section_nodes` table ``(y, wy, wyy)`` of a section, and the scratch
    ``work`` of :func:`_section_moment`."""
    n = _node_count(x_base, w_phi)
    y = np.empty(n)
    wy = np.empty(n)
    wyy = np.empty(n)
    _section_nodes(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi,
                   y, wy, wyy)
    return y, wy, wyy, np.empty((MOMENT_WORK_ROWS, n))


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
    y, wy, wyy, work = _node_table(radius, wall_thickness, base_thickness, x_base, w_base,
                                   phi_trig, w_phi)
    m, dm, _ = _section_moment(kappa, y, wy, wyy, work, mu, alpha, cauchy)
    return m, dm


@formula
def _curvature(moment, radius, wall_thickness, base_thickness, mu, alpha, nodes, guess, rtol):
    """Solve M_S(kappa) = moment for kappa >= 0 [1/m] (nominal stress; :func:`_curvature_of`)."""
    return _curvature_of(moment, radius, wall_thickness, base_thickness, mu, alpha, nodes,
                         guess, rtol, False)


@formula
def _curvature_of(moment, radius, wall_thickness, base_thickness, mu, alpha, nodes, guess,
                  rtol, cauchy):
    """Solve M_S(kappa) = moment [N m] for kappa >= 0 [1/m] (:func:`_curvature_solve`).

    The section a, t, b [m], the silicone's Ogden ``mu`` [Pa] and ``alpha`` [-], and the
    quadrature's ``nodes`` (a :class:`~.records.Nodes`, :func:`quadrature_nodes`), from
    which it makes the section's node table. ``cauchy`` integrates the Cauchy stress
    l S(l) instead of the nominal S(l) (``cauchy_moment``, docs/model.md s. 16). ``guess``
    <= 0 starts from the small-angle solution; ``rtol`` [-] as :data:`NEWTON_RTOL`.
    """
    y, wy, wyy, work = _node_table(radius, wall_thickness, base_thickness, nodes.x_base,
                                   nodes.w_base, nodes.phi_trig, nodes.w_phi)
    return _curvature_nodes(moment, y, wy, wyy, work, mu, alpha, guess, rtol, cauchy)


@formula
def _curvature_nodes(moment, y, wy, wyy, work, mu, alpha, guess, rtol, cauchy):
    """:func:`_curvature_of` on a section's node table (:func:`_section_nodes`) and scratch
    (:func:`_section_moment`) [1/m]."""
    if moment <= 0.0:
        return 0.0
    return _curvature_solve(moment, y, wy, wyy, work, mu, alpha, guess, rtol, cauchy)[0]


@formula
def _curvature_solve(moment, y, wy, wyy, work, mu, alpha, guess, rtol, cauchy):
    """kappa >= 0 solving M_S(kappa) = moment [1/m], and dM_S/dkappa [N m^2] and
    d2M_S/dkappa2 [N m^3] there, by safeguarded Halley iteration.

    Each evaluation of the section gives M_S and its first two derivatives, and Halley's step
    ``f / (f' - f f'' / (2 f'))`` converges cubically: after a step delta the error is about
    C delta^3 / kappa^2 with C <= 3.4 over the accepted range (every set, both stresses;
    docs/model.md s. 12). So the solve stops after a step with |delta| <= rtol^(2/3) kappa
    (1e-6 for rtol 1e-9, an error below 4e-18 relative), without evaluating again: one
    evaluation a solve from a close start. ``guess`` <= 0 starts from the root of the
    second-order expansion of M_S at kappa = 0 (the linear small-angle solution where it has
    none). M_S is smooth and strictly increasing, so the root is unique; every evaluation
    narrows a bracket, and a step that leaves it is replaced by bisection (or doubling while
    no upper bound is known). A zero ``moment`` gives kappa = 0 and the derivatives there.
    """
    if moment <= 0.0 or guess <= 0.0:
        m0, dm0, d2m0 = _section_moment(0.0, y, wy, wyy, work, mu, alpha, cauchy)
        if moment <= 0.0:
            return 0.0, dm0, d2m0
        disc = dm0 * dm0 + 2.0 * d2m0 * moment
        k = 2.0 * moment / (dm0 + math.sqrt(disc)) if disc > 0.0 else moment / dm0
    else:
        k = guess
    lo = 0.0
    hi = math.inf
    tol = rtol * rtol
    m, dm, d2m = 0.0, 0.0, 0.0
    for _ in range(200):
        m, dm, d2m = _section_moment(k, y, wy, wyy, work, mu, alpha, cauchy)
        f = m - moment
        if f == 0.0:
            return k, dm, d2m
        if f > 0.0:
            hi = k
        else:
            lo = k
        newton = f / dm
        den = 1.0 - 0.5 * newton * d2m / dm
        if den > 0.5:  # Halley's step; far from the root, where it may misbehave, Newton's
            step = newton / den
            r = abs(step) / k
            if r * r * r <= tol:
                # the step leaves an error of order C r^3 << rtol^2; the root is in the bracket
                k_new = min(max(k - step, lo), hi)
                return k_new, dm + d2m * (k_new - k), d2m
        else:
            step = newton
        k_new = k - step
        if not (lo < k_new < hi):
            k_new = 0.5 * (lo + hi) if hi < math.inf else 2.0 * k
        k = k_new
    return k, dm, d2m


@formula
def _curvature_rates(pressure_lever, dm, d2m):
    """dkappa/dp [1/(m Pa)] and d2kappa/dp2 [1/(m Pa^2)] on the curve M_S(kappa) = M_P(p).

    ``pressure_lever`` is dM_P/dp [m^3] (M_P is linear in p), ``dm``, ``d2m`` the first two
    derivatives of M_S at kappa(p) (:func:`_curvature_solve`): M_S' kappa' = dM_P/dp and
    M_S'' kappa'^2 + M_S' kappa'' = 0.
    """
    rate = pressure_lever / dm
    return rate, -d2m * rate * rate / dm


@formula
def _curvature_start(pressure, pressures, kappas, rates, rates2, n):
    """Start of the curvature solve at ``pressure`` from solves already made [1/m].

    ``pressures[:n]`` (increasing) hold solved points kappa(p) (``kappas``) with their
    dkappa/dp (``rates``) and d2kappa/dp2 (``rates2``, :func:`_curvature_rates`). The start
    is the quintic Hermite interpolant through the two solved points around ``pressure``
    (through the last two beyond them), whose error is of order h^6 in their spacing h: the
    curvature solve then needs one evaluation (docs/model.md s. 12). Second-order Taylor
    from a single point; 0 (the solve's own start) with none, or when the interpolant is not
    a positive number.
    """
    if n < 1 or pressure <= 0.0:
        return 0.0
    if n == 1:
        g = _taylor_start(pressure, pressures[0], kappas[0], rates[0], rates2[0])
    else:
        j = 1
        while j < n - 1 and pressures[j] < pressure:
            j += 1
        g = _hermite_start(pressure, pressures[j - 1], kappas[j - 1], rates[j - 1],
                           rates2[j - 1], pressures[j], kappas[j], rates[j], rates2[j])
    return g if 0.0 < g < math.inf else 0.0


@formula
def _taylor_start(pressure, p0, k0, rate, rate2):
    """kappa(p0) + kappa'(p0) h + kappa''(p0) h^2 / 2 with h = p - p0 [1/m]."""
    h = pressure - p0
    return k0 + h * (rate + 0.5 * h * rate2)


@formula
def _hermite_start(pressure, p0, k0, r0, s0, p1, k1, r1, s1):
    """Quintic Hermite interpolant of values, first and second derivatives at p0 < p1 [1/m]."""
    h = p1 - p0
    t = (pressure - p0) / h
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    h00 = 1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5
    h01 = 10.0 * t3 - 15.0 * t4 + 6.0 * t5
    h10 = t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5
    h11 = -4.0 * t3 + 7.0 * t4 - 3.0 * t5
    h20 = 0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5
    h21 = 0.5 * t3 - t4 + 0.5 * t5
    return (h00 * k0 + h01 * k1 + h * (h10 * r0 + h11 * r1)
            + h * h * (h20 * s0 + h21 * s1))


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
        kappa >= 0 solving M_P(p) = M_S(kappa) [1/m] (eq. 13), by Halley iteration on the
        analytic derivatives of the quadrature.

    References
    ----------
    Paper eqs. (13)-(15); Polygerinos et al. 2015; docs/model.md section 6.
    """
    p = check("pressure", pressure, 0.0, unit="Pa")
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    mu, alpha = silicone_parameters(silicone).arrays()
    nodes = Nodes(*quadrature_nodes(orders))

    def one(p_, a_, t_, b_):
        return _curvature(_pressure_moment(p_, a_, b_), a_, t_, b_, mu, alpha, nodes, 0.0,
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
