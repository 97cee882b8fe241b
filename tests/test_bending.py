import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import dblquad

import naive
from nylonflex.materials import SILICONE_PARAMETERS, silicone_parameters
from nylonflex.physics import bending, silicone

SETS = list(SILICONE_PARAMETERS)


def test_pressure_moment_is_first_moment_of_the_half_disc():
    # eq. (16) closed form = p * int_halfdisc y dA with y = b + r sin(phi) (eq. 14)
    p, a, b = 12e3, 11e-3, 3e-3
    first, _ = dblquad(lambda r, phi: (b + r * math.sin(phi)) * r, 0, math.pi, 0, a,
                       epsabs=0, epsrel=1e-13)
    assert bending.pressure_moment(p, a, b) == pytest.approx(p * first, rel=1e-12)
    assert bending.pressure_moment(p, a, b) == p * (4 * a**3 + 3 * math.pi * a**2 * b) / 6


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("a,t,kappa", [(5e-3, 1e-3, 3.0), (25e-3, 6e-3, 40.0),
                                       (12e-3, 2e-3, 150.0)])
def test_material_moment_matches_adaptive_quadrature(name, a, t, kappa):
    # docs/model.md section 6 as written, by scipy quad/dblquad at epsrel 1e-12
    # (tests/naive.py)
    mu, alpha = silicone_parameters(name).arrays()
    expected = naive.material_moment(kappa, a, t, t, mu, alpha)
    assert bending.material_moment(kappa, a, t, None, name) == pytest.approx(expected,
                                                                             rel=1e-11)


def test_small_angle_linearised_curvature():
    # S ~ 4 mu_0 (l - 1) for small strain, so M_S ~ 4 mu_0 I kappa with the second moment
    # I = 2(a+t) b^3/3 + pi b^2 (R^2 - a^2)/2 + 4 b (R^3 - a^3)/3 + pi (R^4 - a^4)/8, R = a+t
    a, t = 10e-3, 3e-3
    b, r = t, a + t
    inertia = (2 * r * b**3 / 3 + math.pi * b**2 * (r**2 - a**2) / 2
               + 4 * b * (r**3 - a**3) / 3 + math.pi * (r**4 - a**4) / 8)
    for name in SETS:
        mu0 = silicone.initial_shear_modulus(name)
        p = 0.01  # Pa: deep in the linear range (the error is O(p): 2e-5 at 1 Pa for tc5005)
        linear = bending.pressure_moment(p, a, b) / (4 * mu0 * inertia)
        assert bending.curvature(p, a, t, None, name) == pytest.approx(linear, rel=1e-6)


# The acceptance: fast Gauss-Legendre solve within 1e-9 of the slow reference over
# radius 5-25 mm, wall 1-6 mm, pressure 0-60 kPa, for every silicone set.
_GRID = [(a, t, p) for a in (5e-3, 14e-3, 25e-3) for t in (1e-3, 6e-3)
         for p in (0.0, 0.5e3, 20e3, 60e3)]


@pytest.mark.parametrize("name", SETS)
def test_curvature_matches_slow_reference(name):
    mu, alpha = silicone_parameters(name).arrays()
    for a, t, p in _GRID:
        fast = bending.curvature(p, a, t, None, name)
        slow = naive.curvature(p, a, t, t, mu, alpha, near=fast if fast > 0 else None)
        assert fast == pytest.approx(slow, rel=1e-9, abs=0.0), (a, t, p)


@pytest.mark.slow
# near p = 10 Pa quad reports roundoff at epsrel 1e-12 (the strains are ~1e-6); the bracket
# check of brentq and the 1e-9 comparison still hold
@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
# derandomized: the same 25 designs every run, so that a miss is a defect found once, not a
# coin CI tosses (the one known miss is pinned below)
@settings(max_examples=25, deadline=None, derandomize=True)
@given(st.sampled_from(SETS), st.floats(5e-3, 25e-3), st.floats(1e-3, 6e-3),
       st.floats(10.0, 60e3), st.floats(1e-3, 10e-3))  # p = 0 is exact, tested above
def test_curvature_matches_slow_reference_anywhere(name, a, t, p, b):
    mu, alpha = silicone_parameters(name).arrays()
    fast = bending.curvature(p, a, t, b, name)
    slow = naive.curvature(p, a, t, b, mu, alpha, near=fast if fast > 0 else None)
    assert fast == pytest.approx(slow, rel=1e-9, abs=0.0)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="a known defect: the 24-node phi quadrature falls "
                   "short of 1e-9 past a stretch of about 6 (tc5005; issue 49's quadrature)")
