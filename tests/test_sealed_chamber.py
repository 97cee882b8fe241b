"""The ``sealed_chamber`` variant (docs/model.md s. 22): the sealed air in a compliant
chamber whose section rounds out, and the squeeze bend.

Expected values come from eq. (8) (the rigid limit), the quadratic's own limits, and
``lateral_pressure`` (its own tests pin it) plus the squeeze written from s. 22.
"""

import math

import numpy as np
import pytest

import nylonflex as nf
from conftest import DEG, EXAMPLE_1, EXAMPLE_2
from nylonflex.materials import silicone_parameters
from nylonflex.physics import material_moment
from nylonflex.physics.chamber import P_ATM, _gauge_pressure
from nylonflex.physics.limits import design_limits
from nylonflex.physics.sealed import (COEFFICIENT_NAMES, COEFFICIENTS, ROUNDING_BOUND,
                                      _boyle_pressure, _chamber_stiffness, _free_volume,
                                      _sealed_pressure,
                                      _sealed_stroke, _squeeze_curvature, calibration)

MU, ALPHA = silicone_parameters("tc5005").arrays()
MU0 = silicone_parameters("tc5005").initial_shear_modulus
#: k0 so large that K overflows to ~inf: the rigid chamber; g = 1 (gamma = 0)
RIGID = (600.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0)


@pytest.mark.parametrize("s", [0.0, 1e-6, 0.01, 0.054, 0.097, 0.3, 0.6])
def test_a_rigid_section_gives_eq8(s):
    # docs/model.md s. 3, paper eq. (8): p = P_atm ((1 - s)^-2 - 1)
    p, dp = _sealed_pressure(s, 20e-3, 6e-3, MU, ALPHA, P_ATM, 1.0, RIGID)
    assert p == pytest.approx(_gauge_pressure(s, P_ATM), rel=1e-12, abs=1e-9)
    assert dp == pytest.approx(2.0 * P_ATM / (1.0 - s) ** 3, rel=1e-12)
    # and the closed form with c = p0/K = 0 exactly
    v = (1.0 - s) ** 2
    assert _boyle_pressure(v, 0.0, 1.0, P_ATM)[0] == pytest.approx(
        _gauge_pressure(s, P_ATM), rel=1e-12, abs=1e-9)


@pytest.mark.parametrize("v, c, tau", [(0.9, 10.0, 1.0), (0.5, 1e-3, 1.0), (0.99, 50.0, 1.1),
                                       (1.0, 5.0, 1.0), (0.8, 1e6, 1.0), (0.95, 2.0, 1.2)])
def test_the_root_solves_boyle_with_the_chamber_compliance(v, c, tau):
    # (p0 + p)(v + p/K) = p0 tau, K = p0/c
    p, dp_dv = _boyle_pressure(v, c, tau, P_ATM)
    k = P_ATM / c
    assert (P_ATM + p) * (v + p / k) == pytest.approx(P_ATM * tau, rel=1e-13)
    assert P_ATM + p > 0
    h = 1e-7
    fd = (_boyle_pressure(v + h, c, tau, P_ATM)[0] - _boyle_pressure(v - h, c, tau, P_ATM)[0]) \
        / (2 * h)
    assert dp_dv == pytest.approx(fd, rel=1e-6)


def test_the_quadratics_limits():
    # v = tau: no pressure; a very soft chamber: p -> K (tau - v) (it takes up the squeeze);
    # heating a rigid chamber at v = 1: p = p0 (tau - 1) (Gay-Lussac)
    assert _boyle_pressure(0.9, 3.0, 0.9, P_ATM)[0] == 0.0
    c = 1e8
    assert _boyle_pressure(0.9, c, 1.0, P_ATM)[0] == pytest.approx(P_ATM / c * 0.1, rel=1e-6)
    assert _boyle_pressure(1.0, 0.0, 1.1, P_ATM)[0] == pytest.approx(0.1 * P_ATM, rel=1e-12)
    # compliance always lowers the pressure below eq. (8)
    ps = [_boyle_pressure(0.81, c, 1.0, P_ATM)[0] for c in (0.0, 0.1, 1.0, 10.0)]
    assert all(np.diff(ps) < 0)


def test_stiffness_is_lames_cylinder_times_the_fit():
    # incompressible thick cylinder in plane strain: K = mu0 (1 - (a/(a+t))^2); -> 2 mu0 t/a
    closed = (0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0)
    a, t = 20e-3, 6e-3
    assert _chamber_stiffness(a, t, MU, ALPHA, closed) == pytest.approx(
        MU0 * (1 - (a / (a + t)) ** 2), rel=1e-14)
    assert _chamber_stiffness(a, 1e-6, MU, ALPHA, closed) == pytest.approx(
        2 * MU0 * 1e-6 / a, rel=1e-4)
    fit = (0.3, -0.2, 0.0, 0.0, 1.0, 0.0, 1.0)
    assert _chamber_stiffness(a, t, MU, ALPHA, fit) == pytest.approx(
        MU0 * (1 - (a / (a + t)) ** 2) * math.exp(0.3 - 0.2 * math.log(t / a)), rel=1e-14)


