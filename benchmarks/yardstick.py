"""The NumPy yardstick of ``nylonflex bench`` (benchmarks/suite.py): the grid kernel's
structure in plain NumPy.

What a user might write instead of the Numba kernel: the same quadrature (one node table per
section, :func:`nylonflex.physics.bending.quadrature_nodes`), safeguarded Newton solves to
the same tolerance (``NEWTON_RTOL``) started as the kernel's Newton solves were before it
moved to Halley steps and Hermite starts (docs/model.md s. 12): along the pressure axis
from the previous solves, the full-stroke and strength-limited solves from the solved
curve; and the same loop structure (per section, per coil index, per wrap angle, per
length), each level vectorised over every design it covers instead of looping. The Newton
loops iterate on the designs not yet converged only.

It covers the paper's model without a supply and the mechanical variables (usable stroke,
limit, pressure, torque, tip force, bend angle, range fraction, nylon force and use) and the
three curves: the part of the kernel where its time goes. The thermal variables are left
out, which flatters NumPy. :func:`grid_numpy` returns the same names and shapes as
:func:`nylonflex.engine.grid.compute_slab`; the tests hold both to 1e-9.
"""

from __future__ import annotations

import math

import numpy as np

from nylonflex.engine.grid import coil_table
from nylonflex.physics.bending import NEWTON_RTOL, quadrature_nodes
from nylonflex.physics.chamber import P_ATM
from nylonflex.physics.limits import STROKE_RTOL

__all__ = ["MECHANICAL", "grid_numpy"]

#: The variables :func:`grid_numpy` returns.
MECHANICAL = ("usable_stroke", "limit", "pressure_max", "torque_max", "tip_force_max",
              "bend_angle_max", "range_fraction", "nylon_force_max", "nylon_use",
              "nylon_force", "bend_angle", "tip_force")


def _stress(lam, mu, alpha):
    """Plane-strain nominal Ogden stress S(l) and dS/dl, element-wise [Pa]."""
    ln = np.log(lam)
    inv_l2 = 1.0 / (lam * lam)
    s = np.zeros_like(lam)
    ds = np.zeros_like(lam)
    for m, a in zip(mu, alpha):
        e1 = np.exp((a - 1.0) * ln)
        e2 = inv_l2 / e1
        s += m * (e1 - e2)
        ds += m * ((a - 1.0) * e1 + (a + 1.0) * e2)
    return s, ds / lam


def _node_tables(a, t, b):
    """Node heights and weights (n_sections, n_nodes) of every section, as the kernel's."""
    xb, wb, trig, wp = quadrature_nodes()
    half = 0.5 * b[:, None]
    y_base = half * (xb + 1.0)
    wy_base = wb * half * (2.0 * (a + t))[:, None] * y_base
    quarter = 0.25 * math.pi
    parts_y, parts_w = [y_base], [wy_base]
    for outer, sign in ((a + t, 1.0), (a, -1.0)):
        y = b[:, None] + outer[:, None] * trig[1]
        parts_y.append(y)
        parts_w.append(sign * (wp * quarter * (2.0 * outer * outer)[:, None]
                               * trig[0] * trig[0] * y))
    y = np.concatenate(parts_y, axis=1)
    wy = np.concatenate(parts_w, axis=1)
    return y, wy, wy * y


def _curvature(moment, y, wy, wyy, mu, alpha, guess):
    """Safeguarded Newton for M_S(kappa) = moment, vectorised over rows [1/m]."""
    n = moment.shape[0]
    k = np.array(guess, dtype=float)
    out = np.zeros(n)
    todo = np.flatnonzero(moment > 0.0)
    cold = todo[k[todo] <= 0.0]
    if cold.size:
        s, ds = _stress(np.ones_like(y[cold]), mu, alpha)
        k[cold] = moment[cold] / np.sum(wyy[cold] * ds, axis=1)
    lo = np.zeros(n)
    hi = np.full(n, np.inf)
    for _ in range(200):
        if todo.size == 0:
            break
        kk = k[todo]
        s, ds = _stress(1.0 + kk[:, None] * y[todo], mu, alpha)
        f = np.sum(wy[todo] * s, axis=1) - moment[todo]
        dm = np.sum(wyy[todo] * ds, axis=1)
        lo_t = np.where(f < 0.0, kk, lo[todo])
        hi_t = np.where(f > 0.0, kk, hi[todo])
        step = f / dm
        k_new = kk - step
        inside = (lo_t < k_new) & (k_new < hi_t)
        done = (f == 0.0) | ((np.abs(step) <= NEWTON_RTOL * kk) & inside)
        k_new = np.where(inside, k_new,
                         np.where(np.isfinite(hi_t), 0.5 * (lo_t + hi_t), 2.0 * kk))
        k_new = np.where(f == 0.0, kk, k_new)
        out[todo[done]] = k_new[done]
        lo[todo], hi[todo], k[todo] = lo_t, hi_t, k_new
        todo = todo[~done]
    out[todo] = k[todo]
    return out


