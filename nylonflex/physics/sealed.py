"""The ``sealed_chamber`` variant's formulas: the sealed air, the chamber's compliance and the
squeeze bend, coupled (docs/model.md s. 22).

The wrap shortened by the stroke s leaves the chamber, unpressurised, the volume

    v_free(s) = V/V0 = (1 - s)^2 exp(gamma s),   gamma = g0 + g1 ln(t/a)

((1 - s)^2 is eq. 8's section shrinking at fixed shape; exp(gamma s) the section rounding
out inside the loop and the wall lengthening; gamma = 0 is the rigid section). The air
pushes the compliant chamber out by p/K, K = mu0 k(t/a) its volumetric stiffness,

    k(t/a) = (1 - (a/(a + t))^2) exp(k0 + k1 ln(t/a))

(the bracket is the Lame cylinder's, incompressible, plane strain: k0 = k1 = 0), and Boyle
closes it: (p0 + p)(v_free + p/K) = p0 tau (tau = T/T0, 1 isothermal), whose positive
root is :func:`_boyle_pressure`. K -> inf and gamma = 0 give eq. (8).

The bend adds to ``lateral_pressure``'s balance at that pressure the squeeze's curvature
kappa_sq = c_sq s / h, h = b + a + t/2, c_sq = c0 + c1 ln(t/a) (the wall, squeezed in the
hoop direction by s, lengthens by about s above the strain-limiting skin: c_sq = 1), and
to the blocked moment c_b M_S(kappa_sq) (the moment that holds that curvature straight:
c_b = 1).

Held straight (the blocked force), the chamber cannot lengthen by bending, so its air is
squeezed harder than in the free bend: the blocked pressure p_b = rho p,

    rho = max(1, exp(r0 + r1 x + r2 x^2 + r3 ln s + r4 a/L)),   x = ln(t/a)

(a correlation in the design's dimensionless groups, fitted to the twin's blocked
pressures; rho = 1, r = 0, is the free chamber's pressure, the model before), and the
blocked moment is c_a M_lateral(p_b) + c_b M_S(kappa_sq) (c_a = 1: the lateral balance's
moment at the blocked pressure).

The coefficients come from :data:`CALIBRATION_FILE` (``status`` says whether they are
fitted: the closed-form values above are not), written by :mod:`nylonflex.fe.chamber_fit`
from FE records; the kernels compile them in as constants and their cache is keyed on the
file (``kernels.cache``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ._formula import formula
from .calibrated import _initial_shear_modulus
from .records import SealedCoefficients

__all__ = ["BLOCKED_NEUTRAL", "CALIBRATION_FILE", "COEFFICIENTS", "COEFFICIENT_NAMES",
           "GAMMA_MAX", "ROUNDING_BOUND",
           "anchored_coefficients", "calibration", "sealed_coefficients"]

#: The shipped coefficients, their status and provenance.
CALIBRATION_FILE = Path(__file__).with_name("sealed_chamber.json")

#: The coefficients in the order of :data:`COEFFICIENTS`: stiffness k0, k1; rounding
#: g0, g1; squeeze c0, c1; blocked moment c_b, c_a; blocked pressure r0 .. r4.
COEFFICIENT_NAMES = ("k0", "k1", "g0", "g1", "c0", "c1", "cb", "ca", "r0", "r1", "r2", "r3",
                     "r4")

#: The blocked pressure's coefficients and the values that leave the blocked moment as it
#: was before they existed (the free chamber's pressure, c_a = 1): what a cube written
#: without them (seven stored coefficients) and a ``chamber=`` dict naming none get.
BLOCKED_NEUTRAL = {"ca": 1.0, "r0": 0.0, "r1": 0.0, "r2": 0.0, "r3": 0.0, "r4": 0.0}

#: The area a D-section of perimeter P reaches as the circle of that perimeter, over its
#: own: (pi + 2)^2 / (2 pi^2) [-], the most that rounding alone can give v_free over
#: (1 - s)^2 (docs/model.md s. 22).
ROUNDING_BOUND = (math.pi + 2.0) ** 2 / (2.0 * math.pi ** 2)

#: The largest gamma the formulas use [-]: below 2, v_free falls with s everywhere
#: (dv/ds = (1 - s) e^(gamma s) (gamma (1 - s) - 2)), so p(s) rises and inverts.
GAMMA_MAX = 1.5


def calibration() -> dict:
    """The shipped calibration file's content (coefficients, status, fit, provenance)."""
    return json.loads(CALIBRATION_FILE.read_text())


