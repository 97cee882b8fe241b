"""Incompressible Ogden silicone (paper eqs. 4-6, docs/model.md section 5).

Strain energy (paper's convention, eq. 5)::

    W = sum_i mu_i / alpha_i (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3)

so that the initial shear modulus is mu_0 = 1/2 sum mu_i alpha_i. With sigma_3 = 0 the
principal Cauchy stress is sigma_1 = sum_i mu_i (l1^alpha_i - l3^alpha_i). Two states are
used: plane-strain bending (l2 = 1, l3 = 1/l1) and the hoop compression of the wall
(l1 = 1 - s, l2 = 1), which is the same formula at l = 1 - s.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import silicone_parameters
from ._formula import check, formula, scalar_or_array

__all__ = [
    "bending_stress",
    "cauchy_stress",
    "hoop_stress",
    "initial_shear_modulus",
    "strain_energy",
]


@formula
def _stress_and_slope(stretch, mu, alpha):
    """Plane-strain nominal stress S(l) = sum mu_i (l^(a_i-1) - l^(-a_i-1)) [Pa] and dS/dl.

    This is sigma_1 / l with sigma_1 = sum mu_i (l^a_i - l^-a_i), the Ogden Cauchy stress
    for l2 = 1, l3 = 1/l, sigma_3 = 0 (docs/model.md section 5). One log for all terms and
    one exp a term, since l^(-a-1) = 1 / (l^(a-1) l^2); the material moment computes the same
    powers in its own vectorised loop (:func:`.bending._section_moment`).
    """
    ln = math.log(stretch)
    inv_l2 = 1.0 / (stretch * stretch)
    s = 0.0
    ds = 0.0
    for i in range(mu.shape[0]):
        e1 = math.exp((alpha[i] - 1.0) * ln)
        e2 = inv_l2 / e1
        s += mu[i] * (e1 - e2)
        ds += mu[i] * ((alpha[i] - 1.0) * e1 + (alpha[i] + 1.0) * e2)
    return s, ds / stretch


@formula
def _equibiaxial_stress_and_slope(stretch, mu, alpha):
    """Nominal hoop stress of the paper's eq. (10)-(12) state and its slope [Pa].

    l_theta = l_l = l, l_r = 1/l^2, sigma_r = 0: sigma_theta = sum mu_i (l^a_i - l^-2a_i),
    S = sigma_theta / l = sum mu_i (l^(a_i-1) - l^(-2a_i-1)) (``paper_eq10``).
    """
    s = 0.0
    ds = 0.0
    for i in range(mu.shape[0]):
        a = alpha[i]
        s += mu[i] * (stretch ** (a - 1.0) - stretch ** (-2.0 * a - 1.0))
        ds += mu[i] * ((a - 1.0) * stretch ** (a - 2.0) + (2.0 * a + 1.0)
                       * stretch ** (-2.0 * a - 2.0))
    return s, ds


def _ogden(silicone):
    return silicone_parameters(silicone).arrays()


def initial_shear_modulus(silicone="tc5005"):
    """Initial shear modulus mu_0 = 1/2 sum mu_i alpha_i [Pa] of a silicone set."""
    return silicone_parameters(silicone).initial_shear_modulus


def strain_energy(stretch_1, stretch_2, stretch_3, silicone="tc5005"):
    """Ogden strain energy density W (eq. 5) [J/m^3].

    Parameters
    ----------
    stretch_1, stretch_2, stretch_3 : float or array
        Principal stretches [-], > 0. The material is incompressible; the caller gives a
        volume-preserving triple (l1 l2 l3 = 1).
    silicone : str, dict or Silicone
        Material set (see :mod:`nylonflex.materials`).
    """
    lams = [check(n, v, 0.0, lo_open=True, unit="-")
            for n, v in (("stretch_1", stretch_1), ("stretch_2", stretch_2),
                         ("stretch_3", stretch_3))]
    mu, alpha = _ogden(silicone)
    w = 0.0
    for m, a in zip(mu, alpha):
        w = w + m / a * (lams[0] ** a + lams[1] ** a + lams[2] ** a - 3.0)
    return scalar_or_array(w)


def cauchy_stress(stretch_1, stretch_3, silicone="tc5005"):
    """Principal Cauchy stress sigma_1 with sigma_3 = 0 (eq. 6) [Pa].

    sigma_1 = sum_i mu_i (l1^alpha_i - l3^alpha_i): eq. (6) with the hydrostatic pressure
    eliminated by the free surface sigma_3 = 0.

    Parameters
    ----------
    stretch_1 : float or array
        Stretch in the loaded direction [-], > 0.
    stretch_3 : float or array
        Stretch in the free (stress-free) direction [-], > 0.
    silicone : str, dict or Silicone
        Material set.
    """
    l1 = check("stretch_1", stretch_1, 0.0, lo_open=True, unit="-")
    l3 = check("stretch_3", stretch_3, 0.0, lo_open=True, unit="-")
    mu, alpha = _ogden(silicone)
    s = 0.0
    for m, a in zip(mu, alpha):
        s = s + m * (l1**a - l3**a)
    return scalar_or_array(s)


def _nominal(stretch, silicone):
    mu, alpha = _ogden(silicone)
    lam = np.asarray(stretch, dtype=float)
    out = np.vectorize(lambda x: _stress_and_slope(x, mu, alpha)[0], otypes=[float])(lam)
    return scalar_or_array(out)


def bending_stress(stretch, silicone="tc5005"):
    """Nominal (first Piola) stress of plane-strain stretching, S(l) = sigma_1/l [Pa].

    Parameters
    ----------
    stretch : float or array
        Axial stretch of a fibre of the section l [-], > 0 (l2 = 1, l3 = 1/l).
    silicone : str, dict or Silicone
        Material set.

    Notes
    -----
    docs/model.md section 5; the material moment integrates this stress over the undeformed
    section (section 6).
    """
    lam = check("stretch", stretch, 0.0, lo_open=True, unit="-")
    return _nominal(lam, silicone)


def hoop_stress(stroke, silicone="tc5005"):
    """Nominal hoop stress S_theta of the wall compressed to l_theta = 1 - s [Pa].

    The axial stretch is held at 1 and the radial stress is zero (docs/model.md section 4
    [choice]: the paper's eq. (10) writes l_l = 1 - s, we hold the length as its eq. (8)
    does). Negative: the wall is in compression.

    Parameters
    ----------
    stroke : float or array
        Muscle contraction s [-], 0 <= s < 1.
    silicone : str, dict or Silicone
        Material set.
    """
    s = check("stroke", stroke, 0.0, 1.0, hi_open=True, unit="-")
    return _nominal(1.0 - s, silicone)
