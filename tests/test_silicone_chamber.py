
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nylonflex.materials import SILICONE_PARAMETERS
from nylonflex.physics import chamber, silicone

SETS = list(SILICONE_PARAMETERS)


@pytest.mark.parametrize("s,p", [
    (0.0, 0.0),
    (0.1, 101325 * (1 / 0.81 - 1)),   # docs/model.md section 3 closed form
    (0.054, 101325 * (1 / 0.946**2 - 1)),
])
def test_boyle_pressure(s, p):
    assert chamber.chamber_pressure(s) == pytest.approx(p, rel=1e-14)


def test_volume_ratio_choice_uniform_shrink_at_fixed_length():
    # docs/model.md section 3: V1/V2 = 1/(1 - s)^2 (eq. 8), isothermal P1 V1 = P2 V2
    s = np.linspace(0, 0.3, 7)
    p2 = chamber.P_ATM * chamber.volume_ratio(s)
    assert np.allclose(p2 - chamber.P_ATM, chamber.chamber_pressure(s), rtol=1e-13)


@pytest.mark.parametrize("bad", [1.0, 1.5, -0.01, float("nan")])
def test_stroke_at_or_above_one_is_refused(bad):
    with pytest.raises(ValueError, match=r"stroke: must be in \[0, 1\) \[-\]"):
        chamber.chamber_pressure(bad)


@given(st.sampled_from(SETS))
def test_zero_stress_at_stretch_one(name):
    assert silicone.bending_stress(1.0, name) == 0.0
    assert silicone.hoop_stress(0.0, name) == 0.0
    assert silicone.strain_energy(1.0, 1.0, 1.0, name) == 0.0


@given(st.sampled_from(SETS), st.floats(1.0001, 4.0))
def test_bending_stress_is_tensile_and_increasing(name, lam):
    s = silicone.bending_stress(lam, name)
    assert s > 0
    assert silicone.bending_stress(lam * 1.01, name) > s


def test_neo_hookean_limit():
    # Ogden N=1, alpha=2 is neo-Hookean with shear modulus mu: plane strain nominal stress
    # S = mu (l - l^-3) (docs/model.md section 5 with l2 = 1, l3 = 1/l)
    lam = np.linspace(0.6, 3.0, 9)
    assert np.allclose(silicone.bending_stress(lam, "elastosil_m4601"),
                       220e3 * (lam - lam**-3), rtol=1e-13)


@pytest.mark.parametrize("name", SETS)
def test_small_strain_modulus_is_four_mu0(name):
    # plane strain: dS/dl at l = 1 is 4 mu_0 (E = 3 mu_0, plane strain E/(1 - 1/4))
    h = 1e-6
    slope = (silicone.bending_stress(1 + h, name) - silicone.bending_stress(1 - h, name)) / (2 * h)
    assert slope == pytest.approx(4 * silicone.initial_shear_modulus(name), rel=1e-6)


def test_cauchy_stress_is_derivative_of_strain_energy():
    # eq. (6): sigma_1 - sigma_3 = l1 dW/dl1 - l3 dW/dl3 along an incompressible path
    # (l1, 1, 1/l1): d W / d l1 = (sigma_1 - sigma_3) / l1 with sigma_3 = 0
    for name in SETS:
        l1, h = 1.7, 1e-6
        dw = (silicone.strain_energy(l1 + h, 1, 1 / (l1 + h), name)
              - silicone.strain_energy(l1 - h, 1, 1 / (l1 - h), name)) / (2 * h)
        assert dw == pytest.approx(silicone.cauchy_stress(l1, 1 / l1, name) / l1, rel=1e-7)


def test_hoop_stress_choice_holds_the_length():
    # docs/model.md section 4 [choice]: l_theta = 1 - s, l_l = 1 (not the paper's eq. 10 1 - s),
    # sigma_r = 0, so S_theta(s) = S(1 - s) of the plane-strain formula
    s = 0.08
    assert silicone.hoop_stress(s) == pytest.approx(silicone.bending_stress(1 - s), rel=1e-15)
    lam = 1 - s
    paper_eq10 = silicone.cauchy_stress(lam, 1 / lam**2) / lam  # l_l = 1 - s as printed
    assert abs(silicone.hoop_stress(s) - paper_eq10) > 0.1 * abs(paper_eq10)
    assert silicone.hoop_stress(s) < 0  # compression


def test_bad_stretch_is_refused():
    with pytest.raises(ValueError, match=r"stretch: must be > 0"):
        silicone.bending_stress(0.0)