#: (k0, k1, g0, g1, c0, c1, cb) of :data:`CALIBRATION_FILE` (dimensionless).
COEFFICIENTS = SealedCoefficients(*(float(calibration()["coefficients"][n])
                                    for n in COEFFICIENT_NAMES))


def sealed_coefficients(value=None) -> SealedCoefficients:
    """The coefficients as a :class:`~.records.SealedCoefficients`: the shipped ones for
    None, else from a dict by name or a sequence in :data:`COEFFICIENT_NAMES` order (a
    dict with none of the blocked pressure's names, or a sequence of the first seven, as a
    cube written before them holds, takes :data:`BLOCKED_NEUTRAL`)."""
    if value is None:
        return COEFFICIENTS
    if isinstance(value, dict):
        value = {**BLOCKED_NEUTRAL, **value} if not any(n in value for n in BLOCKED_NEUTRAL) \
            else value
        missing = [n for n in COEFFICIENT_NAMES if n not in value]
        if missing:
            raise ValueError(f"chamber: needs {', '.join(COEFFICIENT_NAMES)}; missing "
                             f"{', '.join(missing)}")
        value = [value[n] for n in COEFFICIENT_NAMES]
    coef = tuple(float(c) for c in value)
    if len(coef) == len(COEFFICIENT_NAMES) - len(BLOCKED_NEUTRAL):  # a cube's before them
        coef += tuple(BLOCKED_NEUTRAL.values())
    if len(coef) != len(COEFFICIENT_NAMES) or not all(math.isfinite(c) for c in coef):
        raise ValueError(f"chamber: needs {len(COEFFICIENT_NAMES)} finite numbers "
                         f"({', '.join(COEFFICIENT_NAMES)}), got {value!r}")
    return SealedCoefficients(*coef)


def anchored_coefficients(measured, mu0, base=None) -> SealedCoefficients:
    """The coefficients that give one measured actuator's chamber (``nylonflex fit
    chamber``, docs/bench.md) at its own t/a and keep ``base``'s trends in t/a elsewhere.

    ``measured`` holds ``stiffness`` K [Pa], ``rounding`` gamma [-], ``squeeze`` c_sq [-]
    and the actuator's ``radius``, ``wall_thickness`` [m]; ``mu0`` [Pa] is the sweep's
    silicone's initial shear modulus; ``base`` the coefficients whose k1, g1, c1 and cb are
    kept (the shipped ones for None). With x = ln(t/a): k0 = ln(K / (mu0 (1 - (a/(a+t))^2)))
    - k1 x, g0 = gamma - g1 x, c0 = c_sq - c1 x.
    """
    base = sealed_coefficients(base)
    a, t = measured["radius"], measured["wall_thickness"]
    x = math.log(t / a)
    lame = 1.0 - (a / (a + t)) ** 2
    return base._replace(k0=math.log(measured["stiffness"] / (mu0 * lame)) - base.k1 * x,
                         g0=measured["rounding"] - base.g1 * x,
                         c0=measured["squeeze"] - base.c1 * x)


@formula
def _chamber_stiffness(radius, wall_thickness, mu, alpha, coef):
    """Volumetric stiffness K = dp/d(V/V0) of the chamber [Pa]: mu0 (1 - (a/(a+t))^2)
    exp(k0 + k1 ln(t/a)), ``coef`` the :data:`COEFFICIENTS` tuple."""
    r = radius / (radius + wall_thickness)
    lame = 1.0 - r * r
    return _initial_shear_modulus(mu, alpha) * lame * math.exp(
        coef[0] + coef[1] * math.log(wall_thickness / radius))


@formula
def _rounding(radius, wall_thickness, coef):
    """gamma = g0 + g1 ln(t/a) [-], at most :data:`GAMMA_MAX`."""
    g = coef[2] + coef[3] * math.log(wall_thickness / radius)
    return g if g < GAMMA_MAX else GAMMA_MAX


