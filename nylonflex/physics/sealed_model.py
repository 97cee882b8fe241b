"""The ``sealed_chamber`` variant as plain functions of one design at a stroke, with any
coefficients: what its calibration (``calibration.chamber``) and the bench fit evaluate
(docs/model.md s. 22). The kernels run the same formulas (:mod:`.sealed`) with the shipped
coefficients.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import silicone_parameters
from ._formula import check, check_section, scalar_or_array
from .bending import _curvature_nodes, _node_table, _section_moment, NEWTON_RTOL, \
    quadrature_nodes
from .chamber import P_ATM
from .limits import LATERAL_PRESSURE, _model_moment
from .sealed import (_blocked_ratio, _boyle_pressure, _chamber_stiffness, _free_volume,
                     _rounding, _sealed_pressure, _sealed_stroke, _squeeze_curvature,
                     sealed_coefficients)

__all__ = ["blocked_ratio", "boyle_pressure", "chamber_stiffness", "free_volume", "lateral_state",
           "sealed_pressure", "sealed_state", "sealed_stroke", "squeeze_moment"]


def boyle_pressure(volume, stiffness=math.inf, tau=1.0, p_atm=P_ATM):
    """Gauge pressure [Pa] of sealed air in a compliant chamber: the positive root of
    (p0 + p)(v + p/K) = p0 tau.

    Parameters
    ----------
    volume : float or array
        v, the chamber's unpressurised volume over its sealed one [-], > 0.
    stiffness : float or array
        K, its volumetric stiffness dp/d(V/V0) [Pa], > 0 (inf: rigid, eq. 8's Boyle).
    tau : float or array
        The air's absolute temperature over the one it was sealed at [-], > 0.
    p_atm : float
        p0, the absolute pressure it was sealed at [Pa].
    """
    v = check("volume", volume, 0.0, lo_open=True, unit="-")
    k = np.asarray(stiffness, dtype=float)
    if np.any(~(k > 0.0)):
        raise ValueError(f"stiffness: must be > 0 Pa (inf: rigid), got {k[~(k > 0.0)].flat[0]:g}")
    tau = check("tau", tau, 0.0, lo_open=True, unit="-")
    f = np.vectorize(lambda v_, k_, t_: _boyle_pressure(v_, p_atm / k_, t_, p_atm)[0],
                     otypes=[float])
    return scalar_or_array(f(v, k, tau))


def blocked_ratio(stroke, radius, wall_thickness, length, coefficients=None):
    """rho = p_b / p [-]: the chamber's pressure held straight over its free bend's at
    stroke s [-], max(1, exp(r0 + r1 x + r2 x^2 + r3 ln s + r4 a/L)), x = ln(t/a), for a,
    t, L [m] (docs/model.md s. 22)."""
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    a, t, _ = check_section(radius, wall_thickness, None)
    L = check("length", length, 0.0, lo_open=True, unit="m")
    coef = sealed_coefficients(coefficients)
    f = np.vectorize(lambda s_, a_, t_, L_: _blocked_ratio(s_, a_, t_, L_, coef), otypes=[float])
    return scalar_or_array(f(s, a, t, L))


def chamber_stiffness(radius, wall_thickness, silicone="tc5005", coefficients=None):
    """The chamber's volumetric stiffness K = mu0 (1 - (a/(a+t))^2) exp(k0 + k1 ln(t/a))
    [Pa] (docs/model.md s. 22)."""
    a, t, _ = check_section(radius, wall_thickness, None)
    mu, alpha = silicone_parameters(silicone).arrays()
    coef = sealed_coefficients(coefficients)
    f = np.vectorize(lambda a_, t_: _chamber_stiffness(a_, t_, mu, alpha, coef), otypes=[float])
    return scalar_or_array(f(a, t))


def free_volume(stroke, radius, wall_thickness, coefficients=None):
    """The unpressurised chamber's volume over its initial one, (1 - s)^2 exp(gamma s) [-]."""
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    a, t, _ = check_section(radius, wall_thickness, None)
    coef = sealed_coefficients(coefficients)
    f = np.vectorize(lambda s_, a_, t_: _free_volume(s_, _rounding(a_, t_, coef))[0],
                     otypes=[float])
    return scalar_or_array(f(s, a, t))


def sealed_pressure(stroke, radius, wall_thickness, silicone="tc5005", coefficients=None,
                    tau=1.0, p_atm=P_ATM):
    """Chamber gauge pressure p(s) of the sealed, compliant chamber [Pa] (s. 22)."""
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    a, t, _ = check_section(radius, wall_thickness, None)
    tau = check("tau", tau, 0.0, lo_open=True, unit="-")
    mu, alpha = silicone_parameters(silicone).arrays()
    coef = sealed_coefficients(coefficients)
    f = np.vectorize(lambda s_, a_, t_, u_: _sealed_pressure(s_, a_, t_, mu, alpha, p_atm, u_,
                                                             coef)[0], otypes=[float])
    return scalar_or_array(f(s, a, t, tau))


def sealed_stroke(pressure, radius, wall_thickness, silicone="tc5005", coefficients=None,
                  tau=1.0, p_atm=P_ATM):
    """The stroke [-] at which the sealed chamber holds the gauge pressure p [Pa]."""
    p = check("pressure", pressure, 0.0, unit="Pa")
    a, t, _ = check_section(radius, wall_thickness, None)
    mu, alpha = silicone_parameters(silicone).arrays()
    coef = sealed_coefficients(coefficients)
    f = np.vectorize(lambda p_, a_, t_: _sealed_stroke(p_, a_, t_, mu, alpha, p_atm, tau, coef),
                     otypes=[float])
    return scalar_or_array(f(p, a, t))


def lateral_state(pressure, radius, wall_thickness, base_thickness, silicone="tc5005"):
    """``lateral_pressure``'s balance at chamber pressure p [Pa] of one section: its
    curvature [1/m] and moment [N m] (floats; b [m] given)."""
    mu, alpha = silicone_parameters(silicone).arrays()
    y, wy, wyy, work = _node_table(radius, wall_thickness, base_thickness, *quadrature_nodes())
    moment = _model_moment(LATERAL_PRESSURE, pressure, radius, wall_thickness, base_thickness)
    return _curvature_nodes(moment, y, wy, wyy, work, mu, alpha, 0.0, NEWTON_RTOL,
                            False), moment


def squeeze_moment(kappa, radius, wall_thickness, base_thickness, silicone="tc5005"):
    """M_S(kappa) [N m] of one section (nominal stress), the moment that holds the
    squeeze's curvature kappa [1/m] straight before c_b."""
    mu, alpha = silicone_parameters(silicone).arrays()
    y, wy, wyy, work = _node_table(radius, wall_thickness, base_thickness, *quadrature_nodes())
    return _section_moment(kappa, y, wy, wyy, work, mu, alpha, False)[0]


def sealed_state(stroke, radius, wall_thickness, length, base_thickness=None, silicone="tc5005",
                 coefficients=None, tau=1.0, p_atm=P_ATM) -> dict:
    """The sealed chamber of one design at stroke s: what the variant says (floats).

    Returns ``pressure`` [Pa], ``volume_ratio`` V/V0 and ``free_volume`` [-], ``stiffness``
    K [Pa], ``squeeze_curvature`` [1/m], ``bend_angle`` [rad] (``lateral_pressure``'s
    balance at p plus the squeeze), ``pressure_angle`` [rad] (the balance alone),
    ``pressure_moment`` M_lateral(p) [N m], ``blocked_pressure`` p_b = rho p [Pa] (held
    straight), ``torque`` [N m] and ``tip_force`` [N] (blocked: c_a M_lateral(p_b) +
    c_b M_S(kappa_sq), over L) (docs/model.md s. 22).
    """
    s = float(check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-"))
    a, t, b = (float(x) for x in check_section(radius, wall_thickness, base_thickness))
    L = float(check("length", length, 0.0, lo_open=True, unit="m"))
    mu, alpha = silicone_parameters(silicone).arrays()
    coef = sealed_coefficients(coefficients)
    k = _chamber_stiffness(a, t, mu, alpha, coef)
    v = _free_volume(s, _rounding(a, t, coef))[0]
    p = _sealed_pressure(s, a, t, mu, alpha, p_atm, tau, coef)[0]
    kappa_p, moment = lateral_state(p, a, t, b, silicone)
    k_sq = _squeeze_curvature(s, a, t, b, coef)
    m_sq = coef[6] * squeeze_moment(k_sq, a, t, b, silicone)
    rho = _blocked_ratio(s, a, t, L, coef)
    torque = coef[7] * rho * moment + m_sq  # M_lateral is linear in p
    return {"pressure": p, "volume_ratio": v + p / k, "free_volume": v, "stiffness": k,
            "squeeze_curvature": k_sq, "bend_angle": (kappa_p + k_sq) * L,
            "pressure_angle": kappa_p * L, "pressure_moment": moment,
            "blocked_pressure": rho * p, "squeeze_moment": m_sq, "torque": torque,
            "tip_force": torque / L}