def _guess(p, pressures, kappas):
    """kappa/p through solved curve points (rows) as the kernel's start, else 0."""
    pos = pressures > 0.0
    pp = pressures[pos]
    q = kappas[:, pos] / pp
    if pp.size == 0:
        return np.zeros(p.shape)
    if pp.size < 3:
        qq = q[:, 0] if pp.size == 1 else \
            q[:, 0] + (q[:, 1] - q[:, 0]) * (p - pp[0]) / (pp[1] - pp[0])
        return np.where(qq > 0.0, qq * p, 0.0)
    j = np.clip(np.searchsorted(pp, p), 1, pp.size - 2) - 1
    rows = np.arange(p.shape[0])
    p0, p1, p2 = pp[j], pp[j + 1], pp[j + 2]
    q0, q1, q2 = q[rows, j], q[rows, j + 1], q[rows, j + 2]
    qq = (q0 * (p - p1) * (p - p2) / ((p0 - p1) * (p0 - p2))
          + q1 * (p - p0) * (p - p2) / ((p1 - p0) * (p1 - p2))
          + q2 * (p - p0) * (p - p1) / ((p2 - p0) * (p2 - p1)))
    return np.where(qq > 0.0, qq * p, 0.0)


def _gauge(s):
    r = 1.0 - s
    return P_ATM * (1.0 / (r * r) - 1.0)


def _force(s, a, t, lever, mu, alpha):
    """F_n(s) and dF_n/ds (docs/model.md s. 4), element-wise [N]."""
    r = 1.0 - s
    p = _gauge(s)
    dp = 2.0 * P_ATM / (r * r * r)
    st, dst = _stress(r, mu, alpha)
    sign = np.where(st >= 0.0, 1.0, -1.0)
    return (p * a + np.abs(st) * t) * lever, (dp * a - sign * dst * t) * lever


def _stroke_limit(f_lim, s_max, a, t, lever, mu, alpha):
    """s*, limit flag and F_n(s*) by safeguarded Newton from s_max, vectorised."""
    f, df = _force(s_max, a, t, lever, mu, alpha)
    s = s_max.copy()
    limit = (f > f_lim).astype(np.int8)
    todo = np.flatnonzero(limit == 1)
    lo = np.zeros_like(s)
    hi = s_max.copy()
    ff, dff = f[todo], df[todo]
    for _ in range(200):
        if todo.size == 0:
            break
        ss = s[todo]
        lo_t = np.where(ff > f_lim[todo], lo[todo], ss)
        hi_t = np.where(ff > f_lim[todo], ss, hi[todo])
        step = (ff - f_lim[todo]) / dff
        s_new = ss - step
        inside = (lo_t < s_new) & (s_new < hi_t)
        done = inside & (np.abs(step) <= STROKE_RTOL * ss)
        s_new = np.where(inside, s_new, 0.5 * (lo_t + hi_t))
        s[todo], lo[todo], hi[todo] = s_new, lo_t, hi_t
        keep = ~done
        todo = todo[keep]
        ff, dff = _force(s[todo], a[todo], t[todo], lever[todo], mu, alpha)
    f, _ = _force(s, a, t, lever, mu, alpha)
    return s, limit, f