@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_curvature_matches_slow_reference_at_extreme_stretch():
    # found by the property test above when it drew at random (2026-12-07): a = 23.4 mm,
    # t = 1 mm, b = 7.8 mm, p = 26.9 kPa, 1 + kappa (a + t + b) = 6.2, beyond every fit;
    # fast 160.93218239, slow 160.93218223 1/m (1.0e-9); 96 nodes give the slow value
    mu, alpha = silicone_parameters("tc5005").arrays()
    a, t, p, b = 0.0234375, 1e-3, 26927.0, 0.0078125
    fast = bending.curvature(p, a, t, b, "tc5005")
    slow = naive.curvature(p, a, t, b, mu, alpha, near=fast)
    assert fast == pytest.approx(slow, rel=1e-9, abs=0.0)


def test_curvature_solves_the_moment_balance_without_a_guess():
    mu, alpha = silicone_parameters("tc5005").arrays()
    assert bending.curvature(30e3, 20e-3, 4e-3) == pytest.approx(
        naive.curvature(30e3, 20e-3, 4e-3, 4e-3, mu, alpha), rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.sampled_from(SETS), st.floats(5e-3, 25e-3), st.floats(1e-3, 6e-3),
       st.lists(st.floats(0.0, 60e3), min_size=2, max_size=6, unique=True))
def test_angle_monotone_in_pressure(name, a, t, pressures):
    p = np.sort(pressures)
    # strictly increasing for pressures a float can tell apart through M_P (hypothesis
    # found 5e-324 Pa: its moment underflows to zero, and so does the angle)
    assume(np.all(np.diff(p) > 1e-9 * p[-1]) and p[1] > 1e-9)
    theta = bending.bend_angle(p, a, t, 0.1, None, name)
    assert np.all(np.diff(theta) > 0)


@given(st.floats(1e-3, 0.3), st.floats(0.0, 40e3))
def test_angle_proportional_to_length(length, p):
    # docs/model.md section 6: theta depends on L only through the factor L
    theta = bending.bend_angle(p, 8e-3, 2e-3, length)
    assert theta == pytest.approx(bending.curvature(p, 8e-3, 2e-3) * length, rel=1e-15)


def test_base_thickness_choice_defaults_to_wall():
    # docs/model.md section 1 [choice]: b = t unless given
    assert bending.curvature(20e3, 9e-3, 3e-3) == bending.curvature(20e3, 9e-3, 3e-3, 3e-3)
    assert bending.curvature(20e3, 9e-3, 3e-3) != bending.curvature(20e3, 9e-3, 3e-3, 1e-3)


def test_nominal_stress_on_undeformed_section_choice():
    # docs/model.md section 6 [choice]: M_S integrates the nominal S = sigma/l, not sigma, over
    # the undeformed section; the two differ by the factor l at each fibre.
    a, t, kappa = 10e-3, 2e-3, 30.0
    mu, alpha = silicone_parameters("tc5005").arrays()

    def moment(stress):
        base, _ = dblquad(lambda y, x: stress(1 + kappa * y) * y, 0, 2 * (a + t), 0, t)
        wall, _ = dblquad(lambda r, phi: stress(1 + kappa * (t + r * math.sin(phi)))
                          * (t + r * math.sin(phi)) * r, 0, math.pi, a, a + t)
        return base + wall

    nominal = moment(lambda lam: naive.stress(lam, mu, alpha))
    cauchy = moment(lambda lam: naive.stress(lam, mu, alpha) * lam)
    got = bending.material_moment(kappa, a, t)
    assert got == pytest.approx(nominal, rel=1e-8)
    assert abs(got - cauchy) > 0.05 * cauchy


def test_tip_force_is_pressure_moment_over_length():
    # eq. (16), docs/model.md section 7
    assert bending.tip_force(10e3, 7.5e-3, 0.07, 2e-3) == pytest.approx(
        bending.pressure_moment(10e3, 7.5e-3, 2e-3) / 0.07, rel=1e-15)


@pytest.mark.parametrize("call,match", [
    (lambda: bending.curvature(1e3, 0.0, 1e-3), r"radius: must be in \[0.0005, 0.2\] m, got 0"),
    (lambda: bending.curvature(1e3, 5e-3, -1e-3), r"wall_thickness: must be in \[0.0001"),
    (lambda: bending.curvature(-5.0, 5e-3, 1e-3), r"pressure: must be >= 0 \[Pa\]"),
    (lambda: bending.bend_angle(1e3, 5e-3, 1e-3, 0.0), r"length: must be > 0 \[m\]"),
    (lambda: bending.curvature(1e3, 5e-3, 1e-3, 0.0), r"base_thickness: must be in \["),
    (lambda: bending.curvature(1e3, 5e-3, 1e-3, silicone="foam"), r"silicone: unknown set"),
])
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()
