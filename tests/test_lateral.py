"""The ``lateral_pressure`` variant (docs/model.md s. 18).

Expected values come from the closed form's own definition (a double integral of the
confining fraction, by scipy), its limits, and the moment balance at small pressure.
"""

import math

import numpy as np
import pytest
from scipy import integrate

import nylonflex as nf
from nylonflex.physics.bending import _lateral_lever, _pressure_moment
from nylonflex.physics.limits import LATERAL_PRESSURE, PAPER, _model_moment

SECTIONS = [(20e-3, 6e-3, 6e-3), (7.5e-3, 2e-3, 2e-3), (6e-3, 5e-3, 5e-3),
            (15e-3, 4e-3, 1e-3), (3e-3, 0.3e-3, 2e-3)]


def _lever_by_quadrature(a, t, b):
    """int over the wall of (R - r)/t y dA plus over the floor under the chamber of
    (y/b) y dA: the definition, integrated numerically."""
    r_out = a + t
    wall, _ = integrate.dblquad(lambda r, phi: (r_out - r) / t * (b + r * math.sin(phi)) * r,
                                0.0, math.pi, a, r_out, epsabs=0, epsrel=1e-12)
    floor, _ = integrate.quad(lambda y: 2 * a * (y / b) * y, 0.0, b, epsrel=1e-13)
    return wall + floor


@pytest.mark.parametrize("a,t,b", SECTIONS)
def test_lateral_lever_is_its_integral(a, t, b):
    assert _lateral_lever(a, t, b) == pytest.approx(_lever_by_quadrature(a, t, b), rel=1e-10)


def test_lateral_lever_of_a_vanishing_wall_is_the_floor_alone():
    a, b = 10e-3, 2e-3
    floor = 2 * a * b * b / 3
    for t in (1e-4, 1e-5, 1e-6):
        # the wall's share shrinks like t (pi b a t / 2 + a^2 t to first order)
        wall = _lateral_lever(a, t, b) - floor
        assert wall == pytest.approx((math.pi * b * a / 2 + a * a) * t, rel=2 * t / a)


def test_paper_moment_is_unchanged_bit_for_bit():
    for a, t, b in SECTIONS:
        for p in (0.0, 1.0, 1234.5, 2.5e4):
            assert _model_moment(PAPER, p, a, t, b) == _pressure_moment(p, a, b)


def test_lateral_moment_is_the_end_caps_and_the_walls():
    for a, t, b in SECTIONS:
        lat = _model_moment(LATERAL_PRESSURE, 1e3, a, t, b)
        assert lat == pytest.approx(1e3 * ((4 * a**3 + 3 * math.pi * a * a * b) / 6
                                           + _lateral_lever(a, t, b)), rel=1e-14)


@pytest.mark.parametrize("a,t,b", SECTIONS[:3])
def test_small_pressure_angle_ratio_is_the_moment_ratio(a, t, b):
    """At small p M_S is linear in kappa, so theta scales with the moment (s. 6)."""
    p = 1.0
    ratio = nf.bend_angle(p, a, t, 0.1, base_thickness=b, model="lateral_pressure") / \
        nf.bend_angle(p, a, t, 0.1, base_thickness=b)
    expected = 1 + _lateral_lever(a, t, b) / _pressure_moment(1.0, a, b)
    assert ratio == pytest.approx(expected, rel=1e-3)


def test_lateral_bends_further_at_every_pressure_and_not_at_zero():
    p = np.array([0.0, 1e3, 5e3, 2e4])
    paper = nf.bend_angle(p, 20e-3, 6e-3, 90e-3)
    lateral = nf.bend_angle(p, 20e-3, 6e-3, 90e-3, model="lateral_pressure")
    assert lateral[0] == paper[0] == 0.0
    assert np.all(lateral[1:] > paper[1:])
    assert np.all(np.diff(lateral) > 0)


def test_bend_angle_broadcasts_and_checks_its_input():
    out = nf.bend_angle(np.array([[1e3], [2e3]]), np.array([10e-3, 20e-3]), 2e-3, 70e-3)
    assert out.shape == (2, 2)
    with pytest.raises(ValueError, match="model: must be one of"):
        nf.bend_angle(1e3, 10e-3, 2e-3, 70e-3, model="nope")
    with pytest.raises(ValueError, match="pressure"):
        nf.bend_angle(-1.0, 10e-3, 2e-3, 70e-3)


def test_cube_curve_of_the_lateral_model_is_nf_bend_angle():
    from nylonflex.config import parse_config
    from nylonflex.sweep.conductor import run_sweep

    cfg = parse_config({
        "name": "lateral", "model": ["paper", "lateral_pressure"],
        "grid": {"radius": {"values": [7.5, 20], "units": "mm"},
                 "wall_thickness": {"values": [2, 6], "units": "mm"},
                 "length": {"values": [70], "units": "mm"},
                 "coil_index": {"values": [1.1, 1.7]},
                 "wrap_angle": {"values": [8], "units": "deg"}},
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                   "pressure": {"start": 0, "stop": 20, "num": 5, "units": "kPa"}}})
    ds = run_sweep(cfg)
    curve = ds["bend_angle"].sel(model="lateral_pressure", radius=ds.radius[1],
                                 wall_thickness=ds.wall_thickness[1], length=70e-3)
    ref = nf.bend_angle(ds.pressure.values, float(ds.radius[1]),
                        float(ds.wall_thickness[1]), 70e-3, model="lateral_pressure")
    np.testing.assert_allclose(curve.values, ref, rtol=1e-9)
    # every design bends at least as far, and pushes at least as hard, as the paper's
    paper = ds.sel(model="paper")
    lat = ds.sel(model="lateral_pressure")
    assert np.all(lat["tip_force"].values >= paper["tip_force"].values)