def test_free_volume_and_the_rounding_bound():
    v, dv = _free_volume(0.1, 0.5)
    assert v == pytest.approx(0.81 * math.exp(0.05), rel=1e-15)
    h = 1e-7
    assert dv == pytest.approx((_free_volume(0.1 + h, 0.5)[0] - _free_volume(0.1 - h, 0.5)[0])
                               / (2 * h), rel=1e-7)
    # a D of perimeter P = (pi + 2) a rounds out at most to the circle of that perimeter
    a = 1.0
    circle = (math.pi + 2.0) ** 2 * a * a / (4.0 * math.pi)
    assert ROUNDING_BOUND == pytest.approx(circle / (math.pi * a * a / 2), rel=1e-15)
    assert ROUNDING_BOUND == pytest.approx(1.3393, abs=1e-4)


@pytest.mark.parametrize("coef", [COEFFICIENTS, (0.5, 0.3, 0.8, -0.2, 1.2, 0.1, 2.0),
                                  (-1.0, 0.0, -1.5, 0.0, 1.0, 0.0, 1.0)])
@pytest.mark.parametrize("s", [1e-4, 0.03, 0.097, 0.25])
def test_the_stroke_that_holds_a_pressure_inverts_it(coef, s):
    a, t = 7.5e-3, 2e-3
    p, dp = _sealed_pressure(s, a, t, MU, ALPHA, P_ATM, 1.0, coef)
    assert p > 0 and dp > 0
    assert _sealed_stroke(p, a, t, MU, ALPHA, P_ATM, 1.0, coef) == pytest.approx(s, rel=1e-10)
    h = 1e-7
    fd = (_sealed_pressure(s + h, a, t, MU, ALPHA, P_ATM, 1.0, coef)[0]
          - _sealed_pressure(s - h, a, t, MU, ALPHA, P_ATM, 1.0, coef)[0]) / (2 * h)
    assert dp == pytest.approx(fd, rel=1e-6)
    assert _sealed_stroke(0.0, a, t, MU, ALPHA, P_ATM, 1.0, coef) == 0.0
    # a pressure no stroke reaches: the compliance alone would take more than the air's
    # whole volume, p/K > p0/(p0 + p)
    k = _chamber_stiffness(a, t, MU, ALPHA, coef)
    assert math.isnan(_sealed_stroke(2.0 * k, a, t, MU, ALPHA, P_ATM, 1.0, coef))


@pytest.mark.parametrize("a, t, L", [(20e-3, 6e-3, 90e-3), (7.5e-3, 2e-3, 70e-3),
                                     (5e-3, 6e-3, 90e-3), (25e-3, 1e-3, 150e-3)])
def test_angle_is_lateral_pressures_plus_the_squeeze(a, t, L):
    # s. 22: theta(p) = theta_lateral(p) + c_sq s(p) L / (b + a + t/2)
    p = np.array([0.0, 200.0, 1e3, 3e3])
    lateral = nf.bend_angle(p, a, t, L, model="lateral_pressure")
    sealed = nf.bend_angle(p, a, t, L, model="sealed_chamber")
    s = np.array([_sealed_stroke(q, a, t, MU, ALPHA, P_ATM, 1.0, COEFFICIENTS) for q in p])
    c_sq = COEFFICIENTS[4] + COEFFICIENTS[5] * math.log(t / a)
    np.testing.assert_allclose(sealed, lateral + c_sq * s * L / (t + a + t / 2), rtol=1e-12)
    assert sealed[0] == 0.0


