"""Design limits of an actuator (paper section 4, figure 12; docs/model.md section 8).

For a design (a, t, L, C, psi): the muscle contracts at most s_max(C) and breaks at
F_lim(C). s* = min(s_max, s_lim) with F_n(s_lim) = F_lim. Then p* = p(s*), M* = M_P(p*),
F* = M*/L, theta* = kappa(p*) L, and [choice] the range fraction theta*/theta(s_max): 1 for a
stroke-limited design, a *full range of motion*.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import nylon_parameters, silicone_parameters
from ._formula import check_input, check_section, check_wrap_angle, formula, scalar_or_array
from .bending import NEWTON_RTOL, _curvature, _pressure_moment, quadrature_nodes
from .chamber import P_ATM, _gauge_pressure
from .wrap import _nylon_force_and_slope, _pitch

__all__ = ["DESIGN_VARIABLES", "design_limits", "stroke_limit"]

#: The names :func:`design_limits` returns, in the cube's order (INTERFACE.md).
DESIGN_VARIABLES = (
    "usable_stroke",
    "limit",
    "pressure_max",
    "torque_max",
    "tip_force_max",
    "bend_angle_max",
    "range_fraction",
    "nylon_force_max",
    "nylon_use",
)

#: Relative Newton step below which s_lim counts as converged [-].
STROKE_RTOL = 1e-10


@formula
def _stroke_limit(force_limit, s_max, radius, wall_thickness, lever, mu, alpha, p_atm, rtol):
    """Usable stroke s*, the limit flag (0 stroke, 1 strength) and F_n(s*) [N].

    s_lim solves F_n(s) = F_lim on (0, s_max) by Newton from s_max, safeguarded by
    bisection; F_n is increasing with F_n(0) = 0.
    """
    f, df = _nylon_force_and_slope(s_max, radius, wall_thickness, lever, mu, alpha, p_atm)
    if f <= force_limit:
        return s_max, 0, f
    lo = 0.0
    hi = s_max
    s = s_max
    for _ in range(200):
        if f > force_limit:
            hi = s
        else:
            lo = s
        step = (f - force_limit) / df
        s_new = s - step
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        elif abs(step) <= rtol * s:
            s = s_new
            break
        s = s_new
        f, df = _nylon_force_and_slope(s, radius, wall_thickness, lever, mu, alpha, p_atm)
    f, df = _nylon_force_and_slope(s, radius, wall_thickness, lever, mu, alpha, p_atm)
    return s, 1, f


@formula
def _stroke_state(radius, wall_thickness, base_thickness, lever, force_limit, s_max,
                  kappa_full, mu, alpha, x_base, w_base, phi_trig, w_phi, p_atm):
    """The length-free part of the design limits.

    ``kappa_full`` is the curvature at p(s_max) (<= 0: computed here). Returns
    (s*, limit, p*, M*, kappa*, F_n(s*), kappa_full).
    """
    if kappa_full <= 0.0:
        kappa_full = _curvature(
            _pressure_moment(_gauge_pressure(s_max, p_atm), radius, base_thickness),
            radius, wall_thickness, base_thickness, mu, alpha, x_base, w_base, phi_trig, w_phi,
            0.0, NEWTON_RTOL)
    s, limit, force = _stroke_limit(force_limit, s_max, radius, wall_thickness, lever, mu,
                                    alpha, p_atm, STROKE_RTOL)
    p = _gauge_pressure(s, p_atm)
    moment = _pressure_moment(p, radius, base_thickness)
    if limit == 0:
        kappa = kappa_full
    else:
        # p* < p(s_max): start Newton from the full-stroke curvature scaled by the moment
        kappa = _curvature(moment, radius, wall_thickness, base_thickness, mu, alpha, x_base,
                           w_base, phi_trig, w_phi,
                           kappa_full * p / _gauge_pressure(s_max, p_atm), NEWTON_RTOL)
    return s, limit, p, moment, kappa, force, kappa_full


@formula
def _design_values(s, limit, p, moment, kappa, force, kappa_full, force_limit, length):
    """The nine design variables (order of DESIGN_VARIABLES) of a design of length L [m]."""
    fraction = 1.0 if limit == 0 else kappa / kappa_full
    return (s, limit, p, moment, moment / length, kappa * length, fraction, force,
            force / force_limit)


def _inputs(radius, wall_thickness, length, coil_index, wrap_angle, base_thickness, ny):
    lo, hi = ny.coil_index_range
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    L = check_input("length", length)
    c = check_input("coil_index", coil_index, lo, hi)
    return a, t, L, c, check_wrap_angle(wrap_angle), b


def stroke_limit(radius, wall_thickness, coil_index, wrap_angle, base_thickness=None,
                 silicone="tc5005", nylon="silver_nylon66"):
    """Usable stroke s* = min(s_max(C), s_lim) of a design [-] (docs/model.md section 8).

    Parameters
    ----------
    radius, wall_thickness : float or array
        a, t [m], > 0.
    coil_index : float or array
        C [-], inside the coil-index table.
    wrap_angle : float or array
        psi [rad], in (0, pi/2).
    base_thickness : float or array, optional
        b [m]; b = t when None.
    silicone, nylon : str, dict or material object
        Material sets.
    """
    return design_limits(radius, wall_thickness, 1.0, coil_index, wrap_angle, base_thickness,
                         silicone, nylon)["usable_stroke"]


def design_limits(radius, wall_thickness, length, coil_index, wrap_angle, base_thickness=None,
                  silicone="tc5005", nylon="silver_nylon66"):
    """Every design variable of the cube for one design or broadcastable arrays of them.

    Parameters
    ----------
    radius : float or array
        Inner chamber radius a [m], > 0.
    wall_thickness : float or array
        Wall thickness t [m], > 0.
    length : float or array
        Actuator length L [m], > 0.
    coil_index : float or array
        Coil index C [-], inside the coil-index table (1.1-1.7 for the default set).
    wrap_angle : float or array
        Helix angle psi of the wrap from the hoop direction [rad], in (0, pi/2).
    base_thickness : float or array, optional
        Bottom layer thickness b [m], > 0; b = t when None (docs/model.md section 1 [choice]).
    silicone : str, dict or Silicone, default "tc5005"
        Silicone set.
    nylon : str, dict or Nylon, default "silver_nylon66"
        Muscle set.

    Returns
    -------
    dict
        ``usable_stroke`` s* [-], ``limit`` (0 stroke-limited, 1 strength-limited),
        ``pressure_max`` p* [Pa], ``torque_max`` M* [N m], ``tip_force_max`` F* [N],
        ``bend_angle_max`` theta* [rad], ``range_fraction`` theta*/theta(s_max) [-],
        ``nylon_force_max`` F_n(s*) [N], ``nylon_use`` F_n(s*)/F_lim [-]. Floats for
        scalar input, arrays of the broadcast shape otherwise.

    Raises
    ------
    ValueError
        Naming the parameter and its accepted range.

    References
    ----------
    Paper section 4 and figure 12; docs/model.md section 8.
    """
    ny = nylon_parameters(nylon)
    mu, alpha = silicone_parameters(silicone).arrays()
    a, t, L, c, psi, b = _inputs(radius, wall_thickness, length, coil_index, wrap_angle,
                                 base_thickness, ny)
    a, t, L, c, psi, b = np.broadcast_arrays(a, t, L, c, psi, b)
    nodes = quadrature_nodes()
    c_tab = np.asarray(ny.coil_index_table)
    out = {name: np.empty(a.shape, dtype=np.int8 if name == "limit" else float)
           for name in DESIGN_VARIABLES}
    for idx in np.ndindex(a.shape):
        ai, ti, bi, Li, ci, pi = (float(x[idx]) for x in (a, t, b, L, c, psi))
        force_limit = float(np.interp(ci, c_tab, ny.tensile_strength_table)) * ny.fibre_area
        s_max = float(np.interp(ci, c_tab, ny.stroke_max_table))
        lever = _pitch(ai, ti, bi, pi, ny.fibre_diameter * (ci + 1.0)) / math.cos(pi)
        state = _stroke_state(ai, ti, bi, lever, force_limit, s_max, 0.0, mu, alpha, *nodes,
                              P_ATM)
        values = _design_values(*state, force_limit, Li)
        for name, v in zip(DESIGN_VARIABLES, values):
            out[name][idx] = v
    return {name: (int(v) if name == "limit" and v.ndim == 0 else scalar_or_array(v))
            for name, v in out.items()}
