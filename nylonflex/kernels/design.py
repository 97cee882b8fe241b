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

#: Number of float design variables in ``out_design``: DESIGN_VARIABLES without ``limit``.
N_FLOAT_DESIGN = 8


def _design_slab(radius, wall, length, coil_s_max, coil_force_limit, coil_width, wrap,
                 base_thickness, stroke, pressure, mu, alpha, x_base, w_base, x_phi, w_phi,
                 p_atm, out_design, out_limit, out_nylon_force, out_bend_angle,
                 out_tip_force):
    """Fill the output arrays for the radii ``radius`` (all other axes whole).

    ``base_thickness`` <= 0 means b = t. ``out_design[v]`` holds the float variables in the
    order of DESIGN_VARIABLES less ``limit``; shapes (na, nt, nl, nc, npsi), curves as the
    registry says.
    """
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
        b = t if base_thickness <= 0.0 else base_thickness
        for ic in range(nc):
            s_max = coil_s_max[ic]
            f_lim = coil_force_limit[ic]
            kappa_full = _curvature(_pressure_moment(_gauge_pressure(s_max, p_atm), a, b),
                                    a, t, b, mu, alpha, x_base, w_base, x_phi, w_phi, 0.0,
                                    NEWTON_RTOL)
            for ip in range(npsi):
                lever = _pitch(a, t, b, wrap[ip], coil_width[ic]) / math.cos(wrap[ip])
                st = _stroke_state(a, t, b, lever, f_lim, s_max, kappa_full, mu, alpha,
                                   x_base, w_base, x_phi, w_phi, p_atm)
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
                    out_nylon_force[ia, it, ic, ip, js] = _wrap_force(
                        stroke_pressure[js], stroke_hoop[js], a, t, lever)
        kappa = 0.0
        for jp in range(npr):
            moment = _pressure_moment(pressure[jp], a, b)
            guess = kappa * pressure[jp] / pressure[jp - 1] if kappa > 0.0 else 0.0
            kappa = _curvature(moment, a, t, b, mu, alpha, x_base, w_base, x_phi, w_phi,
                               guess, NEWTON_RTOL)
            for il in range(nl):
                out_bend_angle[ia, it, il, jp] = kappa * length[il]
                out_tip_force[ia, it, il, jp] = moment / length[il]


#: Threaded (Numba prange) and serial compilations of the same loop. The serial one is for
#: Dask workers, where a second level of threads would oversubscribe the cores.
design_slab_parallel = jit_kernel(_design_slab, parallel=True)
design_slab_serial = jit_kernel(_design_slab, parallel=False)
