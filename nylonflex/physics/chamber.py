"""Chamber pressure from the muscle's stroke: Boyle's law (paper eqs. 7-8, docs/model.md s. 3)."""

from __future__ import annotations

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