def test_the_design_at_the_sealed_pressure():
    # p* is the sealed chamber's at s*; theta* lateral_pressure's balance at p* plus the
    # squeeze; the muscle's load from that pressure, far below eq. (8)'s
    d = design_limits(**EXAMPLE_1, model="sealed_chamber")
    paper = design_limits(**EXAMPLE_1)
    s = d["usable_stroke"]
    assert s == paper["usable_stroke"]  # stroke-limited in both: s_max(1.1)
    p = _sealed_pressure(s, 20e-3, 6e-3, MU, ALPHA, P_ATM, 1.0, COEFFICIENTS)[0]
    assert d["pressure_max"] == pytest.approx(p, rel=1e-14)
    assert d["pressure_max"] < 0.2 * paper["pressure_max"]
    theta = float(nf.bend_angle(p, 20e-3, 6e-3, 90e-3, model="lateral_pressure")) + \
        _squeeze_curvature(s, 20e-3, 6e-3, 6e-3, COEFFICIENTS) * 90e-3
    assert d["bend_angle_max"] == pytest.approx(theta, rel=1e-9)
    assert d["nylon_force_max"] < paper["nylon_force_max"]
    # blocked: c_a times lateral_pressure's moment at the blocked pressure rho p*, plus
    # c_b M_S(kappa_sq), over L; rho from its formula, written out here
    lateral = design_limits(**EXAMPLE_1, model="lateral_pressure")
    m_lat = lateral["torque_max"] * p / lateral["pressure_max"]  # linear in p (s. 18)
    k_sq = _squeeze_curvature(s, 20e-3, 6e-3, 6e-3, COEFFICIENTS)
    m_sq = float(material_moment(k_sq, 20e-3, 6e-3))
    c = COEFFICIENTS
    x = math.log(6 / 20)
    rho = max(1.0, math.exp(c.r0 + c.r1 * x + c.r2 * x * x + c.r3 * math.log(s)
                            + c.r4 * 20 / 90))
    assert rho > 1.5  # held straight, the air is squeezed harder than in the free bend
    assert d["torque_max"] == pytest.approx(c.ca * rho * m_lat + c.cb * m_sq, rel=1e-9)
    assert d["tip_force_max"] == pytest.approx(d["torque_max"] / 90e-3, rel=1e-14)


def test_the_shipped_file_says_what_it_is():
    doc = calibration()
    assert doc["model"] == "sealed_chamber"
    assert doc["status"] in ("uncalibrated", "fitted")
    if doc["status"] == "fitted":  # a fit carries its training records and leave-one-out
        assert len(doc["fit"]["designs"]) >= 10
        assert "loo" in doc["fit"] and "provenance" in doc
        # issue 45's line: full-stroke bend and blocked force within 15 % of the twin on at
        # least 40 designs, each left out of the fit (docs/fidelity.md)
        loo = doc["fit"]["loo"]
        assert loo["tolerance"] == 0.15 and loo["n"] >= 40
        assert loo["within"]["bend_angle"] >= 40 and loo["within"]["tip_force"] >= 40
        assert set(doc["coefficients"]) == set(COEFFICIENT_NAMES)


def test_cube_curves_and_designs_agree_with_the_physics():
    from nylonflex.config import parse_config
    from nylonflex.sweep.conductor import run_sweep

    cfg = parse_config({
        "name": "sealed", "model": ["paper", "sealed_chamber"],
        "grid": {"radius": {"values": [7.5, 20], "units": "mm"},
                 "wall_thickness": {"values": [2, 6], "units": "mm"},
                 "length": {"values": [70, 90], "units": "mm"},
                 "coil_index": {"values": [1.1, 1.7]},
                 "wrap_angle": {"values": [8, 20], "units": "deg"}},
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                   "pressure": {"start": 0, "stop": 5, "num": 4, "units": "kPa"}}})
    ds = run_sweep(cfg)
    sealed = ds.sel(model="sealed_chamber")
    a, t, L = (ds[n].values for n in ("radius", "wall_thickness", "length"))
    A, T, LL, P = np.meshgrid(a, t, L, ds.pressure.values, indexing="ij")
    np.testing.assert_allclose(sealed["bend_angle"].values,
                               nf.bend_angle(P, A, T, LL, model="sealed_chamber"), rtol=1e-9)
    grids = np.meshgrid(*cfg.axes.values(), indexing="ij")
    exact = design_limits(*grids, model="sealed_chamber")
    for name, v in exact.items():
        if name in sealed:
            np.testing.assert_allclose(sealed[name].values, v, rtol=1e-9, err_msg=name)


def test_pointwise_is_the_python_loop():
    d = dict(radius=np.array([20e-3, 7.5e-3, 5e-3, 20e-3]),
             wall_thickness=np.array([6e-3, 2e-3, 6e-3, 3e-3]),
             length=np.array([90e-3, 70e-3, 90e-3, 90e-3]),
             coil_index=np.array([1.1, 1.7, 1.7, 1.1]),
             wrap_angle=np.array([8, 8, 8, 20]) * DEG)
    fast = nf.evaluate(**d, model="sealed_chamber")
    slow = design_limits(*d.values(), model="sealed_chamber")
    for name, v in slow.items():
        np.testing.assert_allclose(fast[name], v, rtol=1e-12, err_msg=name)
    assert nf.evaluate(**EXAMPLE_2, model="sealed_chamber")["pressure_max"] < 0.2 * \
        nf.evaluate(**EXAMPLE_2)["pressure_max"]
