"""Wrap geometry and the load in the nylon wrap (paper eq. 9, docs/model.md section 4).

[choice] One muscle of outer width w = d_f (C + 1) is wound as a helix of angle psi
(measured from the hoop direction) around the outer contour of the cross-section, of
perimeter P_out = pi (a + t) + 2 (a + t) + 2 b. Its axial pitch is the helix pitch but never
less than touching turns: pitch = max(P_out tan psi, w / cos psi). Cutting the actuator
through the chamber's symmetry plane, pressure on the projected area and the compressed wall
are held by the hoop component of the muscle tension, twice per turn::

    F_n(s) = (p(s) a + |S_theta(s)| t) pitch / cos psi

independent of the length L.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import nylon_parameters, silicone_parameters
from ._formula import check, check_section, check_wrap_angle, formula, scalar_or_array
from .chamber import P_ATM, _gauge_pressure, _gauge_pressure_slope
from .silicone import _stress_and_slope

__all__ = ["muscle_length", "muscle_width", "nylon_force", "outer_perimeter", "wrap_pitch",
           "wrap_turns"]


@formula
def _outer_perimeter(radius, wall_thickness, base_thickness):
    """P_out = pi (a + t) + 2 (a + t) + 2 b [m]."""
    r = radius + wall_thickness
    return math.pi * r + 2.0 * r + 2.0 * base_thickness


@formula
def _pitch(radius, wall_thickness, base_thickness, wrap_angle, width):
    """Axial pitch max(P_out tan psi, w / cos psi) [m]."""
    helix = _outer_perimeter(radius, wall_thickness, base_thickness) * math.tan(wrap_angle)
    touching = width / math.cos(wrap_angle)
    return helix if helix > touching else touching


@formula
def _muscle_length(length, pitch, radius, wall_thickness, base_thickness, wrap_angle):
    """Muscle in the wrap l_m = n P_out / cos psi with n = L / pitch turns [m]."""
    return _muscle_length_at(length, pitch,
                             _outer_perimeter(radius, wall_thickness, base_thickness),
                             math.cos(wrap_angle))


@formula
def _muscle_length_at(length, pitch, perimeter, cos_wrap):
    """:func:`_muscle_length` from the outer perimeter P_out [m] and cos psi [-], which do
    not depend on the length (the grid kernel computes them once for all lengths)."""
    return length / pitch * perimeter / cos_wrap


@formula
def _wrap_force(pressure, hoop_stress, radius, wall_thickness, lever):
    """F_n = (p a + |S_theta| t) pitch / cos psi [N] from the pressure and hoop stress.

    ``lever`` = pitch / cos psi [m]. Kernels call it with p(s) and S_theta(s) computed once
    per stroke, since neither depends on the design.
    """
    return (pressure * radius + abs(hoop_stress) * wall_thickness) * lever


@formula
def _nylon_force_and_slope(stroke, radius, wall_thickness, lever, mu, alpha, p_atm):
    """F_n(s) (docs/model.md section 4) [N] and dF_n/ds [N]; lever = pitch / cos psi [m]."""
    p = _gauge_pressure(stroke, p_atm)
    dp = _gauge_pressure_slope(stroke, p_atm)
    s_theta, ds_dlam = _stress_and_slope(1.0 - stroke, mu, alpha)
    # d|S|/ds = sign(S) dS/dl dl/ds with dl/ds = -1
    sign = 1.0 if s_theta >= 0.0 else -1.0
    force = _wrap_force(p, s_theta, radius, wall_thickness, lever)
    slope = (dp * radius - sign * ds_dlam * wall_thickness) * lever
    return force, slope


def _geometry(radius, wall_thickness, base_thickness, wrap_angle):
    return (*check_section(radius, wall_thickness, base_thickness),
            check_wrap_angle(wrap_angle))


def outer_perimeter(radius, wall_thickness, base_thickness=None):
    """Perimeter of the cross-section's outer contour P_out [m].

    Parameters
    ----------
    radius : float or array
        Inner chamber radius a [m], > 0.
    wall_thickness : float or array
        Wall thickness t [m], > 0.
    base_thickness : float or array, optional
        Bottom layer thickness b [m], > 0; b = t when None (docs/model.md section 1 [choice]).
    """
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    return scalar_or_array(_outer_perimeter(a, t, b))


def muscle_width(coil_index, nylon="silver_nylon66"):
    """Outer width of the coiled muscle w = d_f (C + 1) [m]."""
    ny = nylon_parameters(nylon)
    lo, hi = ny.coil_index_range
    c = check("coil_index", coil_index, lo, hi, unit="-")
    return scalar_or_array(ny.fibre_diameter * (c + 1.0))


def wrap_pitch(radius, wall_thickness, wrap_angle, coil_index, base_thickness=None,
               nylon="silver_nylon66"):
    """Axial pitch of the wrap, max(P_out tan psi, w / cos psi) [m].

    Parameters
    ----------
    radius, wall_thickness : float or array
        a, t [m], > 0.
    wrap_angle : float or array
        Helix angle psi from the hoop direction [rad], in (0, pi/2).
    coil_index : float or array
        Coil index C [-], inside the table.
    base_thickness : float or array, optional
        b [m]; b = t when None.
    nylon : str, dict or Nylon
        Muscle set.
    """
    a, t, b, psi = _geometry(radius, wall_thickness, base_thickness, wrap_angle)
    w = muscle_width(coil_index, nylon)
    f = np.vectorize(_pitch, otypes=[float])
    return scalar_or_array(f(a, t, b, psi, w))


def wrap_turns(radius, wall_thickness, length, wrap_angle, coil_index, base_thickness=None,
               nylon="silver_nylon66"):
    """Number of turns n = L / pitch [-] (``length`` L [m], > 0; others as wrap_pitch)."""
    L = check("length", length, 0.0, lo_open=True, unit="m")
    return scalar_or_array(L / wrap_pitch(radius, wall_thickness, wrap_angle, coil_index,
                                          base_thickness, nylon))


def muscle_length(radius, wall_thickness, length, wrap_angle, coil_index, base_thickness=None,
                  nylon="silver_nylon66"):
    """Length of muscle in the wrap l_m = n P_out / cos psi [m] (arguments as wrap_turns)."""
    n = wrap_turns(radius, wall_thickness, length, wrap_angle, coil_index, base_thickness,
                   nylon)
    p_out = outer_perimeter(radius, wall_thickness, base_thickness)
    return scalar_or_array(n * p_out / np.cos(wrap_angle))


def nylon_force(stroke, radius, wall_thickness, wrap_angle, coil_index, base_thickness=None,
                silicone="tc5005", nylon="silver_nylon66"):
    """Tension in the nylon wrap F_n(s) that holds the chamber at stroke s [N].

    Parameters
    ----------
    stroke : float or array
        Muscle contraction s [-], 0 <= s < 1.
    radius, wall_thickness : float or array
        a, t [m], > 0.
    wrap_angle : float or array
        psi [rad], in (0, pi/2).
    coil_index : float or array
        Coil index C [-] (sets the muscle width, hence the touching-turn pitch).
    base_thickness : float or array, optional
        b [m]; b = t when None.
    silicone : str, dict or Silicone
        Wall material.
    nylon : str, dict or Nylon
        Muscle set.

    Returns
    -------
    float or array
        F_n(s) = (p(s) a + |S_theta(s)| t) pitch / cos psi [N]; independent of length.

    References
    ----------
    Paper eq. (9); docs/model.md section 4.
    """
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    a, t, b, psi = _geometry(radius, wall_thickness, base_thickness, wrap_angle)
    lever = np.asarray(wrap_pitch(a, t, psi, coil_index, b, nylon)) / np.cos(psi)
    mu, alpha = silicone_parameters(silicone).arrays()
    f = np.vectorize(lambda *x: _nylon_force_and_slope(*x, mu, alpha, P_ATM)[0],
                     otypes=[float])
    return scalar_or_array(f(s, a, t, lever))