@formula
def _free_volume(stroke, gamma):
    """v_free = (1 - s)^2 exp(gamma s) and dv_free/ds [-]."""
    r = 1.0 - stroke
    e = math.exp(gamma * stroke)
    return r * r * e, r * e * (gamma * r - 2.0)


@formula
def _boyle_pressure(volume, inv_stiffness, tau, p_atm):
    """Gauge pressure p [Pa] of (p0 + p)(v + p/K) = p0 tau, and dp/dv [Pa].

    ``volume`` v_free [-], ``inv_stiffness`` p0/K [-] (0: a rigid chamber), ``tau`` the
    air's T/T0 [-], ``p_atm`` p0 [Pa]. The root with p0 + p > 0, written without
    cancellation: p = 2 p0 (tau - v) / (v + c + sqrt((v + c)^2 + 4 c (tau - v))), c = p0/K;
    c = 0 gives p0 (tau/v - 1) (eq. 8 for tau = 1, v = (1 - s)^2).
    """
    c = inv_stiffness
    d = tau - volume
    w = volume + c
    p = 2.0 * p_atm * d / (w + math.sqrt(w * w + 4.0 * c * d))
    return p, -(p_atm + p) / (volume + c * (p_atm + 2.0 * p) / p_atm)


@formula
def _sealed_pressure(stroke, radius, wall_thickness, mu, alpha, p_atm, tau, coef):
    """Chamber gauge pressure p(s) [Pa] and dp/ds [Pa] of the sealed, compliant chamber."""
    v, dv = _free_volume(stroke, _rounding(radius, wall_thickness, coef))
    c = p_atm / _chamber_stiffness(radius, wall_thickness, mu, alpha, coef)
    p, dp_dv = _boyle_pressure(v, c, tau, p_atm)
    return p, dp_dv * dv


@formula
def _sealed_stroke(pressure, radius, wall_thickness, mu, alpha, p_atm, tau, coef):
    """The stroke s [-] at which the sealed chamber holds the gauge pressure p [Pa]:
    the inverse of :func:`_sealed_pressure` (0 where p is at or below the pressure at
    s = 0; NaN where no stroke reaches p: p/K alone would exceed the air's whole volume).

    The volume Boyle allows, v = p0 tau/(p0 + p) - p/K, is v_free(s): 2 ln(1 - s) +
    gamma s = ln v, decreasing in s (gamma < 2), by Newton safeguarded by bisection.
    """
    v = p_atm * tau / (p_atm + pressure) - pressure / _chamber_stiffness(
        radius, wall_thickness, mu, alpha, coef)
    if v >= 1.0:
        return 0.0
    gamma = _rounding(radius, wall_thickness, coef)
    if v <= 0.0:
        return math.nan
    target = math.log(v)
    lo = 0.0
    hi = 1.0
    s = 1.0 - math.sqrt(v)  # the rigid section's root
    for _ in range(100):
        f = 2.0 * math.log(1.0 - s) + gamma * s - target
        if f > 0.0:
            lo = s
        else:
            hi = s
        step = f / (gamma - 2.0 / (1.0 - s))
        s_new = s - step
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        if abs(s_new - s) <= 1e-15 * (1.0 + s) or hi - lo <= 1e-15:
            return s_new
        s = s_new
    return s


@formula
def _squeeze_curvature(stroke, radius, wall_thickness, base_thickness, coef):
    """kappa_sq = c_sq s / h [1/m], c_sq = c0 + c1 ln(t/a), h = b + a + t/2: the curvature
    the wall's lengthening above the skin gives."""
    c_sq = coef[4] + coef[5] * math.log(wall_thickness / radius)
    return c_sq * stroke / (base_thickness + radius + 0.5 * wall_thickness)


@formula
def _blocked_ratio(stroke, radius, wall_thickness, length, coef):
    """rho = p_b / p [-]: the chamber's pressure held straight over its free bend's, at
    stroke s [-] of a design a, t, L [m]; max(1, exp(r0 + r1 x + r2 x^2 + r3 ln s + r4 a/L)),
    x = ln(t/a) (1 at s = 0)."""
    if stroke <= 0.0:
        return 1.0
    x = math.log(wall_thickness / radius)
    rho = math.exp(coef[8] + coef[9] * x + coef[10] * x * x + coef[11] * math.log(stroke)
                   + coef[12] * radius / length)
    return rho if rho > 1.0 else 1.0
