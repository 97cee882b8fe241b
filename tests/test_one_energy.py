"""One Ogden strain energy: every stress nylonflex computes is its derivative.

The energy is written once, :func:`nylonflex.physics.silicone.strain_energy` (the paper's
eq. 5, W = sum mu_i / alpha_i (l1^a_i + l2^a_i + l3^a_i - 3)). Four other places compute
stresses from the same constants for speed or for their own convention: the kernels' plane
strain and equibiaxial stresses (physics/silicone.py formulas, compiled into the kernels),
calibration's uniaxial and planar test stresses (calibration/hyperelastic.py) and the FE
twin's material (kernels/ogden.py, in FElupe's convention mu_i' = mu_i alpha_i / 2). Each is
held here against a central difference of that one energy along its own deformation path
(a closed form: d/dl W(path(l)) with incompressible principal stretches), never against
another of the four.
"""

from __future__ import annotations

import numpy as np
import pytest

from nylonflex.calibration.hyperelastic import nominal_stress
from nylonflex.materials import silicone_parameters
from nylonflex.physics import silicone
from nylonflex.physics.silicone import _equibiaxial_stress_and_slope, _stress_and_slope

SETS = ("tc5005", "ecoflex_00_30", "dragon_skin_10", "elastosil_m4601")
STRETCHES = (0.6, 0.85, 1.3, 2.2)
H = 1e-6


def _dw(path, lam, name):
    """d/dl W(path(l)) by a central difference of the one energy [Pa]."""
    return (silicone.strain_energy(*path(lam + H), name)
            - silicone.strain_energy(*path(lam - H), name)) / (2 * H)


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("lam", STRETCHES)
def test_plane_strain_stress_is_the_energys_derivative(name, lam):
    # (l, 1, 1/l), sigma_3 = 0: S = sigma_1 / l = dW/dl (docs/model.md s. 5)
    mu, alpha = silicone_parameters(name).arrays()
    s, slope = _stress_and_slope(lam, mu, alpha)
    assert s == pytest.approx(_dw(lambda x: (x, 1.0, 1.0 / x), lam, name), rel=1e-7)
    d2 = (_dw(lambda x: (x, 1.0, 1.0 / x), lam + 1e-4, name)
          - _dw(lambda x: (x, 1.0, 1.0 / x), lam - 1e-4, name)) / 2e-4
    assert slope == pytest.approx(d2, rel=1e-4)


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("lam", STRETCHES)
def test_equibiaxial_stress_is_the_energys_derivative(name, lam):
    # (l, l, 1/l^2), sigma_1 = sigma_2, sigma_3 = 0: dW/dl = 2 sigma_1 / l = 2 S (eq. 10-12)
    mu, alpha = silicone_parameters(name).arrays()
    s, _ = _equibiaxial_stress_and_slope(lam, mu, alpha)
    assert s == pytest.approx(0.5 * _dw(lambda x: (x, x, x**-2), lam, name), rel=1e-7)


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("test,path", [
    ("uniaxial", lambda x: (x, x**-0.5, x**-0.5)),
    ("planar", lambda x: (x, 1.0, 1.0 / x)),
])
def test_calibrations_test_stresses_are_the_energys_derivative(name, test, path):
    # a tensile test's nominal stress along its own path, the lateral faces free
    mu, alpha = silicone_parameters(name).arrays()
    lam = np.array(STRETCHES)
    got = nominal_stress(lam, "ogden2" if len(mu) == 2 else f"ogden{len(mu)}",
                         {"mu": list(mu), "alpha": list(alpha)}, test=test)
    want = [_dw(path, x, name) for x in STRETCHES]
    np.testing.assert_allclose(got, want, rtol=1e-7)


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("lam", STRETCHES)
def test_the_fe_materials_stress_is_the_energys_derivative(name, lam):
    # FElupe's convention mu' = mu alpha / 2 (fe/model.py felupe_ogden) is the same energy;
    # at F = diag(l, 1, 1/l) (J = 1) the principal Cauchy stresses are P_ii l_i, and only
    # differences are the material's (the u-p-J body carries the pressure):
    # (sigma_1 - sigma_3) / l = dW/dl along (l, 1, 1/l)
    pytest.importorskip("felupe")
    from nylonflex.fe.model import felupe_ogden
    from nylonflex.fe.ogden import OgdenIsochoric

    mu, alpha = silicone_parameters(name).arrays()
    material = OgdenIsochoric(*felupe_ogden(mu, alpha))
    F = np.diag([lam, 1.0, 1.0 / lam])[:, :, None, None]
    P = material.gradient([F, np.zeros(0)])[0][:, :, 0, 0]
    sigma_1, sigma_3 = P[0, 0] * lam, P[2, 2] / lam
    assert (sigma_1 - sigma_3) / lam == pytest.approx(
        _dw(lambda x: (x, 1.0, 1.0 / x), lam, name), rel=1e-7)
