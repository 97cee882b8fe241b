"""The design-grid kernel: every design variable and curve of a slab of radii.

Private compiled loops that write into ``out`` arrays and check nothing (numbagg's habit);
:mod:`nylonflex.sweep` validates and shapes. The loops follow the model's structure so that
nothing is computed twice that a design axis does not change:

- per (a, t): the bend-angle curve over pressure (Newton warm-started along the sorted
  pressure axis), independent of C, psi and L;
- per (a, t, C): the curvature at the full stroke p(s_max(C));
- per stroke: p(s) and S_theta(s), shared by every design's nylon-force curve;
- per (a, t, C, psi): the stroke limit and, only for strength-limited designs, one more
  curvature solve (warm-started from the full-stroke one); the nylon-force curve;
- per L: a multiply (theta = kappa L, F = M/L).

:func:`_design_points` evaluates scattered designs (the pointwise evaluator behind
``nylonflex.evaluate``), each with its own materials if asked.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from ..physics.bending import NEWTON_RTOL, _curvature, _pressure_moment
from ..physics.chamber import _gauge_pressure
from ..physics.limits import _design_values, _stroke_state
from ..physics.silicone import _stress_and_slope
from ..physics.wrap import _pitch, _wrap_force
from ._compile import jit_kernel

#: Number of float design variables in ``out.design``: the registry's design variables
#: less ``limit``.
N_FLOAT_DESIGN = 8


def _design_slab(grid, coil, silicone, nodes, out):
    """Fill ``out`` (a :class:`~.records.GridOut`) for the radii ``grid.radius``.

    ``grid`` is a :class:`~.records.GridAxes` (all other axes whole), ``coil`` a
    :class:`~.records.CoilTable` with one entry a coil index of the axis, ``silicone`` an
    :class:`~.records.Ogden` of 1-D arrays, ``nodes`` the quadrature's
    :class:`~.records.Nodes`. ``out.design[v]`` holds the float variables in the registry's
    order less ``limit``; shapes (na, nt, nl, nc, npsi), curves as the registry says.
    """
    radius, wall, length, wrap = grid.radius, grid.wall, grid.length, grid.wrap
    stroke, pressure, p_atm = grid.stroke, grid.pressure, grid.p_atm
    mu, alpha = silicone.mu, silicone.alpha
    x_base, w_base, phi_trig, w_phi = nodes.x_base, nodes.w_base, nodes.phi_trig, nodes.w_phi
    # unpacked before the loop: a record's fields written inside prange are lost (Numba)
    out_design, out_limit, out_force, out_angle, out_tip = out
    coil_s_max, coil_force_limit, coil_width = coil
    b_fixed = grid.base_thickness
    na = radius.shape[0]
    nt = wall.shape[0]
    nl = length.shape[0]
    nc = coil_s_max.shape[0]
    npsi = wrap.shape[0]
    ns = stroke.shape[0]
    npr = pressure.shape[0]
    # p(s) and S_theta(s) depend on the stroke only: once per stroke, not per design
    stroke_pressure = np.empty(ns)
    stroke_hoop = np.empty(ns)
    for js in range(ns):
        stroke_pressure[js] = _gauge_pressure(stroke[js], p_atm)
        stroke_hoop[js] = _stress_and_slope(1.0 - stroke[js], mu, alpha)[0]
    for k in prange(na * nt):
        ia = k // nt
        it = k % nt
        a = radius[ia]
        t = wall[it]
        b = t if b_fixed <= 0.0 else b_fixed
        for ic in range(nc):
            s_max = coil_s_max[ic]
            f_lim = coil_force_limit[ic]
            kappa_full = _curvature(_pressure_moment(_gauge_pressure(s_max, p_atm), a, b),
                                    a, t, b, mu, alpha, x_base, w_base, phi_trig, w_phi, 0.0,
                                    NEWTON_RTOL)
            for ip in range(npsi):
                lever = _pitch(a, t, b, wrap[ip], coil_width[ic]) / math.cos(wrap[ip])
                st = _stroke_state(a, t, b, lever, f_lim, s_max, kappa_full, mu, alpha,
                                   x_base, w_base, phi_trig, w_phi, p_atm)
                for il in range(nl):
                    v = _design_values(st[0], st[1], st[2], st[3], st[4], st[5], st[6], f_lim,
                                       length[il])
                    out_design[0, ia, it, il, ic, ip] = v[0]
                    out_limit[ia, it, il, ic, ip] = v[1]
                    out_design[1, ia, it, il, ic, ip] = v[2]
                    out_design[2, ia, it, il, ic, ip] = v[3]
                    out_design[3, ia, it, il, ic, ip] = v[4]
                    out_design[4, ia, it, il, ic, ip] = v[5]
                    out_design[5, ia, it, il, ic, ip] = v[6]
                    out_design[6, ia, it, il, ic, ip] = v[7]
                    out_design[7, ia, it, il, ic, ip] = v[8]
                for js in range(ns):
                    out_force[ia, it, ic, ip, js] = _wrap_force(
                        stroke_pressure[js], stroke_hoop[js], a, t, lever)
        kappa = 0.0
        for jp in range(npr):
            moment = _pressure_moment(pressure[jp], a, b)
            guess = kappa * pressure[jp] / pressure[jp - 1] if kappa > 0.0 else 0.0
            kappa = _curvature(moment, a, t, b, mu, alpha, x_base, w_base, phi_trig, w_phi,
                               guess, NEWTON_RTOL)
            for il in range(nl):
                out_angle[ia, it, il, jp] = kappa * length[il]
                out_tip[ia, it, il, jp] = moment / length[il]


def _design_points(designs, coil, silicone, nodes, p_atm, out):
    """Every design variable of scattered designs, one a design (``prange`` over them).

    ``designs`` is a :class:`~.records.PointDesigns` and ``coil`` a
    :class:`~.records.CoilTable`, one entry a design. ``silicone`` holds 2-D arrays
    (row, term) with one row for all designs or one row a design. The loop body is the one
    :func:`nylonflex.physics.design_limits` runs, so both give the same numbers.
    """
    radius, wall, base, length, wrap = designs
    s_max_all, f_lim_all, width_all = coil
    mu_all, alpha_all = silicone
    x_base, w_base, phi_trig, w_phi = nodes
    out_design, out_limit = out
    n = radius.shape[0]
    step = 0 if mu_all.shape[0] == 1 else 1  # one row for all, or one a design
    for i in prange(n):
        row = i * step
        mu = mu_all[row]
        alpha = alpha_all[row]
        a = radius[i]
        t = wall[i]
        b = base[i]
        psi = wrap[i]
        f_lim = f_lim_all[i]
        lever = _pitch(a, t, b, psi, width_all[i]) / math.cos(psi)
        st = _stroke_state(a, t, b, lever, f_lim, s_max_all[i], 0.0, mu, alpha, x_base,
                           w_base, phi_trig, w_phi, p_atm)
        v = _design_values(st[0], st[1], st[2], st[3], st[4], st[5], st[6], f_lim, length[i])
        out_design[0, i] = v[0]
        out_limit[i] = v[1]
        out_design[1, i] = v[2]
        out_design[2, i] = v[3]
        out_design[3, i] = v[4]
        out_design[4, i] = v[5]
        out_design[5, i] = v[6]
        out_design[6, i] = v[7]
        out_design[7, i] = v[8]


#: Threaded (Numba prange) and serial compilations of the same loops. The serial ones are
#: for Dask workers, where a second level of threads would oversubscribe the cores.
design_slab_parallel = jit_kernel(_design_slab, parallel=True)
design_slab_serial = jit_kernel(_design_slab, parallel=False)
design_points_parallel = jit_kernel(_design_points, parallel=True)
design_points_serial = jit_kernel(_design_points, parallel=False)
