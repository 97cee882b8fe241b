"""The ``fe_calibrated`` variant's correction: ``lateral_pressure``'s bend angle scaled by a
smooth function of dimensionless groups fitted to the FE twin (docs/model.md s. 21,
docs/fidelity.md).

    theta_cal = theta_lateral(p) * exp(c0 + c1 ln(t/a) + c2 ln(L/a) + c3 q / (1 + q)),
    q = p a / (mu0 t)

q is the wall's hoop stress p a / t over the silicone's initial shear modulus mu0 =
sum(mu_i alpha_i) / 2: how far the pressure has stretched the wall, which is where the
balance and the FE part (the balance is nearly right at 20 deg and bends too far at 50
deg). ln(L/a) carries the end caps, which a length-free balance cannot see. The factor is
bounded in q (q / (1 + q) < 1), so the angle stays increasing in p past the training
range; its length part (L/a)^c2 scales the curvature of each length and leaves the
range fraction and every length-free variable as ``lateral_pressure`` has them (the
blocked tip force is the moment's, which the correction does not change).

The coefficients come from :data:`CALIBRATION_FILE`, written by ``nylonflex fit fe``
(its training designs, their FE angles, the leave-one-design-out error and provenance are
in the same file). The kernels' cache is keyed on it too (``kernels.cache``), so a new fit
can never run with stale machine code.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ._formula import formula

__all__ = ["CALIBRATION_FILE", "COEFFICIENTS", "CORRECTION", "TERMS", "calibration"]

#: The shipped fit (``nylonflex fit fe --designs 48 --workers 2``, see its provenance).
CALIBRATION_FILE = Path(__file__).with_name("fe_calibrated.json")

#: The correction's regressors, in the order of the coefficients.
TERMS = ("1", "ln(t/a)", "ln(L/a)", "q/(1+q)")
#: The correction, in words (the calibration file says it too).
CORRECTION = ("theta = theta_lateral_pressure exp(c0 + c1 ln(t/a) + c2 ln(L/a) + c3 q/(1+q)), "
              "q = p a/(mu0 t), mu0 = sum(mu_i alpha_i)/2")


def calibration() -> dict:
    """The shipped calibration file's content (coefficients, fit, training designs)."""
    return json.loads(CALIBRATION_FILE.read_text())


#: c0..c3 of the correction (dimensionless), from :data:`CALIBRATION_FILE`.
COEFFICIENTS = tuple(float(c) for c in calibration()["coefficients"])
if len(COEFFICIENTS) != len(TERMS):  # pragma: no cover - a hand-edited file
    raise ValueError(f"{CALIBRATION_FILE.name}: needs {len(TERMS)} coefficients, "
                     f"got {len(COEFFICIENTS)}")
_C0, _C1, _C2, _C3 = COEFFICIENTS


@formula
def _initial_shear_modulus(mu, alpha):
    """mu0 = sum(mu_i alpha_i) / 2 of an Ogden set [Pa]."""
    s = 0.0
    for i in range(mu.shape[0]):
        s += mu[i] * alpha[i]
    return 0.5 * s


@formula
def _section_correction(pressure, radius, wall_thickness, mu, alpha):
    """The length-free part of the correction, exp(c0 + c1 ln(t/a) + c3 q/(1+q)) [-]."""
    q = pressure * radius / (_initial_shear_modulus(mu, alpha) * wall_thickness)
    return math.exp(_C0 + _C1 * math.log(wall_thickness / radius) + _C3 * q / (1.0 + q))


@formula
def _length_correction(radius, length):
    """The length part of the correction, (L/a)^c2 [-]."""
    return math.exp(_C2 * math.log(length / radius))
