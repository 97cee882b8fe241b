"""Chamber pressure from the muscle's stroke: Boyle's law (paper eqs. 7-8, docs/model.md s. 3)."""

from __future__ import annotations

import math

from ._formula import check, formula, scalar_or_array

__all__ = ["P_ATM", "chamber_pressure", "volume_ratio"]

#: Atmospheric pressure, the chamber's initial absolute pressure [Pa].
P_ATM = 101325.0


@formula
def _gauge_pressure(stroke, p_atm):
    """p(s) = P_atm ((1 - s)^-2 - 1) [Pa]."""
    r = 1.0 - stroke
    return p_atm * (1.0 / (r * r) - 1.0)


@formula
def _gauge_pressure_slope(stroke, p_atm):
    """dp/ds = 2 P_atm (1 - s)^-3 [Pa]."""
    r = 1.0 - stroke
    return 2.0 * p_atm / (r * r * r)


@formula
def _solid_fraction(radius, wall_thickness, base_thickness):
    """Silicone's share A_s/A_out of the area inside the outer contour [-].

    A_out = pi (a + t)^2 / 2 + 2 (a + t) b (half disc on the base), chamber pi a^2 / 2.
    """
    r = radius + wall_thickness
    outer = 0.5 * math.pi * r * r + 2.0 * r * base_thickness
    return (outer - 0.5 * math.pi * radius * radius) / outer


@formula
def _gauge_pressure_wall(stroke, p_atm, solid):
    """p(s) and dp/ds [Pa] with an incompressible wall (``incompressible_wall``).

    The outer contour shrinks by (1 - s) and the silicone's area A_s is conserved, so the
    chamber's area goes from A_out - A_s to (1 - s)^2 A_out - A_s:
    V1/V2 = (1 - phi) / ((1 - s)^2 - phi) with phi = A_s/A_out. phi = 0 is the paper's
    (1 - s)^-2. Infinite once the chamber closes, (1 - s)^2 <= phi.
    """
    r = 1.0 - stroke
    free = r * r - solid
    if free <= 0.0:
        return math.inf, math.inf
    ratio = (1.0 - solid) / free
    return p_atm * (ratio - 1.0), p_atm * ratio * 2.0 * r / free


def volume_ratio(stroke):
    """Initial over actuated chamber volume V1/V2 = (1 - s)^-2 (eq. 8) [-].

    Parameters
    ----------
    stroke : float or array
        Muscle contraction s, a fraction of its ambient length [-], 0 <= s < 1.

    Notes
    -----
    The wrap shrinks the cross-section by (1 - s) in both directions while the length is
    held (docs/model.md section 3).
    """
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    return scalar_or_array(1.0 / (1.0 - s) ** 2)


def chamber_pressure(stroke, p_atm=P_ATM):
    """Gauge pressure of the sealed air chamber at muscle stroke s [Pa].

    Parameters
    ----------
    stroke : float or array
        Muscle contraction s [-], 0 <= s < 1.
    p_atm : float, default 101325
        Initial absolute chamber pressure, atmospheric [Pa].

    Returns
    -------
    float or array
        p(s) = P_atm ((1 - s)^-2 - 1) [Pa], isothermal (Boyle, eqs. 7-8).

    References
    ----------
    Paper eqs. (7)-(8); docs/model.md section 3.
    """
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    p_atm = float(check("p_atm", p_atm, 0.0, lo_open=True, unit="Pa"))
    return scalar_or_array(_gauge_pressure(s, p_atm))