def grid_numpy(cfg) -> dict:
    """The mechanical variables and curves of ``cfg``'s whole grid (paper model, no
    supply), as :func:`nylonflex.engine.grid.compute_slab` shapes them [SI]."""
    mu, alpha = cfg.silicone.arrays()
    ax, cv = cfg.axes, cfg.curves
    a1, t1 = ax["radius"], ax["wall_thickness"]
    lengths, wraps = ax["length"], ax["wrap_angle"]
    strokes, pressures = cv["stroke"], cv["pressure"]
    s_max_c, f_lim_c, width_c = coil_table(cfg)[:3]
    na, nt, nl, nc, npsi = a1.size, t1.size, lengths.size, s_max_c.size, wraps.size
    # per section (a, t): node table and the bend-angle curve
    a = np.repeat(a1, nt)
    t = np.tile(t1, na)
    b = t.copy() if cfg.base_thickness is None else np.full(a.size, float(cfg.base_thickness))
    y, wy, wyy = _node_tables(a, t, b)
    shape_pm = (4.0 * a ** 3 + 3.0 * math.pi * a * a * b) / 6.0
    kappa_curve = np.zeros((a.size, pressures.size))
    for jp, p in enumerate(pressures):
        guess = _guess(np.full(a.size, p), pressures[:jp], kappa_curve[:, :jp])
        kappa_curve[:, jp] = _curvature(p * shape_pm, y, wy, wyy, mu, alpha, guess)
    # per (section, C): the full-stroke curvature
    p_full = _gauge(s_max_c)
    rows = np.repeat(np.arange(a.size), nc)
    pf = np.tile(p_full, a.size)
    kappa_full = _curvature(pf * shape_pm[rows], y[rows], wy[rows], wyy[rows], mu, alpha,
                            _guess(pf, pressures, kappa_curve[rows]))
    # per (section, C, psi): the stroke limit and the strength-limited solves
    rows3 = np.repeat(rows, npsi)
    ic = np.tile(np.repeat(np.arange(nc), npsi), a.size)
    psi = np.tile(wraps, a.size * nc)
    aa, tt, bb = a[rows3], t[rows3], b[rows3]
    helix = (math.pi * (aa + tt) + 2.0 * (aa + tt) + 2.0 * bb) * np.tan(psi)
    pitch = np.maximum(helix, width_c[ic] / np.cos(psi))
    lever = pitch / np.cos(psi)
    s, limit, force = _stroke_limit(f_lim_c[ic], s_max_c[ic].copy(), aa, tt, lever, mu,
                                    alpha)
    p = _gauge(s)
    moment = p * shape_pm[rows3]
    kf = np.repeat(kappa_full, npsi)
    kappa = kf.copy()
    lim = np.flatnonzero(limit == 1)
    if lim.size:
        r = rows3[lim]
        g = _guess(p[lim], pressures, kappa_curve[r])
        g = np.where(g > 0.0, g, kf[lim] * p[lim] / p_full[ic[lim]])
        kappa[lim] = _curvature(moment[lim], y[r], wy[r], wyy[r], mu, alpha, g)
    fraction = np.where(limit == 0, 1.0, kappa / kf)
    # per length: multiplies; shapes (a, t, L, C, psi)
    shape5 = (na, nt, nc, npsi)

    def per_length(v, scale=None):
        v = v.reshape(shape5)[:, :, None]
        v = v * scale[None, None, :, None, None] if scale is not None else \
            np.broadcast_to(v, (na, nt, nl, nc, npsi))
        return np.ascontiguousarray(v)

    out = {"usable_stroke": per_length(s), "limit": per_length(limit),
           "pressure_max": per_length(p), "torque_max": per_length(moment),
           "tip_force_max": per_length(moment, 1.0 / lengths),
           "bend_angle_max": per_length(kappa, lengths),
           "range_fraction": per_length(fraction), "nylon_force_max": per_length(force),
           "nylon_use": per_length(force / f_lim_c[ic])}
    # curves
    hoop, _ = _stress(1.0 - strokes, mu, alpha)
    out["nylon_force"] = ((_gauge(strokes) * aa[:, None] + np.abs(hoop) * tt[:, None])
                          * lever[:, None]).reshape(na, nt, nc, npsi, strokes.size)
    kc = kappa_curve.reshape(na, nt, 1, pressures.size)
    out["bend_angle"] = kc * lengths[None, None, :, None]
    out["tip_force"] = ((pressures * shape_pm[:, None]).reshape(na, nt, 1, pressures.size)
                        / lengths[None, None, :, None])
    return out
